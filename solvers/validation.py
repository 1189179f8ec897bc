"""Argument checks shared by every kernel: shape and finiteness, before any computation."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from solvers.errors import InputError


def as_vector(
    x: npt.ArrayLike, name: str, size: int, error: type[InputError] = InputError
) -> npt.NDArray[np.float64]:
    """Return ``x`` as a finite float vector of shape ``(size,)``.

    Args:
        x: Value to check.
        name: Argument name used in the error message.
        size: Expected length.
        error: Exception class to raise (a subclass of :class:`InputError`).

    Raises:
        InputError: Wrong shape, non-numeric, NaN or inf.
    """
    return as_array(x, name, (size,), error)


def as_array(
    x: npt.ArrayLike,
    name: str,
    shape: tuple[int | None, ...],
    error: type[InputError] = InputError,
) -> npt.NDArray[np.float64]:
    """Return ``x`` as a finite float array of the given shape (``None`` matches any size).

    Raises:
        InputError: Wrong shape, non-numeric, NaN or inf.
    """
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise error(name, f"expected a numeric array of shape {_fmt(shape)}, got {x!r}") from exc
    if arr.ndim != len(shape) or any(
        want is not None and got != want for got, want in zip(arr.shape, shape, strict=True)
    ):
        raise error(name, f"expected shape {_fmt(shape)}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))[0]
        raise error(
            name, f"non-finite entry {arr[tuple(bad)]} at index {tuple(int(i) for i in bad)}"
        )
    return arr


def positive(x: float, name: str, error: type[InputError] = InputError) -> float:
    """Return ``x`` as a float if it is finite and > 0.

    Raises:
        InputError: ``x`` is not a finite positive number.
    """
    try:
        value = float(x)
    except (TypeError, ValueError) as exc:
        raise error(name, f"expected a positive number, got {x!r}") from exc
    if not np.isfinite(value) or value <= 0.0:
        raise error(name, f"expected a finite number > 0, got {value}")
    return value


def _fmt(shape: tuple[int | None, ...]) -> str:
    return (
        "("
        + ", ".join("N" if s is None else str(s) for s in shape)
        + ("," if len(shape) == 1 else "")
        + ")"
    )
