"""Argument checks: shape, finiteness, bounds and positivity, with the argument named."""

from __future__ import annotations

import numpy as np
import pytest

from solvers.errors import InputError
from solvers.validation import as_array, as_float_list, as_vector, finite_number, positive


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


class _MyError(InputError):
    """A caller's own subclass, as rrc_pin passes one."""


def test_as_float_list_fast_path_and_general_input_agree():
    rng = np.random.default_rng(7)
    x = rng.normal(size=6)
    fast = as_float_list(x, "q", 6)
    assert type(fast) is list and all(type(v) is float for v in fast)
    assert fast == x.tolist()
    assert as_float_list([1, 2, 3], "q", 3) == [1.0, 2.0, 3.0]  # ints, a list: general path
    assert as_float_list(np.arange(3), "q", 3) == [0.0, 1.0, 2.0]
    assert as_float_list(x[::2], "q", 3) == x[::2].tolist()  # a strided view
    big = np.array([1e308, 1e308])  # finite entries whose sum overflows: still accepted
    assert as_float_list(big, "q", 2) == [1e308, 1e308]


@pytest.mark.parametrize(
    ("value", "message"),
    [(np.array([0.0, np.nan, 1.0]), r"^q: non-finite entry nan at index \(1,\)"),
     (np.array([np.inf, -np.inf, 0.0]), r"^q: non-finite entry inf at index \(0,\)"),
     (np.zeros(4), r"^q: expected shape \(3,\), got \(4,\)"),
     (np.zeros((1, 3)), r"^q: expected shape \(3,\), got \(1, 3\)"),
     ([0, 0, "x"], r"^q: expected a numeric array"),
     (None, r"^q: expected shape")],
)
def test_as_float_list_names_the_argument(value, message):
    with pytest.raises(InputError, match=message) as info:
        as_float_list(value, "q", 3)
    assert info.value.argument == "q"
    with pytest.raises(_MyError):
        as_float_list(value, "q", 3, _MyError)


def test_finite_number_accepts_and_bounds():
    assert finite_number(np.float32(0.5), "x") == 0.5
    assert type(finite_number(np.int64(3), "x")) is float
    assert finite_number(-1e300, "x") == -1e300
    assert finite_number(0.0, "a1", 0.0) == 0.0  # inclusive lower bound
    assert finite_number(0.0, "rcond", 0.0, upper=0.5) == 0.0
    assert finite_number(0.4999, "rcond", 0.0, upper=0.5) == 0.4999
    assert finite_number(1e-300, "a2", 0.0, inclusive=False) == 1e-300


@pytest.mark.parametrize(
    ("value", "bounds", "message"),
    [("abc", {}, r"^x: expected a finite number, got 'abc'$"),
     (None, {}, r"^x: expected a finite number, got None$"),
     (np.nan, {}, r"^x: expected a finite number, got nan$"),
     (-np.inf, {"lower": 0.0}, r"^x: expected a finite number >= 0, got -inf$"),
     (-1.0, {"lower": 0.0}, r"^x: expected a finite number >= 0, got -1.0$"),
     (0.0, {"lower": 0.0, "inclusive": False}, r"^x: expected a finite number > 0, got 0.0$"),
     (1.0, {"lower": 0.0, "inclusive": False, "upper": 1.0},
      r"^x: expected a finite number in \(0, 1\), got 1.0$"),
     (0.7, {"lower": 0.0, "upper": 0.5}, r"^x: expected a finite number in \[0, 0.5\), got 0.7$"),
     (2.0, {"upper": 1e-3}, r"^x: expected a finite number < 0.001, got 2.0$")],
)  # fmt: skip
def test_finite_number_states_the_expected_range(value, bounds, message):
    with pytest.raises(InputError, match=message) as info:
        finite_number(value, "x", **bounds)
    assert info.value.argument == "x"
    with pytest.raises(_MyError):
        finite_number(value, "x", **bounds, error=_MyError)


def test_positive_is_finite_number_above_zero():
    with pytest.raises(InputError, match=r"^dt: expected a finite number > 0, got 0.0$"):
        positive(0.0, "dt")
    with pytest.raises(_MyError, match="^dt:"):
        positive(-1.0, "dt", _MyError)
