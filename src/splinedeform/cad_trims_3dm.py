"""Trim loops of ``.3dm`` Brep faces (run in the reader child), and loops written beside a
surface.

rhino3dm (8.x) gives a Brep face's loops (outer / inner), their trims in order
and each trim's edge and direction, but not the trims' 2-D curves. The 2-D curve is
therefore the trim's 3-D edge (a NURBS curve) pulled back onto the face's NURBS surface:
each point ``X(t)`` of the edge is projected, ``(u, v) = argmin |S(u, v) - X(t)|`` by
Gauss–Newton steps ``[S_u S_v] Δ = X - S`` from the nearest point of a
:data:`SEED_GRID`² grid. On a surface affine in ``(u, v)`` (a plane) this is the exact
preimage. A trim without an edge (a singular trim at a pole) is the straight segment
joining its neighbours. On a closed surface a point of the seam has two parameters: a
piece takes the side where its other points are, and a trim lying on the seam the side
that joins it to its neighbours; at a pole, where ``u`` is not defined by the point, a
point takes the ``u`` of its nearest neighbour along the curve.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .cad_trims import FIT_TOL, GAP_TOL, fill_singular, loop_pieces, pieces_arrays
from .errors import InputError
from .trim.bezier import fit_pieces
from .trim.loops import PolygonLoop, TrimDomain
from .trim.piecewise_loop import PiecewiseLoop

#: seeds per side for projecting edge points on a face's surface
SEED_GRID = 33


def trim_arrays_3dm(path: Path, face: int) -> dict[str, Any]:
    """The loops of face ``face`` of a ``.3dm`` file as Bézier pieces (module docstring);
    for a plain surface those written beside it (:func:`add_trim_curves`), if any, else
    ``{"loops": None}``."""
    from .cad_3dm_read import _objects, _rhino3dm

    r3 = _rhino3dm()
    model = r3.File3dm.Read(str(path))
    if model is None:
        raise InputError(f"{path}: not a .3dm (openNURBS) file")
    found = []
    for index, _, geometry in _objects(model, r3):
        if isinstance(geometry, r3.Brep):
            found += [(geometry, f) for f in geometry.Faces]
        else:
            found.append((index, geometry))
    if not 0 <= face < len(found):
        raise InputError(f"{path}: face {face!r} out of range; the file holds "
                         f"{len(found)} surface(s), numbered 0..{len(found) - 1}")
    owner, member = found[face]
    return member_trims(model, r3, owner, member, f"{path} face {face}")


def member_trims(model: Any, r3: Any, owner: Any, member: Any, source: str) -> dict[str, Any]:
    """The loops of one face: ``owner`` its Brep, or the object index of a plain surface
    (whose loops are those written beside it, if any: else ``{"loops": None}``)."""
    if isinstance(owner, int):
        from .cad_3dm_read import _patch_from_rhino

        loops = written_trims(model, r3, owner)
        if loops is None:
            return {"loops": None}
        patch = _patch_from_rhino(member.ToNurbsSurface(), source)
        n = patch["degrees"]
        box = [patch["knots_u"][n[0]], patch["knots_u"][-n[0] - 1],
               patch["knots_v"][n[1]], patch["knots_v"][-n[1] - 1]]
        return {"box": np.array(box, dtype=float), "loops": loops}
    return brep_face_trims(owner, member, source)


def brep_face_trims(brep: Any, brep_face: Any, source: str) -> dict[str, Any]:
    """A rhino3dm Brep face's loops, outer first, as Bézier pieces (module docstring)."""
    from .cad_3dm_read import _patch_from_rhino

    patch = _patch_from_rhino(brep_face.UnderlyingSurface().ToNurbsSurface(), source)
    surface = _PatchProjection(patch)
    box = surface.box
    size = float(np.hypot(box[1] - box[0], box[3] - box[2]))
    loops = sorted(brep_face.Loops, key=lambda lp: str(lp.LoopType).split(".")[-1] != "Outer")
    out = []
    for number, loop in enumerate(loops):
        name = f"{source} loop {number}"
        trims: list[NDArray[np.float64] | None] = []
        for k, trim in enumerate(loop.Trims):
            if trim.EdgeIndex < 0:
                trims.append(None)
                continue
            curve = brep.Edges[trim.EdgeIndex].ToNurbsCurve()
            knots = np.array([curve.Knots[i] for i in range(len(curve.Knots))])
            d = curve.Domain
            breaks = np.unique(np.clip(np.r_[d.T0, knots, d.T1], d.T0, d.T1))
            if trim.IsReversed:
                breaks = breaks[::-1]
            pull = lambda t, c=curve: surface.settle(surface.project(  # noqa: E731
                np.array([[p.X, p.Y, p.Z] for p in map(c.PointAt, map(float, t))])), t)
            trims.append(fit_pieces(pull, breaks, 1, FIT_TOL * size, f"{name} trim {k}"))
        surface.seam_sides(trims)
        out.append(fill_singular(trims, name))
    return pieces_arrays(out, box, GAP_TOL * size, source)


class _PatchProjection:
    """Points in space projected on a NURBS patch's surface (module docstring)."""

    def __init__(self, patch: dict[str, Any]) -> None:
        from .knots import KnotVectorBasis

        self.bases = [KnotVectorBasis(n, np.asarray(t, dtype=float))
                      for n, t in zip(patch["degrees"], (patch["knots_u"], patch["knots_v"]))]
        w = np.asarray(patch["weights"], dtype=float)
        self.hom = np.concatenate([patch["points"] * w[..., None], w[..., None]], axis=-1)
        self.box = np.array([*self.bases[0].domain, *self.bases[1].domain])
        seeds = [np.linspace(*b.domain, SEED_GRID) for b in self.bases]
        self.seed_uv = np.stack(np.meshgrid(*seeds, indexing="ij"), -1).reshape(-1, 2)
        self.seed_xyz = self.evaluate(self.seed_uv)[0]
        self.size = float(np.ptp(self.seed_xyz, axis=0).max())
        self.closed = self._closed()

    def evaluate(self, uv: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        """``S, S_u, S_v`` at points ``uv`` ``(m, 2)`` (quotient rule on ``(w S, w)``)."""
        (bu, bv) = self.bases
        Bu, Du = bu(uv[:, 0]), bu(uv[:, 0], 1)
        Bv, Dv = bv(uv[:, 1]), bv(uv[:, 1], 1)
        H = np.einsum("mi,ijc,mj->mc", Bu, self.hom, Bv)
        Hu = np.einsum("mi,ijc,mj->mc", Du, self.hom, Bv)
        Hv = np.einsum("mi,ijc,mj->mc", Bu, self.hom, Dv)
        W = H[:, 3:]
        S = H[:, :3] / W
        return S, (Hu[:, :3] - S * Hu[:, 3:]) / W, (Hv[:, :3] - S * Hv[:, 3:]) / W

    def project(self, xyz: NDArray[np.float64]) -> NDArray[np.float64]:
        """``argmin_{(u, v)} |S(u, v) - X|`` for points ``xyz`` ``(m, 3)``."""
        gap = np.linalg.norm(xyz[:, None] - self.seed_xyz[None], axis=-1)
        uv = self.seed_uv[np.argmin(gap, axis=1)].copy()
        lo, hi = self.box[[0, 2]], self.box[[1, 3]]
        for _ in range(12):
            S, Su, Sv = self.evaluate(uv)
            J = np.stack([Su, Sv], axis=-1)                 # (m, 3, 2)
            JtJ = np.einsum("mki,mkj->mij", J, J)
            JtJ += 1e-14 * np.trace(JtJ, axis1=1, axis2=2)[:, None, None] * np.eye(2)
            rhs = np.einsum("mki,mk->mi", J, xyz - S)
            uv = np.clip(uv + np.linalg.solve(JtJ, rhs[..., None])[..., 0], lo, hi)
        return uv

    def _closed(self) -> list[bool]:
        """Whether the surface is closed in u, in v: its two opposite sides coincide
        (the seeds on them within 1e-9 of the surface's size)."""
        grid = self.seed_xyz.reshape(SEED_GRID, SEED_GRID, 3)
        size = max(float(np.ptp(self.seed_xyz, axis=0).max()), 1e-300)
        return [bool(np.abs(np.take(grid, 0, k) - np.take(grid, -1, k)).max() <= 1e-9 * size)
                for k in (0, 1)]

    def settle(self, uv: NDArray[np.float64], t: NDArray[np.float64]) -> NDArray[np.float64]:
        """Points of one piece (at curve parameters ``t``) on a seam or a pole, whose
        parameter there is not defined by the point: a seam point takes the seam's side
        where the piece's other points are, a pole point the ``u`` (or ``v``) of the point
        nearest it along the curve that is not at the pole."""
        uv = uv.copy()
        for k in (0, 1):
            lo, hi = self.box[2 * k], self.box[2 * k + 1]
            eps = 1e-9 * (hi - lo)
            if self.closed[k]:
                on = (np.abs(uv[:, k] - lo) <= eps) | (np.abs(uv[:, k] - hi) <= eps)
                if np.any(on) and not np.all(on):
                    ref = np.median(uv[~on, k])
                    uv[on, k] = lo if abs(ref - lo) < abs(ref - hi) else hi
        _, Su, Sv = self.evaluate(uv)
        for k, D in ((0, Su), (1, Sv)):
            pole = np.linalg.norm(D, axis=1) <= 1e-9 * max(self.size, 1e-300)
            if np.any(pole) and not np.all(pole):
                good = np.flatnonzero(~pole)
                nearest = good[np.argmin(np.abs(t[pole, None] - t[None, good]), axis=1)]
                uv[pole, k] = uv[nearest, k]
        return uv

    def seam_sides(self, trims: list[NDArray[np.float64] | None]) -> None:
        """Put each trim lying on a seam (all its points on one side of a closed
        direction) on the side that joins it to its neighbours (in place); between two
        singular trims, on the side where a counter-clockwise loop runs its way (openNURBS
        runs outer loops counter-clockwise in the surface's parameters)."""
        for k in (0, 1):
            if not self.closed[k]:
                continue
            lo, hi = self.box[2 * k], self.box[2 * k + 1]
            eps = 1e-9 * (hi - lo)
            for i, trim in enumerate(trims):
                if trim is None or np.ptp(trim[..., k]) > eps:
                    continue
                if min(abs(trim[..., k].mean() - lo), abs(trim[..., k].mean() - hi)) > eps:
                    continue
                ends = [t for t in (trims[i - 1], trims[(i + 1) % len(trims)]) if t is not None]
                if not ends:        # between singular trims: an outer loop runs
                    rising = trim[-1, -1, 1 - k] > trim[0, 0, 1 - k]   # counter-clockwise
                    trim[..., k] = (hi if rising else lo) if k == 0 else (lo if rising else hi)
                    continue
                best, gap = None, np.inf
                for side in (lo, hi):
                    moved = trim.copy()
                    moved[..., k] = side
                    g = sum(np.hypot(*(moved[0, 0] - ends[0][-1, -1]).T) if j == 0 else
                            np.hypot(*(moved[-1, -1] - e[0, 0]).T) for j, e in enumerate(ends))
                    if g < gap:
                        best, gap = moved, g
                trims[i] = best


# --- .3dm export: trim loops as curve objects -------------------------------------------

#: user-string keys of a written trim curve: the object index of the surface it trims,
#: and its loop ("outer" or "hole k")
TRIM_OF, TRIM_LOOP = "splinedeform.trim_of", "splinedeform.loop"


def domain_pieces(domain: TrimDomain) -> list[NDArray[np.float64]]:
    """Bézier pieces ``(K, n + 1, 2)`` of every loop of ``domain``, outer first, as the
    domain orients them (a spline loop's spans interpolated at ``n + 1`` points: exact);
    None for a circle, which :func:`add_trim_curves` writes as a rational circle."""
    from .trim.bezier import interpolate, lobatto
    from .trim.spline_loop import SplineLoop

    out = []
    for loop in domain.loops:
        if isinstance(loop, PiecewiseLoop | PolygonLoop):
            out.append(loop_pieces(loop))
        elif isinstance(loop, SplineLoop):           # span s is a polynomial of degree n
            n = loop.degree
            t = np.arange(loop.spans)[:, None] + lobatto(n)
            out.append(interpolate(loop.evaluate(t)[0], n))
        else:
            out.append(None)
    return out


def add_trim_curves(model: Any, r3: Any, domain: TrimDomain, surface_index: int,
                    name: str) -> None:
    """Add the loops of ``domain`` to a rhino3dm ``File3dm`` as planar curve objects.

    rhino3dm (8.x) cannot build a trimmed Brep face from 2-D trim curves (its ``Brep``
    offers no loops or trims to add; ``CreateTrimmedPlane`` takes one 3-D curve on a
    plane), so the loops are written beside the surface: each a NURBS curve in the plane
    ``z = 0`` whose ``(x, y)`` are the surface's ``(u, v)`` (the parameters it is written
    with), named ``"<name>: trim outer"`` or ``"<name>: trim hole k"``, with the user
    strings :data:`TRIM_OF` (the surface's object index) and :data:`TRIM_LOOP`. A loop of
    ``K`` Bézier pieces of degree ``n`` is the clamped curve with the pieces' points
    (``n K + 1``, the first repeated at the end) and every joint a knot of multiplicity
    ``n`` at ``t = s``; a circle is openNURBS' rational circle.
    """
    for k, (loop, pieces) in enumerate(zip(domain.loops, domain_pieces(domain))):
        role = "outer" if k == 0 else f"hole {k}"
        if pieces is None:                            # a CircleLoop
            c = r3.Circle(r3.Point3d(*loop.centre, 0.0), loop.radius)
            curve = r3.NurbsCurve.CreateFromCircle(c)
            if loop.sense < 0:
                curve.Reverse()
        else:
            K, n = pieces.shape[0], pieces.shape[1] - 1
            points = np.concatenate([pieces[:, :-1].reshape(-1, 2), pieces[:1, 0]])
            curve = r3.NurbsCurve(3, False, n + 1, len(points))
            for i, (u, v) in enumerate(points):
                curve.Points[i] = r3.Point4d(float(u), float(v), 0.0, 1.0)
            for i, t in enumerate(np.repeat(np.arange(K + 1.0), n)):
                curve.Knots[i] = float(t)
        attributes = r3.ObjectAttributes()
        attributes.Name = f"{name}: trim {role}"
        attributes.SetUserString(TRIM_OF, str(surface_index))
        attributes.SetUserString(TRIM_LOOP, role)
        model.Objects.AddCurve(curve, attributes)


def written_trims(model: Any, r3: Any, surface_index: int) -> list[NDArray[np.float64]] | None:
    """The loops :func:`add_trim_curves` wrote for object ``surface_index``, as Bézier
    pieces (outer first), or None if there are none. A circle is fitted like any rational
    curve (:data:`FIT_TOL` of its size)."""
    found: dict[str, Any] = {}
    for obj in model.Objects:
        attributes = obj.Attributes
        if attributes.GetUserString(TRIM_OF) == str(surface_index):
            found[attributes.GetUserString(TRIM_LOOP)] = obj.Geometry
    if "outer" not in found:
        return None
    roles = ["outer"] + sorted((r for r in found if r != "outer"), key=lambda r: int(r[5:]))
    loops = []
    for role in roles:
        curve = found[role].ToNurbsCurve()
        n = curve.Degree
        P = np.array([[p.X, p.Y, p.W] for p in (curve.Points[i] for i in range(len(curve.Points)))])
        knots = np.array([curve.Knots[i] for i in range(len(curve.Knots))])
        joints = np.unique(knots)
        if (not curve.IsRational and len(P) == n * (len(joints) - 1) + 1
                and np.array_equal(knots, np.repeat(joints, n))):     # our Bézier layout
            pieces = np.stack([P[s * n:s * n + n + 1, :2] for s in range(len(joints) - 1)])
        else:
            d = curve.Domain
            points = lambda t, c=curve: np.array(  # noqa: E731
                [[p.X, p.Y] for p in map(c.PointAt, map(float, t))])
            size = float(np.ptp(points(np.linspace(d.T0, d.T1, 65)), axis=0).max())
            pieces = fit_pieces(points, np.unique(np.clip(np.r_[d.T0, knots, d.T1], d.T0, d.T1)),
                                1, FIT_TOL * size, f"trim curve {role} of object {surface_index}")
        loops.append(pieces)
    return loops
