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
