//! The memory a request may use, and what a refinement is estimated to need, checked before
//! any work starts: a request over the budget is refused with one line (the estimate, the
//! budget and the deepest level that fits) instead of running for a while and aborting.
//!
//! The budget is `--max-memory` when given, else the smaller of the memory the kernel says is
//! available (`MemAvailable`) and the headroom under the address-space limit (`ulimit -v`).
//! In batch mode it is shared by the files processed at once.

use subd_mesh::memory::human_bytes;
use subd_schemes::LevelCounts;

use crate::Failure;
use crate::failure::bad;

/// What a request may use, and where the number comes from.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Budget {
    pub(crate) bytes: u64,
    pub(crate) source: &'static str,
}

impl Budget {
    /// `--max-memory` if given, else what the machine and the process limits allow (`None`
    /// where neither can be read: no check).
    pub(crate) fn detect(max_memory: Option<u64>) -> Option<Budget> {
        if let Some(bytes) = max_memory {
            return Some(Budget {
                bytes,
                source: "--max-memory",
            });
        }
        let available = mem_available().map(|bytes| Budget {
            bytes,
            source: "available memory",
        });
        let address_space = address_space_headroom().map(|bytes| Budget {
            bytes,
            source: "the address-space limit, ulimit -v",
        });
        match (available, address_space) {
            (Some(a), Some(b)) => Some(if b.bytes < a.bytes { b } else { a }),
            (a, b) => a.or(b),
        }
    }

    /// The share of one of `jobs` files processed at once.
    pub(crate) fn share(self, jobs: usize) -> Budget {
        Budget {
            bytes: self.bytes / jobs.max(1) as u64,
            source: self.source,
        }
    }
}

/// `MemAvailable` of `/proc/meminfo`, in bytes.
fn mem_available() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// The soft address-space limit less the address space in use (`None` when unlimited).
fn address_space_headroom() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    let soft: u64 = line
        .trim_start_matches("Max address space")
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let used_kib: u64 = status
        .lines()
        .find(|l| l.starts_with("VmSize:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()?;
    Some(soft.saturating_sub(used_kib * 1024))
}

/// The process's peak resident memory (`VmHWM` of `/proc/self/status`), in bytes.
pub(crate) fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// A size such as `800M`, `4G`, `1.5GiB` or a plain number of bytes (units are binary:
/// K = 1024).
pub(crate) fn parse_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let value: f64 = number
        .parse()
        .map_err(|_| format!("{s:?}: expected a size such as 800M or 4G"))?;
    let unit = unit.trim().to_ascii_uppercase();
    let scale: u64 = match unit.trim_end_matches("IB").trim_end_matches('B') {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        "T" => 1 << 40,
        _ => return Err(format!("{s:?}: unknown unit (use K, M, G or T)")),
    };
    let bytes = value * scale as f64;
    if !bytes.is_finite() || bytes < 1.0 || bytes > u64::MAX as f64 {
        return Err(format!("{s:?}: expected a size of at least one byte"));
    }
    Ok(bytes as u64)
}

/// Refuses a refinement whose estimated peak is over `budget`: one line with the estimate,
/// the budget and the deepest level that fits.
pub(crate) fn check_refinement(
    input: &std::path::Path,
    counts: &[LevelCounts],
    estimate: impl Fn(LevelCounts) -> u64,
    budget: Option<Budget>,
) -> Result<(), Failure> {
    let Some(budget) = budget else {
        return Ok(());
    };
    let levels = counts.len() - 1;
    let need = estimate(counts[levels]);
    if need <= budget.bytes {
        return Ok(());
    }
    let fits = (0..levels)
        .rev()
        .find(|&l| estimate(counts[l]) <= budget.bytes);
    let advice = match fits {
        Some(l) => format!("--levels {l} fits"),
        None => "not even the input fits".to_string(),
    };
    Err(bad(format!(
        "{}: refining {levels} levels needs about {}, over the budget of {} ({}); {advice}",
        input.display(),
        human_bytes(need),
        human_bytes(budget.bytes),
        budget.source,
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_in_binary_units() {
        assert_eq!(parse_size("4096"), Ok(4096));
        assert_eq!(parse_size("800M"), Ok(800 << 20));
        assert_eq!(parse_size("1.5GiB"), Ok(3 << 29));
        assert_eq!(parse_size("2 gb"), Ok(2 << 30));
        assert!(parse_size("12 parsecs").is_err());
        assert!(parse_size("0").is_err());
        assert!(parse_size("-3G").is_err());
    }

    #[test]
    fn the_deepest_fitting_level_is_named() {
        let c = |v: u64| LevelCounts {
            vertices: v,
            edges: 2 * v,
            faces: v,
            face_vertices: 4 * v,
        };
        let counts = [c(10), c(40), c(160), c(640)];
        let budget = Some(Budget {
            bytes: 200,
            source: "--max-memory",
        });
        let e = check_refinement(
            std::path::Path::new("m.obj"),
            &counts,
            |l| l.vertices,
            budget,
        )
        .unwrap_err();
        assert_eq!(
            e.message,
            "m.obj: refining 3 levels needs about 640 B, over the budget of 200 B (--max-memory); --levels 2 fits"
        );
        assert!(
            check_refinement(
                std::path::Path::new("m.obj"),
                &counts[..3],
                |l| l.vertices,
                budget
            )
            .is_ok()
        );
    }
}
