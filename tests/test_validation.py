"""Argument checks: shape, finiteness and positivity, with the argument named."""

from __future__ import annotations

import numpy as np
import pytest

from solvers.errors import InputError
from solvers.validation import as_array, as_vector, positive


def test_good_input_comes_back_as_float_arrays():
    np.testing.assert_array_equal(as_vector([1, 2, 3], "q", 3), [1.0, 2.0, 3.0])
    assert as_array(np.zeros((4, 2)), "Q", (None, 2)).dtype == np.float64
    assert positive(0.01, "dt") == 0.01


@pytest.mark.parametrize(
    ("value", "message"),
    [([1, 2], r"^q: expected shape \(3,\), got \(2,\)"),
     ([1, np.nan, 3], r"^q: non-finite entry nan at index \(1,\)"),
     ([1, 2, -np.inf], r"^q: non-finite entry -inf"),
     ("abc", r"^q: expected a numeric array"),
     ([[1, 2, 3]], r"^q: expected shape \(3,\)")],
)
def test_bad_vectors_name_the_argument(value, message):
    with pytest.raises(InputError, match=message) as info:
        as_vector(value, "q", 3)
    assert info.value.argument == "q"
    assert isinstance(info.value, ValueError)


def test_batch_shape_and_positive():
    with pytest.raises(InputError, match=r"^X: expected shape \(N, 6\)"):
        as_array(np.zeros((3, 5)), "X", (None, 6))
    for bad in (0.0, -1.0, np.nan, np.inf, "x"):
        with pytest.raises(InputError, match="^dt:"):
            positive(bad, "dt")
