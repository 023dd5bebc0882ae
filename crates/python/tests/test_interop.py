"""subd.Mesh to and from trimesh and PyVista: each checked against what the other library
itself computes or loads (areas, counts, its own OBJ reader), and by round trips."""

import pathlib

import numpy as np
import pytest

import subd

trimesh = pytest.importorskip("trimesh")
pv = pytest.importorskip("pyvista")

ROOT = pathlib.Path(__file__).resolve().parents[3]
SHAPES = ROOT.parent / "shared" / "meshes" / "osd"

CUBE_V = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
    dtype=float,
)
CUBE_F = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])


def polygon_area(mesh):
    """Total area of the triangles fanning each polygon from its first corner, computed here."""
    v, sizes, fv = mesh.vertices, mesh.face_sizes, mesh.face_vertices.astype(np.int64)
    total, at = 0.0, 0
    for n in sizes:
        p = v[fv[at:at + n]]
        total += 0.5 * np.linalg.norm(np.cross(p[1:-1] - p[0], p[2:] - p[0]), axis=1).sum()
        at += n
    return total


def test_trimesh_round_trip_keeps_the_surface():
    fine = subd.refine(subd.Mesh(CUBE_V, CUBE_F), "catmull-clark", 2)
    tm = fine.to_trimesh()
    assert isinstance(tm, trimesh.Trimesh)
    # Quads fanned into two triangles each, nothing merged or reordered.
    assert tm.faces.shape == (2 * fine.num_faces, 3)
    assert np.array_equal(tm.vertices, fine.vertices)
    assert tm.is_watertight and tm.is_winding_consistent
    assert tm.area == pytest.approx(polygon_area(fine), rel=1e-12)
    back = subd.Mesh.from_trimesh(tm)
    assert np.array_equal(back.vertices, fine.vertices)
    assert np.array_equal(back.faces, tm.faces)


def test_from_trimesh_refines_as_the_arrays_do():
    tm = trimesh.creation.icosphere(subdivisions=1)
    mesh = subd.Mesh.from_trimesh(tm, index_dtype=np.int32)
    assert mesh.faces.dtype == np.int32
    want = subd.refine(subd.Mesh(tm.vertices, tm.faces), "loop", 2)
    got = subd.refine(mesh, "loop", 2)
    assert np.array_equal(got.vertices, want.vertices)
    assert np.array_equal(got.faces, want.faces)


def test_texture_seams_split_vertices_and_come_back():
    # A cube whose six faces each take the whole texture: every vertex sits on seams.
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    cube = subd.Mesh(CUBE_V, CUBE_F, uvs=uvs, uv_indices=np.tile([0, 1, 2, 3], 6))
    tm = cube.to_trimesh()
    # trimesh keeps one coordinate per vertex: one vertex per distinct (vertex, uv) corner.
    pairs = {(int(v), k % 4) for k, v in enumerate(CUBE_F.reshape(-1))}
    assert len(tm.vertices) == len(pairs) > 8 and tm.visual.uv.shape == (len(pairs), 2)
    # Every triangle corner carries the coordinate its quad corner had.
    corners = tm.faces.reshape(-1, 3)
    fanned = np.array([[0, 1, 2], [0, 2, 3]])
    want = np.concatenate([uvs[fanned].reshape(-1, 2) for _ in range(6)])
    assert np.array_equal(tm.visual.uv[corners.reshape(-1)], want)
    assert np.allclose(tm.vertices[corners.reshape(-1)],
                       CUBE_V[np.concatenate([f[fanned].reshape(-1) for f in CUBE_F])])
    back = subd.Mesh.from_trimesh(tm)
    assert back.uvs is not None
    assert np.array_equal(back.uvs[back.uv_indices], tm.visual.uv[tm.faces.reshape(-1)])


def test_trimesh_loads_the_same_obj():
    obj = SHAPES / "catmark_cube.obj"
    tm = trimesh.load(obj, process=False, force="mesh")
    mesh = subd.Mesh.from_trimesh(tm)
    # trimesh triangulates the quads on loading; the area is the file's either way.
    assert mesh.num_vertices == len(tm.vertices)
    assert polygon_area(subd.read(obj)) == pytest.approx(tm.area, rel=1e-12)


def test_pyvista_round_trip_keeps_every_polygon():
    mixed = subd.Mesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0.5, 0]],
                      [[0, 1, 2, 3], [1, 4, 2]])
    poly = mixed.to_pyvista()
    assert isinstance(poly, pv.PolyData)
    assert poly.n_cells == 2 and poly.n_points == 5
    assert np.array_equal(poly.faces, [4, 0, 1, 2, 3, 3, 1, 4, 2])
    assert poly.area == pytest.approx(polygon_area(mixed), rel=1e-12)
    back = subd.Mesh.from_pyvista(poly)
    assert np.array_equal(back.face_sizes, [4, 3])
    assert np.array_equal(back.face_vertices, mixed.face_vertices)
    assert np.array_equal(back.vertices, mixed.vertices)


def test_pyvista_carries_normals_and_texture_coordinates():
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    cube = subd.Mesh(CUBE_V, CUBE_F, uvs=uvs, uv_indices=np.tile([0, 1, 2, 3], 6))
    smooth = subd.refine(cube, "catmull-clark", 1, limit=True)
    poly = smooth.to_pyvista()
    assert poly.active_texture_coordinates is not None
    assert np.allclose(np.linalg.norm(poly.point_data["Normals"], axis=1), 1.0)
    # VTK's own normals of the refined surface point the same way as the limit normals.
    vtk_normals = poly.compute_normals(cell_normals=False, split_vertices=False,
                                       consistent_normals=False).point_data["Normals"]
    assert np.all(np.einsum("ij,ij->i", vtk_normals, poly.point_data["Normals"]) > 0.8)
    back = subd.Mesh.from_pyvista(poly)
    # Each corner keeps its texture coordinate (VTK may hold them in single precision).
    assert np.allclose(back.uvs[back.uv_indices], smooth.uvs[smooth.uv_indices], atol=1e-7)


def test_from_pyvista_takes_pyvista_shapes_and_refuses_others():
    sphere = pv.Sphere(theta_resolution=12, phi_resolution=8)
    mesh = subd.Mesh.from_pyvista(sphere)
    assert mesh.num_faces == sphere.n_cells and mesh.num_vertices == sphere.n_points
    assert polygon_area(mesh) == pytest.approx(sphere.area, rel=1e-12)
    with pytest.raises(TypeError, match="from_pyvista"):
        subd.Mesh.from_pyvista(np.zeros((3, 3)))
    with pytest.raises(TypeError, match="from_trimesh"):
        subd.Mesh.from_trimesh(object())


def test_holes_are_left_out_going_out():
    cube = subd.Mesh(CUBE_V, CUBE_F, holes=[1])
    fine = subd.refine(cube, "catmull-clark", 1)
    assert len(fine.holes) == 4
    tm = fine.to_trimesh()
    poly = fine.to_pyvista()
    assert len(tm.faces) == 2 * (fine.num_faces - 4) and poly.n_cells == fine.num_faces - 4
    # An open box: the area of the faces that are not holes.
    keep = np.setdiff1d(np.arange(fine.num_faces), fine.holes)
    assert not tm.is_watertight
    assert tm.area == pytest.approx(polygon_area(subd.Mesh(fine.vertices, fine.faces[keep])),
                                    rel=1e-12)
