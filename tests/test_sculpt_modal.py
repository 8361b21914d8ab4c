"""The modal sum used for sculpting equals Model.dynamic with the same pushes as step loads."""

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.sculpt import Push, sculpt_basis


@pytest.mark.parametrize("damping, rayleigh", [(0.8, 0.0), (0.3, 2e-3), (40.0, 0.0)])
def test_superposed_pushes_equal_model_dynamic(damping, rayleigh):
    surf = sd.shapes.plane(size=(1.0, 1.0), cells=(5, 4))
    mat = sd.Material(w10=1.0, w01=1.0, w20=0.02, w11=0.02, w02=0.02, mass=1.0,
                      damping=damping, rayleigh=rayleigh)
    model = sd.Model(surf, mat, boundary={"u0": "clamped", "v1": "pinned"})
    pushes = [Push(0.4, 0.6, (0.0, 0.0, -1.0), 0.0, 0.35),
              Push(0.4, 0.6, (0.0, 0.2, -2.0), 0.35, 0.9),   # dragging: a new step
              Push(0.7, 0.2, (0.5, 0.0, 1.0), 0.5)]          # still held at the end
    basis = sculpt_basis(model, resolution=7)
    loads = [sd.Point(p.u, p.v, p.force, sd.Step(p.t_on, p.t_off)) for p in pushes]
    sol = model.dynamic(loads, t_end=2.0)
    uu, vv = np.meshgrid(basis.samples_u, basis.samples_v, indexing="ij")
    for t in (0.1, 0.35, 0.6, 1.3, 2.0):
        ours = basis.displacement(t, pushes)
        ref = sol.displacement(t, uu.ravel(), vv.ravel())
        # Both are the same closed form evaluated through different factorings (complex
        # roots here, the solver's own modal form there) of a complete dense basis: they
        # agree to round-off, amplified by at most ~1/min(λ) relative to the largest value.
        scale = np.max(np.abs(ref))
        assert scale > 1e-6
        assert np.max(np.abs(ours - ref)) <= 1e-10 * scale


def test_free_surface_refused():
    surf = sd.shapes.plane(cells=(3, 3))
    model = sd.Model(surf, sd.Material(w10=1, w01=1), boundary="free")
    with pytest.raises(sd.InputError, match="rigid-body"):
        sculpt_basis(model)


def test_payload_round_trip():
    from splinedeform.sculpt.export import decode, payload

    surf = sd.shapes.plane(cells=(4, 4))
    model = sd.Model(surf, sd.Material(w10=1, w01=1, damping=0.5), boundary="clamped")
    basis = sculpt_basis(model, resolution=6)
    data = payload(basis)
    assert data["grid"] == [6, 6] and data["modes"] == model.n_free
    # lam and damping travel as float64: exact copies of the same numbers
    assert np.allclose(decode(data["lam"], "<f8"), basis.lam, rtol=1e-15, atol=0)
    # phi travels as float32: relative rounding 2**-24 of each entry
    phi = decode(data["phi"]).reshape(36, -1)
    assert np.allclose(phi, basis.phi_samples, rtol=2**-23, atol=1e-30)
    rest = decode(data["rest"]).reshape(6, 6, 3)
    assert np.allclose(rest[-1, -1], surf.evaluate(np.array([1.0]), np.array([1.0]))[0], rtol=1e-6)
