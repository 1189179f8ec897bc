"""Every other QP solver that qpsolvers finds installed, by name, through ``qpsolvers.Problem``.

Algorithms and references of the ones rrc-pin is tested with (qpsolvers' documentation lists
the rest):

- ``quadprog``: Goldfarb-Idnani dual active set (Goldfarb & Idnani, "A numerically stable
  dual method for solving strictly convex quadratic programs", Math. Prog. 27, 1983).
- ``proxqp``: proximal augmented Lagrangian (Bambade et al., "PROX-QP: Yet another quadratic
  programming solver for robotics and beyond", RSS 2022).
- ``clarabel``: interior point with homogeneous embedding (Goulart & Chen, "Clarabel: an
  interior-point solver for conic programs with quadratic objectives", 2024).
- ``osqp``, ``daqp``: rrc-pin calls these through their own APIs (:mod:`.osqp_backend`,
  :mod:`.daqp_backend`), never through this module.

Warm starts: the previous solution of the same problem key is passed as ``initvals`` (used
by the solvers that take one). Zero-width bounds and rows (``lb == ub``) are widened by
:data:`WIDTH` (quadprog and clarabel refuse them); the caller clips the answer back.
"""

from __future__ import annotations

import time
import warnings
from typing import Any

import numpy as np

from rrc_pin.solvers.errors import ProblemError
from rrc_pin.solvers.qp_backends.base import Array, QPBackend, QPSolution
from rrc_pin.solvers.qp_backends.qp import QP, finite_solution

WIDTH = 1e-9
"""Relative width given to zero-width bounds and rows."""

DEFAULT_OPTIONS: dict[str, dict[str, Any]] = {
    "proxqp": {
        "eps_abs": 1e-9,
        "eps_rel": 0.0,
        "check_duality_gap": True,  # without it, answers were off by up to 5e-4
        "eps_duality_gap_abs": 1e-9,
        "eps_duality_gap_rel": 0.0,
        # Its default, 10,000 outer iterations, took 3.5 s on degenerate strict levels of
        # g1_upper that it then did not solve (soak): a bound on the time, the fallbacks answer.
        "max_iter": 1000,
    },
    "clarabel": {"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10, "tol_feas": 1e-10},
}
"""Per-solver options used unless overridden."""


class QpsolversBackend(QPBackend):
    """One qpsolvers solver, by name.

    Args:
        solver: A name in ``qpsolvers.available_solvers``.
        **options: Solver options overriding :data:`DEFAULT_OPTIONS`.
    """

    def __init__(self, solver: str, **options: Any) -> None:
        super().__init__(**{**DEFAULT_OPTIONS.get(solver, {}), **options})
        self.name = solver

    def solve(self, qp: QP) -> QPSolution:
        """Solve ``qp`` with ``qpsolvers.solve_problem``.

        Raises:
            ProblemError: The solver raised (an unknown option included).
        """
        import qpsolvers

        widened = qp._replace(ub=_widen(qp.lb, qp.ub))
        if qp.l is not None and qp.u is not None:
            widened = widened._replace(u=_widen(qp.l, qp.u))
        t0 = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sol = qpsolvers.solve_problem(
                    widened.problem(), solver=self.name, initvals=self._start(qp),
                    **self.options,
                )  # fmt: skip
            solve_time = time.perf_counter() - t0
            x = finite_solution(sol.x, qp.q.size) if sol.found is True else None
            extras = sol.extras if isinstance(sol.extras, dict) else {}
            iterations = int(np.max(extras.get("iterations", extras.get("iter", [0])), initial=0))
        except Exception as exc:  # raised, or answered something that is not a Solution
            raise ProblemError(f"{self.name}: {exc}") from exc
        if x is not None:  # a failure keeps the last solution of the key as the next start:
            self._remember(qp, x)  # proxqp: 58 of 300 degenerate direction QPs refused, 100 if cold
        return QPSolution(
            None if x is None else x.copy(),  # the warm start is not the caller's
            "solved" if x is not None else "not found",
            iterations,
            solve_time,
            self.name,
        )


def _widen(lo: Array, hi: Array) -> Array:
    """``hi`` raised to at least ``lo + WIDTH (1 + |lo|)`` where both are finite."""
    with np.errstate(invalid="ignore"):
        wider = np.maximum(hi, lo + WIDTH * (1.0 + np.abs(lo)))
    return np.where(np.isfinite(lo) & np.isfinite(hi), wider, hi)
