"""Argument checks shared by every kernel: shape and finiteness, before any computation."""

from __future__ import annotations

import math
from math import isfinite

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.errors import InvalidInput
from rrc_pin.solvers.tick import feasibility

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


def finite_array(x: npt.ArrayLike, name: str) -> npt.NDArray[np.float64]:
    """Return ``x`` as a finite float array of any shape (a ragged one refused).

    Raises:
        InvalidInput: Not real numbers, or NaN or inf.
    """
    arr = real_array(x, name)
    if not all_finite(arr):
        _non_finite(arr, name)
    return arr


def all_finite(x: npt.NDArray[np.float64]) -> bool:
    """Whether every entry of ``x`` is finite (no NaN or infinity)."""
    return feasibility.all_finite(x if x.ndim == 1 else x.reshape(-1))


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
    out = value if type(value) is float else _real_number(value, name, lower, inclusive, upper)
    if (
        not isfinite(out)
        or (lower is not None and (out < lower or (out == lower and not inclusive)))
        or (upper is not None and out >= upper)
    ):
        raise InvalidInput(name, f"expected {_wanted(lower, inclusive, upper)}, got {out}")
    return out


def _real_number(
    value: object, name: str, lower: float | None, inclusive: bool, upper: float | None
) -> float:
    """``value`` as a float if it is a real number (:func:`finite_number`'s bounds for the
    message)."""  # noqa: D205, D209
    real = (int, float, np.integer, np.floating)  # not complex numbers (np.number)
    if isinstance(value, (bool, np.bool_, np.timedelta64)) or not isinstance(value, real):
        raise InvalidInput(name, f"expected {_wanted(lower, inclusive, upper)}, got {value!r}")
    try:
        return float(value)
    except OverflowError:  # an int beyond the float range
        got = f"an int of {len(str(value))} digits"
        wanted = _wanted(lower, inclusive, upper)
        raise InvalidInput(name, f"expected {wanted}, got {got}") from None


def integer(value: object, name: str, lower: int | None = None, upper: int | None = None) -> int:
    """Return ``value`` as an int, optionally within ``[lower, upper]``.

    Raises:
        InvalidInput: ``value`` is not an integer (a bool, a float, a string are refused), or
            outside the bounds; the message states the expected range.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise InvalidInput(name, f"expected {_integer_range(lower, upper)}, got {_brief(value)}")
    out = int(value)
    if (lower is not None and out < lower) or (upper is not None and out > upper):
        got = f"an int of {len(str(out))} digits" if abs(out) > 10**30 else str(out)
        raise InvalidInput(name, f"expected {_integer_range(lower, upper)}, got {got}")
    return out


def flag(value: bool, name: str) -> bool:
    """Return ``value`` as a bool: True or False only (numpy's too; not 1, not an array).

    Raises:
        InvalidInput: ``value`` is not a boolean.
    """
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidInput(name, f"expected True or False, got {_brief(value)}")
    return bool(value)


def choice(value: str, name: str, choices: tuple[str, ...]) -> str:
    """Return ``value``, a string among ``choices``.

    Raises:
        InvalidInput: ``value`` is not one of them (an array or an unhashable included); the
            message lists them.
    """
    if not isinstance(value, str) or value not in choices:
        options = ", ".join(repr(c) for c in choices)
        raise InvalidInput(name, f"expected one of {options}, got {_brief(value)}")
    return value


def names(value: object, name: str, size: int | None = None) -> tuple[str, ...]:
    """Return ``value`` as a tuple of strings: one string, or a list or tuple of them.

    Args:
        value: What to check.
        name: Argument name used in the error message.
        size: The number of names expected, or None for any.

    Raises:
        InvalidInput: Not a string nor a list or tuple of strings (an array, a set, a number
            refused), or not ``size`` of them.
    """
    items = (value,) if isinstance(value, str) else value
    if not isinstance(items, (list, tuple)) or not all(isinstance(v, str) for v in items):
        raise InvalidInput(name, f"expected names (str, or a list of them), got {_brief(value)}")
    if size is not None and len(items) != size:
        raise InvalidInput(name, f"expected {size} names, got {len(items)}: {_brief(value)}")
    return tuple(items)


def _brief(value: object, limit: int = 60) -> str:
    """``repr(value)`` cut to ``limit`` characters (an error names a huge array briefly)."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _integer_range(lower: int | None, upper: int | None) -> str:
    """The range :func:`integer` expects, in words."""
    if lower is None and upper is None:
        return "an integer"
    if upper is None:
        return f"an integer >= {lower}"
    if lower is None:
        return f"an integer <= {upper}"
    return f"an integer in [{lower}, {upper}]"


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

MAX_LENGTH = 1e9
"""[m] The largest translation of a pose accepted: far beyond any robot's workspace, and
small enough that distances, their squares and products never overflow."""


def length(value: float, name: str, lower: float = 0.0, inclusive: bool = False) -> float:
    """A length [m]: a finite number above ``lower`` (``> 0`` by default), below
    :data:`MAX_LENGTH`.

    Raises:
        InvalidInput: Not such a number.
    """  # noqa: D205
    try:
        return finite_number(value, name, lower, inclusive, upper=MAX_LENGTH)
    except InvalidInput as exc:
        got = exc.reason.rsplit(", got ", 1)[-1]
        wanted = f"{'>=' if inclusive else '>'} {lower:g} [m] (below {MAX_LENGTH:g})"
        raise InvalidInput(name, f"expected a finite length {wanted}, got {got}") from None


def within_length(x: npt.NDArray[np.float64], name: str) -> npt.NDArray[np.float64]:
    """``x``, whose entries are lengths [m] within :data:`MAX_LENGTH` of zero.

    Raises:
        InvalidInput: An entry beyond it.
    """
    if np.abs(x).max(initial=0.0) > MAX_LENGTH:
        raise InvalidInput(name, f"an entry beyond {MAX_LENGTH:g} m: {_brief(x.tolist())}")
    return x


def direction(x: npt.ArrayLike, name: str) -> tuple[npt.NDArray[np.float64], float]:
    """``x`` (3,) as a unit vector, and its norm (which may be inf: no entry is).

    Raises:
        InvalidInput: Not a finite (3,) vector, or zero.
    """
    v = as_vector(x, name, 3)
    top = float(np.abs(v).max())
    if top < 1e-300:
        raise InvalidInput(name, f"expected a non-zero vector, got {v.tolist()}")
    scaled = v / top  # no overflow in the norm
    size = math.hypot(*scaled.tolist())
    return scaled / size, top * size


def rigid_transform(
    x: npt.ArrayLike, name: str
) -> npt.NDArray[np.float64]:
    """``x`` as a (4, 4) rigid transform (a rotation and a translation, within :data:`RIGID_TOL`).

    Raises:
        InvalidInput: Wrong shape, a non-finite entry, or not a rigid transform.
    """
    T = as_array(x, name, (4, 4))
    R = T[:3, :3]
    with np.errstate(over="ignore", invalid="ignore"):  # huge entries: not rigid, refused
        rigid = (
            np.abs(R.T @ R - np.eye(3)).max() <= RIGID_TOL
            and np.linalg.det(R) > 0.0
            and np.abs(T[3] - (0.0, 0.0, 0.0, 1.0)).max() <= RIGID_TOL
        )
    if not rigid:
        raise InvalidInput(name, f"not a rigid transform: {T.tolist()}")
    if np.abs(T[:3, 3]).max() > MAX_LENGTH:
        raise InvalidInput(name, f"a translation beyond {MAX_LENGTH:g} m: {T[:3, 3].tolist()}")
    return T
