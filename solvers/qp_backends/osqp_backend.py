"""OSQP through its public Python API, one workspace per problem structure, warm-started.

Algorithm: ADMM operator splitting for convex QPs, with solution polishing (Stellato,
Banjac, Goulart, Bemporad & Boyd, "OSQP: an operator splitting solver for quadratic
programs", Mathematical Programming Computation 12:637-672, 2020).

Warm starts: yes. The workspace of a problem structure (``QP.key``) is set up once with a
fixed dense pattern (the whole upper triangle of P, and the box as identity rows above the
constraint rows), then updated in place (``OSQP.update``) and solved from the previous
primal and dual solution (OSQP's ``warm_starting``). After :meth:`OSQPBackend.reset` the next
solve starts from zero; a warm-started solve that fails is retried once from zero.

Settings: OSQP's defaults, tightened to ``eps_abs = eps_rel = 1e-7`` with polishing (which
then returns the exact solution of the identified active set) and ``max_iter = 20000``:
with 4000 iterations and Ruiz scaling off, the resolver froze arms at their limits (so101,
6 of 100 steps), while 20,000 iterations and the default scaling solve them. The step size
rho is adapted every 50 iterations, not at OSQP's default time-based interval, which made
the answers depend on the machine's load (1 or 2 of the same 300 direction problems
unsolved from run to run); every 50: 1 of 300 in both of the tests' problem sets, against
7 and 8 every 10, 3 and 1 every 25.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import scipy.sparse as sp

from rrc_pin.solvers.errors import ProblemError
from rrc_pin.solvers.qp_backends.base import Array, QPBackend, QPSolution
from rrc_pin.solvers.qp_backends.qp import QP, finite_solution

DEFAULT_SETTINGS: dict[str, Any] = {
    "eps_abs": 1e-7,
    "eps_rel": 1e-7,
    "polishing": True,
    "max_iter": 20000,
    "verbose": False,
    "warm_starting": True,
    "adaptive_rho_interval": 50,
}
"""OSQP settings used unless overridden (``OSQPBackend(eps_abs=..., ...)``)."""

ACCEPTED = ("solved", "solved inaccurate")
"""OSQP statuses that count as a solution (the caller checks the answer against the bounds)."""


@dataclass
class _Workspace:
    """One OSQP solver for one problem structure and the index maps of its updates."""

    solver: Any
    p_rows: npt.NDArray[np.intp]  # entries of P's upper triangle, in CSC order
    p_cols: npt.NDArray[np.intp]
    nz: int
    nc: int  # constraint rows, the box included
    cold: bool = False


class OSQPBackend(QPBackend):
    """OSQP (public API), warm-started, updated in place with a fixed dense pattern.

    Args:
        **options: OSQP settings overriding :data:`DEFAULT_SETTINGS`.
    """

    name = "osqp"

    def __init__(self, **options: Any) -> None:
        super().__init__(**{**DEFAULT_SETTINGS, **options})
        self._workspaces: dict[str, _Workspace] = {}

    def reset(self) -> None:
        """Forget every warm start (the workspaces are kept: their setup is not redone)."""
        super().reset()
        for ws in self._workspaces.values():
            ws.cold = True

    def solve(self, qp: QP) -> QPSolution:
        """Update (or set up) the workspace of ``qp.key`` and solve.

        Raises:
            ProblemError: OSQP raised during setup, update or solve (unknown settings too).
        """
        import osqp

        nz = qp.q.size
        rows = np.eye(nz) if qp.C is None else np.vstack([np.eye(nz), qp.C])
        lower = qp.lb if qp.l is None else np.concatenate([qp.lb, qp.l])
        upper = qp.ub if qp.u is None else np.concatenate([qp.ub, qp.u])
        ws = self._workspaces.get(qp.key)
        # a new key, or a key reused for another size (OSQP's update would keep the old
        # problem and only print an error): set up; a new workspace starts from zero
        fresh = ws is None or (ws.nz, ws.nc) != (nz, rows.shape[0])
        t0 = time.perf_counter()
        try:
            if ws is None or fresh:
                ws = self._setup(osqp, qp, rows, lower, upper)
                self._workspaces[qp.key] = ws
            else:
                ws.solver.update(
                    q=qp.q, l=lower, u=upper, Px=qp.P[ws.p_rows, ws.p_cols], Ax=rows.T.ravel()
                )
            if ws.cold:
                ws.solver.warm_start(x=np.zeros(nz), y=np.zeros(rows.shape[0]))
            result = ws.solver.solve(raise_error=False)
            iterations = int(result.info.iter)
            if result.info.status not in ACCEPTED and not (ws.cold or fresh):
                # a warm start from a very different problem can stall ADMM: once from zero
                ws.solver.warm_start(x=np.zeros(nz), y=np.zeros(rows.shape[0]))
                result = ws.solver.solve(raise_error=False)
                iterations += int(result.info.iter)
            status = str(result.info.status)
            x = finite_solution(result.x, nz) if status in ACCEPTED else None
        except Exception as exc:  # raised, or answered something that is not a result
            self._workspaces.pop(qp.key, None)
            raise ProblemError(f"osqp: {exc}") from exc
        solve_time = time.perf_counter() - t0
        if x is None and status in ACCEPTED:
            status = "non-finite solution"
        ws.cold = x is None
        self._remember(qp, x)  # after a failure the next solve starts from zero
        return QPSolution(x, "solved" if x is not None else status, iterations, solve_time,
                          self.name)  # fmt: skip

    def _setup(self, osqp: Any, qp: QP, rows: Array, lower: Array, upper: Array) -> _Workspace:
        """A workspace whose P and constraint matrix store every entry (zeros included)."""
        nz = qp.q.size
        p_rows, p_cols = np.triu_indices(nz)
        order = np.lexsort((p_rows, p_cols))  # column-major: CSC order
        p_rows, p_cols = p_rows[order], p_cols[order]
        indptr = np.searchsorted(p_cols, np.arange(nz + 1))
        P = sp.csc_matrix((qp.P[p_rows, p_cols], p_rows, indptr), shape=(nz, nz))
        nc = rows.shape[0]
        A = sp.csc_matrix(
            (rows.T.ravel(), np.tile(np.arange(nc), nz), np.arange(nz + 1) * nc), shape=(nc, nz)
        )
        solver = osqp.OSQP()
        solver.setup(P, qp.q, A, lower, upper, **self.options)
        return _Workspace(solver, p_rows, p_cols, nz, nc)
