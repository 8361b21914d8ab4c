"""Reading one face of a STEP or IGES file with OpenCASCADE (run in a child process).

:func:`read_arrays` is what :func:`splinedeform.cad_step.read_step` runs through
:func:`splinedeform.cad_child.read_in_child`: it takes face number ``face`` of the file's
shape (``TopExp_Explorer`` order), converts its surface to a B-spline surface
(``GeomConvert``; planes, cylinders, cones … become exact NURBS), opens a periodic
direction (``SetUNotPeriodic``: clamped knots, same surface) and returns plain arrays:
degrees, the flat knot sequences (``N + n + 1`` knots), poles ``P_ij`` in the file's
length unit (OpenCASCADE reads every file in millimetres; the poles are divided by the
unit's length in millimetres), weights ``w_ij`` and the unit. This module imports only
numpy and OCP, so the child starts quickly.

IGES stores weights as written, but OpenCASCADE replaces a non-positive one by 1 (every
weight then reads 1: a rational surface silently made polynomial), so the weights of
every B-spline surface entity (type 128) are read from the file's text first and a face
whose surface has a weight ``<= 0`` is refused.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np

from .cad_units import IGES_FLAGS, STEP_NAMES, millimetres
from .errors import InputError

#: suffixes of the two formats
STEP_SUFFIXES = (".stp", ".step")
IGES_SUFFIXES = (".igs", ".iges")
#: a face's parameter range within this fraction of its surface's period is the whole period
PERIOD_TOL = 1e-9


MISSING = ("STEP and IGES files need the 'cad-step' extra (OpenCASCADE): "
           "pip install 'splinedeform[cad-step]'")


def ocp() -> Any:
    """OCP, with OpenCASCADE's messages below failures silenced (it prints statistics)."""
    try:
        import OCP
        from OCP.Message import Message, Message_Gravity
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise InputError(MISSING) from exc
    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)
    return OCP


def read_arrays(path: Path, face: int) -> dict[str, Any]:
    """Face ``face`` of a STEP or IGES file as plain arrays (see the module docstring)."""
    ocp()
    iges = path.suffix.lower() in IGES_SUFFIXES
    bad_weights = iges_bad_weights(path) if iges else {}
    reader, faces, units = read_faces(path)
    if not faces:
        raise InputError(f"{path}: the file holds no surface that OpenCASCADE can read (its "
                         f"{reader.NbRootsForTransfer()} root entities gave no face; a "
                         "malformed B-spline, e.g. weights <= 0 or too few poles for its "
                         "knots, is dropped)")
    if not 0 <= face < len(faces):
        raise InputError(f"{path}: face {face!r} out of range; the file holds "
                         f"{len(faces)} face(s), numbered 0..{len(faces) - 1}")
    source = f"{path} face {face}"
    if bad_weights:
        _refuse_bad_weights(reader, faces[face], bad_weights, source)
    arrays = face_arrays(faces[face], source)
    from OCP.TopAbs import TopAbs_REVERSED

    arrays["points"] /= millimetres(units)
    arrays["units"] = units
    arrays["reversed"] = bool(faces[face].Orientation() == TopAbs_REVERSED)
    return arrays


def read_faces(path: Path) -> tuple[Any, list[Any], str | None]:
    """``(reader, faces, units)``: the file read and transferred by OpenCASCADE."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    if path.suffix.lower() in STEP_SUFFIXES:
        from OCP.STEPControl import STEPControl_Reader as Reader
        kind = "STEP"
    else:
        from OCP.IGESControl import IGESControl_Reader as Reader
        kind = "IGES"
    reader = Reader()
    if reader.ReadFile(str(path)) != IFSelect_RetDone:
        raise InputError(f"{path}: not a {kind} file (OpenCASCADE cannot read it)")
    units = _step_units(reader, path) if kind == "STEP" else _iges_units(reader, path)
    reader.TransferRoots()
    faces = []
    explorer = TopExp_Explorer(reader.OneShape(), TopAbs_FACE)
    while explorer.More():
        faces.append((getattr(TopoDS, "Face", None) or TopoDS.Face_s)(explorer.Current()))
        explorer.Next()
    return reader, faces, units


def _step_units(reader: Any, path: Path) -> str | None:
    """The length unit a STEP file declares (``FileUnits``), None if it declares none."""
    from OCP.OCP.collections import Sequence_TCollection_AsciiString as Names

    lengths, angles, solid = Names(), Names(), Names()
    reader.FileUnits(lengths, angles, solid)
    names = {lengths.Value(k).ToCString().lower() for k in range(1, lengths.Length() + 1)}
    if not names:
        return None
    if len(names) > 1 or names.copy().pop() not in STEP_NAMES:
        warnings.warn(f"{path}: its length unit {sorted(names)} is not one of "
                      f"{sorted(STEP_NAMES)}; it is read in millimetres (OpenCASCADE's "
                      "conversion)", stacklevel=2)
        return "mm"
    return STEP_NAMES[names.pop()]


def _iges_units(reader: Any, path: Path) -> str | None:
    """The length unit of an IGES file's global section (unit flag, parameter 14)."""
    section = reader.IGESModel().GlobalSection()
    units = IGES_FLAGS.get(section.UnitFlag())
    if units is None or abs(section.UnitValue() / millimetres(units) - 1) > 1e-12:
        warnings.warn(f"{path}: its length unit (flag {section.UnitFlag()}, "
                      f"{section.UnitName().ToCString()!r}) is not one of "
                      f"{sorted(set(IGES_FLAGS.values()))}; it is read in millimetres "
                      "(OpenCASCADE's conversion)", stacklevel=2)
        return "mm"
    return units


def _whole_periods(surface: Any, bounds: np.ndarray) -> np.ndarray:
    """``bounds`` with a range spanning a period up to round-off set to exactly one period.

    OpenCASCADE's conversion of a periodic surface trimmed to slightly more than its period
    (a cone's face in ``u ∈ [-4e-13, 2π]``) has no poles.
    """
    bounds = bounds.copy()
    for k, (periodic, period) in enumerate(((surface.IsUPeriodic, surface.UPeriod),
                                            (surface.IsVPeriodic, surface.VPeriod))):
        if periodic():
            T = period()
            lo, hi = bounds[2 * k:2 * k + 2]
            if hi - lo >= T * (1 - PERIOD_TOL):
                lo = 0.0 if abs(lo) <= PERIOD_TOL * T else lo
                bounds[2 * k:2 * k + 2] = lo, lo + T
    return bounds


def _bounded_spline(surface: Any, bounds: np.ndarray, source: str, kind: str) -> Any:
    """The B-spline form of an unbounded surface on its face's parameter box (warned)."""
    from OCP.Geom import Geom_RectangularTrimmedSurface
    from OCP.GeomConvert import GeomConvert

    try:
        spline = GeomConvert.SurfaceToBSplineSurface_s(
            Geom_RectangularTrimmedSurface(surface, *map(float, bounds)))
    except Exception as exc:
        raise InputError(f"{source}: its surface ({kind}) has no B-spline form: "
                         f"{exc}") from None
    warnings.warn(f"{source}: its surface ({kind}) is unbounded; the face's parameter "
                  f"box (u, v) in {bounds.round(6).tolist()} is used", stacklevel=2)
    return spline


def _arrays(spline: Any, source: str) -> dict[str, Any]:
    nu, nv = spline.UDegree(), spline.VDegree()
    if nu < 1 or nv < 1:
        raise InputError(f"{source}: surface of degree ({nu}, {nv}); degree 0 is not supported")
    cu, cv = spline.NbUPoles(), spline.NbVPoles()
    if cu <= nu or cv <= nv:
        raise InputError(f"{source}: {cu} x {cv} poles for degrees ({nu}, {nv}); the surface "
                         "is degenerate")
    poles = [[spline.Pole(i, j) for j in range(1, cv + 1)] for i in range(1, cu + 1)]
    points = np.array([[(p.X(), p.Y(), p.Z()) for p in row] for row in poles])
    weights = np.array([[spline.Weight(i, j) for j in range(1, cv + 1)]
                        for i in range(1, cu + 1)])
    knots = []
    for sequence in (spline.UKnotSequence(), spline.VKnotSequence()):
        knots.append(np.array([sequence.Value(k) for k in
                               range(sequence.Lower(), sequence.Upper() + 1)]))
    return {"degrees": (nu, nv), "knots_u": knots[0], "knots_v": knots[1], "points": points,
            "weights": weights}


def iges_bad_weights(path: Path) -> dict[int, tuple[tuple[int, int], float]]:
    """Non-positive weights of the IGES B-spline surfaces (entity 128), read from the text.

    Returns ``{directory entry number: ((i, j), w_ij)}``, the first weight ``<= 0`` of
    each entity. The parameter data of entity 128 are ``128, K1, K2, M1, M2, PROP1-5``,
    ``K1 + M1 + 2`` knots in u, ``K2 + M2 + 2`` in v, then ``(K1 + 1)(K2 + 1)`` weights
    with ``i`` running fastest. Entities with inconsistent counts are left to OpenCASCADE.
    """
    from .input_files import MAX_ARRAY_BYTES, open_input

    with open_input(path, "IGES file", MAX_ARRAY_BYTES) as fh:
        lines = fh.read().decode("latin-1").splitlines()
    glob = "".join(line[:72] for line in lines if line[72:73] == "G")
    delimiter = glob[2] if glob.startswith("1H") and len(glob) > 2 else ","
    records: dict[int, list[str]] = {}
    for line in lines:
        if line[72:73] == "P" and line[64:72].strip().isdigit():
            records.setdefault(int(line[64:72]), []).append(line[:64])
    bad = {}
    for entry, chunks in records.items():
        fields = "".join(chunks).split(";")[0].split(delimiter)
        try:
            if int(fields[0]) != 128:
                continue
            k1, k2, m1, m2 = (int(f) for f in fields[1:5])
            start = 10 + (k1 + m1 + 2) + (k2 + m2 + 2)
            count = (k1 + 1) * (k2 + 1)
            if min(k1, k2, m1, m2) < 0 or len(fields) < start + count:
                continue
            w = np.array([float(f.strip().replace("D", "E") or 0) for f in
                          fields[start:start + count]])
        except ValueError:
            continue
        if np.any(w <= 0):
            k = int(np.argmax(w <= 0))
            bad[entry] = ((k % (k1 + 1), k // (k1 + 1)), float(w[k]))
    return bad


def _refuse_bad_weights(reader: Any, face: Any, bad: dict[int, tuple[tuple[int, int], float]],
                        source: str) -> None:
    """InputError if the surface entity of ``face`` (or, when unknown, any) has ``w <= 0``."""
    entry = None
    try:
        entity = reader.WS().TransferReader().EntityFromShapeResult(face, 1)
        entity = entity.Surface() if hasattr(entity, "Surface") else entity
        entry = int(reader.IGESModel().DNum(entity))
    except Exception:  # noqa: BLE001  (no mapping back to the file: check every surface)
        pass
    found = {entry: bad[entry]} if entry in bad else ({} if entry else bad)
    for number, ((i, j), w) in found.items():
        raise InputError(f"{source}: its B-spline surface (IGES entity 128, directory entry "
                         f"{number}) has weight w[{i}, {j}] = {w:g}; NURBS weights must be "
                         "> 0 (OpenCASCADE would read every weight as 1)")


def face_arrays(face: Any, source: str) -> dict[str, Any]:
    """One face's surface as open B-spline arrays (in millimetres), with whether it was
    ``periodic`` and ``closed`` in u and v before it was opened (warns if trimmed)."""
    spline, periodic, closed = open_spline(face, source)
    try:
        arrays = _arrays(spline, source)
    except InputError:
        raise
    except Exception as exc:  # Standard_OutOfRange and kin: a degenerate conversion
        raise _conversion_error(face, source, exc) from None
    arrays["periodic"], arrays["closed"] = periodic, closed
    return arrays


def open_spline(face: Any, source: str) -> tuple[Any, tuple[bool, bool], tuple[bool, bool]]:
    """``(spline, periodic, closed)``: the face's surface as an open ``Geom_BSplineSurface``
    and whether it was periodic and closed in u and v before it was opened."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepTools import BRepTools
    from OCP.GeomConvert import GeomConvert

    surface = BRep_Tool.Surface_s(face)
    bounds = np.array(BRepTools.UVBounds_s(face))
    kind = surface.DynamicType().Name()
    try:
        spline = GeomConvert.SurfaceToBSplineSurface_s(surface)
    except Exception:  # OpenCASCADE raises Standard_Failure: an infinite plane, cone, …
        spline = None
    if spline is None:
        spline = _bounded_spline(surface, _whole_periods(surface, bounds), source, kind)
    else:
        natural = np.array(spline.Bounds())
        if np.abs(bounds - natural).max() > 1e-9 * max(1.0, np.abs(natural).max()):
            warnings.warn(f"{source} is trimmed to (u, v) in {bounds.round(6).tolist()}; its "
                          "whole underlying surface is used", stacklevel=2)
    periodic = (bool(spline.IsUPeriodic()), bool(spline.IsVPeriodic()))
    closed = (bool(spline.IsUClosed()), bool(spline.IsVClosed()))
    try:
        if spline.IsUPeriodic():
            spline.SetUNotPeriodic()
        if spline.IsVPeriodic():
            spline.SetVNotPeriodic()
    except Exception as exc:  # Standard_OutOfRange and kin: a degenerate conversion
        raise _conversion_error(face, source, exc) from None
    return spline, periodic, closed


def _conversion_error(face: Any, source: str, exc: Exception) -> InputError:
    from OCP.BRep import BRep_Tool

    kind = BRep_Tool.Surface_s(face).DynamicType().Name()
    return InputError(f"{source}: OpenCASCADE could not convert its surface ({kind}) to an "
                      f"open B-spline surface ({type(exc).__name__}: {exc})")


def list_step_arrays(path: Path) -> dict[str, Any]:
    """Every face of a STEP or IGES file: its object (the index and type of the top-level
    shape holding it), whether it is trimmed, closed and periodic, and its NURBS arrays in
    the file's unit (run in the child). A face that cannot be read has an ``error``."""
    ocp()
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS_Iterator

    return faces_listing(path, *read_faces(path))


def faces_listing(path: Path, reader: Any, faces: list[Any], units: str | None
                  ) -> dict[str, Any]:
    """What :func:`list_step_arrays` returns, of a file already read; ``reversed`` is
    whether the face's orientation in the shape is ``TopAbs_REVERSED`` (its normal is
    ``-(S_u × S_v)``)."""
    from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS_Iterator

    iges = path.suffix.lower() in IGES_SUFFIXES
    bad_weights = iges_bad_weights(path) if iges else {}
    shape = reader.OneShape()
    children = []
    iterator = TopoDS_Iterator(shape)
    while iterator.More():
        children.append(iterator.Value())
        iterator.Next()
    if shape.ShapeType().name != "TopAbs_COMPOUND" or not children:
        children = [shape]
    owners: list[int | None] = []        # the explorer visits a compound's children in order
    for index, child in enumerate(children):
        explorer = TopExp_Explorer(child, TopAbs_FACE)
        while explorer.More():
            k = len(owners)
            owners.append(index if k < len(faces) and faces[k].IsSame(explorer.Current())
                          else None)
            explorer.Next()
    if len(owners) != len(faces):
        owners = [None] * len(faces)
    entries = []
    for number, face in enumerate(faces):
        owner = owners[number]
        kind = (children[owner] if owner is not None else shape).ShapeType().name
        entry: dict[str, Any] = {"object": owner, "name": None, "layer": None,
                                 "kind": kind.split("_")[-1].lower(),
                                 "reversed": bool(face.Orientation() == TopAbs_REVERSED)}
        source = f"{path} face {number}"
        try:
            if bad_weights:
                _refuse_bad_weights(reader, face, bad_weights, source)
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                arrays = face_arrays(face, source)
            arrays["points"] /= millimetres(units)
            arrays["trimmed_area"] = _area(face) / millimetres(units) ** 2
            entry.update(arrays)
            from .cad_trims import listed
            from .cad_trims_step import face_trim_arrays

            entry.update(listed(lambda: face_trim_arrays(face, source)))
            entry["trimmed"] = _wires(face) > 1 or any("trimmed" in str(w.message)
                                                         for w in caught)
        except InputError as exc:
            entry["error"] = str(exc)
        entries.append(entry)
    return {"faces": entries, "units": units}


def _area(face: Any) -> float:
    """Area of the face as bounded by its loops (OpenCASCADE's ``BRepGProp``), in mm²."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    properties = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face, properties)
    return float(properties.Mass())


def _wires(face: Any) -> int:
    """Number of wires (outer and inner loops) of a face."""
    from OCP.TopAbs import TopAbs_WIRE
    from OCP.TopExp import TopExp_Explorer

    explorer, count = TopExp_Explorer(face, TopAbs_WIRE), 0
    while explorer.More():
        count += 1
        explorer.Next()
    return count

