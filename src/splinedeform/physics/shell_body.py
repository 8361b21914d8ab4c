"""The Kirchhoff–Love shell on a body of patches: matrices and constraint map.

The unknowns are all patches' control point displacements, patch after patch (row-major
in each), interleaved (dof ``3k + c``). Per patch the shell's own matrices, so that

.. math:: K = \\operatorname{diag}(K_1, …, K_P) + K_\\text{coupling}, \\qquad
          M = \\operatorname{diag}(M_1, …, M_P),

where ``K_coupling`` is the rotation penalty across every interface and C0 line that is
not tied, and across a non-conforming interface and along each stretch two iso-edges
share (a T-junction, :func:`~splinedeform.body.trim_edges.edge_penalty`) also the
displacement penalty (:mod:`.coupling_model`, factors from the material and the mesh).
The constraint map ``d = T d_free`` is ``T = T_b S``: ``T_b = diag(T_p)`` the edge conditions of each patch
(:func:`.shell_edges.constraint_matrix`: the body's kinds on boundary edges, free on
interface edges), and ``S`` merges the columns of ``T_b`` that a conforming interface
identifies. A merged pair of dofs ``(r_a, r_b)`` (the same component of the ``k``-th control
points of the two edges) asks ``d_{r_a} = d_{r_b}``: where both rows of ``T_b`` are unit rows
``e_{j_a}``, ``e_{j_b}`` this is ``x_{j_a} = x_{j_b}`` (the columns are joined into one
class, the classes being the connected components of that graph); where one row is zero
(the component is held: by the edge condition, or by the patch's mask of ``fixed``
components, :func:`~splinedeform.body.constraints.body_fixed_mask`) the other's column is
held too, so a point patches share is held when any of them holds it. Where a row
combines several columns (the points of a pole, tied to one point by a null-space basis
of ``T_p``) the pair is imposed instead, ``T = T_b S N`` with ``range N = null((T_b S)[r_a] − (T_b S)[r_b])``.
So merged control points share all three displacements exactly. Last, across every
conforming interface, seam and C0 line where the rest shape is smooth, the slopes are tied
on each component, ``T ← T E`` (:func:`.coupling_ties.tie_components`), with no rotation
penalty there: the rotation is continuous exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.sparse.csgraph import connected_components

from ..body.body import Body
from ..body.constraints import boundary_presets, edge_rows
from ..body.interface import EDGES
from .plate_body import BodyReduction, refuse
from ..body.trim_edges import edge_penalty, iso_stretches
from ..errors import InputError
from ..surface import Surface
from .coupling_model import c0_coupling, interface_coupling
from .coupling_ties import Ties, smooth_ties, tie_components
from .shell import ShellMaterial, matrices
from .shell_clamp import clamp_rotation
from .shell_edges import KINDS, check_edges, constraint_matrix
from .shell_edges import _impose as impose

Array = NDArray[np.float64]
BODY_KINDS = tuple(k for k in KINDS if k != "pole")
"""Edge kinds a body's boundary edge takes (poles are found, not given)."""


@dataclass(frozen=True)
class ShellBodySystem:
    """Full ``K``, ``M`` (``3N × 3N``), the map ``T`` and the layout of a shell body.

    Attributes
    ----------
    edges : dict
        The kind of each boundary edge, keyed ``(patch, edge)``.
    offsets : ndarray of int
        First control point of each patch (``len(patches) + 1`` values).
    ties : :class:`~.coupling_ties.Ties`
        The interfaces and C0 lines whose slopes ``T`` ties exactly.
    clamps : bool
        Whether a curved patch's clamped edge has its rotation held by Nitsche's terms
        (:mod:`.shell_clamp`, in ``K``), which hold every rigid motion ``T`` leaves.
    motions : :class:`~.shell_rigid.RigidMotions` or None
        The free rigid motions where the system knows them (a body with trimmed faces,
        :mod:`.shell_body_trimmed`); None: those in ``range T``.
    """

    K: sp.csr_matrix
    M: sp.csr_matrix
    T: sp.csr_matrix
    edges: dict[tuple[int, str], str]
    offsets: NDArray[np.int64]
    ties: Ties
    clamps: bool = False
    motions: Any = None


def body_system(body: Body | Sequence[Surface], material: ShellMaterial,
                boundary: str | Mapping[tuple[int, str], str] = "free",
                given: Mapping[int, tuple[sp.spmatrix, sp.spmatrix]] | None = None,
                fixed: NDArray[np.bool_] | None = None) -> ShellBodySystem:
    """Assemble the shell body of the module docstring.

    Parameters
    ----------
    body : Body or list of Surface
        A list is made a body with its interfaces found geometrically.
    boundary : str or mapping
        One kind of :data:`BODY_KINDS` for every boundary edge, or ``{(patch, edge): kind}``
        (missing boundary edges are free).
    given : mapping, optional
        ``{patch: (K_p, M_p)}``: the matrices of those patches, taken instead of
        :func:`.shell.matrices` (a trimmed face's, :mod:`.shell_body_trimmed`).
    fixed : bool array ``(3N,)``, optional
        Held displacement components, interleaved, patch after patch
        (:func:`~splinedeform.body.constraints.body_fixed_mask` with ``components``): each
        patch's share is its ``fixed`` of :func:`.shell_edges.constraint_matrix`, so a held
        component is a zero row of ``T_b``, and :func:`merge_columns` holds its partner
        across a conforming interface too (a point shared by patches is held when any
        holds it); the pole maps and the slope ties ``E`` are imposed on that ``T_b S``.
    """
    if not isinstance(body, Body):
        body = Body(body)
    topology = body.topology
    refuse(topology)
    presets = boundary_presets(boundary, topology, BODY_KINDS)
    patches = body.patches
    sizes = np.array([s.shape[0] * s.shape[1] for s in patches])
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    own = [check_edges(s, {e: presets.get((p, e), "free") for e in EDGES})
           for p, s in enumerate(patches)]
    held = [None if fixed is None else
            fixed[3 * offsets[p]:3 * offsets[p + 1]].reshape(s.shape + (3,))
            for p, s in enumerate(patches)]
    Tb = sp.block_diag([constraint_matrix(s, e, mask, weak_rotation=True, alone=False)
                        for s, e, mask in zip(patches, own, held)], format="csr")
    given = given or {}
    blocks = [given[p] if p in given else matrices(s, material)
              for p, s in enumerate(patches)]
    clamps = [clamp_rotation(s, material, e) for s, e in zip(patches, own)]
    K = sp.block_diag([k if c is None else k + c for (k, _), c in zip(blocks, clamps)],
                      format="csr")
    M = sp.block_diag([m for _, m in blocks], format="csr")
    size = int(offsets[-1])
    ties = smooth_ties(patches, topology.interfaces, offsets)
    couplings = [interface_coupling(patches, topology.interfaces, material, presets,
                                    offsets[:-1], exact=ties.interfaces)]
    couplings += [c0_coupling(s, material, e, int(offsets[p]), size,
                              exact={(d, k) for q, d, k in ties.lines if q == p})
                  for p, (s, e) in enumerate(zip(patches, own))]
    couplings += [edge_penalty(patches, i, material, offsets[:-1], presets)
                  for i in iso_stretches(body.edge_interfaces)]
    for penalty in (c for c in couplings if c is not None):
        K = (K + penalty).tocsr()
    pairs = [np.zeros((0, 2), dtype=np.int64)]
    for i in (i for i in topology.interfaces if i.conforming):
        ra = offsets[i.a] + edge_rows(patches[i.a], i.edge_a)
        rb = offsets[i.b] + edge_rows(patches[i.b], i.edge_b)
        points = np.stack([ra, rb[::-1] if i.reversed else rb], axis=1)
        pairs.append((3 * points[:, None, :] + np.arange(3)[None, :, None]).reshape(-1, 2))
    pairs = np.concatenate(pairs)
    S, rest = merge_columns(Tb, pairs)
    T = (Tb @ S).tocsr()
    if len(rest):                     # rows combining columns (poles): d_ra = d_rb imposed
        T = impose(T, T[rest[:, 0]] - T[rest[:, 1]])
    T = tie_components(T, ties.C)
    if T.shape[1] == 0:
        raise InputError("no free displacement: the boundary and the fixed components hold "
                         f"every control point of the {len(patches)} patches")
    return ShellBodySystem(K, M, T, presets, offsets, ties,
                           any(c is not None for c in clamps))


def merge_columns(Tb: sp.csr_matrix, pairs: NDArray[np.int64]
                  ) -> tuple[sp.csr_matrix, NDArray[np.int64]]:
    """``S`` (columns of ``Tb`` → classes) with ``(Tb S)[r_a] = (Tb S)[r_b]`` for each pair
    of unit or zero rows, and the other pairs.

    A pair of unit rows joins their columns; a zero row holds the other's column (its class
    is dropped). A row of ``Tb`` that combines several columns (a pole's points, tied to
    one point by a null-space basis; a plane not along an axis) cannot be merged: its pairs
    are returned, for ``(Tb S)[r_a] − (Tb S)[r_b] = 0`` to be imposed on the reduced
    coordinates (:func:`.shell_edges._impose`; a pair of equal rows, the two ends of a
    seam at a pole, asks nothing).
    """
    n = Tb.shape[1]
    count = Tb.getnnz(axis=1)
    first = np.zeros(Tb.shape[0], dtype=np.int64)
    first[count > 0] = Tb.indices[Tb.indptr[:-1][count > 0]]
    value = np.zeros(Tb.shape[0])
    value[count > 0] = Tb.data[Tb.indptr[:-1][count > 0]]
    unit = (count == 1) & np.isclose(value, 1.0, rtol=0, atol=1e-14)
    zero = count == 0
    bad = ~(unit | zero)[pairs].all(axis=1)
    rest, pairs = pairs[bad], pairs[~bad]
    if len(rest):                     # equal rows up to round-off: nothing to impose
        apart = abs(Tb[rest[:, 0]] - Tb[rest[:, 1]]).max(axis=1).toarray().ravel()
        rest = rest[apart > 1e-12]    # entries of Tb are O(1): 0, 1 or null vectors
    both = unit[pairs].all(axis=1)
    links = first[pairs[both]]
    graph = sp.coo_matrix((np.ones(len(links)), (links[:, 0], links[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    held = np.zeros(label.max(initial=-1) + 1, dtype=bool)
    beside_held = np.concatenate([pairs[zero[pairs[:, 0]] & unit[pairs[:, 1]], 1],
                                  pairs[unit[pairs[:, 0]] & zero[pairs[:, 1]], 0]])
    held[label[first[beside_held]]] = True
    keep = ~held[label]
    _, new = np.unique(label[keep], return_inverse=True)
    return sp.csr_matrix((np.ones(new.size), (np.flatnonzero(keep), new)),
                         shape=(n, int(new.max(initial=-1)) + 1)), rest


def body_field(patches: Sequence[Surface], term: object, t: float = 0.0,
               signs: tuple[int, ...] = ()) -> Array:
    """One load term's force on every patch, patch after patch, interleaved ``(3N,)``
    (:class:`~splinedeform.physics.plate_body.BodyReduction`: :class:`~splinedeform.body.OnPatch`
    terms act on their patch only, a pressure along ``signs[p] x_u × x_v``)."""
    return np.asarray(BodyReduction(None, patches, None, tuple(signs)).field(term, t)).ravel()


def patch_index(count: int, patch: int | None) -> int:
    """``patch`` checked as an index of ``count`` patches (a read-out on a body names one)."""
    if isinstance(patch, bool) or not isinstance(patch, (int, np.integer)) \
            or not 0 <= patch < count:
        raise InputError(f"a shell body's read-out needs its patch: an index in "
                         f"[0, {count - 1}], got {patch!r}")
    return int(patch)

