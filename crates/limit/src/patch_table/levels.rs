//! Feature-adaptive refinement: the sparse levels a patch table is built from, as
//! OpenSubdiv's `TopologyRefiner::RefineAdaptive` makes them.
//!
//! Level `l + 1` holds two kinds of faces (Vtr's sparse refinement):
//! * **owned** faces, every child of a face selected at level `l`; their vertices have
//!   every face of the uniform level around them, so their rings, rules and positions are
//!   those of uniform refinement, and only they can be patches or be selected in turn;
//! * **neighbour** faces, the child at a selected vertex (a vertex of a selected face) of each
//!   other face around it: the ring the owned faces' patches read.
//!
//! **How a level is made.** Every face of level `l` touching a selected vertex is cut out in
//! level order ([`subd_mesh::cut`]) and refined one uniform step; the kept children are cut
//! from that. The children of a selected vertex read only the faces around it, all in the
//! piece, and a selected face's edge and face points read only its own faces and the two
//! faces of each edge, so every vertex of an owned face is computed by the same operations
//! as uniform refinement, bit for bit (the piece's artificial boundary only spoils children
//! that belong to no owned face).

use subd_mesh::Topology;
use subd_mesh::cut::{self as submesh, NONE};
use subd_schemes::{Options, Refinement, Rule, Scheme, StencilTable};

use super::features::{self, ChildTagInput, Parent, Regularity, VTag};
use crate::LimitError;

/// One sparse level.
#[derive(Debug)]
pub(crate) struct PatchLevel {
    /// The level's faces (owned and neighbour), with the refinement's tags.
    pub topology: Topology,
    /// Vertex rules.
    pub rules: Vec<Rule>,
    /// Vertex tags (inherited as OpenSubdiv inherits them).
    pub tags: Vec<VTag>,
    /// Depth of the level.
    pub depth: usize,
    /// Faces around each vertex in the uniform level (to tell complete rings).
    pub vertex_full: Vec<u32>,
    /// The parent of each face was selected (every face of level 0): a child face tag that
    /// is not incomplete.
    pub parent_selected: Vec<bool>,
    /// Refined to the next level.
    pub selected: Vec<bool>,
    /// Face of the level above each face is a child of, and which child it is.
    pub face_parent: Vec<(u32, u8)>,
    /// Each vertex as weights of the level above's vertices (`None` at level 0).
    pub rows: Option<StencilTable>,
}

/// A level's faces around its selected vertices, refined one step ([`PatchLevel::piece`]).
pub(crate) struct Piece {
    pub sel: Selected,
    /// The level's faces in the piece, in level order.
    pub faces: Vec<u32>,
    pub cut: submesh::SubMesh,
    layout: PieceLayout,
    /// The piece refined one uniform step.
    pub refinement: Refinement,
    /// The children the next level keeps.
    pub kept: KeptChildren,
}

/// The vertices and edges of a level's selected faces.
pub(crate) struct Selected {
    pub vertices: Vec<bool>,
    pub edges: Vec<bool>,
}

impl PatchLevel {
    /// The base level, prepared (boundary rules applied, vertex rules determined) as
    /// uniform refinement prepares it.
    pub(crate) fn base(
        base: &Topology,
        scheme: &Scheme,
        options: &Options,
        reg: Regularity,
    ) -> Result<PatchLevel, LimitError> {
        let r = Refinement::new(base, scheme.clone(), options, 0)?;
        let rules = r.vertex_rules(0).to_vec();
        let topology = r.into_topology(0);
        let tags = features::base_tags(&topology, &rules, reg);
        let nf = topology.num_faces();
        let vertex_full = (0..topology.num_vertices())
            .map(|v| topology.vertex_faces(v).len() as u32)
            .collect();
        Ok(PatchLevel {
            rules,
            tags,
            depth: 0,
            vertex_full,
            parent_selected: vec![true; nf],
            selected: vec![false; nf],
            face_parent: vec![(NONE, 0); nf],
            rows: None,
            topology,
        })
    }

    /// Whether every face around vertex `v` in the uniform level is present.
    pub(crate) fn is_complete(&self, v: usize) -> bool {
        self.topology.vertex_faces(v).len() as u32 == self.vertex_full[v]
    }

    /// The vertices and edges of the selected faces.
    pub(crate) fn selected_parts(&self) -> Selected {
        let t = &self.topology;
        let mut out = Selected {
            vertices: vec![false; t.num_vertices()],
            edges: vec![false; t.num_edges()],
        };
        for f in (0..t.num_faces()).filter(|&f| self.selected[f]) {
            for (&v, &e) in t.face_vertices(f).iter().zip(t.face_edges(f)) {
                out.vertices[v as usize] = true;
                out.edges[e as usize] = true;
            }
        }
        out
    }

    /// Whether the faces of edge `e` are not all selected alike (OpenSubdiv's transitional
    /// edge: one side is refined, the other is not).
    pub(crate) fn is_transitional(&self, e: usize) -> bool {
        let faces = self.topology.edge_faces(e);
        faces.len() >= 2
            && faces
                .iter()
                .any(|&f| self.selected[f as usize] != self.selected[faces[0] as usize])
    }

    /// Faces touching a selected vertex, in face order.
    fn piece_faces(&self, sel: &Selected) -> Vec<u32> {
        let t = &self.topology;
        (0..t.num_faces() as u32)
            .filter(|&f| {
                t.face_vertices(f as usize)
                    .iter()
                    .any(|&v| sel.vertices[v as usize])
            })
            .collect()
    }

    /// Rules for the piece: the level's, except that a vertex missing faces becomes a
    /// corner (its children are never kept; the rule only spares the masks a ring that is
    /// not the vertex's).
    fn piece_rules(&self, cut: &submesh::SubMesh) -> Vec<Rule> {
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

    /// The faces of the level around its selected vertices, cut out and refined one
    /// uniform step, with the children the next level keeps (the refinement's input, shared
    /// by the vertices and each face-varying channel).
    pub(crate) fn piece(&self, scheme: &Scheme, options: &Options) -> Result<Piece, LimitError> {
        let sel = self.selected_parts();
        let faces = self.piece_faces(&sel);
        let cut = submesh::cut(&self.topology, &faces);
        let rules = self.piece_rules(&cut);
        let layout = PieceLayout::new(&cut.topology, *scheme == Scheme::Loop);
        let refinement =
            Refinement::from_prepared(cut.topology.clone(), rules, scheme.clone(), options, 1)?;
        let kept = self.kept_children(&faces, &sel, &layout);
        Ok(Piece {
            sel,
            faces,
            cut,
            layout,
            refinement,
            kept,
        })
    }

    /// The next level: every child of a selected face, each other face's child at a
    /// selected corner, and (Loop) the middle child of a face with a transitional edge.
    pub(crate) fn refine(
        &self,
        scheme: &Scheme,
        options: &Options,
        reg: Regularity,
    ) -> Result<PatchLevel, LimitError> {
        let Piece {
            sel,
            faces: piece_faces,
            cut,
            layout,
            refinement: r,
            kept,
        } = self.piece(scheme, options)?;
        let next = submesh::cut(r.topology(1), &kept.faces);
        let child_rules: Vec<Rule> = {
            let all = r.vertex_rules(1);
            next.vertices.iter().map(|&v| all[v as usize]).collect()
        };
        let parents: Vec<Parent> = next
            .vertices
            .iter()
            .map(|&cv| match layout.origin(cv as usize) {
                ChildOrigin::Vertex(v) => Parent::Vertex(cut.vertices[v]),
                ChildOrigin::Face(f) => Parent::Face(piece_faces[f]),
                ChildOrigin::Edge(e) => Parent::Edge(cut.edges[e]),
            })
            .collect();
        let tags = features::child_tags(
            &ChildTagInput {
                parent: &self.topology,
                parent_tags: &self.tags,
                parent_depth: self.depth,
                parent_vertex_selected: &sel.vertices,
                parent_edge_selected: &sel.edges,
                parent_face_selected: &self.selected,
                reg,
            },
            &next.topology,
            &child_rules,
            &parents,
        );
        let vertex_full = self.child_vertex_full(&parents, layout.loop_scheme);
        let rows = child_rows(
            r.stencils(1),
            &next.vertices,
            &cut.vertices,
            self.topology.num_vertices(),
        );
        let n = kept.faces.len();
        Ok(PatchLevel {
            rules: child_rules,
            tags,
            depth: self.depth + 1,
            vertex_full,
            parent_selected: kept
                .parent
                .iter()
                .map(|&(f, _)| self.selected[f as usize])
                .collect(),
            selected: vec![false; n],
            face_parent: kept.parent,
            rows: Some(rows),
            topology: next.topology,
        })
    }

    /// The children kept, in piece order (Vtr's sparse marking): all of a selected face's;
    /// of another face, the child at each selected corner and, for Loop, the middle child
    /// when an edge is transitional.
    fn kept_children(
        &self,
        piece_faces: &[u32],
        sel: &Selected,
        layout: &PieceLayout,
    ) -> KeptChildren {
        let t = &self.topology;
        let mut kept = KeptChildren::default();
        for (pi, &f) in piece_faces.iter().enumerate() {
            let first = layout.first_child(pi);
            let fv = t.face_vertices(f as usize);
            let selected = self.selected[f as usize];
            let middle = layout.loop_scheme
                && (selected
                    || t.face_edges(f as usize)
                        .iter()
                        .any(|&e| self.is_transitional(e as usize)));
            let children = if layout.loop_scheme { 4 } else { fv.len() };
            for k in 0..children {
                let keep = if k < fv.len() {
                    selected || sel.vertices[fv[k] as usize]
                } else {
                    middle
                };
                if keep {
                    kept.faces.push((first + k) as u32);
                    kept.parent.push((f, k as u8));
                }
            }
        }
        kept
    }

    /// Faces around each child vertex in the uniform level.
    fn child_vertex_full(&self, parents: &[Parent], loop_scheme: bool) -> Vec<u32> {
        let t = &self.topology;
        // Every face of an edge gives two children at its edge point (Catmull-Clark),
        // three (Loop). An edge point is kept only when the edge has a selected end, whose
        // faces are all in the level.
        let per_face = if loop_scheme { 3 } else { 2 };
        parents
            .iter()
            .map(|&p| match p {
                Parent::Vertex(v) => self.vertex_full[v as usize],
                Parent::Face(f) => t.face_size(f as usize) as u32,
                Parent::Edge(e) => per_face * t.edge_faces(e as usize).len() as u32,
            })
            .collect()
    }
}

/// Where the one-step refinement of a piece numbers its children (OpenSubdiv's order:
/// children of vertices, then of faces (Catmull-Clark), then of edges; child faces
/// consecutive per parent face).
struct PieceLayout {
    loop_scheme: bool,
    num_vertices: usize,
    edge_point_base: usize,
    face_offsets: Vec<u32>,
}

enum ChildOrigin {
    Vertex(usize),
    Face(usize),
    Edge(usize),
}

impl PieceLayout {
    fn new(piece: &Topology, loop_scheme: bool) -> PieceLayout {
        let nv = piece.num_vertices();
        PieceLayout {
            loop_scheme,
            num_vertices: nv,
            edge_point_base: if loop_scheme {
                nv
            } else {
                nv + piece.num_faces()
            },
            face_offsets: piece.face_offsets().to_vec(),
        }
    }

    fn first_child(&self, pi: usize) -> usize {
        if self.loop_scheme {
            4 * pi
        } else {
            self.face_offsets[pi] as usize
        }
    }

    fn origin(&self, child_vertex: usize) -> ChildOrigin {
        if child_vertex < self.num_vertices {
            ChildOrigin::Vertex(child_vertex)
        } else if child_vertex < self.edge_point_base {
            ChildOrigin::Face(child_vertex - self.num_vertices)
        } else {
            ChildOrigin::Edge(child_vertex - self.edge_point_base)
        }
    }
}

/// The kept child faces (indices in the piece's child level), with their parent in the
/// level and their index among its children.
#[derive(Default)]
pub(crate) struct KeptChildren {
    pub faces: Vec<u32>,
    pub parent: Vec<(u32, u8)>,
}

/// The kept vertices' rows of the piece's stencils, as weights of the level's vertices.
fn child_rows(
    stencils: &StencilTable,
    kept: &[u32],
    piece_vertices: &[u32],
    level_vertices: usize,
) -> StencilTable {
    let mut offsets = Vec::with_capacity(kept.len() + 1);
    offsets.push(0u32);
    let (mut indices, mut weights) = (Vec::new(), Vec::new());
    for &cv in kept {
        let (idx, w) = stencils.row(cv as usize);
        indices.extend(idx.iter().map(|&i| piece_vertices[i as usize]));
        weights.extend_from_slice(w);
        offsets.push(indices.len() as u32);
    }
    debug_assert!(indices.iter().all(|&i| i != NONE));
    StencilTable::from_csr(level_vertices, offsets, indices, weights)
}
