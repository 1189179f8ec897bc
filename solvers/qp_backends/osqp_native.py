"""OSQP through its native Python API, one workspace per problem structure, warm-started.

Algorithm: ADMM operator splitting for convex QPs, with solution polishing (Stellato,
Banjac, Goulart, Bemporad & Boyd, "OSQP: an operator splitting solver for quadratic
programs", Mathematical Programming Computation 12:637-672, 2020).

Warm starts: yes. The workspace is set up once per problem structure (kind and sizes) with
a fixed, dense-as-sparse pattern (every entry of the upper triangle of P and of the
constraint rows G stored, zeros included), then updated in place (``update(q, l, u, Px,
Ax)``, tens of microseconds) instead of set up again (hundreds); each solve starts from the
previous primal and dual solution (OSQP's ``warm_starting``). Defaults are tighter than
OSQP's 1e-3: ``eps_abs = eps_rel = 1e-6``, with polishing, which then returns the solution
of the identified active set to about 1e-12 (without polishing, an ADMM answer at 1e-6 is
off by up to 1e-4 along weakly curved directions); at most 4000 iterations or 5 ms per
solve. Ruiz scaling is off (``scaling=0``): these problems are small and well scaled, and
without it a matrix update skips the re-equilibration (half of OSQP's time per update). On
the 2119 constrained tracking problems of the benchmark trajectories the polished answers
are the same (to 1e-13) and the solves as fast or faster, median and 99th percentile;
``check_termination``, ``eps`` 1e-5 and adaptive-rho settings were measured too and kept
(1e-5 saves 3 us per solve but leaves answers 1e-3 off wherever polishing fails).

OSQP's C code prints "Polishing not needed - no active set detected at optimal point" to
standard output (whatever ``verbose``) when no constraint is active at the solution; the
resolver's shortcut returns the box-free optimum without calling OSQP in exactly that case.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import scipy.sparse as sp

from solvers.errors import ProblemError
from solvers.qp_backends.base import Array, QPBackend, QPSolution, structure_key
from solvers.qp_problem import QPProblem

DEFAULT_SETTINGS: dict[str, Any] = {
    "eps_abs": 1e-6,
    "eps_rel": 1e-6,
    "polishing": True,
    "max_iter": 4000,
    "time_limit": 5e-3,
    "check_termination": 5,
    "scaling": 0,
    "verbose": False,
    "warm_starting": True,
}
"""OSQP settings used unless overridden (``OSQPBackend(eps_abs=..., ...)``)."""

ACCEPTED = ("solved", "solved inaccurate")
"""OSQP statuses that count as a solution."""


INFTY = 1e30
"""OSQP's infinity (OSQP_INFTY): bounds beyond it are clipped to it."""


@dataclass
class _Workspace:
    """One OSQP solver for one problem structure, and the buffers its updates reuse."""

    name: str  # structure_key of the problem
    solver: Any
    p_flat: npt.NDArray[np.intp]  # flat indices of P's upper triangle, in CSC order
    a_data: Array
    g_index: npt.NDArray[np.intp]
    lo: Array  # (nx + ng,): box rows, then G rows
    up: Array
    lo_box: Array  # views of the first nx entries
    up_box: Array
    zero_x: Array
    zero_y: Array
    native: Any = None
    cold: bool = False


class OSQPBackend(QPBackend):
    """OSQP (native API), warm-started, updated in place with a fixed sparsity pattern.

    Args:
        **settings: OSQP settings overriding :data:`DEFAULT_SETTINGS`.

    Raises:
        ProblemError: osqp is not importable.
    """

    name = "osqp"
    warm_starts = True

    def __init__(self, **settings: Any) -> None:
        try:
            import osqp
        except ImportError as exc:  # pragma: no cover - osqp is a hard dependency
            raise ProblemError("osqp is not installed (pip install osqp)") from exc
        self._osqp = osqp
        self.settings = {**DEFAULT_SETTINGS, **settings}
        self._workspaces: dict[tuple[str, int, int], _Workspace] = {}

    def reset(self) -> None:
        """Forget every warm start (workspaces are kept: their setup is not redone)."""
        for ws in self._workspaces.values():
            ws.cold = True

    def warm_start_state(self) -> dict[str, Array]:
        """Copies of the primal and dual solution of every workspace (the next warm start)."""
        state: dict[str, Array] = {}
        for ws in self._workspaces.values():
            if not ws.cold:
                state[f"{ws.name}:x"] = np.array(ws.native.solution.x)
                state[f"{ws.name}:y"] = np.array(ws.native.solution.y)
        return state

    def solve(self, problem: QPProblem) -> QPSolution:
        """Update (or set up) the workspace of the problem's structure and solve.

        OSQP's ``warm_starting`` starts each solve from the previous primal and dual
        solution of the same workspace; after :meth:`reset` or a failed solve the next one
        starts from zero, and a warm-started solve that fails is retried once from zero.

        Raises:
            ProblemError: OSQP raised during setup, update or solve.
        """
        t0 = time.perf_counter()
        nx = problem.P.shape[0]
        key = (problem.kind, nx, 0 if problem.G is None else problem.G.shape[0])
        ws = self._workspaces.get(key)
        try:
            if ws is None:
                ws = self._setup(problem)
                self._workspaces[key] = ws
            else:
                self._update(ws, problem)
            native = ws.native
            if ws.cold:
                native.warm_start(ws.zero_x, ws.zero_y)
            t1 = time.perf_counter()
            native.solve()
            info = native.info
            status, iterations = info.status, info.iter
            if status not in ACCEPTED and not ws.cold:
                # A warm start (iterate and adapted rho) from a very different problem can
                # stall ADMM: retry once from zero with the initial rho.
                native.update_rho(self.settings.get("rho", 0.1))
                native.warm_start(ws.zero_x, ws.zero_y)
                native.solve()
                info = native.info
                status, iterations = info.status, iterations + info.iter
            t2 = time.perf_counter()
            x = native.solution.x[:nx] if status in ACCEPTED else None
        except Exception as exc:
            self._workspaces.pop(key, None)
            raise ProblemError(f"osqp: {exc}") from exc
        ws.cold = x is None
        return QPSolution(x, x is not None, status, iterations, t1 - t0, t2 - t1, self.name)

    @staticmethod
    def _update(ws: _Workspace, problem: QPProblem) -> None:
        """New data, same pattern: vectors, then matrices (OSQP refactors its KKT system)."""
        np.maximum(problem.lb, -INFTY, out=ws.lo_box)
        np.minimum(problem.ub, INFTY, out=ws.up_box)
        Px = problem.P.take(ws.p_flat)
        native = ws.native
        if problem.G is None:
            native.update_data_vec(q=problem.q, l=ws.lo, u=ws.up)
            native.update_data_mat(P_x=Px, P_i=None, A_x=None, A_i=None)
            return
        nx = ws.lo_box.size
        ws.lo[nx:] = problem.lo
        ws.up[nx:] = problem.hi
        ws.a_data[ws.g_index] = problem.G.T.ravel()
        native.update_data_vec(q=problem.q, l=ws.lo, u=ws.up)
        native.update_data_mat(P_x=Px, P_i=None, A_x=ws.a_data, A_i=None)

    def _setup(self, problem: QPProblem) -> _Workspace:
        nx = problem.P.shape[0]
        G = problem.G if problem.G is not None else np.zeros((0, nx))
        ng = G.shape[0]
        # P: full upper triangle, column-major (CSC order), zeros kept.
        p_rows, p_cols = np.triu_indices(nx)
        order = np.lexsort((p_rows, p_cols))
        p_rows, p_cols = p_rows[order], p_cols[order]
        P = sp.csc_matrix(
            (problem.P[p_rows, p_cols], p_rows, np.searchsorted(p_cols, np.arange(nx + 1))),
            shape=(nx, nx),
        )
        # C = [I; G]: column j holds row j (identity) then rows nx..nx+ng-1 (G[:, j]), dense.
        per_col = 1 + ng
        indices = np.empty(nx * per_col, dtype=np.intp)
        data = np.zeros(nx * per_col)
        identity_index = np.arange(nx) * per_col
        g_index = (identity_index[:, None] + 1 + np.arange(ng)[None, :]).ravel()
        indices[identity_index] = np.arange(nx)
        indices[g_index] = np.tile(nx + np.arange(ng), nx)
        data[identity_index] = 1.0
        data[g_index] = G.T.ravel()
        C = sp.csc_matrix((data, indices, np.arange(nx + 1) * per_col), shape=(nx + ng, nx))
        lo = np.empty(nx + ng)
        up = np.empty(nx + ng)
        np.maximum(problem.lb, -INFTY, out=lo[:nx])
        np.minimum(problem.ub, INFTY, out=up[:nx])
        if ng:
            lo[nx:] = problem.lo
            up[nx:] = problem.hi
        ws = _Workspace(
            name=structure_key(problem),
            solver=self._osqp.OSQP(),
            p_flat=p_rows * nx + p_cols,
            a_data=data,
            g_index=g_index,
            lo=lo,
            up=up,
            lo_box=lo[:nx],
            up_box=up[:nx],
            zero_x=np.zeros(nx),
            zero_y=np.zeros(nx + ng),
        )
        ws.solver.setup(P, problem.q, C, lo, up, **self.settings)
        # The extension object behind osqp.OSQP (update_data_vec/mat, warm_start, solve,
        # info, solution) skips the Python wrapper's per-call bookkeeping (about 20 us);
        # fall back to the public API where an osqp version does not have it.
        ws.native = getattr(ws.solver, "_solver", None) or _PublicAPI(ws.solver)
        return ws


class _PublicAPI:
    """The few native calls, through osqp.OSQP's public methods."""

    def __init__(self, solver: Any) -> None:
        self._solver = solver
        self._result: Any = None

    def update_rho(self, rho: float) -> None:
        self._solver.update_settings(rho=rho)

    def update_data_vec(self, q: Array, l: Array, u: Array) -> None:  # noqa: E741
        self._solver.update(q=q, l=l, u=u)

    def update_data_mat(
        self, P_x: Array, P_i: None, A_x: Array | None, A_i: None
    ) -> None:
        if A_x is None:
            self._solver.update(Px=P_x)
        else:
            self._solver.update(Px=P_x, Ax=A_x)

    def warm_start(self, x: Array, y: Array) -> None:
        self._solver.warm_start(x=x, y=y)

    def solve(self) -> None:
        self._result = self._solver.solve(raise_error=False)

    @property
    def info(self) -> Any:
        return self._result.info

    @property
    def solution(self) -> Any:
        return self._result
