"""The intrinsic plate (``physics = "intrinsic"``) on trimmed faces: against the parametric
plate on a flat unit-speed disc, the closed forms of the clamped and pinned disc, and a
manufactured solution on a curved face (a parabolic cylinder trimmed by a circle in
``(u, v)``), whose load is the surface operator ``D Δ_S² d − T Δ_S d`` written out by hand."""

import numpy as np
import pytest
from numpy.polynomial import polynomial as npp
from scipy.signal import convolve2d

import splinedeform as sd
from splinedeform.trim import CircleLoop, TrimDomain

A = 0.4                                    # the disc's radius about (0.5, 0.5)


def disc(cells, degree):
    plane = sd.shapes.plane(cells=(cells, cells), degree=degree, knots="uniform")
    return plane.with_trim(TrimDomain(CircleLoop((0.5, 0.5), A)))


@pytest.mark.parametrize("edge", ["free", "pinned", "clamped"])
def test_tension_and_mass_are_the_parametric_plates_on_a_flat_disc(edge):
    # x = (u, v, 0): g = I, √g = 1, Γ = 0, so T g^αβ d_α v_β = T ∇d·∇v and the Nitsche
    # terms and penalties (w_t = T) are the parametric plate's with w10 = w01 = T; the two
    # paths add the same products in another order: round-off (measured 2e-15); 1e-12
    surface = disc(8, 3)
    material = sd.Material(w10=1.3, w01=1.3, mass=0.7)
    intrinsic = sd.Model(surface, material, boundary={"outer": edge}, physics="intrinsic")
    parametric = sd.Model(surface, material, boundary={"outer": edge})
    for a, b in ((intrinsic.K_full, parametric.K_full), (intrinsic.M_full, parametric.M_full)):
        assert abs(a - b).max() < 1e-12 * abs(b).max()


@pytest.mark.parametrize("edge, closed_form", [
    ("clamped", A ** 4 / 64),              # q a⁴/(64 D)
    ("pinned", 3 * A ** 4 / 64),           # (5 + ν) q a⁴/(64 (1 + ν) D) at ν = 1
])
def test_the_disc_in_quartics_is_its_closed_form(edge, closed_form):
    # the energy (Δd)² is Kirchhoff's plate with ν = 1 on a pinned loop (Δd = 0 is its
    # natural condition) and any ν on a clamped one; both deflections are quartics, which
    # the extended quartic B-splines hold, and Nitsche's terms are consistent: round-off
    # (measured 5e-13 and 1e-13 on 8 × 8 cells); 1e-10
    model = sd.Model(disc(8, 4), sd.Material(w20=1.0, w11=1.0, w02=1.0),
                     boundary={"outer": edge}, physics="intrinsic")
    centre = model.static(sd.Uniform([0.0, 0.0, 1.0])).displacement(0.5, 0.5)[2]
    assert abs(centre / closed_form - 1) < 1e-10


# a parabolic cylinder x = (u, v, c u²), trimmed by the circle |(u, v) − m| = a: g11 =
# σ² = 1 + 4c²u², g12 = 0, g22 = 1, so Δ_S f = p f_uu − r f_u + f_vv with p = 1/σ²,
# r = 4c²u p². The field d = w², w = a² − |(u, v) − m|², is clamped on the circle and a
# quartic in (u, v)
C, RADIUS, MIDDLE, T, D = 0.8, 0.35, (0.5, 0.45), 1.0, 1.0
_W = np.zeros((3, 3))
_W[0, 0], _W[1, 0], _W[2, 0], _W[0, 1], _W[0, 2] = (
    RADIUS ** 2 - MIDDLE[0] ** 2 - MIDDLE[1] ** 2, 2 * MIDDLE[0], -1.0, 2 * MIDDLE[1], -1.0)
_D = convolve2d(_W, _W)                    # the coefficients of d = w² in u^i v^j


def field(i, j, u, v):
    """``∂_u^i ∂_v^j d`` at ``(u, v)``."""
    k = npp.polyder(npp.polyder(_D, i, axis=0), j, axis=1)
    return npp.polyval2d(u, v, k)


def manufactured_load(u, v, t=0.0):
    """``f = √g (D Δ_S Δ_S d − T Δ_S d)`` per unit parameter area, along z."""
    c2 = C * C
    p = 1 / (1 + 4 * c2 * u * u)
    r = 4 * c2 * u * p * p
    p1 = -8 * c2 * u * p * p
    p2 = -8 * c2 * p * p + 128 * c2 * c2 * u * u * p ** 3
    r1 = 4 * c2 * p * p + 8 * c2 * u * p * p1
    r2 = 16 * c2 * p * p1 + 8 * c2 * u * (p1 * p1 + p * p2)
    d = lambda i, j: field(i, j, u, v)  # noqa: E731
    phi = p * d(2, 0) - r * d(1, 0) + d(0, 2)                                  # Δ_S d
    phi_u = p1 * d(2, 0) + p * d(3, 0) - r1 * d(1, 0) - r * d(2, 0) + d(1, 2)
    phi_uu = (p2 * d(2, 0) + 2 * p1 * d(3, 0) + p * d(4, 0) - r2 * d(1, 0)
              - 2 * r1 * d(2, 0) - r * d(3, 0) + d(2, 2))
    phi_vv = p * d(2, 2) - r * d(1, 2) + d(0, 4)
    f = np.sqrt(1 + 4 * c2 * u * u) * (D * (p * phi_uu - r * phi_u + phi_vv) - T * phi)
    return np.stack([np.zeros_like(f), np.zeros_like(f), f], axis=-1)


def curved(cells, degree):
    surface = sd.shapes.from_function(lambda u, v: np.stack([u, v, C * u * u], -1),
                                      cells=cells, degree=degree, knots="uniform")
    surface = surface.with_trim(TrimDomain(CircleLoop(MIDDLE, RADIUS)))
    model = sd.Model(surface, sd.Material(w10=T, w01=T, w20=D, w11=D, w02=D),
                     boundary={"outer": "clamped"}, physics="intrinsic")
    solution = model.static(sd.Function(manufactured_load))
    u = np.array([0.5, 0.6, 0.35, 0.7, 0.45])
    v = np.array([0.45, 0.5, 0.4, 0.3, 0.7])
    return np.abs(solution.displacement(u, v)[:, 2] - field(0, 0, u, v)).max() / RADIUS ** 4


def test_a_curved_face_holds_its_manufactured_solution():
    # quartic B-splines hold d = w², Nitsche's terms (with the metric's derivatives along
    # the loop) are consistent, so the error is that of the quadrature of the rational
    # metric: measured 1.8e-10 on 6 × 6 cells and 3.8e-12 on 10 × 10 (dropping the
    # coefficients' derivatives from the boundary terms leaves 7e-5); 1e-8 and 1e-10
    assert curved(6, 4) < 1e-8
    assert curved(10, 4) < 1e-10


def test_a_curved_face_converges_in_cubics():
    # cubics do not hold the quartic: 8 → 16 cells measured 1.1e-2 → 3.2e-4 (a rate of
    # 5.1 at the probe points, above the h⁴ of the energy norm's square); bounds with a
    # factor 2 and the rate within [3.5, 6.5]
    coarse, fine = curved(8, 3), curved(16, 3)
    assert coarse < 2.5e-2 and fine < 7e-4
    assert 3.5 < np.log2(coarse / fine) < 6.5


@pytest.mark.parametrize("edge", ["clamped", "pinned"])
def test_a_cylindrical_panel_is_the_conforming_one(edge):
    # a quarter of a cylinder (R = 1, arc length in u) trimmed by a rectangle in (u, v)
    # off the knot lines and held on it by Nitsche's terms, against the same panel as its
    # own patch with its edges held exactly (T = 1, D = 0.1, a load per unit area);
    # 16 × 16 quartic cells each: measured 8e-7 (clamped) and 1.3e-6 (pinned) at the
    # middle (1.3e-5 and 3e-7 on 12 × 12); 1e-5
    from splinedeform.trim import PolygonLoop

    def cylinder(u, v):
        phi = u - np.pi / 4
        return np.stack([np.sin(phi), v, np.cos(phi)], -1)

    (a, b), (c, d) = (0.23, 1.33), (0.21, 1.27)
    material = sd.Material(w10=1.0, w01=1.0, w20=0.1, w11=0.1, w02=0.1)
    load = sd.Uniform([0.0, 0.0, 1.0])
    whole = sd.shapes.from_function(cylinder, cells=16, degree=4, knots="uniform",
                                    domain=((0.0, np.pi / 2), (0.0, 1.5)))
    panel = whole.with_trim(TrimDomain(PolygonLoop([[a, c], [b, c], [b, d], [a, d]])))
    trimmed = sd.Model(panel, material, boundary={"outer": edge}, physics="intrinsic")
    patch = sd.shapes.from_function(cylinder, cells=16, degree=4, knots="open",
                                    domain=((a, b), (c, d)))
    conforming = sd.Model(patch, material, boundary=edge, physics="intrinsic")
    (u0, u1), (v0, v1) = patch.domain
    reference = conforming.static(load).displacement((u0 + u1) / 2, (v0 + v1) / 2)[2]
    middle = trimmed.static(load).displacement((a + b) / 2, (c + d) / 2)[2]
    assert abs(middle / reference - 1) < 1e-5
