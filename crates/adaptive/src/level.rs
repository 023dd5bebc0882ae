//! One level of the adaptive hierarchy: the faces of uniform level `l` that exist (the
//! children of the refined faces of level `l − 1`), as a topology of their own with the
//! uniform level's tags, rules and exact positions, and every element's uniform index.
//!
//! **Why the positions are exact.** A child of a refined face `f` reads, through its mask,
//! only the faces around `f`'s vertices. The restricted hierarchy guarantees that every face
//! around a refined face's vertices exists at its level (see [`crate::hierarchy`]), so the
//! piece that is refined — every face sharing a vertex with a refined face — gives the
//! children of the refined faces from complete rings, kept in the uniform level's order
//! ([`subd_mesh::cut`]): the same operations as uniform refinement, bit for bit.

use glam::DVec3;
use subd_mesh::Topology;
use subd_schemes::{Options, Refinement, Rule, Scheme};

use crate::AdaptiveError;
use subd_mesh::cut::{self as submesh, NONE};
use subd_schemes::ChildLayout;

/// Where a vertex of a level comes from in the level above.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Origin {
    /// A base vertex.
    Base,
    /// The child of vertex `0` of the level above.
    Vertex(u32),
    /// The child (face point) of face `0` of the level above.
    Face(u32),
    /// The child (edge point) of edge `0` of the level above.
    Edge(u32),
}

/// The parameter domain of a face: its base face, the sub-face of a Catmull-Clark base face
/// that is not a quad (OpenSubdiv's ptex convention), and `(u, v)` at each corner.
pub(crate) const WHOLE_FACE: u16 = u16::MAX;

/// One level of the hierarchy.
#[derive(Debug)]
pub(crate) struct SparseLevel {
    pub topology: Topology,
    pub rules: Vec<Rule>,
    pub points: Vec<DVec3>,
    /// Uniform index of every face, edge and vertex at this level.
    pub face_key: Vec<u64>,
    pub edge_key: Vec<u64>,
    pub vertex_key: Vec<u64>,
    /// Faces around every edge and vertex in the uniform level (to tell complete rings).
    pub edge_full: Vec<u32>,
    pub vertex_full: Vec<u32>,
    pub vertex_origin: Vec<Origin>,
    /// Face of the level above each face is a child of (`NONE` at level 0).
    pub face_parent: Vec<u32>,
    pub base_face: Vec<u32>,
    pub sub_face: Vec<u16>,
    /// `(u, v)` of every face-vertex (NaN for a whole non-quad base face).
    pub corner_params: Vec<[f64; 2]>,
    /// Faces refined at this level.
    pub refined: Vec<bool>,
    /// Index in the next level of each vertex's and edge's child, where it exists.
    pub vertex_child: Vec<u32>,
    pub edge_child: Vec<u32>,
}

impl SparseLevel {
    /// The whole base level, prepared (boundary rules applied to its tags, vertex rules
    /// determined) as uniform refinement prepares it.
    pub(crate) fn base(
        base: &Topology,
        points: &[DVec3],
        scheme: &Scheme,
        options: &Options,
    ) -> Result<SparseLevel, AdaptiveError> {
        if points.len() != base.num_vertices() {
            return Err(AdaptiveError::PointCount {
                given: points.len(),
                vertices: base.num_vertices(),
            });
        }
        let r = Refinement::new(base, scheme.clone(), options, 0)?;
        let rules = r.vertex_rules(0).to_vec();
        let topology = r.into_topology(0);
        let (nv, ne, nf) = (
            topology.num_vertices(),
            topology.num_edges(),
            topology.num_faces(),
        );
        let mut corner_params = Vec::with_capacity(topology.num_face_vertices());
        for f in 0..nf {
            match (scheme, topology.face_size(f)) {
                (Scheme::Loop, _) => corner_params.extend([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
                (_, 4) => {
                    corner_params.extend([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
                }
                (_, n) => corner_params.extend(std::iter::repeat_n([f64::NAN; 2], n)),
            }
        }
        let sub_face = (0..nf)
            .map(|f| {
                if *scheme == Scheme::Loop || topology.face_size(f) == 4 {
                    0
                } else {
                    WHOLE_FACE
                }
            })
            .collect();
        Ok(SparseLevel {
            rules,
            points: points.to_vec(),
            face_key: (0..nf as u64).collect(),
            edge_key: (0..ne as u64).collect(),
            vertex_key: (0..nv as u64).collect(),
            edge_full: (0..ne)
                .map(|e| topology.edge_faces(e).len() as u32)
                .collect(),
            vertex_full: (0..nv)
                .map(|v| topology.vertex_faces(v).len() as u32)
                .collect(),
            vertex_origin: vec![Origin::Base; nv],
            face_parent: vec![NONE; nf],
            base_face: (0..nf as u32).collect(),
            sub_face,
            corner_params,
            refined: vec![false; nf],
            vertex_child: vec![NONE; nv],
            edge_child: vec![NONE; ne],
            topology,
        })
    }

    /// Number of faces.
    pub(crate) fn num_faces(&self) -> usize {
        self.topology.num_faces()
    }

    /// Whether every face around vertex `v` in the uniform level is present.
    pub(crate) fn is_complete(&self, v: usize) -> bool {
        self.topology.vertex_faces(v).len() as u32 == self.vertex_full[v]
    }

    /// The corner parameters of face `f`.
    pub(crate) fn params(&self, f: usize) -> &[[f64; 2]] {
        let o = self.topology.face_offsets();
        &self.corner_params[o[f] as usize..o[f + 1] as usize]
    }

    /// Vertex rules for a cut: the level's, except that a vertex missing faces becomes a
    /// corner. Its own children are never kept; the corner rule only spares the masks (and
    /// the limit classification) a ring that is not the vertex's.
    fn cut_rules(&self, cut: &submesh::SubMesh) -> Vec<Rule> {
        cut.vertices
            .iter()
            .zip(&cut.complete)
            .map(|(&v, &whole)| {
                if whole && self.is_complete(v as usize) {
                    self.rules[v as usize]
                } else {
                    Rule::Corner
                }
            })
            .collect()
    }

    /// Cuts `faces` out of this level with rules and positions, ready to refine.
    pub(crate) fn piece(&self, faces: &[u32]) -> (submesh::SubMesh, Vec<Rule>, Vec<DVec3>) {
        let cut = submesh::cut(&self.topology, faces);
        let rules = self.cut_rules(&cut);
        let points = cut
            .vertices
            .iter()
            .map(|&v| self.points[v as usize])
            .collect();
        (cut, rules, points)
    }

    /// The next level: the children of the refined faces of this one (`self.refined`), which
    /// is `level` of the hierarchy. Records where the children of this level's vertices and
    /// edges went.
    pub(crate) fn refine(
        &mut self,
        level: usize,
        scheme: &Scheme,
        options: &Options,
        uniform: &ChildLayout,
    ) -> Result<SparseLevel, AdaptiveError> {
        self.vertex_child.fill(NONE);
        self.edge_child.fill(NONE);
        let t = &self.topology;
        let nf = t.num_faces();
        // The piece: every face sharing a vertex with a refined face.
        let mut touched = vec![false; t.num_vertices()];
        for f in (0..nf).filter(|&f| self.refined[f]) {
            for &v in t.face_vertices(f) {
                touched[v as usize] = true;
            }
        }
        let piece_faces: Vec<u32> = (0..nf as u32)
            .filter(|&f| {
                t.face_vertices(f as usize)
                    .iter()
                    .any(|&v| touched[v as usize])
            })
            .collect();
        let (cut, rules, points) = self.piece(&piece_faces);
        let (pnv, pnf, pnh) = (
            cut.topology.num_vertices(),
            cut.topology.num_faces(),
            cut.topology.num_face_vertices(),
        );
        let piece_offsets = cut.topology.face_offsets().to_vec();
        let r = Refinement::from_prepared(cut.topology, rules, scheme.clone(), options, 1)?;
        let child_points = r.refine_points(&points).pop().expect("one level");
        let c = r.topology(1);
        let child_rules = r.vertex_rules(1);
        let loop_scheme = *scheme == Scheme::Loop;
        let edge_point_base = if loop_scheme { pnv } else { pnv + pnf };
        let half_base = if loop_scheme { 3 * pnf } else { pnh };

        // The kept child faces: children of refined faces, in parent order.
        let mut kept = Vec::new();
        let mut kept_parent = Vec::new();
        let mut kept_k = Vec::new();
        for (pi, &f) in piece_faces.iter().enumerate() {
            if !self.refined[f as usize] {
                continue;
            }
            let children = if loop_scheme {
                4 * pi..4 * pi + 4
            } else {
                piece_offsets[pi] as usize..piece_offsets[pi + 1] as usize
            };
            for (k, cf) in children.enumerate() {
                kept.push(cf as u32);
                kept_parent.push((pi as u32, f));
                kept_k.push(k);
            }
        }
        let next = submesh::cut(c, &kept);

        // Vertices: uniform index, ring size in the uniform level, origin.
        let nv = next.vertices.len();
        let mut vertex_key = Vec::with_capacity(nv);
        let mut vertex_full = Vec::with_capacity(nv);
        let mut vertex_origin = Vec::with_capacity(nv);
        for (i, &cv) in next.vertices.iter().enumerate() {
            let cv = cv as usize;
            if cv < pnv {
                let v = cut.vertices[cv];
                vertex_key.push(self.vertex_key[v as usize]);
                vertex_full.push(self.vertex_full[v as usize]);
                vertex_origin.push(Origin::Vertex(v));
                self.vertex_child[v as usize] = i as u32;
            } else if cv < edge_point_base {
                let f = piece_faces[cv - pnv];
                vertex_key.push(uniform.face_point(level - 1, self.face_key[f as usize]));
                vertex_full.push(self.topology.face_size(f as usize) as u32);
                vertex_origin.push(Origin::Face(f));
            } else {
                let e = cut.edges[cv - edge_point_base];
                vertex_key.push(uniform.edge_point(level - 1, self.edge_key[e as usize]));
                vertex_full.push(uniform.edge_point_faces(self.edge_full[e as usize]));
                vertex_origin.push(Origin::Edge(e));
                self.edge_child[e as usize] = i as u32;
            }
        }
        // Edges: interior edges of a piece face, or halves of a piece edge.
        let mut edge_key = Vec::with_capacity(next.edges.len());
        let mut edge_full = Vec::with_capacity(next.edges.len());
        for &ce in &next.edges {
            let ce = ce as usize;
            if ce < half_base {
                let (pi, j) = if loop_scheme {
                    (ce / 3, ce % 3)
                } else {
                    let pi = piece_offsets.partition_point(|&o| o as usize <= ce) - 1;
                    (pi, ce - piece_offsets[pi] as usize)
                };
                let f = piece_faces[pi] as usize;
                edge_key.push(uniform.interior_edge(level - 1, self.face_key[f], j));
                edge_full.push(2);
            } else {
                let h = ce - half_base;
                let e = cut.edges[h / 2] as usize;
                edge_key.push(uniform.half_edge(level - 1, self.edge_key[e], (h % 2) as u32));
                edge_full.push(self.edge_full[e]);
            }
        }
        // Faces: uniform index and parameter domain.
        let mut face_key = Vec::with_capacity(kept.len());
        let mut face_parent = Vec::with_capacity(kept.len());
        let mut base_face = Vec::with_capacity(kept.len());
        let mut sub_face = Vec::with_capacity(kept.len());
        let mut corner_params = Vec::with_capacity(4 * kept.len());
        for (&(_, f), &k) in kept_parent.iter().zip(&kept_k) {
            let f = f as usize;
            face_key.push(uniform.child_face(level - 1, self.face_key[f], k));
            face_parent.push(f as u32);
            base_face.push(self.base_face[f]);
            let d = self.params(f);
            if loop_scheme {
                sub_face.push(0);
                let m = |a: usize, b: usize| mid(d[a], d[b]);
                corner_params.extend(match k {
                    0 => [d[0], m(0, 1), m(2, 0)],
                    1 => [m(0, 1), d[1], m(1, 2)],
                    2 => [m(2, 0), m(1, 2), d[2]],
                    _ => [m(1, 2), m(2, 0), m(0, 1)],
                });
            } else if self.sub_face[f] == WHOLE_FACE {
                // Sub-face k of a base face that is not a quad: its own unit square.
                sub_face.push(k as u16);
                corner_params.extend([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
            } else {
                sub_face.push(self.sub_face[f]);
                let centre = [
                    0.25 * (d[0][0] + d[1][0] + d[2][0] + d[3][0]),
                    0.25 * (d[0][1] + d[1][1] + d[2][1] + d[3][1]),
                ];
                // Child k of a quad is (V_k, E_k, F, E_{k-1}) rotated to put V_k at corner k.
                let (prev, next_k) = ((k + 3) % 4, (k + 1) % 4);
                let around = [d[k], mid(d[k], d[next_k]), centre, mid(d[prev], d[k])];
                corner_params.extend((0..4).map(|i| around[(i + 4 - k) % 4]));
            }
        }
        let child = SparseLevel {
            rules: next
                .vertices
                .iter()
                .map(|&v| child_rules[v as usize])
                .collect(),
            points: next
                .vertices
                .iter()
                .map(|&v| child_points[v as usize])
                .collect(),
            face_key,
            edge_key,
            vertex_key,
            edge_full,
            vertex_full,
            vertex_origin,
            face_parent,
            base_face,
            sub_face,
            corner_params,
            refined: vec![false; kept.len()],
            vertex_child: vec![NONE; nv],
            edge_child: vec![NONE; next.edges.len()],
            topology: next.topology,
        };
        Ok(child)
    }
}

fn mid(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
}
