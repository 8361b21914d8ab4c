"""A few times asked at the call: the modes come from a Krylov space started from the load.

``Model.dynamic(load, t_end, times=[t])`` on a model with no Krylov space yet starts the
block Lanczos from the load's static response ``K⁻¹F`` (solvers/sparse_eigen.py ``start``):
only the modes the load excites are computed. References: dense ``eigh`` of the same
matrices and the all-modes solution (both exact to round-off, far below the tolerances).
"""

import numpy as np
import pytest
import scipy.linalg as sla

import splinedeform as sd
from splinedeform import modal_solve
from splinedeform.solvers.sparse_eigen import BlockLanczos

PLATE = sd.Material(mass=1.0, damping=0.8, rayleigh=5e-4, w10=10.0, w01=10.0, w20=1.0,
                    w11=1.0, w02=1.0)


@pytest.fixture(autouse=True)
def sparse_path_on_small_nets(monkeypatch):
    """These nets (289 to 361 free coordinates) are below the size where the automatic mode
    count starts its sparse path; lowered, they exercise it."""
    monkeypatch.setattr(modal_solve, "DENSE_BELOW", 256)


def _model(cells=20):
    return sd.Model(sd.shapes.plane(cells=(cells, cells)), PLATE, boundary="clamped")


def _force(model, u, v):
    """The reduced force of a unit normal point force at ``(u, v)`` (one coordinate)."""
    E = model.surface.evaluation_matrix(np.array([u]), np.array([v]))
    return np.asarray((model.T.T @ E.T).todense()).ravel()


def test_a_load_started_space_finds_the_lowest_modes_the_load_excites():
    """An off-centre force excites every mode: the 12 lowest eigenvalues equal dense eigh's
    to 1e-10 relative (converged Ritz pairs: residual 1e-10, eigenvalue error ≤ r²/gap),
    with a block of width 1. A force at the centre of the clamped square excites, in exact
    arithmetic, only the modes symmetric in both directions; every pair its space finds is
    an eigenpair of the dense spectrum to the same 1e-10 (rounding may bring in others,
    never a spurious value)."""
    from splinedeform.solvers.sparse_eigen import factorise
    model = _model(16)
    M, _, K = model.matrices()
    exact = sla.eigh(K.toarray(), M.toarray(), eigvals_only=True)
    lu = factorise(K)
    space = BlockLanczos(K, M, lu, start=lu.solve(_force(model, 0.4, 0.3)[:, None]))
    assert space.b == 1
    found = space.lowest(11)
    assert np.allclose(found.lam, exact[:12], rtol=1e-10, atol=0)
    centre = BlockLanczos(K, M, lu, start=lu.solve(_force(model, 0.5, 0.5)[:, None]))
    pairs = centre.lowest(5)
    nearest = np.min(np.abs(pairs.lam[:, None] - exact[None, :]), axis=1) / pairs.lam
    assert nearest.max() <= 1e-10
    assert abs(pairs.lam[0] - exact[0]) <= 1e-10 * exact[0]


def test_a_zero_starting_block_is_refused():
    """A load with no static response cannot start a space: a clear error, not NaNs."""
    model = _model(16)
    M, _, K = model.matrices()
    with pytest.raises(ValueError, match="starting block"):
        BlockLanczos(K, M, start=np.zeros((K.shape[0], 1)))


@pytest.mark.parametrize("where", [(0.4, 0.3), (0.5, 0.5)])
def test_one_state_from_a_load_started_space_meets_the_default_tolerance(where):
    """The default call with one time asked: within DEFAULT_TOLERANCE of all modes in the
    bound's measure (largest control-point coordinate over the largest static
    displacement), with the modes of the load's space (not kept on the model)."""
    load = sd.Point(*where, (0, 0, -1), profile=sd.Step(0.0, 2.0))
    model = _model()
    t = np.array([1.3])
    one = model.dynamic(load, 4.0, times=t)
    assert one.basis.kind == "sparse" and not one.basis.complete
    assert model not in modal_solve._KRYLOV and not model._bases
    full = _model().dynamic(load, 4.0, modes="all")
    rest = model.surface.control_points
    scale = np.abs(model.static(load, t=1.0).control_points() - rest).max()
    error = np.abs(one.control_points(t) - full.control_points(t)).max() / scale
    assert one.truncation["bound"] <= modal_solve.DEFAULT_TOLERANCE
    assert error <= modal_solve.DEFAULT_TOLERANCE


def test_a_load_started_space_does_not_serve_another_load():
    """After one state of a centre force (only doubly symmetric modes found), a force off
    the centre on the same model gets its own modes: the same answer as on a fresh model,
    to 1e-9 of its static scale (two converged eigen-solutions, residuals 1e-10), both
    with modes=12 (taken from the model's basis, which the first call left untouched) and
    with one time asked."""
    centre = sd.Point(0.5, 0.5, (0, 0, -1), profile=sd.Step(0.0, 2.0))
    off = sd.Point(0.3, 0.6, (0, 0, -1), profile=sd.Step(0.0, 2.0))
    model = _model()
    t = np.array([1.3])
    model.dynamic(centre, 4.0, times=t)
    rest = model.surface.control_points
    for options in ({"modes": 12}, {"times": t}):
        again = model.dynamic(off, 4.0, **options).control_points(t)
        fresh = _model().dynamic(off, 4.0, **options).control_points(t)
        assert np.abs(again - fresh).max() <= 1e-9 * np.abs(fresh - rest).max()
