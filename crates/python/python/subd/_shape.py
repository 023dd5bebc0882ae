"""Functions that move a mesh's control points: :func:`pia` (the limit surface through the
vertices), :func:`edit` (the limit surface meeting point, normal and iso-line constraints)
and :func:`deform` (radial blends around constraint points). Each returns a new
:class:`subd.Mesh` with the input's faces, tags and texture coordinates, and with
``return_report=True`` also a dict of what the CLI's ``--json`` reports.

Constraints are the lists the CLI reads from its JSON files (``subd edit --constraints``,
``subd deform --constraints``), given as Python dicts and lists (numpy numbers and arrays
allowed), and checked by the same parser: a problem is a :class:`subd.MeshError` naming
the constraint, e.g. ``constraint 2: missing "normal"``.
"""

from __future__ import annotations

import json
import numbers
from typing import Optional

import numpy as np

from . import (
    Mesh,
    MeshError,
    SubdError,
    _check_mesh,
    _count,
    _float_array,
    _index_array,
    _rule_names,
    _scheme_name,
    _subd,
    _warn,
)

__all__ = ["ConvergenceError", "deform", "edit", "pia"]

# The largest count the library takes (a Rust usize on a 64-bit machine).
_MAX_COUNT = 2**63 - 1


class ConvergenceError(SubdError, RuntimeError):
    """An interpolation that did not reach its tolerance (no mesh is returned, as the CLI
    writes none). ``report`` holds what :func:`pia` would have reported."""

    def __init__(self, message: str, report: Optional[dict] = None) -> None:
        super().__init__(message)
        self.report = report


def _real(x, what: str) -> float:
    """``x`` as a float, refusing what is not a real number (booleans included)."""
    if isinstance(x, bool) or not isinstance(x, numbers.Real):
        raise TypeError(f"{what}: expected a number, got {type(x).__name__}")
    return float(x)


def _size(n, what: str) -> int:
    """A whole number from 0 to the largest count the library takes."""
    n = _count(n, what)
    if n > _MAX_COUNT:
        raise ValueError(f"{what}: {n} is too large")
    return n


def _name(value, what: str) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{what}: expected a name, got {type(value).__name__}")
    return value


def _vertex_set(values, what: str, num_vertices: int) -> Optional[np.ndarray]:
    """Vertex indices (int64), from indices or from a boolean mask of every vertex."""
    if values is None:
        return None
    a = np.asarray(values)
    if a.dtype.kind == "b":
        if a.shape != (num_vertices,):
            raise MeshError(
                f"{what}: a boolean mask needs one value per vertex ({num_vertices}), "
                f"got shape {a.shape}"
            )
        return np.flatnonzero(a).astype(np.int64)
    return _index_array(a, what).reshape(-1)


def _json_value(x):
    """numpy numbers and arrays as the JSON numbers and lists they hold."""
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    raise TypeError(f"{type(x).__name__} is not a JSON value")


def _constraints_json(constraints) -> str:
    """The CLI's constraint file for ``constraints``: ``{"constraints": [...]}`` or the list
    alone. Each constraint is encoded on its own, so that a value JSON cannot hold (NaN, an
    object) is named by its constraint."""
    if isinstance(constraints, dict) and isinstance(constraints.get("constraints"), (list, tuple)):
        items = constraints["constraints"]
    elif isinstance(constraints, (list, tuple)):
        items = constraints
    elif isinstance(constraints, dict):
        items = None  # the parser names what the object lacks
    else:
        raise TypeError(
            "constraints: expected a list of constraint dicts or {'constraints': [...]}, "
            f"got {type(constraints).__name__}"
        )
    encode = lambda x: json.dumps(x, allow_nan=False, default=_json_value)  # noqa: E731
    if items is None:
        try:
            return encode(constraints)
        except (TypeError, ValueError, RecursionError) as e:
            raise MeshError(f"constraints: {e}") from None
    parts = []
    for i, item in enumerate(items):
        try:
            parts.append(encode(item))
        except (TypeError, ValueError, RecursionError) as e:
            raise MeshError(f"constraint {i}: {e}") from None
    return '{"constraints": [' + ", ".join(parts) + "]}"


def _with_report(mesh: Mesh, report: dict, return_report: bool):
    return (mesh, report) if return_report else mesh


def pia(
    mesh: Mesh,
    scheme: Optional[str] = None,
    *,
    moving=None,
    fixed=None,
    solver: str = "auto",
    tol: float = 1e-10,
    max_iter: int = 10_000,
    lam=None,
    allow_any_lambda: bool = False,
    boundary: Optional[str] = None,
    crease_method: Optional[str] = None,
    triangles: Optional[str] = None,
    return_report: bool = False,
):
    """Progressive iterative interpolation: a mesh with ``mesh``'s faces, tags and texture
    coordinates whose limit surface under ``scheme`` passes through ``mesh``'s vertices
    (``subd pia``).

    ``scheme`` is ``"catmull-clark"``, ``"loop"`` or ``"two-phase"``; the two-phase scheme
    takes ``lam``, one λ in (7/20, 1] or one per vertex (``allow_any_lambda=True`` accepts
    any finite λ), or its name ``"two-phase:0.6"``. Only the vertices in ``moving`` move
    (local PIA), or all but those in ``fixed``; either is a list of vertex indices or a
    boolean mask of every vertex. The solve stops when every moving vertex's limit is
    within ``tol`` times the bounding-box diagonal of its target, after at most
    ``max_iter`` iterations. ``solver`` is ``"auto"``, ``"iterate"``, ``"weighted"``,
    ``"cg"``, ``"chebyshev"`` or ``"direct"``. The rule options are as :func:`subd.refine`'s.

    The error is measured afresh, with a limit table built for the result: where it is
    above ``tol`` the call raises :class:`ConvergenceError` (its ``report`` says how far it
    got). With ``return_report=True`` the result is ``(mesh, report)``; the report holds
    ``scheme``, ``solver``, ``method`` (what ran), ``vertices``, ``moving``,
    ``iterations``, ``converged``, ``max_error`` (model units), ``max_error_relative`` (of
    the diagonal), ``tol``, ``history`` (the solver's max error before the first iteration
    and after each, an array) and ``seconds``.
    """
    _check_mesh(mesh)
    name = _scheme_name(scheme, None, None, mesh)
    n = mesh.num_vertices
    chosen = _vertex_set(moving, "moving", n)
    kept = _vertex_set(fixed, "fixed", n)
    lam_values = None if lam is None else _float_array(lam, "lam").reshape(-1)
    rules = _rule_names(boundary, crease_method, triangles)[:3]
    core, text = _subd.pia(
        mesh._core, name, lam_values, bool(allow_any_lambda), chosen, kept,
        _name(solver, "solver"), _real(tol, "tol"), _size(max_iter, "max_iter"), *rules,
    )
    report = json.loads(text)
    report["history"] = np.asarray(report["history"], dtype=np.float64)
    if core is None:
        raise ConvergenceError(_not_converged(report), report)
    return _with_report(Mesh._wrap(core), report, return_report)


def _not_converged(report: dict) -> str:
    relative = report["max_error_relative"]
    relative = float("nan") if relative is None else relative
    return (
        f"{report['scheme']} interpolation did not reach tol {report['tol']!r} in "
        f"{report['iterations']} iterations ({report['method']['method']}): max error "
        f"{relative:e} of the diagonal (raise max_iter or try another solver)"
    )


def edit(
    mesh: Mesh,
    constraints,
    *,
    method: str = "least-squares",
    scheme: Optional[str] = None,
    penalty: Optional[float] = None,
    exact: bool = False,
    membrane: float = 0.0,
    region_rings=3,
    boundary: Optional[str] = None,
    crease_method: Optional[str] = None,
    triangles: Optional[str] = None,
    return_report: bool = False,
):
    """A mesh with ``mesh``'s faces, tags and texture coordinates whose control vertices
    are moved so that its limit surface meets ``constraints`` (``subd edit``).

    ``constraints`` is a list of dicts (or ``{"constraints": [...]}``), as in the CLI's
    constraint files: ``{"kind": "point", "vertex": 12, "target": [x, y, z]}``; a point or
    normal at a ``vertex`` or at a ``face`` with ``uv`` (and ``sub``), with a ``target`` or a
    ``displacement``; ``{"kind": "normal", ..., "normal": [x, y, z]}``; ``{"kind":
    "isoline", "face": f, "along": "u", "at": 0.5, "faces": k, "displacements": [...]}``
    with ``k + 3`` B-spline control points.

    ``method`` is ``"least-squares"`` (the smallest change of the control vertices the
    constraints involve) or ``"energy"`` (the smallest thin-plate energy of the change over
    the vertices within ``region_rings`` rings of the constraints, ``"all"`` for every
    vertex; exact, or the penalty form with weight ``penalty``; ``membrane`` weighs the
    membrane term). ``scheme`` is ``"catmull-clark"`` or ``"loop"`` (least squares only).
    Dependent constraints come as :class:`subd.SubdWarning`: redundant ones are all met,
    conflicting ones get the least-squares compromise.

    With ``return_report=True`` the result is ``(mesh, report)``, the report measured with
    a limit evaluator built afresh: ``residuals`` (one per constraint: a distance, or the
    sine of the angle to a target normal), ``max_residual_relative``, ``method``
    (``"least-squares"``, ``"energy-exact"`` or ``"energy-penalty"``), ``rows``, ``rank``,
    ``rank_deficient``, ``dependencies``, ``free_vertices``, ``moved_vertices`` (an array),
    ``energy_before``, ``energy_after`` and ``displacement_energy`` (Catmull-Clark) and
    ``seconds``.
    """
    _check_mesh(mesh)
    text = _constraints_json(constraints)
    name = _scheme_name(scheme, None, None, mesh)
    if isinstance(region_rings, str) and region_rings == "all":
        rings = None
    elif isinstance(region_rings, str):
        raise ValueError(f"region_rings {region_rings!r}: expected a number of rings or 'all'")
    else:
        rings = _size(region_rings, "region_rings")
    rules = _rule_names(boundary, crease_method, triangles)[:3]
    core, messages, report_text = _subd.edit(
        mesh._core, text, name, _name(method, "method"),
        None if penalty is None else _real(penalty, "penalty"), bool(exact),
        _real(membrane, "membrane"), rings, bool(return_report), *rules,
    )
    _warn(messages)
    report = json.loads(report_text)
    report["moved_vertices"] = np.asarray(report["moved_vertices"], dtype=np.int64)
    if report["residuals"] is not None:
        # The library reports each constraint's kind beside its residual; here the
        # residuals are an array in the constraints' order.
        report["residuals"] = np.asarray(
            [r["residual"] for r in report["residuals"]], dtype=np.float64)
    return _with_report(Mesh._wrap(core), report, return_report)


def deform(mesh: Mesh, constraints, *, return_report: bool = False):
    """A mesh with ``mesh``'s faces, tags and texture coordinates whose vertices move by
    radial blends around constraint points (``subd deform``; any mesh, any level).

    ``constraints`` is a list of dicts (or ``{"constraints": [...]}``), as in the CLI's
    deformation files: ``{"center": [x, y, z], "radius": r, "displacement": [dx, dy,
    dz]}``. A vertex at a centre moves by its displacement exactly; one outside every
    radius keeps its coordinates bit for bit. With ``return_report=True`` the result is
    ``(mesh, report)``: ``vertices``, ``constraints``, ``moved`` (how many vertices moved)
    and ``max_constraint_error``.
    """
    _check_mesh(mesh)
    core, report_text = _subd.deform(mesh._core, _constraints_json(constraints))
    return _with_report(Mesh._wrap(core), json.loads(report_text), return_report)
