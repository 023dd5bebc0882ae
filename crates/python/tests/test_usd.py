"""USD through subd, checked against Pixar's own USD (``usd-core``, a test dependency):
stages written by ``pxr`` read as ``pxr`` reads them, and every file subd writes opens in
``pxr`` without a diagnostic and says what subd meant."""

import json
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest
from pxr import Gf, Usd, UsdGeom

import subd

ROOT = pathlib.Path(__file__).resolve().parents[3]
STAGES = ROOT / "tests" / "data" / "usd"
SHAPES = ROOT.parent / "shared" / "meshes" / "osd"
SUBD_BIN = os.environ.get("SUBD_BIN")

SCHEMES = {"catmullClark": "catmull-clark", "loop": "loop", "bilinear": "bilinear",
           "none": "polygons"}
BOUNDARIES = {"none": "none", "edgeOnly": "edge-only", "edgeAndCorner": "edge-and-corner"}
FVAR = {"none": "none", "cornersOnly": "corners-only", "cornersPlus1": "corners-plus1",
        "cornersPlus2": "corners-plus2", "boundaries": "boundaries", "all": "all"}


def mesh_prims(stage):
    return [p for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]


def expected(prim, time):
    """What the mesh prim says, read by pxr: faces (left-handed ones reversed, first corner
    kept), world-space points, per-edge sharpness, corners, holes, each corner's UV, rules."""
    mesh = UsdGeom.Mesh(prim)
    counts = list(mesh.GetFaceVertexCountsAttr().Get(time))
    indices = list(mesh.GetFaceVertexIndicesAttr().Get(time))
    left = mesh.GetOrientationAttr().Get() == UsdGeom.Tokens.leftHanded
    order = []
    start = 0
    for c in counts:
        corners = list(range(start, start + c))
        order += [corners[0]] + corners[1:][::-1] if left else corners
        start += c
    world = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(time)
    points = np.array([list(world.Transform(Gf.Vec3d(*p)))
                       for p in mesh.GetPointsAttr().Get(time)])
    edges = {}
    lengths = list(mesh.GetCreaseLengthsAttr().Get(time) or [])
    chain = list(mesh.GetCreaseIndicesAttr().Get(time) or [])
    sharp = list(mesh.GetCreaseSharpnessesAttr().Get(time) or [])
    per_edge = len(sharp) == sum(n - 1 for n in lengths) and len(sharp) != len(lengths)
    at = e = 0
    for c, n in enumerate(lengths):
        for a, b in zip(chain[at:at + n - 1], chain[at + 1:at + n]):
            edges[(min(a, b), max(a, b))] = sharp[e] if per_edge else sharp[c]
            e += 1
        at += n
    corners = dict(zip(mesh.GetCornerIndicesAttr().Get(time) or [],
                       mesh.GetCornerSharpnessesAttr().Get(time) or []))
    st = UsdGeom.PrimvarsAPI(prim).GetPrimvar("st")
    uv = None
    if st and st.HasValue():
        values = np.array(st.Get(time), dtype=np.float64)
        idx = st.GetIndices(time)
        interp = st.GetInterpolation()
        if interp == UsdGeom.Tokens.faceVarying:
            per_corner = values[np.array(idx)] if idx else values
        else:
            per_vertex = values[np.array(idx)] if idx else values
            per_corner = per_vertex[np.array(indices)]
        uv = per_corner[order]
    return {
        "counts": counts,
        "indices": [indices[k] for k in order],
        "points": points,
        "edges": edges,
        "corners": corners,
        "holes": sorted(mesh.GetHoleIndicesAttr().Get(time) or []),
        "uv": uv,
        "scheme": SCHEMES[mesh.GetSubdivisionSchemeAttr().Get()],
        "boundary": BOUNDARIES[mesh.GetInterpolateBoundaryAttr().Get(time)],
        "fvar": FVAR[mesh.GetFaceVaryingLinearInterpolationAttr().Get(time)],
    }


def read_back(path, prim, time):
    """What subd reads, in the same terms."""
    mesh = subd.read(path, prim=prim, time=time)
    edges, sharpness = mesh.creases
    corners, corner_sharpness = mesh.corners
    info = subd.info(mesh)
    uv = None
    if mesh.uvs is not None:
        uv = mesh.uvs[mesh.uv_indices.reshape(-1)]
    return {
        "counts": mesh.face_sizes.tolist(),
        "indices": mesh.face_vertices.tolist(),
        "points": mesh.vertices,
        "edges": {(min(a, b), max(a, b)): s for (a, b), s in zip(edges.tolist(), sharpness)},
        "corners": dict(zip(corners.tolist(), corner_sharpness)),
        "holes": sorted(mesh.holes.tolist()),
        "uv": uv,
        "scheme": info["scheme"],
        "boundary": info["boundary_interpolation"],
        "fvar": info["fvar_interpolation"],
    }


@pytest.mark.parametrize("name", ["meshes.usda", "meshes.usdc", "meshes.usdz", "composed.usda"])
def test_subd_reads_what_pxr_reads(name):
    path = STAGES / name
    stage = Usd.Stage.Open(str(path))
    prims = mesh_prims(stage)
    assert prims, name
    checked = 0
    for prim in prims:
        path_str = str(prim.GetPath())
        times = [None] + ([10.0] if prim.GetAttribute("points").GetNumTimeSamples() else [])
        for t in times:
            want = expected(prim, Usd.TimeCode.Default() if t is None else Usd.TimeCode(t))
            got = read_back(path, path_str, t)
            where = f"{name} {path_str} time {t}"
            for key in ["counts", "indices", "edges", "corners", "holes", "scheme",
                        "boundary", "fvar"]:
                assert got[key] == want[key], (where, key, got[key], want[key])
            # Both sides transform the single-precision points in double precision.
            np.testing.assert_allclose(got["points"], want["points"], rtol=0, atol=1e-12,
                                       err_msg=where)
            assert (got["uv"] is None) == (want["uv"] is None), where
            if want["uv"] is not None:
                assert np.array_equal(got["uv"], want["uv"]), where
            checked += 1
    assert checked >= (5 if name.startswith("meshes") else 1)


PXR_CHECK = r"""
import json, sys
from pxr import Usd, UsdGeom
stage = Usd.Stage.Open(sys.argv[1])
out = []
for prim in stage.Traverse():
    if not prim.IsA(UsdGeom.Mesh):
        continue
    m = UsdGeom.Mesh(prim)
    ok, why = UsdGeom.Mesh.ValidateTopology(m.GetFaceVertexIndicesAttr().Get(),
                                           m.GetFaceVertexCountsAttr().Get(),
                                           len(m.GetPointsAttr().Get()))
    st = UsdGeom.PrimvarsAPI(prim).GetPrimvar("st")
    normals = m.GetNormalsAttr()
    out.append({
        "path": str(prim.GetPath()),
        "valid": ok, "why": why,
        "counts": list(m.GetFaceVertexCountsAttr().Get()),
        "indices": list(m.GetFaceVertexIndicesAttr().Get()),
        "points": [list(p) for p in m.GetPointsAttr().Get()],
        "scheme": m.GetSubdivisionSchemeAttr().Get(),
        "boundary": m.GetInterpolateBoundaryAttr().Get(),
        "creases": [list(m.GetCreaseIndicesAttr().Get() or []),
                    list(m.GetCreaseLengthsAttr().Get() or []),
                    list(m.GetCreaseSharpnessesAttr().Get() or [])],
        "corners": [list(m.GetCornerIndicesAttr().Get() or []),
                    list(m.GetCornerSharpnessesAttr().Get() or [])],
        "holes": list(m.GetHoleIndicesAttr().Get() or []),
        "normals": [list(n) for n in normals.Get()] if normals.HasValue() else None,
        "normals_interpolation": m.GetNormalsInterpolation(),
        "st": [list(v) for v in st.ComputeFlattened()] if st and st.HasValue() else None,
        "st_interpolation": st.GetInterpolation() if st else None,
        "meters_per_unit": UsdGeom.GetStageMetersPerUnit(stage),
        "up_axis": UsdGeom.GetStageUpAxis(stage),
    })
print(json.dumps(out))
"""


def pxr_reads(path):
    """Opens `path` in a fresh pxr process: its meshes, and everything pxr said on stderr."""
    run = subprocess.run([sys.executable, "-c", PXR_CHECK, str(path)], capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout), run.stderr


def f32(a):
    return np.asarray(a, dtype=np.float32).astype(np.float64)


@pytest.mark.skipif(not SUBD_BIN, reason="SUBD_BIN (the subd binary) not set")
@pytest.mark.parametrize("ext", ["usda", "usdc", "usdz"])
@pytest.mark.parametrize("levels", [0, 1])
def test_files_subd_writes_open_in_pxr_and_say_what_subd_meant(tmp_path, ext, levels):
    src = SHAPES / "catmark_fvar_bound1.obj"
    flags = ["refine", "--scheme", "catmull-clark", "--levels", str(levels)]
    usd, obj = tmp_path / f"out.{ext}", tmp_path / "out.obj"
    for out in [usd, obj]:
        run = subprocess.run([SUBD_BIN, *flags, str(src), str(out)], capture_output=True)
        assert run.returncode == 0, run.stderr
    meshes, diagnostics = pxr_reads(usd)
    assert diagnostics == "", diagnostics
    [m] = meshes
    assert m["valid"], m["why"]
    want = subd.read(obj)
    assert m["counts"] == want.face_sizes.tolist()
    assert m["indices"] == want.face_vertices.tolist()
    assert np.array_equal(np.array(m["points"]), f32(want.vertices))
    corner_uv = want.uvs[want.uv_indices.reshape(-1)]
    assert m["st_interpolation"] == "faceVarying"
    assert np.array_equal(np.array(m["st"]), f32(corner_uv))
    # The cage keeps its scheme and tags; a refined level is plain polygons.
    assert m["scheme"] == ("catmullClark" if levels == 0 else "none")
    edges, sharpness = want.creases
    assert m["creases"][1] == [2] * len(edges)
    written = {tuple(sorted(e)): s for e, s in
               zip(np.array(m["creases"][0]).reshape(-1, 2).tolist(), m["creases"][2])}
    assert written == {tuple(sorted(e)): s for e, s in zip(edges.tolist(), sharpness)}


@pytest.mark.skipif(not SUBD_BIN, reason="SUBD_BIN (the subd binary) not set")
def test_a_limit_mesh_carries_its_normals_and_the_stage_units(tmp_path):
    out = tmp_path / "body.usdc"
    run = subprocess.run([SUBD_BIN, "refine", "--scheme", "catmull-clark", "--levels", "1",
                          "--limit", "--prim", "/World/Cage", str(STAGES / "meshes.usda"),
                          str(out)], capture_output=True)
    assert run.returncode == 0, run.stderr
    [m], diagnostics = pxr_reads(out)
    assert diagnostics == ""
    assert m["normals_interpolation"] == "vertex"
    normals = np.array(m["normals"])
    assert normals.shape == (len(m["points"]), 3)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-6)
    assert m["meters_per_unit"] == 0.01 and m["up_axis"] == "Z"


def test_python_writes_usd_that_pxr_reads(tmp_path):
    mesh = subd.read(SHAPES / "catmark_cube_creases0.obj")
    for ext in ["usda", "usdc", "usdz"]:
        path = tmp_path / f"cube.{ext}"
        mesh.write(path)
        [m], diagnostics = pxr_reads(path)
        assert diagnostics == ""
        assert m["indices"] == mesh.face_vertices.tolist()
        assert np.array_equal(np.array(m["points"]), f32(mesh.vertices))
        again = subd.read(path)
        assert np.array_equal(again.creases[1], mesh.creases[1])


def test_python_keeps_the_prim_units_and_scheme_through_its_functions(tmp_path):
    """What is made from a USD mesh keeps its prim's name and its stage's units; the scheme
    defaults to the file's; a cage from pia names the scheme it is the cage of."""
    strip = subd.read(STAGES / "meshes.usda", prim="/World/Strip")
    assert strip.file_scheme == "loop"
    assert strip.stage == ("/World/Strip", 0.01, "Z")
    refined = subd.refine(strip, levels=2)
    by_name = subd.refine(strip, "loop", levels=2)
    assert np.array_equal(refined.vertices, by_name.vertices)
    assert not np.array_equal(refined.vertices,
                              subd.refine(strip, "catmull-clark", levels=2).vertices)
    assert refined.stage == strip.stage
    out = tmp_path / "refined.usda"
    refined.write(out)
    [m], diagnostics = pxr_reads(out)
    assert diagnostics == ""
    assert m["path"].endswith("/Strip") and m["scheme"] == "none"
    assert m["meters_per_unit"] == 0.01 and m["up_axis"] == "Z"
    cage = subd.pia(strip)
    assert cage.stage == strip.stage and cage.file_scheme == "loop"
    cage.write(tmp_path / "cage.usdc")
    [m], diagnostics = pxr_reads(tmp_path / "cage.usdc")
    assert diagnostics == "" and m["scheme"] == "loop" and m["path"].endswith("/Strip")
    # USD cannot name two-phase: its cage is written refined two levels, with a warning.
    grid = subd.read(SHAPES / "catmark_cube.obj")
    two_phase = subd.pia(grid, "two-phase", lam=0.5)
    assert two_phase.file_scheme is None
    with pytest.warns(subd.SubdWarning, match="USD has no name for the two-phase scheme"):
        two_phase.write(tmp_path / "two_phase.usda")
    [m], diagnostics = pxr_reads(tmp_path / "two_phase.usda")
    want = subd.refine(two_phase, "two-phase", levels=2, lam=0.5)
    assert diagnostics == "" and m["scheme"] == "none"
    assert m["indices"] == want.face_vertices.tolist()
    assert np.array_equal(np.array(m["points"]), f32(want.vertices))
    # A mesh from arrays names no scheme, and the default stays Catmull-Clark.
    quad = subd.Mesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]])
    assert quad.file_scheme is None and quad.stage is None
    assert subd.refine(quad).num_faces == 4


@pytest.mark.skipif(not SUBD_BIN, reason="SUBD_BIN (the subd binary) not set")
def test_obj_to_usd_to_obj_keeps_every_tag(tmp_path):
    compared = 0
    for src in sorted(SHAPES.glob("catmark_*crease*.obj")) + [SHAPES / "catmark_hole_test1.obj"]:
        cage = ["refine", "--scheme", "catmull-clark", "--levels", "0"]
        mid, back = tmp_path / f"{src.stem}.usdc", tmp_path / f"{src.stem}.obj"
        for a, b in [(src, mid), (mid, back)]:
            run = subprocess.run([SUBD_BIN, *cage, str(a), str(b)], capture_output=True)
            assert run.returncode == 0, run.stderr
        direct = tmp_path / f"{src.stem}_direct.obj"
        run = subprocess.run([SUBD_BIN, *cage, str(src), str(direct)], capture_output=True)
        assert run.returncode == 0, run.stderr
        tags = lambda p: [l for l in p.read_text().splitlines()
                          if l.startswith(("t crease", "t corner", "t hole"))]
        assert tags(back) == tags(direct), src.name
        compared += 1
    assert compared >= 5


def test_bad_usd_raises_a_typed_error(tmp_path):
    bad = tmp_path / "bad.usda"
    bad.write_text('#usda 1.0\ndef Mesh "M"\n{\n int[] faceVertexCounts = [4]\n'
                   ' int[] faceVertexIndices = [0, 1, 2]\n point3f[] points = [(0,0,0), (1,0,0), (1,1,0)]\n}\n')
    with pytest.raises(subd.FormatError, match="prim /M attribute faceVertexIndices"):
        subd.read(bad)
    with pytest.raises(subd.FormatError, match=r"pick one with --prim \(prim= in Python\)"):
        subd.read(STAGES / "meshes.usda")
    truncated = tmp_path / "cut.usdc"
    truncated.write_bytes((STAGES / "meshes.usdc").read_bytes()[:1000])
    with pytest.raises(subd.SubdError):
        subd.read(truncated)
