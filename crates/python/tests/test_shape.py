"""Tests of subd.pia, subd.edit and subd.deform against computations made another way: the
limit surface evaluated afresh (subd.limit's limit stencils, subd.evaluate's patches), the
`subd` binary's output files and reports (SUBD_BIN), and closed forms of the constraints."""

import json
import os
import pathlib
import subprocess
import warnings

import numpy as np
import pytest

import subd

ROOT = pathlib.Path(__file__).resolve().parents[3]
MESHES = ROOT / "examples" / "meshes"
EDITS = ROOT / "examples" / "edit"
SHAPES = ROOT.parent / "shared" / "meshes" / "osd"
SUBD_BIN = os.environ.get("SUBD_BIN")
needs_bin = pytest.mark.skipif(not SUBD_BIN, reason="SUBD_BIN (the subd binary) not set")

TORUS = MESHES / "torus_creased.obj"
ICOSAHEDRON = MESHES / "icosahedron.obj"
CUBE = MESHES / "cube.obj"


def diagonal(points):
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))


def binary(*args):
    """Runs the binary: (exit status, stdout, stderr)."""
    run = subprocess.run([SUBD_BIN, *map(str, args)], capture_output=True, text=True)
    return run.returncode, run.stdout, run.stderr


def quiet_read(path):
    """The mesh of `path`, the reader's repairs not reported."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", subd.SubdWarning)
        return subd.read(path)


def same_mesh_but_positions(got, base):
    """`got` has `base`'s faces, tags and texture coordinates."""
    assert np.array_equal(got.face_sizes, base.face_sizes)
    assert np.array_equal(got.face_vertices, base.face_vertices)
    for a, b in zip(got.creases + got.corners, base.creases + base.corners):
        assert np.array_equal(a, b)
    assert np.array_equal(got.holes, base.holes)
    assert (got.uvs is None) == (base.uvs is None)
    if base.uvs is not None:
        assert np.array_equal(got.uvs, base.uvs)
        assert np.array_equal(got.uv_indices, base.uv_indices)


# --- pia -------------------------------------------------------------------------------


@pytest.mark.parametrize("path,scheme,extra", [
    (TORUS, "catmull-clark", {}),
    (TORUS, "catmull-clark", {"solver": "direct"}),
    (SHAPES / "catmark_fvar_bound1.obj", "catmull-clark", {"solver": "cg"}),
    (SHAPES / "catmark_edgecorner.obj", "catmull-clark", {"solver": "iterate"}),
    (ICOSAHEDRON, "loop", {}),
    (SHAPES / "loop_icos_semisharp.obj", "loop", {"solver": "weighted"}),
    (CUBE, "two-phase", {"lam": 0.6}),
])
def test_pia_limit_passes_through_the_vertices(path, scheme, extra):
    base = subd.read(path)
    got, report = subd.pia(base, scheme, tol=1e-11, return_report=True, **extra)
    same_mesh_but_positions(got, base)
    # The limit stencils of subd.limit, not the solver's table.
    name = scheme if "lam" not in extra else f"{scheme}:{extra['lam']}"
    limit = subd.limit(got, name)[0]
    error = np.linalg.norm(limit - base.vertices, axis=1).max()
    assert error <= 1.001e-11 * diagonal(base.vertices)
    assert report["converged"] and report["iterations"] >= 1
    assert report["max_error_relative"] <= 1.001e-11
    assert report["moving"] == report["vertices"] == base.num_vertices
    assert isinstance(report["history"], np.ndarray) and report["history"][0] > 0


@needs_bin
@pytest.mark.parametrize("scheme", ["catmull-clark", "loop"])
def test_pia_equals_the_binary_on_every_shape(tmp_path, scheme):
    compared = refused = 0
    for obj in sorted(SHAPES.glob("*.obj")):
        if obj.stem == "catmark_car":
            continue  # diverges for 10 s in each (the non-convergence test covers that)
        out = tmp_path / f"{obj.stem}.obj"
        code, stdout, err = binary("pia", "--scheme", scheme, "--json", obj, out)
        try:
            got, report = subd.pia(quiet_read(obj), scheme, return_report=True)
        except subd.SubdError:
            assert code != 0 and not out.exists(), f"{obj.name}: the binary interpolated it"
            refused += 1
            continue
        assert code == 0, f"{obj.name}: {err}"
        # The file holds the shortest decimal that reads back to the same double.
        assert np.array_equal(got.vertices, quiet_read(out).vertices), obj.name
        want = json.loads(stdout)
        for key in ("iterations", "method", "solver", "moving", "max_error", "converged"):
            assert report[key] == want[key], (obj.name, key)
        assert np.array_equal(report["history"], want["history"]), obj.name
        compared += 1
    assert compared >= 10 and refused >= 1, (compared, refused)


@needs_bin
def test_pia_with_fixed_or_moving_vertices_equals_the_binary(tmp_path):
    base = subd.read(TORUS)
    chosen = [0, 5, 17, 40]
    (tmp_path / "ids.txt").write_text(" ".join(map(str, chosen)) + "\n")
    for flag in ("fixed", "moving"):
        out = tmp_path / f"{flag}.obj"
        code, _, err = binary("pia", "--scheme", "catmull-clark", f"--{flag}",
                              tmp_path / "ids.txt", TORUS, out)
        assert code == 0, err
        got = subd.pia(base, **{flag: chosen})
        assert np.array_equal(got.vertices, subd.read(out).vertices)
        # A boolean mask of every vertex says the same.
        mask = np.zeros(base.num_vertices, dtype=bool)
        mask[chosen] = True
        assert np.array_equal(subd.pia(base, **{flag: mask}).vertices, got.vertices)
        kept = np.setdiff1d(np.arange(base.num_vertices), chosen) if flag == "moving" else chosen
        assert np.array_equal(got.vertices[kept], base.vertices[kept])


@needs_bin
def test_two_phase_with_one_lambda_per_vertex_equals_the_binary(tmp_path):
    base = subd.read(CUBE)
    lam = np.linspace(0.4, 1.0, base.num_vertices)
    (tmp_path / "lam.txt").write_text("\n".join(repr(float(x)) for x in lam) + "\n")
    out = tmp_path / "out.obj"
    code, _, err = binary("pia", "--scheme", "two-phase", "--lambda-file", tmp_path / "lam.txt",
                          CUBE, out)
    assert code == 0, err
    got = subd.pia(base, "two-phase", lam=lam)
    assert np.array_equal(got.vertices, subd.read(out).vertices)
    # One λ for all, given either way, is the same scheme.
    one = subd.pia(base, "two-phase", lam=0.7).vertices
    assert np.array_equal(subd.pia(base, "two-phase:0.7").vertices, one)
    assert np.array_equal(subd.pia(base, "two-phase", lam=[0.7] * 8).vertices, one)


@needs_bin
def test_pia_that_does_not_converge_raises_and_the_binary_writes_nothing(tmp_path):
    out = tmp_path / "out.obj"
    code, _, err = binary("pia", "--scheme", "catmull-clark", "--solver", "iterate",
                          "--max-iter", "2", TORUS, out)
    assert code != 0 and not out.exists() and "did not reach" in err
    with pytest.raises(subd.ConvergenceError, match="did not reach tol 1e-10 in 2 iter") as e:
        subd.pia(subd.read(TORUS), solver="iterate", max_iter=2)
    assert isinstance(e.value, subd.SubdError) and isinstance(e.value, RuntimeError)
    report = e.value.report
    assert not report["converged"] and report["iterations"] == 2
    assert len(report["history"]) == 3 and report["max_error_relative"] > 1e-10


@pytest.mark.parametrize("kwargs,error,match", [
    ({"moving": [0, 99]}, subd.MeshError, r"moving: vertex 99 does not exist \(the mesh has 8"),
    ({"fixed": [-1]}, subd.MeshError, "fixed: vertex index -1 is negative"),
    ({"moving": [0], "fixed": [1]}, ValueError, "give one of them"),
    ({"moving": np.ones(3, dtype=bool)}, subd.MeshError, "one value per vertex"),
    ({"lam": 0.6}, subd.MeshError, "lam applies to the two-phase scheme only"),
    ({"solver": "fast"}, ValueError, "solver: unknown solver \"fast\" \\(one of auto, iterate"),
    ({"tol": 0.0}, subd.MeshError, "tol 0: must be a positive number"),
    ({"tol": float("nan")}, subd.MeshError, "tol NaN"),
    ({"tol": "small"}, TypeError, "tol: expected a number"),
    ({"max_iter": -1}, ValueError, "max_iter: -1 is negative"),
    ({"max_iter": 2**70}, ValueError, "max_iter: .* is too large"),
    ({"boundary": "sharp"}, ValueError, "boundary: unknown boundary interpolation \"sharp\""),
])
def test_pia_names_what_is_wrong(kwargs, error, match):
    with pytest.raises(error, match=match):
        subd.pia(subd.read(CUBE), **kwargs)


@pytest.mark.parametrize("scheme,kwargs,match", [
    ("two-phase", {}, "the two-phase scheme needs lam"),
    ("two-phase", {"lam": 0.2}, r"vertex 0.*allow_any_lambda=True accepts it"),
    ("two-phase", {"lam": [0.6, 0.7]}, "lam: 2 values for 8 vertices"),
    ("two-phase:0.6", {"lam": 0.6}, "gives λ already"),
    ("loop", {}, "face 0 has 4 vertices; the Loop scheme needs triangles"),
    ("sqrt3", {}, "interpolation needs catmull-clark, loop or two-phase"),
])
def test_pia_refuses_a_scheme_it_cannot_use(scheme, kwargs, match):
    with pytest.raises(subd.MeshError, match=match):
        subd.pia(subd.read(CUBE), scheme, **kwargs)
    # Outside the proven range, on request.
    subd.pia(subd.read(CUBE), "two-phase", lam=0.3, allow_any_lambda=True, tol=1e-8,
             solver="direct")


# --- edit ------------------------------------------------------------------------------


def torus_constraints():
    return json.loads((EDITS / "torus_edit.json").read_text())


@pytest.mark.parametrize("kwargs", [
    {},
    {"method": "energy"},
    {"method": "energy", "region_rings": 1},
    {"method": "energy", "region_rings": "all"},
])
def test_edit_meets_its_constraints_on_the_limit_surface(kwargs):
    base = subd.read(TORUS)
    with pytest.warns(subd.SubdWarning, match=r"constraint 3 \(isoline .*\) is redundant"):
        got = subd.edit(base, torus_constraints(), **kwargs)
    same_mesh_but_positions(got, base)
    scale = 1e-10 * diagonal(base.vertices)
    # Vertex 8's limit point rose by 0.25 (subd.limit's stencils).
    rise = subd.limit(got)[0][8] - subd.limit(base)[0][8]
    assert np.abs(rise - [0, 0, 0.25]).max() <= scale
    # Face 40 at (0.5, 0.5): moved by (0, 0, -0.15), normal along (0.2, 0, -1) (patches).
    p0, _ = subd.evaluate(base, "catmull-clark", [40], [0.5], [0.5])
    p1, n1 = subd.evaluate(got, "catmull-clark", [40], [0.5], [0.5])
    assert np.abs(p1 - p0 - [0, 0, -0.15]).max() <= scale
    want = np.array([0.2, 0, -1]) / np.linalg.norm([0.2, 0, -1])
    assert np.linalg.norm(np.cross(n1[0], want)) <= 1e-9
    # The iso-line v = 0.5 of its first face, 60, moved by its B-spline displacements
    # (spline parameter u there).
    u = np.linspace(0, 1, 5)
    before, _ = subd.evaluate(base, "catmull-clark", np.full(5, 60), u, np.full(5, 0.5))
    after, _ = subd.evaluate(got, "catmull-clark", np.full(5, 60), u, np.full(5, 0.5))
    spline = [bspline([0, 0.05, 0.1, 0.05, 0], t) for t in u]
    assert np.abs(after - before - np.outer(spline, [0, 0, 1])).max() <= scale


def bspline(c, t):
    """The uniform cubic B-spline of control values `c` at `t` (span `floor(t)`)."""
    j = min(int(t), len(c) - 4)
    s = t - j
    b = [(1 - s) ** 3 / 6, (3 * s**3 - 6 * s**2 + 4) / 6, (-3 * s**3 + 3 * s**2 + 3 * s + 1) / 6,
         s**3 / 6]
    return sum(w * c[j + k] for k, w in enumerate(b))


@needs_bin
@pytest.mark.parametrize("path,args,kwargs", [
    (TORUS, [], {}),
    (TORUS, ["--method", "energy"], {"method": "energy"}),
    (TORUS, ["--method", "energy", "--region-rings", "1"], {"method": "energy", "region_rings": 1}),
    (TORUS, ["--method", "energy", "--penalty", "1e10", "--membrane", "0.1"],
     {"method": "energy", "penalty": 1e10, "membrane": 0.1}),
    (TORUS, ["--method", "energy", "--exact", "--boundary", "none"],
     {"method": "energy", "exact": True, "boundary": "none"}),
])
def test_edit_equals_the_binary(tmp_path, path, args, kwargs):
    out = tmp_path / "out.obj"
    code, stdout, err = binary("edit", "--constraints", EDITS / "torus_edit.json", *args, "--json",
                               path, out)
    assert code == 0, err
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        got, report = subd.edit(subd.read(path), torus_constraints(), return_report=True,
                                **kwargs)
    assert np.array_equal(got.vertices, subd.read(out).vertices)
    want = json.loads(stdout)
    for key in ("rows", "rank", "rank_deficient", "dependencies", "free_vertices",
                "max_residual_relative", "energy_before", "energy_after",
                "displacement_energy"):
        assert report[key] == want[key], key
    assert report["moved_vertices"].tolist() == want["moved_vertices"]
    assert report["residuals"].tolist() == [r["residual"] for r in want["residuals"]]
    # The warnings are the binary's, less its prefix.
    assert [str(w.message) for w in caught] == [
        line.split(": ", 3)[-1] for line in err.splitlines() if "warning" in line
    ]


@needs_bin
def test_loop_edit_with_numpy_values_equals_the_binary(tmp_path):
    constraints = [
        {"kind": "point", "vertex": np.int64(2), "displacement": np.array([0, 0, 0.3])},
        {"kind": "normal", "face": 4, "uv": (0.3, np.float32(0.25)), "normal": [0, 1, 1]},
    ]
    plain = json.loads(json.dumps(constraints, default=lambda x: x.tolist()))
    (tmp_path / "c.json").write_text(json.dumps({"constraints": plain}))
    out = tmp_path / "out.obj"
    code, _, err = binary("edit", "--scheme", "loop", "--constraints", tmp_path / "c.json",
                          ICOSAHEDRON, out)
    assert code == 0, err
    base = subd.read(ICOSAHEDRON)
    got = subd.edit(base, constraints, scheme="loop")
    assert np.array_equal(got.vertices, subd.read(out).vertices)
    assert np.array_equal(subd.edit(base, {"constraints": plain}, scheme="loop").vertices,
                          got.vertices)
    rise = subd.limit(got, "loop")[0][2] - subd.limit(base, "loop")[0][2]
    assert np.abs(rise - [0, 0, 0.3]).max() <= 1e-12


def test_conflicting_constraints_warn_with_the_compromise():
    lift = lambda dz: {"kind": "point", "vertex": 8, "displacement": [0, 0, dz]}  # noqa: E731
    with pytest.warns(subd.SubdWarning, match=r"constraints 0 \(point at vertex 8\) and 1 "
                                              r"\(point at vertex 8\) conflict"):
        got, report = subd.edit(subd.read(TORUS), [lift(0.1), lift(0.3)], return_report=True)
    assert report["rank_deficient"] and not report["dependencies"][0]["consistent"]
    # The least-squares compromise: halfway.
    rise = subd.limit(got)[0][8] - subd.limit(subd.read(TORUS))[0][8]
    assert abs(rise[2] - 0.2) <= 1e-12


@pytest.mark.parametrize("constraints,match", [
    ([{"kind": "pointy"}], r"constraint 0: unknown kind \"pointy\""),
    ([{"kind": "point", "vertex": 1, "target": [0, 0, 0]}, {"kind": "normal", "vertex": 1}],
     "constraint 1: missing \"normal\""),
    ([{"kind": "point", "vertex": 1, "target": [0, 0, float("nan")]}], "constraint 0: Out of range"),
    ([{"kind": "point", "vertex": 1, "target": [0, 0]}], "constraint 0: \"target\" must have 3"),
    ([{"kind": "point", "vertex": 1, "target": [0, 0, 0], "colour": 1}],
     "constraint 0: unknown field \"colour\""),
    ([{"kind": "point", "vertex": 1, "target": [0, 0, 0]}, {"kind": "point", "vertex": 500,
                                                            "target": [0, 0, 0]}],
     "constraint 1: "),
    ([{"kind": "point", "face": 1, "uv": [0.5, 0.5], "target": {1, 2}}], "constraint 0: .*set"),
    ([], "no constraints"),
    ({"constraint": []}, "no \"constraints\" list"),
])
def test_bad_constraints_are_named(constraints, match):
    with pytest.raises(subd.MeshError, match=match):
        subd.edit(subd.read(TORUS), constraints)


@pytest.mark.parametrize("kwargs,error,match", [
    ({"penalty": 1.0}, subd.MeshError, "apply to the energy method only"),
    ({"method": "energy", "penalty": -1.0}, subd.MeshError, "penalty -1: must be a positive"),
    ({"method": "energy", "penalty": 1.0, "exact": True}, subd.MeshError, "give one of them"),
    ({"method": "energy", "membrane": float("inf")}, subd.MeshError, "membrane inf"),
    ({"method": "energy", "scheme": "loop"}, subd.MeshError, "energy method needs catmull-clark"),
    ({"method": "fair"}, ValueError, "method: unknown editing method \"fair\""),
    ({"scheme": "sqrt3"}, ValueError, "editing needs catmull-clark or loop"),
    ({"method": "energy", "region_rings": "some"}, ValueError, "region_rings 'some'"),
    ({"method": "energy", "region_rings": 1.5}, TypeError, "region_rings: expected a whole"),
])
def test_edit_options_are_checked(kwargs, error, match):
    constraints = [{"kind": "point", "vertex": 1, "displacement": [0, 0, 0.1]}]
    with pytest.raises(error, match=match):
        subd.edit(subd.read(CUBE if kwargs.get("scheme") != "loop" else ICOSAHEDRON),
                  constraints, **kwargs)
    with pytest.raises(TypeError, match="constraints: expected a list"):
        subd.edit(subd.read(CUBE), "points")


def test_a_huge_ring_count_is_every_vertex_the_rings_reach():
    constraints = [{"kind": "point", "vertex": 8, "displacement": [0, 0, 0.1]}]
    base = subd.read(TORUS)
    many = subd.edit(base, constraints, method="energy", region_rings=2**62)
    every = subd.edit(base, constraints, method="energy", region_rings=200)
    assert np.array_equal(many.vertices, every.vertices)


# --- deform ----------------------------------------------------------------------------


@needs_bin
def test_deform_equals_the_binary(tmp_path):
    out = tmp_path / "out.obj"
    code, stdout, err = binary("deform", "--constraints", EDITS / "torus_deform.json", "--json",
                               TORUS, out)
    assert code == 0, err
    constraints = json.loads((EDITS / "torus_deform.json").read_text())["constraints"]
    got, report = subd.deform(subd.read(TORUS), constraints, return_report=True)
    assert np.array_equal(got.vertices, subd.read(out).vertices)
    want = json.loads(stdout)
    for key in ("vertices", "constraints", "moved", "max_constraint_error"):
        assert report[key] == want[key], key


def test_deform_moves_a_centre_exactly_and_blends_around_it():
    base = subd.read(TORUS)
    v = base.vertices
    centre, radius, shift = v[3], 0.7, np.array([0.1, -0.2, 0.3])
    got, report = subd.deform(base, [{"center": centre, "radius": radius,
                                       "displacement": shift}], return_report=True)
    same_mesh_but_positions(got, base)
    assert np.array_equal(got.vertices[3], v[3] + shift)
    r = np.linalg.norm(v - centre, axis=1) / radius
    far = r >= 1
    assert far.any() and np.array_equal(got.vertices[far], v[far])
    assert report["moved"] == int((~far).sum()) and report["max_constraint_error"] == 0
    # One constraint: d(Q) = D (1 - r)^4 (4 r + 1), Wendland's blend, r = |Q - C| / R.
    near = ~far
    want = v[near] + np.outer((1 - r[near]) ** 4 * (4 * r[near] + 1), shift)
    assert np.abs(got.vertices[near] - want).max() <= 1e-14


@pytest.mark.parametrize("constraints,match", [
    ([{"center": [0, 0, 0], "radius": 0, "displacement": [0, 0, 1]}],
     "deformation constraint 0: the radius must be positive"),
    ([{"center": [0, 0, 0], "radius": 1, "displacement": [0, 0, 1]},
      {"center": [0, 0, 0], "radius": 2, "displacement": [0, 0, 1]}],
     "deformation constraint 1: its centre coincides with constraint 0's"),
    ([{"center": [0, 0], "radius": 1, "displacement": [0, 0, 0]}],
     "constraint 0: \"center\" must have 3 numbers"),
    ([{"center": [0, 0, 0], "radius": True, "displacement": [0, 0, 0]}],
     "constraint 0: \"radius\" must be a number"),
    ([{"center": [0, 0, 0], "radius": 1, "displacement": [0, 0, 0], "kind": "point"}],
     "constraint 0: unknown field \"kind\""),
])
def test_bad_deformations_are_named(constraints, match):
    with pytest.raises(subd.MeshError, match=match):
        subd.deform(subd.read(CUBE), constraints)


def test_no_deformation_constraint_leaves_the_mesh_as_it_was():
    base = subd.read(CUBE)
    assert np.array_equal(subd.deform(base, []).vertices, base.vertices)


# --- whatever the options, a result or a documented exception ----------------------------

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings, strategies as st  # noqa: E402

_floats = st.floats(allow_nan=True, allow_infinity=True, width=64)
_small = st.floats(-2, 2)
# Mapped so that a `one_of` holding it counts it as one choice (nested `one_of`s are
# flattened, which would make junk most of every mix).
_junk = st.one_of(st.none(), st.booleans(), st.integers(-(2**64), 2**64), _floats,
                  st.text(max_size=4)).map(lambda x: x)
_vec = st.one_of(st.lists(_small, min_size=3, max_size=3),
                 st.lists(_floats, min_size=3, max_size=3),
                 st.lists(st.integers(-3, 3), min_size=0, max_size=4), _junk)
_MESHES = {}


def mesh(path):
    """The mesh of `path`, read once."""
    if path not in _MESHES:
        _MESHES[path] = subd.read(path)
    return _MESHES[path]


def documented(call):
    """`call()` returns, or raises one of the documented exceptions (never a pyo3
    PanicException, a BaseException)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", subd.SubdWarning)
        try:
            call()
        except (subd.SubdError, ValueError, TypeError):
            pass


# Each example: valid options (so that most examples reach the solvers), then a few of
# them spoiled with junk or with values valid elsewhere.
_cases = st.sampled_from([(CUBE, "catmull-clark"), (CUBE, "two-phase:0.6"),
                          (ICOSAHEDRON, "loop"), (ICOSAHEDRON, "catmull-clark")])
_spoiler = st.one_of(
    _junk, st.floats(0.3, 1.1), st.lists(st.integers(-1, 12), max_size=5),
    st.lists(st.booleans(), min_size=8, max_size=8), st.lists(st.floats(0.2, 1.2), max_size=12),
    st.sampled_from(["catmull-clark", "loop", "two-phase", "sqrt3", "loop:x", "energy",
                     "all", "direct"]),
)
_pia_options = st.fixed_dictionaries({
    "solver": st.sampled_from(["auto", "iterate", "weighted", "cg", "chebyshev", "direct"]),
    "tol": st.floats(1e-14, 1e-2),
    "max_iter": st.integers(0, 60),
    "moving": st.one_of(st.none(), st.lists(st.integers(0, 7), max_size=8)),
    "allow_any_lambda": st.booleans(),
})


def spoiled(names):
    return st.dictionaries(st.sampled_from(names), _spoiler, max_size=2)


@settings(max_examples=300, deadline=None)
@given(case=_cases, options=_pia_options,
       spoil=spoiled(["scheme", "solver", "tol", "max_iter", "moving", "fixed", "lam",
                      "allow_any_lambda"]))
def test_no_pia_option_crashes(case, options, spoil):
    path, scheme = case
    kwargs = {"scheme": scheme, **options, **spoil}
    if isinstance(kwargs["max_iter"], int) and kwargs["max_iter"] > 60:
        kwargs["max_iter"] = 60  # a huge count with an unreachable tol would only take long
    documented(lambda: subd.pia(mesh(path), **kwargs))


def _point(faces, vertices):
    at = st.one_of(
        st.fixed_dictionaries({"vertex": st.integers(0, vertices - 1)}),
        st.fixed_dictionaries({"face": st.integers(0, faces - 1), "uv": st.lists(
            st.floats(0, 1), min_size=2, max_size=2)}),
    )
    goal = st.sampled_from(["target", "displacement"])
    return st.builds(lambda at, g, x: {"kind": "point", **at, g: x}, at, goal,
                     st.lists(_small, min_size=3, max_size=3))


def _normal(faces, vertices):
    return _point(faces, vertices).map(
        lambda p: {k: v for k, v in p.items() if k not in ("target", "displacement")}
    ).flatmap(lambda p: st.lists(_small, min_size=3, max_size=3).map(
        lambda n: {**p, "kind": "normal", "normal": n}))


def _isoline(faces):
    controls = st.lists(st.lists(_small, min_size=3, max_size=3), min_size=faces + 2,
                        max_size=faces + 4)
    line = st.fixed_dictionaries({
        "kind": st.just("isoline"), "face": st.integers(0, 5),
        "along": st.sampled_from(["u", "v"]), "at": st.floats(0, 1),
        "faces": st.just(faces),
    })
    goal = st.sampled_from(["targets", "displacements"])
    return st.builds(lambda c, g, x: {**c, g: x}, line, goal, controls)


def _constraints(path):
    faces, vertices = (6, 8) if path == CUBE else (20, 12)
    one = st.one_of(_point(faces, vertices), _normal(faces, vertices),
                    st.integers(0, 2).flatmap(_isoline))
    return st.lists(one, min_size=1, max_size=3)


_messy_constraint = st.dictionaries(
    st.sampled_from(["kind", "vertex", "face", "sub", "uv", "normal", "target", "along",
                     "colour"]), st.one_of(_junk, st.just("point"), _vec), max_size=4)
_edit_options = st.fixed_dictionaries({
    "method": st.sampled_from(["least-squares", "energy"]),
    "membrane": st.one_of(st.just(0.0), st.floats(0, 1)),
    "region_rings": st.one_of(st.integers(0, 3), st.just("all")),
})


@settings(max_examples=300, deadline=None)
@given(case=_cases.flatmap(lambda c: st.tuples(st.just(c), _constraints(c[0]))),
       options=_edit_options,
       spoil=st.one_of(spoiled(["scheme", "method", "penalty", "exact", "membrane",
                                "region_rings", "constraints"]),
                       st.fixed_dictionaries({"constraints": st.lists(_messy_constraint,
                                                                      max_size=3)})))
def test_no_edit_option_crashes(case, options, spoil):
    (path, scheme), constraints = case
    if options["method"] == "least-squares":
        options["membrane"] = 0.0
    scheme = "catmull-clark" if scheme.startswith("two-phase") else scheme
    kwargs = {"scheme": scheme, "constraints": constraints, **options, **spoil}
    documented(lambda: subd.edit(mesh(path), return_report=True, **kwargs))


_deformation = st.one_of(
    st.fixed_dictionaries({
        "center": st.lists(st.floats(-1, 2), min_size=3, max_size=3),
        "radius": st.floats(1e-3, 4),
        "displacement": st.lists(_small, min_size=3, max_size=3),
    }),
    st.fixed_dictionaries({}, optional={
        "center": _vec, "radius": st.one_of(_floats, _junk), "displacement": _vec,
        "kind": st.just("point")}),
)


@settings(max_examples=300, deadline=None)
@given(constraints=st.one_of(st.lists(_deformation.filter(lambda d: "kind" not in d),
                                      max_size=5),
                             st.lists(_deformation, max_size=5), _junk))
def test_no_deformation_crashes(constraints):
    documented(lambda: subd.deform(mesh(CUBE), constraints, return_report=True))
