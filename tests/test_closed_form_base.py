"""The closed forms' shared helpers (solvers/closed_form/base.py): argument passing and checks."""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin.solvers.closed_form.base import finite, vector
from rrc_pin.solvers.errors import InvalidInput


def test_vector_passes_float_vectors_and_converts_the_rest() -> None:
    q = np.array([0.1, 0.2, 0.3])
    assert vector(q, "q", 3) is q  # the kernel checks size and entries
    assert vector(np.array([1.0, np.nan]), "q", 3).shape == (2,)  # refused by the kernel
    np.testing.assert_array_equal(vector([1, 2, 3], "q", 3), [1.0, 2.0, 3.0])
    assert vector(np.arange(3), "q", 3).dtype == np.float64
    for bad in (np.zeros((3, 1)), [1.0, 2.0], "abc", [True, 0.0, 0.0]):
        with pytest.raises(InvalidInput) as info:
            vector(bad, "q", 3)
        assert info.value.argument == "q"


def test_finite_checks_size_and_entries() -> None:
    assert finite(np.array([0.0, -1e300, 5e-324]), 3)
    assert not finite(np.array([0.0, 1.0]), 3)
    assert not finite(np.array([0.0, 1.0, 2.0, 3.0]), 3)
    for value in (np.nan, np.inf, -np.inf):
        assert not finite(np.array([0.0, value, 0.0]), 3)
