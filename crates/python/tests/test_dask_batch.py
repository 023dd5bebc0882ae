"""The Dask batch example (examples/python/dask_batch.py) run as a user runs it: a
subprocess on a LocalCluster of two worker processes, its outputs compared with subd.refine
in this process and with the closed-form face counts."""

import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

import shutil

import subd

pytest.importorskip("distributed")

ROOT = pathlib.Path(__file__).resolve().parents[3]
EXAMPLE = ROOT / "examples" / "python" / "dask_batch.py"
STAGES = ROOT / "tests" / "data" / "usd"

CUBE_V = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
    dtype=float,
)
CUBE_F = np.array(
    [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
)


def octahedron():
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    f = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    return v, f


def grid(n):
    """An open n x n grid of quads with a triangle fan on one side: mixed polygons."""
    v = [[i, j, 0.1 * ((i * j) % 3)] for j in range(n + 1) for i in range(n + 1)]
    f = [[j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i]
         for j in range(n) for i in range(n)]
    apex = len(v)
    v.append([n + 1, n / 2, 0])
    f += [[j * (n + 1) + n, apex, (j + 1) * (n + 1) + n] for j in range(n)]
    return np.array(v, float), f


def valid_meshes():
    """18 small meshes (quads, triangles, mixed, one creased), each a little different."""
    rng = np.random.default_rng(41)
    shapes = [(CUBE_V, CUBE_F, None), (*octahedron(), None), (*grid(3), None),
              (CUBE_V, CUBE_F, ([[0, 1], [1, 2]], [2.0, 10.0]))]
    for k in range(18):
        v, f, creases = shapes[k % len(shapes)]
        moved = v + rng.normal(scale=0.05, size=np.shape(v))
        yield subd.Mesh(moved, f, creases=creases)


def build_inputs(root):
    """20 files under ``root`` (some in subfolders, .obj and .ply): 18 meshes and 2 bad
    files. Returns (valid paths, bad paths)."""
    valid = []
    for k, mesh in enumerate(valid_meshes()):
        folder = root / ("a" if k % 3 == 0 else "b/c" if k % 3 == 1 else "")
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"mesh{k:02d}.{'ply' if k % 2 else 'obj'}"
        mesh.write(path)
        valid.append(path)
    bad_obj = root / "a" / "out_of_range.obj"
    bad_obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 7\n")
    bad_ply = root / "b" / "truncated.ply"
    subd.Mesh(CUBE_V, CUBE_F).write(bad_ply)
    data = bad_ply.read_bytes()
    bad_ply.write_bytes(data[: len(data) - 40])  # ends inside the face list
    return valid, [bad_obj, bad_ply]


def run_example(*args, timeout=120):
    return subprocess.run([sys.executable, str(EXAMPLE), *map(str, args)],
                          capture_output=True, text=True, timeout=timeout)


def test_batch_on_two_local_workers_refines_the_good_files_and_reports_the_bad(tmp_path):
    in_dir, out_dir = (tmp_path / "in").resolve(), (tmp_path / "out").resolve()
    valid, bad = build_inputs(in_dir)
    assert len(valid) + len(bad) == 20

    run = run_example(in_dir, out_dir, "--scheme", "catmull-clark", "--levels", 1,
                      "--workers", 2)
    assert run.returncode == 1, run.stderr

    # Every good file refined as subd.refine refines it here.
    total = 0
    for src in valid:
        out = out_dir / src.name
        assert out.is_file(), f"{out} missing; stderr:\n{run.stderr}"
        mesh = subd.read(src)
        want = subd.refine(mesh, "catmull-clark", levels=1)
        got = subd.read(out)
        # One level of Catmull-Clark: a quad per corner of every face.
        assert got.num_faces == want.num_faces == int(mesh.face_sizes.sum()), src.name
        assert np.array_equal(got.face_sizes, want.face_sizes), src.name
        assert np.array_equal(got.face_vertices, want.face_vertices), src.name
        assert np.abs(got.vertices - want.vertices).max() <= 1e-12, src.name
        total += got.num_faces
    # Nothing for the bad files, no temporary file left: the 18 outputs only.
    assert sorted(p.name for p in out_dir.iterdir()) == sorted(p.name for p in valid)

    # Each bad file named on one stderr line; nothing else of the form.
    lines = [line for line in run.stderr.splitlines() if line.startswith("subd: ")]
    assert len(lines) == 2, run.stderr
    for path, what in zip(bad, ["vertex 7", "ends inside"]):
        line = next((x for x in lines if x.startswith(f"subd: {path}:")), None)
        assert line is not None and what in line, run.stderr

    summary = run.stdout.strip().splitlines()[-1]
    m = re.fullmatch(r"(\d+) refined, (\d+) failed, (\d+) faces out, ([\d.]+) s", summary)
    assert m, run.stdout
    assert (int(m[1]), int(m[2]), int(m[3])) == (18, 2, total)


def test_each_mesh_prim_of_a_stage_is_a_task_refined_with_its_scheme(tmp_path):
    in_dir, out_dir = (tmp_path / "in").resolve(), (tmp_path / "out").resolve()
    in_dir.mkdir()
    shutil.copy(STAGES / "meshes.usda", in_dir / "scene.usda")
    subd.Mesh(CUBE_V, CUBE_F).write(in_dir / "cube.obj")
    run = run_example(in_dir, out_dir, "--levels", 1, "--workers", 1)
    # /World/Flat names no subdivision scheme (`none`): that task fails, named, as the CLI's.
    assert run.returncode == 1, run.stderr
    [failed] = [line for line in run.stderr.splitlines() if line.startswith("subd: ")]
    assert failed.startswith(f"subd: {in_dir / 'scene.usda'} /World/Flat: "), failed
    assert "names no subdivision scheme" in failed
    prims = [p["path"] for p in subd.mesh_prims(in_dir / "scene.usda")]
    assert len(prims) == 4 and "/World/Flat" in prims
    names = {"cube.obj": (in_dir / "cube.obj", None)}
    for prim in prims:
        if prim != "/World/Flat":
            names["scene" + prim.replace("/", "_") + ".usda"] = (in_dir / "scene.usda", prim)
    assert sorted(p.name for p in out_dir.iterdir()) == sorted(names)
    for name, (src, prim) in names.items():
        mesh = subd.read(src, prim=prim)
        # Each prim with the scheme its stage names (Catmull-Clark, Loop, ...).
        want = subd.refine(mesh, mesh.file_scheme or "catmull-clark", levels=1)
        got = subd.read(out_dir / name)
        assert np.array_equal(got.face_vertices, want.face_vertices), name
        # USD stores single-precision points.
        assert np.abs(got.vertices - want.vertices).max() <= 1e-5 * max(
            1.0, np.abs(want.vertices).max()), name
        if prim is not None:
            assert got.stage[0].rsplit("/", 1)[1] == prim.rsplit("/", 1)[1], name


@pytest.mark.parametrize(
    "case, message",
    [
        ("clash", "would both write it"),
        ("same-dir", "OUT_DIR is IN_DIR"),
        ("empty", "no .obj, .ply, .gltf, .glb, .usd, .usda, .usdc, .usdz files"),
    ],
)
def test_refusals_exit_2_before_anything_runs(tmp_path, case, message):
    in_dir, out_dir = tmp_path / "in", tmp_path / "out"
    in_dir.mkdir()
    if case == "clash":
        for sub in ["x", "y"]:
            (in_dir / sub).mkdir()
            subd.Mesh(CUBE_V, CUBE_F).write(in_dir / sub / "cube.obj")
    if case == "same-dir":
        subd.Mesh(CUBE_V, CUBE_F).write(in_dir / "cube.obj")
        out_dir = in_dir
    run = run_example(in_dir, out_dir, "--scheme", "catmull-clark", "--levels", 1,
                      timeout=60)
    assert run.returncode == 2
    assert message in run.stderr
    if case != "same-dir":
        assert not out_dir.exists()
