"""One sculpting session: a scenario, its current modal basis, re-solves and "Save".

The session keeps the scenario it was started from; a new material or boundary is applied
as overrides of that scenario (validated by the scenario reader, so a value the physics
refuses is named like a key of a file) and the model is rebuilt from it. "Save" writes
the same scenario with the pushes as ``[[load]]`` point forces with step profiles, so
``splinedeform run`` replays the session (:mod:`.save`).

A scenario of several CAD faces (``shape = "cad"``, ``faces = "all"``) opens as a body: the
modes are those of its :class:`~splinedeform.body.BodyModel`, sampled face by face
(:mod:`.modal`); a grab lands on the face under the pointer, whose number the saved load
names; bake and export keep every face (:mod:`.history`, :mod:`.shape_files`); the page
paints each face's moving control points, ``boundary.faces_free_points`` (:mod:`.body_paint`),
and a pin takes one point of a face out of that set (a bake, :meth:`Session.bake`).
"""

from __future__ import annotations

from contextlib import contextmanager
import threading
import time
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from ..errors import InputError, ScenarioError
from ..scenario import build, free_region_mask, scenario_to_toml, with_overrides
from ..scenario.spec import Scenario
from .body_edges import boundary_edges, faces_override
from .body_paint import body_free_mask, painted_overrides, pinned_body, point_classes
from .carry import transfer
from .correction import StaticCorrection, offline_data, static_correction
from .export import _b64, payload
from .history import BasisState, History, baked_nets, baked_scenario
from .messages import BakeMessage, ExportMessage, ResolveMessage, SaveMessage
from .modal import SculptBasis, sculpt_basis
from .save import check_index, face_numbers, net_words, portable, session_scenario
from .wording import in_page_words, page_field  # noqa: F401  (page_field: re-exported)

MATERIAL_FIELDS = ("mass", "damping", "rayleigh", "w10", "w01", "w20", "w11", "w02")
EDGE_NAMES = ("u0", "u1", "v0", "v1")


class Busy(RuntimeError):
    """A re-solve is already running."""


class Session:
    """The state the server keeps: scenario, basis, correction, progress of a re-solve.

    Parameters
    ----------
    scenario : Scenario
        Surface, material and boundary to start from (its loads are not used).
    resolution : int
        Sample grid ``resolution × resolution`` on the surface.
    modes : int or None
        Keep the lowest ``modes`` modes (all when None or more than there are); the
        omitted ones enter through the static correction.
    save_path : Path
        Where "Save" writes the scenario (the page cannot choose another file).
    """

    def __init__(self, scenario: Scenario, resolution: int = 64, modes: int | None = 200,
                 save_path: Path | None = None):
        if scenario.material.physics not in ("parametric", "intrinsic"):
            raise InputError(f"sculpt needs material.physics 'parametric' or 'intrinsic' "
                             f"(x, y and z share the modes), got {scenario.material.physics!r}")
        self.scenario = scenario
        self.resolution = int(resolution)
        self.modes = modes
        self.save_path = Path(save_path or f"{scenario.name}-sculpt.toml")
        self.version = 0
        self._versions = 0              # the last version given: each basis has its own
        self.history = History()
        self.progress: dict[str, Any] = {"busy": False, "stage": "idle", "elapsed": 0.0,
                                         "error": None}
        self._lock = threading.Lock()
        self._state_lock = threading.Lock()
        self.basis: SculptBasis
        self.correction: StaticCorrection
        self.transfer: tuple[int, np.ndarray] | None = None
        """``(old version, P)``: the last re-solve's map from old to new modal coordinates."""
        self._solve(scenario)

    # -- solving ------------------------------------------------------------------------
    def _stage(self, stage: str, start: float) -> None:
        self.progress.update(stage=stage, elapsed=time.perf_counter() - start)

    def _solve(self, scenario: Scenario, carry: bool = True) -> None:
        from threadpoolctl import threadpool_limits

        # one BLAS thread: the machine's other core draws the page (and oversubscribed
        # BLAS threads make a dense eigensolve several times slower, not faster)
        with threadpool_limits(1):
            self._solve_now(scenario, carry)

    def _solve_now(self, scenario: Scenario, carry: bool = True) -> None:
        start = time.perf_counter()
        self._stage("assembling the matrices", start)
        built = build(scenario)
        model = built.model
        k = None if self.modes is None or self.modes >= model.n_free else int(self.modes)
        self._stage(f"computing {k or model.n_free} modes", start)
        basis = sculpt_basis(model, self.resolution, k, built.units)
        self._stage("static correction", start)
        correction = static_correction(basis)
        old = getattr(self, "basis", None)
        if old is not None and carry:
            self._stage("carrying the motion over", start)
            self.transfer = (self.version, transfer(old, basis))
        elif old is not None:
            self.transfer = None            # another surface: nothing to carry over
        with self._state_lock:          # readers see one basis with its version, never a mix
            if old is not None:
                self.history.replaced(self._state())
            self._versions += 1
            self.scenario, self.basis, self.correction = scenario, basis, correction
            self.version = self._versions
        self.timing = time.perf_counter() - start
        self._stage("done", start)

    def resolve(self, message: ResolveMessage) -> None:
        """New material and boundary: validate as scenario overrides, rebuild, re-solve.

        Raises :class:`Busy` when a re-solve is running and
        :class:`~splinedeform.errors.InputError` for values the physics refuses; the
        current basis stays in place then.
        """
        with self._re_solving("validating"):
            overrides: dict[str, Any] = {f"material.{k}": getattr(message.material, k)
                                         for k in MATERIAL_FIELDS}
            overrides.update({f"boundary.{e}": getattr(message.boundary, e) for e in EDGE_NAMES})
            faces = faces_override(message.boundary.faces)
            if faces is not None and not self.basis.is_body:
                raise InputError("boundary.faces sets the edges of a body's faces; this is one "
                                 "surface: set its edges u0, u1, v0 and v1")
            overrides["boundary.faces"] = faces     # None: every boundary edge takes u0
            region = message.free_region
            box = None if region is None else {k: list(getattr(region, k)) for k in "uv"
                                               if getattr(region, k) is not None} or None
            overrides["boundary.free_region"] = box     # None (or {}): the whole net moves
            overrides.update(painted_overrides(message, self.basis.is_body))
            try:
                self._solve(with_overrides(self.scenario, overrides, origin="sculpt page"))
            except ScenarioError as exc:    # the page's settings, not a line of the file
                raise InputError(in_page_words(str(exc), self.scenario.source)) from None

    @contextmanager
    def _re_solving(self, stage: str) -> Iterator[None]:
        """Hold the re-solve lock (:class:`Busy` if it is held) with the progress ``stage``;
        an error is shown on the page (stage ``failed``) and raised again."""
        if not self._lock.acquire(blocking=False):
            raise Busy("a re-solve is already running")
        try:
            self.progress.update(busy=True, error=None, stage=stage, elapsed=0.0)
            yield
        except Exception as exc:
            self.progress.update(error=str(exc), stage="failed")
            raise
        finally:
            self.progress["busy"] = False
            self._lock.release()

    def _state(self) -> BasisState:
        return BasisState(self.scenario, self.basis, self.correction, self.version)

    def bake(self, message: BakeMessage) -> None:
        """Make the shape of the modal state ``message.q`` the rest shape and re-solve
        (:mod:`.history`); :attr:`transfer` maps the old modes onto the new ones. A pin
        gives the new free set: ``free_points`` of one surface, ``faces_free_points`` of a
        body (:func:`.body_paint.pinned_body`)."""
        with self._re_solving("baking"):
            with self._state_lock:
                self._check_version(message.version)
                basis, scenario = self.basis, self.scenario
            nets = baked_nets(basis, np.asarray(message.q, dtype=float))
            # a pin: the free set less the pinned point (the wrong kind refused); a body's
            # is applied before the bake, which renumbers its faces to the baked file's
            pin = None if message.free_points is None and message.faces_free_points is None \
                else painted_overrides(message, basis.is_body)
            if pin is not None and basis.is_body:
                scenario = pinned_body(scenario, basis, pin)
            folder = self.save_path.parent
            baked, path = baked_scenario(scenario, basis, nets, folder,
                                         f"{self.save_path.stem}-baked-{self._versions + 1}")
            try:
                if pin is not None and not basis.is_body:
                    baked = with_overrides(baked, {"boundary.free_region": None,
                                                   "boundary.free_points":
                                                   pin["boundary.free_points"]},
                                           origin="sculpt page")
                self._solve(baked)
            except ScenarioError as exc:
                path.unlink(missing_ok=True)
                raise InputError(in_page_words(str(exc), scenario.source)) from None
            except Exception:
                path.unlink(missing_ok=True)        # refused: no file of a shape never used
                raise

    def export(self, message: ExportMessage) -> tuple[bytes, str, str]:
        """The shape of ``message.q`` as a file (:func:`.shape_files.shape_file`)."""
        from .shape_files import shape_file

        with self._state_lock:
            self._check_version(message.version)
            basis, title = self.basis, self.scenario.title or self.scenario.name
        return shape_file(basis, np.asarray(message.q, dtype=float), message.format, title)

    def load(self, name: str, content: bytes) -> None:
        """A surface (or a whole scenario) from a file the page sent (:mod:`.upload`)."""
        from .upload import loaded

        with self._re_solving("reading " + name):
            stem = f"{self.save_path.stem}-loaded-{self._versions + 1}"
            with loaded(self.scenario, name, content, self.save_path.parent, stem) as scenario:
                self._solve(scenario, carry=False)

    def undo(self, version: int) -> None:
        """Back to the basis before the current one (exactly: kept, not solved again)."""
        self._switch(version, self.history.back)

    def redo(self, version: int) -> None:
        """Forward to the basis undone last."""
        self._switch(version, self.history.forward)

    def _switch(self, version: int, step: Any) -> None:
        if not self._lock.acquire(blocking=False):
            raise Busy("a re-solve is already running")
        try:
            with self._state_lock:
                self._check_version(version)
                state = step(self._state())
                self.scenario, self.basis, self.correction = (state.scenario, state.basis,
                                                              state.correction)
                self.version, self.transfer = state.version, None
        finally:
            self._lock.release()

    # -- what the page receives ------------------------------------------------------------
    def payload(self) -> dict[str, Any]:
        """The modal data (see :func:`.export.payload`) plus the control net, the current
        material and boundary, and what the server offers; a body's adds ``body`` (its
        faces' numbers, unit and boundary edges with their presets, :mod:`.body_edges`, and
        ``classes``, the point of the body each net row is, int32), whose free set is
        painted face by face (:mod:`.body_paint`)."""
        basis, model = self.basis, self.basis.model
        data = payload(basis)
        s = self.scenario
        net_rest = basis.rest_net()
        data.update(
            version=self.version, title=s.title or s.name, n_free=int(model.n_free),
            complete=bool(self.correction.complete),
            phi_net=_b64(basis.phi_net), net_rest=_b64(net_rest),
            material={k: getattr(s.material, k) for k in MATERIAL_FIELDS},
            boundary={e: getattr(s.boundary, e) for e in EDGE_NAMES},
            free_mask=_b64(self._free_mask(), "u1"),
            still_mask=_b64(self._still_mask(), "u1"),
            solve_seconds=round(self.timing, 4), server=True)
        if basis.is_body:
            data.update(net_shape=[int(net_rest.shape[0]), 1], periodic=[False, False],
                        free_region=None, greville=[[], []], body={
                            "faces": face_numbers(basis), "units": basis.units,
                            "edges": boundary_edges(s, model),
                            "classes": _b64(point_classes(basis), "<i4")})
            data["domain"] = [float(basis.patches[0].basis_u.length),
                              float(basis.patches[0].basis_v.length)]
            return data
        surf = model.surface
        data.update(
            net_shape=list(surf.shape), periodic=[bool(surf.basis_u.periodic),
                                                  bool(surf.basis_v.periodic)],
            free_region={k: getattr(s.boundary, f"free_{k}") for k in "uv"}
            if s.boundary.free_u is not None or s.boundary.free_v is not None else None,
            greville=[surf.basis_u.greville().tolist(), surf.basis_v.greville().tolist()],
            domain=[float(surf.basis_u.length), float(surf.basis_v.length)])
        return data

    def page_payload(self) -> dict[str, Any]:
        """:meth:`payload` plus the data of the static correction for a saved page."""
        with self._state_lock:
            basis = self.basis
        return {**self.payload(), "offline": offline_data(basis)}

    def _free_mask(self) -> np.ndarray:
        """The moving set the scenario names (box or list), row-major, True = free; the
        edge presets may hold some of these points too (:meth:`_still_mask` says which)."""
        if self.basis.is_body:                  # a body: the faces' painted sets
            return body_free_mask(self.scenario, self.basis)
        fixed = free_region_mask(self.scenario, self.basis.model.surface)
        shape = self.basis.model.surface.shape
        return np.ones(shape[0] * shape[1], bool) if fixed is None else ~np.ravel(fixed)

    def _still_mask(self) -> np.ndarray:
        """The control points that cannot move in the solved model, row-major: the empty
        rows of its constraint map ``d = T d_free`` (held by an edge preset or outside the
        free set)."""
        T = self.basis.model.constraints.T.tocsr()
        T.eliminate_zeros()
        return np.diff(T.indptr) == 0

    def transfer_payload(self) -> dict[str, Any] | None:
        """The last re-solve's ``P`` (float64, ``(k_new, k_old)`` row-major) for the page."""
        if self.transfer is None:
            return None
        version, P = self.transfer
        return {"from_version": version, "shape": list(P.shape), "transfer": _b64(P, "<f8")}

    def correction_column(self, version: int, index: int) -> np.ndarray:
        """``r_a`` of sample ``index`` on basis ``version`` (see :mod:`.correction`)."""
        with self._state_lock:
            self._check_version(version)
            check_index(self.basis, index, "index")
            correction = self.correction
        return correction.column(index)

    def _check_version(self, version: int) -> None:
        if version != self.version:
            raise InputError(f"the page shows basis {version} but the server has {self.version} "
                             "(re-solved meanwhile); reload the page")

    # -- save --------------------------------------------------------------------------------
    def to_scenario(self, message: SaveMessage) -> Scenario:
        """The session as a scenario: each grab one piecewise point load (:mod:`.save`)."""
        self._check_version(message.version)
        return session_scenario(self.scenario, self.basis, message, self.resolution)

    def save(self, message: SaveMessage) -> tuple[Path, str]:
        """Write the session scenario to :attr:`save_path` (atomically); return it and its text."""
        from ..export import write_text

        scenario = self.to_scenario(message)
        header = [f"# Saved by splinedeform sculpt: {len(message.pushes)} force steps in "
                  f"{len(scenario.loads)} piecewise loads on {net_words(self.basis)}.",
                  "# splinedeform run replays it with every mode"
                  + ("." if self.correction.complete else
                     f" (the page kept {self.basis.lam.size} of {self.basis.model.n_free} and "
                     "added the static part of the others)."), ""]
        text = "\n".join(header) + scenario_to_toml(portable(scenario, self.save_path))
        path = write_text(self.save_path, text)
        return path, text
