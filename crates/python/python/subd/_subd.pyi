"""Type stubs of subd's compiled core (``subd._subd``); use the functions of ``subd``."""

from os import PathLike
from typing import Dict, List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

SCHEMES: List[str]
CURVE_SCHEMES: List[str]

class _CoreMesh:
    def __init__(
        self,
        vertices: npt.NDArray[np.float64],
        face_sizes: npt.NDArray[np.int64],
        face_vertices: npt.NDArray[np.int64],
        crease_edges: npt.NDArray[np.int64],
        crease_sharpness: npt.NDArray[np.float64],
        corner_vertices: npt.NDArray[np.int64],
        corner_sharpness: npt.NDArray[np.float64],
        holes: npt.NDArray[np.int64],
        uvs: Optional[npt.NDArray[np.float64]] = ...,
        uv_indices: Optional[npt.NDArray[np.int64]] = ...,
        accept_inconsistent_orientation: bool = ...,
    ) -> None: ...
    @property
    def vertices(self) -> npt.NDArray[np.float64]: ...
    @property
    def normals(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def face_sizes(self) -> npt.NDArray[np.int64]: ...
    def face_vertices(self, index_dtype: str) -> npt.NDArray[np.integer]: ...
    def uniform_face_size(self) -> Optional[int]: ...
    @property
    def uvs(self) -> Optional[npt.NDArray[np.float64]]: ...
    def uv_indices(self, index_dtype: str) -> Optional[npt.NDArray[np.integer]]: ...
    @property
    def face_levels(self) -> Optional[npt.NDArray[np.uint8]]: ...
    @property
    def orientation_conflicts(self) -> int: ...
    @property
    def creases(self) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.float64]]: ...
    @property
    def corners(self) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.float64]]: ...
    @property
    def holes(self) -> npt.NDArray[np.int64]: ...
    @property
    def num_vertices(self) -> int: ...
    @property
    def num_faces(self) -> int: ...
    @property
    def num_edges(self) -> int: ...
    @property
    def file_scheme(self) -> Optional[str]: ...
    @property
    def stage(self) -> Optional[Tuple[str, Optional[float], Optional[str]]]: ...
    def write(self, path: Union[str, PathLike[str]]) -> List[str]: ...

class _CoreRefiner:
    def __init__(
        self,
        mesh: _CoreMesh,
        scheme_name: str,
        levels: int,
        boundary: Optional[str] = ...,
        crease_method: Optional[str] = ...,
        triangles: Optional[str] = ...,
        device: str = ...,
    ) -> None: ...
    @property
    def device(self) -> str: ...
    @property
    def device_warning(self) -> Optional[str]: ...
    @property
    def num_base_vertices(self) -> int: ...
    @property
    def num_vertices(self) -> int: ...
    def apply(self, values: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def stencil_matrix(
        self, level: Optional[int] = ...
    ) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.float64], Tuple[int, int]]: ...

class _CorePatchTable:
    def __init__(
        self,
        mesh: _CoreMesh,
        scheme_name: str,
        isolation: int,
        end_caps: str,
        single_crease: bool,
        inf_sharp: bool,
        legacy_sharp_corners: bool,
        boundary: Optional[str] = ...,
        crease_method: Optional[str] = ...,
        triangles: Optional[str] = ...,
        fvar_interpolation: Optional[str] = ...,
        device: str = ...,
    ) -> None: ...
    @property
    def device(self) -> str: ...
    @property
    def device_warning(self) -> Optional[str]: ...
    def census(self) -> str: ...
    def arrays(
        self,
    ) -> List[Tuple[str, npt.NDArray[np.uint32], npt.NDArray[np.uint32], npt.NDArray[np.float32]]]: ...
    def points(self) -> npt.NDArray[np.float64]: ...
    def level_vertex_counts(self) -> List[int]: ...
    def local_point_stencils(
        self,
    ) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.float64], Tuple[int, int]]: ...
    def evaluate(
        self,
        faces: npt.NDArray[np.int64],
        subs: npt.NDArray[np.int64],
        u: npt.NDArray[np.float64],
        v: npt.NDArray[np.float64],
        derivatives: bool = ...,
    ) -> List[npt.NDArray[np.float64]]: ...
    def update(self, vertices: npt.NDArray[np.float64]) -> None: ...
    def face_varying(
        self,
    ) -> Optional[Tuple[str, List[int], List[npt.NDArray[np.uint32]], npt.NDArray[np.float64]]]: ...
    def evaluate_uv(
        self,
        faces: npt.NDArray[np.int64],
        subs: npt.NDArray[np.int64],
        u: npt.NDArray[np.float64],
        v: npt.NDArray[np.float64],
    ) -> List[npt.NDArray[np.float64]]: ...
    def update_uv(self, uvs: npt.NDArray[np.float64]) -> None: ...

def read(
    path: Union[str, PathLike[str]],
    accept_inconsistent_orientation: bool = ...,
    no_transform: bool = ...,
    weld_tolerance: Optional[float] = ...,
    prim: Optional[str] = ...,
    time: Optional[float] = ...,
) -> Tuple[_CoreMesh, List[str]]: ...
def mesh_prims(path: Union[str, PathLike[str]]) -> List[Tuple[str, int, int, str]]: ...
def refine(
    mesh: _CoreMesh,
    scheme_name: str,
    levels: int,
    limit: bool = ...,
    boundary: Optional[str] = ...,
    crease_method: Optional[str] = ...,
    triangles: Optional[str] = ...,
    fvar_interpolation: Optional[str] = ...,
    index_dtype: str = ...,
) -> Tuple[_CoreMesh, List[str], Optional[npt.NDArray[np.integer]]]: ...
def info(mesh: _CoreMesh) -> str: ...
def adaptive(
    mesh: _CoreMesh,
    scheme_name: str,
    levels: int,
    limit: bool,
    thresholds: Dict[str, Optional[float]],
    select_faces: Optional[npt.NDArray[np.int64]] = ...,
    select_vertices: Optional[npt.NDArray[np.int64]] = ...,
    boundary: Optional[str] = ...,
    crease_method: Optional[str] = ...,
    triangles: Optional[str] = ...,
    fvar_interpolation: Optional[str] = ...,
) -> Tuple[_CoreMesh, List[str]]: ...
def analyze_mask(mask: List[float], arity: int, max_levels: int) -> str: ...
def analyze_mask2(rows: List[List[float]], lattice: str, max_levels: int) -> str: ...
def analyze_surface(scheme_name: str, valence: int) -> str: ...
def curve(
    points: npt.NDArray[np.float64],
    scheme_name: str,
    levels: int,
    closed: bool,
    parameters: Tuple[Optional[float], Optional[float], Optional[int], Optional[float]],
    normals: Optional[npt.NDArray[np.float64]] = ...,
) -> Tuple[npt.NDArray[np.float64], Optional[npt.NDArray[np.float64]]]: ...
def limit(mesh: _CoreMesh, scheme_name: str) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def evaluate(
    mesh: _CoreMesh,
    scheme_name: str,
    faces: npt.NDArray[np.int64],
    subs: npt.NDArray[np.int64],
    u: npt.NDArray[np.float64],
    v: npt.NDArray[np.float64],
    derivatives: bool = ...,
) -> List[npt.NDArray[np.float64]]: ...
def tessellate(mesh: _CoreMesh, scheme_name: str, rate: int) -> _CoreMesh: ...
def pia(
    mesh: _CoreMesh,
    scheme_name: str,
    lam: Optional[npt.NDArray[np.float64]],
    allow_any_lambda: bool,
    moving: Optional[npt.NDArray[np.int64]],
    fixed: Optional[npt.NDArray[np.int64]],
    solver: str,
    tol: float,
    max_iter: int,
    boundary: Optional[str] = ...,
    crease_method: Optional[str] = ...,
    triangles: Optional[str] = ...,
) -> Tuple[Optional[_CoreMesh], str]: ...
def edit(
    mesh: _CoreMesh,
    constraints_json: str,
    scheme_name: str,
    method: str,
    penalty: Optional[float],
    exact: bool,
    membrane: float,
    region_rings: Optional[int],
    measure: bool,
    boundary: Optional[str] = ...,
    crease_method: Optional[str] = ...,
    triangles: Optional[str] = ...,
) -> Tuple[_CoreMesh, List[str], str]: ...
def deform(mesh: _CoreMesh, constraints_json: str) -> Tuple[_CoreMesh, str]: ...
def set_num_threads(threads: int) -> None: ...
def get_num_threads() -> int: ...
