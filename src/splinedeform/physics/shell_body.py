"""The Kirchhoff–Love shell on a body of patches: matrices and constraint map.

The unknowns are all patches' control point displacements, patch after patch (row-major
in each), interleaved (dof ``3k + c``). Per patch the shell's own matrices, so that

.. math:: K = \\operatorname{diag}(K_1, …, K_P) + K_\\text{coupling}, \\qquad
          M = \\operatorname{diag}(M_1, …, M_P),

where ``K_coupling`` is the rotation penalty across every interface and C0 line, and
across a non-conforming interface also the displacement penalty
(:mod:`.coupling_model`, factors from the material and the mesh). The constraint map
``d = T d_free`` is ``T = T_b S``: ``T_b = diag(T_p)`` the edge conditions of each patch
(:func:`.shell_edges.constraint_matrix`: the body's kinds on boundary edges, free on
interface edges), and ``S`` merges the columns of ``T_b`` that a conforming interface
identifies. A merged pair of dofs ``(r_a, r_b)`` (the same component of the ``k``-th control
points of the two edges) asks ``d_{r_a} = d_{r_b}``: where both rows of ``T_b`` are unit rows
``e_{j_a}``, ``e_{j_b}`` this is ``x_{j_a} = x_{j_b}`` (the columns are joined into one
class, the classes being the connected components of that graph); where one row is zero
(the component is held) the other's column is held too. So merged control points share all
three displacements exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray
from scipy.sparse.csgraph import connected_components

from ..body.body import Body
from ..body.constraints import boundary_presets, edge_rows
from ..body.interface import EDGES
from ..body.model import BodyReduction
from ..body.model import _refuse as refuse
from ..errors import InputError
from ..surface import Surface
from .coupling_model import c0_coupling, interface_coupling
from .shell import ShellMaterial, matrices
from .shell_edges import KINDS, check_edges, constraint_matrix

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
    """

    K: sp.csr_matrix
    M: sp.csr_matrix
    T: sp.csr_matrix
    edges: dict[tuple[int, str], str]
    offsets: NDArray[np.int64]


def body_system(body: Body | Sequence[Surface], material: ShellMaterial,
                boundary: str | Mapping[tuple[int, str], str] = "free") -> ShellBodySystem:
    """Assemble the shell body of the module docstring.

    Parameters
    ----------
    body : Body or list of Surface
        A list is made a body with its interfaces found geometrically.
    boundary : str or mapping
        One kind of :data:`BODY_KINDS` for every boundary edge, or ``{(patch, edge): kind}``
        (missing boundary edges are free).
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
    Tb = sp.block_diag([constraint_matrix(s, e) for s, e in zip(patches, own)], format="csr")
    blocks = [matrices(s, material) for s in patches]
    K = sp.block_diag([k for k, _ in blocks], format="csr")
    M = sp.block_diag([m for _, m in blocks], format="csr")
    size = int(offsets[-1])
    couplings = [interface_coupling(patches, topology.interfaces, material, presets,
                                    offsets[:-1])]
    couplings += [c0_coupling(s, material, e, int(offsets[p]), size)
                  for p, (s, e) in enumerate(zip(patches, own))]
    for penalty in (c for c in couplings if c is not None):
        K = (K + penalty).tocsr()
    pairs = [np.zeros((0, 2), dtype=np.int64)]
    for i in (i for i in topology.interfaces if i.conforming):
        ra = offsets[i.a] + edge_rows(patches[i.a], i.edge_a)
        rb = offsets[i.b] + edge_rows(patches[i.b], i.edge_b)
        points = np.stack([ra, rb[::-1] if i.reversed else rb], axis=1)
        pairs.append((3 * points[:, None, :] + np.arange(3)[None, :, None]).reshape(-1, 2))
    T = (Tb @ merge_columns(Tb, np.concatenate(pairs))).tocsr()
    if T.shape[1] == 0:
        raise InputError("no free displacement: the boundary holds every control point of "
                         f"the {len(patches)} patches")
    return ShellBodySystem(K, M, T, presets, offsets)


def merge_columns(Tb: sp.csr_matrix, pairs: NDArray[np.int64]) -> sp.csr_matrix:
    """``S`` (columns of ``Tb`` → classes) with ``(Tb S)[r_a] = (Tb S)[r_b]`` for each pair.

    A pair of unit rows joins their columns; a zero row holds the other's column (its class
    is dropped). A pair whose two rows are already equal asks nothing (the two control
    points of one pole, where a seam meets it, move as that one point). A row of ``Tb``
    that combines several columns otherwise cannot be merged: refused.
    """
    n = Tb.shape[1]
    apart = abs(Tb[pairs[:, 0]] - Tb[pairs[:, 1]]).max(axis=1).toarray().ravel()
    pairs = pairs[apart > 1e-14]             # T_b's entries are 0, 1 or O(1) null vectors
    count = Tb.getnnz(axis=1)
    first = np.zeros(Tb.shape[0], dtype=np.int64)
    first[count > 0] = Tb.indices[Tb.indptr[:-1][count > 0]]
    value = np.zeros(Tb.shape[0])
    value[count > 0] = Tb.data[Tb.indptr[:-1][count > 0]]
    unit = (count == 1) & np.isclose(value, 1.0, rtol=0, atol=1e-14)
    zero = count == 0
    bad = ~(unit | zero)[pairs].all(axis=1)
    if np.any(bad):
        point = int(pairs[np.flatnonzero(bad)[0], 0]) // 3
        raise InputError(f"control point {point} of the body lies on a conforming interface "
                         "but its edge condition couples it to other control points "
                         "(uniform knots, a plane not along an axis): use open knots and "
                         "axis-aligned conditions at edges that meet")
    both = unit[pairs].all(axis=1)
    links = first[pairs[both]]
    graph = sp.coo_matrix((np.ones(len(links)), (links[:, 0], links[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    held = np.zeros(label.max() + 1, dtype=bool)
    beside_held = np.concatenate([pairs[zero[pairs[:, 0]] & unit[pairs[:, 1]], 1],
                                  pairs[unit[pairs[:, 0]] & zero[pairs[:, 1]], 0]])
    held[label[first[beside_held]]] = True
    keep = ~held[label]
    _, new = np.unique(label[keep], return_inverse=True)
    return sp.csr_matrix((np.ones(new.size), (np.flatnonzero(keep), new)),
                         shape=(n, int(new.max(initial=-1)) + 1))


def body_field(patches: Sequence[Surface], term: object, t: float = 0.0) -> Array:
    """One load term's force on every patch, patch after patch, interleaved ``(3N,)``
    (:class:`~splinedeform.body.model.BodyReduction`: :class:`~splinedeform.body.OnPatch`
    terms act on their patch only)."""
    return np.asarray(BodyReduction(None, patches).field(term, t)).ravel()


def patch_index(count: int, patch: int | None) -> int:
    """``patch`` checked as an index of ``count`` patches (a read-out on a body names one)."""
    if isinstance(patch, bool) or not isinstance(patch, (int, np.integer)) \
            or not 0 <= patch < count:
        raise InputError(f"a shell body's read-out needs its patch: an index in "
                         f"[0, {count - 1}], got {patch!r}")
    return int(patch)


def free_coordinates(T: sp.spmatrix, shapes: Sequence[tuple[int, int]],
                     nets: Sequence[object], names: Sequence[str]) -> Array:
    """``d_free`` with ``T d_free`` the given displacement nets (one per patch), by least
    squares ``Tᵀ T d_free = Tᵀ d``; refused where ``d`` is not in ``range T``."""
    rows = []
    for net, shape, name in zip(nets, shapes, names):
        arr = np.asarray(net, dtype=float)
        if arr.shape != tuple(shape) + (3,):
            raise InputError(f"{name} must have shape (n_u, n_v, 3) = {tuple(shape) + (3,)}, "
                             f"got {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise InputError(f"{name} must be finite")
        rows.append(arr.ravel())
    flat = np.concatenate(rows)
    free = spla.spsolve((T.T @ T).tocsc(), T.T @ flat)
    if np.linalg.norm(T @ free - flat) > 1e-9 * max(np.linalg.norm(flat), 1e-300):
        raise InputError(f"{names[0].split('[')[0]} moves displacement components that the "
                         "boundary conditions fix or tie")
    return np.asarray(free)
