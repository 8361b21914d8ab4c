"""Clamped edges of a curved Kirchhoff–Love shell: ``d = 0`` held in ``T``, the rotation
``a_3·∂_n d`` by Nitsche's terms (:mod:`splinedeform.physics.shell_clamp`), so the
membrane strain at the edge is free. A long cylinder clamped at both ends under internal
pressure against Timoshenko's edge solution, and the convergence of a clamped cylindrical
panel."""

import numpy as np

import splinedeform as sd
from splinedeform.physics.shell import ShellMaterial
from splinedeform.physics.shell_model import ShellModel

NU = 0.3


def test_a_clamped_cylinder_under_pressure_is_timoshenkos():
    # a quarter of a cylinder (R = 1, t = 0.02, L = 2) with symmetry edges along its
    # generators, clamped at both circular ends (their normal turns along the edge).
    # Timoshenko, Theory of Plates and Shells §114: w = w_p (1 − e^{−βx}(cos βx + sin βx)),
    # β⁴ = 3(1−ν²)/(R²t²); βL = 18, so the two ends do not meet (e^{−9} at the middle).
    # The middle is w_p = (1−ν²) p R²/(E t) / (1 − 2ν²/(βL)) (the axial force of the held
    # ends, ∫ε_x = 0). 4 × 32 quartic cells measured 3.2e-4 from w_p and 1.4e-4, 2.3e-4
    # at βx = π/2, π: the shell theories differ by O(t/R) = 2e-2 times the edge layer's
    # share; 1e-3. (Holding the whole slope, ε_x = 0 at the ends, was 4.9e-4 below the
    # converged middle on these cells, 9.6e-4 on 4 × 16, converging at first order: within
    # this bar, which the shell theories' difference sets; the panel below tells them apart)
    R, t, L, E = 1.0, 0.02, 2.0, 1.0e4
    beta = (3 * (1 - NU ** 2)) ** 0.25 / np.sqrt(R * t)

    def cylinder(u, v):
        return np.stack([R * np.cos(u), v, R * np.sin(u)], -1)

    quarter = sd.shapes.from_function(cylinder, cells=(4, 32), degree=4, knots="open",
                                      domain=((0.0, np.pi / 2), (0.0, L)))
    model = ShellModel(quarter, ShellMaterial(E, NU, t, 1.0),
                       {"u0": "symmetry", "u1": "symmetry", "v0": "clamped", "v1": "clamped"})
    solution = model.static(sd.Pressure(1.0))

    def w(x):
        return np.linalg.norm(solution.displacement(np.pi / 4, x))

    w_p = (1 - NU ** 2) * R ** 2 / (E * t) / (1 - 2 * NU ** 2 / (beta * L))
    assert abs(w(L / 2) / w_p - 1) < 1e-3
    for bx in (np.pi / 2, np.pi):
        edge = 1 - np.exp(-bx) * (np.cos(bx) + np.sin(bx))
        assert abs(w(bx / beta) / (w_p * edge) - 1) < 1e-3


def cylinder(u, v):
    # the cylindrical panel of tests/validation/test_trim_shell.py: R = 1, arc length in u
    phi = u - np.pi / 4
    return np.stack([np.sin(phi), v, np.cos(phi)], -1)


PANEL = ((0.23, 1.33), (0.21, 1.27))
THICK = ShellMaterial(1.0e4, NU, 0.2, 1.0)          # t = 0.2: no locking


def panel_middle(cells):
    """The displacement at the middle of the panel as its own patch (quartic, open
    knots), clamped on its four edges."""
    patch = sd.shapes.from_function(cylinder, cells=cells, degree=4, knots="open",
                                    domain=PANEL)
    model = ShellModel(patch, THICK, {e: "clamped" for e in ("u0", "u1", "v0", "v1")})
    (u0, u1), (v0, v1) = patch.domain
    return model.static(sd.Pressure(1.0)).displacement((u0 + u1) / 2, (v0 + v1) / 2)


def test_a_clamped_curved_panel_converges_at_high_order():
    # against 24 × 24 cells (32 × 32 measured 3e-9 from it): 8, 12, 16 cells measured
    # 1.4e-5, 6.2e-7, 5.0e-8 (the displacement vector at the middle), a rate of 8.2 over
    # 8 → 16: at least the p + 1 = 5 of quartics in L², the middle of this nearly
    # symmetric panel superconverging; bounds 5e-5 and 2e-7, a rate in [5, 10]. Holding
    # the whole slope (the membrane strains at the edges held at zero) measured 7.9e-3,
    # 3.8e-3 at 8, 16 cells and converged at first order (1.09, 1.08, 1.03, 1.01 over
    # 4 → 8 → 12 → 16 → 32) to the same answer
    reference = panel_middle(24)
    errors = [np.linalg.norm(panel_middle(cells) - reference) / np.linalg.norm(reference)
              for cells in (8, 16)]
    assert errors[0] < 5e-5 and errors[1] < 2e-7
    assert 5 < np.log2(errors[0] / errors[1]) < 10


def test_the_clamped_panel_is_the_trimmed_one():
    # the same panel trimmed from the whole quarter cylinder (12 × 12 quartic uniform
    # cells, off the knot lines) and clamped by Nitsche's terms on its loop, d included:
    # measured 2.2e-6 from the patch's 16 × 16 cells (the trimmed one's own change
    # 12 → 24 is 2.2e-6, the two converged ones 4.5e-7 apart); 1e-5
    from splinedeform.trim import PolygonLoop, TrimDomain

    (a, b), (c, d) = PANEL
    whole = sd.shapes.from_function(cylinder, cells=12, degree=4, knots="uniform",
                                    domain=((0.0, np.pi / 2), (0.0, 1.5)))
    panel = whole.with_trim(TrimDomain(PolygonLoop([[a, c], [b, c], [b, d], [a, d]])))
    trimmed = ShellModel(panel, THICK, {"outer": "clamped"}).static(sd.Pressure(1.0))
    middle = trimmed.displacement((a + b) / 2, (c + d) / 2)
    patch = panel_middle(16)
    assert np.linalg.norm(middle - patch) < 1e-5 * np.linalg.norm(patch)


def test_a_body_of_the_panel_clamps_as_the_surface():
    # the panel as a body of one patch, boundary "clamped": the same matrices, constraint
    # map and Nitsche terms, assembled through the body; round-off of two solves
    # (measured 4e-16 on 8 × 8 cells); 1e-9. No free rigid motion is left in either
    from splinedeform.body import Body

    patch = sd.shapes.from_function(cylinder, cells=8, degree=4, knots="open", domain=PANEL)
    body = ShellModel(Body([patch]), THICK, "clamped")
    assert body.rigid.shape[1] == 0
    (u0, u1), (v0, v1) = patch.domain
    middle = body.static(sd.Pressure(1.0)).displacement((u0 + u1) / 2, (v0 + v1) / 2, 0)
    alone = panel_middle(8)
    assert np.linalg.norm(middle - alone) < 1e-9 * np.linalg.norm(alone)


def test_a_flat_shell_holds_the_normal_slope_and_a_curved_one_pins():
    # flat (a distorted map of a square in z = 0, so a_αβ ≠ 0 but b_αβ = a_αβ·a_3 = 0): the
    # clamped edges keep the second rows of d_z at rest (the rotation, exact there) and
    # leave the in-plane components pinned (their slopes are the membrane's); the curved
    # panel's clamped edges are pinned in T, the rotation Nitsche's. Column counts of T are
    # integers (compared to 0.5)
    from splinedeform.physics.shell_edges import constraint_matrix

    def distorted(u, v):
        return np.stack([(u + u ** 2) / 2, v + 0.15 * u * np.sin(np.pi * v), 0 * u], -1)

    flat = sd.shapes.from_function(distorted, cells=6, degree=3, knots="open")
    curved = sd.shapes.from_function(cylinder, cells=6, degree=3, knots="open", domain=PANEL)
    clamped = {e: "clamped" for e in ("u0", "u1", "v0", "v1")}
    pinned = {e: "pinned" for e in clamped}
    per_pinned = constraint_matrix(flat, pinned).shape[1] / 3
    per_clamped = constraint_matrix(flat, clamped).shape[1] / 3       # every slope held
    assert abs(constraint_matrix(flat, clamped, weak_rotation=True).shape[1]
               - (2 * per_pinned + per_clamped)) < 0.5
    assert abs(constraint_matrix(curved, clamped, weak_rotation=True).shape[1]
               - constraint_matrix(curved, pinned).shape[1]) < 0.5
