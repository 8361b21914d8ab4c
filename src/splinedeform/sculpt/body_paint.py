"""A body's free set on the sculpting page: the moving control points painted face by face.

The page paints the control points of the face under the pointer and sends, per face whose
net is not all free, the points that move: ``faces_free_points = {"3": [[i, j], ...]}``
(the file's face numbers, ``[i, j]`` = row ``i`` along u, column ``j`` along v of that
face's net). The session applies it as the scenario key ``boundary.faces_free_points``
(:func:`splinedeform.scenario.body.face_masks`: on a listed face every point not listed is
fixed, a face not listed moves; a point two faces share is fixed when either fixes it), so
the scenario reader refuses a face not in the body or an index off its net at its key, and
"Save" writes the key for ``splinedeform run``. One surface's set is ``free_points``; each
kind is refused where it does not apply.

A pin (alt-click) on a body is a bake whose message carries the painted set less the pinned
point, keyed by the face numbers of the basis baked: the session applies it before the bake,
which renumbers it to the baked file's faces (:func:`.history.baked_scenario`). A point
that faces share (a conforming interface's, a pole's) is one unknown, fixed when any face
fixes it; :func:`point_classes` tells the page which rows of its net are one point, so that
it shows (and sends) the pin held on every face that has it.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..scenario.spec import Scenario
from .messages import BakeMessage, ResolveMessage


def painted_overrides(message: ResolveMessage | BakeMessage, is_body: bool) -> dict[str, Any]:
    """The scenario overrides of the painted set of ``message`` (a re-solve's, or a pin's
    bake): ``boundary.free_points``
    of one surface or ``boundary.faces_free_points`` of a body (None removes a key: the
    whole net, or every face, moves); the kind that does not apply is refused."""
    points, faces = message.free_points, message.faces_free_points
    if is_body and points is not None:
        raise InputError("free_points lists the moving control points of one surface; this "
                         "is a body of faces: send each face's as faces_free_points "
                         '{"face": [[i, j], ...]}')
    if not is_body and faces is not None:
        raise InputError("faces_free_points lists the moving control points of a body's "
                         "faces; this is one surface: send them as free_points [[i, j], ...]")
    return {"boundary.free_points": None if points is None else [list(p) for p in points],
            "boundary.faces_free_points": None if faces is None else
            {str(face): [list(p) for p in listed] for face, listed in faces.items()}}


def body_free_mask(scenario: Scenario, basis: Any) -> NDArray[np.bool_]:
    """The moving set of a body's nets, patch after patch, row-major within a patch (the
    rows of :attr:`~.modal.SculptBasis.phi_net`), True = free: ``~fixed_p`` of a face
    that ``boundary.faces_free_points`` lists, every point of one it does not."""
    from ..scenario.body import face_masks

    masks = face_masks(scenario, basis.model.body) if hasattr(basis.model.body, "faces") else None
    return np.concatenate([np.ones(s.shape[0] * s.shape[1], bool) if fixed is None
                           else ~np.ravel(fixed)
                           for s, fixed in zip(basis.patches, masks or [None] * len(basis.patches))])


def pinned_body(scenario: Scenario, basis: Any, overrides: dict[str, Any]) -> Scenario:
    """``scenario`` with a pin's free set ``overrides["boundary.faces_free_points"]`` (the
    face numbers of ``basis``), checked on its body before the bake renumbers the faces:
    a face not in the body, an index off a face's net or a face left empty is refused as
    the page's setting (:func:`splinedeform.scenario.body.face_masks`)."""
    from ..errors import ScenarioError
    from ..scenario import with_overrides
    from ..scenario.body import face_masks
    from .wording import in_page_words

    if overrides.get("boundary.faces_free_points") is None:
        raise InputError("a pin on a body lists the free set less the pinned point as "
                         'faces_free_points {"face": [[i, j], ...]}')
    try:
        pinned = with_overrides(scenario, {"boundary.faces_free_points":
                                           overrides["boundary.faces_free_points"]},
                                origin="sculpt page")
        face_masks(pinned, basis.model.body)
    except ScenarioError as exc:
        raise InputError(in_page_words(str(exc), scenario.source)) from None
    return pinned


def point_classes(basis: Any) -> NDArray[np.int64]:
    """The point of the body each row of its nets is, patch after patch, row-major within a
    patch: rows of one class are one unknown (:func:`splinedeform.body.constraints.
    merged_classes`), each its own class elsewhere."""
    from ..body.constraints import merged_classes

    return merged_classes(basis.patches, basis.model.body.topology)
