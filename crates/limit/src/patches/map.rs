//! [`PatchMap`]: from a place on a root face (ptex face, u, v) to the patch that covers it
//! (OpenSubdiv's `Far::PatchMap`): one quadtree per root face, a patch at depth `d` a leaf
//! `d − root depth` steps down.
//!
//! Quads split into the four quadrants of their domain. Triangles split into three corner
//! triangles and the middle one, which is turned half a turn: a point of the middle child
//! is `(1 − 2u, 1 − 2v)` in the child's own coordinates, so every node is read the same way.

use super::param::PatchParam;

/// A child slot of a node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Slot {
    Empty,
    /// A patch (its global index) covers the slot.
    Patch(u32),
    /// A deeper node.
    Node(u32),
}

/// Quadtrees over the root faces.
#[derive(Debug, Clone)]
pub struct PatchMap {
    triangles: bool,
    /// Node of each root face (`u32::MAX` where no patch lies on it: holes).
    roots: Vec<u32>,
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

    fn new_node(&mut self) -> u32 {
        self.nodes.push([Slot::Empty; 4]);
        (self.nodes.len() - 1) as u32
    }

    /// Inserts patch `index`: a leaf at its depth below its root, reached through the
    /// children that hold the patch's centre.
    fn insert(&mut self, index: u32, param: PatchParam) {
        let place = param.place();
        let root = place.face as usize;
        if self.roots[root] == u32::MAX {
            self.roots[root] = self.new_node();
        }
        let mut node = self.roots[root];
        let steps = usize::from(place.depth) - usize::from(place.non_quad);
        if steps == 0 {
            self.nodes[node as usize] = [Slot::Patch(index); 4];
            return;
        }
        // A point inside the patch, in the root's coordinates.
        let (mut u, mut v) = if self.triangles {
            let (s, t) = param.unnormalize_triangle(0.25, 0.25);
            (s, t)
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
            let slots = &mut self.nodes[node as usize];
            if step + 1 == steps {
                slots[k] = Slot::Patch(index);
            } else {
                node = match slots[k] {
                    Slot::Node(n) => n,
                    _ => {
                        let n = self.new_node();
                        self.nodes[node as usize][k] = Slot::Node(n);
                        n
                    }
                };
            }
        }
    }

    /// The patch (global index) at `(u, v)` of root face `root`, or `None` where no patch
    /// lies (a hole, a root out of range).
    pub fn find(&self, root: usize, u: f64, v: f64) -> Option<usize> {
        let mut node = *self.roots.get(root)?;
        if node == u32::MAX {
            return None;
        }
        let (mut u, mut v) = (u, v);
        loop {
            let (k, cu, cv) = if self.triangles {
                triangle_child(u, v)
            } else {
                quad_child(u, v)
            };
            match self.nodes[node as usize][k] {
                Slot::Empty => return None,
                Slot::Patch(p) => return Some(p as usize),
                Slot::Node(n) => {
                    node = n;
                    (u, v) = (cu, cv);
                }
            }
        }
    }
}
