//! Local refinement at many places of one face, the descent shared: each piece on the way
//! down is cut out and refined once for all the places it holds, and every place gets the
//! bits [`super::evaluate`] gives it alone.

use glam::DVec3;
use subd_mesh::Topology;
use subd_schemes::{Options, Rule, Scheme};

use super::{
    CORNER_LEVEL, Carried, MAX_LOCAL_LEVELS, Neighbourhood, child_at, corner_limit, cut_out,
    descent_options, exact_corner, inline, nearest_corner, patch_value,
};
use crate::LimitError;
use crate::evaluation::patch::SurfacePoint;
use crate::evaluation::piece::{Piece, eval_piece, piece_of, project};

/// [`super::evaluate`] at many places `(u, v)` of face `f`, each value the same bits as
/// its: the descent is shared while places lie in the same child face, so each
/// piece on the way is cut out and refined once for all the places in it (a
/// tessellation's samples of one cap share most of their pieces).
#[allow(clippy::too_many_arguments)]
pub(crate) fn evaluate_many(
    t: &Topology,
    rules: &[Rule],
    level: usize,
    points: &[DVec3],
    f: usize,
    scheme: &Scheme,
    options: &Options,
    places: &[(f64, f64)],
) -> Result<Vec<SurfacePoint>, LimitError> {
    inline(|| {
        let pick = |ids: &[u32]| ids.iter().map(|&v| points[v as usize]).collect::<Vec<_>>();
        let start = cut_out(t, rules, pick, f)?;
        let descent = SharedDescent {
            level,
            scheme,
            options: descent_options(options),
            face: f,
        };
        let todo = places
            .iter()
            .enumerate()
            .map(|(k, &(u, v))| Place {
                k,
                u,
                v,
                scale: 1.0,
            })
            .collect();
        let mut out = vec![SurfacePoint::default(); places.len()];
        descent.descend(start, 0, todo, &mut out)?;
        Ok(out)
    })
}

/// One place of [`evaluate_many`] on its way down: its index among the places, its
/// parameters in the current piece's face and the scale of the map to the first face's.
struct Place {
    k: usize,
    u: f64,
    v: f64,
    scale: f64,
}

/// What `super::descend` keeps fixed, for the descent shared by many places.
struct SharedDescent<'a> {
    level: usize,
    scheme: &'a Scheme,
    options: Options,
    /// The face the descent started from (named in errors).
    face: usize,
}

impl SharedDescent<'_> {
    /// `super::descend`'s steps for every place in `nb`'s face at once: the piece refined once,
    /// the places that stop here evaluated, the others grouped by the child that holds them
    /// and each child cut out once.
    fn descend(
        &self,
        nb: Neighbourhood,
        depth: usize,
        mut places: Vec<Place>,
        out: &mut [SurfacePoint],
    ) -> Result<(), LimitError> {
        let scheme = self.scheme;
        if depth == MAX_LOCAL_LEVELS {
            for p in places {
                let corner = nearest_corner(scheme, p.u, p.v);
                out[p.k] = corner_limit(&nb, &nb.points, scheme, &self.options, corner)?;
            }
            return Ok(());
        }
        let r = nb.refine(scheme, &self.options, 1)?;
        let (t0, rules0) = (r.topology(0), r.vertex_rules(0));
        if crate::evaluation::piece::is_direct(t0, rules0, nb.face, scheme)? {
            for p in places {
                let piece = (&nb.topology, &nb.rules[..], nb.face);
                out[p.k] = patch_value(piece, &nb.points, scheme, (p.u, p.v, p.scale), self.face)?;
            }
            return Ok(());
        }
        // Places exactly at a corner stop there once the corner alone keeps the face
        // irregular (as in `super::descend`); the test on the piece is made once.
        let deep = depth >= 2.max(CORNER_LEVEL.saturating_sub(self.level));
        let mut decayed = None;
        let mut moving = Vec::with_capacity(places.len());
        for p in places.drain(..) {
            if let Some(corner) = exact_corner(scheme, p.u, p.v)
                && deep
                && *decayed.get_or_insert_with(|| {
                    crate::levels_for_exact_limit(&nb.topology, scheme).0 == 0
                })
            {
                out[p.k] = corner_limit(&nb, &nb.points, scheme, &self.options, corner)?;
                continue;
            }
            let (child, s, t, k) = child_at(t0, scheme, nb.face, p.u, p.v);
            moving.push((
                child,
                Place {
                    k: p.k,
                    u: s,
                    v: t,
                    scale: p.scale * k,
                },
            ));
        }
        if moving.is_empty() {
            return Ok(());
        }
        moving.sort_by_key(|m| m.0);
        let refined = r.refine_points(&nb.points).pop().expect("one level");
        let (t1, rules1) = (r.topology(1), r.vertex_rules(1));
        let mut rest = moving.into_iter().peekable();
        while let Some((child, first)) = rest.next() {
            let mut group = vec![first];
            while let Some((_, p)) = rest.next_if(|m| m.0 == child) {
                group.push(p);
            }
            // A child that is a known patch is evaluated where it is: its ring is whole in
            // the refined piece (see the module's note), so cutting it out would change
            // nothing it reads. Its piece (and a corner piece's projection) serves all its
            // places.
            let piece = piece_of(t1, rules1, child, scheme)?;
            if !matches!(piece, Piece::Refined | Piece::Local) {
                let projected = project(&piece, &refined);
                for p in group {
                    let value = eval_piece(&piece, &refined, projected.as_ref(), child, p.u, p.v);
                    out[p.k] = value?.scaled(p.scale);
                }
                continue;
            }
            let next = cut_out(t1, rules1, |ids| refined.pick(ids), child)?;
            self.descend(next, depth + 1, group, out)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::evaluate;
    use super::*;
    use subd_mesh::TopologyBuilder;
    use subd_schemes::Refinement;

    /// A half-disk of `n` faces around vertex 0, which lies on the boundary with `n` faces
    /// (irregular for both schemes: quads with `n != 2`, triangles with `n != 3`), lifted
    /// off the plane so that every derivative is non-trivial.
    fn half_disk(n: usize, quads: bool) -> (Topology, Vec<DVec3>) {
        let rim = |k: usize, r: f64| {
            let a = std::f64::consts::PI * k as f64 / (if quads { 2 * n } else { n }) as f64;
            DVec3::new(r * a.cos(), r * a.sin(), 0.3 * (3.0 * a).sin() + 0.1 * r)
        };
        let mut positions = vec![DVec3::new(0.0, 0.0, 0.2)];
        let (mut sizes, mut fv) = (Vec::new(), Vec::new());
        if quads {
            // Spokes 1..=n+1, then a corner vertex between each pair of spokes.
            positions.extend((0..=n).map(|k| rim(2 * k, 1.0)));
            positions.extend((0..n).map(|k| rim(2 * k + 1, 1.4)));
            for k in 0..n {
                sizes.push(4);
                fv.extend_from_slice(&[0, 1 + k as u32, (n + 2 + k) as u32, 2 + k as u32]);
            }
        } else {
            positions.extend((0..=n).map(|k| rim(k, 1.0)));
            for k in 0..n {
                sizes.push(3);
                fv.extend_from_slice(&[0, 1 + k as u32, 2 + k as u32]);
            }
        }
        let t = TopologyBuilder::new(positions.len())
            .build(&sizes, &fv)
            .expect("a valid half-disk");
        (t, positions)
    }

    /// The shared descent gives every place the bits of its own descent, on faces at an
    /// irregular boundary vertex (local refinement all the way to the corner).
    #[test]
    fn many_places_equal_one_at_a_time() {
        for (scheme, n) in [(Scheme::CatmullClark, 3), (Scheme::Loop, 5)] {
            let quads = scheme == Scheme::CatmullClark;
            let (t, positions) = half_disk(n, quads);
            let options = Options::default();
            let level = 1;
            let r = Refinement::new(&t, scheme.clone(), &options, level).expect("refines");
            let points = r.refine_points(&positions).pop().expect("level 1");
            let (lt, rules) = (r.topology(level), r.vertex_rules(level));
            let f = lt.vertex_faces(0)[0] as usize;
            let direct = crate::evaluation::piece::is_direct(lt, rules, f, &scheme).unwrap();
            assert!(!direct, "{scheme:?}: the face must need local refinement");
            let m = 8;
            let places: Vec<(f64, f64)> = (0..=m)
                .flat_map(|j| (0..=m).map(move |i| (i, j)))
                .filter(|&(i, j)| quads || i + j <= m)
                .map(|(i, j)| (f64::from(i) / f64::from(m), f64::from(j) / f64::from(m)))
                .chain([(0.013, 0.002), (0.4, 0.31)])
                .collect();
            let many =
                evaluate_many(lt, rules, level, &points, f, &scheme, &options, &places).unwrap();
            for (k, &(u, v)) in places.iter().enumerate() {
                let one = evaluate(lt, rules, level, &points, f, &scheme, &options, u, v).unwrap();
                assert_eq!(many[k], one, "{scheme:?} at ({u}, {v})");
            }
            // The corner's own sample descended to the corner limit, not to a patch.
            assert!(many[0].du.length() > 0.0 && many[0].dv.length() > 0.0);
        }
    }
}
