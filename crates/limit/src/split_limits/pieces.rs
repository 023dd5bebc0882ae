//! The refinements the split schemes' masks are read from where a vertex's neighbourhood
//! becomes regular only below the base: the whole base refined, or pieces cut around the
//! vertices still pending ([`Neighbourhoods`]), with the bounds that make a piece refine as
//! the whole base does where the masks read it; for values, the butterflies' levels each one
//! step below the piece of the level above ([`Refiner::level_for_points`]).

use glam::DVec3;
use subd_mesh::Topology;
use subd_mesh::cut::{NONE, cut};
use subd_mesh::neighbourhood::{faces_touching, vertices_within_rings, without_pinches};
use subd_schemes::{Options, Refinement, Scheme, Split};

use crate::LimitError;
use crate::split_limits::composed_rows::{ComposedRows, Row};

/// How the levels below the base are refined where a vertex's masks apply only further down.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Neighbourhoods {
    /// Pieces cut around the vertices still waiting for a level ([`subd_mesh::cut`]), wide
    /// enough that the piece's refinement agrees with the whole mesh's where the masks read
    /// it; the whole mesh when a piece cannot be refined (a pinched cut).
    #[default]
    Local,
    /// The whole mesh every time: the reference the pieces are checked against.
    Whole,
}

/// A refinement the masks of some base vertices are read from: of the whole base, or of a
/// piece cut around them.
pub(super) struct Refined {
    pub(super) r: Refinement,
    /// For a piece: the piece vertex of each base vertex ([`NONE`] outside) and the base vertex
    /// of each piece vertex. Vertices keep their index at every level of the √3 and butterfly
    /// splits, so these serve every level.
    pub(super) piece: Option<(Vec<u32>, Vec<u32>)>,
}

impl Refined {
    /// The refinement's vertex of base vertex `v`.
    pub(super) fn vertex(&self, v: u32) -> u32 {
        match &self.piece {
            None => v,
            Some((of_base, _)) => of_base[v as usize],
        }
    }

    /// The points of the refinement's `level`, from the points of the whole base.
    fn points_at(&self, base: &[DVec3], level: usize) -> Vec<DVec3> {
        match &self.piece {
            None => self.r.points_at(base, level),
            Some((_, to_base)) => {
                let own: Vec<DVec3> = to_base.iter().map(|&b| base[b as usize]).collect();
                self.r.points_at(&own, level)
            }
        }
    }

    /// A row over the vertices of the refinement's `level` as a row over the base vertices.
    pub(super) fn base_row(&self, row: Row, level: usize, composed: &mut ComposedRows) -> Row {
        let row = if level == 0 {
            row
        } else {
            composed.over_level_zero(&row, level)
        };
        match &self.piece {
            None => row,
            Some((_, to_base)) => row
                .into_iter()
                .map(|(u, w)| (to_base[u as usize], w))
                .collect(),
        }
    }
}

/// Makes the refinements the masks are read from, as [`Neighbourhoods`] says.
pub(super) struct Refiner<'a> {
    pub(super) base: &'a Topology,
    pub(super) scheme: &'a Scheme,
    pub(super) how: Neighbourhoods,
}

impl Refiner<'_> {
    /// The whole base refined `levels` times.
    pub(super) fn whole(&self, levels: usize) -> Result<Refined, LimitError> {
        let r = Refinement::new(self.base, self.scheme.clone(), &Options::default(), levels)
            .map_err(|e| LimitError::Analysis(e.to_string()))?;
        Ok(Refined { r, piece: None })
    }

    /// A refinement `levels` deep that agrees with the whole base's on balls of `radius`
    /// (rings of level `levels`) around `vertices`.
    ///
    /// A ring of a finer level lies inside the ring of the base it came from, and one step
    /// reads its parent within two rings (the butterflies' wings) plus one for the features
    /// and splits a rule sees; so a piece of the faces within `radius + 3·levels + 2` base
    /// rings of `vertices` refines, on those balls, exactly as the whole base does. That
    /// holds for a ball read at any level down to `levels`.
    pub(super) fn around(
        &self,
        vertices: &[u32],
        levels: usize,
        radius: usize,
    ) -> Result<Refined, LimitError> {
        self.piece(vertices, levels, radius + 3 * levels + 2)
    }

    /// [`Self::around`] for balls read at level `levels` only, in a piece as small as the
    /// split allows. The butterflies' split halves distances: an old vertex `d` rings from
    /// `v` is `2d` rings away one level down, and an edge point within `r` rings has both
    /// ends within `⌊(r + 1)/2⌋` rings of the level above (each child edge changes the sum of
    /// the ends' distances by at most one). Its stencil reads the rings of those ends (the
    /// wings lie across their edges), so a level is exact within `C` rings when the level
    /// above is within `⌊(C + 1)/2⌋ + 1`; one more ring per level is kept as a margin, and
    /// `radius + 1` at the last level, so the ball's own vertices have whole rings. √3's
    /// split does not halve distances so simply: it keeps [`Self::around`]'s count.
    pub(super) fn around_last_level(
        &self,
        vertices: &[u32],
        levels: usize,
        radius: usize,
    ) -> Result<Refined, LimitError> {
        if self.scheme.split() != Split::Triangle {
            return self.around(vertices, levels, radius);
        }
        let mut rings = radius + 1;
        for _ in 0..levels {
            rings = rings.div_ceil(2) + 2;
        }
        self.piece(vertices, levels, rings)
    }

    /// The level `level` for the masks of `pending` when values are asked for: the base at
    /// level 0; for the butterflies below level 1, one step of a piece cut out of the level
    /// above (`above`) around the vertices still pending, so that each level refines only
    /// their neighbourhood, not the base's again; otherwise a piece of the base refined
    /// `level` deep ([`Self::around_last_level`]).
    ///
    /// Each butterfly level is kept exact within `E = max(radius + 1, 6)` rings of the
    /// pending vertices, the masks' balls and their rings included. One step is exact within
    /// `E` rings when the level above is within `C = ⌈E/2⌉ + 2` ([`Self::around_last_level`]'s
    /// step), and a piece cut `C` rings around them reads the faces touching those rings,
    /// exact where the level above is within `C + 1 = ⌈E/2⌉ + 3 ≤ E` (as `E ≥ 6`, and `E`
    /// does not grow as the pending vertices become fewer).
    pub(super) fn level_for_points(
        &self,
        above: Option<PointsLevel>,
        pending: &[u32],
        level: usize,
        radius: usize,
        base_points: &[DVec3],
    ) -> Result<PointsLevel, LimitError> {
        let chained = self.scheme.split() == Split::Triangle && self.how == Neighbourhoods::Local;
        let exact = if chained {
            (radius + 1).max(6)
        } else {
            radius + 1
        };
        if level == 0 {
            return Ok(PointsLevel {
                refined: None,
                numbering: Vec::new(),
                points: Vec::new(),
            });
        }
        match above {
            Some(above) if chained && above.refined.is_some() => {
                self.step_below(&above, pending, exact.div_ceil(2) + 2)
            }
            _ => {
                let refined = self.around_last_level(pending, level, exact - 1)?;
                let points = refined.points_at(base_points, level);
                let numbering = refined
                    .piece
                    .map(|(of_base, _)| of_base)
                    .unwrap_or_default();
                Ok(PointsLevel {
                    refined: Some((refined.r, level)),
                    numbering,
                    points,
                })
            }
        }
    }

    /// One step of the faces of `above`'s level touching the vertices within `rings` of the
    /// pending vertices (all of that level where that is every face, or where the cut would
    /// pinch a vertex), with its points.
    fn step_below(
        &self,
        above: &PointsLevel,
        pending: &[u32],
        rings: usize,
    ) -> Result<PointsLevel, LimitError> {
        let (r_above, at) = above.refined.as_ref().expect("a refined level above");
        let t = r_above.topology(*at);
        let seeds: Vec<u32> = pending.iter().map(|&v| above.vertex(v)).collect();
        let faces = without_pinches(
            t,
            &faces_touching(t, &vertices_within_rings(t, &seeds, rings)),
        );
        let step = |t: &Topology| {
            Refinement::new(t, self.scheme.clone(), &Options::default(), 1)
                .map_err(|e| LimitError::Analysis(e.to_string()))
        };
        let sub = (faces.len() < t.num_faces()).then(|| cut(t, &faces));
        let (r, of_above, points) = match sub.as_ref().map(|sub| (step(&sub.topology), sub)) {
            Some((Ok(r), sub)) => {
                let own: Vec<DVec3> = sub
                    .vertices
                    .iter()
                    .map(|&u| above.points[u as usize])
                    .collect();
                (r, Some(sub.vertex_of_source(t.num_vertices())), own)
            }
            _ => (step(t)?, None, above.points.clone()),
        };
        let points = r.points_at(&points, 1);
        let numbering = (0..self.base.num_vertices() as u32)
            .map(|v| {
                let u = above.vertex(v);
                match (&of_above, u) {
                    (_, NONE) => NONE,
                    (Some(of_above), u) => of_above[u as usize],
                    (None, u) => u,
                }
            })
            .collect();
        Ok(PointsLevel {
            refined: Some((r, 1)),
            numbering,
            points,
        })
    }

    /// The faces touching the vertices within `rings` base rings of `vertices`, refined
    /// `levels` deep; the whole base where that is every face, or where the piece cannot be
    /// refined.
    fn piece(&self, vertices: &[u32], levels: usize, rings: usize) -> Result<Refined, LimitError> {
        if self.how == Neighbourhoods::Whole || levels == 0 {
            return self.whole(levels);
        }
        let faces = without_pinches(
            self.base,
            &faces_touching(
                self.base,
                &vertices_within_rings(self.base, vertices, rings),
            ),
        );
        if faces.len() == self.base.num_faces() {
            return self.whole(levels);
        }
        let sub = cut(self.base, &faces);
        // A cut can pinch a vertex between two runs of faces, which the schemes refuse.
        let Ok(r) = Refinement::new(
            &sub.topology,
            self.scheme.clone(),
            &Options::default(),
            levels,
        ) else {
            return self.whole(levels);
        };
        Ok(Refined {
            r,
            piece: Some((sub.vertex_of_source(self.base.num_vertices()), sub.vertices)),
        })
    }
}

/// A level the masks are read at when values are asked for: the base itself, or a piece
/// refined to the level (from the base, or one step from the piece of the level above),
/// with its points.
pub(super) struct PointsLevel {
    /// The piece's refinement and the level of it the masks read; `None` at the base.
    refined: Option<(Refinement, usize)>,
    /// The level's vertex of each base vertex ([`NONE`] outside the piece); empty where
    /// they are the same.
    numbering: Vec<u32>,
    /// The level's points (empty at the base, whose points are given).
    points: Vec<DVec3>,
}

impl PointsLevel {
    pub(super) fn topology<'t>(&'t self, base: &'t Topology) -> &'t Topology {
        match &self.refined {
            Some((r, level)) => r.topology(*level),
            None => base,
        }
    }

    pub(super) fn numbering(&self) -> Option<&[u32]> {
        (!self.numbering.is_empty()).then_some(&self.numbering[..])
    }

    pub(super) fn points<'p>(&'p self, base: &'p [DVec3]) -> &'p [DVec3] {
        if self.refined.is_some() {
            &self.points
        } else {
            base
        }
    }

    /// The level's vertex of base vertex `v`.
    fn vertex(&self, v: u32) -> u32 {
        self.numbering().map_or(v, |n| n[v as usize])
    }
}
