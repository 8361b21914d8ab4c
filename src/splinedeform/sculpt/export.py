"""The modal basis as the page receives it once: JSON with float32 arrays in base64.

The page snaps a grab to the nearest sample point ``(u_i, v_j)``, so the participation of a
push is a row of ``Φ_s`` and the page needs no B-spline evaluation; the saved scenario
records the same ``(u_i, v_j)``.
"""

from __future__ import annotations

import base64
from typing import Any

import numpy as np

from .modal import SculptBasis


def _b64(array: np.ndarray, dtype: str = "<f4") -> str:
    return base64.b64encode(np.ascontiguousarray(array, dtype=dtype).tobytes()).decode("ascii")


def payload(basis: SculptBasis) -> dict[str, Any]:
    """JSON-ready modal data: ``lam``, ``damping`` (float64), ``phi`` (float32, sample-major
    ``(S, k)``), rest positions of the samples (float32 ``(S, 3)``) and the grid.

    The samples of a body's patches follow each other (``S = P ru rv``): ``grid`` is then
    ``[P ru, rv]``, ``u`` the patches' u samples one after the other and ``faces`` per patch
    its ``v`` samples, control net shape, periodic directions, Greville abscissae and
    parameter lengths, so the page draws each patch as its own grid (no triangle joins two
    patches) and paints each patch's control points.

    With trimmed patches (:mod:`.trimmed`) the trim crossings follow the grids and
    ``trim`` holds the triangles to draw (int32 ``(F, 3)``), which samples lie inside the
    trims (uint8) and each crossing's patch and ``(u, v)``.
    """
    rest = [s.evaluate(*np.meshgrid(u, v, indexing="ij")).reshape(-1, 3)
            for s, (u, v) in zip(basis.patches, basis.samples)]
    trimmed, trim = basis.trimmed, None
    if trimmed is not None:
        for p, surface in enumerate(basis.patches):
            at = trimmed.uv[trimmed.patch == p]
            if len(at):
                rest.append(np.asarray(surface.evaluate(at[:, 0], at[:, 1])).reshape(-1, 3))
        trim = {"triangles": _b64(trimmed.triangles, "<i4"),
                "inside": _b64(trimmed.inside, "u1"),
                "crossings": {"face": trimmed.patch.tolist(), "u": trimmed.uv[:, 0].tolist(),
                              "v": trimmed.uv[:, 1].tolist()}}
    ru, rv = basis.grid
    return {"modes": int(basis.lam.size), "trim": trim,
            "grid": [len(basis.samples) * ru, rv],
            "u": np.concatenate([u for u, _ in basis.samples]).tolist(),
            "v": basis.samples[0][1].tolist(),
            "faces": [{"v": v.tolist(), "net": list(s.shape),
                       "periodic": [bool(s.basis_u.periodic), bool(s.basis_v.periodic)],
                       "greville": [s.basis_u.greville().tolist(), s.basis_v.greville().tolist()],
                       "domain": [float(s.basis_u.length), float(s.basis_v.length)]}
                      for s, (_, v) in zip(basis.patches, basis.samples)],
            "lam": _b64(basis.lam, "<f8"), "damping": _b64(basis.damping, "<f8"),
            "phi": _b64(basis.phi_samples), "rest": _b64(np.concatenate(rest))}


def decode(text: str, dtype: str = "<f4") -> np.ndarray:
    """Inverse of the base64 encoding used by :func:`payload`."""
    return np.frombuffer(base64.b64decode(text), dtype=dtype)
