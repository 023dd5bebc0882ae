//! Patch tables on the device against the host's: every OpenSubdiv Catmull-Clark and Loop
//! shape, the points recomputed on the device from a moved cage, the patches evaluated at
//! places on every face and on the uniform grid of every patch, compared with
//! `PatchTable::evaluate` and `PatchTable::patch_grid` in f64.

mod common;

use std::path::PathBuf;

use common::{diagonal, gpu, osd_shapes, read_shape};

use subd_gpu::{GpuError, GpuPatchTable, GpuPatchValues};
use subd_limit::eval::FaceParam;
use subd_limit::patches::{EndCaps, PatchOptions, PatchTable};
use subd_mesh::{DVec3, Mesh};
use subd_schemes::{Options, Scheme};

/// The Catmull-Clark and Loop shapes of the OSD suite with at most `max_vertices`.
fn shapes(max_vertices: usize) -> Vec<(PathBuf, Scheme, Mesh)> {
    osd_shapes()
        .into_iter()
        .filter(|(_, scheme)| *scheme != Scheme::Bilinear)
        .map(|(path, scheme)| {
            let mesh = read_shape(&path);
            (path, scheme, mesh)
        })
        .filter(|(_, _, mesh)| mesh.positions.len() <= max_vertices)
        .collect()
}

/// A cage moved off its rest pose: every vertex pushed along a smooth field, so the
/// device's update has to recompute every level and local point.
fn moved(points: &[DVec3]) -> Vec<DVec3> {
    let d = diagonal(points);
    points
        .iter()
        .map(|p| *p + 0.05 * d * DVec3::new((3.0 * p.y / d).sin(), (2.0 * p.z / d).cos(), 0.3))
        .collect()
}

/// Places on every face (each sub-face of a non-quad Catmull-Clark face): corners, edge
/// midpoints and inside points of the domain (a triangle's for Loop).
fn places(table: &PatchTable, mesh: &Mesh, scheme: &Scheme) -> Vec<FaceParam> {
    let domain: &[(f64, f64)] = if *scheme == Scheme::Loop {
        &[
            (0.0, 0.0),
            (1.0, 0.0),
            (0.0, 1.0),
            (0.5, 0.5),
            (0.2, 0.3),
            (0.61, 0.05),
        ]
    } else {
        &[
            (0.0, 0.0),
            (1.0, 1.0),
            (0.5, 0.0),
            (0.2, 0.3),
            (0.61, 0.95),
            (0.5, 0.5),
        ]
    };
    let topology = &mesh.topology;
    let mut out = Vec::new();
    for face in 0..topology.num_faces() {
        let n = topology.face_size(face);
        let subs = if *scheme == Scheme::CatmullClark && n != 4 {
            n
        } else {
            1
        };
        for sub in 0..subs {
            for &(u, v) in domain {
                let at = FaceParam { face, sub, u, v };
                // Holes have no surface.
                if table.find(&at).is_ok() {
                    out.push(at);
                }
            }
        }
    }
    out
}

/// The largest absolute weight sum of a place's derivative rows: the device's f32
/// points' rounding, times this, bounds the derivatives' error.
fn derivative_reach(table: &PatchTable, at: &FaceParam) -> f64 {
    let (a, i) = table.find(at).unwrap();
    let w = table.evaluate_basis(a, i, at.u, at.v).unwrap();
    w.rows[1..3]
        .iter()
        .map(|r| r.iter().map(|x| x.abs()).sum::<f64>())
        .fold(1.0, f64::max)
}

/// [`derivative_reach`] of every sample of `patch_grid(rate)`, patch after patch.
fn sample_reaches(table: &PatchTable, rate: usize) -> Vec<f64> {
    let mut out = Vec::new();
    for (a, array) in table.arrays().iter().enumerate() {
        let triangle = array
            .kind()
            .num_control_points()
            .is_some_and(|n| n == 12 || n == 3 || n == 18);
        for (i, param) in array.params().iter().enumerate() {
            for y in 0..=rate {
                for x in 0..=rate {
                    let (s, t) = (x as f64 / rate as f64, y as f64 / rate as f64);
                    let (s, t) = if triangle && s + t > 1.0 {
                        (s / (s + t), t / (s + t))
                    } else {
                        (s, t)
                    };
                    let (u, v) = if triangle {
                        param.unnormalize_triangle(s, t)
                    } else {
                        param.unnormalize(s, t)
                    };
                    let w = table.evaluate_basis(a, i, u, v).unwrap();
                    let reach = w.rows[1..3]
                        .iter()
                        .map(|r| r.iter().map(|x| x.abs()).sum::<f64>())
                        .fold(1.0, f64::max);
                    out.push(reach);
                }
            }
        }
    }
    out
}

/// Every shape, Gregory end caps (OpenSubdiv's default) at isolation 3: the device's
/// points after an update, and its values at places on every face, within 1e-6 of the
/// diagonal of the host's f64 values (derivatives: times their weights' absolute sum).
#[test]
fn patches_on_the_device_evaluate_as_on_the_host() {
    let Some(gpu) = gpu() else { return };
    let options = PatchOptions {
        isolation: 3,
        end_caps: EndCaps::GregoryBasis,
        ..Default::default()
    };
    let (mut checked, mut places_checked, mut worst) = (0, 0, [0.0_f64; 2]);
    for (path, scheme, mesh) in shapes(usize::MAX) {
        let rules = Options::from_hints(&mesh.hints);
        let Ok(mut table) =
            PatchTable::new(&mesh.topology, &mesh.positions, &scheme, &rules, &options)
        else {
            continue; // Loop on a shape with quads
        };
        let on_device = GpuPatchTable::new(&gpu, &table).unwrap();
        let cage = moved(&mesh.positions);
        table.update(&cage).unwrap();
        on_device.update_points(&gpu, &cage).unwrap();
        let tolerance = 1e-6 * diagonal(&cage);
        let at = path.display();
        let points = gpu.read_points(on_device.points()).unwrap();
        for (k, (got, want)) in points.iter().zip(table.points()).enumerate() {
            let d = got.distance(*want);
            assert!(d <= tolerance, "{at}: point {k}: {d:e}");
        }
        let places = places(&table, &mesh, &scheme);
        let coords = on_device.coords(&gpu, &table, &places).unwrap();
        let out = GpuPatchValues::new(&gpu, places.len()).unwrap();
        on_device.evaluate(&gpu, &coords, &out).unwrap();
        let p = gpu.read_points(&out.positions).unwrap();
        let du = gpu.read_points(&out.du).unwrap();
        let dv = gpu.read_points(&out.dv).unwrap();
        for (q, place) in places.iter().enumerate() {
            let want = table.evaluate(*place).unwrap();
            let d = p[q].distance(want.position);
            assert!(d <= tolerance, "{at}: {place:?}: position {d:e}");
            worst[0] = worst[0].max(d / tolerance * 1e-6);
            let reach = derivative_reach(&table, place);
            for (got, want, what) in [(du[q], want.du, "du"), (dv[q], want.dv, "dv")] {
                let d = got.distance(want);
                assert!(d <= tolerance * reach, "{at}: {place:?}: {what} {d:e}");
                worst[1] = worst[1].max(d / (tolerance * reach) * 1e-6);
            }
        }
        checked += 1;
        places_checked += places.len();
    }
    eprintln!(
        "{checked} shapes, {places_checked} places: worst position {:e} of the diagonal, derivative {:e} of it times the weights' sum",
        worst[0], worst[1]
    );
    assert!(checked >= 40, "only {checked} shapes");
}

/// The uniform grid of every patch at rate 4, with each end-cap kind that has control
/// points: the device's samples against `patch_grid`'s (positions within 1e-6 of the
/// diagonal, normals of the device's derivatives against the host's where the surface is
/// not degenerate), and its triangle list the grid's faces, bit for bit.
#[test]
fn tessellations_on_the_device_are_the_hosts_grids() {
    let Some(gpu) = gpu() else { return };
    let (mut checked, mut too_large) = (0, 0);
    for (path, scheme, mesh) in shapes(usize::MAX) {
        for end_caps in [EndCaps::GregoryBasis, EndCaps::BSpline, EndCaps::Bilinear] {
            let options = PatchOptions {
                isolation: 2,
                end_caps,
                ..Default::default()
            };
            let rules = Options::from_hints(&mesh.hints);
            let Ok(table) =
                PatchTable::new(&mesh.topology, &mesh.positions, &scheme, &rules, &options)
            else {
                continue;
            };
            let on_device = match GpuPatchTable::new(&gpu, &table) {
                Ok(t) => t,
                // B-spline caps around loop_pole360's pole: 33M stencil entries, past
                // lavapipe's 128 MB binding, which the device must say, not crash on.
                Err(e @ GpuError::TooLarge { .. }) => {
                    eprintln!("{}: {end_caps:?}: {e}", path.display());
                    too_large += 1;
                    continue;
                }
                Err(e) => panic!("{}: {end_caps:?}: {e}", path.display()),
            };
            let tessellation = on_device.tessellation(&gpu, 4).unwrap();
            let grid = table.patch_grid(4).unwrap();
            let at = format!("{}: {end_caps:?}", path.display());
            let tolerance = 1e-6 * diagonal(&mesh.positions);
            let values = &tessellation.values;
            let p = gpu.read_points(&values.positions).unwrap();
            let du = gpu.read_points(&values.du).unwrap();
            let dv = gpu.read_points(&values.dv).unwrap();
            assert_eq!(p.len(), grid.positions.len(), "{at}");
            let reaches = sample_reaches(&table, 4);
            for (k, want) in grid.positions.iter().enumerate() {
                let d = p[k].distance(*want);
                assert!(d <= tolerance, "{at}: sample {k}: {d:e}");
                // A normal is as accurate as its derivatives relative to their cross
                // product: derivatives off by e turn it by about e (|du| + |dv|) / |du × dv|
                // (where the surface is degenerate, a Gregory corner's vanishing
                // derivatives, it is what rounding makes it).
                let error = tolerance * reaches[k];
                let cross = du[k].cross(dv[k]);
                let turn = error * (du[k].length() + dv[k].length()) / cross.length();
                if grid.normals[k].length() > 0.5 && turn < 0.1 {
                    let n = cross.normalize();
                    let d = n.distance(grid.normals[k]);
                    assert!(d <= 2.0 * turn, "{at}: normal {k}: {d:e}, bound {turn:e}");
                }
            }
            let want: Vec<u32> = if grid.face_size == 4 {
                grid.faces
                    .chunks_exact(4)
                    .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
                    .collect()
            } else {
                grid.faces.clone()
            };
            assert_eq!(tessellation.read_indices(&gpu).unwrap(), want, "{at}");
            checked += 1;
        }
    }
    assert!(checked >= 300, "only {checked} tables");
    assert!(
        too_large <= 1,
        "{too_large} tables too large for the device"
    );
}

/// What the device cannot do is an error, not a panic: exact end caps, a place off the
/// surface, another table's places, a rate of 0.
#[test]
fn what_the_device_cannot_do_is_an_error() {
    let Some(gpu) = gpu() else { return };
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/meshes/osd");
    let mesh = read_shape(&dir.join("catmark_cube.obj"));
    let rules = Options::from_hints(&mesh.hints);
    let new = |end_caps| {
        let options = PatchOptions {
            isolation: 2,
            end_caps,
            ..Default::default()
        };
        let s = Scheme::CatmullClark;
        PatchTable::new(&mesh.topology, &mesh.positions, &s, &rules, &options).unwrap()
    };
    let exact = new(EndCaps::Exact);
    let err = GpuPatchTable::new(&gpu, &exact).unwrap_err();
    assert!(matches!(err, GpuError::Unsupported(_)), "{err}");
    let table = new(EndCaps::GregoryBasis);
    let on_device = GpuPatchTable::new(&gpu, &table).unwrap();
    let off = FaceParam {
        face: 99,
        sub: 0,
        u: 0.5,
        v: 0.5,
    };
    let err = on_device.coords(&gpu, &table, &[off]).unwrap_err();
    assert!(matches!(err, GpuError::Limit(_)), "{err}");
    let other = new(EndCaps::Bilinear);
    let on = FaceParam { face: 0, ..off };
    let other_device = GpuPatchTable::new(
        &gpu,
        &PatchTable::new(
            &mesh.topology,
            &mesh.positions,
            &Scheme::CatmullClark,
            &rules,
            &PatchOptions {
                isolation: 1,
                ..Default::default()
            },
        )
        .unwrap(),
    )
    .unwrap();
    let err = other_device.coords(&gpu, &other, &[on]).unwrap_err();
    assert!(matches!(err, GpuError::Mismatch(_)), "{err}");
    assert!(matches!(
        on_device.tessellation(&gpu, 0),
        Err(GpuError::Mismatch(_))
    ));
    // A rate whose grid cannot exist is refused before anything is built for it.
    for rate in [1 << 20, usize::MAX / 2] {
        let err = on_device.tessellation(&gpu, rate).unwrap_err();
        assert!(matches!(err, GpuError::TooLarge { .. }), "{err}");
    }
    // A read past a buffer is an error, and the device goes on working.
    let small = on_device.tessellation(&gpu, 1).unwrap();
    let err = gpu.read_u32(&small.indices, 1 << 40).unwrap_err();
    assert!(matches!(err, GpuError::Mismatch(_)), "{err}");
    assert!(gpu.check().is_ok());
}
