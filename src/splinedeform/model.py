"""The deformation model: Galerkin matrices by Kronecker products, reduction, solves.

For every coordinate alike (DESIGN.md §1.5)::

    M = μ G0u⊗G0v                    (or its row-sum lumped diagonal)
    C = (γ/μ) M + β K
    K = w10 G1u⊗G0v + w01 G0u⊗G1v + w20 G2u⊗G0v + 2 w11 G1u⊗G1v + w02 G0u⊗G2v

with exact 1-D Gram matrices ``G_a``; constraints ``d = T d_free`` reduce them to
``M_r = Tᵀ M T`` etc. Data flows one way: surface + material + boundary → model →
static / modes / dynamic solutions.

The model owns static, modes and dynamics for every physics: what differs between the
plate and the Kirchhoff–Love shell (unknowns per control point, damping, load fields, rigid
modes, the static solve's refusals, the eigensolvers' guard, read-out) is the
:class:`~splinedeform.physics.formulation.Formulation` in ``model.formulation``
(:class:`~splinedeform.physics.plate.PlateFormulation` here, the shell's in
:class:`splinedeform.ShellModel`).
"""

from __future__ import annotations

import time
from typing import Any, Mapping

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from .assembly import ReducedFactors, _largest, check_bending, full_matrices
from .boundary import Constraints
from .errors import InputError
from .loads import Load, as_load, static_time
from .material import Material, check_scales
from .physics.formulation import Formulation, damping
from .physics.plate import METHODS, surface_system
from . import modal_solve
from .modal_solve import check_count as _check_count
from .readout import free_coordinates
from .modal_solution import ModalSolution
from .solution import Readout, SampledSolution, StaticSolution
from . import spectrum
from .solvers import modal_basis, numeric
from .solvers.forcing import ReducedForcing
from .solvers.system import KroneckerFactors, Reduction
from .surface import Surface
from .threads import owned
from .static_solve import check_options

Array = NDArray[np.float64]
STEP_METHODS = ("newmark", "radau3", "radau5", "radau7", "genalpha")   # take a step dt


class Model:
    """A B-spline surface with a material and boundary conditions.

    Parameters
    ----------
    surface : Surface
        The initial (and, by default, rest) surface.
    material : Material
    boundary : str or mapping, default "free"
        ``"free" | "pinned" | "clamped"`` for all edges, or per edge
        ``{"u0": ..., "u1": ..., "v0": ..., "v1": ...}`` (missing edges are free).
    fixed : bool array ``(n_u, n_v)``, optional
        Control points that do not move (the paper's reduced set of moving points).
    mass_matrix : {"consistent", "lumped"}
        Consistent ``μ G0⊗G0`` (accurate) or row-sum lumped (diagonal, cheaper).
    rest : {"initial", "none"}
        Rest shape: the initial surface (an unloaded surface stays put), or none (the
        energy of the position itself, i.e. the extra load ``-K p0``).
    physics : {"parametric", "intrinsic"}
        ``parametric``: the paper's energy per unit parameter area (Kronecker matrices);
        ``intrinsic``: the same plate under tension measured on the initial surface
        (:mod:`splinedeform.physics.intrinsic`), independent of the parametrisation.
        A trimmed surface (``surface.trim``) takes either over its trimmed region
        (:mod:`splinedeform.trim.model_matrices`, :mod:`splinedeform.trim.intrinsic_trimmed`;
        the shell's is :mod:`splinedeform.trim.shell_trimmed`), with ``boundary`` naming its loops
        (``{"outer": "clamped", "hole1": "free"}``). With bending weights, the tangent
        continuity across each C0 knot line where the rest shape is smooth is imposed
        exactly by the constraint map (:mod:`splinedeform.physics.coupling_ties`), the
        rotation across any other by a penalty (:mod:`splinedeform.physics.coupling_model`);
        either leaves no Kronecker factors.

    Examples
    --------
    >>> import splinedeform as sd
    >>> surf = sd.shapes.plane(cells=(4, 4))
    >>> model = sd.Model(surf, sd.Material(w10=1, w01=1), boundary="clamped")
    >>> model.n_free
    9
    """

    #: the patches of a body (``None``: one surface, :attr:`surface`)
    patches: tuple[Surface, ...] | None = None
    #: the reduced 1-D Gram matrices and the constructor's boundary and fixed points, for
    #: :meth:`with_material` (None on a model built otherwise, as a body of patches)
    _factors: ReducedFactors | None = None
    _arguments: dict[str, Any] | None = None

    def __init__(self, surface: Surface, material: Material,
                 boundary: str | Mapping[str, str] = "free", fixed: ArrayLike | None = None,
                 mass_matrix: str = "consistent", rest: str = "initial",
                 physics: str = "parametric"):
        start = time.perf_counter()
        if not isinstance(surface, Surface):
            raise InputError(f"surface must be a splinedeform.Surface, got {type(surface).__name__}")
        check_options(material, mass_matrix, rest, physics)
        check_bending(surface, material)
        self.surface = surface
        self.material = material
        self.mass_matrix = mass_matrix
        self.rest = rest
        self.physics = physics
        system = surface_system(surface, material, boundary, fixed, mass_matrix, physics, rest)
        self.constraints: Constraints = system.constraints
        self.formulation: Formulation = system.formulation
        self.gram_u, self.gram_v = system.gram_u, system.gram_v
        # K and M on the whole net: assembled only where the constrained matrices are made
        # from them, else when first asked for (K_full, M_full)
        self._full: tuple[sp.csr_matrix, sp.csr_matrix] | None = system.full
        self._K, self._M, self._C = system.reduced
        # the reduced 1-D Gram matrices, kept for models of other materials (with_material)
        self._factors = system.factors
        self._arguments = {"boundary": boundary, "fixed": fixed}
        self._finish(start)
        if system.rigid_modes is not None:      # a trimmed net's, counted on its region
            self._rigid = (system.rigid_modes,)

    @property
    def shares_geometry(self) -> bool:
        """Whether :meth:`with_material` shares this model's geometry (else it builds anew)."""
        return self._arguments is not None and self._factors is not None

    def with_material(self, material: Material) -> Model:
        """This model's surface, boundary, mass matrix and physics with another material,
        sharing what does not depend on it (:func:`splinedeform.same_geometry.with_material`)."""
        from .same_geometry import with_material

        return with_material(self, material)

    def _finish(self, start: float) -> None:
        """Damping ``C_r = (γ/μ) M_r + β K_r`` (unless made with K_r), the checks of scale
        and the caches."""
        material = self.material
        if getattr(self, "_C", None) is None:
            self._C = damping(self.formulation, self._M, self._K)
        if self._M.nnz and isinstance(material, Material):
            check_scales(material, _largest(self._K), _largest(self._M))
        self._eigen: tuple[Array, Array] | None = None
        self._bases: dict[tuple, modal_basis.ModalBasis] = {}
        self._rigid: tuple[int | None] | None = None
        self.timings: dict[str, float] = {"assembly": time.perf_counter() - start}

    def _full_matrices(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        if self._full is None:
            self._full = full_matrices(self.gram_u, self.gram_v, self.material,
                                       self.mass_matrix == "lumped")
        return self._full

    @property
    def K_full(self) -> sp.csr_matrix:
        """Stiffness ``K`` of the whole net, before constraints (assembled when first used)."""
        return self._full_matrices()[0]

    @property
    def M_full(self) -> sp.csr_matrix:
        """Mass ``M`` of the whole net, before constraints (assembled when first used)."""
        return self._full_matrices()[1]

    # -- layout --------------------------------------------------------------------
    @property
    def T(self) -> sp.csr_matrix:
        """The constraint map ``d = T d_free`` (rows: the formulation's unknowns)."""
        return self.constraints.T

    @property
    def n_free(self) -> int:
        """Number of free coordinates (moving control points per coordinate, or the
        shell's free unknowns)."""
        return int(self.T.shape[1])

    @property
    def unknowns_label(self) -> str:
        """How summaries name :attr:`n_free`."""
        return self.formulation.unknowns_label

    def matrices(self) -> tuple[sp.csc_matrix, sp.csc_matrix, sp.csc_matrix]:
        """Reduced ``(M_r, C_r, K_r)``, each ``(n_free, n_free)``, shared by x, y and z."""
        return self._M, self._C, self._K

    def to_full(self, d_free: Array) -> Array:
        """Full displacement net ``T d_free`` as ``(n_u, n_v, 3)`` (or ``(n_u, n_v)`` for a scalar field)."""
        full = self.T @ d_free
        return np.asarray(full).reshape(self.surface.shape + np.shape(d_free)[1:])

    @property
    def reduction(self) -> Reduction:
        """The constraint map and load offset the solvers reduce loads with."""
        rest = self._reduce_force(np.zeros((self.T.shape[0], 3))) \
            if self.rest == "none" else None
        return self._reduction(rest)

    def _reduction(self, rest: Array | None) -> Reduction:
        """:class:`Reduction` of ``T`` with the formulation's load fields."""
        return self.formulation.reduction(self.T, rest)

    @property
    def readout(self) -> Readout:
        """What a solution of this model needs to read out its free coordinates."""
        return self.formulation.readout(self.T, self._M, self._K)

    def load_vector(self, load: Load | None, t: float = 0.0) -> Array:
        """Reduced generalised force ``Tᵀ (F(t) [- K p0 when rest='none'])``: ``(n_free, 3)``
        (one unknown per control point) or ``(n_free,)`` (three, interleaved)."""
        reduction = self._reduction(None)
        F = sum((term.profile(t) * reduction.field(term, t) for term in as_load(load).terms()),
                np.zeros((self.T.shape[0], reduction.columns)))
        F_r = self._reduce_force(F)
        return F_r if reduction.columns == 3 else F_r[:, 0]

    def _reduce_force(self, F_full: Array) -> Array:
        if self.rest == "none":
            F_full = F_full - self.K_full @ self._rest_net()
        return np.asarray(self.T.T @ F_full)

    def _rest_net(self) -> Array:
        """The rest control points ``p0`` as rows ``(n_points, 3)`` of ``T``'s layout."""
        return self.surface.control_points.reshape(-1, 3)

    # -- static ----------------------------------------------------------------------
    @owned
    def static(self, load: Load | None, t: float | None = None) -> StaticSolution:
        """Equilibrium ``K_r d = Tᵀ F(t)`` by a sparse direct solve.

        A load whose profile varies in time (a step switched on later, a harmonic) needs
        the time ``t`` at which its equilibrium is wanted; it is never taken at ``t = 0``
        silently.

        The solve and its refusals are the formulation's
        (:meth:`~splinedeform.physics.formulation.Formulation.static_displacement`): the
        plate's band Cholesky, the shell's nested dissection with its free rigid motions
        removed by ``Rᵀ M_r d = 0``.

        Raises
        ------
        SingularSystemError
            When the surface is unconstrained (rigid motions have no stiffness), the
            weights leave some deformation without energy, or a shell's load does work on
            a rigid motion its boundary leaves free.
        """
        start = time.perf_counter()
        F = self.load_vector(as_load(load), static_time(as_load(load), t))
        d = self._solve_stiffness(F)
        return StaticSolution(self.readout, d, F, {"static": time.perf_counter() - start})

    def _solve_stiffness(self, F: Array) -> Array:
        return self.formulation.static_displacement(self, F)

    # -- modes -------------------------------------------------------------------------
    @owned
    def eigen(self, k: int | None = None, check_spectrum: bool = True) -> tuple[Array, Array]:
        """Lowest ``k`` (default all) eigenpairs of ``K_r φ = λ M_r φ`` with ``Φᵀ M_r Φ = I``.

        Ascending ``λ`` (round-off negatives clipped to 0) and explicit ``Φ`` of shape
        ``(n_free, k)``. Dense ``eigh`` of the reduced system (the reference) up to
        ``DENSE_LIMIT`` free coordinates; larger nets use the separable Kronecker factors
        when they apply, sparse shift-invert Lanczos for the lowest ``k``, or dense ``eigh``
        up to ``DENSE_MAX`` (see :mod:`splinedeform.solvers.modal_basis`). A few modes
        (``k <= n/10``, ``n >= 400``) of a net whose modes are not yet known come from
        sparse Lanczos too unless the separable factors apply: ``O(n k²)`` against the
        ``O(n³)`` of all modes. Cached (:mod:`splinedeform.spectrum`). Each computed pair
        is checked by the formulation's guard (the plate: the condition number; the shell:
        each pair's residual, :mod:`splinedeform.solvers.eigen_trust`) and refused if not
        resolved; ``check_spectrum=False`` skips the check (at the caller's risk).
        """
        return spectrum.eigen(self, None if k is None else _check_count(k, self.n_free),
                              check_spectrum)

    @owned
    def modal_basis(self, eigensolver: str = "auto", modes: int | None = None,
                    omega_max: float | None = None, check_spectrum: bool = True
                    ) -> modal_basis.ModalBasis:
        """Modes as a :class:`~splinedeform.solvers.modal_basis.ModalBasis` (cached).

        Parameters
        ----------
        eigensolver : {"auto", "dense", "separable", "sparse"}
            See :func:`~splinedeform.solvers.modal_basis.choose`.
        modes, omega_max : optional
            Keep only the lowest ``modes`` modes, or those with ``ω <= omega_max``.
        check_spectrum : bool
            See :meth:`eigen`.
        """
        return spectrum.modal_basis_of(self, eigensolver, modes, omega_max, check_spectrum)

    def kronecker_factors(self) -> KroneckerFactors:
        """The reduced 1-D Gram factors of ``M_r`` and ``K_r`` (:mod:`splinedeform.spectrum`)."""
        return spectrum.kronecker_factors(self)

    @property
    def rigid_modes(self) -> int | None:
        """Dimension of ``null K_r`` (motions without energy) from the weights and the
        constraints, not from eigenvalues (:func:`~splinedeform.solvers.rigid.rigid_count`);
        ``None`` where no structure is known (intrinsic plate without tension); the
        formulation's basis of ``null K_r`` where it has one (the shell's free rigid
        motions)."""
        basis = self.formulation.rigid_basis
        if basis is not None:
            return int(basis.shape[1])
        if self._rigid is None:
            self._rigid = (spectrum.rigid_count(self),)
        return self._rigid[0]

    def frequencies(self, k: int = 6, check_spectrum: bool = True) -> Array:
        """Lowest ``k`` undamped angular frequencies ``ω_i = √λ_i``, ascending."""
        return np.sqrt(self.eigen(k, check_spectrum)[0])

    def modes(self, k: int = 6, check_spectrum: bool = True) -> tuple[Array, Any]:
        """Lowest ``k`` frequencies and mode shapes: scalar fields on the net
        ``(k, n_u, n_v)`` (one unknown per control point; x, y and z move alike) or control
        net displacements ``(k, n_u, n_v, 3)`` (the shell); a body's: a list, one per patch."""
        lam, phi = self.eigen(k, check_spectrum)
        return np.sqrt(lam), self.readout.mode_shapes(phi)

    # -- dynamics ------------------------------------------------------------------------
    def initial_state(self, displacement: ArrayLike | None, velocity: ArrayLike | None
                      ) -> tuple[Array, Array]:
        """Free coordinates of an initial displacement/velocity of the control net."""
        return (free_coordinates(self.readout, self.T, displacement, "initial_displacement"),
                free_coordinates(self.readout, self.T, velocity, "initial_velocity"))

    @owned
    def dynamic(self, load: Load | None, t_end: float, method: str = "analytic",
                times: ArrayLike | None = None, initial_displacement: ArrayLike | None = None,
                initial_velocity: ArrayLike | None = None, **options: Any) -> Any:
        """Motion under ``load`` on ``[0, t_end]``.

        Parameters
        ----------
        method : {"analytic", "newmark", "radau3", "radau5", "radau7", "genalpha", "rk45", \
"dop853", "radau", "bdf"}
            ``analytic`` is the closed-form modal solution, valid at any ``t``.
            Numerical methods integrate to the output ``times``.
        times : array, optional
            Output times for numerical methods (default 201 evenly spaced on ``[0, t_end]``);
            for ``analytic``, the times the modes are chosen for (below).
        options
            ``analytic``: by default (no ``modes``, ``omega_max`` or ``tolerance``) the modes
            are chosen for ``tolerance = 1e-8``
            (:data:`splinedeform.modal_solve.DEFAULT_TOLERANCE`) where the bound applies
            (piecewise-constant loads from rest, no rigid modes, more than 1024 free
            coordinates and no separable factors), all modes otherwise;
            ``modes="all"`` takes all modes. ``tolerance``: the fewest lowest modes, plus
            the exact static part of the rest, for which an a-priori bound of the omitted
            modes' dynamic response ``c_∞ Σ_j ‖R_j‖_M E(t − t_j)`` is at most ``tolerance``
            of the largest static displacement ``max_t ‖K⁻¹F(t)‖_∞``, in the largest
            control-point coordinate (``c_∞ ≥ max_p √((M⁻¹)_pp)``,
            :mod:`splinedeform.solvers.mode_select`) at ``times`` (default 201 on
            ``[0, t_end]`` and half their spacing after each jump; one time for one
            state). It holds at **any** time asked later: the bound is evaluated there,
            and a time where the basis' bound misses (just after a jump) is computed with
            modes chosen for it
            (``solution.accuracy``); the bound reached is ``solution.truncation["bound"]``.
            ``modes`` (keep the lowest k modes) or ``omega_max`` (keep ``ω <= omega_max``),
            both with the exact static part of the omitted modes (mode acceleration) and a
            report in ``solution.truncation``;
            ``eigensolver`` (``"auto"``, ``"dense"``, ``"separable"``, ``"sparse"``, see
            :func:`splinedeform.solvers.modal_basis.choose`). ``newmark``: ``dt``.
            ``radau3/5/7`` (Radau IIA, order 5/9/13) and ``genalpha``: ``dt`` or
            ``substeps`` (steps per interval between output times and load breakpoints;
            Radau default one, gen-α default ``dt = t_end/2000``), gen-α ``rho_inf``.
            ``solve_ivp`` methods: ``rtol``, ``atol``, ``max_step``.
        """
        if method not in METHODS:
            raise InputError(f"unknown method {method!r}; choose one of {METHODS}")
        if method not in self.formulation.methods:
            raise InputError(f"the {self.physics} model's dynamic solve takes the methods "
                             f"{self.formulation.methods}, got {method!r}")
        try:
            t_end = float(t_end)
        except (TypeError, ValueError):
            raise InputError(f"t_end must be a number, got {t_end!r}") from None
        if not np.isfinite(t_end) or t_end <= 0:
            raise InputError(f"t_end must be finite and > 0, got {t_end}")
        load = as_load(load)
        d0, v0 = self.initial_state(initial_displacement, initial_velocity)
        forcing = ReducedForcing(self.reduction, load)
        if method == "analytic":
            return self._analytic(forcing, t_end, d0, v0, times=times, **options)
        start = time.perf_counter()
        M, C, K = self.matrices()
        out_times, d, v, stats = numeric.run(M, C, K, forcing, forcing.breakpoints, method,
                                             t_end, times, d0, v0, **options)
        timings = dict(self.timings)
        timings["integration"] = time.perf_counter() - start
        return SampledSolution(self.readout, method, t_end, forcing, timings, out_times, d, v,
                               stats)

    def _analytic(self, forcing: Any, t_end: float, d0: Array, v0: Array,
                  **options: Any) -> ModalSolution:
        """Closed-form modal solution (:func:`splinedeform.modal_solve.analytic`)."""
        return modal_solve.analytic(self, forcing, t_end, d0, v0, **options)
