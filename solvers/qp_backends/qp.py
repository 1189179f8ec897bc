r"""The QP of one priority level, built apart from solving it.

.. math::

    \min_z \tfrac12 z^T P z + q^T z \quad \text{s.t.} \quad l \le C z \le u, \quad
    lb \le z \le ub

(two-sided rows, as DAQP and OSQP take them; :meth:`QP.problem` gives the one-sided
``qpsolvers.Problem`` of the same QP), and how its solution z decodes into joint rates:
:math:`\dot q = x_0 + M z` (:class:`Decoding`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import numpy.typing as npt
import qpsolvers

from rrc_pin.solvers.errors import NumericalFailure
from rrc_pin.solvers.tick import feasibility
from rrc_pin.solvers.tick.problem import Box, Rows

if TYPE_CHECKING:
    from rrc_pin.solvers.qp_backends.base import QPBackend

Array = npt.NDArray[np.float64]

FEASIBILITY_TOL = 1e-6
"""A backend's answer may leave the box and rows by this much times (1 + the norm of the
velocity limits) before it counts as a failure (it is clipped back into the box either way)."""


class QP(NamedTuple):
    """A convex QP with two-sided constraint rows and a box (module docstring).

    Attributes:
        P: Symmetric positive definite cost matrix (nz, nz).
        q: Cost vector (nz,).
        C: Constraint rows (nc, nz), or None.
        l: Lower bounds of ``C z`` (nc,), -inf allowed, or None.
        u: Upper bounds of ``C z`` (nc,), +inf allowed, or None.
        lb: Lower bounds of z (nz,), -inf allowed.
        ub: Upper bounds of z (nz,), +inf allowed.
        key: Name of the problem's structure (kind and sizes): one warm start per key.
    """

    P: Array
    q: Array
    C: Array | None
    l: Array | None  # noqa: E741 - the usual name of the lower row bounds
    u: Array | None
    lb: Array
    ub: Array
    key: str

    def problem(self) -> qpsolvers.Problem:
        """The same QP as a ``qpsolvers.Problem``: rows ``G z <= h`` for every finite side.

        The box is passed as ``lb, ub`` when it is finite, else its finite sides become rows
        (some solvers mishandle infinite box bounds: proxqp reports no solution).
        """
        rows, rhs = [], []
        if self.C is not None and self.l is not None and self.u is not None:
            low, high = np.isfinite(self.l), np.isfinite(self.u)
            rows += [self.C[high], -self.C[low]]
            rhs += [self.u[high], -self.l[low]]
        lb: Array | None = self.lb
        ub: Array | None = self.ub
        if not (np.isfinite(self.lb).all() and np.isfinite(self.ub).all()):
            eye = np.eye(self.q.size)
            low, high = np.isfinite(self.lb), np.isfinite(self.ub)
            rows += [eye[high], -eye[low]]
            rhs += [self.ub[high], -self.lb[low]]
            lb = ub = None
        h = np.concatenate(rhs) if rhs else None
        G = np.vstack(rows) if h is not None and h.size else None  # no finite side: no rows
        return qpsolvers.Problem(self.P, self.q, G, h if G is not None else None, lb=lb, ub=ub)


class Decoding(NamedTuple):
    r"""Joint rates of a solution z: :math:`\dot q = x_0 + M z` (n,).

    Attributes:
        x0: Offset (n,), or None for zero.
        M: Map (n, nz), or None for the identity (z is the joint rates).
    """

    x0: Array | None
    M: Array | None

    def rates(self, z: Array) -> Array:
        """The joint rates (n,) of ``z`` (nz,)."""
        x = z if self.M is None else self.M @ z
        return x if self.x0 is None else x + self.x0


class QPSolution(NamedTuple):
    """What a backend returned for one :class:`QP`.

    Attributes:
        x: Primal solution (nz,), or None when none was found. Within the backend's
            tolerance only: the caller checks it and enforces the bounds exactly.
        status: The backend's own status ("solved" when found).
        iterations: Iterations used (0 where the backend does not say).
        solve_time: Time spent in the backend's solver [s].
        backend: Backend name.
    """

    x: Array | None
    status: str
    iterations: int
    solve_time: float
    backend: str


def finite_solution(x: object, nz: int) -> Array | None:
    """``x`` as a new finite real (nz,) float array, or None where it is not one.

    What a solver library returned is checked here before it is an answer: None, a ragged
    or non-numeric sequence, complex or boolean entries, the wrong shape and a non-finite
    entry are no solution.
    """
    try:
        z = np.asarray(x)
    except (TypeError, ValueError, OverflowError):
        return None
    if z.dtype.kind not in "fiu" or z.shape != (nz,):
        return None
    z = np.array(z, dtype=np.float64)
    return z if feasibility.all_finite(z) else None


class Solved(NamedTuple):
    """A backend's answer, checked and decoded.

    Attributes:
        x: The decoded rates (n,) (:func:`solve_checked`), or the solution z (nz,)
            (:func:`checked`).
        backend: The backend's name.
        iterations: Its iterations.
        solve_time: Time in its solver [s].
    """

    x: Array
    backend: str
    iterations: int
    solve_time: float


def solve_checked(backend: QPBackend, qp: QP, decoding: Decoding) -> Solved:
    """``qp`` solved by ``backend``, its answer checked (shape, finite) and decoded.

    Anything the backend raises, an answer past its time limit, and an answer of the wrong
    shape or with a non-finite entry, is a :class:`~rrc_pin.solvers.errors.NumericalFailure`: the
    caller's fallbacks answer.

    Raises:
        NumericalFailure: No usable answer.
    """
    try:
        sol = backend.solve(qp)
    except Exception as exc:
        raise NumericalFailure(f"{backend.name}: {type(exc).__name__}: {exc}") from exc
    solved = checked(sol, qp.q.size, backend.name)
    limit = backend.time_limit
    if limit is not None and solved.solve_time > limit:
        raise NumericalFailure(f"{solved.backend}: took {solved.solve_time:.3g} s, past the "
                               f"time limit {limit:.3g} s")  # fmt: skip
    return solved._replace(x=decoding.rates(solved.x))


def checked(sol: object, nz: int, name: str) -> Solved:
    """A backend's answer ``sol`` checked field by field: its solution z (nz,) undecoded.

    Raises:
        NumericalFailure: ``sol`` is not a :class:`QPSolution`, has no solution, a solution
            that is not a finite real (nz,) array (:func:`finite_solution`), or iterations
            or a time that are not numbers >= 0.
    """
    if not isinstance(sol, QPSolution):
        raise NumericalFailure(f"{name}: answered a {type(sol).__name__}, not a QPSolution")
    label = sol.backend if isinstance(sol.backend, str) else name
    if sol.x is None:
        raise NumericalFailure(f"{label}: {sol.status}")
    z = finite_solution(sol.x, nz)
    if z is None:
        what = (f"{sol.x.dtype} {sol.x.shape}" if isinstance(sol.x, np.ndarray)
                else type(sol.x).__name__)  # fmt: skip
        raise NumericalFailure(f"{label}: answer ({what}) is not a finite real ({nz},) array")
    iterations, elapsed = sol.iterations, sol.solve_time
    if not (isinstance(iterations, (int, np.integer)) and not isinstance(iterations, bool)
            and iterations >= 0):  # fmt: skip
        raise NumericalFailure(f"{label}: iterations {iterations!r}, not a count")
    if not (isinstance(elapsed, (float, int, np.floating, np.integer))
            and not isinstance(elapsed, bool) and 0.0 <= elapsed < math.inf):  # fmt: skip
        raise NumericalFailure(f"{label}: solve time {elapsed!r}, not a time [s]")
    return Solved(z, label, int(iterations), float(elapsed))


@dataclass(slots=True)
class Work:
    """What the backends did during one tick, and which methods failed.

    Attributes:
        backend: The last backend that answered, or "".
        iterations: Their iterations, summed.
        solve_time: Time inside their solvers [s].
        attempts: ``(method or level, reason)`` of every failure.
    """

    backend: str = ""
    iterations: int = 0
    solve_time: float = 0.0
    attempts: list[tuple[str, str]] = field(default_factory=list)


def solve_within(
    qp: QP, decoding: Decoding, box: Box, rows: Rows | None, backend: QPBackend, work: Work,
    clip: bool = True,
) -> Array:  # fmt: skip
    """The backend's answer to ``qp``, within the box and rows to :data:`FEASIBILITY_TOL`.

    Args:
        qp: The problem.
        decoding: How its solution decodes into rates.
        box: The step's bounds.
        rows: Constraint rows, or None.
        backend: The backend.
        work: Where its work is counted.
        clip: Clip the answer into the box; False: the answer as decoded (within the
            tolerance of the box; a direction answer keeps its direction, which a clip of each
            joint on its own turns: the caller's final clip is reported).

    Raises:
        NumericalFailure: No usable answer (the backend's fault, time-out or infeasibility, a
            non-finite answer or one outside the constraints beyond the tolerance).
    """
    solved = solve_checked(backend, qp, decoding)
    work.backend = solved.backend
    work.iterations += solved.iterations
    work.solve_time += solved.solve_time
    x: Array = solved.x.copy()
    size = feasibility.clip_into(x if clip else x.copy(), box.lb, box.ub)
    tol = tolerance(box)
    if not (size <= tol and (rows is None or feasibility.rows_hold(rows.G, x, rows.h, tol))):
        over = 0.0 if rows is None else float(np.max(rows.G @ x - rows.h, initial=0.0))
        raise NumericalFailure(f"{solved.backend}: answer outside the box by {size:.3g}, the rows "
                               f"by {over:.3g} (tolerance {tol:.3g})")  # fmt: skip
    return x


def tolerance(box: Box) -> float:
    """How far a backend's answer may leave the box and rows [rad/s or m/s, or the rows' units].

    :data:`FEASIBILITY_TOL` times (1 + the norm of the velocity limits).
    """
    return velocity_tolerance(box.velocity)


def velocity_tolerance(velocity: Array) -> float:
    """:func:`tolerance` of a box of velocity limits ``velocity`` (n,)."""
    return FEASIBILITY_TOL * (1.0 + math.hypot(*np.minimum(velocity, 1e300).tolist()))
