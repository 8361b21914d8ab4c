"""NURBS patches to and from STEP and IGES files (OpenCASCADE, through ``cadquery-ocp``).

A :class:`~splinedeform.cad.NurbsPatch` becomes an OpenCASCADE ``Geom_BSplineSurface``
(poles ``P_ij``, weights ``w_ij``, distinct knots with multiplicities, degrees) bounded
by its natural edges as one face, or, given its trim region, by wires whose edges have
the trim loops as pcurves (:mod:`splinedeform.cad_step_trims`); a face marked reversed
in its body is written ``TopAbs_REVERSED``. Faces are written as a compound with
``STEPControl_Writer`` / ``IGESControl_Writer``, in the patches' length unit (STEP
``LENGTH_UNIT``, IGES unit flag; millimetres when not known). Reading
(:func:`read_step`) runs :func:`splinedeform.cad_step_read.read_arrays` in a child
process, so that a file OpenCASCADE crashes on is an error naming the file; a face is
read untrimmed, in the file's unit. Needs the ``cad-step`` extra (``cadquery-ocp``, a
large binary package).
"""

from __future__ import annotations

import importlib.util
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .cad import NurbsPatch, frame_patches
from .cad_child import check_cad_file, read_in_child
from .cad_step_read import IGES_SUFFIXES, MISSING, STEP_SUFFIXES, ocp, read_arrays
from .cad_step_trims import checked_signs, checked_trims, oriented, trimmed_face
from .cad_units import millimetres, occt_name
from .errors import InputError
from .export.atomic import atomic_path

__all__ = ["IGES_SUFFIXES", "STEP_SUFFIXES", "bspline_surface", "read_step", "write_step",
           "write_frames_step"]

#: OpenCASCADE tolerance for the natural edges of a written face (model units)
EDGE_TOLERANCE = 1e-9
#: edges of written faces closer than this fraction of the patches' size are sewn into one
SEW_TOLERANCE = 1e-7

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


def bspline_surface(patch: NurbsPatch, scale: float = 1.0) -> Any:
    """The ``Geom_BSplineSurface`` of ``patch`` (knots as distinct values + multiplicities),
    its poles multiplied by ``scale`` (millimetres per unit of the patch, for OpenCASCADE)."""
    ocp()
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt

    A1d, A1i, A2d, A2p = _collections()
    P = np.asarray(patch.points, dtype=float) * scale
    w = np.asarray(patch.weights, dtype=float)
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


def write_step(path: str | os.PathLike, patches: list[NurbsPatch],
               units: str | None = None, shell: bool = False,
               trims: Sequence[Any] | None = None,
               orientation: Sequence[int] | None = None) -> Path:
    """Write ``patches`` as B-spline faces of one compound to a STEP or IGES file, chosen
    by the suffix (atomically); return its path.

    ``units`` (a key of :data:`splinedeform.cad_units.UNITS`; default: the first patch's,
    millimetres if that is not known) is the unit of the patches' coordinates and of the file.
    ``trims`` gives per patch its :class:`~splinedeform.trim.loops.TrimDomain` in the
    patch's parameters, or None: that face is bounded by its trim loops
    (:func:`splinedeform.cad_step_trims.trimmed_face`), the others by their natural edges.
    ``orientation`` gives per patch ``+1`` or ``-1`` (a face whose outward normal is
    ``-(S_u × S_v)``, written ``TopAbs_REVERSED``); default ``+1``.
    With ``shell``, the faces are sewn where their edges meet (OpenCASCADE's
    ``BRepBuilderAPI_Sewing``, within :data:`SEW_TOLERANCE` of the patches' size): one
    shell whose faces share their common edges, as the body they came from.
    """
    ocp()
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.Interface import Interface_Static
    from OCP.TopoDS import TopoDS_Compound

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in STEP_SUFFIXES + IGES_SUFFIXES:
        raise InputError(f"{path}: STEP or IGES files end in {STEP_SUFFIXES + IGES_SUFFIXES}")
    if units is None and patches:
        units = patches[0].units
    scale, name = millimetres(units), occt_name(units)
    domains = checked_trims(trims, len(patches))
    signs = checked_signs(orientation, len(patches))
    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    size = _size(patches) * scale
    faces = []
    for k, (patch, domain, sign) in enumerate(zip(patches, domains, signs)):
        surface = bspline_surface(patch, scale)
        if domain is None:
            face = BRepBuilderAPI_MakeFace(surface, EDGE_TOLERANCE * scale).Face()
        else:
            try:
                face = trimmed_face(surface, domain, size)
            except InputError as exc:
                raise InputError(f"{path}: face {k}: {exc}") from None
        faces.append(oriented(face, sign))
    for face in faces:
        builder.Add(compound, face)
    if shell and patches:
        compound = _sewn(faces, size)
    with atomic_path(path) as tmp:
        if suffix in STEP_SUFFIXES:
            from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

            writer = STEPControl_Writer()    # (which sets the unit to its default)
            before = Interface_Static.CVal_s("write.step.unit")
            Interface_Static.SetCVal_s("write.step.unit", name)  # converted from millimetres
            try:
                ok = writer.Transfer(compound, STEPControl_AsIs) == IFSelect_RetDone and \
                    writer.Write(str(tmp)) == IFSelect_RetDone
            finally:                         # a process-wide setting: left as it was
                Interface_Static.SetCVal_s("write.step.unit", before)
        else:
            from OCP.IGESControl import IGESControl_Writer

            writer = IGESControl_Writer(name, 1)   # faces as B-rep entities, in `units`
            ok = writer.AddShape(compound)
            writer.ComputeModel()
            ok = ok and writer.Write(str(tmp))
        if not ok:
            raise InputError(f"{path}: OpenCASCADE could not write the file")
    return path


def _size(patches: list[NurbsPatch]) -> float:
    """The diagonal of the patches' control points' bounding box (0 for no patch)."""
    if not patches:
        return 0.0
    points = np.concatenate([np.asarray(p.points, float).reshape(-1, 3) for p in patches])
    return float(np.linalg.norm(np.ptp(points, axis=0)))


def _sewn(faces: list[Any], size: float) -> Any:
    """The faces sewn into a shell (see :func:`write_step`), ``size`` in millimetres."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing

    sewing = BRepBuilderAPI_Sewing(SEW_TOLERANCE * max(size, 1e-300))
    for face in faces:
        sewing.Add(face)
    sewing.Perform()
    return sewing.SewedShape()


def write_frames_step(path: str | os.PathLike, surface: Any, times: Any, nets: Any,
                      units: str | None = None, trim: Any = None) -> Path:
    """The initial surface (face 0) and every frame ``k`` (face ``k + 1``) in one STEP or
    IGES file, same degrees, knots and weights (see :func:`splinedeform.cad.frame_patches`),
    in ``units``, each face bounded by the loops of ``trim`` (a
    :class:`~splinedeform.trim.loops.TrimDomain`) when given (see :func:`write_step`)."""
    patches = frame_patches(surface, times, nets)[0]
    return write_step(path, patches, units, trims=[trim] * len(patches))


def read_step(path: str | os.PathLike, face: int = 0) -> NurbsPatch:
    """Face number ``face`` of a STEP or IGES file as a NURBS patch (its untrimmed surface),
    in the file's length unit (:attr:`NurbsPatch.units`).

    Read in a child process (:func:`splinedeform.cad_child.read_in_child`): a file that
    crashes OpenCASCADE is an ``InputError`` naming the file. A face whose parameter bounds
    are smaller than its surface's (a trimmed face) is read as the whole underlying
    surface, with a warning.
    """
    path = Path(path)
    check_cad_file(path)
    if importlib.util.find_spec("OCP") is None:  # pragma: no cover - depends on the install
        raise InputError(MISSING)
    if isinstance(face, bool) or not isinstance(face, int) or face < 0:
        raise InputError(f"{path}: face {face!r} out of range; faces are numbered from 0")
    data = read_in_child(read_arrays, path, face, library="OpenCASCADE")
    return NurbsPatch(tuple(data["degrees"]), data["knots_u"], data["knots_v"],
                      data["points"], data["weights"], units=data["units"],
                      reversed=bool(data.get("reversed", False)))
