"""The Kirchhoff–Love shell on trimmed faces: a thin circular plate as a trimmed square
shell (loops held by Nitsche's method) under a uniform pressure, clamped and simply
supported, against Kirchhoff's closed forms, and its lowest frequencies against the Bessel
roots; a free trimmed shell's rigid motions; the refusals."""

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.physics.shell import ShellMaterial
from splinedeform.physics.shell_model import ShellModel
from splinedeform.trim import CircleLoop, TrimDomain

A, E, NU, THICKNESS, Q = 0.4, 1.0e4, 0.3, 0.01, 1.0
D = E * THICKNESS ** 3 / (12 * (1 - NU ** 2))
MATERIAL = ShellMaterial(E, NU, THICKNESS, 1.0)
CLOSED_FORMS = {"clamped": Q * A ** 4 / (64 * D),                       # Timoshenko §62
                "pinned": (5 + NU) * Q * A ** 4 / (64 * (1 + NU) * D)}   # §63


def disc_shell(cells, degree, edge):
    plane = sd.shapes.plane(cells=(cells, cells), degree=degree, knots="uniform")
    surface = plane.with_trim(TrimDomain(CircleLoop((0.5, 0.5), A)))
    return ShellModel(surface, MATERIAL, {"outer": edge})


def centre(model):
    return model.static(sd.Pressure(Q)).displacement(0.5, 0.5)


@pytest.mark.parametrize("edge", ["clamped", "pinned"])
def test_the_disc_in_quartics_is_kirchhoffs(edge):
    # a flat linear shell bends as Kirchhoff's plate (no membrane action under a normal
    # load); both deflections are quartics in (u, v), the extended quartic B-splines hold
    # them and Nitsche's terms are consistent: round-off (measured 5e-13 and 2e-14 of
    # the closed form on 8 × 8 cells); 1e-9. The in-plane displacement is zero (1e-12 of
    # the deflection)
    d = centre(disc_shell(8, 4, edge))
    assert abs(d[2] / CLOSED_FORMS[edge] - 1) < 1e-9
    assert np.abs(d[:2]).max() < 1e-12 * d[2]


@pytest.mark.parametrize("edge", ["clamped", "pinned"])
def test_cubic_discs_converge_to_the_closed_form(edge):
    # 12 → 24 cubic cells measured 1.4e-4 → 5.2e-6 (clamped) and 3.7e-5 → 1.3e-6
    # (pinned): well within the 1 % bar and falling at about h⁴ or faster; bounds with
    # a factor 3 and a rate of at least 3
    coarse, fine = (abs(centre(disc_shell(cells, 3, edge))[2] / CLOSED_FORMS[edge] - 1)
                    for cells in (12, 24))
    assert coarse < {"clamped": 5e-4, "pinned": 1.2e-4}[edge]
    assert fine < coarse / 8


@pytest.mark.parametrize("edge, closed_form, cells", [
    # Navier's series 16/π⁶ Σ_{m,n odd} (−1)^((m+n)/2−1)/(m n (m² + n²)²) (199² terms)
    ("pinned", 0.004062352660673777, 8),
    ("clamped", 0.00126532, 12),           # Timoshenko & Woinowsky-Krieger §44, table 35
])
def test_a_square_held_on_the_rectangles_edges(edge, closed_form, cells):
    # the whole rectangle as the outer loop: its edges u0 … v1 held by Nitsche's terms on
    # that loop's points; quartic cells measured 3.5e-6 (pinned, 8 × 8) and 5.4e-7
    # (clamped, 12 × 12) from w = c q a⁴/D, as the untrimmed shell holding the edges
    # exactly does (3.0e-6 and 3.6e-7); 1e-5
    from splinedeform.trim import PolygonLoop

    plane = sd.shapes.plane(cells=(cells, cells), degree=4, knots="uniform")
    square = plane.with_trim(TrimDomain(PolygonLoop([[0, 0], [1, 0], [1, 1], [0, 1]])))
    model = ShellModel(square, MATERIAL, {e: edge for e in ("u0", "u1", "v0", "v1")})
    w = model.static(sd.Pressure(Q)).displacement(0.5, 0.5)[2]
    assert abs(w * D / (closed_form * Q) - 1) < 1e-5


def test_lowest_frequencies_are_the_bessel_roots():
    # ω = (λ²/a²) √(D/(ρt)) with λ² = 10.2158, 21.2604 (twice), 34.8770 (twice) of the
    # clamped disc (Leissa, Vibration of Plates, table 2.1); 12 × 12 quartic cells
    # measured within 3e-4 (the in-plane modes lie far above); 1e-3
    omega, _ = disc_shell(12, 4, "clamped").modes(5)
    lam2 = omega * A ** 2 / np.sqrt(D / (MATERIAL.density * THICKNESS))
    roots = np.array([10.2158, 21.2604, 21.2604, 34.8770, 34.8770])
    assert np.abs(lam2 / roots - 1).max() < 1e-3


def test_a_free_trimmed_shell_keeps_its_rigid_motions():
    # no held loop: the six rigid motions of the plane's (linear) net lie in the range of
    # the extension, which reproduces polynomials; their eigenvalues are round-off of K_r
    # (measured 0: the round-off negatives are clipped); 1e-8 of the seventh
    plane = sd.shapes.plane(cells=(6, 6), degree=3, knots="uniform")
    surface = plane.with_trim(TrimDomain(CircleLoop((0.5, 0.5), A)))
    model = ShellModel(surface, MATERIAL, {"outer": "free"})
    assert model.rigid.shape[1] == 6
    lam, _ = model.eigen(7)
    assert np.all(lam[:6] < 1e-8 * lam[6])


def test_refusals_name_the_problem():
    from splinedeform.trim import PolygonLoop

    plane = sd.shapes.plane(cells=(6, 6), degree=3, knots="uniform")
    holed = plane.with_trim(TrimDomain(PolygonLoop([[0, 0], [1, 0], [1, 1], [0, 1]]),
                                       (CircleLoop((0.5, 0.5), 0.2),)))
    with pytest.raises(sd.InputError, match="boundary.u0 must be one of"):
        ShellModel(holed, MATERIAL, {"u0": "diaphragm"})
    disc = plane.with_trim(TrimDomain(CircleLoop((0.5, 0.5), A)))
    z_only = np.zeros(plane.shape + (3,), bool)
    z_only[4, 4, 2] = True                # the three components follow one extension map
    with pytest.raises(sd.InputError, match=r"point\(s\) \[4, 4\] hold some components only"):
        ShellModel(disc, MATERIAL, {"outer": "clamped"}, fixed=z_only)
    with pytest.raises(sd.InputError, match="hole7"):
        ShellModel(disc, MATERIAL, {"hole7": "clamped"})
    quadratic = sd.shapes.plane(cells=(6, 6), degree=2, knots="uniform")
    with pytest.raises(sd.InputError, match="degree >= 3"):
        ShellModel(quadratic.with_trim(TrimDomain(CircleLoop((0.5, 0.5), A))), MATERIAL,
                   {"outer": "pinned"})


def test_a_pinned_cylindrical_panel_is_the_conforming_one():
    # a quarter of a cylinder (R = 1, arc length in u) trimmed by a rectangle in (u, v)
    # off the knot lines, pinned on it by Nitsche's terms (the curved metric's derivatives
    # along the loop, the membrane and bending coefficients in the penalty), against the
    # same panel as its own patch with its edges pinned exactly (the edge's control
    # points at rest); 12 × 12 quartic cells each, a thick panel (t = 0.2, no locking):
    # measured 5e-7 of the displacement at the middle (7e-7 on 16 × 16, the conforming
    # one's own change 12 → 16 is 2e-8); 1e-5
    from splinedeform.trim import PolygonLoop

    def cylinder(u, v):
        phi = u - np.pi / 4
        return np.stack([np.sin(phi), v, np.cos(phi)], -1)

    (a, b), (c, d) = (0.23, 1.33), (0.21, 1.27)
    material = ShellMaterial(1.0e4, 0.3, 0.2, 1.0)
    whole = sd.shapes.from_function(cylinder, cells=12, degree=4, knots="uniform",
                                    domain=((0.0, np.pi / 2), (0.0, 1.5)))
    panel = whole.with_trim(TrimDomain(PolygonLoop([[a, c], [b, c], [b, d], [a, d]])))
    trimmed = ShellModel(panel, material, {"outer": "pinned"}).static(sd.Pressure(1.0))
    patch = sd.shapes.from_function(cylinder, cells=12, degree=4, knots="open",
                                    domain=((a, b), (c, d)))
    conforming = ShellModel(patch, material, {e: "pinned" for e in ("u0", "u1", "v0", "v1")})
    (u0, u1), (v0, v1) = patch.domain
    reference = conforming.static(sd.Pressure(1.0)).displacement((u0 + u1) / 2, (v0 + v1) / 2)
    # the two middles are one point of the cylinder, to the two fits' error (1e-7 of R)
    assert np.allclose(panel.evaluate((a + b) / 2, (c + d) / 2),
                       patch.evaluate((u0 + u1) / 2, (v0 + v1) / 2), atol=1e-7)
    middle = trimmed.displacement((a + b) / 2, (c + d) / 2)
    assert np.linalg.norm(middle - reference) < 1e-5 * np.linalg.norm(reference)
