//! [`PeakModel`]: the peak memory of refining to a level and writing it, estimated from the
//! output level's counts ([`crate::refined_counts`]) before any work starts, so that a
//! request over a budget can be refused instead of aborting.

use crate::{LevelCounts, Scheme};

/// How a refinement's peak memory scales: bytes per vertex of the output level, with every
/// level above it, the output arrays and the encoder's buffers. Measured with
/// `/usr/bin/time -f %M` on the 101,600-quad bench torus and its triangulation, levels 1–4
/// (BENCHMARKS.md, "Memory estimates"; the numbers per scheme are
/// [`Scheme::peak_bytes_per_vertex`]), rounded up by a sixth or more.
#[derive(Debug, Clone, Copy)]
pub struct PeakModel {
    /// Bytes per output vertex.
    per_vertex: u64,
    /// Bytes per output vertex when the output level is streamed to the file from the level
    /// above (OpenSubdiv's schemes without `--limit`): the level above's topology, its
    /// points and the output level's face points.
    streamed_per_vertex: Option<u64>,
    /// Bytes per output vertex that `--limit` adds (the output level's limit stencils).
    limit_per_vertex: u64,
}

/// Process, binary and allocator overhead.
const FIXED_BYTES: u64 = 24 << 20;
/// The input file and what parsing it holds at once (its bytes, tokens, the base topology).
const PER_INPUT_BYTE: u64 = 4;
/// A `.glb` writer's f32 position, normal and index arrays, per output vertex.
const GLB_PER_VERTEX: u64 = 24;
/// A streamed `.glb`'s positions and vertex normals, held whole (the normals sum every
/// face around a vertex), per output vertex.
const STREAMED_GLB_PER_VERTEX: u64 = 50;

/// Bytes a depth-first chunk holds per face of the last level it makes: the piece's levels
/// (its one-ring included), the last level's points and uniform indices, the encoded
/// records. Measured with `/usr/bin/time -f %M` (BENCHMARKS.md, "Depth-first"), rounded up.
const DEPTH_FIRST_PER_CHUNK_FACE: u64 = 400;
/// The fewest and most last-level faces a depth-first chunk is sized for: fewer makes the
/// pieces' one-rings most of the work, more gains nothing.
const DEPTH_FIRST_CHUNK_FACES: (u64, u64) = (1 << 14, 1 << 18);

/// A depth-first refinement's memory ([`crate::DepthFirst`]): `threads` chunks held at once,
/// whatever the level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DepthFirstPeak {
    /// Last-level faces per chunk.
    pub faces_per_chunk: u64,
    /// The estimated peak, in bytes.
    pub bytes: u64,
}

impl DepthFirstPeak {
    /// The largest chunks (within bounds) whose peak fits `budget` bytes with `threads`
    /// chunks at once, from a file of `file_bytes`; the smallest chunks where none fit.
    pub fn fitting(budget: u64, file_bytes: u64, threads: usize) -> DepthFirstPeak {
        let fixed = FIXED_BYTES.saturating_add(PER_INPUT_BYTE.saturating_mul(file_bytes));
        let per_chunk = DEPTH_FIRST_PER_CHUNK_FACE.saturating_mul(threads.max(1) as u64);
        let (least, most) = DEPTH_FIRST_CHUNK_FACES;
        let faces_per_chunk = (budget.saturating_sub(fixed) / per_chunk).clamp(least, most);
        DepthFirstPeak {
            faces_per_chunk,
            bytes: fixed.saturating_add(per_chunk.saturating_mul(faces_per_chunk)),
        }
    }
}

impl PeakModel {
    /// The measured bytes per output vertex of `scheme` (the two-phase scheme is
    /// Catmull-Clark's after level 1; the split schemes hold every level and stream
    /// nothing).
    pub fn of(scheme: &Scheme) -> PeakModel {
        let (per_vertex, streamed) = scheme.peak_bytes_per_vertex();
        PeakModel {
            per_vertex,
            streamed_per_vertex: streamed,
            limit_per_vertex: if streamed.is_some() { 1150 } else { 2800 },
        }
    }

    /// The estimated peak of refining to the level of `last` from a file of `file_bytes`,
    /// writing `.glb` or not, with `--limit` or not.
    pub fn peak(self, file_bytes: u64, last: LevelCounts, glb: bool, limit: bool) -> u64 {
        let per_vertex = match self.streamed_per_vertex {
            Some(s) if !limit => s + if glb { STREAMED_GLB_PER_VERTEX } else { 0 },
            _ => {
                self.per_vertex
                    + if glb { GLB_PER_VERTEX } else { 0 }
                    + if limit { self.limit_per_vertex } else { 0 }
            }
        };
        FIXED_BYTES
            .saturating_add(PER_INPUT_BYTE.saturating_mul(file_bytes))
            .saturating_add(per_vertex.saturating_mul(last.vertices))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The estimate is affine in the output vertices and the file size, and each option
    /// adds what it holds.
    /// A depth-first chunk is sized to the budget, within bounds, and the estimate does not
    /// grow with the level.
    #[test]
    fn depth_first_chunks_fit_the_budget() {
        let roomy = DepthFirstPeak::fitting(64 << 30, 0, 2);
        assert_eq!(roomy.faces_per_chunk, DEPTH_FIRST_CHUNK_FACES.1);
        let tight = DepthFirstPeak::fitting(FIXED_BYTES + 2 * 400 * 50_000, 0, 2);
        assert_eq!(tight.faces_per_chunk, 50_000);
        assert_eq!(tight.bytes, FIXED_BYTES + 2 * 400 * 50_000);
        let none = DepthFirstPeak::fitting(1 << 20, 0, 16);
        assert_eq!(none.faces_per_chunk, DEPTH_FIRST_CHUNK_FACES.0);
        assert!(none.bytes > 1 << 20);
    }

    #[test]
    fn the_estimate_adds_what_each_output_holds() {
        let last = |vertices| LevelCounts {
            vertices,
            edges: 0,
            faces: 0,
            face_vertices: 0,
        };
        let cc = PeakModel::of(&Scheme::CatmullClark);
        let base = cc.peak(0, last(0), false, false);
        assert_eq!(base, FIXED_BYTES);
        assert_eq!(cc.peak(1000, last(0), false, false), FIXED_BYTES + 4000);
        // Streamed Catmull-Clark: 70 bytes a vertex; `--limit` holds the level and its
        // limit stencils instead.
        assert_eq!(cc.peak(0, last(100), false, false), FIXED_BYTES + 7000);
        assert_eq!(
            cc.peak(0, last(100), false, true),
            FIXED_BYTES + 100 * (105 + 1150)
        );
        let sqrt3 = PeakModel::of(&Scheme::Sqrt3);
        assert_eq!(
            sqrt3.peak(0, last(10), true, false),
            FIXED_BYTES + 10 * (235 + 24)
        );
    }
}
