"""Probes of a body: where each entry of ``output.probes`` reads the body's displacement.

* ``[u, v]``: the point ``x_k(u, v)`` of the face ``k = output.probe_faces[i]`` (required);
* ``[x, y, z]``: a point ``p`` in space, read at its nearest point of a face, the face
  ``probe_faces[i]`` names, else the face it is nearest to. The nearest point of face
  ``k`` starts at the closest sample of a ``17 × 17`` parameter grid of every candidate
  face and is refined by Gauss–Newton steps on ``min |x_k(u, v) − p|²``,

  .. math:: (J^T J)\\, δ = J^T (p − x_k), \\qquad J = [x_u\\; x_v],

  kept on the parameter domain (clamped, or wrapped in a periodic direction);
* none given: every face's centre.

A probe's history is ``d_f(u, v) = Σ_kl N_kl(u, v) (P_f − P_rest)_kl`` of its face at every
frame (:meth:`splinedeform.readout.BodyReadout.probe`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
from numpy.typing import NDArray

#: samples per direction of each face for the start of the nearest-point search
START_SAMPLES = 17
#: Gauss–Newton steps of the nearest-point search (quadratic convergence from the start)
NEWTON_STEPS = 30


@dataclass(frozen=True)
class BodyProbe:
    """A probe on patch ``patch`` of a body at its parameters ``at``, named ``name``."""

    name: str
    patch: int
    at: tuple[float, float]


def _domain_point(surface: Any, uv: NDArray[np.float64]) -> NDArray[np.float64]:
    """``uv`` kept on the domain: clamped, or wrapped in a periodic direction."""
    out = uv.copy()
    for i, basis in enumerate((surface.basis_u, surface.basis_v)):
        out[i] = (np.mod(out[i], basis.length) if basis.periodic
                  else np.clip(out[i], 0.0, basis.length))
    return out


def _samples(surface: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Parameters ``(S, 2)`` and points ``(S, 3)`` of the start grid of ``surface``."""
    u = np.linspace(0.0, surface.basis_u.length, START_SAMPLES)
    v = np.linspace(0.0, surface.basis_v.length, START_SAMPLES)
    U, V = np.meshgrid(u, v, indexing="ij")
    return np.stack([U.ravel(), V.ravel()], axis=1), surface.evaluate_grid(u, v).reshape(-1, 3)


def nearest_point(surface: Any, point: Sequence[float]) -> tuple[float, tuple[float, float]]:
    """``(distance, (u, v))`` of the point of ``surface`` nearest to ``point`` (module
    docstring)."""
    p = np.asarray(point, dtype=float)
    params, X = _samples(surface)
    uv = params[int(np.argmin(np.linalg.norm(X - p, axis=1)))]
    for _ in range(NEWTON_STEPS):
        u, v = np.array([uv[0]]), np.array([uv[1]])
        r = p - surface.evaluate_grid(u, v)[0, 0]
        J = np.stack([surface.evaluate_grid(u, v, du=1)[0, 0],
                      surface.evaluate_grid(u, v, dv=1)[0, 0]], axis=1)
        step = np.linalg.lstsq(J, r, rcond=None)[0]
        new = _domain_point(surface, uv + step)
        if np.allclose(new, uv, rtol=0, atol=1e-13 * max(surface.basis_u.length,
                                                          surface.basis_v.length)):
            uv = new
            break
        uv = new
    x = surface.evaluate_grid(np.array([uv[0]]), np.array([uv[1]]))[0, 0]
    return float(np.linalg.norm(x - p)), (float(uv[0]), float(uv[1]))


def nearest_face(patches: Sequence[Any], point: Sequence[float]) -> int:
    """The patch whose start grid has the sample nearest to ``point`` (ties: the one whose
    refined nearest point is nearer)."""
    p = np.asarray(point, dtype=float)
    gaps = np.array([np.linalg.norm(_samples(s)[1] - p, axis=1).min() for s in patches])
    close = np.flatnonzero(gaps <= gaps.min() * (1 + 1e-9) + 1e-300)
    if close.size == 1:
        return int(close[0])
    return int(min(close, key=lambda k: nearest_point(patches[k], p)[0]))


def body_probes(scenario: Any, body: Any) -> list[BodyProbe]:
    """The probes of a body scenario (module docstring), checked at their keys."""
    from .scenario.body import check_at

    faces = list(getattr(body, "faces", range(len(body))))
    probes, named = scenario.output.probes, scenario.output.probe_faces
    if not probes:
        return [BodyProbe(f"face {f} centre", k, (0.5 * s.basis_u.length,
                                                   0.5 * s.basis_v.length))
                for k, (f, s) in enumerate(zip(faces, body.patches))]
    if named is not None and len(named) != len(probes):
        raise scenario.error("output.probe_faces", f"gives {len(named)} face(s) for "
                             f"{len(probes)} probe(s): one face per entry of output.probes")
    out = []
    for i, probe in enumerate(probes, start=1):
        where = f"output.probes[{i}]"
        patch = None
        if named is not None:
            if named[i - 1] not in faces:
                raise scenario.error(f"output.probe_faces[{i}]", f"face {named[i - 1]} is "
                                     f"not in this body, whose faces are {faces}")
            patch = faces.index(named[i - 1])
        if len(probe) == 2:
            if patch is None:
                raise scenario.error(where, "[u, v] on a body needs its face: give "
                                     "output.probe_faces (one face per probe), or a point "
                                     "[x, y, z] in space")
            check_at(scenario, where, (float(probe[0]), float(probe[1])), body[patch])
            at = (float(probe[0]), float(probe[1]))
            name = f"face {faces[patch]} ({at[0]:g}, {at[1]:g})"
        else:
            patch = nearest_face(body.patches, probe) if patch is None else patch
            at = nearest_point(body[patch], probe)[1]
            name = (f"point ({', '.join(f'{x:g}' for x in probe)}) on face {faces[patch]} "
                    f"({at[0]:.6g}, {at[1]:.6g})")
        out.append(BodyProbe(name, patch, at))
    return out
