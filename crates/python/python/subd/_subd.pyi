"""Type stubs of subd's compiled core (``subd._subd``); use the functions of ``subd``."""

from os import PathLike
from typing import List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

SCHEMES: List[str]

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
    ) -> None: ...
    @property
    def vertices(self) -> npt.NDArray[np.float64]: ...
    @property
    def normals(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def face_sizes(self) -> npt.NDArray[np.int64]: ...
    @property
    def face_vertices(self) -> npt.NDArray[np.int64]: ...
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
    def write(self, path: Union[str, PathLike[str]]) -> None: ...

class _CoreRefiner:
    def __init__(
        self,
        mesh: _CoreMesh,
        scheme_name: str,
        levels: int,
        boundary: Optional[str] = ...,
        crease_method: Optional[str] = ...,
        triangles: Optional[str] = ...,
    ) -> None: ...
    @property
    def num_base_vertices(self) -> int: ...
    @property
    def num_vertices(self) -> int: ...
    def apply(self, values: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def stencil_matrix(
        self, level: Optional[int] = ...
    ) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.float64], Tuple[int, int]]: ...

def read(path: Union[str, PathLike[str]], accept_inconsistent_orientation: bool = ...) -> Tuple[_CoreMesh, List[str]]: ...
def refine(
    mesh: _CoreMesh,
    scheme_name: str,
    levels: int,
    limit: bool = ...,
    boundary: Optional[str] = ...,
    crease_method: Optional[str] = ...,
    triangles: Optional[str] = ...,
) -> _CoreMesh: ...
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
def set_num_threads(threads: int) -> None: ...
def get_num_threads() -> int: ...
