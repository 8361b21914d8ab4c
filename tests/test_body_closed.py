"""Closed bodies stay closed: a cylinder of two halves, a tube with a seam, a sphere of two
hemispheres with seams and poles.

Merged control points make the displacement continuous exactly, so the gap where patches
(or the two ends of one patch) meet is the rest shape's gap plus round-off: below 1e-12 of
a body of size 1. The answers are compared with closed forms of the membrane
``−T Δ_S d = f`` within their discretisation error (measured, with a margin, below).
"""

from __future__ import annotations

from math import pi

import numpy as np

import splinedeform as sd

R, H = 1.0, 2.0
MEMBRANE = sd.Material(w10=1.0, w01=1.0)
GAP = 1e-12      # round-off of merged coordinates on a body of size 1 (module docstring)


def tube(angle: float, cells: tuple[int, int]) -> sd.Surface:
    """``angle`` radians of the cylinder ``x = (R cos(u/R), R sin(u/R), v)``, open knots."""
    def f(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return np.stack([R * np.cos(u / R), R * np.sin(u / R), v], axis=-1)
    return sd.shapes.from_function(f, cells=cells, knots="open",
                                   domain=((0.0, angle * R), (0.0, H)))


def test_cylinder_of_two_halves_is_symmetric_and_closed() -> None:
    first = tube(pi, (6, 6))
    # the mirror image y -> -y, reversed in u so that its normal points outwards too
    second = sd.Surface(first.control_points[::-1] * [1, -1, 1], first.basis_u, first.basis_v)
    body = sd.Body([first, second])
    assert body.summary() == {"shared": 2, "seam": 0, "boundary": 4, "non_manifold": 0,
                              "poles": 0, "non_conforming": 0}
    static = sd.BodyModel(body, MEMBRANE, boundary="pinned").static(sd.Pressure(1.0))
    nets = static.control_points()
    # the mirror symmetry of the body and the load holds for the answer, to round-off
    np.testing.assert_allclose(nets[1], nets[0][::-1] * [1, -1, 1], rtol=0, atol=GAP)
    a, b = static.surface()
    v = np.linspace(0.0, H, 11)
    for ua, ub in ((0.0, pi * R), (pi * R, 0.0)):
        gap = np.abs(a.evaluate(np.full_like(v, ua), v) - b.evaluate(np.full_like(v, ub), v))
        assert gap.max() < GAP
    # −T (w'' − w/R²) = q with w(0) = w(H) = 0:
    # w = q R²/T (1 − cosh((z − H/2)/R) / cosh(H/2R));
    # 6 × 6 cubic spans resolve it to 8e-5 of its largest value (measured): 2e-4
    w = R**2 * (1 - np.cosh((v - H / 2) / R) / np.cosh(H / (2 * R)))
    radial = np.array([np.cos(1.0), np.sin(1.0), 0.0])
    d = static.displacement(np.full_like(v, 1.0), v, patch=0)
    np.testing.assert_allclose(d @ radial, w, rtol=0, atol=2e-4 * w.max())


def test_tube_with_a_seam_stays_closed() -> None:
    whole = tube(2 * pi, (12, 6))
    body = sd.Body([whole])
    assert body.summary()["seam"] == 1 and body.summary()["boundary"] == 2
    model = sd.BodyModel(body, MEMBRANE, boundary="pinned")
    deformed = model.static(sd.Pressure(1.0)).surface()[0]
    v = np.linspace(0.0, H, 11)
    gap = deformed.evaluate(np.zeros_like(v), v) - deformed.evaluate(np.full_like(v, 2 * pi), v)
    assert np.abs(gap).max() < GAP
    # merged, the two rows of control points at the seam are one
    assert model.n_free == (whole.shape[0] - 1) * (whole.shape[1] - 2)


def test_sphere_of_two_hemispheres_stays_closed() -> None:
    upper = sd.shapes.half_sphere(R, cells=(8, 4), knots=("open", "open"))
    # mirrored z -> -z and reversed in u: the normal points outwards
    lower = sd.Surface(upper.control_points[::-1] * [1, 1, -1], upper.basis_u, upper.basis_v)
    body = sd.Body([upper, lower])
    assert body.summary() == {"shared": 1, "seam": 2, "boundary": 0, "non_manifold": 0,
                              "poles": 2, "non_conforming": 0}
    model = sd.BodyModel(body, sd.Material(w10=1.0, w01=1.0, damping=2.0))
    assert model.rigid_modes == 1          # nothing holds it: a translation per coordinate
    motion = model.dynamic(sd.Pressure(1.0), 30.0)
    nets = motion.control_points(30.0)
    for net in nets:                       # each pole's control points move as one
        assert np.ptp(net[:, -1], axis=0).max() < GAP
    top, bottom = motion.surface(30.0)
    t = np.linspace(0.0, 2 * pi * R, 9)
    zero = np.zeros_like(t)
    assert np.abs(top.evaluate(t, zero) - bottom.evaluate(2 * pi * R - t, zero)).max() < GAP
    for half in (top, bottom):
        lat = np.linspace(0.0, pi * R / 2, 7)
        seam = (half.evaluate(np.zeros_like(lat), lat)
                - half.evaluate(np.full_like(lat, 2 * pi * R), lat))
        assert np.abs(seam).max() < GAP
    # the net force of a pressure on a closed surface is 0, so with damping the motion
    # settles at the static w = q R²/(2T) (−T Δ_S x = 2T x/R²); after 30 time units the
    # transient (e^{-t}) is gone and 8 × 4 cubic spans are within 7.8e-4 of it (measured;
    # 12 × 6: 5.0e-4): 2e-3
    U, V = np.meshgrid(np.linspace(0, 2 * pi * R, 9), np.linspace(0, 0.45 * pi * R, 5),
                       indexing="ij")
    radial = np.sum(motion.displacement(30.0, U, V, patch=0) * upper.evaluate(U, V), -1) / R
    np.testing.assert_allclose(radial, R**2 / 2, rtol=2e-3)


def test_pole_merged_like_the_single_surface_pole_preset() -> None:
    # the same net and constraints built two ways (the pole's points one unknown): the same
    # matrices in another order, 1e-10 (as the split squares)
    dome = sd.shapes.half_sphere(R, cells=(8, 4))
    single = sd.Model(dome, MEMBRANE, boundary={"v0": "clamped", "v1": "pole"},
                      physics="intrinsic")
    body = sd.BodyModel([dome], MEMBRANE, boundary="clamped")
    assert body.n_free == single.n_free
    np.testing.assert_allclose(body.frequencies(6), single.frequencies(6), rtol=1e-10)
