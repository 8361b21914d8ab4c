"""Products with a collocation matrix (collocation.py) by each of its three ways, against
the dense matrix product."""

import numpy as np
import pytest

from splinedeform import collocation
from splinedeform.basis import BSplineBasis


def product_cases():
    rng = np.random.default_rng(3)
    open_basis = BSplineBasis(3, 40, 1.0, "open")
    periodic = BSplineBasis(3, 40, 1.0, "periodic")
    sorted_x = np.linspace(0.0, 1.0, 1203)
    return {
        "gathered (small)": (open_basis, sorted_x[:7], rng.normal(size=(open_basis.size, 5))),
        "dense blocks (sorted, large)": (open_basis, sorted_x,
                                         rng.normal(size=(open_basis.size, 1000))),
        "sparse (unsorted, large)": (open_basis, rng.permutation(sorted_x),
                                     rng.normal(size=(open_basis.size, 1000))),
        "sparse (periodic wrap, large)": (periodic, sorted_x,
                                          rng.normal(size=(periodic.size, 1000))),
        "sparse (sorted, mid-sized)": (open_basis, sorted_x[:300],
                                       rng.normal(size=(open_basis.size, 40))),
    }


CASES = product_cases()


@pytest.mark.parametrize("name", CASES)
def test_each_way_equals_the_dense_product(name, monkeypatch):
    basis, x, rows = CASES[name]
    calls = []
    blocked = collocation._blocked
    monkeypatch.setattr(collocation, "_blocked",
                        lambda *a: calls.append(1) or blocked(*a))
    index, values = basis.nonzero(x)
    expected = basis(x) @ rows
    got = collocation.collocate(index, values, rows)
    assert got.shape == expected.shape and got.flags.c_contiguous
    assert bool(calls) == (name == "dense blocks (sorted, large)")   # the way meant
    # n + 1 = 4 products of numbers of size O(1) summed in another order: a few roundings
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-14 * np.abs(rows).max())
