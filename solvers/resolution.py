"""Joint rates for one commanded task velocity: the QP, then a chain of fallbacks.

:class:`ResolutionChain` tries its methods in order until one answers:

- ``"qp"``: the QP of :mod:`solvers.qp_problem` (tracking, or direction-preserving while no
  joint has to recover; optionally a strict second level for the secondary objective).
  Without a backend when it is not needed: the box-free minimiser inside the bounds *is*
  the solution (checked before P and q are even built), a direction problem with at most
  one null-space direction is solved exactly (:mod:`solvers.plane_lp`), and so is a second
  level with one null-space direction (an interval). Otherwise a backend of
  :mod:`solvers.qp_backends` (warm-started); this method fails when the backend raises,
  reports no solution, or runs out of its iteration or time budget.
- ``"dls"``: damped least squares (:mod:`solvers.dls`) projected (clipped) into the bounds.
- ``"scaling"``: the damped least-squares rates scaled uniformly by the largest s in [0, 1]
  that keeps them within the bounds (direction kept), then clipped for recovering joints.
- ``"hold"``: the feasible rates nearest to zero; always the implicit last resort.

Every answer is clipped into the bounds, so it is exactly feasible whatever the backend's
tolerance (the clip size is reported), and finite. Numerical trouble never raises: the
:class:`Resolution` says which method answered and why the earlier ones did not.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from solvers.dls import Damping, TaskSVD, task_svd
from solvers.errors import InputError, SolverError
from solvers.joint_bounds import VelocityBounds
from solvers.plane_lp import max_scale_one_null
from solvers.qp_backends import QPBackend, make_backend
from solvers.qp_problem import (
    QPProblem,
    direction_problem,
    priority_problem,
    tracking_free,
    tracking_problem_from,
)
from solvers.resolution_record import Resolution
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
            the box (it is then the QP's solution).
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

    def reset(self) -> None:
        """Forget the backend's warm start."""
        if self.backend is not None:
            self.backend.reset()

    def warm_start_state(self) -> dict[str, Array]:
        """Copies of the backend's warm-start values (empty without a backend)."""
        return self.backend.warm_start_state() if self.backend is not None else {}

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
            validate: Check shapes and finiteness (off only for inputs checked already).

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
        J = np.asarray(J, dtype=np.float64)
        xdot = np.asarray(xdot, dtype=np.float64)
        z = None if secondary is None else np.asarray(secondary, dtype=np.float64)
        xw = xdot if factor is None else factor.T @ xdot
        attempts: list[tuple[str, str]] = []
        svd: TaskSVD | None
        try:
            svd = task_svd(J, factor, self.damping)
        except (np.linalg.LinAlgError, ArithmeticError) as exc:
            svd = None
            attempts.append(("svd", str(exc)))
        answer: _Answer | None = None
        for method in self.methods:
            try:
                answer = self._run(method, svd, xw, bounds, z)
            except (SolverError, np.linalg.LinAlgError, ArithmeticError) as exc:
                attempts.append((method, str(exc)))
                continue
            if math.isfinite(answer.qdot @ answer.qdot) or np.isfinite(answer.qdot).all():
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
            svd.lambda_sq if svd is not None else math.nan,
            J=J,
            xdot=xdot,
            bounds=bounds,
            factor=factor,
            active_tol=self.active_tol,
            joint_names=joint_names,
        )

    def _run(
        self,
        method: str,
        svd: TaskSVD | None,
        xw: Array,
        bounds: VelocityBounds,
        z: Array | None,
    ) -> _Answer:
        if method == "hold":
            return _hold(bounds)
        if svd is None:
            raise _MethodFailed("no SVD of the Jacobian")
        if method == "qp":
            return self._qp(svd, xw, bounds, z)
        qdot = svd.dls(xw)
        if z is not None:
            Vn = svd.Vt[svd.rank :]
            qdot = qdot + Vn.T @ (Vn @ z)
        if method == "dls":
            clipped = np.minimum(np.maximum(qdot, bounds.lb), bounds.ub)
            return _Answer(clipped, "dls", None, "projected", _size(clipped - qdot))
        s = uniform_scale(qdot, bounds)
        scaled = s * qdot
        clipped = np.minimum(np.maximum(scaled, bounds.lb), bounds.ub)
        return _Answer(clipped, "scaling", s, "scaled", _size(clipped - scaled))

    def _qp(self, svd: TaskSVD, xw: Array, bounds: VelocityBounds, z: Array | None) -> _Answer:
        soft_z = z if self.priority == "soft" else None
        if self.direction_preserving and bounds.contains_zero:
            dls = svd.dls(xw)
            if (
                self.shortcut
                and soft_z is None
                and svd.rank == svd.sigma.size  # full row rank: dls is in the row space
                and (dls >= bounds.lb).all()
                and (dls <= bounds.ub).all()
            ):  # u = 1, z = 0: the box-free optimum, before the problem is built
                answer = _Answer(dls, "qp_direction", 1.0, "unconstrained optimum")
            else:
                problem = direction_problem(svd, dls, bounds, soft_z, self.secondary_weight)
                x, answer = self._solve(problem, "qp_direction", bounds)
                answer.scale = problem.scale(x)
        else:
            # the box-free minimiser first; P and q are built only when it leaves the box
            free = tracking_free(svd, xw, soft_z, self.secondary_weight)
            x = free.x
            if self.shortcut and (x >= bounds.lb).all() and (x <= bounds.ub).all():
                answer = _Answer(x, "qp", None, "unconstrained optimum")
            else:
                problem = tracking_problem_from(svd, free, bounds)
                _, answer = self._solve(problem, "qp", bounds, check_free=False)
        if z is None or self.priority != "strict" or svd.rank == svd.n:
            return answer
        second = priority_problem(svd, answer.qdot, bounds, z)
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

    def _solve(
        self, problem: QPProblem, method: str, bounds: VelocityBounds, check_free: bool = True
    ) -> tuple[Array, _Answer]:
        """Solve ``problem`` (shortcut, closed form or backend); rates clipped into ``bounds``."""
        if check_free and self.shortcut and problem.free_in_box():
            x = problem.x_free
            if problem.G is None:
                return x, _Answer(x, method, None, "unconstrained optimum")
            status, iterations, solve_time, backend = "unconstrained optimum", 0, 0.0, ""
        elif problem.kind == "direction" and problem.P.shape[0] <= 2:
            x = _direction_exact(problem, bounds)
            status, iterations, solve_time, backend = "exact", 0, 0.0, ""
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
        raw = problem.rates(x)
        qdot = np.minimum(np.maximum(raw, bounds.lb), bounds.ub)
        return x, _Answer(
            qdot, method, None, status, _size(qdot - raw), iterations, solve_time, backend
        )


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
    s = 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        up = (qdot > bounds.ub) & (bounds.ub >= 0.0)
        down = (qdot < bounds.lb) & (bounds.lb <= 0.0)
        if np.any(up):
            s = min(s, float(np.min(bounds.ub[up] / qdot[up])))
        if np.any(down):
            s = min(s, float(np.min(bounds.lb[down] / qdot[down])))
    return max(0.0, s)


def _direction_exact(problem: QPProblem, bounds: VelocityBounds) -> Array:
    """Solution (z, u) of a direction problem with at most one null-space direction.

    No null space: the rates are u w and the largest feasible u is optimal. One direction:
    the plane LP of :mod:`solvers.plane_lp` (largest u, then z nearest its target).
    """
    G = problem.G
    if G is None:  # pragma: no cover - direction problems always have G
        raise _MethodFailed("direction problem without G")
    if G.shape[1] == 1:
        return np.array([uniform_scale(G[:, 0], bounds)])
    z, u = max_scale_one_null(G[:, 0], G[:, 1], bounds.lb, bounds.ub, float(problem.x_free[0]))
    return np.array([z, u])


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


def _size(d: Array) -> float:
    return float(np.abs(d).max()) if d.size else 0.0


