"""The figures of one solved case: one row of the sweep's results.

From a :class:`~splinedeform.pipeline.RunResult` (displacements ``D_f`` of the control
net at the frames ``f``, sampled on the surface as ``d_f(u, v) = Σ B_k(u) B_l(v) D_f,kl``):

- ``max_displacement = max_f max_(u,v) |d_f(u, v)|`` on the output grid, and the frame
  time at which it is reached (``time_of_max``; dynamic solves only);
- ``omega_1 …``: the lowest natural angular frequencies ``ω_i = √λ_i`` of
  ``K φ = λ M φ`` (modes and dynamic solves with ``solve.modes > 0``);
- energies: static ``strain = ½ dᵀ K d``, ``work = Fᵀ d``, ``total``; dynamic the largest
  kinetic and strain energies over the frames and the total at the last frame;
- each probe ``p_i``: the largest ``|d_f(u_i, v_i)|`` over the frames and its
  displacement ``(x, y, z)`` at the last frame.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def figures(result: Any) -> dict[str, Any]:
    """The row's figures of one solved case (see the module's description)."""
    scenario = result.scenario
    kind = scenario.solve.kind
    row: dict[str, Any] = {"max_displacement": (float(result.max_displacement)
                                                if kind != "modes" else None)}
    if kind == "dynamic":
        row["time_of_max"] = float(result.times[int(np.argmax(result.displacement_per_frame))])
    if result.omegas is not None:
        row.update({f"omega_{i}": float(w) for i, w in enumerate(result.omegas, start=1)})
    energy = result.energy or {}
    if kind == "static":
        row.update({f"{name}_energy" if name != "work" else "work": float(energy[name])
                    for name in ("strain", "work", "total")})
    elif kind == "dynamic":
        row["kinetic_energy_max"] = float(np.max(energy["kinetic"]))
        row["strain_energy_max"] = float(np.max(energy["strain"]))
        row["total_energy_end"] = float(energy["total"][-1])
    for i, history in enumerate(result.probes.values(), start=1):
        history = np.asarray(history)
        row[f"p{i}_max"] = float(np.linalg.norm(history, axis=-1).max())
        row.update({f"p{i}_{c}": float(x) for c, x in zip("xyz", history[-1])})
    return row
