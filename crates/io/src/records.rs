//! Output records encoded in parallel and written in order.

use std::io::Write;

use rayon::prelude::*;

/// Records per parallel task.
const RECORDS_PER_TASK: usize = 1 << 14;
/// Tasks encoded before their bytes are written: bounds the memory held at once (a few
/// megabytes of text) while giving every thread work.
const TASKS_PER_WINDOW: usize = 32;

/// Writes records `0..count`, where `record(i, buf)` appends the bytes of record `i` to
/// `buf`. Records are encoded by all threads, a window of tasks at a time, and written in
/// index order, so the output is the same as a serial loop's.
pub(crate) fn write_records(
    w: &mut dyn Write,
    count: usize,
    record: impl Fn(usize, &mut Vec<u8>) + Sync,
) -> std::io::Result<()> {
    let window = RECORDS_PER_TASK * TASKS_PER_WINDOW;
    let mut start = 0;
    while start < count {
        let end = (start + window).min(count);
        let chunks: Vec<Vec<u8>> = (start..end)
            .step_by(RECORDS_PER_TASK)
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|first| {
                let mut buf = Vec::with_capacity(RECORDS_PER_TASK * 48);
                for i in first..(first + RECORDS_PER_TASK).min(end) {
                    record(i, &mut buf);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_come_out_in_order_across_windows() {
        let count = RECORDS_PER_TASK * TASKS_PER_WINDOW * 2 + 17;
        let mut out = Vec::new();
        write_records(&mut out, count, |i, b| {
            let _ = writeln!(b, "{i}");
        })
        .unwrap();
        let expected: String = (0..count).map(|i| format!("{i}\n")).collect();
        assert_eq!(String::from_utf8(out).unwrap(), expected);
    }
}
