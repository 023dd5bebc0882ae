//! The one front door: every surface scheme through one `Scheme` and one `Refinement`, and a
//! typed error (never a panic) where a feature does not cover a scheme.

use subd_adaptive::{AdaptiveError, AdaptiveRefinement};
use subd_limit::LimitError;
use subd_limit::eval::LimitEvaluator;
use subd_mesh::{DVec3, Topology, TopologyBuilder};
use subd_pia::{Pia, PiaError};
use subd_schemes::{Options, RefineError, Refinement, Rule, Scheme, TwoPhase};

fn cube() -> (Topology, Vec<DVec3>) {
    let faces = [
        0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4,
    ];
    let t = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
    let p = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
        .collect();
    (t, p)
}

fn tetrahedron() -> (Topology, Vec<DVec3>) {
    let faces = [0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2];
    let t = TopologyBuilder::new(4).build(&[3; 4], &faces).unwrap();
    (t, vec![DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE])
}

/// Every scheme by name refines through the same calls, and the points it evaluates
/// directly equal its composed stencil tables applied to the base points (two independent
/// paths through the masks).
#[test]
fn every_scheme_refines_through_one_type() {
    let (quads, qp) = cube();
    let (tris, tp) = tetrahedron();
    for name in Scheme::NAMES {
        let name = if name == "two-phase" {
            "two-phase:0.6"
        } else {
            name
        };
        let scheme: Scheme = name.parse().unwrap();
        let (t, p) = match scheme.input_faces() {
            subd_schemes::FaceKind::Triangles => (&tris, &tp),
            _ => (&quads, &qp),
        };
        let r = Refinement::new(t, scheme.clone(), &Options::default(), 2).unwrap();
        assert_eq!(r.scheme(), &scheme);
        let direct = r.refine_points(p);
        for (level, points) in direct.iter().enumerate().skip(1) {
            let composed = r.composed(level).apply_points(p);
            assert_eq!(composed.len(), r.num_vertices(level), "{name} L{level}");
            for (a, b) in points.iter().zip(&composed) {
                assert!((*a - *b).length() < 1e-13, "{name} L{level}: {a} vs {b}");
            }
            assert_eq!(r.faces(level).0.len() - 1, r.topology(level).num_faces());
            assert_eq!(r.vertex_rules(level).len(), r.num_vertices(level));
        }
        assert_eq!(r.points_at(p, 2), direct[2], "{name}");
    }
}

/// One `λ` for every vertex and the same `λ` given per vertex are the same refinement.
#[test]
fn one_lambda_equals_the_same_lambda_per_vertex() {
    let (t, p) = cube();
    let one = Scheme::TwoPhase(TwoPhase::uniform(0.7).unwrap());
    let each = Scheme::TwoPhase(TwoPhase::new(vec![0.7; 8]).unwrap());
    let a = Refinement::new(&t, one, &Options::default(), 2).unwrap();
    let b = Refinement::new(&t, each, &Options::default(), 2).unwrap();
    assert_eq!(a.refine_points(&p), b.refine_points(&p));
    assert_eq!(a.phase_one_lambda(), Some(&[0.7; 8][..]));
}

#[test]
fn refusals_are_typed_errors_naming_what_is_missing() {
    let (quads, qp) = cube();
    let (tris, _) = tetrahedron();
    let options = Options::default();
    let unset: Scheme = "two-phase".parse().unwrap();
    assert!(matches!(
        Refinement::new(&quads, unset, &options, 1),
        Err(RefineError::MissingLambda)
    ));
    let e = Refinement::new(&quads, Scheme::Sqrt3, &options, 1).unwrap_err();
    assert!(matches!(e, RefineError::NotTriangle { face: 0, .. }), "{e}");
    assert!(e.to_string().contains("sqrt3"), "{e}");
    let rules = vec![Rule::Smooth; 4];
    let e = Refinement::from_prepared(tris.clone(), rules, Scheme::Sqrt3, &options, 1).unwrap_err();
    assert!(matches!(e, RefineError::Unsupported { .. }), "{e}");
    let e = Pia::new(&tris, &Scheme::ModifiedButterfly, &options).unwrap_err();
    assert!(matches!(e, PiaError::Scheme { .. }), "{e}");
    assert!(e.to_string().contains("modified-butterfly"), "{e}");
    let e = AdaptiveRefinement::new(&quads, &qp, &Scheme::DooSabin, &options, &[], 1)
        .err()
        .unwrap();
    assert!(matches!(e, AdaptiveError::Scheme { .. }), "{e}");
    let e = LimitEvaluator::new(&tris, &Scheme::BUTTERFLY, &options).unwrap_err();
    assert!(matches!(e, LimitError::Scheme { .. }), "{e}");
    assert!(e.to_string().contains("butterfly"), "{e}");
}
