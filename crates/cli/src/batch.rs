//! Batch mode: the mesh commands take `IN OUT`, or any number of inputs (files, or
//! directories searched recursively) with `--out-dir DIR`.
//!
//! Files run on `--jobs` worker threads (default: one per CPU). Each file's own parallel
//! work (stencil evaluation, PIA sweeps) goes to rayon's shared pool, so a few large meshes
//! still use every core once the small ones are done. A failed file prints its usual
//! one-line error and the others go on; the exit code is 2 if any failed.

use std::io::{IsTerminal, Write};
use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::Instant;

use clap::{Args, ValueEnum};
use serde::Serialize;

use crate::failure::bad;
use crate::{EXIT_BAD_INPUT, Failure};

/// Extensions of the mesh files a directory input contributes.
const MESH_EXTENSIONS: [&str; 8] = ["obj", "ply", "glb", "gltf", "usd", "usda", "usdc", "usdz"];

/// The input and output paths of a mesh command, single or batch.
#[derive(Debug, Clone, Args)]
pub(crate) struct Files {
    /// `IN OUT`; or, with --out-dir, any number of inputs: mesh files, or directories
    /// searched recursively for .obj, .ply, .glb, .gltf, .usd, .usda, .usdc and .usdz files.
    /// Each mesh prim of a USD stage with several is an input of its own.
    #[arg(required = true, value_name = "IN... [OUT]")]
    paths: Vec<PathBuf>,
    /// Batch mode: write one output per input into DIR (created if missing), named after
    /// the input's file stem.
    #[arg(long, value_name = "DIR")]
    out_dir: Option<PathBuf>,
    /// Batch mode: the outputs' format (default: the input's; .gltf inputs give .glb).
    #[arg(long, value_enum, requires = "out_dir")]
    format: Option<OutputFormat>,
    /// Batch mode: files processed at once (default: the number of CPUs).
    #[arg(long, requires = "out_dir")]
    jobs: Option<NonZeroUsize>,
}

/// An output format of batch mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum OutputFormat {
    Obj,
    Ply,
    Glb,
    Usda,
    Usdc,
    Usdz,
    /// Text, one line per vertex (`subd limit` only).
    Txt,
}

impl OutputFormat {
    /// The format an output path names by its extension (case-insensitive), if subd
    /// writes it.
    pub(crate) fn of(path: &Path) -> Option<OutputFormat> {
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("txt"))
        {
            return Some(OutputFormat::Txt);
        }
        match subd_io::Format::for_output(path)? {
            subd_io::Format::Obj => Some(OutputFormat::Obj),
            subd_io::Format::Ply => Some(OutputFormat::Ply),
            subd_io::Format::Glb => Some(OutputFormat::Glb),
            // `.usd` is written as binary, as USD writes it.
            subd_io::Format::Usda => Some(OutputFormat::Usda),
            subd_io::Format::Usdc => Some(OutputFormat::Usdc),
            subd_io::Format::Usdz => Some(OutputFormat::Usdz),
            subd_io::Format::Gltf => None,
        }
    }

    /// The file extension, without the dot.
    pub(crate) fn extension(self) -> &'static str {
        match self {
            OutputFormat::Obj => "obj",
            OutputFormat::Ply => "ply",
            OutputFormat::Glb => "glb",
            OutputFormat::Usda => "usda",
            OutputFormat::Usdc => "usdc",
            OutputFormat::Usdz => "usdz",
            OutputFormat::Txt => "txt",
        }
    }
}

/// One file's work: where to read, where to write, and whether the command may draw its
/// own progress display (not in batch mode, which draws one bar for all files).
pub(crate) struct Job {
    pub(crate) input: PathBuf,
    pub(crate) output: PathBuf,
    pub(crate) quiet: bool,
    /// Files processed at the same time as this one (they share the memory budget).
    pub(crate) concurrent: usize,
    /// The mesh prim to read, for a USD stage with several (batch mode: one job each).
    pub(crate) prim: Option<String>,
}

/// What batch mode needs to know about the command it drives.
pub(crate) struct Command {
    /// The subcommand's name, for messages.
    pub(crate) name: &'static str,
    /// The output formats the command writes.
    pub(crate) formats: &'static [OutputFormat],
}

/// Output formats of the commands that write meshes.
pub(crate) const MESH_OUTPUTS: &[OutputFormat] = &[
    OutputFormat::Obj,
    OutputFormat::Ply,
    OutputFormat::Glb,
    OutputFormat::Usda,
    OutputFormat::Usdc,
    OutputFormat::Usdz,
];

#[derive(Serialize)]
struct FileError<'a> {
    /// The input's place in the batch (batch mode only), so a report in completion order
    /// can be put back in input order.
    #[serde(skip_serializing_if = "Option::is_none")]
    index: Option<usize>,
    input: String,
    output: String,
    error: &'a str,
    code: i32,
}

#[derive(Serialize)]
struct Summary {
    command: &'static str,
    files: usize,
    succeeded: usize,
    failed: usize,
    seconds: f64,
}

#[derive(Serialize)]
struct SummaryLine {
    summary: Summary,
}

/// A command's JSON report lines with the input's place in the batch as their first field
/// (`{"index":3,...}`); lines that are not JSON objects pass unchanged.
fn with_index(report: &[u8], index: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(report.len() + 16);
    for line in report.split_inclusive(|&b| b == b'\n') {
        match line.strip_prefix(b"{") {
            Some(rest) if rest.first().is_some_and(|&b| b != b'}') => {
                out.extend_from_slice(format!("{{\"index\":{index},").as_bytes());
                out.extend_from_slice(rest);
            }
            Some(rest) => {
                out.extend_from_slice(format!("{{\"index\":{index}").as_bytes());
                out.extend_from_slice(rest);
            }
            None => out.extend_from_slice(line),
        }
    }
    out
}

/// What one file's run left behind, sent from a worker to the thread that owns the
/// output streams.
struct Outcome {
    index: usize,
    stdout: Vec<u8>,
    stderr: Vec<u8>,
    failure: Option<Failure>,
}

/// Runs `one` on the command's file(s): once with `IN OUT`, or on every input with
/// `--out-dir`. `json` is the command's `--json`: batch mode then prints one line per file
/// (the command's report, or the error, with the input's `index` in the batch first: lines
/// come in completion order) and a summary line last.
pub(crate) fn run<F>(
    files: &Files,
    command: &Command,
    json: bool,
    out: &mut dyn Write,
    err: &mut dyn Write,
    one: F,
) -> Result<(), Failure>
where
    F: Fn(&Job, &mut dyn Write, &mut dyn Write) -> Result<(), Failure> + Sync,
{
    let Some(dir) = &files.out_dir else {
        return run_single(files, command, out, err, &one);
    };
    let jobs = prepare(files, dir, command)?;
    let t0 = Instant::now();
    let bar = FilesBar::new(&jobs, json);
    let mut report = Report {
        jobs: &jobs,
        json,
        out,
        err,
        bar: &bar,
        failed: 0,
    };
    run_jobs(&jobs, &one, &bar, |outcome| report.outcome(outcome));
    bar.finish();
    let failed = report.failed;
    summarize(command, jobs.len(), failed, t0, json, out, err)
}

/// The single `IN OUT` form: one job, its stderr held until it ends (a refusal alone).
fn run_single<F>(
    files: &Files,
    command: &Command,
    out: &mut dyn Write,
    err: &mut dyn Write,
    one: &F,
) -> Result<(), Failure>
where
    F: Fn(&Job, &mut dyn Write, &mut dyn Write) -> Result<(), Failure> + Sync,
{
    let [input, output] = &files.paths[..] else {
        return Err(bad(format!(
            "{}: expected IN OUT, or inputs with --out-dir DIR ({} paths given)",
            command.name,
            files.paths.len()
        )));
    };
    let job = Job {
        input: input.clone(),
        output: output.clone(),
        quiet: false,
        concurrent: 1,
        prim: None,
    };
    crate::refusal_alone(err, |err| one(&job, out, err))
}

/// The jobs of a batch into `dir`, after the format check, each knowing how many run at
/// once; the directory created.
fn prepare(files: &Files, dir: &Path, command: &Command) -> Result<Vec<Job>, Failure> {
    if let Some(f) = files.format
        && !command.formats.contains(&f)
    {
        return Err(bad(format!(
            "--format {}: {} does not write it",
            f.extension(),
            command.name
        )));
    }
    let mut jobs = plan(files, dir, command)?;
    std::fs::create_dir_all(dir).map_err(|e| {
        bad(format!(
            "{}: cannot create the directory: {e}",
            dir.display()
        ))
    })?;
    let workers = files
        .jobs
        .map(NonZeroUsize::get)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, NonZeroUsize::get))
        .min(jobs.len());
    for job in &mut jobs {
        job.concurrent = workers;
    }
    Ok(jobs)
}

/// Runs the jobs on their workers, each job's streams captured, and hands each outcome to
/// `done` on this thread as it completes.
fn run_jobs<F>(jobs: &[Job], one: &F, bar: &FilesBar, mut done: impl FnMut(Outcome))
where
    F: Fn(&Job, &mut dyn Write, &mut dyn Write) -> Result<(), Failure> + Sync,
{
    let workers = jobs.first().map_or(1, |j| j.concurrent);
    let next = AtomicUsize::new(0);
    let (tx, rx) = mpsc::channel::<Outcome>();
    std::thread::scope(|scope| {
        for _ in 0..workers {
            let tx = tx.clone();
            let next = &next;
            scope.spawn(move || {
                loop {
                    let index = next.fetch_add(1, Ordering::Relaxed);
                    let Some(job) = jobs.get(index) else { break };
                    bar.started(job);
                    let (mut stdout, mut stderr) = (Vec::new(), Vec::new());
                    let failure = one(job, &mut stdout, &mut stderr).err();
                    let sent = tx.send(Outcome {
                        index,
                        stdout,
                        stderr,
                        failure,
                    });
                    if sent.is_err() {
                        break;
                    }
                }
            });
        }
        drop(tx);
        for outcome in rx {
            done(outcome);
        }
    });
}

/// Writes the batch's outcomes as they come: streams are written here only, a whole file
/// at a time, so lines never interleave.
struct Report<'a> {
    jobs: &'a [Job],
    json: bool,
    out: &'a mut dyn Write,
    err: &'a mut dyn Write,
    bar: &'a FilesBar,
    failed: usize,
}

impl Report<'_> {
    fn outcome(&mut self, outcome: Outcome) {
        let job = &self.jobs[outcome.index];
        let many = self.jobs.len() > 1;
        self.bar.finished(outcome.index);
        let err = &mut *self.err;
        self.bar.suspend(|| {
            // A refused input's stderr (its reading warnings) gives way to the refusal.
            if !matches!(&outcome.failure, Some(f) if f.code == EXIT_BAD_INPUT) {
                let _ = err.write_all(&outcome.stderr);
            }
            if let Some(f) = &outcome.failure {
                let _ = writeln!(err, "subd: {}", f.message);
            }
        });
        if self.json && many {
            let _ = self
                .out
                .write_all(&with_index(&outcome.stdout, outcome.index));
        } else {
            let _ = self.out.write_all(&outcome.stdout);
        }
        if let Some(f) = outcome.failure {
            self.failed += 1;
            if self.json {
                crate::print_json(
                    self.out,
                    &FileError {
                        index: many.then_some(outcome.index),
                        input: job.input.display().to_string(),
                        output: job.output.display().to_string(),
                        error: &f.message,
                        code: f.code,
                    },
                );
            }
        }
    }
}

/// The summary line (and JSON line); a failure if any file failed.
fn summarize(
    command: &Command,
    files: usize,
    failed: usize,
    t0: Instant,
    json: bool,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    let summary = Summary {
        command: command.name,
        files,
        succeeded: files - failed,
        failed,
        seconds: t0.elapsed().as_secs_f64(),
    };
    let line = format!(
        "{}: {} of {} files done, {} failed ({:.2} s)",
        command.name, summary.succeeded, summary.files, summary.failed, summary.seconds
    );
    if json {
        crate::print_json(out, &SummaryLine { summary });
    }
    if failed > 0 {
        return Err(Failure {
            code: EXIT_BAD_INPUT,
            message: line,
        });
    }
    let _ = writeln!(err, "subd: {line}");
    Ok(())
}

/// The inputs in order (directories expanded, sorted by path) with their outputs; refuses
/// two inputs that would write the same output before any work starts.
fn plan(files: &Files, dir: &Path, command: &Command) -> Result<Vec<Job>, Failure> {
    let mut inputs = Vec::new();
    for path in &files.paths {
        if path.is_dir() {
            let mut found = Vec::new();
            collect_meshes(path, &mut found).map_err(|e| {
                bad(format!(
                    "{}: cannot list the directory: {e}",
                    path.display()
                ))
            })?;
            found.sort();
            inputs.extend(found);
        } else {
            inputs.push(path.clone());
        }
    }
    if inputs.is_empty() {
        return Err(bad(format!("{}: no input meshes found", command.name)));
    }
    let mut jobs = Vec::with_capacity(inputs.len());
    let mut seen = std::collections::HashMap::new();
    for input in inputs {
        let extension = match files.format {
            Some(f) => f.extension(),
            None => default_extension(&input),
        };
        for (prim, name) in items(&input) {
            let output = dir.join(name).with_extension(extension);
            if let Some(first) = seen.insert(output.clone(), input.clone()) {
                return Err(bad(format!(
                    "{}: {} and {} would both write it (outputs are named after the input stem)",
                    output.display(),
                    first.display(),
                    input.display()
                )));
            }
            jobs.push(Job {
                input: input.clone(),
                output,
                quiet: true,
                concurrent: 1,
                prim,
            });
        }
    }
    Ok(jobs)
}

/// The items of one input, with the names of their outputs: the file itself, named after
/// its stem; or, for a USD stage with several mesh prims, each prim, named after the stem
/// and the prim's path (`scene_World_Body`). A stage that cannot be opened is one item,
/// which fails with the reader's message when it runs.
fn items(input: &Path) -> Vec<(Option<String>, std::ffi::OsString)> {
    let stem = input
        .file_stem()
        .unwrap_or(input.as_os_str())
        .to_os_string();
    let usd = subd_io::Format::from_path(input).is_some_and(subd_io::Format::is_usd);
    let prims = if usd {
        subd_io::usd::mesh_prims(input).unwrap_or_default()
    } else {
        Vec::new()
    };
    if prims.len() < 2 {
        return vec![(None, stem)];
    }
    prims
        .into_iter()
        .map(|p| {
            let mut name = stem.clone();
            for part in p.path.split('/').filter(|s| !s.is_empty()) {
                name.push("_");
                name.push(part);
            }
            (Some(p.path), name)
        })
        .collect()
}

/// The output extension of an input when `--format` is not given: its own, with .gltf
/// (not written) becoming .glb. An unknown extension is kept, and the file fails with the
/// command's usual message.
fn default_extension(input: &Path) -> &'static str {
    let ext = input
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("ply") => "ply",
        Some("glb" | "gltf") => "glb",
        Some("usda") => "usda",
        Some("usdc") => "usdc",
        Some("usdz") => "usdz",
        Some("usd") => "usd",
        _ => "obj",
    }
}

fn collect_meshes(dir: &Path, found: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_dir() {
            collect_meshes(&path, found)?;
        } else if path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| MESH_EXTENSIONS.iter().any(|m| e.eq_ignore_ascii_case(m)))
        {
            found.push(path);
        }
    }
    Ok(())
}

/// One progress bar over the batch's bytes, counting files and naming the file started
/// last; drawn only on a terminal and never with `--json`.
struct FilesBar {
    bar: Option<indicatif::ProgressBar>,
    /// Each file's size, read once (for the bar only).
    sizes: Vec<u64>,
    done: AtomicUsize,
    total: usize,
}

impl FilesBar {
    fn new(jobs: &[Job], json: bool) -> FilesBar {
        let total = jobs.len();
        if json || !std::io::stderr().is_terminal() {
            return FilesBar {
                bar: None,
                sizes: Vec::new(),
                done: AtomicUsize::new(0),
                total,
            };
        }
        let sizes: Vec<u64> = jobs
            .iter()
            .map(|j| std::fs::metadata(&j.input).map_or(0, |m| m.len()))
            .collect();
        let bar = indicatif::ProgressBar::new(sizes.iter().sum());
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "[{bar:30}] {binary_bytes}/{binary_total_bytes} {prefix} {wide_msg}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar.set_prefix(format!("0/{total} files"));
        bar.enable_steady_tick(std::time::Duration::from_millis(100));
        FilesBar {
            bar: Some(bar),
            sizes,
            done: AtomicUsize::new(0),
            total,
        }
    }

    fn started(&self, job: &Job) {
        if let Some(b) = &self.bar {
            b.set_message(job.input.display().to_string());
        }
    }

    /// Job `index` is done.
    fn finished(&self, index: usize) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        if let Some(b) = &self.bar {
            b.inc(self.sizes[index]);
            b.set_prefix(format!("{done}/{} files", self.total));
        }
    }

    /// Runs `f` with the bar hidden, so a line printed meanwhile is not drawn over.
    fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        match &self.bar {
            Some(b) => b.suspend(f),
            None => f(),
        }
    }

    fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::with_index;

    #[test]
    fn index_goes_first_in_every_report_line() {
        let report = b"{\"input\":\"a.obj\",\"levels\":2}\n{}\nnot json\n";
        let got = String::from_utf8(with_index(report, 7)).unwrap();
        assert_eq!(
            got,
            "{\"index\":7,\"input\":\"a.obj\",\"levels\":2}\n{\"index\":7}\nnot json\n"
        );
        for line in got.lines().take(2) {
            let v: serde_json::Value = serde_json::from_str(line).unwrap();
            assert_eq!(v["index"], 7);
        }
    }
}
