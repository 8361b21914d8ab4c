"""NURBS patches to and from STEP and IGES files (OpenCASCADE, through ``cadquery-ocp``).

A :class:`~splinedeform.cad.NurbsPatch` becomes an OpenCASCADE ``Geom_BSplineSurface``
(poles ``P_ij``, weights ``w_ij``, distinct knots with multiplicities, degrees) bounded
by its natural edges as one face; faces are written as a compound with
``STEPControl_Writer`` / ``IGESControl_Writer``. Reading takes face number ``face`` of
the file's shape (``TopExp_Explorer`` order), converts its surface to a B-spline surface
(``GeomConvert``; planes, cylinders, … become exact NURBS), opens a periodic direction
(``SetUNotPeriodic``: clamped knots, same surface) and returns the flat knot sequence
(``N + n + 1`` knots), poles and weights. Faces are read untrimmed. Needs the
``cad-step`` extra (``cadquery-ocp``, a large binary package).
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from .cad import NurbsPatch, frame_patches
from .errors import InputError
from .export.atomic import atomic_path

#: suffixes of the two formats
STEP_SUFFIXES = (".stp", ".step")
IGES_SUFFIXES = (".igs", ".iges")
#: OpenCASCADE tolerance for the natural edges of a written face (model units)
EDGE_TOLERANCE = 1e-9


def _ocp() -> Any:
    """OCP, with OpenCASCADE's messages below failures silenced (it prints statistics)."""
    try:
        import OCP
        from OCP.Message import Message, Message_Gravity
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise InputError("STEP and IGES files need the 'cad-step' extra (OpenCASCADE): "
                         "pip install 'splinedeform[cad-step]'") from exc
    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)
    return OCP


def _collections() -> tuple[Any, Any, Any, Any]:
    """``(Array1 of double, Array1 of int, Array2 of double, Array2 of gp_Pnt)``.

    OCP 7.8+ names them ``OCP.OCP.collections.Array1_double`` …; older releases
    ``TColStd_Array1OfReal`` …; both index from the lower bound given.
    """
    try:
        from OCP.OCP.collections import Array1_double, Array1_int, Array2_double, Array2_gp_Pnt
        return Array1_double, Array1_int, Array2_double, Array2_gp_Pnt
    except ImportError:  # pragma: no cover - older OCP
        from OCP.TColgp import TColgp_Array2OfPnt
        from OCP.TColStd import (TColStd_Array1OfInteger, TColStd_Array1OfReal,
                                 TColStd_Array2OfReal)
        return TColStd_Array1OfReal, TColStd_Array1OfInteger, TColStd_Array2OfReal, \
            TColgp_Array2OfPnt


def bspline_surface(patch: NurbsPatch) -> Any:
    """The ``Geom_BSplineSurface`` of ``patch`` (knots as distinct values + multiplicities)."""
    _ocp()
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt

    A1d, A1i, A2d, A2p = _collections()
    P, w = np.asarray(patch.points, dtype=float), np.asarray(patch.weights, dtype=float)
    nu, nv = w.shape
    poles, weights = A2p(1, nu, 1, nv), A2d(1, nu, 1, nv)
    for i, j in np.ndindex(nu, nv):  # OpenCASCADE arrays are filled one entry at a time
        poles.SetValue(i + 1, j + 1, gp_Pnt(*map(float, P[i, j])))
        weights.SetValue(i + 1, j + 1, float(w[i, j]))
    arrays = []
    for knots in (patch.knots_u, patch.knots_v):
        values, mults = np.unique(np.asarray(knots, dtype=float), return_counts=True)
        a, m = A1d(1, values.size), A1i(1, values.size)
        for k, (value, mult) in enumerate(zip(values, mults), start=1):
            a.SetValue(k, float(value))
            m.SetValue(k, int(mult))
        arrays.append((a, m))
    (ku, mu), (kv, mv) = arrays
    return Geom_BSplineSurface(poles, weights, ku, kv, mu, mv, int(patch.degrees[0]),
                               int(patch.degrees[1]), False, False)


def write_step(path: str | os.PathLike, patches: list[NurbsPatch]) -> Path:
    """Write ``patches`` as untrimmed B-spline faces of one compound to a STEP or IGES
    file, chosen by the suffix (atomically); return its path."""
    _ocp()
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.TopoDS import TopoDS_Compound

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in STEP_SUFFIXES + IGES_SUFFIXES:
        raise InputError(f"{path}: STEP or IGES files end in {STEP_SUFFIXES + IGES_SUFFIXES}")
    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    for patch in patches:
        builder.Add(compound, BRepBuilderAPI_MakeFace(bspline_surface(patch),
                                                      EDGE_TOLERANCE).Face())
    with atomic_path(path) as tmp:
        if suffix in STEP_SUFFIXES:
            from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

            writer = STEPControl_Writer()
            ok = writer.Transfer(compound, STEPControl_AsIs) == IFSelect_RetDone and \
                writer.Write(str(tmp)) == IFSelect_RetDone
        else:
            from OCP.IGESControl import IGESControl_Writer

            writer = IGESControl_Writer("MM", 1)   # faces as B-rep entities, millimetres
            ok = writer.AddShape(compound)
            writer.ComputeModel()
            ok = ok and writer.Write(str(tmp))
        if not ok:
            raise InputError(f"{path}: OpenCASCADE could not write the file")
    return path


def write_frames_step(path: str | os.PathLike, surface: Any, times: Any, nets: Any) -> Path:
    """The initial surface (face 0) and every frame ``k`` (face ``k + 1``) in one STEP or
    IGES file, same degrees, knots and weights (see :func:`splinedeform.cad.frame_patches`)."""
    return write_step(path, frame_patches(surface, times, nets)[0])


def _faces(path: Path) -> list[Any]:
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
    reader.TransferRoots()
    shape = reader.OneShape()
    faces = []
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        faces.append(_to_face(TopoDS, explorer.Current()))
        explorer.Next()
    return faces


def read_step(path: str | os.PathLike, face: int = 0) -> NurbsPatch:
    """Face number ``face`` of a STEP or IGES file as a NURBS patch (its untrimmed surface).

    A face whose parameter bounds are smaller than its surface's (a trimmed face) is read
    as the whole underlying surface, with a warning.
    """
    _ocp()
    from OCP.BRep import BRep_Tool
    from OCP.BRepTools import BRepTools
    from OCP.GeomConvert import GeomConvert

    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    faces = _faces(path)
    if not faces:
        raise InputError(f"{path}: the file holds no surface")
    if isinstance(face, bool) or not isinstance(face, int) or not 0 <= face < len(faces):
        raise InputError(f"{path}: face {face!r} out of range; the file holds "
                         f"{len(faces)} face(s), numbered 0..{len(faces) - 1}")
    source = f"{path} face {face}"
    surface = BRep_Tool.Surface_s(faces[face])
    bounds = np.array(BRepTools.UVBounds_s(faces[face]))
    kind = surface.DynamicType().Name()
    try:
        spline = GeomConvert.SurfaceToBSplineSurface_s(surface)
    except Exception:  # OpenCASCADE raises Standard_Failure: an infinite plane, cone, …
        spline = None
    if spline is None:
        from OCP.Geom import Geom_RectangularTrimmedSurface

        try:
            spline = GeomConvert.SurfaceToBSplineSurface_s(
                Geom_RectangularTrimmedSurface(surface, *map(float, bounds)))
        except Exception as exc:
            raise InputError(f"{source}: its surface ({kind}) has no B-spline form: "
                             f"{exc}") from None
        warnings.warn(f"{source}: its surface ({kind}) is unbounded; the face's parameter "
                      f"box (u, v) in {bounds.round(6).tolist()} is used", stacklevel=2)
    else:
        natural = np.array(spline.Bounds())
        if np.abs(bounds - natural).max() > 1e-9 * max(1.0, np.abs(natural).max()):
            warnings.warn(f"{source} is trimmed to (u, v) in {bounds.round(6).tolist()}; its "
                          "whole underlying surface is used", stacklevel=2)
    if spline.IsUPeriodic():
        spline.SetUNotPeriodic()
    if spline.IsVPeriodic():
        spline.SetVNotPeriodic()
    return _patch(spline, source)


def _patch(spline: Any, source: str) -> NurbsPatch:
    nu, nv = spline.UDegree(), spline.VDegree()
    if nu < 1 or nv < 1:
        raise InputError(f"{source}: surface of degree ({nu}, {nv}); degree 0 is not supported")
    cu, cv = spline.NbUPoles(), spline.NbVPoles()
    points = np.array([[_xyz(spline.Pole(i, j)) for j in range(1, cv + 1)]
                       for i in range(1, cu + 1)])
    weights = np.array([[spline.Weight(i, j) for j in range(1, cv + 1)]
                        for i in range(1, cu + 1)])
    knots = []
    for sequence in (spline.UKnotSequence(), spline.VKnotSequence()):
        knots.append(np.array([sequence.Value(k) for k in
                               range(sequence.Lower(), sequence.Upper() + 1)]))
    return NurbsPatch((nu, nv), knots[0], knots[1], points, weights)


def _to_face(topods: Any, shape: Any) -> Any:
    """``TopoDS::Face`` (``TopoDS.Face`` in OCP 7.8+, ``TopoDS.Face_s`` before)."""
    return (getattr(topods, "Face", None) or topods.Face_s)(shape)


def _xyz(p: Any) -> tuple[float, float, float]:
    return p.X(), p.Y(), p.Z()
