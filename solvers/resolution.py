"""Joint rates for one commanded task velocity: the QP, then a chain of fallbacks.

:class:`ResolutionChain` tries its methods in order until one answers:

- ``"qp"``: the QP of :mod:`solvers.qp_problem` (tracking, or direction-preserving while no
  joint has to recover; optionally a strict second level for the secondary objective).
  Without a backend when it is not needed: the box-free minimiser inside the bounds *is*
  the solution (checked before P and q are even built); a tracking problem is solved
  exactly on a guessed active set (the previous step's, then the joints the box-free
  minimiser violates) when the optimality check passes (:mod:`solvers.active_set`); a
  direction problem with at most one null-space direction is solved exactly
  (:mod:`solvers.plane_lp`), and so is a second level with one null-space direction (an
  interval). Otherwise a backend of :mod:`solvers.qp_backends` (warm-started); this method
  fails when the backend raises, reports no solution, or runs out of its iteration or time
  budget.
- ``"dls"``: damped least squares (:mod:`solvers.dls`) projected (clipped) into the bounds.
- ``"scaling"``: the damped least-squares rates scaled uniformly by the largest s in [0, 1]
  that keeps them within the bounds (direction kept), then clipped for recovering joints.
- ``"hold"``: the feasible rates nearest to zero; always the implicit last resort.

Every answer is clipped into the bounds, so it is exactly feasible whatever the backend's
tolerance (the clip size is reported), and finite. Numerical trouble never raises: the
:class:`Resolution` says which method answered and why the earlier ones did not.

The Jacobian is factorised once per step (:func:`solvers.task_factor.factor_task`): a
Cholesky solve where it certifies that the damping is zero, the SVD otherwise. The hot path
(the steps of a control loop) costs about a dozen numpy calls; scalar work on the handful
of joints is done on Python floats, cheaper than numpy calls at this size.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterator
from dataclasses import dataclass
from operator import le, sub
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from solvers.active_set import active_joints, solve_on_active_set
from solvers.dls import Damping
from solvers.errors import InputError, SolverError
from solvers.joint_bounds import VelocityBounds
from solvers.qp_backends import QPBackend, make_backend
from solvers.qp_problem import (
    QPProblem,
    TrackingFree,
    direction_problem_from,
    direction_step,
    direction_terms,
    largest_scale,
    priority_problem,
    tracking_free,
    tracking_problem_from,
)
from solvers.resolution_record import Resolution
from solvers.task_factor import Task, factor_task
from solvers.validation import as_array, as_vector

Array = npt.NDArray[np.float64]

METHODS: tuple[str, ...] = ("qp", "dls", "scaling", "hold")
"""Method names a chain may contain, in their usual order."""


@dataclass(slots=True)
class _Answer:
    qdot: Array
    method: str
    scale: float | None
    status: str
    clip: float = 0.0
    iterations: int = 0
    solve_time: float = 0.0
    backend: str = ""


class _MethodFailed(SolverError):
    """A method of the chain did not produce an answer (internal control flow)."""


class ResolutionChain:
    r"""The resolver's numerical core: a QP backend (warm-started) and its fallbacks.

    Args:
        backend: A backend name (:func:`solvers.qp_backends.installed_backends`), a
            :class:`~solvers.qp_backends.QPBackend`, or None for a chain without QP.
        methods: Methods tried in order (names of :data:`METHODS`); ``"hold"`` is always
            appended. Default: ``("qp", "dls", "scaling")``, or without ``"qp"`` when
            ``backend`` is None.
        damping: Adaptive damping schedule (default :class:`~solvers.dls.Damping()`).
        direction_preserving: Use the direction-preserving QP while no joint must recover.
        priority: ``"soft"`` (secondary objective in the cost, null space only) or
            ``"strict"`` (a second QP in the null space of the primary solution).
        secondary_weight: Weight :math:`\mu` in (0, 1) of the secondary objective.
        shortcut: Return the box-free minimiser without calling the backend when it lies in
            the box (it is then the QP's solution), and try the guessed active sets
            (:mod:`solvers.active_set`) before the backend.
        active_tol: Distance to a bound under which the bound is reported active [rad/s].
        backend_options: Settings passed to the backend when ``backend`` is a name.

    Raises:
        BackendNotFound: Unknown backend name.
        InputError: Unknown method, invalid priority, weight or tolerance.
    """

    def __init__(
        self,
        backend: str | QPBackend | None = "osqp",
        methods: tuple[str, ...] | None = None,
        damping: Damping | None = None,
        direction_preserving: bool = False,
        priority: Literal["soft", "strict"] = "soft",
        secondary_weight: float = 1e-2,
        shortcut: bool = True,
        active_tol: float = 1e-6,
        backend_options: dict[str, Any] | None = None,
    ) -> None:
        if isinstance(backend, str):
            backend = make_backend(backend, **(backend_options or {}))
        if methods is None:
            methods = ("qp", "dls", "scaling") if backend is not None else ("dls", "scaling")
        methods = tuple(methods)
        for name in methods:
            if name not in METHODS:
                raise InputError("fallbacks", f"unknown method {name!r}; expected {METHODS}")
        if "qp" in methods and backend is None:
            raise InputError("backend", "the chain contains 'qp' but no backend was given")
        if priority not in ("soft", "strict"):
            raise InputError("priority", f"expected 'soft' or 'strict', got {priority!r}")
        if not 0.0 < secondary_weight < 1.0:
            raise InputError("secondary_weight", f"expected (0, 1), got {secondary_weight!r}")
        if not (np.isfinite(active_tol) and active_tol >= 0.0):
            raise InputError("active_tol", f"expected a finite number >= 0, got {active_tol!r}")
        if damping is not None and not isinstance(damping, Damping):
            raise InputError("damping", f"expected a solvers.dls.Damping, got {damping!r}")
        self.backend = backend
        self.methods = methods if methods[-1:] == ("hold",) else (*methods, "hold")
        self.damping = damping if damping is not None else Damping()
        self.direction_preserving = bool(direction_preserving)
        self.priority = priority
        self.secondary_weight = float(secondary_weight)
        self.shortcut = bool(shortcut)
        self.active_tol = float(active_tol)
        self._active: tuple[tuple[int, ...], tuple[int, ...]] = ((), ())

    def reset(self) -> None:
        """Forget the backend's warm start and the previous active set."""
        if self.backend is not None:
            self.backend.reset()
        self._active = ((), ())

    def warm_start_state(self) -> dict[str, Array]:
        """Copies of the values that seed the next step.

        The backend's warm start, and the previous tracking answer's active set (joints at
        their lower and upper bounds, ``active:lower`` and ``active:upper``).
        """
        state = self.backend.warm_start_state() if self.backend is not None else {}
        state["active:lower"] = np.array(self._active[0], dtype=np.intp)
        state["active:upper"] = np.array(self._active[1], dtype=np.intp)
        return state

    def resolve(
        self,
        J: npt.ArrayLike,
        xdot: npt.ArrayLike,
        bounds: VelocityBounds,
        secondary: npt.ArrayLike | None = None,
        factor: Array | None = None,
        joint_names: list[str] | None = None,
        validate: bool = True,
    ) -> Resolution:
        """Joint rates realising ``xdot`` at best within ``bounds``.

        Args:
            J: Task Jacobian (m, n), same frame and rows as ``xdot``.
            xdot: Task velocity (m,) [m/s] then [rad/s].
            bounds: Joint-rate bounds of this step
                (:func:`~solvers.joint_bounds.joint_velocity_bounds`).
            secondary: Desired joint rates (n,) for the secondary objective, or None.
            factor: Task-weight factor L (m, m) (:func:`~solvers.dls.weight_factor`) or None.
            joint_names: Names for :attr:`ActiveLimit.name`.
            validate: Check shapes and finiteness (off only for float64 arrays checked
                already).

        Returns:
            The :class:`Resolution`; never raises for numerical trouble.

        Raises:
            InputError: Wrong shapes or non-finite entries (when ``validate``).
        """
        t0 = time.perf_counter()
        if validate:
            J = as_array(J, "J", (None, None))
            m, n = J.shape
            xdot = as_vector(xdot, "xdot", m)
            as_vector(bounds.lb, "bounds.lb", n)
            as_vector(bounds.ub, "bounds.ub", n)
            if np.any(bounds.lb > bounds.ub):
                raise InputError("bounds", "expected lb <= ub")
            if secondary is not None:
                secondary = as_vector(secondary, "secondary", n)
        z: Array | None = secondary  # type: ignore[assignment]
        xw: Array = xdot if factor is None else factor.T @ xdot  # type: ignore[assignment]
        attempts: list[tuple[str, str]] = []
        task: Task | None
        try:
            task = factor_task(J, factor, self.damping)  # type: ignore[arg-type]
        except (np.linalg.LinAlgError, ArithmeticError) as exc:
            task = None
            attempts.append(("svd", str(exc)))
        answer: _Answer | None = None
        for method in self.methods:
            try:
                answer = self._run(method, task, xw, bounds, z)
            except (SolverError, np.linalg.LinAlgError, ArithmeticError) as exc:
                attempts.append((method, str(exc)))
                continue
            if _finite(answer.qdot):
                break
            attempts.append((method, "non-finite rates"))
            answer = None
        if answer is None:  # unreachable: "hold" always answers; kept as a guard
            answer = _hold(bounds)
        total = time.perf_counter() - t0
        return Resolution(
            answer.qdot,
            answer.method,
            answer.scale,
            answer.status,
            total - answer.solve_time,
            answer.solve_time,
            answer.clip,
            answer.iterations,
            answer.backend,
            tuple(attempts),
            task.lambda_sq if task is not None else math.nan,
            J=J,  # type: ignore[arg-type]
            xdot=xdot,  # type: ignore[arg-type]
            bounds=bounds,
            factor=factor,
            active_tol=self.active_tol,
            joint_names=joint_names,
        )

    def _run(
        self,
        method: str,
        task: Task | None,
        xw: Array,
        bounds: VelocityBounds,
        z: Array | None,
    ) -> _Answer:
        if method == "qp":
            if task is None:
                raise _MethodFailed("no factorisation of the Jacobian")
            return self._qp(task, xw, bounds, z)
        if method == "hold":
            return _hold(bounds)
        if task is None:
            raise _MethodFailed("no factorisation of the Jacobian")
        qdot = task.dls(xw)
        if z is not None:
            qdot = qdot + task.null_project(z)
        if method == "dls":
            return _clipped(qdot, bounds, "dls", None, "projected")
        s = uniform_scale(qdot, bounds)
        return _clipped(s * qdot, bounds, "scaling", s, "scaled")

    def _qp(self, task: Task, xw: Array, bounds: VelocityBounds, z: Array | None) -> _Answer:
        soft_z = z if self.priority == "soft" else None
        if self.direction_preserving and bounds.contains_zero:
            answer = self._direction(task, xw, bounds, soft_z)
        else:
            # the box-free minimiser first; P and q are built only when it leaves the box
            free = tracking_free(task, xw, soft_z, self.secondary_weight)
            if self.shortcut and _within(free.x, bounds):
                answer = _Answer(free.x, "qp", None, "unconstrained optimum")
                self._active = ((), ())
            else:
                answer = self._tracking(task, free, bounds)
        if z is None or self.priority != "strict" or task.rank == task.n:
            return answer
        second = priority_problem(task, answer.qdot, bounds, z)
        try:
            _, answer2 = self._solve(second, "qp_priority", bounds)
        except _MethodFailed as exc:
            answer.status += f"; second level failed ({exc}), primary kept"
            return answer
        answer2.scale = answer.scale
        answer2.solve_time += answer.solve_time
        answer2.iterations += answer.iterations
        answer2.clip = max(answer2.clip, answer.clip)
        return answer2

    def _tracking(self, task: Task, free: TrackingFree, bounds: VelocityBounds) -> _Answer:
        """The tracking QP whose box-free minimiser leaves the box: guessed active set, or backend.

        The guesses are the previous tracking answer's active set, then the joints the
        box-free minimiser violates; each is checked for optimality
        (:mod:`solvers.active_set`) and the backend is asked only when both fail (about
        1.5% of the steps of the benchmark trajectories, against 95% with a bound active).
        """
        if self.shortcut:
            for guess in _guesses(self._active, free.x, bounds):
                solution = solve_on_active_set(task, free, bounds, *guess)
                if solution is not None:
                    self._active = guess
                    qdot, clip = solution
                    return _Answer(qdot, "qp", None, "exact on the guessed active set", clip)
        problem = tracking_problem_from(task, free, bounds)
        _, answer = self._solve(problem, "qp", bounds, check_free=False)
        self._active = active_joints(answer.qdot, bounds)
        return answer

    def _direction(
        self, task: Task, xw: Array, bounds: VelocityBounds, z: Array | None
    ) -> _Answer:
        """The direction-preserving QP: shortcut, exact plane LP, or the backend."""
        dls = task.dls(xw)
        if (
            self.shortcut
            and z is None
            and task.rank == min(task.J.shape)  # full row rank: dls is in the row space
            and _within(dls, bounds)
        ):  # u = 1, z = 0: the box-free optimum, before the problem is built
            return _Answer(dls, "qp_direction", 1.0, "unconstrained optimum")
        terms = direction_terms(task, dls, bounds, z, self.secondary_weight)
        if terms.Vn.shape[0] <= 1:  # solved exactly, no backend
            qdot, s, clip = direction_step(terms, bounds)
            return _Answer(qdot, "qp_direction", s, "exact", clip)
        problem = direction_problem_from(terms, bounds)
        x, answer = self._solve(problem, "qp_direction", bounds)
        answer.scale = problem.scale(x)
        return answer

    def _solve(
        self, problem: QPProblem, method: str, bounds: VelocityBounds, check_free: bool = True
    ) -> tuple[Array, _Answer]:
        """Solve ``problem`` (shortcut, closed form or backend); rates clipped into ``bounds``."""
        if check_free and self.shortcut and problem.free_in_box():
            x = problem.x_free
            if problem.G is None:
                return x, _Answer(x, method, None, "unconstrained optimum")
            status, iterations, solve_time, backend = "unconstrained optimum", 0, 0.0, ""
        elif problem.kind == "priority" and problem.P.shape[0] == 1:
            x = np.array([_interval_point(problem.G[:, 0], problem.lo, problem.hi,
                                          float(problem.x_free[0]))])
            status, iterations, solve_time, backend = "exact", 0, 0.0, ""
        else:
            if self.backend is None:  # pragma: no cover - excluded at construction
                raise _MethodFailed("no backend")
            sol = self.backend.solve(problem)
            if not sol.found or sol.x is None:
                raise _MethodFailed(f"{sol.backend}: {sol.status}")
            x = sol.x
            status, iterations, solve_time, backend = (
                sol.status, sol.iterations, sol.solve_time, sol.backend,
            )
        answer = _clipped(problem.rates(x), bounds, method, None, status)
        answer.iterations, answer.solve_time, answer.backend = iterations, solve_time, backend
        return x, answer


def uniform_scale(qdot: Array, bounds: VelocityBounds) -> float:
    """Largest s in [0, 1] with ``s * qdot`` within the bounds.

    Only the joints whose bounds contain zero count: a recovering joint cannot be satisfied
    by scaling (it is clipped after).

    Args:
        qdot: Joint rates (n,).
        bounds: Joint-rate bounds.

    Returns:
        The scale s in [0, 1].
    """
    return largest_scale(qdot.tolist(), *bounds.lists())


def _within(x: Array, bounds: VelocityBounds) -> bool:
    """True when ``lb <= x <= ub`` (False for NaN); Python floats: n is small."""
    xl = x.tolist()
    lb, ub = bounds.lists()
    return all(map(le, lb, xl)) and all(map(le, xl, ub))


def _guesses(
    previous: tuple[tuple[int, ...], tuple[int, ...]], x: Array, bounds: VelocityBounds
) -> Iterator[tuple[tuple[int, ...], tuple[int, ...]]]:
    """Active-set guesses: ``previous`` (unless empty or too long), then ``x``'s violations."""
    if previous != ((), ()) and max(previous[0] + previous[1]) < x.size:
        yield previous
    violated = _violated(x, bounds)
    if violated != previous:
        yield violated


def _violated(x: Array, bounds: VelocityBounds) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """Joints of ``x`` below their lower, and above their upper bound."""
    values = x.tolist()
    lows, highs = bounds.lists()
    lower = tuple(i for i, (v, low) in enumerate(zip(values, lows)) if v < low)  # noqa: B905
    upper = tuple(i for i, (v, high) in enumerate(zip(values, highs)) if v > high)  # noqa: B905
    return lower, upper


def _finite(x: Array) -> bool:
    """True when every entry of ``x`` is finite (one sum; numpy only if it overflows)."""
    return math.isfinite(sum(x.tolist())) or bool(np.isfinite(x).all())


def _clipped(
    raw: Array, bounds: VelocityBounds, method: str, scale: float | None, status: str
) -> _Answer:
    """The answer ``raw`` clipped into the bounds, with the size of the clip."""
    qdot = np.minimum(np.maximum(raw, bounds.lb), bounds.ub)
    gaps = map(sub, qdot.tolist(), raw.tolist())
    return _Answer(qdot, method, scale, status, max(map(abs, gaps), default=0.0))


def _interval_point(g: Array, lo: Array, hi: Array, target: float) -> float:
    """The x nearest ``target`` with ``lo <= g x <= hi`` (one variable: an interval)."""
    moving = np.abs(g) > 1e-12
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = lo[moving] / g[moving], hi[moving] / g[moving]
    x_lo = float(np.minimum(t1, t2).max(initial=-np.inf))
    x_hi = float(np.maximum(t1, t2).min(initial=np.inf))
    if x_lo > x_hi:  # rounding at a degenerate point: the interval is a point
        x_lo = x_hi = 0.5 * (x_lo + x_hi)
    return min(max(target, x_lo), x_hi)


def _hold(bounds: VelocityBounds) -> _Answer:
    qdot = np.minimum(np.maximum(0.0, bounds.lb), bounds.ub)
    return _Answer(qdot, "hold", None, "hold: feasible rates nearest zero")
