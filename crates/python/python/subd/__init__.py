"""subd: subdivision surfaces with OpenSubdiv's rules, numpy arrays in and out.

>>> import numpy as np, subd
>>> cube = subd.Mesh(
...     [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
...     [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]],
... )
>>> fine = subd.refine(cube, "catmull-clark", levels=2)
>>> fine.faces.shape
(96, 4)

The work runs in Rust with the GIL released, on the package's thread pool
(:func:`set_num_threads`, or the environment variable ``SUBD_NUM_THREADS``).
"""

from __future__ import annotations

import os
from typing import Optional, Sequence, Tuple, Union

import numpy as np


class SubdError(Exception):
    """Base class of the errors subd raises."""


class MeshError(SubdError, ValueError):
    """An invalid mesh, tag or option; the message names the element."""


class FormatError(SubdError, ValueError):
    """A file that cannot be read; the message names the file and line."""


from . import _subd  # noqa: E402  (the exceptions above must exist first: Rust raises them)

SCHEMES: Tuple[str, ...] = tuple(_subd.SCHEMES)
"""The scheme names :func:`refine` and :func:`limit` take."""

__all__ = [
    "SCHEMES",
    "FormatError",
    "Mesh",
    "MeshError",
    "Refiner",
    "evaluate",
    "SubdError",
    "get_num_threads",
    "limit",
    "read",
    "refine",
    "set_num_threads",
    "tessellate",
]

_Faces = Union[np.ndarray, Sequence[Sequence[int]]]


def _index_array(values, what: str) -> np.ndarray:
    """``values`` as a C-contiguous int64 array, refusing what is not a whole number."""
    a = np.asarray(values)
    if a.size == 0:
        return np.zeros(a.shape, dtype=np.int64)
    if a.dtype.kind in "iu":
        if a.dtype.kind == "u" and a.dtype.itemsize == 8 and a.max() > np.iinfo(np.int64).max:
            raise MeshError(f"{what}: index {int(a.max())} out of range")
        return np.ascontiguousarray(a, dtype=np.int64)
    if a.dtype.kind == "b":
        raise MeshError(f"{what}: booleans are not indices")
    if a.dtype.kind == "f":
        if not np.all(np.isfinite(a)) or not np.all(a == np.round(a)):
            raise MeshError(f"{what}: indices must be whole numbers")
        if np.any(np.abs(a) > 2.0**62):
            raise MeshError(f"{what}: index out of range")
        return np.ascontiguousarray(a, dtype=np.int64)
    raise MeshError(f"{what}: expected integers, got dtype {a.dtype}")


def _float_array(values, what: str) -> np.ndarray:
    """``values`` as a C-contiguous float64 array."""
    a = np.asarray(values)
    if a.dtype.kind not in "iuf" and a.size:
        raise MeshError(f"{what}: expected numbers, got dtype {a.dtype}")
    return np.ascontiguousarray(a, dtype=np.float64)


def _flat_faces(faces: _Faces) -> Tuple[np.ndarray, np.ndarray]:
    """Face sizes and face-vertex indices from an (m, k) array or a sequence of faces."""
    if isinstance(faces, np.ndarray) and faces.ndim == 2:
        m, k = faces.shape
        return np.full(m, k, dtype=np.int64), _index_array(faces.reshape(-1), "faces")
    if isinstance(faces, np.ndarray) and faces.ndim != 1:
        raise MeshError(f"faces: expected an (m, k) array or a sequence of faces, got shape {faces.shape}")
    try:
        rows = [np.asarray(f).reshape(-1) for f in faces]
    except (TypeError, ValueError) as e:
        raise MeshError(f"faces: expected an (m, k) array or a sequence of faces ({e})") from None
    sizes = np.array([len(r) for r in rows], dtype=np.int64)
    flat = np.concatenate(rows) if rows else np.zeros(0, dtype=np.int64)
    return sizes, _index_array(flat, "faces")


class Mesh:
    """A polygon mesh with OpenSubdiv's tags.

    Parameters
    ----------
    vertices : (n, 3) array-like of float
    faces : (m, k) array of int, or a sequence of index sequences (mixed polygons)
    creases : (edges (k, 2) int, sharpness (k,) float), optional
        Edge sharpness; ``inf`` or 10 and above is infinitely sharp.
    corners : (vertices (c,) int, sharpness (c,) float), optional
    holes : sequence of face indices, optional
    """

    __slots__ = ("_core",)

    def __init__(
        self,
        vertices,
        faces: _Faces,
        *,
        creases: Optional[Tuple[object, object]] = None,
        corners: Optional[Tuple[object, object]] = None,
        holes=None,
    ) -> None:
        v = _float_array(vertices, "vertices")
        if v.ndim != 2 or v.shape[1] != 3:
            if not (v.size == 0 and v.ndim in (1, 2)):
                raise MeshError(f"vertices: expected an (n, 3) array, got shape {v.shape}")
            v = v.reshape(0, 3)
        sizes, flat = _flat_faces(faces)
        ce, cs = _pairs(creases, "creases", 2)
        vv, vs = _pairs(corners, "corners", 1)
        h = _index_array([] if holes is None else holes, "holes").reshape(-1)
        self._core = _subd._CoreMesh(v, sizes, flat, ce.reshape(-1, 2), cs, vv.reshape(-1), vs, h)

    @classmethod
    def _wrap(cls, core) -> "Mesh":
        mesh = cls.__new__(cls)
        mesh._core = core
        return mesh

    @property
    def vertices(self) -> np.ndarray:
        """Vertex positions, (n, 3) float64."""
        return self._core.vertices

    @property
    def normals(self) -> Optional[np.ndarray]:
        """Unit limit normals, (n, 3) float64, after ``refine(..., limit=True)``; else None."""
        return self._core.normals

    @property
    def face_sizes(self) -> np.ndarray:
        """Number of corners of every face, (m,) int64."""
        return self._core.face_sizes

    @property
    def face_vertices(self) -> np.ndarray:
        """Vertex indices of every face, one face after the other, (sum of sizes,) int64."""
        return self._core.face_vertices

    @property
    def faces(self) -> np.ndarray:
        """Faces as an (m, k) int64 array when every face has k corners."""
        sizes = self.face_sizes
        if sizes.size == 0:
            return np.zeros((0, 3), dtype=np.int64)
        if np.any(sizes != sizes[0]):
            raise ValueError(
                "faces of several sizes: use face_sizes and face_vertices (the flat pair)"
            )
        return self.face_vertices.reshape(-1, int(sizes[0]))

    @property
    def creases(self) -> Tuple[np.ndarray, np.ndarray]:
        """(edges (k, 2) int64, sharpness (k,) float64) of the edges with sharpness > 0."""
        return self._core.creases

    @property
    def corners(self) -> Tuple[np.ndarray, np.ndarray]:
        """(vertices (c,) int64, sharpness (c,) float64) of the vertices with sharpness > 0."""
        return self._core.corners

    @property
    def holes(self) -> np.ndarray:
        """Indices of the faces that are holes, int64."""
        return self._core.holes

    @property
    def num_vertices(self) -> int:
        return self._core.num_vertices

    @property
    def num_faces(self) -> int:
        return self._core.num_faces

    @property
    def num_edges(self) -> int:
        return self._core.num_edges

    def write(self, path: Union[str, os.PathLike]) -> None:
        """Writes the mesh: OBJ (with crease tags), PLY or glTF binary, by the extension."""
        self._core.write(os.fspath(path))

    def __repr__(self) -> str:
        return f"subd.Mesh({self.num_vertices} vertices, {self.num_faces} faces)"


def _pairs(pair, what: str, width: int) -> Tuple[np.ndarray, np.ndarray]:
    """(indices, sharpness) arrays of a crease or corner argument."""
    if pair is None:
        return np.zeros((0, width), dtype=np.int64), np.zeros(0, dtype=np.float64)
    try:
        indices, sharpness = pair
    except (TypeError, ValueError):
        raise MeshError(f"{what}: expected a pair (indices, sharpness)") from None
    i = _index_array(indices, what)
    s = _float_array(sharpness, f"{what} sharpness").reshape(-1)
    if width == 2 and i.size and (i.ndim != 2 or i.shape[1] != 2):
        raise MeshError(f"{what}: expected edges as a (k, 2) array, got shape {i.shape}")
    if i.size // width != s.size:
        raise MeshError(f"{what}: {i.size // width} elements but {s.size} sharpness values")
    return i.reshape(-1, width) if width == 2 else i.reshape(-1), s


def _check_mesh(mesh) -> None:
    if not isinstance(mesh, Mesh):
        raise TypeError(f"expected a subd.Mesh, got {type(mesh).__name__}")


def read(path: Union[str, os.PathLike], *, accept_inconsistent_orientation: bool = False) -> Mesh:
    """Reads an OBJ (with OpenSubdiv's crease, corner and hole tags), PLY or glTF file."""
    core, _warnings = _subd.read(os.fspath(path), bool(accept_inconsistent_orientation))
    return Mesh._wrap(core)


def _scheme_name(scheme: str, tension: Optional[float], lam: Optional[float]) -> str:
    if not isinstance(scheme, str):
        raise TypeError(f"scheme: expected a name such as 'catmull-clark', got {type(scheme).__name__}")
    if tension is not None and lam is not None:
        raise ValueError("tension is the butterfly's parameter and lam the two-phase scheme's: give one")
    parameter = tension if tension is not None else lam
    if parameter is None:
        return scheme
    if scheme not in ("butterfly", "two-phase"):
        raise ValueError(f"the {scheme} scheme takes no tension or lam")
    return f"{scheme}:{float(parameter)!r}"


def refine(
    mesh: Mesh,
    scheme: str = "catmull-clark",
    levels: int = 1,
    *,
    limit: bool = False,
    boundary: Optional[str] = None,
    crease_method: Optional[str] = None,
    triangles: Optional[str] = None,
    tension: Optional[float] = None,
    lam: Optional[float] = None,
) -> Mesh:
    """The mesh refined ``levels`` times with ``scheme`` (one of :data:`SCHEMES`).

    With ``limit=True`` the vertices are moved to the exact limit surface and the result
    has unit ``normals``. The rule options take the CLI's names and default to the mesh's
    own (its file's tags, else OpenSubdiv's defaults): ``boundary`` ``"none"``,
    ``"edge-only"`` or ``"edge-and-corner"``; ``crease_method`` ``"uniform"`` or
    ``"chaikin"``; ``triangles`` ``"catmark"`` or ``"smooth"``. ``tension`` is the
    butterfly's parameter, ``lam`` the two-phase scheme's.
    """
    _check_mesh(mesh)
    levels = _count(levels, "levels")
    name = _scheme_name(scheme, tension, lam)
    rules = _rule_names(boundary, crease_method, triangles)
    return Mesh._wrap(_subd.refine(mesh._core, name, levels, bool(limit), *rules))


def _rule_names(boundary, crease_method, triangles):
    for value, what in ((boundary, "boundary"), (crease_method, "crease_method"),
                        (triangles, "triangles")):
        if value is not None and not isinstance(value, str):
            raise TypeError(f"{what}: expected a name, got {type(value).__name__}")
    return boundary, crease_method, triangles


class Refiner:
    """A mesh's topology refined once, for many position sets or other per-vertex data.

    >>> r = subd.Refiner(mesh, "loop", 2)                 # doctest: +SKIP
    >>> frames = [r.apply(p) for p in animation]          # doctest: +SKIP

    ``apply(values)`` refines an (n, k) float array of per-vertex values (positions,
    colours, any columns) to the last level; with three columns the result is exactly
    :func:`refine`'s positions for those vertices. ``stencil_matrix(level=None)`` gives the
    weights from the base vertices to a level as a ``scipy.sparse.csr_matrix`` when SciPy
    is installed, else as ``(indptr, indices, weights)``.
    """

    __slots__ = ("_core", "levels")

    def __init__(
        self,
        mesh: Mesh,
        scheme: str = "catmull-clark",
        levels: int = 1,
        *,
        boundary: Optional[str] = None,
        crease_method: Optional[str] = None,
        triangles: Optional[str] = None,
        tension: Optional[float] = None,
        lam: Optional[float] = None,
    ) -> None:
        _check_mesh(mesh)
        self.levels = _count(levels, "levels")
        name = _scheme_name(scheme, tension, lam)
        rules = _rule_names(boundary, crease_method, triangles)
        self._core = _subd._CoreRefiner(mesh._core, name, self.levels, *rules)

    @property
    def num_vertices(self) -> int:
        """Vertices of the last level."""
        return self._core.num_vertices

    def apply(self, values) -> np.ndarray:
        """(n, k) per-vertex values of the base mesh refined to the last level: (n_L, k)."""
        a = _float_array(values, "values")
        one_column = a.ndim == 1
        if one_column:
            a = a.reshape(-1, 1)
        if a.ndim != 2:
            raise ValueError(f"values: expected an (n, k) array, got shape {a.shape}")
        out = self._core.apply(np.ascontiguousarray(a))
        return out.reshape(-1) if one_column else out

    def stencil_matrix(self, level: Optional[int] = None):
        """The weights from the base vertices to ``level`` (default the last)."""
        if level is not None:
            level = _count(level, "level")
        indptr, indices, weights, shape = self._core.stencil_matrix(level)
        try:
            import scipy.sparse
        except ImportError:
            return indptr, indices, weights
        return scipy.sparse.csr_matrix((weights, indices, indptr), shape=shape)


def limit(mesh: Mesh, scheme: str = "catmull-clark") -> Tuple[np.ndarray, np.ndarray]:
    """(positions, normals), both (n, 3) float64: the exact limit of every vertex."""
    _check_mesh(mesh)
    return _subd.limit(mesh._core, _scheme_name(scheme, None, None))


def evaluate(
    mesh: Mesh,
    scheme: str,
    faces,
    u,
    v,
    *,
    sub=None,
    derivatives: bool = False,
):
    """The exact limit surface at ``(faces[i], u[i], v[i])``, vectorised.

    ``u`` and ``v`` lie in [0, 1] (a quad's corners 0, 1, 2, 3 at (0, 0), (1, 0), (1, 1),
    (0, 1); a Loop triangle's at (0, 0), (1, 0), (0, 1)). ``sub`` picks the corner quad of
    a Catmull-Clark face that is not a quad (OpenSubdiv's ptex convention; default 0).
    Returns ``(positions, normals)``, each (m, 3); with ``derivatives=True`` also ``du``,
    ``dv``, ``duu``, ``duv`` and ``dvv``.
    """
    _check_mesh(mesh)
    f = _index_array(faces, "faces").reshape(-1)
    s = np.zeros_like(f) if sub is None else _index_array(sub, "sub").reshape(-1)
    uu = _float_array(u, "u").reshape(-1)
    vv = _float_array(v, "v").reshape(-1)
    if s.size == 1 and f.size != 1:
        s = np.full_like(f, int(s[0]))
    out = _subd.evaluate(mesh._core, _scheme_name(scheme, None, None), f, s, uu, vv,
                         bool(derivatives))
    return tuple(out)


def tessellate(mesh: Mesh, scheme: str = "catmull-clark", rate: int = 4) -> Mesh:
    """The limit surface sampled ``rate`` times along every edge: a watertight mesh of
    quads (Catmull-Clark) or triangles (Loop) with unit ``normals``."""
    _check_mesh(mesh)
    rate = _count(rate, "rate")
    return Mesh._wrap(_subd.tessellate(mesh._core, _scheme_name(scheme, None, None), rate))


def _count(n, what: str) -> int:
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
        raise TypeError(f"{what}: expected a whole number, got {type(n).__name__}")
    if n < 0:
        raise ValueError(f"{what}: {n} is negative")
    return int(n)


def set_num_threads(n: int) -> None:
    """Sets the number of threads subd's calls use (0: one per core)."""
    _subd.set_num_threads(_count(n, "threads"))


def get_num_threads() -> int:
    """The number of threads subd's calls use."""
    return _subd.get_num_threads()
