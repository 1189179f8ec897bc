"""Argument checks shared by every kernel: shape and finiteness, before any computation."""

from __future__ import annotations

from math import isfinite

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.errors import InvalidInput
from rrc_pin.solvers.tick import kernels

_F64 = np.dtype(np.float64)


def as_vector(
    x: npt.ArrayLike, name: str, size: int
) -> npt.NDArray[np.float64]:
    """Return ``x`` as a finite float vector of shape ``(size,)``.

    Args:
        x: Value to check.
        name: Argument name used in the error message.
        size: Expected length.

    Raises:
        InvalidInput: Wrong shape, non-numeric, NaN or inf.
    """
    return as_array(x, name, (size,))


def as_array(
    x: npt.ArrayLike,
    name: str,
    shape: tuple[int | None, ...],
) -> npt.NDArray[np.float64]:
    """Return ``x`` as a finite float array of the given shape (``None`` matches any size).

    Raises:
        InvalidInput: Wrong shape, not real numbers (booleans, complex numbers and strings are
            refused), NaN or inf.
    """
    if type(x) is np.ndarray and x.dtype == _F64 and x.shape == shape:  # the common case
        if not all_finite(x):
            _non_finite(x, name)
        return x
    arr = real_array(x, name, f"expected a real numeric array of shape {_fmt(shape)}")
    if arr.ndim != len(shape) or any(
        want is not None and got != want for got, want in zip(arr.shape, shape, strict=True)
    ):
        raise InvalidInput(name, f"expected shape {_fmt(shape)}, got {arr.shape}")
    if not all_finite(arr):
        _non_finite(arr, name)
    return arr


def all_finite(x: npt.NDArray[np.float64]) -> bool:
    """Whether every entry of ``x`` is finite (no NaN or infinity)."""
    return kernels.all_finite(x.reshape(-1))


def real_array(
    x: npt.ArrayLike,
    name: str,
    want: str = "expected real numbers",
) -> npt.NDArray[np.float64]:
    """``x`` as a float array of any shape (infinities and NaN kept), real numbers only.

    Raises:
        InvalidInput: Booleans (alone, as an array or inside a list: ``[0.1, True]``), complex
            numbers, strings, objects or ragged sequences.
    """
    try:
        raw = np.asarray(x)
    except (TypeError, ValueError) as exc:  # ragged sequences
        raise InvalidInput(name, f"{want}, got {x!r}") from exc
    if raw.dtype.kind not in "fiu" or (type(x) is not np.ndarray and _holds_bool(x)):
        # booleans, complex numbers, strings and objects; numpy makes [0.1, True] floats
        raise InvalidInput(name, f"{want}, got {x!r}")
    return raw.astype(np.float64, copy=False)


def _holds_bool(x: object) -> bool:
    """Whether the nested lists and tuples ``x`` hold a boolean (Python's or numpy's)."""
    if type(x) is not list and type(x) is not tuple:
        return isinstance(x, (bool, np.bool_)) or (
            isinstance(x, np.ndarray) and x.dtype.kind == "b"
        )
    kinds = set(map(type, x))
    if bool in kinds or np.bool_ in kinds:
        return True
    nested = kinds & {list, tuple, np.ndarray}
    return bool(nested) and any(_holds_bool(v) for v in x if type(v) in nested)


def _non_finite(arr: npt.NDArray[np.float64], name: str) -> None:
    bad = np.argwhere(~np.isfinite(arr))[0]
    where = tuple(int(i) for i in bad)
    raise InvalidInput(name, f"non-finite entry {arr[tuple(bad)]} at index {where}")


def finite_number(
    value: float,
    name: str,
    lower: float | None = None,
    inclusive: bool = True,
    upper: float | None = None,
) -> float:
    """Return ``value`` as a finite float, optionally bounded.

    Args:
        value: Value to check.
        name: Argument name used in the error message.
        lower: Lower bound, or None for none.
        inclusive: Whether ``value == lower`` is accepted.
        upper: Exclusive upper bound, or None for none.

    Raises:
        InvalidInput: ``value`` is not a real number (a bool or a string is refused), not
            finite, or out of bounds; the message
            states the expected range (``>= 0``, ``> 0``, ``in (0, 1)``, ``in [0, 0.5)``).
    """
    real = (int, float, np.integer, np.floating)  # not complex numbers (np.number)
    if isinstance(value, (bool, np.bool_, np.timedelta64)) or not isinstance(value, real):
        raise InvalidInput(name, f"expected {_wanted(lower, inclusive, upper)}, got {value!r}")
    try:
        out = float(value)
    except OverflowError:  # an int beyond the float range
        got = f"an int of {len(str(value))} digits"
        wanted = _wanted(lower, inclusive, upper)
        raise InvalidInput(name, f"expected {wanted}, got {got}") from None
    if (
        not isfinite(out)
        or (lower is not None and (out < lower or (out == lower and not inclusive)))
        or (upper is not None and out >= upper)
    ):
        raise InvalidInput(name, f"expected {_wanted(lower, inclusive, upper)}, got {out}")
    return out


def _wanted(lower: float | None, inclusive: bool, upper: float | None) -> str:
    """The range :func:`finite_number` expects, in words."""
    if lower is None and upper is None:
        return "a finite number"
    if upper is None:
        return f"a finite number {'>=' if inclusive else '>'} {lower:g}"
    if lower is None:
        return f"a finite number < {upper:g}"
    return f"a finite number in {'[' if inclusive else '('}{lower:g}, {upper:g})"


def positive(x: float, name: str) -> float:
    """Return ``x`` as a float if it is finite and > 0.

    Raises:
        InvalidInput: ``x`` is not a finite positive number.
    """
    return finite_number(x, name, 0.0, inclusive=False)


def _fmt(shape: tuple[int | None, ...]) -> str:
    return (
        "("
        + ", ".join("N" if s is None else str(s) for s in shape)
        + ("," if len(shape) == 1 else "")
        + ")"
    )


RIGID_TOL = 1e-9
"""Largest departure of a pose from a rigid transform (R^T R - I, last row) accepted."""


def rigid_transform(
    x: npt.ArrayLike, name: str
) -> npt.NDArray[np.float64]:
    """``x`` as a (4, 4) rigid transform (a rotation and a translation, within :data:`RIGID_TOL`).

    Raises:
        InvalidInput: Wrong shape, a non-finite entry, or not a rigid transform.
    """
    T = as_array(x, name, (4, 4))
    R = T[:3, :3]
    rigid = (
        np.abs(R.T @ R - np.eye(3)).max() <= RIGID_TOL
        and np.linalg.det(R) > 0.0
        and np.abs(T[3] - (0.0, 0.0, 0.0, 1.0)).max() <= RIGID_TOL
    )
    if not rigid:
        raise InvalidInput(name, f"not a rigid transform: {T.tolist()}")
    return T
