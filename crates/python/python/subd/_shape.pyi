"""Type stubs of :mod:`subd._shape` (``subd.pia``, ``subd.edit``, ``subd.deform``)."""

from typing import Any, Dict, List, Literal, Mapping, Optional, Sequence, Tuple, Union, overload

import numpy.typing as npt

from . import Mesh, SubdError

_Constraints = Union[Sequence[Mapping[str, Any]], Mapping[str, Any]]
_Vertices = Union[npt.ArrayLike, Sequence[int]]

class ConvergenceError(SubdError, RuntimeError):
    report: Optional[Dict[str, Any]]
    def __init__(self, message: str, report: Optional[Dict[str, Any]] = ...) -> None: ...

@overload
def pia(
    mesh: Mesh,
    scheme: Optional[str] = ...,
    *,
    moving: Optional[_Vertices] = ...,
    fixed: Optional[_Vertices] = ...,
    solver: str = ...,
    tol: float = ...,
    max_iter: int = ...,
    lam: Optional[Union[float, npt.ArrayLike]] = ...,
    allow_any_lambda: bool = ...,
    boundary: Optional[str] = ...,
    crease_method: Optional[str] = ...,
    triangles: Optional[str] = ...,
    return_report: Literal[False] = ...,
) -> Mesh: ...
@overload
def pia(
    mesh: Mesh,
    scheme: Optional[str] = ...,
    *,
    moving: Optional[_Vertices] = ...,
    fixed: Optional[_Vertices] = ...,
    solver: str = ...,
    tol: float = ...,
    max_iter: int = ...,
    lam: Optional[Union[float, npt.ArrayLike]] = ...,
    allow_any_lambda: bool = ...,
    boundary: Optional[str] = ...,
    crease_method: Optional[str] = ...,
    triangles: Optional[str] = ...,
    return_report: Literal[True],
) -> Tuple[Mesh, Dict[str, Any]]: ...
@overload
def edit(
    mesh: Mesh,
    constraints: _Constraints,
    *,
    method: str = ...,
    scheme: Optional[str] = ...,
    penalty: Optional[float] = ...,
    exact: bool = ...,
    membrane: float = ...,
    region_rings: Union[int, Literal["all"]] = ...,
    boundary: Optional[str] = ...,
    crease_method: Optional[str] = ...,
    triangles: Optional[str] = ...,
    return_report: Literal[False] = ...,
) -> Mesh: ...
@overload
def edit(
    mesh: Mesh,
    constraints: _Constraints,
    *,
    method: str = ...,
    scheme: Optional[str] = ...,
    penalty: Optional[float] = ...,
    exact: bool = ...,
    membrane: float = ...,
    region_rings: Union[int, Literal["all"]] = ...,
    boundary: Optional[str] = ...,
    crease_method: Optional[str] = ...,
    triangles: Optional[str] = ...,
    return_report: Literal[True],
) -> Tuple[Mesh, Dict[str, Any]]: ...
@overload
def deform(mesh: Mesh, constraints: _Constraints, *, return_report: Literal[False] = ...) -> Mesh: ...
@overload
def deform(
    mesh: Mesh, constraints: _Constraints, *, return_report: Literal[True]
) -> Tuple[Mesh, Dict[str, Any]]: ...

__all__: List[str]
