//! Many places evaluated at once ([`PatchTable::evaluate_first`]): in parallel, and past a
//! size face by face, so that one face's places read its patches while they are in cache.

use glam::DVec3;

use super::table::PatchTable;
use crate::LimitError;
use crate::evaluation::eval::FaceParam;

impl PatchTable {
    /// Positions and first derivatives at many places, in parallel (the first error, in
    /// the order of `at`, if any).
    ///
    /// # Errors
    /// As [`Self::find`].
    pub fn evaluate_first(&self, at: &[FaceParam]) -> Result<Vec<[DVec3; 3]>, LimitError> {
        let mut out = vec![[DVec3::ZERO; 3]; at.len()];
        self.evaluate_first_into(at, &mut out)?;
        Ok(out)
    }

    /// [`Self::evaluate_first`] into a buffer the caller keeps (no allocation per call).
    ///
    /// # Errors
    /// As [`Self::find`], for the first failing place in the order of `at`.
    ///
    /// # Panics
    /// If `out` is not as long as `at`.
    pub fn evaluate_first_into(
        &self,
        at: &[FaceParam],
        out: &mut [[DVec3; 3]],
    ) -> Result<(), LimitError> {
        use rayon::prelude::*;
        assert_eq!(at.len(), out.len(), "one output per place");
        if at.len() < FACE_ORDER_FROM {
            let failures: Vec<(usize, LimitError)> = at
                .par_iter()
                .zip(out.par_iter_mut())
                .enumerate()
                .with_min_len(4096)
                .filter_map(
                    |(i, (p, o))| match self.evaluate_first_on(self.own_points(), *p) {
                        Ok(v) => {
                            *o = v;
                            None
                        }
                        Err(e) => Some((i, e)),
                    },
                )
                .collect();
            return first_failure(failures);
        }
        // Many places are taken face by face, so that the places of one face read its
        // patches' control points while they are in cache; the values are put back in the
        // caller's order (the same values: each place's sums are unchanged).
        let (order, places) = face_order(at, self.base_topology().num_faces());
        let mut sorted = vec![[DVec3::ZERO; 3]; at.len()];
        let failures: Vec<(usize, LimitError)> = order
            .par_iter()
            .zip(&places)
            .zip(sorted.par_iter_mut())
            .with_min_len(4096)
            .filter_map(
                |((&i, p), o)| match self.evaluate_first_on(self.own_points(), *p) {
                    Ok(v) => {
                        *o = v;
                        None
                    }
                    Err(e) => Some((i as usize, e)),
                },
            )
            .collect();
        scatter(&order, &sorted, out);
        first_failure(failures)
    }
}

/// Places from which [`PatchTable::evaluate_first_into`] takes them face by face.
const FACE_ORDER_FROM: usize = 1 << 15;

/// The indices of `at` ordered by face (a counting sort; faces out of range last), and the
/// places in that order (read in order, written scattered: cheaper than the reverse). One
/// range of faces per thread, each thread reading every place and keeping its own.
fn face_order(at: &[FaceParam], faces: usize) -> (Vec<u32>, Vec<FaceParam>) {
    use rayon::prelude::*;
    let keys = faces + 1;
    let key = |p: &FaceParam| p.face.min(faces);
    let parts = rayon::current_num_threads().clamp(1, keys);
    let pieces: Vec<(Vec<u32>, Vec<FaceParam>)> = (0..parts)
        .into_par_iter()
        .map(|k| {
            let (lo, hi) = (k * keys / parts, (k + 1) * keys / parts);
            let mut start = vec![0u32; hi - lo + 1];
            for p in at.iter().filter(|p| (lo..hi).contains(&key(p))) {
                start[key(p) - lo + 1] += 1;
            }
            for f in 1..start.len() {
                start[f] += start[f - 1];
            }
            let n = start[hi - lo] as usize;
            let (mut order, mut places) = (vec![0u32; n], vec![at[0]; n]);
            for (i, p) in at.iter().enumerate() {
                if (lo..hi).contains(&key(p)) {
                    let slot = &mut start[key(p) - lo];
                    order[*slot as usize] = i as u32;
                    places[*slot as usize] = *p;
                    *slot += 1;
                }
            }
            (order, places)
        })
        .collect();
    let (mut order, mut places) = (Vec::with_capacity(at.len()), Vec::with_capacity(at.len()));
    for (o, p) in pieces {
        order.extend(o);
        places.extend(p);
    }
    (order, places)
}

/// `out[order[k]] = sorted[k]` for every `k`: one range of `out` per thread, each thread
/// reading every index and writing its own.
fn scatter(order: &[u32], sorted: &[[DVec3; 3]], out: &mut [[DVec3; 3]]) {
    use rayon::prelude::*;
    let chunk = out.len().div_ceil(rayon::current_num_threads()).max(1);
    out.par_chunks_mut(chunk).enumerate().for_each(|(k, part)| {
        let range = k * chunk..k * chunk + part.len();
        for (&i, v) in order.iter().zip(sorted) {
            if range.contains(&(i as usize)) {
                part[i as usize - range.start] = *v;
            }
        }
    });
}

/// The error of the first failing place (in the caller's order), if any.
fn first_failure(failures: Vec<(usize, LimitError)>) -> Result<(), LimitError> {
    match failures.into_iter().min_by_key(|(i, _)| *i) {
        Some((_, e)) => Err(e),
        None => Ok(()),
    }
}
