//! Output records encoded in parallel and written in order.

use std::io::Write;
use std::ops::Range;

use rayon::prelude::*;

/// Records per parallel task.
const RECORDS_PER_TASK: usize = 1 << 14;
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
/// record `i` from it. One window's data is held at a time.
pub(crate) fn write_windows<D: Sync>(
    w: &mut dyn Write,
    count: usize,
    mut load: impl FnMut(Range<usize>) -> std::io::Result<D>,
    record: impl Fn(&D, usize, &mut Vec<u8>) + Sync,
) -> std::io::Result<()> {
    let (window, mut start) = (window(), 0);
    while start < count {
        let end = (start + window).min(count);
        let data = load(start..end)?;
        let chunks: Vec<Vec<u8>> = (start..end)
            .step_by(RECORDS_PER_TASK)
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|first| {
                let mut buf = Vec::with_capacity(RECORDS_PER_TASK * 48);
                for i in first..(first + RECORDS_PER_TASK).min(end) {
                    record(&data, i, &mut buf);
                }
                buf
            })
            .collect();
        for c in &chunks {
            w.write_all(c)?;
        }
        start = end;
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
