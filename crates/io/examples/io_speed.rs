//! Read and write throughput of one mesh file, for comparing builds:
//!
//! ```text
//! cargo run --release -p subd-io --example io_speed -- read FILE [REPEATS]
//! cargo run --release -p subd-io --example io_speed -- write FILE OUT [REPEATS]
//! cargo run --release -p subd-io --example io_speed -- encode FILE obj|ply [REPEATS]
//! ```
//!
//! `read` times [`subd_io::read_mesh`] (and, apart, the topology build it includes);
//! `write` reads FILE once, then times [`subd_io::write_mesh`] to OUT (format by extension,
//! PLY binary, a new file each time); `encode` times [`subd_io::encode_mesh`] into a sink
//! (no file). Each line: seconds and MB/s (10^6 bytes of the file read or written).
//! Threads: `RAYON_NUM_THREADS`.

use std::path::Path;
use std::time::Instant;

use subd_io::{Format, ReadOptions, WriteOptions, encode_mesh, read_mesh, write_mesh};
use subd_mesh::TopologyBuilder;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let repeats = |k: usize| args.get(k).and_then(|s| s.parse().ok()).unwrap_or(1usize);
    match args.first().map(String::as_str) {
        Some("read") if args.len() >= 2 => read(Path::new(&args[1]), repeats(2)),
        Some("write") if args.len() >= 3 => {
            write(Path::new(&args[1]), Path::new(&args[2]), repeats(3))
        }
        Some("encode") if args.len() >= 3 => encode(Path::new(&args[1]), &args[2], repeats(3)),
        _ => Err(
            "usage: io_speed read FILE [REPEATS] | write FILE OUT [REPEATS] | encode FILE obj|ply [REPEATS]"
                .into(),
        ),
    }
}

fn mb_per_s(bytes: u64, seconds: f64) -> f64 {
    bytes as f64 / seconds / 1e6
}

fn read(path: &Path, repeats: usize) -> Result<(), Box<dyn std::error::Error>> {
    let bytes = std::fs::metadata(path)?.len();
    for _ in 0..repeats {
        let t = Instant::now();
        let file = read_mesh(path, &ReadOptions::default())?;
        let total = t.elapsed().as_secs_f64();
        let topo = &file.mesh.topology;
        let sizes: Vec<u32> = topo.face_sizes().collect();
        let t = Instant::now();
        TopologyBuilder::new(file.mesh.positions.len()).build(&sizes, topo.all_face_vertices())?;
        let build = t.elapsed().as_secs_f64();
        println!(
            "read {total:.3} s {:.1} MB/s; topology build {build:.3} s; rest {:.3} s {:.1} MB/s",
            mb_per_s(bytes, total),
            total - build,
            mb_per_s(bytes, total - build)
        );
    }
    Ok(())
}

fn write(path: &Path, out: &Path, repeats: usize) -> Result<(), Box<dyn std::error::Error>> {
    let file = read_mesh(path, &ReadOptions::default())?;
    for _ in 0..repeats {
        // Each write makes a new file (replacing one costs the file system more: freeing
        // the old one's pages, and ext4 starts writing back a file renamed over another).
        let _ = std::fs::remove_file(out);
        let t = Instant::now();
        write_mesh(out, &file.mesh, &WriteOptions::default())?;
        let s = t.elapsed().as_secs_f64();
        let bytes = std::fs::metadata(out)?.len();
        println!(
            "write {s:.3} s {:.1} MB/s ({bytes} bytes)",
            mb_per_s(bytes, s)
        );
    }
    Ok(())
}

/// Counts the bytes written to it.
struct Counter(u64);

impl std::io::Write for Counter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0 += buf.len() as u64;
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

fn encode(path: &Path, format: &str, repeats: usize) -> Result<(), Box<dyn std::error::Error>> {
    let format = match format {
        "obj" => Format::Obj,
        "ply" => Format::Ply,
        _ => return Err("encode: obj or ply".into()),
    };
    let file = read_mesh(path, &ReadOptions::default())?;
    for _ in 0..repeats {
        let mut sink = Counter(0);
        let t = Instant::now();
        encode_mesh(&mut sink, &file.mesh, format, &WriteOptions::default())?;
        let s = t.elapsed().as_secs_f64();
        println!(
            "encode {s:.3} s {:.1} MB/s ({} bytes)",
            mb_per_s(sink.0, s),
            sink.0
        );
    }
    Ok(())
}
