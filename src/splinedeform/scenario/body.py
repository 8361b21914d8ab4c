"""Scenarios of a body: several faces of a CAD file deformed as one connected surface.

``[surface] shape = "cad"`` with ``faces`` choosing more than one face builds a
:class:`FileBody` (the patches, the file's interfaces, the file face number of each patch)
and a :class:`~splinedeform.body.BodyModel`. What a body takes from a scenario:

* ``[boundary]``: one preset for every boundary edge (an edge no other face meets), so
  ``u0 = u1 = v0 = v1``, replaced edge by edge by ``[boundary.faces]``
  (``3 = {u0 = "clamped"}``, the file's face numbers; :func:`face_presets`); the moving
  control points of single faces by ``boundary.faces_free_points`` (``0 = [[i, j], ...]``,
  all others of that face fixed; :func:`face_masks`; on a trimmed face too, its map
  taking the mask, :func:`~splinedeform.trim.holed.with_edges`), where ``free_region``
  and ``free_points`` are a single surface's;
* ``surface.refine`` / ``surface.elevate``: every face alike, in its own u and v; where
  the counts differ in u and v, interfaces are made to conform again by exact elevation
  and knot insertion (:func:`refined_body`);
* ``[[load]]``: a uniform force or a pressure acts on every face, or on face ``face``
  only; a point load names its face (``face = k``, the file's face number) and ``at`` in
  that face's parameters;
* ``[output]``: the formats of :data:`BODY_FORMATS`; ``probes`` name their face
  (``probe_faces``) or are points in space read on their nearest face
  (:mod:`splinedeform.probes_body`); without them, each face's centre.
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Any, Iterator, Sequence

from ..body.body import Body
from .schema_types import SHELL_EDGES
from .spec import Scenario

#: output formats written for a body (:mod:`splinedeform.outputs_body`)
BODY_FORMATS = ("vtu", "obj", "stl", "ply", "json", "npz", "3dm", "step", "iges", "images",
                "gif", "mp4", "viewer", "report")
#: physics a body runs with
BODY_PHYSICS = ("intrinsic", "parametric", "shell")


class FileBody(Body):
    """A :class:`~splinedeform.body.Body` read from a CAD file.

    Parameters
    ----------
    patches, interfaces
        As for :class:`~splinedeform.body.Body` (the interfaces are the file's).
    faces : sequence of int
        The file's face number of each patch.
    counts : dict
        The file's edge counts (shared, boundary, seam, non_manifold, off_sides, and the
        joins found by geometry); the body adds its ``poles`` and ``non_conforming``
        interfaces (:meth:`~splinedeform.body.Body.summary`).
    orientation : sequence of {+1, -1}, optional
        Per patch ``-1`` where the file's Brep marks the face reversed
        (:attr:`~splinedeform.body.Body.orientation`: a pressure pushes along the Brep's
        normal).
    """

    def __init__(self, patches: Sequence[Any], interfaces: Sequence[Any],
                 faces: Sequence[int], counts: dict[str, int],
                 orientation: Sequence[int] | None = None):
        super().__init__(patches, interfaces, orientation=orientation)
        self.faces = tuple(int(f) for f in faces)
        own = self.summary()          # what the file's edges do not say: poles, matching
        self.counts = {**dict(counts), "poles": own["poles"],
                       "non_conforming": own["non_conforming"]}

    def patch_of_face(self, face: int) -> int | None:
        """The patch index of the file's face ``face`` (None if the body lacks it)."""
        return self.faces.index(face) if face in self.faces else None


def is_body(surface: Any) -> bool:
    """Whether a built surface is a body of patches."""
    return isinstance(surface, Body)


def body_from_cad(scenario: Scenario) -> tuple[Any, int, str | None]:
    """``(body, face, units)`` of ``surface.faces`` (``"all"`` when neither ``face`` nor
    ``faces`` is given): one face chosen gives no body and that face (read as ``face``
    is); several give a :class:`FileBody` of their surfaces and their interfaces: the
    file's, and those of the faces that the file joins to nothing (plain surfaces, STEP
    faces sewn to none) found where their sides meet (:mod:`splinedeform.cad_join`)."""
    from ..cad_body import body_of, choose_faces, read_listing
    from ..errors import InputError
    from .build import _located

    spec, raw = scenario.surface, scenario.raw.get("surface", {})
    if "face" in raw and "faces" in raw:
        raise scenario.error("surface.faces", "give face (one face) or faces (a body), "
                                              "not both")
    path, faces = spec.path, spec.parameters.get("faces") or "all"
    with _located(scenario, "surface.path"):
        listing = read_listing(path)
        if not listing["faces"]:
            raise InputError(f"{path}: the file holds no surface")
    with _located(scenario, "surface.faces"):
        chosen = choose_faces(listing, list(faces) if isinstance(faces, tuple) else faces,
                              str(path))
    if len(chosen) == 1:
        return None, chosen[0], listing["units"]
    with _located(scenario, "surface.faces"):
        surfaces, topology, info = body_of(path, listing, chosen)
        signs = [-1 if r else 1 for r in info["reversed"]]
        if any(topology.counts.values()):
            return (FileBody(surfaces, topology.interfaces, info["faces"], topology.counts,
                             signs), chosen[0], info["units"])
        # nothing counted (no file edge and no side: faces closed in both directions):
        # the body finds its own (:func:`splinedeform.body.topology.find_topology`)
        return FileBody(surfaces, None, info["faces"], {}, signs), chosen[0], info["units"]


def refined_body(scenario: Scenario, body: FileBody) -> FileBody:
    """``body`` with every face elevated by ``surface.elevate`` degrees, then with
    ``surface.refine`` knots inserted per span, each face in its own u and v
    (:func:`splinedeform.refine.refine_surface`).

    A shared edge can be a u edge of one face and a v edge of its neighbour, so counts
    that differ in u and v give the two sides of an edge different degrees or knots. Such
    an interface that conformed is made to conform again, exactly: after the elevation the
    side of lower degree is elevated along the edge until the degrees agree
    (:func:`matched_degrees`), after the insertion each side gets the knots of the other
    that it lacks (:func:`splinedeform.body.body.insert_missing_knots`, Boehm's
    insertion), each repeated while a direction's new degree or knots reach other edges.
    Each interface's ``conforming`` is checked again on the refined faces
    (:func:`splinedeform.body.topology.conforming`)."""
    from dataclasses import replace

    from ..body.body import MAX_PASSES, insert_missing_knots
    from ..body.topology import conforming
    from ..errors import InputError
    from ..refine import refine_surface
    from .build import _located

    spec = scenario.surface
    uneven = spec.elevate[0] != spec.elevate[1] or spec.refine[0] != spec.refine[1]
    joined = [i for i in body.interfaces if i.conforming]
    key = "surface.elevate" if spec.elevate != (0, 0) else "surface.refine"
    with _located(scenario, key):
        patches = [refine_surface(s, spec.elevate) for s in body]
        if uneven:
            patches = matched_degrees(patches, joined)
        patches = [refine_surface(s, (0, 0), spec.refine) for s in patches]
        for _ in range(MAX_PASSES if uneven else 0):
            if not insert_missing_knots(patches, joined):
                break
        else:
            if uneven:
                raise InputError(f"knot insertion did not make the refined faces conform "
                                 f"again in {MAX_PASSES} rounds; give one count for u and v")
    tol = body.topology.tol
    interfaces = [replace(i, conforming=conforming(patches[i.a], i.edge_a, patches[i.b],
                                                   i.edge_b, i.reversed, tol))
                  if i.conforming else i for i in body.interfaces]
    return FileBody(patches, interfaces, body.faces, body.counts, body.orientation)


def matched_degrees(patches: list[Any], interfaces: Sequence[Any]) -> list[Any]:
    """``patches`` with the side of lower degree of each interface elevated along its
    edge (:func:`splinedeform.refine.refine_surface`, exact) until both sides agree."""
    from ..body.body import MAX_PASSES
    from ..body.topology import edge_basis
    from ..errors import InputError
    from ..refine import refine_surface

    patches = list(patches)
    for _ in range(MAX_PASSES):
        wanted: dict[tuple[int, int], int] = {}
        for i in interfaces:
            pa = edge_basis(patches[i.a], i.edge_a).degree
            pb = edge_basis(patches[i.b], i.edge_b).degree
            for p, edge, by in ((i.a, i.edge_a, pb - pa), (i.b, i.edge_b, pa - pb)):
                axis = 1 if edge[0] == "u" else 0          # the direction along the edge
                if by > 0:
                    wanted[(p, axis)] = max(wanted.get((p, axis), 0), by)
        if not wanted:
            return patches
        for (p, axis), by in wanted.items():
            patches[p] = refine_surface(patches[p], (by, 0) if axis == 0 else (0, by))
    raise InputError(f"degree elevation did not give the faces' edges common degrees in "
                     f"{MAX_PASSES} rounds; give one count for u and v")


def check_body_scenario(scenario: Scenario, body: FileBody) -> None:
    """Refuse, at its key, what a body does not take (module docstring)."""
    s = scenario
    if s.material.physics not in BODY_PHYSICS:
        raise s.error("material.physics", f"a body of {len(body)} faces runs with physics "
                      f"{' or '.join(BODY_PHYSICS)}; the shell is not coupled across a body's "
                      "interfaces yet (choose one face with face = k)")
    presets = s.boundary.edges()
    if len(set(presets.values())) > 1:
        raise s.error("boundary", "a body takes one preset for every boundary edge (an edge "
                      "no other face meets): give u0 = u1 = v0 = v1, got " + ", ".join(
                          f"{e} = {p!r}" for e, p in presets.items()))
    raw = s.raw.get("boundary", {})
    for key in ("free_region", "free_points"):
        if key in raw:
            raise s.error(f"boundary.{key}", "applies to one surface, not to a body of "
                                             f"{len(body)} faces; list each face's moving "
                                             "control points in boundary.faces_free_points "
                                             "(0 = [[i, j], ...])")
    for ext in s.output.formats:
        if ext not in BODY_FORMATS:
            raise s.error("output.formats", f"{ext} is not written for a body of "
                          f"{len(body)} faces yet; a body writes {', '.join(BODY_FORMATS)}")
    for i, spec in enumerate(s.loads, start=1):
        if spec.face is None:
            if spec.kind == "point":
                raise s.error(f"load[{i}].face", "a point load on a body names its face: "
                              f"face = k, one of the file's faces {list(body.faces)}")
            continue
        patch = body.patch_of_face(spec.face)
        if patch is None:
            raise s.error(f"load[{i}].face", f"face {spec.face} is not in this body, whose "
                                             f"faces are {list(body.faces)}")
        if spec.at is not None:
            check_at(s, f"load[{i}].at", spec.at, body[patch])


def check_at(scenario: Scenario, path: str, at: tuple[float, float], surface: Any) -> None:
    """Refuse at ``path`` parameters ``at`` outside the domain of a body's face."""
    for x, basis, name in ((at[0], surface.basis_u, "u"), (at[1], surface.basis_v, "v")):
        if not basis.periodic and not -1e-12 <= x <= basis.length * (1 + 1e-12):
            raise scenario.error(path, f"{name} = {x:g} is outside the parameter domain "
                                       f"[0, {basis.length:g}] of this face")


def check_single_surface_loads(scenario: Scenario, face: int | None) -> None:
    """``load.face`` on one surface: only the face it is (a CAD face), else refused;
    ``boundary.faces`` and ``output.probe_faces`` are a body's, refused on one surface."""
    if scenario.output.probe_faces is not None:
        raise scenario.error("output.probe_faces", "names faces of a body of CAD faces; one "
                             "surface's probes are [u, v] on it")
    if "faces" in scenario.raw.get("boundary", {}):
        raise scenario.error("boundary.faces", "names edges of the faces of a body of CAD "
                             "faces; one surface takes u0, u1, v0 and v1")
    if "faces_free_points" in scenario.raw.get("boundary", {}):
        raise scenario.error("boundary.faces_free_points", "names control points of the faces "
                             "of a body of CAD faces; one surface lists its own in "
                             "boundary.free_points")
    for i, spec in enumerate(scenario.loads, start=1):
        if spec.face is not None and spec.face != face:
            where = (f"the one face read ({face})" if face is not None
                     else "a body of CAD faces")
            raise scenario.error(f"load[{i}].face", f"face {spec.face}: this load acts on "
                                                    f"{where}; remove face or choose faces")


def face_presets(scenario: Scenario, body: FileBody) -> str | dict[tuple[int, str], str]:
    """The boundary of a body: ``boundary.u0`` (the one preset) on every boundary edge,
    replaced on the edges that ``boundary.faces`` names (``{face: {edge: preset}}``, the
    file's face numbers), as ``{(patch, edge): preset}``; a face not in the body, or an
    edge that is an interface or a pole, is refused at its key."""
    named = scenario.raw.get("boundary", {}).get("faces")
    if not named:
        return scenario.boundary.u0
    topology = body.topology
    out = {edge: scenario.boundary.u0 for edge in topology.boundary}
    joined = {(i.a, i.edge_a): (i.b, i.edge_b) for i in topology.interfaces}
    joined.update({(i.b, i.edge_b): (i.a, i.edge_a) for i in topology.interfaces})
    for key, edges in named.items():
        patch = body.patch_of_face(int(key))
        if patch is None:
            raise scenario.error(f"boundary.faces.{key}", f"face {key} is not in this body, "
                                 f"whose faces are {list(body.faces)}")
        for edge, preset in edges.items():
            where = f"boundary.faces.{key}.{edge}"
            if preset in SHELL_EDGES and scenario.material.physics != "shell":
                raise scenario.error(where, f"{preset!r} is an edge of the Kirchhoff–Love "
                                     "shell only (material.physics = \"shell\"), not of "
                                     f"physics {scenario.material.physics!r}")
            if (patch, edge) in joined:
                other, side = joined[(patch, edge)]
                raise scenario.error(where, f"edge {edge} of face {key} is an interface (it "
                                     f"meets edge {side} of face {body.faces[other]}): an "
                                     "interface takes no condition, only a boundary edge does")
            if (patch, edge) in topology.poles:
                raise scenario.error(where, f"edge {edge} of face {key} is a pole (collapsed "
                                            "to a point): it takes no condition")
            out[(patch, edge)] = preset
    return out


def face_masks(scenario: Scenario, body: FileBody) -> list[Any] | None:
    """The masks of fixed control points of ``boundary.faces_free_points``
    (``{face: [[i, j], ...]}``, the file's face numbers), one per patch: on a listed face
    every point not listed is fixed, a face not listed gets ``None``; ``None`` without the
    key. A face not in the body, or an index off its face's net, is refused at its key
    path ``boundary.faces_free_points.<face>[n]`` (``n`` from 1)."""
    from .checks import moving_points_mask

    named = scenario.raw.get("boundary", {}).get("faces_free_points")
    if not named:
        return None
    masks: list[Any] = [None] * len(body)
    for key, points in named.items():
        patch = body.patch_of_face(int(key))
        if patch is None:
            raise scenario.error(f"boundary.faces_free_points.{key}", f"face {key} is not in "
                                 f"this body, whose faces are {list(body.faces)}")
        masks[patch] = moving_points_mask(scenario, points, body[patch].shape,
                                          f"boundary.faces_free_points.{key}",
                                          f"face {key}: its net")
    return masks


def body_model(scenario: Scenario, body: FileBody) -> Any:
    """The model of a body scenario: a :class:`~splinedeform.body.BodyModel` (the thin plate
    under tension), or under ``physics = "shell"`` a
    :class:`~splinedeform.physics.shell_model.ShellModel` of the body (conforming interfaces
    merged, the rest and every interface's rotation coupled, :mod:`..physics.shell_body`),
    both with the masks of ``boundary.faces_free_points`` (:func:`face_masks`)."""
    from ..body.model import BodyModel
    from ..material import Material
    from .build import _located

    check_body_scenario(scenario, body)
    boundary = face_presets(scenario, body)
    fixed = face_masks(scenario, body)
    if scenario.material.physics == "shell":
        from ..physics.shell import ShellMaterial
        from ..physics.shell_model import ShellModel

        with _located(scenario, "material"):
            shell = ShellMaterial(**scenario.material.shell())
        with _located(scenario, "boundary"), _at_face_masks(body):
            return ShellModel(body, shell, boundary, fixed=fixed)
    with _located(scenario, "material"):
        material = Material(**scenario.material.weights())
    with _located(scenario, "boundary"), _at_face_masks(body):
        return BodyModel(body, material, boundary=boundary,
                         mass_matrix=scenario.material.mass_matrix,
                         physics=scenario.material.physics, fixed=fixed)


@contextmanager
def _at_face_masks(body: FileBody) -> Iterator[None]:
    """Put an error that a trimmed face's mask of fixed points causes (its ``patch``,
    :func:`~splinedeform.body.trimmed.mask_of_face`) at ``boundary.faces_free_points.<face>``
    (the file's face number)."""
    from ..errors import InputError

    try:
        yield
    except InputError as exc:
        patch = getattr(exc, "patch", None)
        if patch is not None and getattr(exc, "key", None) is None:
            key = f"boundary.faces_free_points.{body.faces[patch]}"
            exc.key = key  # type: ignore[attr-defined]
        raise


def on_faces(scenario: Scenario, body: Any, load: Any, index: int) -> Any:
    """``load`` of ``[[load]]`` number ``index`` on its face only, when it names one."""
    face = scenario.loads[index - 1].face
    if face is None or not isinstance(body, FileBody):
        return load
    from ..body.loads import OnPatch

    return OnPatch(load, body.patch_of_face(face))


def describe_body(built: Any) -> list[tuple[str, str]]:
    """Rows of ``splinedeform validate`` for a body: faces, nets, topology, unknowns."""
    body = built.surface
    points = sum(s.shape[0] * s.shape[1] for s in body)
    counts = getattr(body, "counts", None) or body.summary()
    rows = [("faces", f"{len(body)} ({', '.join(str(f) for f in body.faces)})"),
            ("control nets", f"{points} points in {len(body)} nets"),
            ("edges", ", ".join(f"{v} {k.replace('_', '-')}" for k, v in counts.items())),
            *([("trim edges", "{shared} shared, {free} free, {stretches} stretches coupled"
                .format(**body.trim_summary()))] if any(s.trim is not None for s in body)
              else []),
            (getattr(built.model, "unknowns_label", "free control points"),
             str(built.model.n_free))]
    return rows + ([("length unit", built.units)] if built.units is not None else [])
