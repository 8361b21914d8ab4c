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
    ``(ru*rv, k)``), rest positions of the samples (float32 ``(ru*rv, 3)``) and the grid."""
    surf = basis.model.surface
    uu, vv = np.meshgrid(basis.samples_u, basis.samples_v, indexing="ij")
    rest = surf.evaluate(uu.ravel(), vv.ravel())
    return {"modes": int(basis.lam.size),
            "grid": [int(basis.samples_u.size), int(basis.samples_v.size)],
            "u": basis.samples_u.tolist(), "v": basis.samples_v.tolist(),
            "lam": _b64(basis.lam, "<f8"), "damping": _b64(basis.damping, "<f8"),
            "phi": _b64(basis.phi_samples), "rest": _b64(rest)}


def decode(text: str, dtype: str = "<f4") -> np.ndarray:
    """Inverse of the base64 encoding used by :func:`payload`."""
    return np.frombuffer(base64.b64decode(text), dtype=dtype)
