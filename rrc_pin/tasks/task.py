"""What every task is: rows ``A qdot ~= b`` of one control tick (pink's Task pattern)."""

from __future__ import annotations

import functools
import math
from abc import ABC, abstractmethod
from typing import ClassVar

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import FrameNotFound, InvalidInput
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.solvers.checks import as_vector, finite_number
from rrc_pin.solvers.tick.problem import TaskRows

Array = npt.NDArray[np.float64]


class Task(ABC):
    """A task of a resolution: its Jacobian rows and desired rates at one tick.

    Attributes:
        name: Name in the resolution's report.
        weight: Cost of the task's squared residual (weighted priorities) and its rows' weight
            within a strict level; > 0, scalar or one per row.
        joint_rows: Whether each row is one joint's own rate (a row of the identity): a joint
            mask (``Resolver.mask``) drops the rows of the joints it holds, as a model without
            them would have none; other tasks keep every row.
    """

    name: str
    weight: float | Array
    joint_rows: ClassVar[bool] = False

    @abstractmethod
    def frames(self) -> tuple[str, ...]:
        """Frames the task reads (checked against the robot before anything is computed)."""

    @abstractmethod
    def rows(self, kin: Kinematics) -> TaskRows:
        """The rows ``A qdot ~= b`` (A: (m, nv)) at the configuration of ``kin``."""

    def check(self, layout: Layout) -> None:
        """Refuse a task that names what the robot does not have (before any computation).

        Raises:
            FrameNotFound: A frame the robot does not have (the error lists its frames).
            InvalidInput: Anything else that does not fit the robot.
        """
        for frame in self.frames():
            if frame not in layout.frames:
                raise FrameNotFound(frame, sorted(layout.frames), "frame")

    def _row_weights(self, m: int) -> Array | None:
        """The weight as (m,) row weights, or None when it is 1 everywhere.

        A scalar weight's rows are read-only and shared (:func:`row_weights`).
        """
        if isinstance(self.weight, float):  # check_weight gives a float or an (m,) array
            return None if self.weight == 1.0 else row_weights(self.weight, m)
        return None if (self.weight == 1.0).all() else self.weight


@functools.cache
def identity(n: int) -> Array:
    """The identity rows (n, n), read-only, made once per size (joint-space tasks' Jacobian)."""
    eye = np.eye(n)
    eye.flags.writeable = False
    return eye


@functools.lru_cache(maxsize=256)
def row_weights(weight: float, m: int) -> Array:
    """The rows (m,) of a scalar weight, read-only, made once per weight and size."""
    rows = np.full(m, weight)
    rows.flags.writeable = False
    return rows


def check_weight(weight: float | npt.ArrayLike, size: int | None = None) -> float | Array:
    """A task weight: a finite number > 0, or (size,) of them.

    Raises:
        InvalidInput: Not positive, not finite, or the wrong shape.
    """
    if type(weight) is float and 0.0 < weight < math.inf:  # the common case
        return weight
    if not isinstance(weight, (list, tuple, np.ndarray)):
        return finite_number(weight, "weight", 0.0, inclusive=False)  # type: ignore[arg-type]
    if size is None:
        raise InvalidInput("weight", f"expected a number > 0, got {weight!r}")
    w: Array = as_vector(weight, "weight", size).copy()  # the task's own
    if (w <= 0.0).any():
        raise InvalidInput("weight", f"expected weights > 0, got {w}")
    w.flags.writeable = False  # a task's rows may be kept per weight: replace it, not its values
    return w


def task_name(name: object) -> str:
    """A task's name for the report: a non-empty string.

    Raises:
        InvalidInput: Anything else, naming ``name``.
    """
    if not isinstance(name, str) or not name:
        raise InvalidInput("name", f"expected a non-empty string, got {name!r}")
    return name
