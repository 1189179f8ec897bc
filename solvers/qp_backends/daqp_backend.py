"""DAQP through its own Python API (``daqp.solve``).

Algorithm: dual active-set method with recursive LDL^T updates, for small and medium dense
QPs (Arnström, Bemporad & Axehill, "A dual active-set solver for embedded quadratic
programming using recursive LDL^T updates", IEEE TAC 67(8), 2022). It returns the exact
solution of the identified active set (no ADMM tolerance), takes two-sided rows and simple
bounds natively, and is warm-started here with the previous primal solution of the same
problem structure (``primal_start``, which seeds the active set).

Called directly rather than through ``qpsolvers.solve_problem``, whose conversions cost more
than DAQP's solve of a resolver's small QP (docs/api.md, "One tick's cost").
"""

from __future__ import annotations

import time

import numpy as np

from rrc_pin.solvers.errors import ProblemError
from rrc_pin.solvers.qp_backends.base import Array, QPBackend, QPSolution
from rrc_pin.solvers.qp_backends.qp import QP, finite_solution

DEFAULT_SETTINGS = {"primal_tol": 1e-9}
"""DAQP settings used unless overridden. DAQP's default primal tolerance (1e-6) lets an
inactive bound be exceeded by up to that much, and clipping the answer back then bends the
commanded direction (by 2.6e-6 on random panda problems); at 1e-9 the violated bound joins
the active set and the answers are exact to 4e-16, with no more iterations."""


RETRY_TOL = 1e-8
"""Primal tolerance of one cold retry of a problem DAQP declared infeasible (exit flag -1): at
1e-9 it refused 36 of 4,000 random strict lower levels, all feasible (joints on their bounds
make a degenerate vertex at z = 0; Clarabel solves each); the retry leaves 4-6."""

CYCLING_TOL = 1e-7
"""Primal tolerance of one cold retry of a problem DAQP cycled on (exit flag -2). Cycling met
degenerate vertices of direction QPs (maximise the scale s <= 1, with collision rows of
near-parallel capsules, cosines 0.994-0.999 between rows, active with s = 1); in 10-minute
panda-folding sessions 10 and 2 ticks of 60,000 cycled at 1e-9, warm or cold, and went to the
fallback. Two of them kept: both cycle at 1e-9, one still at 1e-8, both solve cold at 1e-7 in
3 iterations (within :data:`rrc_pin.solvers.qp_backends.qp.FEASIBILITY_TOL`)."""

RETRIES = {-1: RETRY_TOL, -2: CYCLING_TOL}
"""DAQP's exit flags retried once, cold, and the primal tolerance of the retry."""


class DaqpBackend(QPBackend):
    """DAQP, warm-started from the last primal solution per problem key.

    Args:
        **options: DAQP settings (``primal_tol``, ``dual_tol``, ``iter_limit``...).
    """

    name = "daqp"

    def __init__(self, **options: object) -> None:
        super().__init__(**{**DEFAULT_SETTINGS, **options})

    def solve(self, qp: QP) -> QPSolution:
        """Solve ``qp`` (:class:`~rrc_pin.solvers.qp_backends.base.QPBackend`).

        Raises:
            ProblemError: DAQP raised (for instance on an unknown setting).
        """
        import daqp

        nz = qp.q.size
        A: Array
        if qp.C is None or qp.l is None or qp.u is None:
            A, upper, lower = np.zeros((0, nz)), qp.ub, qp.lb
        else:  # the box first, then the rows (DAQP takes infinite bounds as they are), each
            # row of unit norm: DAQP's tolerances are absolute, and a row of norm 8e-7 (a
            # joint barely in a null space, on its bound) was left broken by 4e-6 at 1e-9
            norms = np.linalg.norm(qp.C, axis=1)
            norms[norms == 0.0] = 1.0
            A = qp.C / norms[:, None]
            upper = np.concatenate([qp.ub, qp.u / norms])
            lower = np.concatenate([qp.lb, qp.l / norms])
        sense = np.zeros(upper.size, dtype=np.intc)  # C ints: all inequalities
        t0 = time.perf_counter()
        try:
            x, _, exitflag, info = daqp.solve(
                qp.P, qp.q, A, upper, lower, sense, primal_start=self._start(qp), **self.options
            )
            iterations = int(info["iterations"])
            loose = RETRIES.get(exitflag, 0.0)
            if self.options.get("primal_tol", 0.0) < loose:
                retry = {**self.options, "primal_tol": loose, "primal_start": None}
                x, _, exitflag, info = daqp.solve(qp.P, qp.q, A, upper, lower, sense, **retry)
                iterations += int(info["iterations"])
            z = finite_solution(x, nz) if exitflag > 0 else None
        except Exception as exc:  # raised, or answered something that is not its tuple
            raise ProblemError(f"daqp: {exc}") from exc
        solve_time = time.perf_counter() - t0
        self._remember(qp, z)
        status = "solved" if z is not None else f"exitflag {exitflag}"
        return QPSolution(z, status, iterations, solve_time, self.name)
