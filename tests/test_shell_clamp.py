"""The clamped edge's Nitsche terms without the terms of ``d`` itself
(``displacement_held``): the constraint map holds ``d = 0`` on the edge, so the reduced
``Tᵀ K T`` is the full terms' (:mod:`splinedeform.physics.shell_clamp`)."""

import numpy as np
import scipy.sparse as sp

import splinedeform as sd
from splinedeform.body import Body
from splinedeform.physics.shell import ShellMaterial
from splinedeform.physics.shell_clamp import clamp_rotation
from splinedeform.physics.shell_model import ShellModel

THICK = ShellMaterial(1.0e4, 0.3, 0.2, 1.0)
PANEL = ((0.23, 1.33), (0.21, 1.27))
CLAMPED = {e: "clamped" for e in ("u0", "u1", "v0", "v1")}


def cylinder(u, v):
    # the cylindrical panel of tests/validation/test_shell_clamped.py: R = 1
    phi = u - np.pi / 4
    return np.stack([np.sin(phi), v, np.cos(phi)], -1)


def reduced_gap(T, fast, full):
    """The largest entry of ``Tᵀ (fast − full) T`` against the largest of ``Tᵀ full T``."""
    gap = abs(T.T @ (fast - full) @ T).max()
    return gap / abs(T.T @ full @ T).max()


def test_the_clamped_panel_reduces_to_the_full_terms():
    # the left-out terms have v_0 = 0 on the edge as a factor, zero in range T (measured
    # 0: T's rows of the edge's control points are zero); 1e-12 of the largest entry, room
    # for a T whose rows there are zero only to round-off. The left-out terms are not
    # small before T (measured 0.21 of the largest entry of the full terms); 1e-2
    patch = sd.shapes.from_function(cylinder, cells=8, degree=4, knots="open", domain=PANEL)
    T = ShellModel(patch, THICK, CLAMPED).T
    fast = clamp_rotation(patch, THICK, CLAMPED)
    full = clamp_rotation(patch, THICK, CLAMPED, displacement_held=False)
    assert reduced_gap(T, fast, full) < 1e-12
    assert abs(fast - full).max() > 1e-2 * abs(full).max()


def test_a_body_of_two_panels_reduces_to_the_full_terms():
    # the panel split at its middle into a body of two cubic patches, boundary clamped
    # (each patch's clamped edges as the body found them, its interface edge not among
    # them): the body's T (ties included) against the full terms, block by block;
    # measured 0, 1e-12 as above; the left-out terms measured 0.29 of the largest entry
    (u0, u1), v = PANEL
    middle = (u0 + u1) / 2
    patches = [sd.shapes.from_function(cylinder, cells=6, degree=3, knots="open",
                                       domain=(side, v))
               for side in ((u0, middle), (middle, u1))]
    body = ShellModel(Body(patches), THICK, "clamped").formulation
    T = body.T
    own = [{e: kind for (q, e), kind in body.edges.items() if q == p} for p in (0, 1)]
    assert abs(sum(len(e) for e in own) - 6) < 0.5          # edge counts: integers
    fast, full = (sp.block_diag([clamp_rotation(s, THICK, e, displacement_held=held)
                                 for s, e in zip(patches, own)], format="csr")
                  for held in (True, False))
    assert abs(T.shape[0] - fast.shape[0]) < 0.5            # row counts: integers
    assert reduced_gap(T, fast, full) < 1e-12
    assert abs(fast - full).max() > 1e-2 * abs(full).max()


def _flat(plane):
    """A 6×6 quartic square in the plane x_a = 0.3 (``plane`` = a) or tilted about x."""
    surf = sd.shapes.plane(cells=(6, 6), degree=4)
    P = surf.control_points.copy()
    if plane == "tilted":
        c, s = np.cos(0.4), np.sin(0.4)
        P[..., 1], P[..., 2] = c * P[..., 1] - s * P[..., 2], s * P[..., 1] + c * P[..., 2]
    else:
        P = np.roll(P, plane - 2, axis=-1)           # the square's normal along e_a
        P[..., plane] = 0.3
    return surf.with_control_points(P)


def test_a_flat_clamp_holds_the_rotation_not_the_membranes_slope():
    """On a flat shell clamping holds ``d = 0`` and the rotation of the normal (the slope of
    the normal component) only. Under an in-plane load the rotation plays no part, so the
    clamped and the pinned shell are the same membrane: equal to 1e-12 of the displacement
    (round-off of two solves of the same reduced system; holding every slope, as before,
    made them differ by 8 % here). Under a normal load clamped differs from pinned (the
    plate's clamping: ~3× stiffer at the centre). A square in a tilted plane, whose clamp is
    Nitsche's, agrees with the axis-aligned square's exact clamp to 1e-5 (Nitsche's terms on
    6 quartic cells: a discretisation difference, measured 2.5e-7)."""
    from splinedeform.physics.shell_model import AreaForce

    pinned = {e: "pinned" for e in CLAMPED}
    for a in (0, 1, 2):
        surf = _flat(a)
        inplane = np.zeros(3)
        inplane[(a + 1) % 3] = 1.0
        d = [ShellModel(surf, THICK, edges).static(AreaForce(force=tuple(inplane)))
             .displacement(0.37, 0.61) for edges in (CLAMPED, pinned)]
        assert abs(d[0] - d[1]).max() <= 1e-12 * abs(d[1]).max()
        normal = np.zeros(3)
        normal[a] = 1.0
        w = [ShellModel(surf, THICK, edges).static(AreaForce(force=tuple(normal)))
             .displacement(0.5, 0.5)[a] for edges in (CLAMPED, pinned)]
        assert 2.0 < w[1] / w[0] < 5.0
    level = ShellModel(_flat(2), THICK, CLAMPED).static(AreaForce(force=(0, 0, 1.0)))
    c, s = np.cos(0.4), np.sin(0.4)
    tilted = ShellModel(_flat("tilted"), THICK, CLAMPED).static(
        AreaForce(force=(0, -s, c)))
    w_level = level.displacement(0.5, 0.5)[2]
    w_tilted = tilted.displacement(0.5, 0.5) @ np.array([0, -s, c])
    assert abs(w_tilted - w_level) <= 1e-5 * abs(w_level)
