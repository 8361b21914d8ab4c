"""The pushes of a session as ``[[load]]`` tables: one piecewise table per grab.

The page records a grab as a chain of pushes on one sample point: the force changes every
frame, each push starting when the previous one ends (``t_on`` of one = ``t_off`` of the
one before). A chain with forces ``F_1 … F_m`` switched at ``t_1 < … < t_m`` (and released
at ``t_off``, if it was) is the point force

    F(t) = Σ_c s_c(t) e_c,   s_c(t) = F_k · e_c  for t_k <= t < t_{k+1},  0 after t_off

written as ``profile = "piecewise"`` tables with the points ``[t_k, s(t_k)]`` (and
``[t_off, 0]``). When every ``F_k`` is parallel to one direction ``F*`` (a push along
the normal) one table says it all: ``force = F*`` (the largest of the chain) and
``s(t) = F_k · F* / |F*|²``; when the force turns (the spring to the pointer) it takes one
table per coordinate that is not zero throughout, ``e_c`` the axes. Either way the sum is
the page's force to rounding, so ``splinedeform run`` replays the drag.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .messages import PushMessage

PARALLEL = 1e-12
"""Forces whose cross product with the chain's largest is below this fraction of the
product of their lengths count as parallel (rounding of a force along the normal)."""


def grab_chains(pushes: Sequence[PushMessage]) -> list[list[PushMessage]]:
    """The pushes grouped into grabs: consecutive pushes on one sample, each starting when
    the one before ended (a push still held ends its chain)."""
    chains: list[list[PushMessage]] = []
    for push in pushes:
        last = chains[-1][-1] if chains else None
        if last is not None and last.index == push.index and last.t_off is not None \
                and last.t_off == push.t_on:
            chains[-1].append(push)
        else:
            chains.append([push])
    return chains


def chain_tables(chain: Sequence[PushMessage], at: list[float]) -> list[dict[str, Any]]:
    """The ``[[load]]`` tables (point force at ``at``) of one grab, see the module text."""
    forces = np.array([p.force for p in chain], dtype=float)               # (m, 3)
    times = [float(p.t_on) for p in chain]
    end = chain[-1].t_off
    largest = forces[np.argmax(np.linalg.norm(forces, axis=1))]
    size = float(np.linalg.norm(largest))
    if size == 0.0:
        return []                                                # no force at all
    cross = np.linalg.norm(np.cross(forces, largest), axis=1)
    if np.all(cross <= PARALLEL * np.linalg.norm(forces, axis=1) * size):
        directions = [largest]
        values = [forces @ largest / size**2]
    else:
        axes = [c for c in range(3) if np.any(forces[:, c] != 0.0)]
        directions = [np.eye(3)[c] for c in axes]
        values = [forces[:, c] for c in axes]
    tables = []
    for direction, s in zip(directions, values):
        points = [[t, float(v)] for t, v in zip(times, s)]
        if end is not None:
            points.append([float(end), 0.0])
        tables.append({"kind": "point", "at": list(at),
                       "force": [float(f) for f in direction],
                       "profile": "piecewise", "points": points})
    return tables
