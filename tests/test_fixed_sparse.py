"""FixedPattern: a fixed sparsity pattern filled from entry values equals SciPy's own COO
conversion (duplicates summed), for whole matrices, column subsets and dense blocks."""

import numpy as np
import pytest
import scipy.sparse as sp

from flipkit.errors import ConfigError
from flipkit.solvers.fixed_sparse import FixedPattern


@pytest.fixture
def entries():
    rng = np.random.default_rng(5)
    rows, cols = rng.integers(0, 30, 800), rng.integers(0, 25, 800)  # many duplicates
    return rows, cols, rng.normal(size=800)


@pytest.mark.parametrize("fmt, kind", [("csc", sp.csc_matrix), ("csr", sp.csr_matrix)])
def test_matrix_equals_scipy_coo_conversion(entries, fmt, kind):
    rows, cols, values = entries
    pattern = FixedPattern(rows, cols, (30, 25), fmt)
    for scale in (1.0, -3.0):  # new values on the same pattern
        got, want = pattern.matrix(scale * values), kind((scale * values, (rows, cols)), shape=(30, 25))
        assert got.format == fmt and got.shape == (30, 25)
        np.testing.assert_allclose(got.toarray(), want.toarray(), atol=1e-14)
        assert got.has_sorted_indices or got.sort_indices() is None


def test_column_subsets_sparse_and_dense(entries):
    rows, cols, values = entries
    pattern = FixedPattern(rows, cols, (30, 25), "csc")
    full = sp.csc_matrix((values, (rows, cols)), shape=(30, 25)).toarray()
    data = pattern.data(values)
    for pick in ([3, 0, 24, 7], [5], list(range(25))[::-1]):
        sub = pattern.columns(pick)
        np.testing.assert_allclose(sub.matrix(data).toarray(), full[:, pick], atol=1e-14)
        np.testing.assert_allclose(sub.dense(data), full[:, pick], atol=1e-14)


def test_bad_patterns_are_refused(entries):
    rows, cols, _ = entries
    with pytest.raises(ConfigError, match="csc, csr"):
        FixedPattern(rows, cols, (30, 25), "coo")
    with pytest.raises(ConfigError, match="inside"):
        FixedPattern(rows, cols, (20, 25))
    with pytest.raises(ConfigError, match="csc pattern"):
        FixedPattern(rows, cols, (30, 25), "csr").columns([0])
