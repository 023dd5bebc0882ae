//! [`PatchMap`]: from a place on a root face (ptex face, u, v) to the patch that covers it
//! (OpenSubdiv's `Far::PatchMap`): one quadtree per root face, a patch at depth `d` a leaf
//! `d − root depth` steps down.
//!
//! Quads split into the four quadrants of their domain. Triangles split into three corner
//! triangles and the middle one, which is turned half a turn: a point of the middle child
//! is `(1 − 2u, 1 − 2v)` in the child's own coordinates, so every node is read the same way.

use super::param::PatchParam;

/// A child slot, packed in 32 bits so that a node is 16 bytes: [`EMPTY`], a patch (its
/// global index), or with [`NODE`] set a deeper node. A root face covered by one patch holds
/// it directly, so the common lookup touches one word.
type Slot = u32;
const EMPTY: Slot = u32::MAX;
const NODE: Slot = 1 << 31;

/// Quadtrees over the root faces.
#[derive(Debug, Clone)]
pub struct PatchMap {
    triangles: bool,
    /// Slot of each root face: one patch, a node, or empty (holes).
    roots: Vec<Slot>,
    nodes: Vec<[Slot; 4]>,
}

/// Which child of a triangle holds local `(u, v)`, and the point in the child's coordinates.
fn triangle_child(u: f64, v: f64) -> (usize, f64, f64) {
    if u >= 0.5 {
        (1, 2.0 * u - 1.0, 2.0 * v)
    } else if v >= 0.5 {
        (2, 2.0 * u, 2.0 * v - 1.0)
    } else if u + v >= 0.5 {
        (3, 1.0 - 2.0 * u, 1.0 - 2.0 * v)
    } else {
        (0, 2.0 * u, 2.0 * v)
    }
}

/// Which quadrant of a quad holds local `(u, v)`, and the point in the quadrant's coordinates.
fn quad_child(u: f64, v: f64) -> (usize, f64, f64) {
    let (hu, hv) = (u >= 0.5, v >= 0.5);
    let q = usize::from(hu) | (usize::from(hv) << 1);
    (
        q,
        if hu { 2.0 * u - 1.0 } else { 2.0 * u },
        if hv { 2.0 * v - 1.0 } else { 2.0 * v },
    )
}

impl PatchMap {
    /// The map of patches with parameters `params` (global order) over `num_roots` root
    /// faces.
    pub(crate) fn new(
        params: impl Iterator<Item = PatchParam>,
        num_roots: usize,
        triangles: bool,
    ) -> PatchMap {
        let mut map = PatchMap {
            triangles,
            roots: vec![u32::MAX; num_roots],
            nodes: Vec::new(),
        };
        for (index, param) in params.enumerate() {
            map.insert(index as u32, param);
        }
        map
    }

    fn new_node(&mut self) -> Slot {
        self.nodes.push([EMPTY; 4]);
        NODE | (self.nodes.len() - 1) as u32
    }

    /// Inserts patch `index`: a leaf at its depth below its root, reached through the
    /// children that hold the patch's centre.
    fn insert(&mut self, index: u32, param: PatchParam) {
        let place = param.place();
        let root = place.face as usize;
        let steps = usize::from(place.depth) - usize::from(place.non_quad);
        if steps == 0 {
            self.roots[root] = index;
            return;
        }
        if self.roots[root] == EMPTY {
            self.roots[root] = self.new_node();
        }
        let mut node = (self.roots[root] & !NODE) as usize;
        // A point inside the patch, in the root's coordinates.
        let (mut u, mut v) = if self.triangles {
            param.unnormalize_triangle(0.25, 0.25)
        } else {
            param.unnormalize(0.5, 0.5)
        };
        for step in 0..steps {
            let (k, cu, cv) = if self.triangles {
                triangle_child(u, v)
            } else {
                quad_child(u, v)
            };
            (u, v) = (cu, cv);
            if step + 1 == steps {
                self.nodes[node][k] = index;
            } else {
                if self.nodes[node][k] == EMPTY {
                    let n = self.new_node();
                    self.nodes[node][k] = n;
                }
                node = (self.nodes[node][k] & !NODE) as usize;
            }
        }
    }

    /// The patch (global index) at `(u, v)` of root face `root`, or `None` where no patch
    /// lies (a hole, a root out of range).
    pub fn find(&self, root: usize, u: f64, v: f64) -> Option<usize> {
        let mut slot = *self.roots.get(root)?;
        let (mut u, mut v) = (u, v);
        loop {
            match slot {
                EMPTY => return None,
                s if s & NODE == 0 => return Some(s as usize),
                s => {
                    let (k, cu, cv) = if self.triangles {
                        triangle_child(u, v)
                    } else {
                        quad_child(u, v)
                    };
                    slot = self.nodes[(s & !NODE) as usize][k];
                    (u, v) = (cu, cv);
                }
            }
        }
    }
}
