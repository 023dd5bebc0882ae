//! Times building a patch table and evaluating it on the bench torus (`cargo xtask bench`'s
//! quad mesh, or its triangulation for Loop): `patch_time <cc|loop> <isolation> <repeats>
//! [eval|fvar]`; prints the seconds of each run (`fvar`: adding a face-varying channel, a
//! UV layout cut along one ring of the torus, to a built table). Run it with
//! `RAYON_NUM_THREADS` set.

use std::time::Instant;

use subd_limit::eval::FaceParam;
use subd_limit::patches::{EndCaps, PatchOptions, PatchTable};
use subd_mesh::fvar::{FVarChannel, FVarLinearInterpolation};
use subd_mesh::{DVec3, Topology, TopologyBuilder};
use subd_schemes::{Options, Refinement, Scheme};

fn bench_torus() -> (Topology, Vec<DVec3>) {
    let base = subd_mesh::primitives::torus_with_hexagons(160, 160, 8, 3.0, 1.0);
    let r = Refinement::new(&base.topology, Scheme::CatmullClark, &Options::default(), 1)
        .expect("refine");
    let pts = r.refine_points(&base.positions).pop().expect("level 1");
    (r.into_topology(1), pts)
}

fn split_quads(t: &Topology) -> Topology {
    let mut idx = Vec::with_capacity(t.num_faces() * 6);
    for f in 0..t.num_faces() {
        let v = t.face_vertices(f);
        idx.extend_from_slice(&[v[0], v[1], v[2], v[0], v[2], v[3]]);
    }
    TopologyBuilder::new(t.num_vertices())
        .build(&vec![3; 2 * t.num_faces()], &idx)
        .expect("valid")
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let loop_scheme = args.get(1).is_some_and(|s| s == "loop");
    let isolation: u8 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2);
    let repeats: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(5);
    let eval = args.get(4).is_some_and(|s| s == "eval");
    let fvar = args.get(4).is_some_and(|s| s == "fvar");
    let (quads, points) = bench_torus();
    let (topo, scheme, caps) = if loop_scheme {
        (split_quads(&quads), Scheme::Loop, EndCaps::GregoryBasis)
    } else {
        (quads, Scheme::CatmullClark, EndCaps::GregoryBasis)
    };
    let options = PatchOptions {
        isolation,
        end_caps: caps,
        inf_sharp: true,
        legacy_sharp_corners: false,
        single_crease: false,
    };
    let rules = Options::default();
    let table = PatchTable::new(&topo, &points, &scheme, &rules, &options).expect("table");
    let at: Vec<FaceParam> = (0..1_000_000usize)
        .map(|i| {
            let face = (i * 7919) % topo.num_faces();
            let (u, v) = (
                ((i * 37) % 101) as f64 / 101.0,
                ((i * 53) % 97) as f64 / 97.0,
            );
            let (u, v) = if loop_scheme && u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            FaceParam { face, sub: 0, u, v }
        })
        .collect();
    let channel = uv_layout(&topo, &points);
    for _ in 0..repeats {
        let mut built = fvar.then(|| build_table(&topo, &points, &scheme, &rules, &options));
        let t = Instant::now();
        let n = if let Some(table) = &mut built {
            table
                .add_face_varying(&channel, FVarLinearInterpolation::CornersPlus1)
                .expect("face-varying");
            table.face_varying()[0].values().len() / 2
        } else if eval {
            table.evaluate_first(&at).expect("evaluate").len()
        } else {
            PatchTable::new(&topo, &points, &scheme, &rules, &options)
                .expect("table")
                .census()
                .patches
        };
        println!("{:.4} s ({n})", t.elapsed().as_secs_f64());
    }
}

/// A table of its own for each face-varying run (the channel is added to it).
fn build_table(
    topo: &Topology,
    points: &[DVec3],
    scheme: &Scheme,
    rules: &Options,
    options: &PatchOptions,
) -> PatchTable {
    PatchTable::new(topo, points, scheme, rules, options).expect("table")
}

/// A UV layout: the angle around the torus's axis and the height, cut where the angle wraps:
/// the faces across the cut take values of their own for their vertices past it, so the
/// cut is a seam (and every vertex on it has two values).
fn uv_layout(topo: &Topology, points: &[DVec3]) -> FVarChannel {
    let angle = |p: DVec3| p.y.atan2(p.x) / std::f64::consts::TAU + 0.5;
    let mut values: Vec<f64> = points.iter().flat_map(|&p| [angle(p), p.z]).collect();
    let mut indices = Vec::with_capacity(topo.num_face_vertices());
    // The second value of each vertex past the cut, shared by the faces across it.
    let mut across = vec![u32::MAX; points.len()];
    for f in 0..topo.num_faces() {
        let fv = topo.face_vertices(f);
        let wraps = fv.iter().any(|&v| angle(points[v as usize]) > 0.75)
            && fv.iter().any(|&v| angle(points[v as usize]) < 0.25);
        for &v in fv {
            let p = points[v as usize];
            if wraps && angle(p) < 0.25 {
                if across[v as usize] == u32::MAX {
                    across[v as usize] = (values.len() / 2) as u32;
                    values.extend([angle(p) + 1.0, p.z]);
                }
                indices.push(across[v as usize]);
            } else {
                indices.push(v);
            }
        }
    }
    FVarChannel::new(topo, 2, values, indices).expect("layout")
}
