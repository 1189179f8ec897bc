"""The resolver users run at every control tick: a commanded twist in, joint rates out.

:class:`Resolver` joins an arm (its Jacobian from Pinocchio, or from the paper's closed form)
to the numerical chain of :mod:`solvers.resolution`: the joint-rate bounds of the step
(velocity, position over one step with a margin, optional acceleration; a start outside the
limits asks only to move back), the QP (warm-started backend), and the fallbacks. Bad input
raises :class:`~rrc_pin.errors.InvalidInput` naming the argument before any state changes;
numerical trouble never raises (the :class:`~solvers.resolution_record.Resolution` says which
method answered).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, Literal

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import InvalidInput
from rrc_pin.robot import PIN_REFERENCE, Robot, frame_id
from solvers.dls import Damping, weight_factor
from solvers.errors import InputError
from solvers.joint_bounds import JointLimits
from solvers.resolution import ResolutionChain
from solvers.resolution_record import Resolution
from solvers.spatial import REFERENCES, Reference, check_reference
from solvers.validation import as_vector, positive

Array = npt.NDArray[np.float64]

TASKS: dict[str, tuple[int, ...]] = {
    "full": (0, 1, 2, 3, 4, 5),
    "position": (0, 1, 2),
    "orientation": (3, 4, 5),
}
"""Named task row selections of the [v; w] twist."""


class Resolver:
    """Joint rates for commanded twists, inside the joint limits, at every control tick.

    Args:
        arm: A :class:`rrc_pin.Robot` (or anything with ``nq``, ``lower``, ``upper``,
            ``velocity_limit``, ``jacobian(q, ref)``, ``joint_names`` and ``closed_form``).
        dt: Control period [s], > 0 (``solve`` may override it per call).
        backend: QP backend name (:func:`solvers.qp_backends.installed_backends`; default the
            native, warm-started OSQP), or None for damped least squares without a QP.
        fallbacks: Methods tried after the QP, in order (``"dls"``, ``"scaling"``,
            ``"hold"``); default ``("scaling", "dls")`` when ``direction_preserving``,
            else ``("dls", "scaling")``. ``"hold"`` always ends the chain.
        task_weights: Task weights W over the selected rows: (m,) positive or (m, m) SPD.
        damping: Adaptive damping schedule (default :class:`solvers.dls.Damping()`).
        margin: Distance kept from every position limit [rad or m], >= 0.
        direction_preserving: When the command cannot be met, slow down along its direction
            (maximise the scale s) instead of distorting it; the least-squares tracking QP is
            used for steps where a joint must recover into its range.
        task: Rows of the twist to track: ``"full"`` (6), ``"position"`` (0:3),
            ``"orientation"`` (3:6), a boolean mask (6,) or row indices. Default ``"full"``
            for arms of six joints or more, ``"position"`` below.
        priority: ``"soft"`` (secondary objective in the cost, null space only) or
            ``"strict"`` (a second QP in the primary's null space).
        secondary_weight: Weight in (0, 1) of the secondary objective.
        acceleration_limit: Joint acceleration limits [rad/s^2], scalar or (nq,), or None.
        velocity_limit: Joint velocity limits (nq,) replacing the arm's (which must then be
            finite).
        position_gain: Fraction in (0, 1] of the distance to a position bound allowed per step.
        use_closed_form: Take the Jacobian from ``arm.closed_form`` (``world_aligned`` only).
        shortcut: Skip the backend when the QP's solution is known without it: the box-free
            optimum when it is feasible, the exact solution on a guessed active set when it
            passes the optimality check (:mod:`solvers.active_set`).
        active_tol: Distance to a bound under which it is reported active [rad/s].
        backend_options: Settings for the backend (e.g. OSQP ``eps_abs``).

    Raises:
        InvalidInput: Non-positive dt, invalid limits, task, weights, margin or options.
        BackendNotFound: Unknown backend name (the error lists the installed ones).
    """

    def __init__(
        self,
        arm: Any,
        dt: float = 0.01,
        backend: str | None = "osqp",
        fallbacks: Sequence[str] | None = None,
        task_weights: npt.ArrayLike | None = None,
        damping: Damping | None = None,
        margin: float = 0.0,
        direction_preserving: bool = True,
        *,
        task: str | Sequence[int] | Sequence[bool] | None = None,
        priority: Literal["soft", "strict"] = "soft",
        secondary_weight: float = 1e-2,
        acceleration_limit: npt.ArrayLike | None = None,
        velocity_limit: npt.ArrayLike | None = None,
        position_gain: float = 1.0,
        use_closed_form: bool = False,
        shortcut: bool = True,
        active_tol: float = 1e-6,
        backend_options: dict[str, Any] | None = None,
    ) -> None:
        self.arm = arm
        self.nq = int(arm.nq)
        self.dt = positive(dt, "dt", InvalidInput)
        v = arm.velocity_limit if velocity_limit is None else velocity_limit
        v = as_vector(v, "velocity_limit", self.nq, InvalidInput)
        if not 0.0 < position_gain <= 1.0:
            raise InvalidInput("position_gain", f"expected (0, 1], got {position_gain!r}")
        self.position_gain = float(position_gain)
        try:
            self.limits = JointLimits(arm.lower, arm.upper, v, margin, acceleration_limit)
        except InputError as exc:
            raise _invalid(exc, {"v_max": "velocity_limit", "a_max": "acceleration_limit"}) from exc
        self.rows = _task_rows(task, self.nq)
        self.closed_form = _closed_form(arm, self.rows) if use_closed_form else None
        try:
            self.factor = weight_factor(task_weights, len(self.rows), "task_weights")
        except InputError as exc:
            raise _invalid(exc) from exc
        if fallbacks is None:
            fallbacks = ("scaling", "dls") if direction_preserving else ("dls", "scaling")
        methods = tuple(fallbacks) if backend is None else ("qp", *fallbacks)
        try:
            self.chain = ResolutionChain(
                backend=backend,
                methods=methods,
                damping=damping,
                direction_preserving=direction_preserving,
                priority=priority,
                secondary_weight=secondary_weight,
                shortcut=shortcut,
                active_tol=active_tol,
                backend_options=backend_options,
            )
        except InputError as exc:
            raise _invalid(exc) from exc
        self.joint_names = list(getattr(arm, "joint_names", [])) or None
        self._pin = _pinocchio_jacobian(arm) if self.closed_form is None else None
        self._row_index = None if self.rows == TASKS["full"] else np.array(self.rows)
        self._twist_shape = (len(self.rows),)
        self._last_qdot: Array | None = None
        self._steps = 0

    @property
    def task_dim(self) -> int:
        """Number of task rows tracked."""
        return len(self.rows)

    def reset(self) -> None:
        """Forget the warm start and the previous joint rates."""
        self.chain.reset()
        self._last_qdot = None
        self._steps = 0

    def warm_start_state(self) -> dict[str, Any]:
        """Copies of every value that carries over to the next ``solve``."""
        state: dict[str, Any] = dict(self.chain.warm_start_state())
        state["last_qdot"] = None if self._last_qdot is None else self._last_qdot.copy()
        state["steps"] = self._steps
        return state

    def solve(
        self,
        q: npt.ArrayLike,
        twist: npt.ArrayLike,
        ref: Reference = "world_aligned",
        qdot_prev: npt.ArrayLike | None = None,
        secondary: npt.ArrayLike | None = None,
        dt: float | None = None,
    ) -> Resolution:
        """Joint rates realising ``twist`` at ``q`` at best, within this step's limits.

        Args:
            q: Joint positions (nq,) [rad or m].
            twist: Commanded twist [v; w] (6,) [m/s, rad/s] in frame ``ref``, or only the
                task rows (task_dim,).
            ref: ``world_aligned`` (default), ``local`` or ``world`` (see
                :mod:`solvers.spatial`).
            qdot_prev: Previous joint rates (nq,) for the acceleration limits; default the
                rates this resolver returned last (zero at the first step).
            secondary: Desired joint rates (nq,) [rad/s] for the secondary objective
                (posture, joint centring, manipulability gradient...), or None.
            dt: Step [s] for this call; default the constructor's.

        Returns:
            The :class:`~solvers.resolution_record.Resolution` (finite, within the bounds).

        Raises:
            InvalidInput: Wrong shape or non-finite q, twist, qdot_prev or secondary, unknown
                ref (or not ``world_aligned`` with the closed form), non-positive dt. Raised
                before any state changes.
        """
        q = _vector(q, "q", self.nq)
        twist = self._task_twist(twist)
        if ref not in REFERENCES:
            check_reference(ref, InvalidInput)
        if self.closed_form is not None and ref != "world_aligned":
            raise InvalidInput("ref", f"the closed form gives world_aligned Jacobians, got {ref!r}")
        if qdot_prev is not None:
            qdot_prev = _vector(qdot_prev, "qdot_prev", self.nq)
        if secondary is not None:
            secondary = _vector(secondary, "secondary", self.nq)
        step = self.dt if dt is None else positive(dt, "dt", InvalidInput)

        J = self._jacobian(q, ref)
        prev = None
        if self.limits.a_max is not None:
            prev = qdot_prev if qdot_prev is not None else self._last_qdot
        bounds = self.limits.bounds(q, step, self.position_gain, prev)
        result = self.chain.resolve(
            J, twist, bounds, secondary, self.factor, self.joint_names, validate=False
        )
        # kept for the next acceleration bound (a copy: the caller may modify its result)
        self._last_qdot = result.qdot if self.limits.a_max is None else result.qdot.copy()
        self._steps += 1
        return result

    def _task_twist(self, twist: npt.ArrayLike) -> Array:
        if type(twist) is np.ndarray and twist.shape == self._twist_shape:
            return _vector(twist, "twist", self._twist_shape[0])
        size = np.shape(twist)
        if size == (6,) and self.task_dim != 6:
            return _vector(twist, "twist", 6)[list(self.rows)]
        if size != (self.task_dim,):
            want = "(6,)" if self.task_dim == 6 else f"(6,) or ({self.task_dim},)"
            raise InvalidInput("twist", f"expected shape {want}, got {size}")
        return _vector(twist, "twist", self.task_dim)

    def _jacobian(self, q: Array, ref: Reference) -> Array:
        if self._pin is not None:
            compute, model, data, frame, frames = self._pin
            J = compute(model, data, q, frame, frames[ref])
        elif self.closed_form is not None:
            J = np.asarray(self.closed_form.jacobian(q), dtype=np.float64)
        else:
            J = np.asarray(self.arm.jacobian(q, ref), dtype=np.float64)
        return J if self._row_index is None else J[self._row_index]


_FLOAT64 = np.dtype(np.float64)


def _vector(x: npt.ArrayLike, name: str, n: int) -> Array:
    """``x`` as a finite float (n,) array; no numpy call when it is one already."""
    if type(x) is np.ndarray and x.dtype is _FLOAT64 and x.shape == (n,):
        # a sum of finite floats overflows only past 1e307: then as_vector decides
        if math.isfinite(sum(x.tolist())):
            return x
    return as_vector(x, name, n, InvalidInput)


def _invalid(exc: InputError, rename: dict[str, str] | None = None) -> InvalidInput:
    """The solvers' InputError as this package's InvalidInput (same argument, renamed)."""
    if isinstance(exc, InvalidInput):
        return exc
    argument = (rename or {}).get(exc.argument, exc.argument)
    return InvalidInput(argument, str(exc).split(": ", 1)[-1])


def _pinocchio_jacobian(arm: Any) -> tuple[Any, ...] | None:
    """Arguments of a direct ``pinocchio.computeFrameJacobian`` call, or None.

    For a :class:`rrc_pin.Robot` whose Pinocchio configuration is the joint vector (no
    continuous joints). ``Robot.jacobian`` checks q again and maps it to Pinocchio's
    configuration; the resolver has checked q already, so it calls Pinocchio directly (same
    model, data and frame).
    """
    if not isinstance(arm, Robot) or arm.model.nq != arm.nq or arm.model.nv != arm.nq:
        return None
    frame = frame_id(arm.model, arm.tool_frame)
    return (pin.computeFrameJacobian, arm.model, arm.data, frame, PIN_REFERENCE)


def _task_rows(task: Any, nq: int) -> tuple[int, ...]:
    if task is None:
        return TASKS["full"] if nq >= 6 else TASKS["position"]
    if isinstance(task, str):
        if task not in TASKS:
            raise InvalidInput("task", f"expected one of {', '.join(TASKS)} or rows, got {task!r}")
        return TASKS[task]
    arr = np.asarray(task)
    if arr.dtype == bool:
        if arr.shape != (6,):
            raise InvalidInput("task", f"a boolean mask must have shape (6,), got {arr.shape}")
        rows = tuple(int(i) for i in np.flatnonzero(arr))
    else:
        if arr.ndim != 1 or not np.issubdtype(arr.dtype, np.integer):
            raise InvalidInput("task", f"expected row indices, got {task!r}")
        rows = tuple(int(i) for i in arr)
    if not rows or len(set(rows)) != len(rows) or any(not 0 <= r < 6 for r in rows):
        raise InvalidInput("task", f"expected distinct rows in 0..5, got {task!r}")
    return rows


def _closed_form(arm: Any, rows: tuple[int, ...]) -> Any:
    try:
        cf = arm.closed_form
    except ImportError as exc:
        raise InvalidInput("use_closed_form", f"closed form unavailable: {exc}") from exc
    if cf is None:
        raise InvalidInput("use_closed_form", "this arm has no closed form")
    if max(rows) >= cf.task_dim:
        raise InvalidInput(
            "task", f"the closed form has {cf.task_dim} task rows; rows {rows} asked"
        )
    return cf
