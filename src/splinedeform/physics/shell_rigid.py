"""Rigid motions a shell's boundary leaves free: ``null K_r = range T ∩ {t + ω × p}``.

The linear shell's energy vanishes exactly on the rigid motions ``r = t + ω × p`` of its
control points (a B-spline net moved rigidly moves the surface rigidly), so ``K_r = Tᵀ K T``
is singular exactly on the reduced coordinates ``x`` with ``T x = R y`` for the six
motions ``R = [e_x, e_y, e_z, e_x × p, e_y × p, e_z × p]``. With ``Q`` an orthonormal basis
of ``range R`` and ``X`` the least-squares solution of ``T X = Q`` (normal equations,
sparse), the residual ``T X − Q`` vanishes on exactly those combinations ``y``: its small
singular vectors. Every combination is found, rotations about axes that do not pass
through the origin included (a pinned edge along ``x = 1`` leaves the rotation about it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

Array = NDArray[np.float64]
EXACT = 1e-8
"""A combination is rigid-and-allowed when ``‖T x − R y‖ <= EXACT ‖R y‖``."""


@dataclass(frozen=True)
class RigidMotions:
    """Free rigid motions: ``reduced (n_free, k)`` M-agnostic orthonormal columns,
    ``twists (6, k)`` their ``(t, ω)`` with ``T reduced = R twists``."""

    reduced: Array
    twists: Array

    @property
    def count(self) -> int:
        return self.reduced.shape[1]


def free_rigid_motions(T: sp.spmatrix, points: Array) -> RigidMotions:
    """The rigid motions in ``range T`` for control points ``points (n, 3)``."""
    P = np.asarray(points, dtype=float).reshape(-1, 3)
    motions = [np.tile(np.eye(3)[c], (P.shape[0], 1)) for c in range(3)]
    motions += [np.cross(np.eye(3)[c], P) for c in range(3)]
    R = np.stack([m.ravel() for m in motions], axis=1)
    Q, S = np.linalg.qr(R)
    keep = np.abs(np.diag(S)) > 1e-12 * np.abs(np.diag(S)).max()   # points on a line
    Q, S = Q[:, keep], S[keep]
    normal = sp.csc_matrix(T.T @ T)
    X = spla.splu(normal).solve(np.asarray(T.T @ Q))
    residual = np.asarray(T @ X) - Q
    _, s, vt = np.linalg.svd(residual, full_matrices=False)
    y = vt[s <= EXACT].T                                          # (m, k), orthonormal
    if y.shape[1] == 0:
        return RigidMotions(np.zeros((T.shape[1], 0)), np.zeros((6, 0)))
    reduced = X @ y
    u, sv, _ = np.linalg.svd(reduced, full_matrices=False)
    twists = np.linalg.lstsq(S, y, rcond=None)[0]                  # R twists = Q y
    return RigidMotions(u[:, sv > 1e-10 * sv.max()], twists)


def _vector(v: Array) -> str:
    v = v / np.linalg.norm(v)
    v = v * np.sign(v[np.argmax(np.abs(v))])                 # largest component positive
    v = np.where(np.abs(v) < 1e-9 * max(np.abs(v).max(), 1e-300), 0.0, v)
    return "(" + ", ".join(f"{x:.4g}" for x in v + 0.0) + ")"


def _canonical(span: Array) -> list[Array]:
    """Unit vectors spanning ``span (3, r)``: the coordinate axes it contains first."""
    r = span.shape[1]
    if r == 0:
        return []
    Q = np.linalg.qr(span)[0]
    out = [e for e in np.eye(3) if np.linalg.norm(Q.T @ e) > 1 - 1e-9][:r]
    while len(out) < r:
        rest = Q - np.column_stack(out) @ (np.column_stack(out).T @ Q) if out else Q
        u, s, _ = np.linalg.svd(rest)
        out.append(u[:, 0])
    return out


def describe(twists: Array, size: float = 1.0) -> list[str]:
    """Words for a basis of the free motions: rotations about axes, then translations.

    The rotation parts ``ω`` span a subspace (its coordinate axes named first); each such
    ``ω`` comes with a combination of the motions giving it, a rotation about the axis
    through ``p0 = ω × t/|ω|²`` (its screw part named when present), the free translations
    taken out of ``t`` (the axis nearest the origin); the combinations without rotation
    are translations. ``size`` is the extent of the net,
    the length that makes ``|ω| size`` comparable with ``|t|``.
    """
    if twists.shape[1] == 0:
        return []
    t, w = twists[:3], twists[3:]
    u, s, vt = np.linalg.svd(w, full_matrices=True)
    scale = max(float(np.abs(t).max(initial=0.0)), size * float(np.abs(w).max(initial=0.0)))
    rank = int(np.sum(s * size > 1e-8 * scale))
    words = []
    translations = _canonical(t @ vt[rank:].T)
    for axis in _canonical(u[:, :rank]):
        c = np.linalg.lstsq(w, axis, rcond=None)[0]
        tj = t @ c
        for e in translations:                         # the axis nearest the origin
            tj = tj - (e @ tj) * e
        through = np.cross(axis, tj)
        through = np.where(np.abs(through) < 1e-9 * size, 0.0, through) + 0.0
        screw = float(axis @ tj)
        words.append(f"rotation about the axis along {_vector(axis)} through "
                     f"({', '.join(f'{x:.4g}' for x in through)})"
                     + (f" (a screw, pitch {screw:.3g})" if abs(screw) > 1e-8 * size else ""))
    for direction in translations:
        words.append(f"translation along {_vector(direction)}")
    return words
