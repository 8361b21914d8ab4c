"""A whole CAD body: the chosen faces of a file as surfaces, with the file's topology.

:func:`read_body` reads every face of a ``.3dm``, STEP or IGES file once, in the reader
child (:func:`splinedeform.cad_3dm_read.list_3dm_body`,
:func:`splinedeform.cad_step_edges.list_step_body`), keeps the faces chosen (``"all"``,
face numbers as ``splinedeform faces`` lists them, or object names and layers), makes
each a deformable :class:`~splinedeform.surface.Surface`
(:func:`splinedeform.cad.surface_from_patch`) and finds the interfaces between them from
the file's edges (:func:`splinedeform.cad_topology.body_topology`), and those of the faces that the
file joins to nothing (plain surfaces, STEP faces sewn to none) from the geometry
(:mod:`splinedeform.cad_join`; trimmed ones along their trim edges,
:mod:`splinedeform.cad_join_trims`). A face that cannot
be deformed (unreadable, general weights on unclamped knots) is skipped, and ``info``
says why; a trimmed face is taken untrimmed, with one warning line naming it.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path
from typing import Any, Sequence, Union

from .cad import CAD_SUFFIXES, NurbsPatch, surface_from_patch
from .cad_child import check_cad_file, read_in_child
from .cad_faces import is_trimmed
from .cad_join import file_edges, join_loose_faces, loose_faces
from .cad_join_trims import join_trims
from .cad_topology import Topology, body_topology
from .errors import InputError, InputWarning

#: what ``faces`` may be: every face, face numbers, or object names / layers
FaceChoice = Union[str, Sequence[Union[int, str]]]


def read_listing(path: Path) -> dict[str, Any]:
    """Every face of a CAD file with its arrays, and the file's edges (read in the child)."""
    kind = CAD_SUFFIXES.get(path.suffix.lower())
    if kind is None:
        raise InputError(f"{path}: not a CAD file (expected one of "
                         f"{', '.join(CAD_SUFFIXES)}), got suffix {path.suffix or 'none'!r}")
    check_cad_file(path)
    if kind == "openNURBS":
        from .cad_3dm_read import _rhino3dm, list_3dm_body

        _rhino3dm()
        return read_in_child(list_3dm_body, path, library="openNURBS (rhino3dm)")
    import importlib.util

    from .cad_step_edges import list_step_body
    from .cad_step_read import MISSING

    if importlib.util.find_spec("OCP") is None:  # pragma: no cover - the installation
        raise InputError(MISSING)
    return read_in_child(list_step_body, path, library="OpenCASCADE")


def patches_of(listing: dict[str, Any]) -> list[NurbsPatch | None]:
    """The NURBS patch of every face of a listing (None where the face has an ``error``)."""
    return [None if "error" in f else
            NurbsPatch(tuple(int(n) for n in f["degrees"]), f["knots_u"], f["knots_v"],
                       f["points"], f["weights"], units=listing["units"],
                       reversed=bool(f.get("reversed")))
            for f in listing["faces"]]


def label(entry: dict[str, Any], number: int) -> str:
    """``face 3`` or ``face 3 (lid)``: a face's number and its object's name, if any."""
    return f"face {number}" + (f" ({entry['name']})" if entry.get("name") else "")


def choose_faces(listing: dict[str, Any], faces: FaceChoice, source: str) -> list[int]:
    """The file face numbers chosen by ``faces`` (see :func:`read_body`), in file order
    for ``"all"`` and names, in the order given for numbers."""
    entries = listing["faces"]
    if not entries:
        raise InputError(f"{source}: the file holds no surface")
    if isinstance(faces, str):
        if faces != "all":
            raise InputError(f"{source}: faces must be \"all\", a list of face numbers or a "
                             f"list of names / layers, got {faces!r}")
        return list(range(len(entries)))
    chosen: list[int] = []
    names = sorted({e[k] for e in entries for k in ("name", "layer") if e.get(k)})
    for item in faces:
        if isinstance(item, bool) or not isinstance(item, (int, str)):
            raise InputError(f"{source}: a face is a number or a name, got {item!r}")
        if isinstance(item, int):
            if not 0 <= item < len(entries):
                raise InputError(f"{source}: face {item} out of range; the file holds "
                                 f"{len(entries)} face(s), numbered 0..{len(entries) - 1}")
            found = [item]
        else:
            found = [k for k, e in enumerate(entries) if item in (e.get("name"), e.get("layer"))]
            if not found:
                raise InputError(f"{source}: no object or layer is named {item!r}; the names "
                                 f"and layers are {', '.join(map(repr, names)) or 'none'}")
        chosen += [k for k in found if k not in chosen]
    if not chosen:
        raise InputError(f"{source}: no face chosen (faces is empty)")
    return chosen


def read_body(path: str | os.PathLike, faces: FaceChoice = "all"
              ) -> tuple[list[Any], Topology, dict[str, Any]]:
    """The faces ``faces`` of a CAD file as surfaces, their topology, and what was read.

    Parameters
    ----------
    path : path-like
        A ``.3dm``, STEP or IGES file.
    faces : ``"all"`` or list of int or str
        Every face of every surface object; face numbers (as ``splinedeform faces``
        lists them); or names of objects or layers (``.3dm``), each taking all its faces.

    Returns
    -------
    surfaces : list of Surface
        One per face kept, in the order chosen, named ``<stem> face <k>``.
    topology : Topology
        Interfaces between the surfaces (their indices in ``surfaces``) and the counts of
        shared, boundary, seam, non-manifold and off-side edges.
    info : dict
        ``units`` (the file's), ``faces`` (the file face number of each surface),
        ``names`` (object name of each, or None), ``reversed`` (whether each is marked
        reversed in its Brep: its outward normal is ``-(S_u × S_v)``), ``trimmed`` (file
        face numbers taken untrimmed), ``skipped`` (``{face number: why}``) and
        ``joined_by_geometry``: the interfaces found by matching the sides of the loose
        faces, those the file joins to nothing (plain surfaces, STEP faces sewn to none;
        :mod:`splinedeform.cad_join`), ``{"face_a", "edge_a", "face_b", "edge_b"}`` in
        file face numbers (the file's own interfaces come first in ``topology``), and
        ``partly_joined_by_geometry`` the sides of theirs that share only a stretch with
        another (T-junctions, coupled along it by the body), likewise; both with the trim
        edges of loose trimmed faces joined along another face's trim edge or side
        (:mod:`splinedeform.cad_join_trims`; an edge ``hole1``, ``outer.2`` or ``u0``),
        those that run along the whole of both edges in the first.
    """
    path = Path(path)
    listing = read_listing(path)
    return body_of(path, listing, choose_faces(listing, faces, str(path)))


def body_of(path: Path, listing: dict[str, Any], chosen: list[int]
            ) -> tuple[list[Any], Topology, dict[str, Any]]:
    """What :func:`read_body` returns, for the faces ``chosen`` of a file's listing
    (:func:`read_listing`, :func:`choose_faces`)."""
    patches = patches_of(listing)
    surfaces, kept, skipped, trimmed = [], [], {}, []
    seams = _seam_faces(listing, patches, chosen)
    for number in chosen:
        entry, patch = listing["faces"][number], patches[number]
        if patch is None:
            skipped[number] = entry["error"]
            continue
        source = f"{path} {label(entry, number)}"
        try:
            with warnings.catch_warnings():
                if number in seams:               # the body's interface joins its seam
                    warnings.filterwarnings("ignore", message=".*seam is not joined")
                surface = surface_from_patch(patch, name=f"{path.stem} face {number}",
                                             source=source)
        except InputError as exc:
            skipped[number] = str(exc)
            continue
        if is_trimmed(entry):
            trimmed.append(number)
            warnings.warn(f"{source} is trimmed; its whole underlying surface is used",
                          InputWarning, stacklevel=2)
        surfaces.append(surface)
        kept.append(number)
    if not surfaces:
        raise InputError(f"{path}: none of the faces chosen can be deformed: "
                         + "; ".join(f"face {k}: {why}" for k, why in skipped.items()))
    loose = loose_faces(listing, kept, trimmed)
    edges = file_edges(listing, {kept[k] for k in loose})
    topology = body_topology(patches, edges, kept)
    file_count = len(topology.interfaces)
    topology = join_loose_faces(surfaces, topology, loose)
    topology = join_trims(surfaces, listing, kept, trimmed, topology)
    info = {"units": listing["units"], "faces": kept,
            "names": [listing["faces"][k].get("name") for k in kept],
            "reversed": [bool(listing["faces"][k].get("reversed")) for k in kept],
            "trimmed": trimmed, "skipped": skipped,
            "joined_by_geometry": [
                {"face_a": kept[i.a], "edge_a": i.edge_a, "face_b": kept[i.b],
                 "edge_b": i.edge_b} for i in topology.interfaces[file_count:]] + [
                {"face_a": kept[a], "edge_a": ea, "face_b": kept[b], "edge_b": eb}
                for a, ea, b, eb, whole in topology.trim_joins if whole],
            "partly_joined_by_geometry": [
                {"face_a": kept[a], "edge_a": ea, "face_b": kept[b], "edge_b": eb}
                for a, ea, b, eb in topology.stretches] + [
                {"face_a": kept[a], "edge_a": ea, "face_b": kept[b], "edge_b": eb}
                for a, ea, b, eb, whole in topology.trim_joins if not whole]}
    return surfaces, topology, info


def _seam_faces(listing: dict[str, Any], patches: list[NurbsPatch | None],
                chosen: list[int]) -> set[int]:
    """File faces among ``chosen`` that have a seam edge in the file."""
    return {e["faces"][0] for e in listing["edges"]
            if len(e["faces"]) == 2 and e["faces"][0] == e["faces"][1]
            and e["faces"][0] in chosen and patches[e["faces"][0]] is not None}
