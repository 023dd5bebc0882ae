//! The device's refinement against the CPU's: every OpenSubdiv shape, each level's points
//! within 1e-6 of the shape's bounding-box diagonal of the CPU's f64 points (computed from
//! the masks directly, not through the stencil tables the device applies).

mod common;

use common::{diagonal, gpu, gpu_with, osd_shapes as shapes, read_shape};
use subd_gpu::{Gpu, GpuError, GpuRefiner, GpuStencilTable, LevelTables, Precision};
use subd_mesh::DVec3;
use subd_schemes::{Options, Refinement, Scheme};

fn max_distance(a: &[DVec3], b: &[DVec3]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f64::max)
}

/// With f64 sums (the default where the adapter has them, as lavapipe and datacentre GPUs
/// do), every level and a table composed over three levels within 1e-6 of the diagonal.
/// With f32 sums the long rows cost more: a face point of valence 360, and a composed
/// table's rows, lose a rounding per block of entries, and each level's f32 values are
/// rounded again: within 1.5e-6 (measured on lavapipe: 1.04e-6 per level on the valence-360
/// pole, 1.05e-6 composed).
#[test]
fn every_shape_refines_on_the_device_as_on_the_cpu() {
    let Some(gpu) = gpu() else { return };
    eprintln!("adapter: {:?}", gpu.adapter());
    let f64_sums = gpu.precision() == Precision::F64;
    if f64_sums {
        refine_every_shape(&gpu, 1e-6, 1e-6);
    } else if std::env::var_os("CI").is_some() {
        panic!("CI's adapter (lavapipe) has 64-bit floats; this one has not");
    } else {
        eprintln!("SKIPPED: f64 sums (the adapter has no SHADER_F64)");
    }
    let f32_sums = gpu_with(Some(Precision::F32)).expect("the adapter opened before");
    refine_every_shape(&f32_sums, 1.5e-6, 1.5e-6);
}

fn refine_every_shape(gpu: &Gpu, level_tolerance: f64, composed_tolerance: f64) {
    let (mut checked, mut worst) = (0, [0.0_f64; 2]);
    for (path, scheme) in shapes() {
        let mesh = read_shape(&path);
        let rules = Options::from_hints(&mesh.hints);
        let Ok(refinement) = Refinement::new(&mesh.topology, scheme, &rules, 3) else {
            continue; // a shape the scheme does not take (Loop on quads)
        };
        let cpu = refinement.refine_points(&mesh.positions);
        let diagonal = diagonal(&mesh.positions);
        let per_level = GpuRefiner::new(gpu, &refinement, 3, LevelTables::PerLevel).unwrap();
        per_level.update_points(gpu, &mesh.positions).unwrap();
        for (level, want) in cpu.iter().enumerate() {
            let got = gpu.read_points(per_level.level(level).unwrap()).unwrap();
            let d = max_distance(&got, want) / diagonal;
            let at = format!("{}: level {level}", path.display());
            assert!(d <= level_tolerance, "{at}: {d:e} of the diagonal");
            worst[0] = worst[0].max(d);
        }
        let composed = GpuRefiner::new(gpu, &refinement, 3, LevelTables::Composed).unwrap();
        composed.update_points(gpu, &mesh.positions).unwrap();
        let got = gpu.read_points(composed.last()).unwrap();
        let d = max_distance(&got, &cpu[3]) / diagonal;
        assert!(
            d <= composed_tolerance,
            "{}: composed: {d:e}",
            path.display()
        );
        worst[1] = worst[1].max(d);
        checked += 1;
    }
    eprintln!(
        "{:?}: worst per level {:e}, composed {:e}",
        gpu.precision(),
        worst[0],
        worst[1]
    );
    assert!(checked > 50, "only {checked} shapes refined");
}

/// A new cage is a new frame: the same refiner, new base values, new levels.
#[test]
fn an_update_recomputes_every_level() {
    let Some(gpu) = gpu() else { return };
    let quads = subd_mesh::TopologyBuilder::new(6)
        .build(&[4, 4], &[0, 1, 4, 3, 1, 2, 5, 4])
        .unwrap();
    let refinement = Refinement::new(&quads, Scheme::CatmullClark, &Options::default(), 2).unwrap();
    let refiner = GpuRefiner::new(&gpu, &refinement, 3, LevelTables::PerLevel).unwrap();
    for frame in 0..3 {
        let lift = f64::from(frame);
        let cage: Vec<DVec3> = (0..6)
            .map(|i| DVec3::new(f64::from(i % 3), f64::from(i / 3), lift * f64::from(i % 2)))
            .collect();
        refiner.update_points(&gpu, &cage).unwrap();
        let got = gpu.read_points(refiner.last()).unwrap();
        let want = refinement.points_at(&cage, 2);
        assert!(
            max_distance(&got, &want) <= 1e-6 * diagonal(&cage),
            "frame {frame}"
        );
    }
}

/// Any width: texture coordinates (2) and colours (4) through a table.
#[test]
fn tables_apply_to_columns_of_any_width() {
    let Some(gpu) = gpu() else { return };
    let tri = subd_mesh::TopologyBuilder::new(4)
        .build(&[3, 3], &[0, 1, 2, 0, 2, 3])
        .unwrap();
    let refinement = Refinement::new(&tri, Scheme::Loop, &Options::default(), 1).unwrap();
    let table = refinement.stencils(1);
    let on_device = GpuStencilTable::new(&gpu, table).unwrap();
    for width in [1, 2, 4, 7] {
        let values: Vec<f64> = (0..4 * width).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut want = vec![0.0; table.num_rows() * width];
        table.apply(&values, width, &mut want);
        let as_f32: Vec<f32> = values.iter().map(|&v| v as f32).collect();
        let src = gpu.upload_columns(&as_f32, width).unwrap();
        let dst = gpu.columns(table.num_rows(), width).unwrap();
        on_device.apply(&gpu, &src, &dst).unwrap();
        let got = gpu.read_columns(&dst).unwrap();
        for (g, w) in got.iter().zip(&want) {
            assert!((f64::from(*g) - w).abs() < 1e-6, "width {width}: {g} {w}");
        }
    }
}

#[test]
fn mismatched_and_oversized_buffers_are_errors() {
    let Some(gpu) = gpu() else { return };
    let quad = subd_mesh::TopologyBuilder::new(4)
        .build(&[4], &[0, 1, 2, 3])
        .unwrap();
    let refinement = Refinement::new(&quad, Scheme::CatmullClark, &Options::default(), 1).unwrap();
    let table = GpuStencilTable::new(&gpu, refinement.stencils(1)).unwrap();
    let src = gpu.columns(3, 3).unwrap();
    let dst = gpu.columns(table.num_rows(), 3).unwrap();
    let e = table.apply(&gpu, &src, &dst).unwrap_err();
    assert!(matches!(e, GpuError::Mismatch(_)), "{e}");
    assert!(e.to_string().contains("applied to 3 rows"), "{e}");
    let e = gpu.columns(1 << 40, 3).unwrap_err();
    assert!(matches!(e, GpuError::TooLarge { .. }), "{e}");
    assert!(gpu.upload_columns(&[1.0; 5], 3).is_err());
}

/// A level's limit on the device: level 1 refined there, then its limit stencils. The
/// positions and normals against the CPU's limit of the same level taken by its masks
/// without tables (`level_limit_points`), the tangents (whose direction convention is the
/// tables') against the CPU's f64 application of the same tables: positions within 1e-6 of
/// the diagonal, tangents within 1e-6 of it times their row's absolute weight sum, normals
/// as close as tangents that close allow.
#[test]
fn limits_on_the_device_are_the_cpus() {
    let Some(gpu) = gpu() else { return };
    let mut checked = 0;
    for (path, scheme) in shapes() {
        if scheme == Scheme::Bilinear {
            continue; // its limit is the mesh itself: no limit stencils
        }
        let mesh = read_shape(&path);
        let rules = Options::from_hints(&mesh.hints);
        let Ok(refinement) = Refinement::new(&mesh.topology, scheme.clone(), &rules, 1) else {
            continue;
        };
        if refinement.num_vertices(1) > 2000 {
            // The CPU's limit tables of the largest shapes (car, bishop, pawn) take seconds
            // each; on the device they are the same shader over more rows.
            continue;
        }
        let level = refinement.points_at(&mesh.positions, 1);
        let kept = subd_limit::Tangents::Kept;
        let want = subd_limit::level_limit_points(&refinement, 1, &rules, &level, kept).unwrap();
        let table = subd_limit::limit_stencils(refinement.topology(1), &scheme, &rules).unwrap();
        let by_table = table.apply(&level);
        let limit = subd_gpu::GpuLimitStencils::new(&gpu, &table).unwrap();
        let refiner = GpuRefiner::new(&gpu, &refinement, 3, LevelTables::PerLevel).unwrap();
        refiner.update_points(&gpu, &mesh.positions).unwrap();
        let out = limit.outputs(&gpu, 3).unwrap();
        limit.apply(&gpu, refiner.last(), &out).unwrap();
        let tolerance = 1e-6 * diagonal(&mesh.positions);
        let read = |c| gpu.read_points(c).unwrap();
        let (p, t1, t2) = (
            read(&out.positions),
            read(&out.tangent1),
            read(&out.tangent2),
        );
        let at = path.display();
        let d = max_distance(&p, &want.positions);
        assert!(d <= tolerance, "{at}: positions: {d:e}");
        // A tangent row's weights sum to zero and reach several units: it scales the f32
        // rounding of the level's points by its weights' absolute sum.
        for (got, want, rows, what) in [
            (&t1, &by_table.tangent1, &table.tangent1, "tangent 1"),
            (&t2, &by_table.tangent2, &table.tangent2, "tangent 2"),
        ] {
            for v in 0..got.len() {
                let reach: f64 = rows.row(v).1.iter().map(|w| w.abs()).sum();
                let d = got[v].distance(want[v]);
                assert!(d <= tolerance * reach.max(1.0), "{at}: {what} {v}: {d:e}");
            }
        }
        // A normal is as accurate as its tangents relative to their cross product: a
        // tangent off by e turns it by at most about e (|t1| + |t2|) / |t1 × t2|.
        for (v, n) in want.normals.iter().enumerate() {
            let cross = t1[v].cross(t2[v]);
            let turn = tolerance * (t1[v].length() + t2[v].length()) / cross.length();
            if n.is_finite() && n.length() > 0.5 {
                let got = cross.normalize_or_zero();
                assert!(
                    got.distance(*n) <= 2.0 * turn,
                    "{at}: normal {v}: {got} {n}"
                );
            }
        }
        checked += 1;
    }
    assert!(checked > 40, "only {checked} shapes");
}

/// Texture coordinates on the device: every OSD shape with UVs, refined two levels with
/// each of its scheme's interpolation modes, against the CPU's level-by-level refinement
/// of the values (`refine_values`), within 1e-6 of the UVs' bounding-box diagonal.
#[test]
fn texture_coordinates_on_the_device_are_the_cpus() {
    use subd_mesh::fvar::FVarLinearInterpolation as Mode;
    let Some(gpu) = gpu() else { return };
    let mut checked = 0;
    for (path, scheme) in shapes() {
        let mesh = read_shape(&path);
        let Some(uv) = mesh.fvar.first() else {
            continue;
        };
        let rules = Options::from_hints(&mesh.hints);
        let Ok(refinement) = Refinement::new(&mesh.topology, scheme, &rules, 2) else {
            continue;
        };
        let values = uv.values();
        let (lo, hi) =
            values
                .chunks_exact(2)
                .fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), v| {
                    (
                        [lo[0].min(v[0]), lo[1].min(v[1])],
                        [hi[0].max(v[0]), hi[1].max(v[1])],
                    )
                });
        let tolerance = 1e-6 * (hi[0] - lo[0]).hypot(hi[1] - lo[1]).max(1e-300);
        for mode in [Mode::None, Mode::CornersPlus1, Mode::All] {
            let fv = refinement.face_varying(uv, mode).unwrap();
            let want = fv.refine_values(values, 2);
            let on_device = subd_gpu::GpuFaceVarying::new(&gpu, &fv, 2).unwrap();
            let as_f32: Vec<f32> = values.iter().map(|&x| x as f32).collect();
            on_device.update(&gpu, &as_f32).unwrap();
            let got = gpu.read_columns(on_device.last()).unwrap();
            assert_eq!(got.len(), want[2].len());
            for (g, w) in got.iter().zip(&want[2]) {
                let d = (f64::from(*g) - w).abs();
                assert!(d <= tolerance, "{}: {mode:?}: {g} {w}", path.display());
            }
        }
        checked += 1;
    }
    assert!(
        checked >= 5,
        "only {checked} shapes with texture coordinates"
    );
}

/// A lost device (here destroyed, as a driver reset or a removed GPU would lose it) is an
/// error from every later call, never a panic or a hang; a new `Gpu` works again.
#[test]
fn a_lost_device_is_an_error_not_a_panic() {
    let Some(gpu) = gpu() else { return };
    let path = shapes().into_iter().next().expect("a shape").0;
    let mesh = read_shape(&path);
    let refinement = Refinement::new(
        &mesh.topology,
        Scheme::CatmullClark,
        &Options::from_hints(&mesh.hints),
        2,
    )
    .unwrap();
    let refiner = GpuRefiner::new(&gpu, &refinement, 3, LevelTables::PerLevel).unwrap();
    refiner.update_points(&gpu, &mesh.positions).unwrap();
    assert!(gpu.wait().is_ok());
    gpu.device_and_queue().0.destroy();
    let _ = refiner.update_points(&gpu, &mesh.positions);
    let err = gpu.wait().unwrap_err();
    assert!(matches!(err, GpuError::Failed(_)), "{err}");
    assert!(err.to_string().contains("lost"), "{err}");
    assert!(gpu.read_points(refiner.last()).is_err());
    assert!(gpu.check().is_err());
    let again = Gpu::new().expect("a new device");
    assert!(again.check().is_ok());
}
