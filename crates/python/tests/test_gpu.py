"""device="gpu" against the CPU: subd.Refiner.apply and subd.PatchTable.evaluate on the
device (Mesa's lavapipe in CI) within 1e-6 of the size of the CPU's f64 results, and the
failures: no adapter, exact end caps, an unknown device."""

import os
import pathlib
import subprocess
import sys
import warnings

import numpy as np
import pytest

import subd

SHAPES = pathlib.Path(__file__).resolve().parents[3].parent / "shared" / "meshes" / "osd"


def _has_adapter() -> bool:
    try:
        subd.Refiner(subd.read(SHAPES / "catmark_cube.obj"), "catmull-clark", 1, device="gpu")
        return True
    except subd.DeviceError as e:
        if os.environ.get("CI"):
            raise AssertionError(f"CI needs a GPU adapter (mesa-vulkan-drivers): {e}")
        print(f"SKIPPED: no GPU adapter ({e})", file=sys.stderr)
        return False


needs_adapter = pytest.mark.skipif(not _has_adapter(), reason="no GPU adapter")


def _size(points) -> float:
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))


@needs_adapter
@pytest.mark.parametrize("shape,scheme", [("catmark_car", "catmull-clark"),
                                          ("catmark_cube_creases2", "catmull-clark"),
                                          ("loop_xord_boundary", "loop")])
def test_refiner_on_the_gpu_applies_as_on_the_cpu(shape, scheme):
    mesh = subd.read(SHAPES / f"{shape}.obj")
    cpu = subd.Refiner(mesh, scheme, 3)
    gpu = subd.Refiner(mesh, scheme, 3, device="gpu")
    assert (cpu.device, gpu.device) == ("cpu", "gpu")
    tolerance = 1e-6 * _size(mesh.vertices)
    assert np.abs(gpu.apply(mesh.vertices) - cpu.apply(mesh.vertices)).max() <= tolerance
    # Four columns (a colour with alpha), and a second frame through the same refiner.
    colours = np.random.default_rng(1).random((len(mesh.vertices), 4))
    assert np.abs(gpu.apply(colours) - cpu.apply(colours)).max() <= 1e-6
    moved = mesh.vertices * 1.5 + 2.0
    assert np.abs(gpu.apply(moved) - cpu.apply(moved)).max() <= 1e-6 * _size(moved)


@needs_adapter
@pytest.mark.parametrize("shape,scheme", [("catmark_car", "catmull-clark"),
                                          ("loop_xord_interior", "loop")])
def test_patch_table_on_the_gpu_evaluates_as_on_the_cpu(shape, scheme):
    mesh = subd.read(SHAPES / f"{shape}.obj")
    cpu = subd.PatchTable(mesh, scheme, isolation=3)
    gpu = subd.PatchTable(mesh, scheme, isolation=3, device="gpu")
    assert gpu.device == "gpu"
    rng = np.random.default_rng(7)
    n = 500
    faces = rng.integers(0, mesh.num_faces, n)
    u, v = rng.random(n), rng.random(n)
    if scheme == "loop":
        u, v = u * (1 - v), v  # inside the triangle
    tolerance = 1e-6 * _size(mesh.vertices)
    got, want = gpu.evaluate(faces, u, v), cpu.evaluate(faces, u, v)
    assert np.abs(got[0] - want[0]).max() <= tolerance
    # Derivatives scale with the patch's depth; their f32 rounding with their size.
    for g, w in zip(got[1:], want[1:]):
        assert np.abs(g - w).max() <= tolerance * max(1.0, np.abs(w).max())
    moved = mesh.vertices + np.array([0.0, 0.5, 0.25]) * _size(mesh.vertices)
    cpu.update(moved)
    gpu.update(moved)
    got, want = gpu.evaluate(faces, u, v)[0], cpu.evaluate(faces, u, v)[0]
    assert np.abs(got - want).max() <= 1e-6 * _size(moved)
    with pytest.raises(ValueError, match="second derivatives"):
        gpu.evaluate(faces, u, v, derivatives=True)
    # device="auto" answers second derivatives on the CPU instead.
    auto = subd.PatchTable(mesh, scheme, isolation=3, device="auto")
    auto.update(moved)
    second = auto.evaluate(faces, u, v, derivatives=True)
    assert len(second) == 6
    assert np.abs(second[3] - cpu.evaluate(faces, u, v, derivatives=True)[3]).max() == 0.0


@needs_adapter
def test_what_the_device_cannot_do_is_said():
    mesh = subd.read(SHAPES / "catmark_cube.obj")
    with pytest.raises(subd.DeviceError, match="exact end caps"):
        subd.PatchTable(mesh, "catmull-clark", isolation=2, end_caps="exact", device="gpu")
    with pytest.warns(subd.SubdWarning, match="exact end caps"):
        table = subd.PatchTable(mesh, "catmull-clark", isolation=2, end_caps="exact",
                                device="auto")
    assert table.device == "cpu"
    with pytest.raises(ValueError, match="device"):
        subd.Refiner(mesh, "catmull-clark", 1, device="tpu")
    with pytest.raises(subd.MeshError):
        gpu = subd.PatchTable(mesh, "catmull-clark", isolation=2, device="gpu")
        gpu.evaluate([99], [0.5], [0.5])


def test_without_an_adapter_gpu_fails_and_auto_warns():
    """With the Vulkan loader pointed at no driver there is no adapter: device="gpu" raises
    DeviceError, device="auto" runs on the CPU with a SubdWarning (in a child process: the
    loader reads its environment once)."""
    script = (
        "import warnings, numpy as np, subd\n"
        f"m = subd.read({str(SHAPES / 'catmark_cube.obj')!r})\n"
        "try:\n"
        "    subd.Refiner(m, 'catmull-clark', 1, device='gpu')\n"
        "    raise SystemExit('no error')\n"
        "except subd.DeviceError as e:\n"
        "    assert 'no GPU adapter' in str(e), e\n"
        "with warnings.catch_warnings(record=True) as w:\n"
        "    warnings.simplefilter('always')\n"
        "    r = subd.Refiner(m, 'catmull-clark', 1, device='auto')\n"
        "assert r.device == 'cpu' and any(issubclass(x.category, subd.SubdWarning) for x in w)\n"
        "cpu = subd.Refiner(m, 'catmull-clark', 1)\n"
        "assert np.array_equal(r.apply(m.vertices), cpu.apply(m.vertices))\n"
        "print('ok')\n"
    )
    env = dict(os.environ, VK_ICD_FILENAMES="/nonexistent/icd.json",
               VK_DRIVER_FILES="/nonexistent/icd.json")
    out = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True,
                         text=True)
    assert out.returncode == 0 and "ok" in out.stdout, out.stderr


@needs_adapter
def test_auto_falls_back_to_the_cpu_when_the_device_cannot():
    """device="auto": values too wide for the device's buffers (lavapipe binds at most
    128 MB) run on the CPU with a SubdWarning, where device="gpu" raises DeviceError."""
    mesh = subd.read(SHAPES / "catmark_cube.obj")  # 8 vertices; 386 at level 3
    k = 90_000  # level 3 in f32: 386 * 90,000 * 4 bytes = 139 MB
    values = np.random.default_rng(2).random((8, k))
    auto = subd.Refiner(mesh, "catmull-clark", 3, device="auto")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        got = auto.apply(values)
    want = subd.Refiner(mesh, "catmull-clark", 3).apply(values)
    if os.environ.get("CI"):
        assert caught, "CI's lavapipe binds less than the level needs"
    if caught:
        assert "running on the CPU" in str(caught[0].message)
        assert np.array_equal(got, want)
        with pytest.raises(subd.DeviceError, match="limit"):
            subd.Refiner(mesh, "catmull-clark", 3, device="gpu").apply(values)
    else:
        assert np.abs(got - want).max() <= 1e-6
