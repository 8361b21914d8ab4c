"""Weight functions: zero on the loops, positive inside, unit slope, derivatives."""

import numpy as np
import pytest

from splinedeform.errors import InputError
from splinedeform.trim import CircleLoop, PolygonLoop, TrimDomain
from splinedeform.trim.plate import assemble_plate
from splinedeform.trim.weight import DiscWeight, RvachevWeight

SQUARE = PolygonLoop([[0.1, 0.1], [0.9, 0.1], [0.9, 0.9], [0.1, 0.9]])
HOLED = TrimDomain(SQUARE, (CircleLoop((0.5, 0.5), 0.2),))


def test_rvachev_weight_vanishes_on_the_loops_and_is_positive_inside():
    t = np.linspace(0.05, 0.95, 37)
    on_edges = np.concatenate([np.stack([0.1 + 0.8 * t, np.full_like(t, 0.1)], -1),
                               np.stack([np.full_like(t, 0.9), 0.1 + 0.8 * t], -1)])
    angle = 2 * np.pi * t
    on_hole = 0.5 + 0.2 * np.stack([np.cos(angle), np.sin(angle)], -1)
    w = RvachevWeight(HOLED)
    # exact zeros up to round-off of coordinates of size 1 (1e-14)
    assert np.max(np.abs(w(np.concatenate([on_edges, on_hole])))) < 1e-14
    rng = np.random.default_rng(3)
    p = rng.uniform(0, 1, (3000, 2))
    assert np.array_equal(w(p) > 0, HOLED.contains(p))


def test_rvachev_weight_is_normalised_on_edges():
    # |∇w| = 1 on a straight edge away from its corners and from the hole (R-conjunction
    # with a function that does not vanish there keeps the slope: ∂(f∧g) = ∂f when f = 0,
    # g > 0); 1e-12 is round-off
    w = RvachevWeight(HOLED)
    p = np.array([[0.5, 0.1], [0.9, 0.4], [0.3, 0.9]])
    _, wx, wy, *_ = w.derivatives(p)
    assert np.allclose(np.hypot(wx, wy), 1.0, rtol=0, atol=1e-12)


@pytest.mark.parametrize("power", [1, 2])
def test_weight_derivatives_against_central_differences(power):
    # central differences with step 1e-5 are accurate to ~1e-9 (h² f''' and round-off
    # 1e-16/h²·|f|); 1e-6 leaves room
    p = np.array([[0.33, 0.71], [0.8, 0.2], [0.62, 0.45]])
    e = 1e-5
    for weight in (RvachevWeight(HOLED, power), DiscWeight((0.5, 0.5), 0.4, power)):
        J = weight.derivatives(p)
        for first, second, step in ((1, (3, 4), [e, 0]), (2, (4, 5), [0, e])):
            plus, minus = weight.derivatives(p + step), weight.derivatives(p - step)
            assert np.allclose((plus[0] - minus[0]) / (2 * e), J[first], rtol=0, atol=1e-6)
            assert np.allclose((plus[1] - minus[1]) / (2 * e), J[second[0]], rtol=0, atol=1e-6)
            assert np.allclose((plus[2] - minus[2]) / (2 * e), J[second[1]], rtol=0, atol=1e-6)


def test_non_convex_polygon_and_plate_corners_are_refused():
    ell = PolygonLoop([[0.1, 0.1], [0.9, 0.1], [0.9, 0.5], [0.5, 0.5], [0.5, 0.9], [0.1, 0.9]])
    with pytest.raises(InputError, match="convex"):
        RvachevWeight(TrimDomain(ell))
    with pytest.raises(InputError, match="corners"):
        assemble_plate(TrimDomain(SQUARE), 6, 3, RvachevWeight(TrimDomain(SQUARE)))
