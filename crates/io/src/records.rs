//! Output records encoded in parallel and written in order.

use std::io::Write;
use std::ops::Range;

use rayon::prelude::*;

/// Records per parallel task: a task's bytes (1.1 MB and up for every record kind written)
/// exceed the 1 MiB buffer of [`crate::atomic_write`], so they go to the file without a copy.
const RECORDS_PER_TASK: usize = 1 << 16;
/// Tasks per thread encoded before their bytes are written: bounds the memory held at once
/// (a window of streamed points or faces and its text) while giving every thread work.
const TASKS_PER_THREAD: usize = 4;
/// Tasks per window at the least.
const MIN_TASKS_PER_WINDOW: usize = 8;

/// Records per window: a few tasks for every thread of the pool.
pub(crate) fn window() -> usize {
    RECORDS_PER_TASK * (TASKS_PER_THREAD * rayon::current_num_threads()).max(MIN_TASKS_PER_WINDOW)
}

/// Writes records `0..count`, where `record(i, buf)` appends the bytes of record `i` to
/// `buf`. Records are encoded by all threads, a window of tasks at a time, and written in
/// index order, so the output is the same as a serial loop's.
pub(crate) fn write_records(
    w: &mut dyn Write,
    count: usize,
    record: impl Fn(usize, &mut Vec<u8>) + Sync,
) -> std::io::Result<()> {
    write_windows(w, count, |_| Ok(()), |_, i, b| record(i, b))
}

/// [`write_records`] with data made per window: `load(range)` gives what the records of
/// `range` read (a window of streamed points or faces), and `record(data, i, buf)` encodes
/// record `i` from it. The next window is loaded and encoded by the pool while this thread
/// writes the last one, so the disk is kept busy; two windows are held at a time, and their
/// buffers are reused (fresh pages cost the kernel as much as writing them).
pub(crate) fn write_windows<D: Sync>(
    w: &mut dyn Write,
    count: usize,
    mut load: impl FnMut(Range<usize>) -> std::io::Result<D> + Send,
    record: impl Fn(&D, usize, &mut Vec<u8>) + Sync,
) -> std::io::Result<()> {
    let window = window();
    // The window being written, and the buffers the next one is encoded into.
    let (mut written, mut spare): (Vec<Vec<u8>>, Vec<Vec<u8>>) = (Vec::new(), Vec::new());
    let mut start = 0;
    while start < count {
        let range = start..(start + window).min(count);
        start = range.end;
        let mut loaded = Ok(());
        let wrote = rayon::in_place_scope(|s| {
            let (load, record, spare, loaded) = (&mut load, &record, &mut spare, &mut loaded);
            s.spawn(move |_| {
                *loaded = load(range.clone()).map(|d| encode(&d, range, record, spare));
            });
            write_blocks(w, &written)
        });
        wrote?;
        loaded?;
        std::mem::swap(&mut written, &mut spare);
    }
    write_blocks(w, &written)
}

/// Encodes records `range` from `data` by all threads into `bufs`, a task's bytes per
/// buffer (as many buffers as tasks are kept; their memory is reused).
fn encode<D: Sync>(
    data: &D,
    range: Range<usize>,
    record: &(impl Fn(&D, usize, &mut Vec<u8>) + Sync),
    bufs: &mut Vec<Vec<u8>>,
) {
    bufs.resize_with(range.len().div_ceil(RECORDS_PER_TASK), Vec::new);
    bufs.par_iter_mut().enumerate().for_each(|(task, buf)| {
        buf.clear();
        let first = range.start + task * RECORDS_PER_TASK;
        for i in first..(first + RECORDS_PER_TASK).min(range.end) {
            record(data, i, buf);
        }
    });
}

/// Writes buffers in order.
fn write_blocks(w: &mut dyn Write, blocks: &[Vec<u8>]) -> std::io::Result<()> {
    for b in blocks {
        w.write_all(b)?;
    }
    Ok(())
}

/// Calls `visit(data, i)` for `0..count` in order, serially, a window at a time, with data
/// made per window as in [`write_windows`].
pub(crate) fn for_each_windowed<D>(
    count: usize,
    mut load: impl FnMut(Range<usize>) -> std::io::Result<D>,
    mut visit: impl FnMut(&D, usize),
) -> std::io::Result<()> {
    let (window, mut start) = (window(), 0);
    while start < count {
        let end = (start + window).min(count);
        let data = load(start..end)?;
        for i in start..end {
            visit(&data, i);
        }
        start = end;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_come_out_in_order_across_windows() {
        let count = window() * 2 + 17;
        let mut out = Vec::new();
        write_records(&mut out, count, |i, b| {
            let _ = writeln!(b, "{i}");
        })
        .unwrap();
        let expected: String = (0..count).map(|i| format!("{i}\n")).collect();
        assert_eq!(String::from_utf8(out).unwrap(), expected);
    }
}
