"""``selected_rows``: whether a sparse map only selects rows, read from CSR or CSC as they are.

Integers are compared exactly (indices, not floating-point results)."""

import numpy as np
import pytest
import scipy.sparse as sp

from splinedeform.solvers.products import selected_rows


@pytest.mark.parametrize("format", ["csr", "csc", "coo"])
def test_a_selection_gives_the_row_of_each_column(format):
    rows = np.array([4, 0, 7, 2])                       # columns 0..3 select these rows
    T = sp.csr_matrix((np.ones(4), (rows, np.arange(4))), shape=(9, 4)).asformat(format)
    got = selected_rows(T)
    # row indices (integers): equal when they differ by less than half a unit
    assert got is not None and got.shape == rows.shape
    assert np.abs(got - rows).max() < 0.5


@pytest.mark.parametrize("format", ["csr", "csc"])
def test_what_is_not_a_selection_gives_none(format):
    def matrix(data, r, c, shape=(5, 3)):
        return sp.csr_matrix((np.asarray(data, float), (r, c)), shape=shape).asformat(format)
    weighted = matrix([1, 0.5, 1], [0, 1, 2], [0, 1, 2])           # an entry not 1
    repeated_row = matrix([1, 1, 1], [0, 0, 2], [0, 1, 2])         # two columns, one row
    two_in_a_column = matrix([1, 1, 1], [0, 1, 2], [0, 0, 2])      # column 1 empty
    for T in (weighted, repeated_row, two_in_a_column):
        assert selected_rows(T) is None
    assert selected_rows(np.eye(3)) is None                        # not sparse
