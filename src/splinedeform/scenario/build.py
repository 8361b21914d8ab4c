"""Building library objects (surface, model, load) from a scenario."""

from __future__ import annotations

import math
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator

from ..errors import InputError, ScenarioError
from .body import (body_model, check_single_surface_loads, describe_body, is_body,
                   refined_body)
from .spec import Scenario, SurfaceSpec
from ..trim.surface_trim import region_contains
from .cad_trim import face_loop_presets, reader_warnings, with_face_trim
from .trim_build import loop_presets, trimmed


@dataclass
class Built:
    """The library objects of a scenario (see :func:`build`)."""

    surface: Any            # splinedeform.Surface
    model: Any              # splinedeform.Model
    load: Any               # splinedeform.loads.Load or None
    fixed: Any = None       # bool mask (n_u, n_v) of the free region, or None
    units: str | None = None  # length unit of a CAD surface (splinedeform.cad_units), or None


@contextmanager
def _located(scenario: Scenario, path: str) -> Iterator[None]:
    """Re-raise library errors as scenario errors located at ``path``.

    :class:`~splinedeform.errors.InputError` (and :class:`SingularSystemError`) keep their
    message; a numerical failure further down (``ValueError`` such as numpy's
    ``LinAlgError``, ``ArithmeticError`` such as an overflow) is named with its kind, so a
    scenario never ends in a traceback.
    """
    try:
        yield
    except ScenarioError:
        raise
    except InputError as exc:   # an error that knows its key (e.g. material.mass) is put there
        raise scenario.error(getattr(exc, "key", None) or path, str(exc)) from None
    except (ValueError, ArithmeticError) as exc:
        raise scenario.error(path, f"numerical failure ({type(exc).__name__}: {exc}); the "
                                   "values given are probably too extreme") from None


def build_surface(scenario: Scenario) -> Any:
    """The initial surface: a built-in shape, a stored control net or a fitted point grid."""
    return surface_and_units(scenario)[0]


def surface_and_units(scenario: Scenario) -> tuple[Any, str | None]:
    """The initial surface (see :func:`build_surface`) and its length unit: a CAD file's
    (or ``surface.units``), None for other surfaces."""
    spec = scenario.surface
    if spec.shape == "cad":
        return _cad_surface(scenario)
    return trimmed(scenario, _refined(scenario, _surface_of_shape(scenario))), None


def _cad_surface(scenario: Scenario) -> tuple[Any, str | None]:
    """A CAD surface, refined, on its face's trimmed region where the model can take it
    (:mod:`splinedeform.scenario.cad_trim`), and its unit."""
    with reader_warnings() as caught:
        surface, units = _surface_from_cad(scenario)
    surface = with_face_trim(scenario, _refined(scenario, surface), caught)
    return trimmed(scenario, surface), units


def _refined(scenario: Scenario, surface: Any) -> Any:
    """``surface`` elevated by ``surface.elevate`` degrees, then with ``surface.refine``
    knots inserted per span (:func:`splinedeform.refine.refine_surface`; same geometry);
    a body face by face (:func:`.body.refined_body`)."""
    spec = scenario.surface
    if spec.refine == (0, 0) and spec.elevate == (0, 0):
        return surface
    if is_body(surface):                 # face by face, kept conforming
        return refined_body(scenario, surface)
    from ..refine import refine_surface

    key = "surface.elevate" if spec.elevate != (0, 0) else "surface.refine"
    with _located(scenario, key):
        return refine_surface(surface, spec.elevate, spec.refine)


def _surface_of_shape(scenario: Scenario) -> Any:
    spec = scenario.surface
    if spec.shape == "file":
        return _surface_from_file(scenario)
    from .. import shapes

    with _located(scenario, "surface"), _periodic_at_knots(scenario):
        return getattr(shapes, spec.shape)(**spec.parameters, **_fit_options(spec))


@contextmanager
def _periodic_at_knots(scenario: Scenario) -> Iterator[None]:
    """A periodic direction refused on an open shape is located at ``surface.knots``."""
    try:
        yield
    except InputError as exc:
        if "'periodic' but" in str(exc) and "knots" in scenario.raw.get("surface", {}):
            raise scenario.error("surface.knots", str(exc)) from None
        raise


def _fit_options(spec: SurfaceSpec) -> dict[str, Any]:
    """``cells``, ``degree``, ``knots``, ``method`` for a shape function (None: its default)."""
    options: dict[str, Any] = {"degree": spec.degree, "method": spec.method}
    if spec.cells is not None:
        options["cells"] = spec.cells
    if spec.knots is not None:
        options["knots"] = spec.knots
    return options


def _surface_from_cad(scenario: Scenario) -> tuple[Any, str | None]:
    """Surface ``face`` of a CAD file, as a deformable NURBS surface (its whole surface),
    and its unit: ``surface.units`` if given, else the file's; without ``face``, the body
    of the faces chosen by ``faces`` (default ``"all"``; :func:`.body.body_from_cad`)."""
    from ..cad import read_cad, surface_from_patch

    path = scenario.surface.path
    assert path is not None
    face = scenario.surface.parameters["face"]
    raw = scenario.raw.get("surface", {})
    if "face" not in raw or "faces" in raw:          # faces = "all" unless face is given
        from .body import body_from_cad

        body, face, units = body_from_cad(scenario)
        if body is not None:
            return body, scenario.surface.parameters.get("units") or units
    with _located(scenario, "surface.path"):
        patch = read_cad(path, face)
        surface = surface_from_patch(patch, name=f"{path.stem} face {face}",
                                     source=f"{path} face {face}")
    return surface, scenario.surface.parameters.get("units") or patch.units


def _surface_from_file(scenario: Scenario) -> Any:
    from .. import shapes
    from ..export import read_control_net

    spec = scenario.surface
    path = spec.path
    assert path is not None
    suffix = path.suffix.lower()
    if not path.exists():          # a pipe or device is refused on opening, naming it
        raise scenario.error("surface.path", f"file not found: {path}")
    if suffix not in (".json", ".npz", ".npy"):
        raise scenario.error("surface.path", f"expected a control net (.json, .npz) or a point "
                                             f"grid (.npy, .npz), got {path.name!r}")
    grid = _point_grid(scenario, path) if suffix in (".npy", ".npz") else None
    if grid is None:
        fitted = [k for k in ("cells", "degree", "knots", "method")
                  if k in scenario.raw.get("surface", {})]
        if fitted:
            raise scenario.error(f"surface.{fitted[0]}", f"does not apply to a control net "
                                                         f"file ({path.name} holds its own bases)")
        with _located(scenario, "surface.path"):
            return read_control_net(path, frame=spec.frame)
    if "frame" in scenario.raw.get("surface", {}):
        raise scenario.error("surface.frame", "applies to control net files only, "
                                              f"{path.name} is a point grid")
    if spec.method == "quasi":
        raise scenario.error("surface.method", "a point grid is fitted by \"interpolate\" "
                                               "or \"l2\" (\"quasi\" needs a function)")
    with _located(scenario, "surface.path"):
        return shapes.from_points(grid, **_fit_options(spec))


def _point_grid(scenario: Scenario, path: Path) -> Any:
    """The ``(N_u, N_v, 3)`` grid in a ``.npy`` / ``.npz`` file, or None for a control net."""
    import numpy as np

    from ..export.nets import real_array
    from ..input_files import check_array_file, open_input

    try:
        with open_input(path, "point grid") as fh:
            check_array_file(fh, path)
            data = np.load(fh, allow_pickle=False)
            if isinstance(data, np.lib.npyio.NpzFile):
                if "control_points" in data.files and "kind_u" in data.files:
                    return None
                names = data.files
                if "points" not in names and len(names) != 1:
                    raise scenario.error("surface.path", f"{path.name} holds {names}; a point "
                                                         "grid .npz needs one array or 'points'")
                data = data["points" if "points" in names else names[0]]
    except ScenarioError:
        raise
    except InputError as exc:       # not a regular file, or arrays larger than memory
        raise scenario.error("surface.path", str(exc)) from None
    except (OSError, ValueError) as exc:
        raise scenario.error("surface.path", f"cannot read {path.name}: {exc}") from None
    if data.ndim != 3 or data.shape[2] != 3:
        raise scenario.error("surface.path", f"a point grid must have shape (N_u, N_v, 3), "
                                             f"got {data.shape}")
    with _located(scenario, "surface.path"):
        return real_array(data, f"point grid {path.name}")


def build_load(scenario: Scenario, scale: float = 1.0, body: Any = None) -> Any:
    """The sum of the ``[[load]]`` tables as a :mod:`splinedeform.loads` object (or None),
    with forces and pressures divided by ``scale`` (see :mod:`splinedeform.load_scale`);
    on a ``body``, a load naming its ``face`` acts on that face only.

    Under ``physics = "shell"`` a ``uniform`` load is a force per unit surface area
    (:class:`~splinedeform.AreaForce`, e.g. self-weight).
    """
    from .. import loads as L
    from ..physics.shell_model import AreaForce
    from .body import on_faces

    uniform = AreaForce if scenario.material.physics == "shell" else L.Uniform

    total = None
    for i, spec in enumerate(scenario.loads, start=1):
        force = None if spec.force is None else tuple(f / scale for f in spec.force)
        q = None if spec.q is None else spec.q / scale
        with _located(scenario, f"load[{i}]"):
            profile = {"constant": lambda: L.Constant(),
                       "step": lambda: L.Step(spec.t_on, spec.t_off),
                       "piecewise": lambda: L.Piecewise(spec.points),
                       "harmonic": lambda: L.Harmonic(spec.omega, spec.phase)}[spec.profile]()
            load = {"point": lambda: L.Point(spec.at[0], spec.at[1], force, profile),
                    "uniform": lambda: uniform(force=force, profile=profile),
                    "pressure": lambda: L.Pressure(q, profile)}[spec.kind]()
        load = on_faces(scenario, body, load, i)
        total = load if total is None else total + load
    return total


def free_region_mask(scenario: Scenario, surface: Any) -> Any:
    """``fixed`` mask (True = fixed): control points whose Greville point lies outside the box,
    or, with ``free_points``, every control point not listed."""
    boundary = scenario.boundary
    if not boundary.has_free_region:
        return None
    if boundary.free_points is not None:
        return _free_points_mask(scenario, surface.shape)
    inside = []
    for name, basis in (("u", surface.basis_u), ("v", surface.basis_v)):
        g = basis.greville()
        box = getattr(boundary, f"free_{name}") or (-math.inf, math.inf)
        tol = 1e-12 * basis.length
        inside.append((g >= box[0] - tol) & (g <= box[1] + tol))
    moving = inside[0][:, None] & inside[1][None, :]
    if not moving.any():
        raise scenario.error("boundary.free_region", "no control point has its Greville "
                                                     "abscissae inside this box; widen it")
    return ~moving


def _free_points_mask(scenario: Scenario, shape: tuple[int, int]) -> Any:
    """``fixed`` mask of ``boundary.free_points``; an index off the net names its entry."""
    from .checks import moving_points_mask

    return moving_points_mask(scenario, scenario.boundary.free_points or (), shape,
                              "boundary.free_points", "this surface: the net")


def _check_parameters(scenario: Scenario, surface: Any) -> None:
    """Point loads and probes must lie on the parameter domain (any value when periodic)."""
    bases = (surface.basis_u, surface.basis_v)
    for i, probe in enumerate(scenario.output.probes, start=1):
        if len(probe) != 2:
            raise scenario.error(f"output.probes[{i}]", "a point [x, y, z] in space is a "
                                 "probe of a body of CAD faces; one surface takes [u, v]")
    checks = [(f"load[{i}].at", spec.at) for i, spec in enumerate(scenario.loads, start=1)
              if spec.at is not None]
    checks += [(f"output.probes[{i}]", p) for i, p in enumerate(scenario.output.probes, start=1)]
    for path, (u, v) in checks:
        for x, basis, name in ((u, bases[0], "u"), (v, bases[1], "v")):
            if not basis.periodic and not -1e-12 <= x <= basis.length * (1 + 1e-12):
                raise scenario.error(path, f"{name} = {x:g} is outside the parameter domain "
                                           f"[0, {basis.length:g}] of this surface")
        if surface.trim is not None and not region_contains(surface, [u, v]):
            raise scenario.error(path, f"(u, v) = ({u:g}, {v:g}) is outside the trimmed "
                                       "region of this surface (surface.trim)")


def build(scenario: Scenario) -> Built:
    """Surface, model and load of a scenario; library input errors name the scenario key."""
    surface, units = _checked_surface(scenario)
    if not is_body(surface):
        _check_parameters(scenario, surface)
    built = _model_on(scenario, surface, units)
    built.load = build_load(scenario, body=surface if is_body(surface) else None)
    return built


def build_model(scenario: Scenario) -> Built:
    """Surface and model of a scenario without its loads (``load = None``).

    What scenarios differing only in ``[[load]]``, ``[solve]`` and ``[output]`` share: each
    then needs only :func:`check_parameters` and :func:`build_load` of its own.
    """
    return _model_on(scenario, *_checked_surface(scenario))


check_parameters = _check_parameters


def _checked_surface(scenario: Scenario) -> tuple[Any, str | None]:
    """The surface and its unit (:func:`surface_and_units`), a file's lengths checked."""
    surface, units = surface_and_units(scenario)
    if scenario.surface.shape in ("file", "cad"):     # the built-in shapes' lengths are keys
        from .geometry import extent_problem

        problem = extent_problem(surface, scenario.material.thickness)
        if problem is not None:
            raise scenario.error("surface.path", problem)
    return surface, units


def _model_on(scenario: Scenario, surface: Any, units: str | None) -> Built:
    from ..material import Material
    from ..model import Model

    loops = face_loop_presets(scenario, surface)
    if is_body(surface):
        return Built(surface=surface, model=body_model(scenario, surface), load=None,
                     units=units)
    check_single_surface_loads(scenario, scenario.surface.parameters.get("face")
                               if scenario.surface.shape == "cad" else None)
    fixed = free_region_mask(scenario, surface)
    if scenario.material.physics == "shell":
        return Built(surface=surface, model=_shell_model(scenario, surface, fixed, loops),
                     load=None, fixed=fixed, units=units)
    with _located(scenario, "material"):
        material = Material(**scenario.material.weights())
    with _located(scenario, "boundary"):
        model = Model(surface, material, boundary={**scenario.boundary.edges(),
                                                   **loop_presets(scenario), **loops},
                      fixed=fixed,
                      mass_matrix=scenario.material.mass_matrix,
                      physics=scenario.material.physics)
    return Built(surface=surface, model=model, load=None, fixed=fixed, units=units)


def _shell_model(scenario: Scenario, surface: Any, fixed: Any, loops: dict[str, str]
                 ) -> Any:
    """The Kirchhoff–Love shell of ``physics = "shell"`` (a trimmed surface's loops held
    as ``[boundary.loops]`` or the loops' ``edge`` say)."""
    from ..physics.shell import ShellMaterial
    from ..physics.shell_model import ShellModel

    with _located(scenario, "material"):
        material = ShellMaterial(**scenario.material.shell())
    with _located(scenario, "boundary"):
        boundary = scenario.boundary.edges()
        if getattr(surface, "trim", None) is not None:
            boundary = {**boundary, **loop_presets(scenario), **loops}
        return ShellModel(surface, material, boundary, fixed=fixed)


def describe(scenario: Scenario, built: Built | None = None) -> list[tuple[str, str]]:
    """(label, value) rows saying what :func:`run` would do (for ``splinedeform validate``)."""
    s = scenario
    rows = [("scenario", s.title or s.name), ("surface", s.surface.shape)]
    if built is not None and is_body(built.surface):
        rows += describe_body(built)
    elif built is not None:
        n_u, n_v = built.surface.shape
        rows += [("control net", f"{n_u} x {n_v} ({n_u * n_v} points)"),
                 (getattr(built.model, "unknowns_label", "free control points"),
                  str(built.model.n_free))]
        rows += [("length unit", built.units)] if built.units is not None else []
    rows += [("loads", ", ".join(f"{ld.kind} ({ld.profile})" for ld in s.loads) or "none"),
             ("solve", s.solve.kind + (f" with {s.solve.method} to t = {s.solve.t_end:g}"
                                       if s.solve.kind == "dynamic" else "")),
             ("frames", str(len(s.solve.frame_times()) if s.solve.kind == "dynamic"
                            else s.solve.frames)),
             ("outputs", ", ".join(s.output.formats) or "none")]
    return rows
