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

import json
import os
import warnings
from typing import List, Optional, Sequence, Tuple, Union

import numpy as np


class SubdError(Exception):
    """Base class of the errors subd raises."""


class MeshError(SubdError, ValueError):
    """An invalid mesh, tag or option; the message names the element."""


class FormatError(SubdError, ValueError):
    """A file that cannot be read; the message names the file and line."""


class DeviceError(SubdError, RuntimeError):
    """The GPU path failed: no adapter, a lost device, a mesh past the device's buffer
    limits, or something the device does not do (a patch table with exact end caps)."""


class SubdWarning(UserWarning):
    """Something subd left out or changed and went on (a reader's repair, texture
    coordinates a scheme cannot carry)."""


from . import _subd  # noqa: E402  (the exceptions above must exist first: Rust raises them)
from . import _interop  # noqa: E402

SCHEMES: Tuple[str, ...] = tuple(_subd.SCHEMES)
"""The scheme names :func:`refine` and :func:`limit` take."""

__all__ = [
    "SCHEMES",
    "ConvergenceError",
    "DeviceError",
    "FormatError",
    "Mesh",
    "MeshError",
    "PatchTable",
    "Refiner",
    "evaluate",
    "SubdError",
    "SubdWarning",
    "adaptive",
    "deform",
    "edit",
    "info",
    "get_num_threads",
    "limit",
    "mesh_prims",
    "pia",
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


_INDEX_DTYPES = ("int64", "int32", "uint32")


def _index_dtype_name(dtype) -> str:
    """The name of an ``index_dtype`` argument (int64, int32 or uint32), or TypeError."""
    try:
        name = np.dtype(dtype).name
    except TypeError:
        name = None
    if name not in _INDEX_DTYPES:
        raise TypeError(f"index_dtype: expected np.int64, np.int32 or np.uint32, got {dtype!r}")
    return name


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
    uvs : (u, 2) array-like of float, optional
        Texture coordinates (a face-varying channel: seams allowed).
    uv_indices : int array-like, optional
        One index into ``uvs`` per face corner, face after face (an (m, k) array or the
        flat (sum of sizes,) form); required with ``uvs``.
    accept_inconsistent_orientation : bool
        Take an edge two faces use in the same direction (as OpenSubdiv does, making it
        non-manifold) instead of raising :class:`MeshError`, as :func:`read` does.
    index_dtype : numpy dtype, optional
        The integer type of the face (and texture-coordinate) indices the mesh hands out:
        ``np.int64`` (default, as trimesh and libigl take them), ``np.int32`` or
        ``np.uint32`` (half the memory). See :attr:`index_dtype`.

    A mesh is immutable: its properties are read-only arrays, the same array on every
    access, without copies where the library's buffer has numpy's type (:attr:`vertices`
    and :attr:`normals` are views of it, which keep the mesh alive). Make a new mesh from
    changed copies (``mesh.vertices.copy()``).
    """

    __slots__ = ("_core", "_arrays", "_index_dtype")

    def __init__(
        self,
        vertices,
        faces: _Faces,
        *,
        creases: Optional[Tuple[object, object]] = None,
        corners: Optional[Tuple[object, object]] = None,
        holes=None,
        uvs=None,
        uv_indices=None,
        accept_inconsistent_orientation: bool = False,
        index_dtype=np.int64,
    ) -> None:
        self._arrays = {}
        self._index_dtype = _index_dtype_name(index_dtype)
        v = _float_array(vertices, "vertices")
        if v.ndim != 2 or v.shape[1] != 3:
            if not (v.size == 0 and v.ndim in (1, 2)):
                raise MeshError(f"vertices: expected an (n, 3) array, got shape {v.shape}")
            v = v.reshape(0, 3)
        sizes, flat = _flat_faces(faces)
        ce, cs = _pairs(creases, "creases", 2)
        vv, vs = _pairs(corners, "corners", 1)
        h = _index_array([] if holes is None else holes, "holes").reshape(-1)
        uv, uvi = _uv_arrays(uvs, uv_indices)
        self._core = _subd._CoreMesh(
            v, sizes, flat, ce.reshape(-1, 2), cs, vv.reshape(-1), vs, h, uv, uvi,
            bool(accept_inconsistent_orientation),
        )

    @classmethod
    def _wrap(cls, core, index_dtype: str = "int64", face_vertices=None) -> "Mesh":
        """A mesh around ``core``, with its face-vertex indices when they were made already."""
        mesh = cls.__new__(cls)
        mesh._core = core
        mesh._arrays = {}
        mesh._index_dtype = index_dtype
        if face_vertices is not None:
            mesh._arrays["face_vertices"] = face_vertices
        return mesh

    def _kept(self, key: str, make):
        """The array (or tuple of arrays) ``make()`` gives, made once and kept read-only."""
        value = self._arrays.get(key)
        if value is None:
            value = make()
            for a in value if isinstance(value, tuple) else (value,):
                if isinstance(a, np.ndarray):
                    a.flags.writeable = False
            self._arrays[key] = value
        return value

    @property
    def index_dtype(self) -> np.dtype:
        """The integer type of :attr:`faces`, :attr:`face_vertices` and :attr:`uv_indices`:
        ``int64`` (default), ``int32`` or ``uint32``. Settable; the arrays are made afresh in
        the new type (``int32`` raises :class:`MeshError` past 2^31 vertices)."""
        return np.dtype(self._index_dtype)

    @index_dtype.setter
    def index_dtype(self, dtype) -> None:
        name = _index_dtype_name(dtype)
        if name != self._index_dtype:
            for key in ("face_vertices", "faces", "uv_indices"):
                self._arrays.pop(key, None)
            self._index_dtype = name

    @property
    def vertices(self) -> np.ndarray:
        """Vertex positions, (n, 3) float64: a read-only view of the mesh's own buffer."""
        return self._kept("vertices", lambda: self._core.vertices)

    @property
    def normals(self) -> Optional[np.ndarray]:
        """Unit limit normals, (n, 3) float64 (a read-only view), after
        ``refine(..., limit=True)``; else None."""
        if "normals" not in self._arrays:
            self._arrays["normals"] = self._core.normals
        return self._arrays["normals"]

    @property
    def face_sizes(self) -> np.ndarray:
        """Number of corners of every face, (m,) int64."""
        return self._kept("face_sizes", lambda: self._core.face_sizes)

    @property
    def face_vertices(self) -> np.ndarray:
        """Vertex indices of every face, one face after the other, (sum of sizes,), in
        :attr:`index_dtype`."""
        return self._kept("face_vertices", lambda: self._core.face_vertices(self._index_dtype))

    @property
    def faces(self) -> np.ndarray:
        """Faces as an (m, k) array in :attr:`index_dtype` when every face has k corners (a
        view of :attr:`face_vertices`)."""
        faces = self._arrays.get("faces")
        if faces is None:
            k = self._core.uniform_face_size()
            if k is None:
                raise ValueError(
                    "faces of several sizes: use face_sizes and face_vertices (the flat pair)"
                )
            faces = self._kept("faces", lambda: self.face_vertices.reshape(-1, k))
        return faces

    @property
    def uvs(self) -> Optional[np.ndarray]:
        """Texture coordinates, (u, 2) float64, or None."""
        if "uvs" not in self._arrays:
            self._arrays["uvs"] = self._core.uvs
            if self._arrays["uvs"] is not None:
                self._arrays["uvs"].flags.writeable = False
        return self._arrays["uvs"]

    @property
    def uv_indices(self) -> Optional[np.ndarray]:
        """One index into :attr:`uvs` per face corner, face after face, in
        :attr:`index_dtype`; or None."""
        if "uv_indices" not in self._arrays:
            self._arrays["uv_indices"] = self._core.uv_indices(self._index_dtype)
        return self._arrays["uv_indices"]

    @property
    def face_levels(self) -> Optional[np.ndarray]:
        """The refinement level of every face of an :func:`adaptive` result (uint8), else
        None."""
        if "face_levels" not in self._arrays:
            levels = self._core.face_levels
            if levels is not None:
                levels.flags.writeable = False
            self._arrays["face_levels"] = levels
        return self._arrays["face_levels"]

    @property
    def creases(self) -> Tuple[np.ndarray, np.ndarray]:
        """(edges (k, 2) int64, sharpness (k,) float64) of the edges with sharpness > 0."""
        return self._kept("creases", lambda: self._core.creases)

    @property
    def corners(self) -> Tuple[np.ndarray, np.ndarray]:
        """(vertices (c,) int64, sharpness (c,) float64) of the vertices with sharpness > 0."""
        return self._kept("corners", lambda: self._core.corners)

    @property
    def holes(self) -> np.ndarray:
        """Indices of the faces that are holes, int64."""
        return self._kept("holes", lambda: self._core.holes)

    @property
    def num_vertices(self) -> int:
        return self._core.num_vertices

    @property
    def num_faces(self) -> int:
        return self._core.num_faces

    @property
    def num_edges(self) -> int:
        return self._core.num_edges

    @property
    def file_scheme(self) -> Optional[str]:
        """The scheme the mesh's file names (USD's ``subdivisionScheme``): ``"catmull-clark"``,
        ``"loop"``, ``"bilinear"``, ``"none"`` (plain polygons), or None where it names none
        (OBJ, PLY, glTF, arrays). The functions that take a ``scheme`` use it when given
        none (else Catmull-Clark); :func:`pia` and :func:`edit` name theirs in their cage."""
        return self._core.file_scheme

    @property
    def stage(self) -> Optional[Tuple[str, Optional[float], Optional[str]]]:
        """``(prim path, metersPerUnit, upAxis)`` of the USD prim the mesh, or the mesh it was
        made from, was read from (units None where the stage authors none); None for other
        files. A USD output names its prim after the path and writes the units back."""
        return self._core.stage

    def write(self, path: Union[str, os.PathLike]) -> None:
        """Writes the mesh by the extension: OBJ (with crease tags), PLY, glTF binary, or USD
        (.usda, .usdc, .usdz, .usd: one Mesh prim with its scheme, rules and tags, named after
        the prim it was read from, with that stage's units; see :attr:`stage`).

        The result of :func:`pia` or :func:`edit` is a control cage and names its scheme; a
        USD file cannot name two-phase, Doo-Sabin, √3 or the butterflies, so it holds such a
        cage refined two levels as plain polygons, with a :class:`SubdWarning`."""
        _warn(self._core.write(os.fspath(path)))

    @classmethod
    def from_trimesh(cls, mesh, **options) -> "Mesh":
        """A mesh of a ``trimesh.Trimesh``: its vertices, faces and (where its visual has them,
        one per vertex) texture coordinates. ``options`` are the constructor's (``creases``,
        ``index_dtype``, ...)."""
        return _interop.from_trimesh(cls, mesh, **options)

    def to_trimesh(self):
        """The mesh as a ``trimesh.Trimesh`` (needs trimesh): faces other than triangles
        fanned from their first corner, texture coordinates as trimesh keeps them (one per
        vertex: vertices split at seams), limit normals as its vertex normals, holes left
        out. trimesh has no creases: they are left behind."""
        return _interop.to_trimesh(self)

    @classmethod
    def from_pyvista(cls, data, **options) -> "Mesh":
        """A mesh of a ``pyvista.PolyData`` (another dataset: its surface): its points,
        polygons and active texture coordinates. ``options`` are the constructor's."""
        return _interop.from_pyvista(cls, data, **options)

    def to_pyvista(self):
        """The mesh as a ``pyvista.PolyData`` (needs pyvista): every polygon as it is,
        texture coordinates as its active ones (vertices split at seams), limit normals as
        point data ``Normals``, holes left out. VTK has no creases: they are left behind."""
        return _interop.to_pyvista(self)

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


def _uv_arrays(uvs, uv_indices):
    """(uvs (u, 2) float64, indices int64) or (None, None)."""
    if uvs is None and uv_indices is None:
        return None, None
    if uvs is None or uv_indices is None:
        raise MeshError("uvs and uv_indices come together: give both or neither")
    uv = _float_array(uvs, "uvs")
    if uv.size == 0:
        uv = uv.reshape(0, 2)
    if uv.ndim != 2 or uv.shape[1] != 2:
        raise MeshError(f"uvs: expected a (u, 2) array, got shape {uv.shape}")
    return uv, _index_array(uv_indices, "uv_indices").reshape(-1)


def _warn(messages) -> None:
    for m in messages:
        warnings.warn(m, SubdWarning, stacklevel=3)


def _check_mesh(mesh) -> None:
    if not isinstance(mesh, Mesh):
        raise TypeError(f"expected a subd.Mesh, got {type(mesh).__name__}")


def read(
    path: Union[str, os.PathLike],
    *,
    accept_inconsistent_orientation: bool = False,
    no_transform: bool = False,
    weld_tolerance: Optional[float] = None,
    prim: Optional[str] = None,
    time: Optional[float] = None,
    index_dtype=np.int64,
) -> Mesh:
    """Reads an OBJ (with OpenSubdiv's crease, corner and hole tags, texture coordinates),
    PLY, glTF or USD (.usda, .usdc, .usdz, .usd) file. What the reader repaired or left out
    comes as :class:`SubdWarning`.

    The options are the CLI's: ``accept_inconsistent_orientation`` takes an edge two faces
    use in the same direction (non-manifold, as OpenSubdiv does) instead of raising;
    glTF and USD: ``no_transform`` reads each mesh as stored rather than placed by its
    nodes (prims); glTF only: ``weld_tolerance`` welds vertices closer than it (default:
    identical positions only); USD only: ``prim`` is the path of the mesh prim to read
    (default: the stage's only one) and ``time`` the time code at which time-sampled
    attributes are read (default: their default values). A USD mesh's scheme and rules
    (``subdivisionScheme``, ``interpolateBoundary``, creases, corners, holes,
    ``primvars:st``) are the mesh's, as for OBJ tags. ``index_dtype`` is the mesh's
    :attr:`Mesh.index_dtype`.
    """
    dtype = _index_dtype_name(index_dtype)
    weld = None if weld_tolerance is None else _threshold(weld_tolerance, "weld_tolerance")
    if prim is not None and not isinstance(prim, str):
        raise TypeError(f"prim: expected a prim path such as '/World/Body', got {type(prim).__name__}")
    at = None if time is None else float(time)
    core, messages = _subd.read(os.fspath(path), bool(accept_inconsistent_orientation),
                                bool(no_transform), weld, prim, at)
    _warn(messages)
    return Mesh._wrap(core, dtype)


def mesh_prims(path: Union[str, os.PathLike]) -> List[dict]:
    """The mesh prims of a USD stage (composed, in traversal order), as ``subd info`` lists
    them: dicts of ``path``, ``faces``, ``points`` and ``scheme`` (the
    ``subdivisionScheme`` token, ``catmullClark`` where not authored). Read one with
    ``read(path, prim=...)``. Raises :class:`FormatError` when the file is no stage."""
    return [{"path": p, "faces": f, "points": n, "scheme": s}
            for p, f, n, s in _subd.mesh_prims(os.fspath(path))]


def info(mesh: Mesh) -> dict:
    """What ``subd info --json`` reports: counts, face-size and valence histograms,
    boundaries, non-manifold elements, components, Euler characteristic and genus,
    irregular vertices, tags and the texture coordinates' seams."""
    _check_mesh(mesh)
    report = json.loads(_subd.info(mesh._core))
    for key in ("face_sizes", "valences"):
        report[key] = {int(k): v for k, v in report[key].items()}
    return report


def _scheme_name(scheme: Optional[str], tension: Optional[float], lam: Optional[float],
                 mesh: Optional["Mesh"] = None) -> str:
    if scheme is None:
        scheme = _file_scheme(mesh)
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


def _file_scheme(mesh: Optional["Mesh"]) -> str:
    """The scheme a mesh's file names (USD's ``subdivisionScheme``), else Catmull-Clark."""
    named = None if mesh is None else mesh._core.file_scheme
    if named == "none":
        raise ValueError("the mesh's file names no subdivision scheme (subdivisionScheme "
                         "none): give scheme=")
    return "catmull-clark" if named is None else named


def refine(
    mesh: Mesh,
    scheme: Optional[str] = None,
    levels: int = 1,
    *,
    limit: bool = False,
    boundary: Optional[str] = None,
    crease_method: Optional[str] = None,
    triangles: Optional[str] = None,
    fvar_interpolation: Optional[str] = None,
    tension: Optional[float] = None,
    lam: Optional[float] = None,
    index_dtype=None,
) -> Mesh:
    """The mesh refined ``levels`` times with ``scheme`` (one of :data:`SCHEMES`; by default
    the one the mesh's file names, :attr:`Mesh.file_scheme`, else Catmull-Clark, as every
    function here that takes a ``scheme``).

    With ``limit=True`` the vertices are moved to the exact limit surface and the result
    has unit ``normals``. The rule options take the CLI's names and default to the mesh's
    own (its file's tags, else OpenSubdiv's defaults): ``boundary`` ``"none"``,
    ``"edge-only"`` or ``"edge-and-corner"``; ``crease_method`` ``"uniform"`` or
    ``"chaikin"``; ``triangles`` ``"catmark"`` or ``"smooth"``. ``tension`` is the
    butterfly's parameter, ``lam`` the two-phase scheme's.

    Texture coordinates are refined with the mesh (to their limit too with ``limit``),
    interpolated as ``fvar_interpolation`` says: ``"none"``, ``"corners-only"``,
    ``"corners-plus1"`` (default, unless the mesh's file names one), ``"corners-plus2"``,
    ``"boundaries"`` or ``"all"``. Where Doo-Sabin or √3 cannot carry their seams they are
    left out with a :class:`SubdWarning`.

    The result's :attr:`Mesh.index_dtype` is ``index_dtype`` (default: the input's); for
    Catmull-Clark, Loop and Bilinear its face indices are written once, straight into the
    array :attr:`Mesh.faces` returns.
    """
    _check_mesh(mesh)
    levels = _count(levels, "levels")
    name = _scheme_name(scheme, tension, lam, mesh)
    rules = _rule_names(boundary, crease_method, triangles, fvar_interpolation)
    dtype = mesh._index_dtype if index_dtype is None else _index_dtype_name(index_dtype)
    core, messages, face_vertices = _subd.refine(mesh._core, name, levels, bool(limit), *rules,
                                                 dtype)
    _warn(messages)
    return Mesh._wrap(core, dtype, face_vertices)


def adaptive(
    mesh: Mesh,
    scheme: Optional[str] = None,
    *,
    flatness: Optional[float] = None,
    max_distance: Optional[float] = None,
    curvature: Optional[float] = None,
    dihedral: Optional[float] = None,
    select_faces=None,
    select_vertices=None,
    levels: int = 4,
    limit: bool = False,
    boundary: Optional[str] = None,
    crease_method: Optional[str] = None,
    triangles: Optional[str] = None,
    fvar_interpolation: Optional[str] = None,
) -> Mesh:
    """The mesh refined only where the criteria ask (Loop or Catmull-Clark), up to
    ``levels``, without cracks: every vertex is one of uniform refinement's (or, with
    ``limit=True``, on the exact limit surface, with unit ``normals``). The result's
    ``face_levels`` gives the level of every face.

    A face is refined when any criterion asks; with none, every face is refined to
    ``levels``. ``flatness``: Sun et al.'s test, degrees between the normals at a vertex.
    ``max_distance``: the largest distance to the limit surface, relative to the bounding-box
    diagonal. ``curvature``: Gaussian curvature times the squared diagonal (a sphere: 12).
    ``dihedral``: degrees. ``select_faces``: base faces whose descendants are refined;
    ``select_vertices``: base vertices, refining the faces with two or more of them. Texture
    coordinates are carried at their exact limit; the rule options are :func:`refine`'s.
    """
    _check_mesh(mesh)
    levels = _count(levels, "levels")
    thresholds = {
        "flatness": _threshold(flatness, "flatness"),
        "max_distance": _threshold(max_distance, "max_distance"),
        "curvature": _threshold(curvature, "curvature"),
        "dihedral": _threshold(dihedral, "dihedral"),
    }
    faces = None if select_faces is None else _index_array(select_faces, "select_faces").reshape(-1)
    verts = (None if select_vertices is None
             else _index_array(select_vertices, "select_vertices").reshape(-1))
    rules = _rule_names(boundary, crease_method, triangles, fvar_interpolation)
    core, messages = _subd.adaptive(mesh._core, _scheme_name(scheme, None, None, mesh), levels,
                                    bool(limit), thresholds, faces, verts, *rules)
    _warn(messages)
    return Mesh._wrap(core)


def analyze(
    mask=None,
    *,
    mask2=None,
    lattice: str = "quad",
    arity: int = 2,
    max_levels: int = 8,
    surface: Optional[str] = None,
    valence: Optional[int] = None,
    tension: Optional[float] = None,
) -> dict:
    """What ``subd analyze --json`` reports, as a dict; give exactly one of:

    * ``mask``: a univariate mask (coefficients by increasing power of z, summing to
      ``arity``, 2 or 3; fractions such as ``"1/16"`` are accepted): whether the scheme
      converges and how smooth it is shown to be (norms of the difference schemes for
      ``L = 1..max_levels``);
    * ``mask2``: a bivariate binary mask, a sequence of rows (row j holds the coefficients
      of z1^i z2^j), summing to 4, on ``lattice`` ``"quad"`` or ``"three-direction"``;
    * ``surface`` and ``valence``: the eigenvalue test of a surface scheme's local
      subdivision matrix at an interior vertex (``tension`` for the butterfly).
    """
    given = [x is not None for x in (mask, mask2, surface)]
    if sum(given) != 1:
        raise ValueError("give exactly one of mask, mask2 and surface")
    levels = _count(max_levels, "max_levels")
    if surface is not None:
        if valence is None:
            raise ValueError("surface needs a valence")
        name = _scheme_name(surface, tension, None)
        return json.loads(_subd.analyze_surface(name, _count(valence, "valence")))
    if mask is not None:
        coeffs = [_coefficient(c, "mask") for c in np.atleast_1d(np.asarray(mask, dtype=object))]
        return json.loads(_subd.analyze_mask(coeffs, _count(arity, "arity"), levels))
    rows = [[_coefficient(c, "mask2") for c in row] for row in mask2]
    if not isinstance(lattice, str):
        raise TypeError(f"lattice: expected a name, got {type(lattice).__name__}")
    return json.loads(_subd.analyze_mask2(rows, lattice, levels))


CURVE_SCHEMES: Tuple[str, ...] = tuple(_subd.CURVE_SCHEMES)
"""The curve scheme names :func:`curve` takes."""


def curve(
    points,
    scheme: str = "four-point",
    levels: int = 1,
    *,
    closed: bool = False,
    normals=None,
    omega: Optional[float] = None,
    mu: Optional[float] = None,
    order: Optional[int] = None,
    alpha0: Optional[float] = None,
):
    """A subdivision curve: ``points`` ((n, 2) or (n, 3)) refined ``levels`` times with
    ``scheme`` (one of :data:`CURVE_SCHEMES`), an open polyline unless ``closed``.

    The parameters are ``subd curve``'s and are refused where the scheme takes none:
    ``omega`` (4-point and ternary tension; default 1/16, 1/4 for the ternary schemes),
    ``mu`` (the two-parameter 4-point schemes), ``order`` (``bspline``, default 4) and
    ``alpha0`` (``tension``, default 1). Returns the points, with the input's columns; for
    the circle-average schemes (``circle-four-point``, ``circle-ternary``: planar points
    with normals, Liu et al.) returns ``(points, normals)``, the input's ``normals`` (n, 2)
    estimated from the polygon when not given.
    """
    p = _float_array(points, "points")
    if p.ndim != 2 or p.shape[1] not in (2, 3):
        raise MeshError(f"points: expected an (n, 2) or (n, 3) array, got shape {p.shape}")
    if not isinstance(scheme, str):
        raise TypeError(f"scheme: expected a name such as 'four-point', got {type(scheme).__name__}")
    n = None if normals is None else _float_array(normals, "normals")
    if n is not None and (n.ndim != 2 or n.shape[1] != 2):
        raise MeshError(f"normals: expected an (n, 2) array, got shape {n.shape}")
    parameters = (_threshold(omega, "omega"), _threshold(mu, "mu"),
                  None if order is None else _count(order, "order"), _threshold(alpha0, "alpha0"))
    out, out_normals = _subd.curve(p, scheme, _count(levels, "levels"), bool(closed), parameters, n)
    return out if out_normals is None else (out, out_normals)


def _coefficient(c, what: str) -> float:
    """A number, or a fraction written ``"p/q"``."""
    if isinstance(c, str):
        p, slash, q = c.partition("/")
        try:
            return float(p) / float(q) if slash else float(p)
        except (ValueError, ZeroDivisionError):
            raise MeshError(f"{what}: {c!r} is not a number") from None
    if isinstance(c, bool) or not isinstance(c, (int, float, np.integer, np.floating)):
        raise MeshError(f"{what}: {c!r} is not a number")
    return float(c)


def _threshold(value, what: str) -> Optional[float]:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{what}: expected a number, got {type(value).__name__}")
    return float(value)


def _rule_names(boundary, crease_method, triangles, fvar_interpolation=None):
    names = (boundary, crease_method, triangles, fvar_interpolation)
    for value, what in zip(names, ("boundary", "crease_method", "triangles",
                                   "fvar_interpolation")):
        if value is not None and not isinstance(value, str):
            raise TypeError(f"{what}: expected a name, got {type(value).__name__}")
    return names


class Refiner:
    """A mesh's topology refined once, for many position sets or other per-vertex data.

    >>> r = subd.Refiner(mesh, "loop", 2)                 # doctest: +SKIP
    >>> frames = [r.apply(p) for p in animation]          # doctest: +SKIP

    ``apply(values)`` refines an (n, k) float array of per-vertex values (positions,
    colours, any columns) to the last level; with three columns the result is exactly
    :func:`refine`'s positions for those vertices. ``stencil_matrix(level=None)`` gives the
    weights from the base vertices to a level as a ``scipy.sparse.csr_matrix`` when SciPy
    is installed, else as ``(indptr, indices, weights)``.

    ``device="gpu"`` runs ``apply`` on the GPU (subd-gpu: the level stencils uploaded once
    per column count, values in f32, sums in f64 where the adapter has them): within 1e-6
    of the values' range of the CPU's; :class:`DeviceError` without an adapter.
    ``device="auto"`` takes the GPU where there is one, else the CPU with a
    :class:`SubdWarning`, and falls back the same way when the device fails later (values
    past its buffer limits, a lost device). ``device`` says which was chosen. The results come back as numpy arrays;
    the device buffers stay inside (wgpu's buffers cannot be handed to Python safely).
    """

    __slots__ = ("_core", "levels")

    def __init__(
        self,
        mesh: Mesh,
        scheme: Optional[str] = None,
        levels: int = 1,
        *,
        boundary: Optional[str] = None,
        crease_method: Optional[str] = None,
        triangles: Optional[str] = None,
        tension: Optional[float] = None,
        lam: Optional[float] = None,
        device: str = "cpu",
    ) -> None:
        _check_mesh(mesh)
        self.levels = _count(levels, "levels")
        name = _scheme_name(scheme, tension, lam, mesh)
        rules = _rule_names(boundary, crease_method, triangles)[:3]
        self._core = _subd._CoreRefiner(mesh._core, name, self.levels, *rules, device=device)
        if self._core.device_warning:
            _warn([self._core.device_warning])

    @property
    def device(self) -> str:
        """Where ``apply`` runs: ``"gpu"`` or ``"cpu"``."""
        return self._core.device

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


def _places(faces, u, v, sub):
    """(faces, sub, u, v) as flat arrays for the core: ``sub`` defaults to 0 and a single
    sub-face applies to every face."""
    f = _index_array(faces, "faces").reshape(-1)
    s = np.zeros_like(f) if sub is None else _index_array(sub, "sub").reshape(-1)
    uu = _float_array(u, "u").reshape(-1)
    vv = _float_array(v, "v").reshape(-1)
    if s.size == 1 and f.size != 1:
        s = np.full_like(f, int(s[0]))
    return f, s, uu, vv


class PatchTable:
    """A mesh's feature-adaptive patch table, as OpenSubdiv's ``Far::PatchTable``.

    >>> t = subd.PatchTable(mesh, "catmull-clark", isolation=3)   # doctest: +SKIP
    >>> t.census()["by_type"]                                     # doctest: +SKIP
    {'GREGORY_BASIS': 24, 'REGULAR': 144}

    The topology is refined around irregular features (extraordinary vertices, sharp
    features, boundaries, non-quads) to ``isolation`` levels; faces with a regular
    neighbourhood become bicubic B-spline (Catmull-Clark) or quartic box-spline (Loop)
    patches, the faces still at an irregular feature *end caps*: ``"gregory"`` (OpenSubdiv's
    default), ``"bilinear"``, ``"bspline"`` or ``"exact"`` (the exact limit). The defaults
    are OpenSubdiv 3.5's ``PatchTableFactory::Options``.

    * ``arrays``: per patch type, a dict with ``type`` (OpenSubdiv's name),
      ``control_points`` ((n, k) uint32 indices into ``points``), ``params`` ((n, 2)
      uint32, OpenSubdiv's packed ``PatchParam``) and ``sharpness`` (single creases):
      read-only views of the table's own memory, no copies.
    * ``points``: refined vertices of every level, then the local points (a view too).
    * ``save(path)``: the arrays as a ``.npz`` archive.
    * ``local_point_stencils``: the local points as weights of the refined vertices
      (``scipy.sparse.csr_matrix`` when SciPy is installed, else CSR arrays).
    * ``evaluate(faces, u, v, sub=None, derivatives=False)``: vectorised.
    * ``update(vertices)``: new base positions, same topology (animation).
    * With texture coordinates in the mesh, their face-varying patches (OpenSubdiv's
      ``generateFVarTables`` with its default linear patches, refined with
      ``fvar_interpolation``): ``face_varying`` (views of the arrays),
      ``evaluate_uv(faces, u, v, sub=None)`` and ``update_uv(uvs)``.
    * ``device="gpu"``: the table also on the GPU (subd-gpu), where ``evaluate`` computes
      positions and first derivatives (``derivatives=True`` stays on the CPU: a
      ``ValueError``) and ``update`` recomputes the points too; f32 values, within 1e-6 of
      the mesh's size of the CPU's. Exact end caps have no fixed basis for the device:
      :class:`DeviceError` (``device="auto"``: the CPU, with a :class:`SubdWarning`).
    """

    __slots__ = ("_core", "_scheme", "_end_caps", "_isolation")

    def __init__(
        self,
        mesh: Mesh,
        scheme: Optional[str] = None,
        *,
        isolation: int = 10,
        end_caps: str = "gregory",
        single_crease: bool = False,
        inf_sharp: bool = False,
        legacy_sharp_corners: bool = True,
        boundary: Optional[str] = None,
        crease_method: Optional[str] = None,
        triangles: Optional[str] = None,
        fvar_interpolation: Optional[str] = None,
        device: str = "cpu",
    ) -> None:
        _check_mesh(mesh)
        isolation = _count(isolation, "isolation")
        if not 1 <= isolation <= 10:
            raise ValueError(f"isolation: {isolation} is outside 1..10")
        rules = _rule_names(boundary, crease_method, triangles, fvar_interpolation)
        self._scheme, self._end_caps, self._isolation = (
            _scheme_name(scheme, None, None, mesh), end_caps, isolation)
        self._core = _subd._CorePatchTable(
            mesh._core, self._scheme, isolation, end_caps,
            bool(single_crease), bool(inf_sharp), bool(legacy_sharp_corners), *rules,
            device=device)
        if self._core.device_warning:
            _warn([self._core.device_warning])

    @property
    def device(self) -> str:
        """Where ``evaluate`` runs: ``"gpu"`` or ``"cpu"``."""
        return self._core.device

    def census(self) -> dict:
        """Patches by type, depth and boundary mask, and the local points (as ``subd
        patches --json`` prints them)."""
        return json.loads(self._core.census())

    @property
    def arrays(self) -> list:
        """The patch arrays, in table order: read-only views of the table's memory (no
        copies; ``control_points`` and ``params`` uint32, ``sharpness`` float32)."""
        return [dict(type=t, control_points=c, params=p, sharpness=s.reshape(-1))
                for t, c, p, s in self._core.arrays()]

    @property
    def points(self) -> np.ndarray:
        """(n, 3): refined vertices of every level, then the local points. A read-only view
        of the table's memory: ``update`` overwrites it in place, so it follows."""
        return self._core.points()

    def save(self, path) -> None:
        """Writes the table to ``path`` as a ``.npz`` archive (``numpy.load`` reads it back),
        the arrays of ``subd patches ... OUT.json`` under these names: ``scheme`` and
        ``end_caps`` (strings), ``isolation``, ``level_vertex_counts``, ``points`` (n, 3),
        ``local_point_offsets``, ``local_point_indices``, ``local_point_weights`` (CSR over
        the refined vertices), ``array_types`` (OpenSubdiv's type names, in table order)
        and, for the i-th array, ``array{i}_control_points`` (patches, k),
        ``array{i}_params`` (patches, 2) and ``array{i}_sharpness`` (patches,); with texture
        coordinates also ``uv_interpolation``, ``uv_level_value_counts``, ``uv_values``
        (m, 2) and ``array{i}_uv_values`` (patches, 4 or 3)."""
        indptr, indices, weights, _ = self._core.local_point_stencils()
        arrays = self.arrays
        fields = dict(scheme=np.array(self._scheme), end_caps=np.array(self._end_caps),
                      isolation=np.array(self._isolation),
                      level_vertex_counts=np.array(self.level_vertex_counts, dtype=np.int64),
                      points=self.points, local_point_offsets=indptr,
                      local_point_indices=indices, local_point_weights=weights,
                      array_types=np.array([a["type"] for a in arrays]))
        for i, a in enumerate(arrays):
            fields[f"array{i}_control_points"] = a["control_points"]
            fields[f"array{i}_params"] = a["params"]
            fields[f"array{i}_sharpness"] = a["sharpness"]
        fvar = self.face_varying
        if fvar is not None:
            fields["uv_interpolation"] = np.array(fvar["interpolation"])
            fields["uv_level_value_counts"] = np.array(fvar["level_value_counts"], dtype=np.int64)
            fields["uv_values"] = fvar["values"]
            for i, pv in enumerate(fvar["patch_values"]):
                fields[f"array{i}_uv_values"] = pv
        with open(os.fspath(path), "wb") as f:
            np.savez(f, **fields)

    @property
    def level_vertex_counts(self) -> list:
        """Vertices of each refined level (level 0: the base vertices)."""
        return self._core.level_vertex_counts()

    @property
    def local_point_stencils(self):
        """The local points as weights of the refined vertices of all levels."""
        indptr, indices, weights, shape = self._core.local_point_stencils()
        try:
            import scipy.sparse
        except ImportError:
            return indptr, indices, weights
        return scipy.sparse.csr_matrix((weights, indices, indptr), shape=shape)

    def evaluate(self, faces, u, v, *, sub=None, derivatives: bool = False):
        """The surface at ``(faces[i], u[i], v[i])`` (``sub``: the corner quad of a
        Catmull-Clark face that is not a quad). Returns ``(positions, du, dv)``, each
        (m, 3), and with ``derivatives=True`` also ``duu``, ``duv``, ``dvv``."""
        return tuple(self._core.evaluate(*_places(faces, u, v, sub), bool(derivatives)))

    def update(self, vertices) -> None:
        """Moves the base vertices ((n, 3)); the refined and local points follow."""
        a = _float_array(vertices, "vertices")
        if a.ndim != 2 or a.shape[1] != 3:
            raise ValueError(f"vertices: expected an (n, 3) array, got shape {a.shape}")
        self._core.update(np.ascontiguousarray(a))

    @property
    def face_varying(self) -> Optional[dict]:
        """The texture coordinates' face-varying patches, or ``None`` when the mesh has
        none: ``interpolation`` (the mode's name), ``level_value_counts``,
        ``patch_values`` (per array, (n, 4) for Catmull-Clark or (n, 3) for Loop uint32
        indices into ``values``: the patch's face at its level) and ``values`` ((m, 2),
        the coordinates refined to every level). Read-only views of the table's memory."""
        parts = self._core.face_varying()
        if parts is None:
            return None
        mode, counts, patch_values, values = parts
        return dict(interpolation=mode, level_value_counts=counts,
                    patch_values=patch_values, values=values)

    def evaluate_uv(self, faces, u, v, *, sub=None):
        """The texture coordinates at ``(faces[i], u[i], v[i])`` on the face-varying patches
        (OpenSubdiv's ``EvaluateBasisFaceVarying``): ``(uv, du, dv)``, each (m, 2)."""
        return tuple(self._core.evaluate_uv(*_places(faces, u, v, sub)))

    def update_uv(self, uvs) -> None:
        """New texture coordinates ((n, 2), the mesh's layout); the refined values follow
        (in place: views of ``face_varying["values"]`` follow too)."""
        a = _float_array(uvs, "uvs")
        if a.ndim != 2:
            raise ValueError(f"uvs: expected an (n, 2) array, got shape {a.shape}")
        self._core.update_uv(np.ascontiguousarray(a))


def limit(mesh: Mesh, scheme: Optional[str] = None) -> Tuple[np.ndarray, np.ndarray]:
    """(positions, normals), both (n, 3) float64: the exact limit of every vertex."""
    _check_mesh(mesh)
    return _subd.limit(mesh._core, _scheme_name(scheme, None, None, mesh))


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
    out = _subd.evaluate(mesh._core, _scheme_name(scheme, None, None, mesh), f, s, uu, vv,
                         bool(derivatives))
    return tuple(out)


def tessellate(mesh: Mesh, scheme: Optional[str] = None, rate: int = 4) -> Mesh:
    """The limit surface sampled ``rate`` times along every edge: a watertight mesh of
    quads (Catmull-Clark) or triangles (Loop) with unit ``normals``."""
    _check_mesh(mesh)
    rate = _count(rate, "rate")
    return Mesh._wrap(_subd.tessellate(mesh._core, _scheme_name(scheme, None, None, mesh), rate))


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


from ._shape import ConvergenceError, deform, edit, pia  # noqa: E402
