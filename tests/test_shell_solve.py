"""The shell's static solve in nested dissection order against the bordered system.

Reference: ``[[K, M R], [(M R)ᵀ, 0]] [d; λ] = [F; 0]`` factored by SuperLU with its own
column ordering and pivoting, an independent route to the same ``d``.
"""

from math import pi

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import splinedeform as sd
from splinedeform.physics.shell import ShellMaterial
from splinedeform.physics.shell_model import ShellModel
from splinedeform.physics.shell_solve import dissection_ranks


def bordered(model, F):
    C = model._M @ model.rigid
    A = sp.bmat([[model._K, sp.csr_matrix(C)], [sp.csr_matrix(C.T), None]], format="csc")
    return spla.splu(A).solve(np.concatenate([F, np.zeros(C.shape[1])]))[: model.n_free]


@pytest.mark.parametrize("case", ["pinched", "free", "plate"])
def test_static_solve_equals_the_bordered_system(case):
    if case == "pinched":      # diaphragm ends: one free rigid motion (along the axis)
        surface = sd.shapes.cylinder(radius=3.0, height=6.0, cells=(12, 6))
        model = ShellModel(surface, ShellMaterial(3e6, 0.3, 0.03),
                           {"v0": "diaphragm", "v1": "diaphragm"})
        load = (sd.loads.Point(0.0, 3.0, (-1.0, 0, 0))
                + sd.loads.Point(pi * 3.0, 3.0, (1.0, 0, 0)))
    elif case == "free":       # all six rigid motions free, a self-equilibrated pressure
        surface = sd.shapes.cylinder(radius=1.0, height=2.0, cells=(10, 4))
        model, load = ShellModel(surface, ShellMaterial(1e4, 0.3, 0.05)), sd.loads.Pressure(1.0)
    else:                      # clamped: no rigid motion
        model = ShellModel(sd.shapes.plane(cells=6), ShellMaterial(1e4, 0.3, 0.01),
                           {e: "clamped" for e in ("u0", "u1", "v0", "v1")})
        load = sd.loads.Point(0.3, 0.6, (0.0, 0.0, 1.0))
    d = model.static(load).d_free
    F = model.load_vector(load)
    reference = bordered(model, F)
    # two factorisations of systems with condition numbers up to ~1e9 (the thin pinched
    # cylinder): measured agreement 1e-13 .. 4e-11 relative
    assert np.abs(d - reference).max() <= 1e-8 * np.abs(reference).max()
    assert np.abs(model.rigid.T @ (model._M @ d)).max(initial=0.0) <= 1e-10 * np.abs(d).max()


@pytest.mark.parametrize("n_u, n_v, periodic",
                         [(7, 5, False), (40, 9, True), (13, 30, False), (31, 12, False)])
def test_dissection_order_is_a_permutation_with_separators_last(n_u, n_v, periodic):
    rank = dissection_ranks(n_u, n_v, (3, 3), periodic).reshape(n_u, n_v)
    # integer ranks: a permutation of 0 … n − 1, compared exactly (no rounding involved)
    assert np.array_equal(np.sort(rank.ravel()), np.arange(n_u * n_v))
    if periodic:               # the two cuts that open the ring come last
        cuts = np.r_[0:3, n_u // 2:n_u // 2 + 3]
        assert rank[cuts].min() == n_u * n_v - cuts.size * n_v
    elif n_u * n_v > 48:       # the first separator (3 middle lines of the longer side)
        if n_u >= n_v:
            assert rank[n_u // 2:n_u // 2 + 3].min() == n_u * n_v - 3 * n_v
        else:
            assert rank[:, n_v // 2:n_v // 2 + 3].min() == n_u * n_v - 3 * n_u
