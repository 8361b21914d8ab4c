"""A trimmed CAD face in a scenario: its own trim loops attached to the built surface.

Face ``face`` of a ``.3dm``, STEP or IGES file is read as its whole underlying surface;
its loops (:func:`splinedeform.cad_trims.read_trims`) are attached after ``elevate`` and
``refine`` (the loops live in parameter space, refinement does not move them), so the
model and every output use the trimmed region only. ``surface.trimmed`` switches this:
by default the trim is taken where the trimmed model can hold the surface (any physics
and any NURBS weights, for one face and for a face of a body; clamped knots with simple
interior knots, not periodic; :func:`~splinedeform.trim.surface_trim.trim_grid`) and the
whole face is used otherwise, with one warning line naming the face and the reason;
``trimmed = true`` refuses such a face, ``trimmed = false`` takes the whole face without a
word.
"""

from __future__ import annotations

import warnings
from contextlib import contextmanager
from typing import Any, Iterator

from ..errors import InputError, InputWarning
from ..surface import Surface
from ..trim.model_matrices import loop_names
from ..trim.surface_trim import equal_cell_form, holed_rectangle, whole_rectangle

#: what the CAD readers say of a trimmed face read whole; replaced by this module's word
WHOLE_SURFACE = "whole underlying surface is used"


@contextmanager
def reader_warnings() -> Iterator[list[warnings.WarningMessage]]:
    """Record the warnings of reading a face, to be shown by :func:`with_face_trim`."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield caught


def _shown(caught: list[warnings.WarningMessage], drop_whole: bool) -> None:
    """Show the recorded warnings again, those about the whole surface left out."""
    for w in caught:
        if drop_whole and WHOLE_SURFACE in str(w.message):
            continue
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def _face_number(spec: Any) -> int:
    """The face read: ``face``, or the one face chosen by ``faces`` (as the reader chose it,
    :func:`splinedeform.cad_body.choose_faces`)."""
    faces = spec.parameters.get("faces")
    if faces is None:
        return int(spec.parameters["face"])
    from ..cad_body import choose_faces, read_listing

    chosen = choose_faces(read_listing(spec.path),
                          list(faces) if isinstance(faces, tuple) else faces, str(spec.path))
    return int(chosen[0])


def with_face_trim(scenario: Any, surface: Any, caught: list[warnings.WarningMessage]) -> Any:
    """``surface`` (face ``surface.face`` of ``surface.path``, refined) with the face's trim
    loops attached, or whole (module docstring); the reader's warnings ``caught`` shown
    again, its word on the whole surface replaced by one line of this module's."""
    spec = scenario.surface
    asked = spec.parameters.get("trimmed")
    from .body import FileBody
    if isinstance(surface, FileBody) and asked is not False:
        return with_body_trims(scenario, surface, caught)
    if not isinstance(surface, Surface) or spec.trim is not None or asked is False:
        _shown(caught, drop_whole=asked is False)          # the whole face was asked for
        return surface
    from ..cad_trims import read_trims

    face, path = _face_number(spec), spec.path
    source, reason = f"{path} face {face}", None
    try:
        domain = read_trims(path, face)
    except InputError as exc:                               # loops that cannot be read
        domain, reason = None, f"its trim loops cannot be read ({exc})"
    else:
        if domain is None or (not domain.holes and whole_rectangle(surface, domain.outer)):
            _shown(caught, drop_whole=False)
            return surface                                  # not trimmed: nothing to attach
    trimmed = None
    if reason is None:
        try:
            trimmed = equal_cell_form(surface).with_trim(domain)
        except InputError as exc:
            reason = str(exc)
    if reason is not None:
        if asked:
            raise scenario.error("surface.trimmed", f"{source} is trimmed, but {reason}; "
                                 "set trimmed = false to take its whole surface")
        _shown(caught, drop_whole=True)
        warnings.warn(f"{source} is trimmed; its whole underlying surface is used: {reason}",
                      InputWarning, stacklevel=2)
        return surface
    _shown(caught, drop_whole=True)
    return trimmed


def face_loop_presets(scenario: Any, surface: Any) -> dict[str, str]:
    """``boundary.loops`` as the model's boundary keys (``outer``, ``hole1.0``, …), checked
    against the loops of the trimmed CAD face ``surface``; a loop or trim edge the face has
    not, or a face with no loops to hold, is refused at its key."""
    named = scenario.raw.get("boundary", {}).get("loops")
    if not named:
        return {}
    where = "boundary.loops"
    spec = scenario.surface
    if spec.shape != "cad" or spec.trim is not None:
        raise scenario.error(where, "names the trim loops of a CAD face (surface.shape = "
                             "\"cad\"); loops given by hand take their condition as `edge` "
                             "in [[surface.trim.loops]]")
    domain = getattr(surface, "trim", None)
    if domain is None:
        raise scenario.error(where, f"{spec.path} is simulated on its whole surface (a body "
                             "of faces, a face without trim loops, or trimmed = false), so "
                             "it has no trim loops to hold")
    names = loop_names(domain)
    out: dict[str, str] = {}
    for name, value in named.items():
        if name not in names:
            raise scenario.error(f"{where}.{name}", f"the face has no loop {name!r}; its loops "
                                 f"are {list(names)} (splinedeform faces lists them)")
        if name == "outer" and holed_rectangle(surface):
            raise scenario.error(f"{where}.outer", "the face's outer loop is its parameter "
                                 "rectangle: hold its edges u0, u1, v0, v1 in [boundary]")
        if isinstance(value, str):
            out[name] = value
            continue
        count = domain.edge_count(names.index(name))
        for key, preset in value.items():
            if int(key) >= count:
                raise scenario.error(f"{where}.{name}.{key}", f"loop {name!r} is made of "
                                     f"{count} trim edge(s), numbered 0 to {count - 1}")
            out[name if count == 1 else f"{name}.{int(key)}"] = preset
    return out


def with_body_trims(scenario: Any, body: Any, caught: list[warnings.WarningMessage]) -> Any:
    """A body of CAD faces (:class:`~splinedeform.scenario.body.FileBody`) with each trimmed
    face's loops attached where the trimmed model can hold it (as for one face, module
    docstring), so that faces sharing a trim curve are coupled along it
    (:mod:`splinedeform.body.trimmed`); the file's interfaces of a face whose rectangle
    edges leave its region are dropped. A face that cannot be trimmed is taken whole, with
    the reader's one warning line (with its reason); ``trimmed = true`` refuses it."""
    from ..body.trimmed import edgeless
    from ..cad_trims import read_trims
    from .body import FileBody

    path, asked = scenario.surface.path, scenario.surface.parameters.get("trimmed")
    patches, kept_whole = list(body.patches), []
    trimmed_faces: set[int] = set()
    for p, (face, surface) in enumerate(zip(body.faces, body.patches)):
        source, reason = f"{path} face {face}", None
        try:
            domain = read_trims(path, face)
        except InputError as exc:
            domain, reason = None, f"its trim loops cannot be read ({exc})"
        else:
            if domain is None or (not domain.holes and whole_rectangle(surface, domain.outer)):
                continue
        if reason is None:
            try:
                patches[p] = equal_cell_form(surface).with_trim(domain)
                trimmed_faces.add(face)
                continue
            except InputError as exc:
                reason = str(exc)
        if asked:
            raise scenario.error("surface.trimmed", f"{source} is trimmed, but {reason}; "
                                 "set trimmed = false to take its whole surface")
        kept_whole.append(f"{source} is trimmed; its whole underlying surface is used: "
                          f"{reason}")
    for w in caught:
        message = str(w.message)
        if WHOLE_SURFACE in message and any(message.startswith(f"{path} face {f} ")
                                            for f in trimmed_faces | set(body.faces)):
            continue
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    for line in kept_whole:
        warnings.warn(line, InputWarning, stacklevel=2)
    if not trimmed_faces:
        return body
    gone = {p for p, s in enumerate(patches) if edgeless(s)}
    interfaces = [i for i in body.interfaces if not {i.a, i.b} & gone]
    return FileBody(patches, interfaces, body.faces, body.counts, body.orientation)
