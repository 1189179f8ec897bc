"""Every other QP solver that qpsolvers finds installed, selectable by name.

Algorithms and references of the ones rrc-pin is tested with (qpsolvers' own docs list
the rest):

- ``daqp``: dual active-set (Arnström, Bemporad & Axehill, "A dual active-set solver for
  embedded quadratic programming using recursive LDL^T updates", IEEE TAC 67(8), 2022).
  Warm start: no (qpsolvers ignores initial values for DAQP).
- ``proxqp``: proximal augmented Lagrangian (Bambade, El-Kazdadi, Taylor & Carpentier,
  "PROX-QP: Yet another Quadratic Programming Solver for Robotics and beyond", RSS 2022).
  Warm start: yes (the previous primal solution). Seen to declare a few feasible
  one-variable problems primal infeasible (then the resolver falls back).
- ``quadprog``: Goldfarb-Idnani dual active-set (Goldfarb & Idnani, Mathematical Programming
  27:1-33, 1983). Warm start: no.
- ``clarabel``: interior point with homogeneous embedding (Goulart & Chen, "Clarabel: an
  interior-point solver for conic programs with quadratic objectives", arXiv:2405.12762,
  2024). Warm start: no.

Each solve goes through ``qpsolvers.solve_problem``; build time (our conversion plus
qpsolvers') and solve time are recorded apart. Two-sided rows become pairs of one-sided
rows; box entries are passed as a box when all finite, else as rows. Variables with a
zero-width box are eliminated and zero-width rows widened by 1e-9 (quadprog and clarabel
refuse them). Tolerances are tightened where the solver's defaults are loose.
"""

from __future__ import annotations

import time
import warnings
from typing import Any

import numpy as np

from solvers.errors import ProblemError
from solvers.qp_backends.base import Array, QPBackend, QPSolution, structure_key
from solvers.qp_problem import QPProblem

WARM_STARTING: frozenset[str] = frozenset({"proxqp", "osqp", "qpalm", "piqp", "highs"})
"""qpsolvers solvers that use the initial values they are given."""

DEFAULT_OPTIONS: dict[str, dict[str, Any]] = {
    "proxqp": {
        "eps_abs": 1e-9,
        "eps_rel": 0.0,
        "check_duality_gap": True,  # without it, answers were off by up to 5e-4
        "eps_duality_gap_abs": 1e-9,
        "eps_duality_gap_rel": 0.0,
    },
    "clarabel": {"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10, "tol_feas": 1e-10},
    "osqp": {"eps_abs": 1e-7, "eps_rel": 1e-7, "polishing": True},
}
"""Per-solver options used unless overridden."""


class QpsolversBackend(QPBackend):
    """One qpsolvers solver, by name.

    Args:
        solver: A name in ``qpsolvers.available_solvers``.
        **options: Solver options overriding :data:`DEFAULT_OPTIONS`.

    Raises:
        ProblemError: qpsolvers is not importable or does not have ``solver``.
    """

    def __init__(self, solver: str, **options: Any) -> None:
        try:
            import qpsolvers
        except ImportError as exc:  # pragma: no cover - qpsolvers is a hard dependency
            raise ProblemError("qpsolvers is not installed (pip install qpsolvers)") from exc
        if solver not in qpsolvers.available_solvers:
            raise ProblemError(f"qpsolvers has no installed solver {solver!r}")
        self._qpsolvers = qpsolvers
        self.name = solver
        self.warm_starts = solver in WARM_STARTING
        self.options = {**DEFAULT_OPTIONS.get(solver, {}), **options}
        self._x: dict[str, Array] = {}

    def reset(self) -> None:
        """Forget the previous solutions."""
        self._x.clear()

    def warm_start_state(self) -> dict[str, Array]:
        """Copies of the previous solutions, by problem structure."""
        return {key: x.copy() for key, x in self._x.items()}

    def solve(self, problem: QPProblem) -> QPSolution:
        """Solve with ``qpsolvers.solve_problem``.

        Raises:
            ProblemError: The solver raised.
        """
        t0 = time.perf_counter()
        key = structure_key(problem)
        full = problem
        problem, free = _eliminate_fixed(problem)
        qp = self._qpsolvers.Problem(problem.P, problem.q, *_inequalities(problem))
        initvals = self._x.get(key) if self.warm_starts else None
        if initvals is not None and free is not None:
            initvals = initvals[free]
        t1 = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sol = self._qpsolvers.solve_problem(
                    qp, solver=self.name, initvals=initvals, **self.options
                )
        except Exception as exc:
            raise ProblemError(f"{self.name}: {exc}") from exc
        t2 = time.perf_counter()
        x = sol.x
        found = bool(sol.found) and x is not None and bool(np.all(np.isfinite(x)))
        if found and free is not None:
            x_full = full.lb.copy()  # fixed variables at their (single) value
            x_full[free] = x
            x = x_full
        if found:
            self._x[key] = np.array(x, dtype=np.float64)
        inner_build = float(getattr(sol, "build_time", 0.0) or 0.0)
        inner_solve = getattr(sol, "solve_time", None)
        solve_time = float(inner_solve) if inner_solve else (t2 - t1)
        extras = sol.extras if isinstance(sol.extras, dict) else {}
        iterations = extras.get("iterations", extras.get("iter", 0))
        return QPSolution(
            x=np.array(x, dtype=np.float64) if found else None,
            found=found,
            status="solved" if found else "not found",
            iterations=int(np.max(iterations)) if np.size(iterations) else 0,
            build_time=(t1 - t0) + inner_build,
            solve_time=solve_time,
            backend=self.name,
        )


WIDTH = 1e-9
"""Relative width given to zero-width rows (lo == hi), which quadprog refuses as
inconsistent; the resolver clips the answer back into the exact bounds."""


def _widen(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``hi`` raised to at least ``lo + WIDTH (1 + |lo|)`` where both are finite."""
    with np.errstate(invalid="ignore"):
        wider = np.maximum(hi, lo + WIDTH * (1.0 + np.abs(lo)))
    return np.where(np.isfinite(lo) & np.isfinite(hi), wider, hi)


def _eliminate_fixed(problem: QPProblem) -> tuple[QPProblem, np.ndarray | None]:
    """The problem without the variables whose box has zero width (lb == ub).

    Interior-point and dual active-set solvers fail on such boxes (quadprog: "constraints
    are inconsistent"). Returns the reduced problem and the mask of the remaining variables
    (None when nothing is fixed).
    """
    fixed = problem.lb >= problem.ub
    if not fixed.any() or problem.G is not None:
        return problem, None
    free = ~fixed
    value = problem.lb[fixed]
    q = problem.q[free] + problem.P[np.ix_(free, fixed)] @ value
    reduced = problem._replace(
        P=problem.P[np.ix_(free, free)], q=q, lb=problem.lb[free], ub=problem.ub[free],
        x_free=problem.x_free[free],
    )
    return reduced, free


def _inequalities(problem: QPProblem) -> tuple[Any, ...]:
    """``(G, h, A, b, lb, ub)`` of qpsolvers for ``problem`` (no equality constraints)."""
    rows: list[np.ndarray] = []
    rhs: list[np.ndarray] = []
    if problem.G is not None and problem.lo is not None and problem.hi is not None:
        rows += [problem.G, -problem.G]
        rhs += [_widen(problem.lo, problem.hi), -problem.lo]
    lb, ub = problem.lb, _widen(problem.lb, problem.ub)
    if not (np.all(np.isfinite(lb)) and np.all(np.isfinite(ub))):
        eye = np.eye(lb.size)
        low, high = np.isfinite(lb), np.isfinite(ub)
        rows += [-eye[low], eye[high]]
        rhs += [-lb[low], ub[high]]
        lb = ub = None
    if not rows:
        return None, None, None, None, lb, ub
    return np.vstack(rows), np.concatenate(rhs), None, None, lb, ub
