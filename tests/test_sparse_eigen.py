"""Block shift-invert Lanczos against dense ``eigh`` on small nets.

Reference: ``scipy.linalg.eigh(K, M)`` of the same reduced matrices (LAPACK, all modes).
Tolerances: an accepted Ritz pair has a relative residual ``r ≤ 1e-10``, so its eigenvalue
is within ``r²/gap`` and ``r`` of the true one; dense ``eigh`` itself is accurate to about
``ε κ(K) ≈ 1e-16 · 1e6`` relative on these nets. 1e-9 relative covers both with room.
"""

import numpy as np
import pytest
import scipy.linalg as sla

import splinedeform as sd
from splinedeform.solvers import block_cholesky, sparse_eigen

PLATE = sd.Material(mass=1.0, damping=0.8, rayleigh=5e-4, w10=10.0, w01=10.0, w20=1.0,
                    w11=1.0, w02=1.0)


def _models():
    surf = sd.shapes.plane(cells=(14, 11))
    mask = np.zeros(surf.shape, dtype=bool)
    mask[:, :2] = True
    mask[5:9, 6:9] = True
    return {
        "clamped plate with twist": sd.Model(surf, PLATE, boundary="clamped"),
        "fixed points, not a rectangle": sd.Model(surf, PLATE, fixed=mask),
        "lumped mass": sd.Model(surf, PLATE, boundary="clamped", mass_matrix="lumped"),
    }


@pytest.fixture(scope="module")
def models():
    return _models()


@pytest.mark.parametrize("factor", ["banded", "block"])
@pytest.mark.parametrize("name", list(_models()))
def test_lowest_eigenpairs_match_dense_eigh(models, name, factor, monkeypatch):
    """Both factorisations of K: the band solve of these small nets, and the block one
    (solvers/block_cholesky.py, with its wider Lanczos blocks) that large nets use."""
    if factor == "block":
        monkeypatch.setattr(block_cholesky, "CACHED_BAND", 0)
    model = models[name]
    M, _, K = model.matrices()
    lam_ref, phi_ref = sla.eigh(K.toarray(), M.toarray())
    k = 24
    krylov = sparse_eigen.BlockLanczos(K, M)
    assert getattr(krylov.lu, "method", "superlu") == factor or name.startswith("fixed")
    modes = krylov.lowest(k)
    assert modes.lam.size in (k + 1, model.n_free)      # all when the space fills R^n
    lam, phi = modes.lam[:k + 1], modes.phi[:, :k + 1]
    assert np.max(np.abs(lam - lam_ref[:k + 1]) / lam_ref[:k + 1]) <= 1e-9
    # eigenvectors: residual and M-orthonormality (1e-8: r ≤ 1e-10 relative to ν, times κ)
    Kp = K @ phi
    res = np.linalg.norm(Kp - (M @ phi) * lam, axis=0) / np.linalg.norm(Kp, axis=0)
    assert res.max() <= 1e-8
    gram = phi.T @ (M @ phi)
    assert np.abs(gram - np.eye(k + 1)).max() <= 1e-10
    # a simple eigenvalue's vector matches the dense one up to sign (angle ≤ r/gap)
    gaps = np.diff(lam_ref[:k + 2])
    simple = [i for i in range(k) if min(gaps[i], gaps[i - 1] if i else np.inf)
              > 1e-3 * lam_ref[i]]
    cos = np.abs(np.einsum("ik,ik->k", phi_ref[:, simple], M @ phi[:, simple]))
    assert np.all(cos >= 1 - 1e-9)


def test_a_grown_space_gives_the_same_modes_as_a_fresh_one(models):
    """Asking for 6 and then 30 modes extends one Krylov space; a fresh space with another
    random start must give the same eigenvalues (to the 1e-9 of the module docstring)."""
    M, _, K = models["clamped plate with twist"].matrices()
    krylov = sparse_eigen.BlockLanczos(K, M)
    few = krylov.lowest(6)
    many = krylov.lowest(30)
    fresh = sparse_eigen.lowest_modes(K, M, 30, seed=7)
    assert np.max(np.abs(many.lam - fresh.lam) / fresh.lam) <= 1e-9
    assert np.max(np.abs(many.lam[:7] - few.lam) / few.lam) <= 1e-9
    assert many.solves > few.solves


def test_a_tiny_system_returns_all_its_modes():
    """When the Krylov space fills R^n every mode is returned (n = 4 here)."""
    model = sd.Model(sd.shapes.plane(cells=(3, 3)), PLATE, boundary="clamped")
    M, _, K = model.matrices()
    modes = sparse_eigen.lowest_modes(K, M, 3)
    lam_ref = sla.eigh(K.toarray(), M.toarray(), eigvals_only=True)
    assert modes.lam.size == model.n_free
    assert np.max(np.abs(modes.lam - lam_ref) / lam_ref) <= 1e-9




def test_a_refused_room_falls_back_to_twice_the_vectors_asked(models, monkeypatch):
    """Where the address space of eight times the vectors asked is refused (MemoryError),
    the basis takes twice what it asks and gives the dense eigenvalues (to the 1e-9 of the
    module docstring). Here 5 pairs in blocks of 2 ask 3·5 + 4·2 = 23 vectors: eight times
    that (capped at n = 130) is refused, twice (46) is not."""
    M, _, K = models["clamped plate with twist"].matrices()
    assert K.shape[0] == 130
    lam_ref = sla.eigh(K.toarray(), M.toarray(), eigvals_only=True)
    empty, refused = np.empty, []

    def tight(shape, *args, **kwargs):
        if isinstance(shape, tuple) and len(shape) == 2 and shape[0] == K.shape[0] \
                and shape[1] > 64:
            refused.append(shape[1])
            raise MemoryError
        return empty(shape, *args, **kwargs)

    monkeypatch.setattr(sparse_eigen.np, "empty", tight)
    krylov = sparse_eigen.BlockLanczos(K, M)
    modes = krylov.lowest(4)
    assert refused == [130]
    assert krylov.V.shape[1] == 46
    assert np.max(np.abs(modes.lam - lam_ref[:5]) / lam_ref[:5]) <= 1e-9
