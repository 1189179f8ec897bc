"""Argument checks: real numbers only, shape and finiteness, bounds, the argument named."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from rrc_pin.solvers.checks import as_array, as_vector, finite_number, positive
from rrc_pin.solvers.errors import InvalidInput


def test_good_input_comes_back_as_float_arrays(rng: np.random.Generator) -> None:
    x = rng.standard_normal(6)
    for value, want in (
        ([1, 2, 3], [1.0, 2.0, 3.0]),
        ((1.5, -2, 0), [1.5, -2.0, 0.0]),
        (np.arange(3), [0.0, 1.0, 2.0]),
        (np.array([1, 2, 3], dtype=np.uint8), [1.0, 2.0, 3.0]),
        (np.array([0.5, 1, 2], dtype=np.float32), [0.5, 1.0, 2.0]),
        (x[::2], x[::2]),  # a strided view
        ([np.float64(1), np.int32(2), 3], [1.0, 2.0, 3.0]),
    ):
        got = as_vector(value, "q", 3)
        assert got.dtype == np.float64 and got.shape == (3,)
        np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(as_vector(x, "q", 6), x)  # the common case, unchanged
    assert as_array(np.zeros((4, 2)), "Q", (None, 2)).shape == (4, 2)
    assert as_array([[1, 2]] * 5, "Q", (5, None)).dtype == np.float64
    assert as_array(1.5, "s", ()).shape == ()
    assert as_vector([1e308, -1e308], "q", 2)[0] == 1e308  # finite, however large


@pytest.mark.parametrize(
    "value",
    [[True, False, True],
     np.array([True, False, True]),
     [0.5, True, 0.0],  # issue 28 item 8: numpy makes the boolean a float
     (1, 2, np.True_),
     [np.float64(1), False, 2],
     [1j, 0, 0],
     np.array([1, 2, 3], dtype=complex),
     "abc",
     ["1", "2", "3"],
     np.array(["1", "2", "3"]),
     [[1, 2], [3]],  # ragged
     [[1, 2, 3], [4, 5]],
     [1, [2, 3], 4],
     None,
     [None, 1, 2],
     {"a": 1},
     np.array([1, 2, 3], dtype=object),
     np.array(["2020-01-01"] * 3, dtype="datetime64[D]")],
)  # fmt: skip
def test_what_is_not_real_numbers_is_refused(value: object) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # refused outright: no ComplexWarning, no cast
        with pytest.raises(InvalidInput, match=r"^q: expected a real numeric array of shape \(3,\)"
                           ) as info:  # fmt: skip
            as_vector(value, "q", 3)  # type: ignore[arg-type]
    assert info.value.argument == "q"
    assert info.value.reason.startswith("expected a real numeric array")
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize(
    ("value", "message"),
    [([1, 2], r"^q: expected shape \(3,\), got \(2,\)$"),
     ([[1, 2, 3]], r"^q: expected shape \(3,\), got \(1, 3\)$"),
     (3.0, r"^q: expected shape \(3,\), got \(\)$"),
     ([], r"^q: expected shape \(3,\), got \(0,\)$"),
     ([1, np.nan, 3], r"^q: non-finite entry nan at index \(1,\)$"),
     ([1, 2, -np.inf], r"^q: non-finite entry -inf at index \(2,\)$"),
     (np.array([np.inf, np.nan, 0.0]), r"^q: non-finite entry inf at index \(0,\)$")],
)  # fmt: skip
def test_bad_shapes_and_non_finite_entries_name_the_argument(value: object, message: str) -> None:
    with pytest.raises(InvalidInput, match=message) as info:
        as_vector(value, "q", 3)  # type: ignore[arg-type]
    assert info.value.argument == "q"


def test_batch_shapes() -> None:
    with pytest.raises(InvalidInput, match=r"^X: expected shape \(N, 6\), got \(3, 5\)$"):
        as_array(np.zeros((3, 5)), "X", (None, 6))
    with pytest.raises(InvalidInput, match=r"^X: expected shape \(N, 6\), got \(6,\)$"):
        as_array(np.zeros(6), "X", (None, 6))
    with pytest.raises(InvalidInput, match=r"^X: non-finite entry nan at index \(2, 4\)$"):
        bad = np.zeros((3, 6))
        bad[2, 4] = np.nan
        as_array(bad, "X", (None, 6))
    with pytest.raises(InvalidInput, match=r"^X: expected a real numeric array of shape \(N, 6\)"):
        as_array(np.zeros((3, 6), dtype=bool), "X", (None, 6))


def test_finite_number_accepts_and_bounds() -> None:
    assert finite_number(np.float32(0.5), "x") == 0.5
    assert type(finite_number(np.int64(3), "x")) is float
    assert type(finite_number(3, "x")) is float
    assert finite_number(np.float16(0.25), "x") == 0.25
    assert finite_number(-1e300, "x") == -1e300
    assert finite_number(0.0, "a1", 0.0) == 0.0  # inclusive lower bound
    assert finite_number(0.0, "rcond", 0.0, upper=0.5) == 0.0
    assert finite_number(0.4999, "rcond", 0.0, upper=0.5) == 0.4999
    assert finite_number(1e-300, "a2", 0.0, inclusive=False) == 1e-300
    assert finite_number(-5.0, "x", upper=1.0) == -5.0


@pytest.mark.parametrize(
    "value",
    [True, False, np.bool_(True), "0.01", "abc", None, 1j, np.complex128(1.0), [0.1],
     np.array([0.1]), np.array(0.5), {}, np.timedelta64(1, "s"), 10**400],
)  # fmt: skip
def test_finite_number_refuses_what_is_not_a_real_number(value: object) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InvalidInput, match=r"^dt: expected a finite number") as info:
            finite_number(value, "dt")  # type: ignore[arg-type]
    assert info.value.argument == "dt"


@pytest.mark.parametrize(
    ("value", "bounds", "message"),
    [(np.nan, {}, r"^x: expected a finite number, got nan$"),
     (np.inf, {}, r"^x: expected a finite number, got inf$"),
     (-np.inf, {"lower": 0.0}, r"^x: expected a finite number >= 0, got -inf$"),
     (-1.0, {"lower": 0.0}, r"^x: expected a finite number >= 0, got -1.0$"),
     (0.0, {"lower": 0.0, "inclusive": False}, r"^x: expected a finite number > 0, got 0.0$"),
     (1.0, {"lower": 0.0, "inclusive": False, "upper": 1.0},
      r"^x: expected a finite number in \(0, 1\), got 1.0$"),
     (0.7, {"lower": 0.0, "upper": 0.5}, r"^x: expected a finite number in \[0, 0.5\), got 0.7$"),
     (2.0, {"upper": 1e-3}, r"^x: expected a finite number < 0.001, got 2.0$"),
     (True, {"lower": 0.0}, r"^x: expected a finite number >= 0, got True$"),
     ("1", {"lower": 0.0, "upper": 2.0}, r"^x: expected a finite number in \[0, 2\), got '1'$")],
)  # fmt: skip
def test_finite_number_states_the_expected_range(value: object, bounds: dict, message: str) -> None:
    with pytest.raises(InvalidInput, match=message) as info:
        finite_number(value, "x", **bounds)  # type: ignore[arg-type]
    assert info.value.argument == "x"


@pytest.mark.parametrize("dt", [True, "0.01", 0.0, -0.01, np.nan, np.inf, None])
def test_positive_refuses_dt(dt: object) -> None:
    with pytest.raises(InvalidInput, match=r"^dt: expected a finite number > 0, got ") as info:
        positive(dt, "dt")  # type: ignore[arg-type]
    assert info.value.argument == "dt"


def test_positive() -> None:
    assert positive(0.01, "dt") == 0.01
    assert positive(np.float32(2.0), "dt") == 2.0
    assert positive(1, "dt") == 1.0
