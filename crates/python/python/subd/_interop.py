"""Meshes to and from trimesh and PyVista (optional imports: neither is a dependency).

Both libraries keep one texture coordinate (and one normal) per vertex, where subd keeps a
face-varying channel with seams: going out, a vertex is split wherever its corners carry
different texture coordinates, as trimesh and VTK do themselves when they load a file with
seams; coming in, a per-vertex channel is taken as one index per corner.
"""

from __future__ import annotations

from typing import Optional, Tuple

import numpy as np


def _import(name: str, what: str):
    try:
        return __import__(name)
    except ImportError:
        raise ImportError(f"{what} needs {name} (pip install {name})") from None


def _surface_corners(mesh) -> Tuple[np.ndarray, np.ndarray]:
    """(face sizes, corner mask) of the faces that are not holes (holes are no surface)."""
    sizes = mesh.face_sizes
    keep = np.ones(len(sizes), dtype=bool)
    keep[mesh.holes] = False
    return sizes[keep], np.repeat(keep, sizes)


def _split_at_seams(mesh) -> Tuple[np.ndarray, np.ndarray, np.ndarray, Optional[np.ndarray],
                                   Optional[np.ndarray]]:
    """(vertices, face sizes, face_vertices, per-vertex uvs or None, per-vertex normals or
    None) of the faces that are not holes: a vertex whose corners carry different texture
    coordinates is split into one vertex per coordinate; without texture coordinates
    nothing is split."""
    sizes, corners = _surface_corners(mesh)
    vertices, normals = mesh.vertices, mesh.normals
    fv = mesh.face_vertices.astype(np.int64)[corners]
    if mesh.uvs is None:
        return vertices, sizes, fv, None, normals
    pairs = np.stack([fv, mesh.uv_indices.astype(np.int64)[corners]], axis=1)
    unique, corner_to_new = np.unique(pairs, axis=0, return_inverse=True)
    corner_to_new = corner_to_new.reshape(-1)
    source, uv = unique[:, 0], unique[:, 1]
    # Vertices no face uses keep their place at the end (no texture coordinate: zero).
    unused = np.setdiff1d(np.arange(len(vertices)), source)
    source = np.concatenate([source, unused])
    uvs = np.concatenate([mesh.uvs[uv], np.zeros((len(unused), 2))])
    split_normals = None if normals is None else normals[source]
    return vertices[source], sizes, corner_to_new, uvs, split_normals


def _triangulated(sizes: np.ndarray, fv: np.ndarray) -> np.ndarray:
    """(t, 3) triangles fanning every face from its first corner (trimesh holds triangles)."""
    if sizes.size and np.all(sizes == 3):
        return fv.reshape(-1, 3)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    fans = sizes - 2
    first = np.repeat(starts, fans)
    # The k-th triangle of a face: corners 0, k+1, k+2.
    k = np.arange(fans.sum()) - np.repeat(np.cumsum(fans) - fans, fans)
    return np.stack([fv[first], fv[first + k + 1], fv[first + k + 2]], axis=1)


def to_trimesh(mesh):
    """``mesh`` as a ``trimesh.Trimesh`` (triangles: other faces fanned from their first
    corner; holes left out), with its texture coordinates (vertices split at seams) and
    limit normals."""
    trimesh = _import("trimesh", "to_trimesh")
    vertices, sizes, fv, uvs, normals = _split_at_seams(mesh)
    faces = _triangulated(sizes, fv)
    visual = None if uvs is None else trimesh.visual.TextureVisuals(uv=uvs)
    return trimesh.Trimesh(vertices=np.array(vertices), faces=faces, visual=visual,
                           vertex_normals=None if normals is None else np.array(normals),
                           process=False)


def from_trimesh(cls, tm, **options):
    """A mesh of a ``trimesh.Trimesh``'s vertices and faces, with its texture coordinates
    where its visual has them (one per vertex)."""
    vertices = getattr(tm, "vertices", None)
    faces = getattr(tm, "faces", None)
    if vertices is None or faces is None:
        raise TypeError(f"from_trimesh: expected a trimesh.Trimesh, got {type(tm).__name__}")
    faces = np.asarray(faces)
    uv = getattr(getattr(tm, "visual", None), "uv", None)
    if uv is not None and len(uv) == len(vertices):
        options.setdefault("uvs", np.asarray(uv, dtype=np.float64))
        options.setdefault("uv_indices", faces.reshape(-1))
    return cls(np.asarray(vertices), faces, **options)


def to_pyvista(mesh):
    """``mesh`` as a ``pyvista.PolyData`` (every polygon but holes), with its texture coordinates
    (vertices split at seams) and limit normals as point data ``Normals``."""
    pv = _import("pyvista", "to_pyvista")
    vertices, sizes, fv, uvs, normals = _split_at_seams(mesh)
    cells = np.empty(len(sizes) + len(fv), dtype=np.int64)
    heads = np.arange(len(sizes)) + np.concatenate([[0], np.cumsum(sizes)[:-1]])
    cells[heads] = sizes
    body = np.ones(len(cells), dtype=bool)
    body[heads] = False
    cells[body] = fv
    poly = pv.PolyData(np.array(vertices), faces=cells)
    if uvs is not None:
        poly.active_texture_coordinates = uvs
    if normals is not None:
        poly.point_data["Normals"] = np.array(normals)
        poly.point_data.active_normals_name = "Normals"
    return poly


def from_pyvista(cls, data, **options):
    """A mesh of a ``pyvista.PolyData``'s points and polygons (any other dataset: its
    surface), with its active texture coordinates (one per point)."""
    pv = _import("pyvista", "from_pyvista")
    if not isinstance(data, pv.DataSet):
        raise TypeError(f"from_pyvista: expected a pyvista dataset, got {type(data).__name__}")
    poly = data if isinstance(data, pv.PolyData) else data.extract_surface()
    if poly.n_strips:
        raise ValueError("from_pyvista: the PolyData has triangle strips; call .triangulate() "
                         "or strips_to_polys first")
    polys = poly.GetPolys()
    offsets = pv.convert_array(polys.GetOffsetsArray())
    fv = pv.convert_array(polys.GetConnectivityArray())
    sizes = np.diff(np.asarray(offsets, dtype=np.int64))
    fv = np.asarray(fv, dtype=np.int64)
    uv = poly.active_texture_coordinates
    if uv is not None:
        options.setdefault("uvs", np.asarray(uv, dtype=np.float64))
        options.setdefault("uv_indices", fv)
    faces = fv.reshape(-1, sizes[0]) if sizes.size and np.all(sizes == sizes[0]) else \
        np.split(fv, np.cumsum(sizes)[:-1])
    return cls(np.asarray(poly.points, dtype=np.float64), faces, **options)
