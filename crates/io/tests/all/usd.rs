//! USD in and out: hand-written stages read against what they say, every OpenSubdiv shape
//! through all three USD encodings and back, and bad input named.

use std::path::PathBuf;

use subd_io::{Format, ReadOptions, WriteOptions, encode_mesh, parse_mesh};
use subd_mesh::fvar::FVarLinearInterpolation;
use subd_mesh::{BoundaryInterpolation, DVec3, FileScheme, Mesh, TriangleSubdivision};

fn read(text: &str, options: &ReadOptions) -> Result<subd_io::MeshFile, String> {
    parse_mesh(text.as_bytes(), Format::Usda, options).map_err(|e| e.to_string())
}

/// A unit quad pair under two Xforms, left-handed, with a per-edge crease chain, a corner,
/// a hole, unindexed face-varying texture coordinates and time-sampled points.
const STAGE: &str = r#"#usda 1.0
(
    defaultPrim = "World"
    metersPerUnit = 0.01
    upAxis = "Z"
)
def Xform "World"
{
    double3 xformOp:translate = (10, 0, 0)
    uniform token[] xformOpOrder = ["xformOp:translate"]
    def Xform "Inner"
    {
        float xformOp:rotateZ = 90
        double3 xformOp:scale = (2, 2, 2)
        uniform token[] xformOpOrder = ["xformOp:rotateZ", "xformOp:scale"]
        def Mesh "Pair"
        {
            int[] faceVertexCounts = [4, 4]
            int[] faceVertexIndices = [0, 1, 2, 3, 1, 4, 5, 2]
            point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (2, 0, 0), (2, 1, 0)]
            point3f[] points.timeSamples = {
                0: [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (2, 0, 0), (2, 1, 0)],
                2: [(0, 0, 2), (1, 0, 2), (1, 1, 2), (0, 1, 2), (2, 0, 2), (2, 1, 2)],
            }
            uniform token subdivisionScheme = "loop"
            token interpolateBoundary = "none"
            token faceVaryingLinearInterpolation = "boundaries"
            token triangleSubdivisionRule = "smooth"
            uniform token orientation = "leftHanded"
            int[] creaseIndices = [0, 1, 4]
            int[] creaseLengths = [3]
            float[] creaseSharpnesses = [1.5, 3]
            int[] cornerIndices = [3]
            float[] cornerSharpnesses = [10]
            int[] holeIndices = [1]
            texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1), (0, 1), (5, 0), (6, 0), (6, 1), (5, 1)] (
                interpolation = "faceVarying"
            )
        }
    }
}
"#;

#[test]
fn a_stage_reads_as_it_says() {
    let file = read(STAGE, &ReadOptions::default()).unwrap();
    let mesh = &file.mesh;
    let t = &mesh.topology;
    // leftHanded: each face reversed, its first corner kept.
    assert_eq!(t.face_vertices(0), &[0, 3, 2, 1]);
    assert_eq!(t.face_vertices(1), &[1, 2, 5, 4]);
    // Scale 2, then a quarter turn about z, then 10 along x: (1, 0, 0) -> (10, 2, 0).
    assert!((mesh.positions[1] - DVec3::new(10.0, 2.0, 0.0)).length() < 1e-12);
    assert!((mesh.positions[5] - DVec3::new(8.0, 4.0, 0.0)).length() < 1e-12);
    // Per-edge sharpness along the chain 0-1-4.
    let edge = |a, b| t.find_edge(a, b).map(|e| t.edge_sharpness(e as usize));
    assert_eq!(edge(0, 1), Some(1.5));
    assert_eq!(edge(1, 4), Some(3.0));
    assert_eq!(t.vertex_sharpness(3), 10.0);
    assert!(t.tags().holes()[1] && !t.tags().holes()[0]);
    let h = mesh.hints;
    assert_eq!(h.scheme, Some(FileScheme::Loop));
    assert_eq!(h.boundary_interpolation, Some(BoundaryInterpolation::None));
    assert_eq!(
        h.fvar_interpolation,
        Some(FVarLinearInterpolation::Boundaries)
    );
    assert_eq!(h.triangle_subdivision, Some(TriangleSubdivision::Smooth));
    // Unindexed face-varying values: one per corner, in the reversed corner order.
    let uv = mesh.uv().unwrap();
    assert_eq!(uv.indices(), &[0, 3, 2, 1, 4, 7, 6, 5]);
    assert_eq!(uv.value(5), &[6.0, 0.0]);
    let stage = file.stage.unwrap();
    assert_eq!(stage.prim, "/World/Inner/Pair");
    assert_eq!(stage.meters_per_unit, Some(0.01));
    assert_eq!(stage.up_axis.as_deref(), Some("Z"));
}

#[test]
fn options_pick_the_time_and_drop_the_transforms() {
    let at = |time| ReadOptions {
        time,
        ignore_transforms: true,
        ..ReadOptions::default()
    };
    let default = read(STAGE, &at(None)).unwrap().mesh;
    assert_eq!(default.positions[1], DVec3::X);
    // Halfway between the samples at 0 and 2.
    let one = read(STAGE, &at(Some(1.0))).unwrap().mesh;
    assert_eq!(one.positions[1], DVec3::new(1.0, 0.0, 1.0));
}

/// Every OpenSubdiv shape: OBJ → USD (each encoding) → mesh equals the OBJ's mesh (positions
/// through USD's single precision), and → OBJ again keeps every tag line bit for bit.
#[test]
fn every_shape_survives_usd_and_back() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/meshes/osd");
    let mut shapes = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "obj") {
            continue;
        }
        let options = ReadOptions {
            accept_inconsistent_orientation: true,
            ..ReadOptions::default()
        };
        let obj = subd_io::read_mesh(&path, &options).unwrap().mesh;
        for format in [Format::Usda, Format::Usdc, Format::Usdz] {
            let mut bytes = Vec::new();
            encode_mesh(&mut bytes, &obj, format, &WriteOptions::default()).unwrap();
            let back = parse_mesh(&bytes, format, &options)
                .unwrap_or_else(|e| panic!("{}: {format:?}: {e}", path.display()))
                .mesh;
            same_mesh(&obj, &back, &format!("{} {format:?}", path.display()));
            let (a, b) = (obj_tags(&obj), obj_tags(&back));
            assert_eq!(a, b, "{} {format:?}", path.display());
        }
        shapes += 1;
    }
    assert!(shapes > 60, "only {shapes} shapes");
}

fn same_mesh(a: &Mesh, b: &Mesh, name: &str) {
    let (ta, tb) = (&a.topology, &b.topology);
    assert_eq!(ta.face_offsets(), tb.face_offsets(), "{name}");
    assert_eq!(ta.all_face_vertices(), tb.all_face_vertices(), "{name}");
    assert_eq!(ta.tags(), tb.tags(), "{name}");
    for (p, q) in a.positions.iter().zip(&b.positions) {
        let single = p.as_vec3().as_dvec3();
        assert_eq!(single, *q, "{name}");
    }
    // What a silent OBJ means, USD states: subd's defaults where the OBJ has no tag.
    let (ha, hb) = (a.hints, b.hints);
    assert_eq!(hb.scheme, Some(FileScheme::Polygons), "{name}");
    assert_eq!(
        hb.boundary_interpolation,
        Some(
            ha.boundary_interpolation
                .unwrap_or(BoundaryInterpolation::EdgeOnly)
        ),
        "{name}"
    );
    assert_eq!(
        hb.fvar_interpolation,
        Some(
            ha.fvar_interpolation
                .unwrap_or(FVarLinearInterpolation::CornersPlus1)
        ),
        "{name}"
    );
    assert_eq!(
        hb.triangle_subdivision,
        Some(
            ha.triangle_subdivision
                .unwrap_or(TriangleSubdivision::Catmark)
        ),
        "{name}"
    );
    assert_eq!(ha.crease_method, hb.crease_method, "{name}");
    assert_eq!(a.uv().is_some(), b.uv().is_some(), "{name}");
    if let (Some(u), Some(v)) = (a.uv(), b.uv()) {
        assert_eq!(u.indices(), v.indices(), "{name}");
        for (x, y) in u.values().iter().zip(v.values()) {
            assert_eq!(*x as f32 as f64, *y, "{name}");
        }
    }
}

/// The tag lines an OBJ writer gives, less the three rules USD always states (compared as
/// hints in `same_mesh`).
fn obj_tags(mesh: &Mesh) -> Vec<String> {
    let mut out = Vec::new();
    encode_mesh(&mut out, mesh, Format::Obj, &WriteOptions::default()).unwrap();
    String::from_utf8(out)
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("t ") && !l.starts_with("t interpolateboundary"))
        .filter(|l| !l.starts_with("t facevaryinginterpolateboundary"))
        .filter(|l| !l.starts_with("t smoothtriangles"))
        .map(str::to_string)
        .collect()
}

#[test]
fn bad_stages_name_the_prim_and_the_attribute() {
    let mesh = |body: &str| format!("#usda 1.0\ndef Mesh \"M\"\n{{\n{body}\n}}\n");
    let quad = "int[] faceVertexCounts = [4]\nint[] faceVertexIndices = [0, 1, 2, 3]\npoint3f[] points = [(0,0,0), (1,0,0), (1,1,0), (0,1,0)]";
    let cases = [
        (
            "int[] faceVertexCounts = [4]\nint[] faceVertexIndices = [0, 1, 2]\npoint3f[] points = [(0,0,0), (1,0,0), (1,1,0)]",
            "prim /M attribute faceVertexIndices: has 3 indices, but faceVertexCounts adds up to 4",
        ),
        (
            "int[] faceVertexCounts = [3]\nint[] faceVertexIndices = [0, 1, 7]\npoint3f[] points = [(0,0,0), (1,0,0), (1,1,0)]",
            "prim /M attribute faceVertexIndices: value [2] = 7 is out of range (3 points)",
        ),
        (
            &format!(
                "{quad}\nint[] creaseIndices = [0, 1]\nint[] creaseLengths = [3]\nfloat[] creaseSharpnesses = [1]"
            ),
            "prim /M attribute creaseLengths: adds up to 3, but creaseIndices has 2 values",
        ),
        (
            &format!(
                "{quad}\nint[] creaseIndices = [0, 1]\nint[] creaseLengths = [2]\nfloat[] creaseSharpnesses = [1, 2, 3]"
            ),
            "prim /M attribute creaseSharpnesses: has 3 values; expected one per crease (1) or one per edge (1)",
        ),
        (
            &format!("{quad}\nuniform token subdivisionScheme = \"sqrt3\""),
            "prim /M attribute subdivisionScheme: unknown token \"sqrt3\" (expected one of catmullClark, loop, bilinear, none)",
        ),
        (
            &format!(
                "{quad}\ntexCoord2f[] primvars:st = [(0,0)] (\ninterpolation = \"faceVarying\"\n)\nint[] primvars:st:indices = [0, 0, 0]"
            ),
            "prim /M attribute primvars:st:indices: has 3 entries, expected 4",
        ),
        (
            &format!("{quad}\nint[] holeIndices = [1]"),
            "prim /M attribute holeIndices:",
        ),
        (
            "int[] faceVertexCounts = [4]\npoint3f[] points = [(0,0,0)]",
            "prim /M attribute faceVertexIndices: missing (a Mesh needs it)",
        ),
    ];
    for (body, expected) in cases {
        let err = read(&mesh(body), &ReadOptions::default()).unwrap_err();
        assert!(err.starts_with(expected), "{err}\n  expected: {expected}");
    }
    let two = "#usda 1.0\ndef Mesh \"A\"\n{\n}\ndef Mesh \"B\"\n{\n}\ndef Xform \"X\"\n{\n}\n";
    let err = read(two, &ReadOptions::default()).unwrap_err();
    assert_eq!(
        err,
        "the stage has 2 Mesh prims; pick one with --prim (prim= in Python): /A, /B"
    );
    let pick = |p: &str| ReadOptions {
        prim: Some(p.into()),
        ..ReadOptions::default()
    };
    let err = read(two, &pick("/X")).unwrap_err();
    assert_eq!(err, "prim /X is a Xform, not a Mesh (mesh prims: /A, /B)");
    let samples = mesh(&format!(
        "{}\npoint3f[] points.timeSamples = {{ 1: [(0,0,0), (1,0,0), (1,1,0), (0,1,0)] }}",
        &quad[..quad.rfind('\n').unwrap()]
    ));
    let err = read(&samples, &ReadOptions::default()).unwrap_err();
    assert!(
        err.contains("attribute points: has time samples (1 from 1 to 1) and no default value"),
        "{err}"
    );
}

/// A coordinate past `f32`'s range would become infinity in `point3f`: refused, naming the
/// vertex, rather than written as a file that cannot be read back.
#[test]
fn coordinates_beyond_single_precision_are_refused() {
    let points = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1e39, 0.0)];
    let view = subd_io::MeshView::new(&points, &[0, 3], &[0, 1, 2], &[]).unwrap();
    let mut out = Vec::new();
    let err =
        subd_io::encode_view(&mut out, &view, Format::Usdc, &WriteOptions::default()).unwrap_err();
    assert!(
        err.to_string()
            .contains("vertex 2 has a coordinate beyond single precision")
    );
}

#[test]
fn corrupt_binary_files_are_errors() {
    let mesh = subd_io::read_mesh(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../../shared/meshes/osd/catmark_cube.obj"),
        &ReadOptions::default(),
    )
    .unwrap()
    .mesh;
    for format in [Format::Usdc, Format::Usdz] {
        let mut bytes = Vec::new();
        encode_mesh(&mut bytes, &mesh, format, &WriteOptions::default()).unwrap();
        for cut in (0..bytes.len()).step_by(97) {
            // Any answer but a panic: a truncated file is an error, never a crash.
            let _ = parse_mesh(&bytes[..cut], format, &ReadOptions::default());
        }
        assert!(parse_mesh(&bytes[..bytes.len() / 2], format, &ReadOptions::default()).is_err());
    }
}

/// A `.usdc` codes large integer arrays in two halves on two threads (the vendored
/// `openusd`'s `encode_ints`): a grid whose vertices are renumbered so that its index
/// deltas take every width the coding has (8, 16 and 32 bits, and the common one), with
/// more indices than the parallel threshold and a length that is not a multiple of four,
/// reads back with every index and position.
#[test]
fn large_index_arrays_survive_the_parallel_integer_coding() {
    let (nx, ny) = (301, 300); // 90,300 quads, 361,200 indices
    let nv = (nx + 1) * (ny + 1);
    // Swap vertices at distances of every size (a small linear congruential generator:
    // the test needs spread, not statistics).
    let mut renumber: Vec<u32> = (0..nv as u32).collect();
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = |bound: usize| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1);
        (state >> 33) as usize % bound
    };
    for k in 0..nv / 3 {
        let reach = [50, 20_000, nv][k % 3];
        let a = next(nv);
        let b = (a + 1 + next(reach)).min(nv - 1);
        renumber.swap(a, b);
    }
    let mut positions = vec![DVec3::ZERO; nv];
    for j in 0..=ny {
        for i in 0..=nx {
            positions[renumber[j * (nx + 1) + i] as usize] = DVec3::new(i as f64, j as f64, 0.5);
        }
    }
    let mut offsets = vec![0_u32];
    let mut corners = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let v = |di: usize, dj: usize| renumber[(j + dj) * (nx + 1) + i + di];
            corners.extend([v(0, 0), v(1, 0), v(1, 1), v(0, 1)]);
            offsets.push(corners.len() as u32);
        }
    }
    // One triangle more, so that the index count is not a multiple of four.
    corners.extend([renumber[0], renumber[1], renumber[nx + 2]]);
    offsets.push(corners.len() as u32);
    assert!(corners.len() > 1 << 18 && corners.len() % 4 != 0);
    let view = subd_io::MeshView::new(&positions, &offsets, &corners, &[]).unwrap();
    let mut bytes = Vec::new();
    subd_io::encode_view(&mut bytes, &view, Format::Usdc, &WriteOptions::default()).unwrap();
    let options = ReadOptions {
        accept_inconsistent_orientation: true,
        ..ReadOptions::default()
    };
    let back = parse_mesh(&bytes, Format::Usdc, &options).unwrap().mesh;
    assert_eq!(back.topology.all_face_vertices(), &corners[..]);
    assert_eq!(back.positions, positions);
}
