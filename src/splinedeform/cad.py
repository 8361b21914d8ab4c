"""NURBS surfaces to and from openNURBS ``.3dm`` files (through ``rhino3dm``).

A surface is held as :class:`NurbsPatch`: degrees ``(n_u, n_v)``, full clamped knot
vectors (``N + n + 1`` knots each, our convention and splipy's/geomdl's), control points
``P_ij`` of shape ``(N_u, N_v, 3)`` and weights ``w_ij``. The point is

.. math:: S(u, v) = \\frac{\\sum_{ij} w_{ij} N_i(u) N_j(v) P_{ij}}{\\sum_{ij} w_{ij} N_i(u) N_j(v)}.

and its coordinates are in :attr:`NurbsPatch.units`. openNURBS stores ``N + n - 1`` knots
(the first and last are implied) and homogeneous control points ``(w x, w y, w z, w)``;
files are read in a child process (:mod:`splinedeform.cad_3dm_read`,
:mod:`splinedeform.cad_child`). Needs the ``cad`` extra.
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .basis import BSplineBasis
from .cad_3dm_read import _rhino3dm, read_3dm_arrays
from .cad_child import check_cad_file, read_in_child
from .cad_units import check_units, rhino_name
from .errors import InputError, InputWarning
from .export.atomic import atomic_path
from .knots import KnotVectorBasis, RationalBasis
from .rational import clamped, product_factors
from .surface import Basis, Surface

if TYPE_CHECKING:
    from .cad_brep_3dm import BrepTopology
    from .trim.loops import TrimDomain

#: relative tolerance for weights to count as a product ``a_i b_j`` (or as all equal)
WEIGHT_TOL = 1e-12
#: distance (relative to the net's size) under which a seam's two rows of points coincide
SEAM_TOL = 1e-9


@dataclass(frozen=True)
class NurbsPatch:
    """A rational tensor-product B-spline surface (see the module docstring)."""

    degrees: tuple[int, int]
    knots_u: NDArray[np.float64]
    knots_v: NDArray[np.float64]
    points: NDArray[np.float64]
    weights: NDArray[np.float64]
    #: length unit of ``points`` (a key of :data:`splinedeform.cad_units.UNITS`), None: unknown
    units: str | None = None
    #: whether its Brep marks the face reversed (outward normal ``-(S_u × S_v)``)
    reversed: bool = False

    def __post_init__(self) -> None:
        check_units(self.units, "NURBS patch units")
        bu = KnotVectorBasis(self.degrees[0], self.knots_u)
        bv = KnotVectorBasis(self.degrees[1], self.knots_v)
        shape = (bu.size, bv.size)
        if np.shape(self.points) != shape + (3,) or np.shape(self.weights) != shape:
            raise InputError(f"a NURBS patch with these knots needs {shape} control points "
                             f"(x, y, z) and weights, got points {np.shape(self.points)} and "
                             f"weights {np.shape(self.weights)}")
        if np.any(np.asarray(self.weights) <= 0):
            raise InputError("NURBS weights must be > 0")

    def __repr__(self) -> str:
        """One line: net size, degrees, knot counts, domain, weights (never the arrays)."""
        shape = np.shape(self.weights)
        spans = []
        for n, knots in zip(self.degrees, (self.knots_u, self.knots_v)):
            t = np.asarray(knots, dtype=float).ravel()
            spans.append(f"[{t[n]:.6g}, {t[t.size - n - 1]:.6g}]")
        w = np.asarray(self.weights, dtype=float)
        rational = "equal weights" if np.ptp(w) <= WEIGHT_TOL * np.abs(w).max() else "rational"
        return (f"NurbsPatch({shape[0]}×{shape[1]} control points, degree={tuple(self.degrees)}, "
                f"knots=(knot vector of {np.size(self.knots_u)}, knot vector of "
                f"{np.size(self.knots_v)}), domain={spans[0]} × {spans[1]}, {rational})")

    def evaluate(self, u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
        """``S(u_a, v_b)`` on the grid ``u × v``, shape ``(len(u), len(v), 3)``."""
        Bu = KnotVectorBasis(self.degrees[0], self.knots_u)(u)
        Bv = KnotVectorBasis(self.degrees[1], self.knots_v)(v)
        w = np.asarray(self.weights)
        num = np.einsum("ai,ij,ijk,bj->abk", Bu, w, self.points, Bv)
        return num / (Bu @ w @ Bv.T)[..., None]


def refine(patch: NurbsPatch, splits: int) -> NurbsPatch:
    """The same surface with every knot span split into ``splits`` equal spans.

    Knot insertion in homogeneous coordinates ``(w P, w)``: the coarse B-splines lie in
    the span of the fine ones, ``N_coarse = N_fine S``, and ``S`` is found by collocation
    at the fine Greville points (exact up to round-off; Schoenberg–Whitney holds there).
    The new weights stay a product ``a_i b_j`` when the old ones were.
    """
    if isinstance(splits, bool) or not isinstance(splits, (int, np.integer)) or splits < 1:
        raise InputError(f"splits must be an integer >= 1, got {splits!r}")
    maps = []
    for n, knots in zip(patch.degrees, (patch.knots_u, patch.knots_v)):
        coarse = KnotVectorBasis(n, knots)
        br = coarse.breaks
        new = (br[:-1, None] + np.diff(br)[:, None] * np.arange(1, splits) / splits).ravel()
        fine = KnotVectorBasis(n, np.sort(np.concatenate([coarse.knots, new])))
        g = fine.greville()
        maps.append((fine, np.linalg.solve(fine(g), coarse(g))))
    (fu, Su), (fv, Sv) = maps
    w = np.asarray(patch.weights, dtype=float)
    hom = np.concatenate([patch.points * w[..., None], w[..., None]], axis=-1)
    hom = np.einsum("ai,ijc,bj->abc", Su, hom, Sv)
    return NurbsPatch(patch.degrees, fu.knots, fv.knots, hom[..., :3] / hom[..., 3:],
                      hom[..., 3], patch.units, patch.reversed)


def surface_from_patch(patch: NurbsPatch, name: str = "cad surface",
                       source: str = "NURBS patch") -> Surface:
    """The deformable :class:`~splinedeform.surface.Surface` of a NURBS patch.

    Knots are translated so the parameter domain starts at 0 (their spacing, hence the
    parametrisation, is kept). Equal weights give polynomial :class:`KnotVectorBasis`
    directions (exact Gram matrices). Weights that are a product ``w_ij = a_i b_j``
    (surfaces of revolution, extrusions and ruled conics) give ``R_ij = R_i(u) R_j(v)``
    with ``R_i = a_i N_i / Σ a_k N_k``, and the Kronecker structure of the model survives.
    Other weights are kept per control point (:attr:`Surface.net_weights`; the rational
    basis element by element, :mod:`splinedeform.rational`).
    """
    bu = KnotVectorBasis(patch.degrees[0], patch.knots_u)
    bv = KnotVectorBasis(patch.degrees[1], patch.knots_v)
    bu, bv = bu.shifted(bu.domain[0]), bv.shifted(bv.domain[0])
    warn_open_seams(patch, source)
    w = np.asarray(patch.weights, dtype=float)
    factors = weight_factors(w)
    if factors is None:
        for direction, basis in (("u", bu), ("v", bv)):
            if not clamped(basis):
                raise InputError(f"{source}: its weights are not a product w_ij = a_i b_j "
                                 f"and its knot vector in {direction} is not clamped (end "
                                 "knots repeated degree + 1 times); general weights need "
                                 "clamped knots: re-export the surface with clamped knots")
        return Surface(np.asarray(patch.points, dtype=float), bu, bv, name=name,
                       net_weights=w, orientation=-1 if patch.reversed else 1)
    a, b = factors
    basis_u: Basis = bu if np.ptp(a) <= WEIGHT_TOL * a.max() else RationalBasis(bu, a)
    basis_v: Basis = bv if np.ptp(b) <= WEIGHT_TOL * b.max() else RationalBasis(bv, b)
    return Surface(np.asarray(patch.points, dtype=float), basis_u, basis_v, name=name,
                   orientation=-1 if patch.reversed else 1)


def warn_open_seams(patch: NurbsPatch, source: str = "NURBS patch") -> None:
    """Warn (once per direction) where the surface is closed but its seam is not joined.

    The surface is closed in ``u`` when its first and last rows of control points
    coincide, ``P_0j = P_{N-1,j}`` within :data:`SEAM_TOL` of the net's size (a row that
    is one point, a pole, does not count). Read from a file, the two rows are separate
    unknowns: nothing keeps the seam closed, and its two sides move apart under load.
    """
    P = np.asarray(patch.points, dtype=float)
    size = max(float(np.ptp(P.reshape(-1, 3), axis=0).max()), 1e-300)
    for axis, name in ((0, "u"), (1, "v")):
        first, last = np.take(P, 0, axis=axis), np.take(P, -1, axis=axis)
        if (np.linalg.norm(first - last, axis=-1).max() <= SEAM_TOL * size
                and np.ptp(first, axis=0).max() > SEAM_TOL * size):
            warnings.warn(f"{source} is closed in {name} (its first and last control points "
                          f"in {name} coincide) but the seam is not joined: its two sides "
                          "are separate unknowns and move apart under load", InputWarning,
                          stacklevel=3)


def weight_factors(w: NDArray[np.float64]
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """Factors ``a, b`` with ``w = a bᵀ`` within :data:`WEIGHT_TOL` (one ``b_j`` is 1), or
    None for general weights (:func:`splinedeform.rational.product_factors`)."""
    return product_factors(w, WEIGHT_TOL)


def patch_from_surface(surface: Surface, control_points: NDArray[np.float64] | None = None
                       ) -> NurbsPatch:
    """The NURBS patch of ``surface`` (or of another net ``control_points`` on its bases).

    Open, uniform and general knot vectors are written as they are (Höllig's uniform
    layout is an unclamped knot vector); a periodic direction is unwrapped into the
    uniform layout on the same cells with its first ``n`` control points repeated at
    the end. Weights are the surface's :attr:`~Surface.weights` (general ones as they are,
    ``a_i b_j`` from rational directions, 1 elsewhere), unwrapped like the points.
    """
    P = surface.control_points if control_points is None else np.asarray(control_points, float)
    w = surface.weights
    knots = []
    for axis, basis in enumerate((surface.basis_u, surface.basis_v)):
        if isinstance(basis, BSplineBasis) and basis.periodic:
            n, m = basis.degree, basis.cells
            P = np.take(P, np.mod(np.arange(m + n) - n, m), axis=axis)
            w = np.take(w, np.mod(np.arange(m + n) - n, m), axis=axis)
            basis = BSplineBasis(n, m, basis.length, "uniform")
        knots.append(np.asarray(basis.knots, dtype=float))
    return NurbsPatch((surface.basis_u.degree, surface.basis_v.degree), knots[0], knots[1],
                      P, np.array(w))


#: CAD file suffixes and what reads them
CAD_SUFFIXES = {".3dm": "openNURBS", ".igs": "IGES", ".iges": "IGES", ".stp": "STEP",
                ".step": "STEP"}


def cad_kind(path: Path) -> str:
    """The format of a CAD file by its suffix (a value of :data:`CAD_SUFFIXES`); an
    ``InputError`` for any other suffix."""
    kind = CAD_SUFFIXES.get(path.suffix.lower())
    if kind is None:
        raise InputError(f"{path}: not a CAD file (expected one of "
                         f"{', '.join(CAD_SUFFIXES)}), got suffix {path.suffix or 'none'!r}")
    return kind


def read_cad(path: str | os.PathLike, face: int = 0) -> NurbsPatch:
    """Surface number ``face`` of a CAD file, chosen by its suffix (see :data:`CAD_SUFFIXES`)."""
    path = Path(path)
    kind = cad_kind(path)
    if kind == "openNURBS":
        return read_3dm(path, face)
    from .cad_step import read_step   # STEP and IGES: OpenCASCADE, the 'cad-step' extra

    return read_step(path, face)


def write_3dm(path: str | os.PathLike, patches: list[NurbsPatch],
              names: list[str] | None = None, units: str | None = None,
              trims: list[TrimDomain | None] | None = None,
              body: BrepTopology | None = None) -> Path:
    """Write ``patches`` as NURBS surfaces to a ``.3dm`` file (atomically); return its path.

    ``names`` label the objects (openNURBS object names), one per patch. ``units`` (a key
    of :data:`splinedeform.cad_units.UNITS`; default: the first patch's) is the file's
    ``ModelUnitSystem``; ``None`` when not known (openNURBS ``UnitSystem.None``).
    A patch with a trim (``trims``: one per patch, None for an untrimmed one) is a
    one-face Brep with those loops (:mod:`splinedeform.cad_brep_trims`); where openNURBS
    refuses it, its surface with the loops beside it as curves in its ``(u, v)``
    (:func:`splinedeform.cad_trims_3dm.add_trim_curves`), and a warning.

    With ``body`` (the patches' topology) the patches are one Brep object instead, its
    edges joined where the faces meet (:func:`splinedeform.cad_brep_3dm.body_brep`),
    named ``body.name`` with each face's name as the user string ``splinedeform.face k``;
    where the Brep cannot be formed, a one-line warning says why and the patches are
    written one surface each as without ``body``.
    """
    r3 = _rhino3dm()
    path = Path(path)
    if names is not None and len(names) != len(patches):
        raise InputError(f"{len(names)} object names for {len(patches)} surfaces")
    if trims is not None and len(trims) != len(patches):
        raise InputError(f"{len(trims)} trims for {len(patches)} surfaces")
    if units is None and patches:
        units = patches[0].units
    model = r3.File3dm()
    model.Settings.ModelUnitSystem = getattr(r3.UnitSystem, rhino_name(units))
    if body is not None and add_body_brep(model, r3, patches, names, trims, body):
        patches = []
    for index, patch in enumerate(patches):
        (nu, nv), w = patch.degrees, np.asarray(patch.weights)
        cu, cv = w.shape
        srf = r3.NurbsSurface.Create(3, True, nu + 1, nv + 1, cu, cv)
        for i, k in enumerate(np.asarray(patch.knots_u)[1:-1]):
            srf.KnotsU[i] = float(k)
        for i, k in enumerate(np.asarray(patch.knots_v)[1:-1]):
            srf.KnotsV[i] = float(k)
        hom = np.concatenate([patch.points * w[..., None], w[..., None]], axis=-1)
        for i, j in np.ndindex(cu, cv):  # rhino3dm sets control points one at a time
            srf.Points[i, j] = r3.Point4d(*map(float, hom[i, j]))
        attributes = r3.ObjectAttributes()
        if names is not None:
            attributes.Name = names[index]
        trim = trims[index] if trims is not None else None
        if trim is not None and _add_trimmed_face(model, r3, patch, trim, attributes):
            continue
        model.Objects.AddSurface(srf, attributes)
        if trim is not None:
            from .cad_trims_3dm import add_trim_curves

            add_trim_curves(model, r3, trim, len(model.Objects) - 1,
                            names[index] if names is not None else f"surface {index}")
    with atomic_path(path) as tmp:
        if not model.Write(str(tmp), 7):
            raise InputError(f"{path}: openNURBS could not write the file")
    return path


def add_body_brep(model: Any, r3: Any, patches: list[NurbsPatch], names: list[str] | None,
                  trims: list[TrimDomain | None] | None, body: BrepTopology) -> bool:
    """Add ``patches`` to ``model`` as the one Brep of ``body`` (see :func:`write_3dm`);
    False, with a one-line warning naming the reason, where it cannot be formed."""
    from .cad_brep_3dm import BrepError, body_brep

    try:
        brep = body_brep(patches, body, r3, trims)
    except BrepError as exc:
        warnings.warn(f"the body is written as {len(patches)} separate surfaces, not one "
                      f"Brep: {exc}", InputWarning, stacklevel=3)
        return False
    attributes = r3.ObjectAttributes()
    attributes.Name = body.name
    for k, name in enumerate(names or []):
        attributes.SetUserString(f"{FACE_NAME}{k}", name)
    model.Objects.AddBrep(brep, attributes)
    return True


def _add_trimmed_face(model: Any, r3: Any, patch: NurbsPatch, trim: TrimDomain,
                      attributes: Any) -> bool:
    """Add ``patch`` trimmed by ``trim`` to ``model`` as a one-face Brep; False, with a
    one-line warning naming the reason, where openNURBS refuses it."""
    from .cad_brep_3dm import BrepError, BrepTopology, body_brep

    try:
        brep = body_brep([patch], BrepTopology(()), r3, [trim])
    except BrepError as exc:
        warnings.warn(f"{attributes.Name or 'a trimmed surface'} is written with its trim "
                      f"loops as curves beside it, not as a trimmed Brep face: {exc}",
                      InputWarning, stacklevel=3)
        return False
    model.Objects.AddBrep(brep, attributes)
    return True


#: user-string key (followed by the face number) of a Brep face's name
FACE_NAME = "splinedeform.face "


def frame_patches(surface: Surface, times: NDArray[np.float64], nets: NDArray[np.float64],
                  label: str = "t") -> tuple[list[NurbsPatch], list[str]]:
    """The initial surface and every frame as NURBS patches, with their names.

    Patch 0, named ``initial``, is ``surface``; patch ``k + 1``, named
    ``frame k: <label> = <times[k]>``, has the net ``nets[k]`` on the same degrees, knots
    and weights (see :func:`patch_from_surface`).
    """
    nets = np.asarray(nets, dtype=float)
    times = np.asarray(times, dtype=float).ravel()
    if nets.ndim != 4 or nets.shape[0] != times.size or nets.shape[1:] != surface.shape + (3,):
        raise InputError(f"frames must be {times.size} nets of shape {surface.shape + (3,)}, "
                         f"got {nets.shape}")
    patches = [patch_from_surface(surface)] + [patch_from_surface(surface, P) for P in nets]
    names = ["initial"] + [f"frame {k}: {label} = {t:.9g}" for k, t in enumerate(times)]
    return patches, names


def write_frames_3dm(path: str | os.PathLike, surface: Surface, times: NDArray[np.float64],
                     nets: NDArray[np.float64], label: str = "t",
                     units: str | None = None, trim: TrimDomain | None = None) -> Path:
    """The initial surface and every frame as named NURBS surfaces in one ``.3dm`` file
    (object ``k + 1`` is frame ``k``; see :func:`frame_patches`), in ``units`` (see
    :func:`write_3dm`), each with the trim loops ``trim`` when given. Written atomically."""
    patches, names = frame_patches(surface, times, nets, label)
    return write_3dm(path, patches, names, units=units,
                     trims=None if trim is None else [trim] * len(patches))


def read_3dm(path: str | os.PathLike, face: int = 0) -> NurbsPatch:
    """Surface number ``face`` of a ``.3dm`` file (surfaces and Brep faces, in file order),
    in the file's ``ModelUnitSystem`` (:attr:`NurbsPatch.units`; None if not one of ours).

    Read in a child process (:func:`splinedeform.cad_child.read_in_child`): a file that
    crashes openNURBS is an ``InputError`` naming the file. A Brep face is read as its
    underlying surface; a face that is really trimmed (its outer loop is not the
    surface's own boundary, or it has inner loops) is warned about, once.
    """
    path = Path(path)
    check_cad_file(path)
    _rhino3dm()
    if isinstance(face, bool) or not isinstance(face, int) or face < 0:
        raise InputError(f"{path}: face {face!r} out of range; faces are numbered from 0")
    data = read_in_child(read_3dm_arrays, path, face, library="openNURBS (rhino3dm)")
    return NurbsPatch(tuple(data["degrees"]), data["knots_u"], data["knots_v"],
                      data["points"], data["weights"], units=data["units"],
                      reversed=bool(data.get("reversed", False)))
