"""subd.PatchTable against independent computations: the `subd` binary's census, the exact
limit (subd.evaluate), finite differences, and its own stencils applied by SciPy."""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import subd
from test_subd import CUBE_F, CUBE_V, icosahedron

SHAPES = pathlib.Path(__file__).resolve().parents[3].parent / "shared" / "meshes" / "osd"
SUBD_BIN = os.environ.get("SUBD_BIN")


@pytest.mark.skipif(not SUBD_BIN, reason="SUBD_BIN not set")
@pytest.mark.parametrize("shape,scheme,iso", [("catmark_cube", "catmull-clark", 3),
                                               ("catmark_car", "catmull-clark", 2),
                                               ("loop_xord_boundary", "loop", 2)])
def test_census_equals_the_binary(shape, scheme, iso):
    path = SHAPES / f"{shape}.obj"
    caps = "gregory" if scheme == "catmull-clark" else "bilinear"
    out = subprocess.run([SUBD_BIN, "patches", "--scheme", scheme, "--isolation", str(iso),
                          "--end-caps", caps, str(path), "--json"],
                         check=True, capture_output=True, text=True).stdout
    table = subd.PatchTable(subd.read(path), scheme, isolation=iso, end_caps=caps)
    assert table.census() == json.loads(out)


def test_exact_end_caps_equal_the_exact_evaluator():
    mesh = subd.Mesh(CUBE_V, CUBE_F)
    table = subd.PatchTable(mesh, "catmull-clark", isolation=2, end_caps="exact",
                            inf_sharp=True, legacy_sharp_corners=False)
    rng = np.random.default_rng(4)
    faces = rng.integers(0, 6, 200)
    u, v = rng.random(200), rng.random(200)
    p, du, dv = table.evaluate(faces, u, v)
    q, _, qdu, qdv, *_ = subd.evaluate(mesh, "catmull-clark", faces, u, v, derivatives=True)
    assert np.abs(p - q).max() <= 1e-12
    assert np.abs(du - qdu).max() <= 1e-9 and np.abs(dv - qdv).max() <= 1e-9


def test_derivatives_agree_with_differences():
    v, f = icosahedron()
    table = subd.PatchTable(subd.Mesh(v, f), "loop", isolation=3, end_caps="bilinear")
    h = 1e-6
    # Inside a box-spline patch of face 3 (away from the corner end caps).
    uu = np.array([0.4 - h, 0.4 + h, 0.4])
    p, du, *_ = table.evaluate([3, 3, 3], uu, [0.3, 0.3, 0.3], derivatives=True)
    assert np.abs((p[1] - p[0]) / (2 * h) - du[2]).max() <= 1e-6


def test_arrays_points_and_stencils_fit_together():
    pytest.importorskip("scipy")
    mesh = subd.Mesh(CUBE_V, CUBE_F)
    table = subd.PatchTable(mesh, "catmull-clark", isolation=3)
    points = table.points
    refined = sum(table.level_vertex_counts)
    stencils = table.local_point_stencils
    # The local points are their stencils applied to the refined vertices.
    assert np.abs(stencils @ points[:refined] - points[refined:]).max() <= 1e-14
    census = table.census()
    assert sum(len(a["params"]) for a in table.arrays) == census["patches"]
    for a in table.arrays:
        assert a["control_points"].max() < len(points)
        assert a["params"].dtype == np.uint32 and a["params"].shape[1] == 2


def test_update_equals_a_rebuild():
    mesh = subd.Mesh(CUBE_V, CUBE_F)
    table = subd.PatchTable(mesh, "catmull-clark", isolation=2)
    moved = CUBE_V * 2.0 + [0.5, 0.0, -1.0]
    table.update(moved)
    rebuilt = subd.PatchTable(subd.Mesh(moved, CUBE_F), "catmull-clark", isolation=2)
    assert np.array_equal(table.points, rebuilt.points)


def test_bad_requests_raise_typed_errors():
    mesh = subd.Mesh(CUBE_V, CUBE_F)
    with pytest.raises(ValueError, match="isolation: 11"):
        subd.PatchTable(mesh, "catmull-clark", isolation=11)
    with pytest.raises(ValueError, match="end_caps"):
        subd.PatchTable(mesh, "catmull-clark", end_caps="smooth")
    with pytest.raises(subd.MeshError, match="triangles"):
        subd.PatchTable(mesh, "loop")
    table = subd.PatchTable(mesh, "catmull-clark", isolation=1)
    with pytest.raises(subd.MeshError, match="point 1"):
        table.evaluate([0, 9], [0.5, 0.5], [0.5, 0.5])
    with pytest.raises(ValueError, match="vertices"):
        table.update(np.zeros((8, 2)))


def test_arrays_and_points_are_read_only_views_that_follow_update():
    mesh = subd.Mesh(CUBE_V, CUBE_F)
    table = subd.PatchTable(mesh, "catmull-clark", isolation=2)
    points = table.points
    # A view of the table's memory: not its own data, not writeable, the same buffer twice.
    assert not points.flags.owndata and not points.flags.writeable
    assert np.shares_memory(points, table.points)
    with pytest.raises(ValueError):
        points[0, 0] = 1.0
    for a in table.arrays:
        assert not a["control_points"].flags.owndata and a["control_points"].dtype == np.uint32
        assert not a["params"].flags.writeable
    # `update` overwrites the points in place: the view taken before shows the new ones.
    moved = CUBE_V * 3.0 - 1.0
    table.update(moved)
    rebuilt = subd.PatchTable(subd.Mesh(moved, CUBE_F), "catmull-clark", isolation=2)
    assert np.array_equal(points, rebuilt.points)
    # The view keeps the table's memory alive after the table itself is gone.
    del table
    assert np.array_equal(points, rebuilt.points)


@pytest.mark.skipif(not SUBD_BIN, reason="SUBD_BIN not set")
def test_npz_holds_the_binarys_json_layout(tmp_path):
    path = SHAPES / "catmark_car.obj"
    out = tmp_path / "car.json"
    subprocess.run([SUBD_BIN, "patches", "--scheme", "catmull-clark", "--isolation", "2",
                    str(path), str(out)], check=True, capture_output=True)
    layout = json.loads(out.read_text())
    table = subd.PatchTable(subd.read(path), "catmull-clark", isolation=2)
    table.save(tmp_path / "car.npz")
    z = np.load(tmp_path / "car.npz")
    assert str(z["scheme"]) == layout["scheme"]
    assert list(z["level_vertex_counts"]) == layout["level_vertex_counts"]
    assert np.array_equal(z["points"], np.array(layout["points"]))
    assert np.array_equal(z["local_point_offsets"], layout["local_point_offsets"])
    assert np.array_equal(z["local_point_indices"], layout["local_point_indices"])
    assert np.array_equal(z["local_point_weights"], layout["local_point_weights"])
    assert list(z["array_types"]) == [a["type"] for a in layout["arrays"]]
    # The car's texture coordinates: the same face-varying patches from both fronts.
    fvar = layout["face_varying"][0]
    assert str(z["uv_interpolation"]) == fvar["interpolation"] == "corners-plus1"
    assert list(z["uv_level_value_counts"]) == fvar["level_value_counts"]
    assert np.array_equal(z["uv_values"].reshape(-1), np.array(fvar["values"]))
    for i, pv in enumerate(fvar["patch_values"]):
        assert np.array_equal(z[f"array{i}_uv_values"].reshape(-1), np.array(pv))
    for i, a in enumerate(layout["arrays"]):
        k = a["control_points_per_patch"]
        cps = np.array(a["control_points"], dtype=np.int64).reshape(-1, k)
        assert np.array_equal(z[f"array{i}_control_points"], cps)
        assert np.array_equal(z[f"array{i}_params"], np.array(a["params"]).reshape(-1, 2))
        assert np.array_equal(z[f"array{i}_sharpness"], np.array(a["sharpness"], np.float32))


def _bilinear_uv(mesh, faces, u, v):
    """The bilinear interpolation of each quad's corner texture coordinates."""
    idx = np.asarray(mesh.uv_indices).reshape(-1, 4)[faces]
    c = np.asarray(mesh.uvs)[idx]
    u, v = u[:, None], v[:, None]
    return ((1 - u) * (1 - v) * c[:, 0] + u * (1 - v) * c[:, 1] + u * v * c[:, 2]
            + (1 - u) * v * c[:, 3])


def test_uv_patches_refined_linearly_are_each_faces_interpolation():
    mesh = subd.read(SHAPES / "catmark_cube.obj")
    table = subd.PatchTable(mesh, "catmull-clark", isolation=3, fvar_interpolation="all")
    rng = np.random.default_rng(9)
    faces = rng.integers(0, 6, 300)
    u, v = rng.random(300), rng.random(300)
    uv, du, dv = table.evaluate_uv(faces, u, v)
    assert uv.shape == (300, 2)
    assert np.abs(uv - _bilinear_uv(mesh, faces, u, v)).max() <= 1e-14
    h = 1e-6
    up, _, _ = table.evaluate_uv(faces, np.clip(u + h, 0, 1), v)
    um, _, _ = table.evaluate_uv(faces, np.clip(u - h, 0, 1), v)
    inside = (u > h) & (u < 1 - h)
    assert np.abs((up - um)[inside] / (2 * h) - du[inside]).max() <= 1e-8
    vp, _, _ = table.evaluate_uv(faces, u, np.clip(v + h, 0, 1))
    vm, _, _ = table.evaluate_uv(faces, u, np.clip(v - h, 0, 1))
    inside = (v > h) & (v < 1 - h)
    assert np.abs((vp - vm)[inside] / (2 * h) - dv[inside]).max() <= 1e-8
    fv = table.face_varying
    assert fv["interpolation"] == "all"
    assert fv["level_value_counts"][0] == len(mesh.uvs)
    assert not fv["values"].flags.writeable and fv["values"].shape[1] == 2


def test_update_uv_moves_the_refined_values_in_place():
    mesh = subd.read(SHAPES / "catmark_car.obj")
    table = subd.PatchTable(mesh, "catmull-clark", isolation=2, fvar_interpolation="corners-plus1")
    values = table.face_varying["values"]
    faces = np.arange(50)
    u = np.full(faces.shape, 0.3)
    before, _, _ = table.evaluate_uv(faces, u, u)
    # Refinement is affine: moving every coordinate moves every refined value alike.
    table.update_uv(np.asarray(mesh.uvs) * 2.0 + [1.0, -3.0])
    after, _, _ = table.evaluate_uv(faces, u, u)
    assert np.abs(after - (before * 2.0 + [1.0, -3.0])).max() <= 1e-12
    # The view taken before holds every refined level's new values: a table built from the
    # moved coordinates has the same bits.
    moved = subd.Mesh(mesh.vertices, mesh.faces, creases=mesh.creases, corners=mesh.corners,
                      holes=mesh.holes, uvs=np.asarray(mesh.uvs) * 2.0 + [1.0, -3.0],
                      uv_indices=mesh.uv_indices)
    rebuilt = subd.PatchTable(moved, "catmull-clark", isolation=2,
                              fvar_interpolation="corners-plus1")
    assert np.array_equal(values, rebuilt.face_varying["values"])
    with pytest.raises(ValueError):
        table.update_uv(np.zeros((3, 2)))
    plain = subd.PatchTable(subd.Mesh(CUBE_V, CUBE_F), "catmull-clark", isolation=2)
    assert plain.face_varying is None
    with pytest.raises(ValueError):
        plain.evaluate_uv([0], [0.5], [0.5])


@pytest.mark.parametrize("kwargs,match", [
    ({"end_caps": "round"},
     'end_caps: unknown end caps "round" \\(one of gregory, bspline, bilinear, exact\\)'),
    ({"boundary": "sharp"}, 'boundary: unknown boundary interpolation "sharp"'),
    ({"fvar_interpolation": "corners"}, "fvar_interpolation: unknown face-varying interpolation"),
])
def test_unknown_option_names_are_listed(kwargs, match):
    # The names come from the library's tables, the same the CLI offers.
    with pytest.raises(ValueError, match=match):
        subd.PatchTable(subd.Mesh(CUBE_V, CUBE_F), "catmull-clark", **kwargs)
