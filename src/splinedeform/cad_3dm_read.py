"""Reading one surface of a ``.3dm`` file with rhino3dm (run in a child process).

:func:`read_3dm_arrays` is what :func:`splinedeform.cad.read_3dm` runs through
:func:`splinedeform.cad_child.read_in_child`. openNURBS stores ``N + n - 1`` knots (the
first and last are implied) and homogeneous control points ``(w x, w y, w z, w)``; the
result is plain arrays: degrees, full knot vectors (``N + n + 1`` knots), points
``P_ij``, weights ``w_ij`` (all ``> 0``, else refused) and the file's length unit. This
module imports only numpy and rhino3dm, so the child starts quickly.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np

from .cad_units import units_from_rhino
from .errors import InputError, InputWarning

#: points per side, and distance (relative to the net's size), of the trimming test
TRIM_SAMPLES = 257
TRIM_TOL = 1e-4


def _rhino3dm() -> Any:
    try:
        import rhino3dm
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise InputError("reading or writing .3dm files needs the 'cad' extra: "
                         "pip install 'splinedeform[cad]'") from exc
    return rhino3dm


def read_3dm_arrays(path: Path, face: int) -> dict[str, Any]:
    """What :func:`read_3dm` reads, as plain arrays (run in the child process)."""
    r3 = _rhino3dm()
    model = r3.File3dm.Read(str(path))
    if model is None:
        raise InputError(f"{path}: not a .3dm (openNURBS) file")
    found, geometry_of = [], []
    for _, _, geometry in _objects(model, r3):
        if isinstance(geometry, r3.Brep):
            found += [(f, True) for f in geometry.Faces]
            geometry_of += [geometry] * len(geometry.Faces)
        else:
            found.append((geometry, False))
            geometry_of.append(geometry)
    if not found:
        raise InputError(f"{path}: the file holds no surface")
    if not 0 <= face < len(found):
        raise InputError(f"{path}: face {face!r} out of range; the file holds "
                         f"{len(found)} surface(s), numbered 0..{len(found) - 1}")
    surface, in_brep = found[face]
    source = f"{path} face {face}"
    reversed_ = in_brep and bool(surface.OrientationIsReversed)
    if in_brep:
        if _is_trimmed(geometry_of[face], surface):
            warnings.warn(f"{source} is a trimmed Brep face; its whole underlying surface "
                          "is used", InputWarning, stacklevel=2)
        surface = surface.UnderlyingSurface()
    data = _patch_from_rhino(surface.ToNurbsSurface(), source)
    data["units"] = units_from_rhino(str(model.Settings.ModelUnitSystem).split(".")[-1])
    data["reversed"] = reversed_
    return data


def _objects(model: Any, r3: Any) -> list[tuple[int, Any, Any]]:
    """``(object index, object, geometry)`` of every object holding surfaces, in file order:
    a Brep, a plain surface, or an extrusion as its Brep (its wall and caps)."""
    out = []
    for index, obj in enumerate(model.Objects):
        geometry = obj.Geometry
        if isinstance(geometry, r3.Extrusion):
            geometry = geometry.ToBrep(False)
        if isinstance(geometry, (r3.Brep, r3.Surface)):
            out.append((index, obj, geometry))
    return out


def list_3dm_arrays(path: Path) -> dict[str, Any]:
    """Every face of a ``.3dm`` file: its object (index, name, layer, kind), whether it is
    trimmed, closed and periodic in the file, whether its Brep marks it ``reversed``
    (``BrepFace.OrientationIsReversed``: its normal is ``-(S_u × S_v)``), and its NURBS
    arrays (run in the child)."""
    r3 = _rhino3dm()
    model = r3.File3dm.Read(str(path))
    if model is None:
        raise InputError(f"{path}: not a .3dm (openNURBS) file")
    layers = [layer.FullPath for layer in model.Layers]
    faces = []
    for index, obj, geometry in _objects(model, r3):
        attributes = obj.Attributes
        layer = attributes.LayerIndex
        kind = ("extrusion" if isinstance(obj.Geometry, r3.Extrusion)
                else "brep" if isinstance(geometry, r3.Brep) else "surface")
        own = {"object": index, "name": attributes.Name or None, "kind": kind,
               "layer": layers[layer] if 0 <= layer < len(layers) else None}
        members = list(geometry.Faces) if isinstance(geometry, r3.Brep) else [geometry]
        for number, member in enumerate(members):
            entry = {**own, "member": number, "reversed": kind != "surface"
                     and bool(member.OrientationIsReversed)}
            try:
                surface = member.UnderlyingSurface() if kind != "surface" else member
                entry["trimmed"] = kind != "surface" and _is_trimmed(geometry, member)
                entry["closed"] = (bool(surface.IsClosed(0)), bool(surface.IsClosed(1)))
                entry["periodic"] = (bool(surface.IsPeriodic(0)), bool(surface.IsPeriodic(1)))
                entry.update(_patch_from_rhino(surface.ToNurbsSurface(), f"{path} object {index}"))
                from .cad_trims import listed
                from .cad_trims_3dm import member_trims

                entry.update(listed(lambda: member_trims(
                    model, r3, index if kind == "surface" else geometry, member,
                    f"{path} face {len(faces)}")))
            except InputError as exc:
                entry["error"] = str(exc)
            faces.append(entry)
    return {"faces": faces,
            "units": units_from_rhino(str(model.Settings.ModelUnitSystem).split(".")[-1])}


def _is_trimmed(brep: object, brep_face: object) -> bool:
    """Whether a Brep face is trimmed: it has inner loops, its parameter box is smaller
    than its surface's domain, or an edge of its outer loop leaves the box's four sides.

    The sides are sampled at :data:`TRIM_SAMPLES` points each and the edges at 9; an edge
    point counts as on a side within ``TRIM_TOL`` of the box's diagonal (point to chord:
    the chords of a curved side are off it by far less).
    """
    surface = brep_face.UnderlyingSurface()
    box = [brep_face.Domain(k) for k in (0, 1)]
    whole = [surface.Domain(k) for k in (0, 1)]
    span = max(abs(d.T1 - d.T0) for d in whole)
    if len(brep_face.Loops) > 1 or any(
            abs(a.T0 - b.T0) > 1e-9 * span or abs(a.T1 - b.T1) > 1e-9 * span
            for a, b in zip(box, whole)):
        return True
    s = np.linspace(0.0, 1.0, TRIM_SAMPLES)
    (u0, u1), (v0, v1) = [(d.T0, d.T1) for d in box]
    us, vs = u0 + (u1 - u0) * s, v0 + (v1 - v0) * s
    sides = [[(u, v0) for u in us], [(u1, v) for v in vs], [(u, v1) for u in us[::-1]],
             [(u0, v) for v in vs[::-1]]]
    chords = np.array([[_xyz(surface.PointAt(u, v)) for u, v in side] for side in sides])
    edge_points = []
    for trim in brep_face.OuterLoop.Trims:
        if trim.EdgeIndex >= 0:          # a singular trim (a pole) has no edge
            edge = brep.Edges[trim.EdgeIndex]
            d = edge.Domain
            edge_points += [_xyz(edge.PointAt(d.T0 + (d.T1 - d.T0) * k / 8)) for k in range(9)]
    if not edge_points:
        return False
    a, b = chords[:, :-1].reshape(-1, 3), chords[:, 1:].reshape(-1, 3)
    x = np.array(edge_points)[:, None, :]
    ab = b - a
    tau = np.clip(np.einsum("psk,sk->ps", x - a, ab) / np.maximum((ab * ab).sum(-1), 1e-300),
                  0.0, 1.0)
    gap = np.linalg.norm(x - a - tau[..., None] * ab, axis=-1).min(axis=1)
    diagonal = np.ptp(chords.reshape(-1, 3), axis=0).max()
    return bool(gap.max() > TRIM_TOL * max(diagonal, np.abs(chords).max(), 1e-300))


def _xyz(p) -> tuple[float, float, float]:
    return p.X, p.Y, p.Z


def _patch_from_rhino(srf: Any, source: str) -> dict[str, Any]:
    """Degrees, full knot vectors, points and weights of a rhino3dm NURBS surface."""
    nu, nv = srf.OrderU - 1, srf.OrderV - 1
    if nu < 1 or nv < 1:
        raise InputError(f"{source}: surface of degree ({nu}, {nv}); degree 0 is not supported")
    ku = [srf.KnotsU[i] for i in range(len(srf.KnotsU))]
    kv = [srf.KnotsV[i] for i in range(len(srf.KnotsV))]
    cu, cv = srf.Points.CountU, srf.Points.CountV
    hom = np.array([[list(_xyzw(srf.Points[i, j])) for j in range(cv)] for i in range(cu)])
    w = hom[..., 3]
    if np.any(w <= 0):
        i, j = np.argwhere(w <= 0)[0]
        raise InputError(f"{source}: weight w[{i}, {j}] = {w[i, j]:g}; NURBS weights must "
                         "be > 0")
    return {"degrees": (nu, nv), "knots_u": np.r_[ku[0], ku, ku[-1]],
            "knots_v": np.r_[kv[0], kv, kv[-1]], "points": hom[..., :3] / w[..., None],
            "weights": w}


def _xyzw(p) -> tuple[float, float, float, float]:
    return p.X, p.Y, p.Z, p.W


#: interior points sampled along every Brep edge for the topology (ends left out: they
#: lie on two sides of a face)
EDGE_SAMPLES = 9


def list_3dm_body(path: Path) -> dict[str, Any]:
    """:func:`list_3dm_arrays` and the Brep edges: ``edges`` is one entry per edge of
    every Brep (an extrusion's too), ``{"faces": [face number per trim], "points":
    (EDGE_SAMPLES, 3) interior points}``, faces numbered as in the listing; a seam has
    its face twice, a pole (a trim without an edge) is left out (run in the child)."""
    data = list_3dm_arrays(path)
    r3 = _rhino3dm()
    model = r3.File3dm.Read(str(path))
    edges, first = [], 0
    t = (np.arange(EDGE_SAMPLES) + 0.5) / EDGE_SAMPLES
    for _, _, geometry in _objects(model, r3):
        if not isinstance(geometry, r3.Brep):
            first += 1
            continue
        uses: dict[int, list[int]] = {}
        for number, brep_face in enumerate(geometry.Faces):
            for loop in brep_face.Loops:
                for trim in loop.Trims:
                    if trim.EdgeIndex >= 0:
                        uses.setdefault(trim.EdgeIndex, []).append(first + number)
        for index, faces in sorted(uses.items()):
            edge = geometry.Edges[index]
            d = edge.Domain
            edges.append({"faces": faces, "points": np.array(
                [_xyz(edge.PointAt(d.T0 + (d.T1 - d.T0) * s)) for s in t])})
        first += len(geometry.Faces)
    data["edges"] = edges
    return data
