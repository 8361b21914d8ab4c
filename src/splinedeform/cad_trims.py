"""Trim loops of CAD faces: read as Bézier pieces in the deformed surface's parameters.

:func:`read_trims` gives the :class:`~splinedeform.trim.loops.TrimDomain` of face
``face`` of a ``.3dm``, STEP or IGES file in the parameters of the surface that
:func:`splinedeform.cad.surface_from_patch` makes of the same face: the file's ``(u, v)``
moved by the origin ``(u_0, v_0)`` of the surface's knot vectors, so that the domain
starts at 0. Loops are chains of trim curves, each fitted with Bézier pieces
(:mod:`splinedeform.trim.bezier`): exactly where a trim is polynomial in the surface's
parameters, within :data:`FIT_TOL` of the face's parameter box (its diagonal) where it is
rational or must be found by projection. Consecutive trims must meet within
:data:`GAP_TOL`. A loop of straight pieces is a :class:`~splinedeform.trim.loops.PolygonLoop`,
any other a :class:`~splinedeform.trim.piecewise_loop.PiecewiseLoop`; the
:class:`TrimDomain` orients them (outer counter-clockwise, holes clockwise).

``.3dm``: the trims' 3-D edges pulled back onto the face
(:mod:`splinedeform.cad_trims_3dm`, which also writes and reads loops beside a surface).
STEP / IGES: the pcurves themselves (:mod:`splinedeform.cad_trims_step`).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .cad_child import check_cad_file, read_in_child
from .errors import InputError
from .trim.bezier import join_loop
from .trim.loops import Loop, PolygonLoop, TrimDomain
from .trim.piecewise_loop import PiecewiseLoop

#: distance (relative to the diagonal of the face's parameter box) within which the Bézier
#: pieces of a rational or projected trim curve follow it
FIT_TOL = 1e-10
#: distance (same measure) within which one trim's end must meet the next one's start
GAP_TOL = 1e-6


def read_trims(path: str | os.PathLike, face: int = 0) -> TrimDomain | None:
    """The trim loops of face ``face`` of a CAD file as a :class:`TrimDomain` in the
    parameters of :func:`~splinedeform.cad.surface_from_patch` (module docstring); None for
    a plain surface of a ``.3dm`` file (no Brep: nothing trims it). An untrimmed Brep
    face's outer loop is its parameter rectangle."""
    from .cad import cad_kind

    path = Path(path)
    kind = cad_kind(path)
    check_cad_file(path)
    if isinstance(face, bool) or not isinstance(face, int) or face < 0:
        raise InputError(f"{path}: face {face!r} out of range; faces are numbered from 0")
    if kind == "openNURBS":
        from .cad_3dm_read import _rhino3dm
        from .cad_trims_3dm import trim_arrays_3dm

        _rhino3dm()
        data = read_in_child(trim_arrays_3dm, path, face, library="openNURBS (rhino3dm)")
    else:
        from .cad_step_read import ocp
        from .cad_trims_step import step_trim_arrays

        ocp()
        data = read_in_child(step_trim_arrays, path, face, library="OpenCASCADE")
    return domain_from_arrays(data, f"{path} face {face}")


def pieces_arrays(loops: list[list[NDArray[np.float64]]], box: NDArray[np.float64],
                  gap: float, source: str) -> dict[str, Any]:
    """``{"box": (u0, u1, v0, v1), "loops": [(K, n + 1, 2), ...], "edges": [(K,), ...]}``:
    each loop's trims joined (:func:`~splinedeform.trim.bezier.join_loop`), the outer loop
    first, and the trim (its number in the loop, from 0) each piece comes from. Bézier
    points outside the box by less than :data:`FIT_TOL` of its diagonal (round-off of the
    fit, where a loop touches a side) are moved onto it, so the loops stay in the box."""
    box = np.asarray(box, dtype=float)
    lo, hi = box[[0, 2]], box[[1, 3]]
    slack = FIT_TOL * float(np.hypot(*(hi - lo)))
    joined, edges = [], []
    for k, trims in enumerate(loops):
        pieces = join_loop(trims, gap, f"{source} loop {k}")
        near = (pieces > lo - slack) & (pieces < hi + slack)
        joined.append(np.where(near, np.clip(pieces, lo, hi), pieces))
        edges.append(np.repeat(np.arange(len(trims)), [len(t) for t in trims]))
    return {"box": box, "loops": joined, "edges": edges}


def domain_from_arrays(data: dict[str, Any], source: str) -> TrimDomain | None:
    """The :class:`TrimDomain` of :func:`pieces_arrays`' result, moved to start at 0, with
    each loop's trim edges (:attr:`TrimDomain.edges`) where the result names them."""
    if data.get("loops") is None:
        return None
    origin = np.asarray(data["box"], dtype=float)[[0, 2]]
    edges = tuple(tuple(int(x) for x in e) for e in data.get("edges") or ())
    loops: list[Loop] = []
    for number, pieces in enumerate(data["loops"]):
        pieces = np.asarray(pieces, dtype=float) - origin
        try:
            if _straight(pieces):
                loops.append(PolygonLoop(pieces[:, 0]))
            else:
                loops.append(PiecewiseLoop.from_pieces(pieces))
        except InputError as exc:
            raise InputError(f"{source} loop {number}: {exc}") from None
    try:
        return TrimDomain(loops[0], tuple(loops[1:]), edges)
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None


#: cells per side of the grid of the trimmed-fraction quadrature
FRACTION_CELLS = 8


def trimmed_fraction(domain: TrimDomain, lengths: tuple[float, float]) -> float:
    """``|Ω| / (L_u L_v)``: the part of the parameter box ``[0, L_u] × [0, L_v]`` inside the
    loops, by :func:`~splinedeform.trim.quadrature.trim_quadrature` (Gauss–Green on cut
    cells, ``n + 1`` points along pieces of degree ``n``: exact for ``∫ 1``). The loops
    are moved by ``0.3 L / m`` into a grid of ``m`` = :data:`FRACTION_CELLS` cells of
    ``L (1 + 0.7 / m) / m``, so that the box's sides, where outer loops often run, lie
    inside cells, off the grid's lines and away from its ends."""
    from .trim.cells import Grid
    from .trim.quadrature import trim_quadrature

    m = FRACTION_CELLS
    L = np.asarray(lengths, dtype=float)
    shift = 0.3 * L / m
    moved = TrimDomain(*_moved(domain.loops, shift))
    degree = max([getattr(loop, "degree", 1) for loop in domain.loops])
    rule = trim_quadrature(moved, Grid((m, m), tuple(L * (1 + 0.7 / m))), max(2, degree + 1))
    return float(rule.weights.sum() / L.prod())


def _moved(loops: tuple[Loop, ...], shift: NDArray[np.float64]) -> tuple[Loop, tuple[Loop, ...]]:
    """Polygon and piecewise loops translated by ``shift``: the outer one and the holes."""
    out: list[Loop] = []
    for loop in loops:
        pieces = loop_pieces(loop) + shift
        out.append(PolygonLoop(pieces[:, 0]) if isinstance(loop, PolygonLoop)
                   else PiecewiseLoop.from_pieces(pieces))
    return out[0], tuple(out[1:])


def trim_summary(entry: dict[str, Any], source: str) -> dict[str, Any]:
    """``loops`` (``[outer, inner]`` counts), ``loop_names`` (each loop's name, as
    ``boundary.loops`` takes it, and its number of trim edges) and ``trimmed_fraction`` of a
    listed face (:func:`listed`), None where it has no loops; ``trim_error`` where they
    cannot be read."""
    none = {"loops": None, "loop_names": None, "trimmed_fraction": None}
    if "trim_error" in entry:
        return {**none, "trim_error": entry["trim_error"]}
    data = entry.get("trim") or {"loops": None}
    try:
        domain = domain_from_arrays(data, source)
        if domain is None:
            return none
        box = np.asarray(data["box"], dtype=float)
        fraction = trimmed_fraction(domain, (box[1] - box[0], box[3] - box[2]))
    except InputError as exc:
        return {**none, "trim_error": str(exc)}
    from .trim.model_matrices import loop_names

    names = {name: domain.edge_count(k) for k, name in enumerate(loop_names(domain))}
    return {"loops": [1, len(domain.holes)], "loop_names": names, "trimmed_fraction": fraction}


def _straight(pieces: NDArray[np.float64]) -> bool:
    """Whether every piece is a straight segment: its Bézier points on its chord within
    ``1e-13`` of the loop's size (round-off of the fit)."""
    a, b = pieces[:, :1], pieces[:, -1:]
    chord = b - a
    cross = chord[..., 0] * (pieces - a)[..., 1] - chord[..., 1] * (pieces - a)[..., 0]
    size = max(float(np.ptp(pieces.reshape(-1, 2), axis=0).max()), 1e-300)
    return bool(np.all(np.abs(cross) <= 1e-13 * size * np.hypot(*chord.T)[..., None]))


def loop_pieces(loop: Loop) -> NDArray[np.float64]:
    """Bézier pieces ``(K, n + 1, 2)`` of a polygon or piecewise loop (as oriented)."""
    if isinstance(loop, PiecewiseLoop):
        return loop.pieces
    if isinstance(loop, PolygonLoop):
        a, b = loop.segments()
        return np.stack([a, b], axis=1)
    raise InputError(f"a {type(loop).__name__} has no Bézier pieces")


def listed(read: Any) -> dict[str, Any]:
    """``{"trim": read()}``, or ``{"trim_error": message}`` if it raises ``InputError``:
    what a face listing shows of a face's loops."""
    try:
        return {"trim": read()}
    except InputError as exc:
        return {"trim_error": str(exc)}


def fill_singular(trims: list[NDArray[np.float64] | None], source: str
                   ) -> list[NDArray[np.float64]]:
    """Trims without an edge as straight segments from the previous trim's end to the
    next one's start."""
    if all(t is None for t in trims):
        raise InputError(f"{source}: the loop has no edges")
    out = list(trims)
    for k, trim in enumerate(trims):
        if trim is None:
            before = next(t for t in (trims[k - j] for j in range(1, len(trims) + 1))
                          if t is not None)
            after = next(t for t in (trims[(k + j) % len(trims)] for j in range(1, len(trims)))
                         if t is not None)
            out[k] = np.stack([before[-1, -1], after[0, 0]])[None]
    return [t for t in out if t is not None]
