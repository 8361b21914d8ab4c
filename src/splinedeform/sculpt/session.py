"""One sculpting session: a scenario, its current modal basis, re-solves and "Save".

The session keeps the scenario it was started from; a new material or boundary is applied
as overrides of that scenario (validated by the scenario reader, so a value the physics
refuses is named like a key of a file) and the model is rebuilt from it. "Save" writes
the same scenario with the pushes as ``[[load]]`` point forces with step profiles, so
``splinedeform run`` replays the session; a surface read from a file (``file``, ``cad``) is
named relative to the saved scenario, copied beside it when it lies outside its folder.
"""

from __future__ import annotations

import dataclasses
from contextlib import contextmanager
import shutil
import threading
import time
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from ..errors import InputError, ScenarioError
from ..scenario import build, free_region_mask, scenario_to_toml, with_overrides
from ..scenario.body import is_body
from ..scenario.spec import Scenario
from .carry import transfer
from .correction import StaticCorrection, offline_data, static_correction
from .export import _b64, payload
from .grabs import chain_tables, grab_chains
from .history import BasisState, History, baked_net, baked_scenario
from .messages import BakeMessage, ExportMessage, PushMessage, ResolveMessage, SaveMessage
from .modal import SculptBasis, sculpt_basis
from .wording import in_page_words, page_field  # noqa: F401  (page_field: re-exported)

MATERIAL_FIELDS = ("mass", "damping", "rayleigh", "w10", "w01", "w20", "w11", "w02")
EDGE_NAMES = ("u0", "u1", "v0", "v1")
MAX_PROBES = 8
"""Grabbed points written as probes of the saved scenario (the first ones)."""


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
        if is_body(built.surface):
            raise scenario.error("surface.faces", f"sculpting opens one surface, not yet a body "
                                 f"of {len(built.surface)} faces: choose one with face = k")
        model = built.model
        k = None if self.modes is None or self.modes >= model.n_free else int(self.modes)
        self._stage(f"computing {k or model.n_free} modes", start)
        basis = sculpt_basis(model, self.resolution, k)
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
            region = message.free_region
            box = None if region is None else {k: list(getattr(region, k)) for k in "uv"
                                               if getattr(region, k) is not None} or None
            overrides["boundary.free_region"] = box     # None (or {}): the whole net moves
            points = message.free_points
            overrides["boundary.free_points"] = None if points is None else [list(p) for p in points]
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
        (:mod:`.history`); :attr:`transfer` maps the old modes onto the new ones."""
        with self._re_solving("baking"):
            with self._state_lock:
                self._check_version(message.version)
                basis, scenario = self.basis, self.scenario
            net = baked_net(basis, np.asarray(message.q, dtype=float))
            folder = self.save_path.parent
            baked, path = baked_scenario(scenario, basis, net, folder,
                                         f"{self.save_path.stem}-baked-{self._versions + 1}")
            try:
                if message.free_points is not None:   # a pin: the set less the pinned point
                    baked = with_overrides(baked, {
                        "boundary.free_region": None,
                        "boundary.free_points": [list(p) for p in message.free_points]},
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
        material and boundary, and what the server offers."""
        basis, model = self.basis, self.basis.model
        data = payload(basis)
        surf = model.surface
        s = self.scenario
        data.update(
            version=self.version, title=s.title or s.name, n_free=int(model.n_free),
            complete=bool(self.correction.complete),
            net_shape=list(surf.shape), periodic=[bool(surf.basis_u.periodic),
                                                  bool(surf.basis_v.periodic)],
            phi_net=_b64(basis.phi_net), net_rest=_b64(surf.control_points.reshape(-1, 3)),
            material={k: getattr(s.material, k) for k in MATERIAL_FIELDS},
            boundary={e: getattr(s.boundary, e) for e in EDGE_NAMES},
            free_region={k: getattr(s.boundary, f"free_{k}") for k in "uv"}
            if s.boundary.free_u is not None or s.boundary.free_v is not None else None,
            free_mask=_b64(self._free_mask(), "u1"),
            still_mask=_b64(self._still_mask(), "u1"),
            greville=[surf.basis_u.greville().tolist(), surf.basis_v.greville().tolist()],
            domain=[float(surf.basis_u.length), float(surf.basis_v.length)],
            solve_seconds=round(self.timing, 4), server=True)
        return data

    def page_payload(self) -> dict[str, Any]:
        """:meth:`payload` plus the data of the static correction for a saved page."""
        with self._state_lock:
            basis = self.basis
        return {**self.payload(), "offline": offline_data(basis)}

    def _free_mask(self) -> np.ndarray:
        """The moving set the scenario names (box or list), row-major, True = free; the
        edge presets may hold some of these points too (:meth:`_still_mask` says which)."""
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
            self._check_index(index, "index")
            correction = self.correction
        return correction.column(index)

    def _check_version(self, version: int) -> None:
        if version != self.version:
            raise InputError(f"the page shows basis {version} but the server has {self.version} "
                             "(re-solved meanwhile); reload the page")

    def _check_index(self, index: int, what: str) -> None:
        count = self.basis.samples_u.size * self.basis.samples_v.size
        if not 0 <= index < count:
            raise InputError(f"{what} = {index} is not a sample point (0 .. {count - 1})")

    # -- save --------------------------------------------------------------------------------
    def to_scenario(self, message: SaveMessage) -> Scenario:
        """The session as a scenario: each grab one piecewise point load (:mod:`.grabs`),
        probes at the grabbed points."""
        self._check_version(message.version)
        for n, push in enumerate(message.pushes, start=1):
            self._check_push(push, n)
        loads, probes = [], []
        for chain in grab_chains(message.pushes):
            at = self._sample_point(chain[0].index)
            loads += chain_tables(chain, at)
            if at not in probes and len(probes) < MAX_PROBES:
                probes.append(at)
        if not loads:
            raise InputError("nothing to save: every push of the session has zero force")
        overrides: dict[str, Any] = {
            "load": loads,
            "title": f"sculpted: {self.scenario.title or self.scenario.name}",
            "solve": {"kind": "dynamic", "method": "analytic", "t_end": message.t_end,
                      "frames": 101, "modes": min(6, self.basis.model.n_free)},
            "output": {"formats": ["report", "images", "viewer"],
                       "resolution": min(self.resolution, 64)},
        }
        if probes:
            overrides["output"]["probes"] = probes
        return with_overrides(self.scenario, overrides, origin="sculpt save")

    def _check_push(self, push: PushMessage, n: int) -> None:
        self._check_index(push.index, f"pushes[{n}].index")
        if push.t_off is not None and not push.t_off > push.t_on:
            raise InputError(f"pushes[{n}]: t_off = {push.t_off} must be after t_on = {push.t_on}")

    def _sample_point(self, index: int) -> list[float]:
        """``[u, v]`` of sample ``index`` (row-major over the sample grid)."""
        rv = self.basis.samples_v.size
        return [float(self.basis.samples_u[index // rv]), float(self.basis.samples_v[index % rv])]

    def save(self, message: SaveMessage) -> tuple[Path, str]:
        """Write the session scenario to :attr:`save_path` (atomically); return it and its text."""
        from ..export import write_text

        scenario = self.to_scenario(message)
        model = self.basis.model
        header = [f"# Saved by splinedeform sculpt: {len(message.pushes)} force steps in "
                  f"{len(scenario.loads)} piecewise loads on "
                  f"{model.surface.shape[0]}x{model.surface.shape[1]} control points.",
                  "# splinedeform run replays it with every mode"
                  + ("." if self.correction.complete else
                     f" (the page kept {self.basis.lam.size} of {model.n_free} and added the "
                     "static part of the others)."), ""]
        text = "\n".join(header) + scenario_to_toml(self._portable(scenario))
        path = write_text(self.save_path, text)
        return path, text

    def _portable(self, scenario: Scenario) -> Scenario:
        """``scenario`` with its surface file (if any) named relative to the save file's
        folder, which ``splinedeform run`` reads without ``--allow-outside-paths``: the
        file as it is when it lies in that folder or below, else a copy beside the save."""
        from ..export import write_with

        source = scenario.surface.path
        if source is None:
            return scenario
        source = Path(source).resolve()
        folder = self.save_path.parent.resolve()
        if not source.is_relative_to(folder):
            target = folder / source.name
            if target.exists() and not _same_file(target, source):
                target = folder / f"{self.save_path.stem}-{source.name}"
            if not (target.exists() and _same_file(target, source)):
                write_with(target, lambda tmp: shutil.copyfile(source, tmp))
            source = target
        relative = Path(source.relative_to(folder).as_posix())
        return dataclasses.replace(scenario,
                                   surface=dataclasses.replace(scenario.surface, path=relative))


def _same_file(a: Path, b: Path) -> bool:
    """Whether two regular files hold the same bytes (anything else in their place, such as
    a named pipe, is not the same file and is never read)."""
    from ..input_files import MAX_TEXT_BYTES, open_input

    if not (a.is_file() and b.is_file()) or a.stat().st_size != b.stat().st_size:
        return False
    with open_input(a, "file", MAX_TEXT_BYTES * 32) as fa, \
            open_input(b, "file", MAX_TEXT_BYTES * 32) as fb:
        return fa.read() == fb.read()

