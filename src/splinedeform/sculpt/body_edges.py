"""The boundary edges of a body on the sculpting page, each with its own preset.

A body's boundary edges (edges no other face meets, :attr:`~splinedeform.body.Body.
topology`) take ``boundary.u0`` of the scenario, replaced edge by edge by
``[boundary.faces]`` (``3 = {v1 = "clamped"}``, the file's face numbers;
:func:`splinedeform.scenario.body.face_presets`). The page lists every boundary edge as
``(face, side)`` with its preset and sends back only the edges whose preset differs from
the one for every edge, as ``boundary.faces``; the scenario reader validates them (a face
not in the body, an interface or a pole is refused at its key).
"""

from __future__ import annotations

from typing import Any, Mapping

from ..scenario.spec import Scenario


def boundary_edges(scenario: Scenario, model: Any) -> list[dict[str, Any]]:
    """``[{"face": f, "patch": p, "edge": side, "preset": preset}, ...]``: every boundary
    edge of the body of ``model`` (patch ``p`` is face ``f`` of the file) with the preset
    the scenario gives it."""
    from ..scenario.body import face_presets

    body = model.body
    faces = list(getattr(body, "faces", range(len(body.patches))))
    presets = face_presets(scenario, body) if hasattr(body, "patch_of_face") else scenario.boundary.u0
    return [{"face": int(faces[p]), "patch": int(p), "edge": side,
             "preset": presets if isinstance(presets, str) else presets[(p, side)]}
            for p, side in body.topology.boundary]


def faces_override(faces: Mapping[str, Mapping[str, str]] | None) -> dict[str, dict[str, str]] | None:
    """``boundary.faces`` of a re-solve: the edges the page set on their own (None: none)."""
    named = {str(face): dict(edges) for face, edges in (faces or {}).items() if edges}
    return named or None
