"""The faces of a CAD file, listed (``splinedeform faces FILE``).

Every object of a ``.3dm``, STEP or IGES file that holds surfaces (a Brep, a plain surface,
an extrusion read as its Brep: wall and caps) and each of its faces, numbered as
``shape = "cad"``'s ``face`` counts them, with what decides how it can be deformed: its
degrees and net size, its weights (``1``, a product ``a_i b_j`` or general), whether it is
trimmed and closed or periodic in the file, whether its Brep marks it reversed, its
``C^0`` knots (an interior knot repeated ``n`` times), its degenerate edges (a row of the
net that is one point, a pole) and the area of its untrimmed surface,

.. math:: A = \\int\\!\\!\\int |S_u \\times S_v| \\, du\\, dv,
          \\quad S_u = (N_u - S\\, W_u) / W,

by Gauss–Legendre quadrature with :data:`AREA_POINTS` points per knot span and direction
(``N = Σ w P N_i N_j``, ``W = Σ w N_i N_j``). The files are read in the reader child
(:mod:`splinedeform.cad_child`).
"""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .cad import SEAM_TOL, WEIGHT_TOL, weight_factors
from .cad_trims import trim_summary
from .knots import KnotVectorBasis
from .quadrature import gauss_points

#: Gauss points per knot span and direction for the area (a rational integrand: not exact;
#: 16 points give round-off on conics, see tests/test_cad_faces.py)
AREA_POINTS = 16
#: a STEP / IGES face whose own area (inside its loops) is smaller than its surface's by
#: more than this fraction is trimmed
TRIM_AREA_TOL = 1e-6


def read_faces(path: str | os.PathLike) -> dict[str, Any]:
    """``{"file", "units", "faces": [...]}``: every face of a CAD file (see the module
    docstring); one dict per face with ``face``, ``object``, ``name``, ``layer``, ``kind``,
    ``degrees``, ``net``, ``weights``, ``trimmed``, ``closed``, ``periodic``, ``c0_knots``,
    ``degenerate``, ``area`` (of the untrimmed surface), ``reversed`` (marked reversed in
    its Brep: ``TopAbs_REVERSED``, ``BrepFace.OrientationIsReversed``) and
    ``trimmed_area`` (inside the face's loops, by OpenCASCADE; None for ``.3dm``), or
    ``error`` for a face that cannot be read. Knot values are the file's parameters.
    ``topology`` holds the counts of shared, boundary, seam, non-manifold and off-side
    edges of the whole file and its interfaces (:mod:`splinedeform.cad_topology`); where
    the file joins some faces to nothing (plain surfaces, STEP faces sewn to none), those
    of the body of every face that can be deformed, as ``faces = "all"`` reads it
    (:func:`splinedeform.cad_body.read_body`): with the interfaces and T-junction
    stretches found from the geometry (:mod:`splinedeform.cad_join`; the file's
    interfaces first), counted ``joined_by_geometry`` and ``partly_joined_by_geometry``,
    the stretches listed as ``stretches``, the trim edges of loose trimmed faces joined
    (:mod:`splinedeform.cad_join_trims`) as ``trim_joins``; face numbers are the file's."""
    from .cad_body import patches_of, read_listing
    from .cad_topology import body_topology

    path = Path(path)
    data = read_listing(path)
    patches = patches_of(data)
    faces = [_describe(number, entry) for number, entry in enumerate(data["faces"])]
    topology = _joined(path, data, faces) or body_topology(
        patches, data["edges"], range(len(patches))).as_dict()
    return {"file": str(path), "units": data["units"], "faces": faces,
            "topology": topology}


def _joined(path: Path, data: dict[str, Any], faces: list[dict[str, Any]]
            ) -> dict[str, Any] | None:
    """The topology of the body of every deformable face with its geometric joins, in
    file face numbers (see :func:`read_faces`); None where no face is loose or none can
    be deformed."""
    from .cad_body import body_of
    from .cad_join import loose_faces
    from .cad_join_trims import loose_trimmed
    from .errors import InputError

    trimmed = [f["face"] for f in faces if f.get("trimmed")]
    every = range(len(faces))
    if not (loose_faces(data, every, trimmed) or loose_trimmed(data, every, trimmed)):
        return None
    chosen = [f["face"] for f in faces if "error" not in f]
    try:
        with warnings.catch_warnings():      # trimmed faces: listed in the table already
            warnings.simplefilter("ignore")
            _, topology, info = body_of(path, data, chosen)
    except InputError:
        return None
    out = topology.as_dict()
    kept = info["faces"]
    for item in out["interfaces"] + out.get("stretches", []) + out.get("trim_joins", []):
        item["a"], item["b"] = kept[item["a"]], kept[item["b"]]
    return out


def _describe(number: int, entry: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {"face": number, **{k: entry.get(k) for k in
                                               ("object", "name", "layer", "kind")}}
    if "error" in entry:
        return {**out, "error": entry["error"]}
    degrees = tuple(int(n) for n in entry["degrees"])
    bases = [KnotVectorBasis(n, np.asarray(t, dtype=float))
             for n, t in zip(degrees, (entry["knots_u"], entry["knots_v"]))]
    points, w = np.asarray(entry["points"], float), np.asarray(entry["weights"], float)
    whole = area(bases, points, w)
    inside = entry.get("trimmed_area")
    loops = trim_summary(entry, f"face {number}")
    fraction = loops["trimmed_fraction"]
    trimmed = is_trimmed(entry, whole) or (fraction is not None
                                           and fraction < 1 - TRIM_AREA_TOL)
    return {**out, "degrees": list(degrees), "net": list(w.shape), "weights": _weights(w),
            "trimmed": trimmed, "closed": [bool(c) for c in entry["closed"]],
            "periodic": [bool(c) for c in entry["periodic"]],
            "c0_knots": {d: [float(x) for x in b.c0_knots] for d, b in zip("uv", bases)},
            "degenerate": degenerate_edges(points), "area": whole,
            "reversed": bool(entry.get("reversed")),
            "trimmed_area": None if inside is None else abs(float(inside)),
            **loops}


def is_trimmed(entry: dict[str, Any], whole: float | None = None) -> bool:
    """Whether a listed face is trimmed: so read, or (STEP / IGES) its area inside its loops
    is below its surface's ``whole`` area (computed if not given) by :data:`TRIM_AREA_TOL`."""
    inside = entry.get("trimmed_area")
    if entry["trimmed"] or inside is None:
        return bool(entry["trimmed"])
    if whole is None:
        bases = [KnotVectorBasis(int(n), np.asarray(t, dtype=float))
                 for n, t in zip(entry["degrees"], (entry["knots_u"], entry["knots_v"]))]
        whole = area(bases, np.asarray(entry["points"], float),
                     np.asarray(entry["weights"], float))
    return bool(abs(inside) < whole * (1 - TRIM_AREA_TOL))


def _weights(w: NDArray[np.float64]) -> str:
    """``"1"`` (polynomial), ``"product"`` (``a_i b_j``) or ``"general"``."""
    if np.ptp(w) <= WEIGHT_TOL * w.max():
        return "1"
    return "product" if weight_factors(w) is not None else "general"


def degenerate_edges(points: NDArray[np.float64]) -> list[str]:
    """Edges ``u0``, ``u1``, ``v0``, ``v1`` of the net whose row of control points is one
    point within :data:`~splinedeform.cad.SEAM_TOL` of the net's size (a pole)."""
    size = max(float(np.ptp(points.reshape(-1, 3), axis=0).max()), 1e-300)
    rows = {"u0": points[0], "u1": points[-1], "v0": points[:, 0], "v1": points[:, -1]}
    return [name for name, row in rows.items()
            if np.ptp(row, axis=0).max() <= SEAM_TOL * size]


def area(bases: list[KnotVectorBasis], points: NDArray[np.float64],
         weights: NDArray[np.float64]) -> float:
    """Area of the rational surface ``S = N / W`` (see the module docstring)."""
    (xu, au), (xv, av) = (gauss_points(b, AREA_POINTS) for b in bases)
    (Bu, Du), (Bv, Dv) = ((b(x), b(x, 1)) for b, x in zip(bases, (xu, xv)))
    hom = np.concatenate([points * weights[..., None], weights[..., None]], axis=-1)
    grid = lambda A, B: np.einsum("ai,ijc,bj->abc", A, hom, B)  # noqa: E731
    H, Hu, Hv = grid(Bu, Bv), grid(Du, Bv), grid(Bu, Dv)
    W = H[..., 3:]
    S = H[..., :3] / W
    Su, Sv = (Hu[..., :3] - S * Hu[..., 3:]) / W, (Hv[..., :3] - S * Hv[..., 3:]) / W
    return float(np.einsum("a,b,ab->", au, av, np.linalg.norm(np.cross(Su, Sv), axis=-1)))


def faces_text(listing: dict[str, Any]) -> str:
    """The listing as a table, one line per face."""
    head = ("face", "object", "name", "layer", "kind", "degree", "net", "weights", "trimmed",
            "closed", "periodic", "C0 knots", "poles", "area", "loops", "inside")
    rows = []
    for f in listing["faces"]:
        if "error" in f:
            rows.append((str(f["face"]), str(f["object"]), f["name"] or "-", f["layer"] or "-",
                         f["kind"], "unreadable: " + f["error"]))
            continue
        uv = lambda pair: "".join(d for d, c in zip("uv", pair) if c) or "-"  # noqa: E731
        c0 = ", ".join(f"{d}={x:.6g}" for d, xs in f["c0_knots"].items() for x in xs) or "-"
        rows.append((str(f["face"]), str(f["object"]), f["name"] or "-", f["layer"] or "-",
                     f["kind"], "x".join(map(str, f["degrees"])), "x".join(map(str, f["net"])),
                     f["weights"], "yes" if f["trimmed"] else "no", uv(f["closed"]),
                     uv(f["periodic"]), c0, ",".join(f["degenerate"]) or "-",
                     f"{f['area']:.6g}", *_loops_text(f)))
    widths = [max([len(head[k])] + [len(r[k]) for r in rows if len(r) > k])
              for k in range(len(head))]
    widths[5] = max([len(head[5])] + [len(r[5]) for r in rows if len(r) > 6])
    lines = [f"{listing['file']}: {len(listing['faces'])} face(s), units "
             f"{listing['units'] or 'not declared'}",
             "  ".join(h.ljust(wd) for h, wd in zip(head, widths)).rstrip()]
    lines += ["  ".join(c.ljust(wd) for c, wd in zip(r, widths)).rstrip() for r in rows]
    lines += [line for f in listing["faces"] if (line := loop_names_line(f))]
    turned = [str(f["face"]) for f in listing["faces"] if f.get("reversed")]
    if turned:
        lines.append(f"reversed in their Brep (outward normal -(S_u × S_v)): face(s) "
                     f"{', '.join(turned)}")
    if "topology" in listing:
        lines.append(topology_line(listing["topology"]))
    return "\n".join(lines) + "\n"


def loop_names_line(face: dict[str, Any]) -> str | None:
    """``face 3 loops: outer (4 trim edges, outer.0 … outer.3), hole1``: the names
    ``boundary.loops`` holds a trimmed face's loops and trim edges by; None for a face that
    is not trimmed or has no loops read."""
    names = face.get("loop_names")
    if not names or not face.get("trimmed"):
        return None
    parts = [name if count == 1 else f"{name} ({count} trim edges, {name}.0 … {name}.{count - 1})"
             for name, count in names.items()]
    return f"face {face['face']} loops: " + ", ".join(parts)


def topology_line(topology: dict[str, Any]) -> str:
    """``edges: 12 shared, 0 boundary, 0 seams, 0 non-manifold`` (and the edges on no side
    of their face's rectangle, the interfaces found, conforming or not, and where the
    file joins some faces to nothing, how many joins were found from the geometry and how
    many of them share only part of a side: ``; 3 joined by geometry (2 of them along
    part of a side)``)."""
    conforming = sum(i["conforming"] for i in topology["interfaces"])
    line = (f"edges: {topology['shared']} shared, {topology['boundary']} boundary, "
            f"{topology['seam']} seam(s), {topology['non_manifold']} non-manifold")
    if topology.get("partly_shared"):
        line += (f", {topology['partly_shared']} of them along part of a side "
                 "(T-junctions, coupled as stretches)")
    if topology["off_sides"]:
        trims = topology.get("trim_edges") or {}
        line += (f", {topology['off_sides']} on trimming loops ({trims.get('shared', 0)} "
                 f"shared by two faces, {trims.get('free', 0)} free)")
    line += f"; {len(topology['interfaces'])} interface(s), {conforming} conforming"
    if "joined_by_geometry" in topology:
        partly = topology.get("partly_joined_by_geometry", 0)
        line += (f"; {topology['joined_by_geometry']} joined by geometry"
                 + (f" ({partly} of them along part of a side)" if partly else ""))
    return line


def _loops_text(face: dict[str, Any]) -> tuple[str, str]:
    """``("1+2", "87.2%")``: outer + inner loops and the part of the parameter box inside
    them; ``("unread", "-")`` where the loops cannot be read, ``("-", "-")`` where there
    are none."""
    if face.get("trim_error"):
        return "unread", "-"
    if face["loops"] is None:
        return "-", "-"
    return f"{face['loops'][0]}+{face['loops'][1]}", f"{100 * face['trimmed_fraction']:.4g}%"


def faces_json(listing: dict[str, Any]) -> str:
    """The listing as JSON."""
    return json.dumps(listing, indent=2) + "\n"
