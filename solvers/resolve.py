r"""The resolver's numerical pipeline: task rows and the step's bounds in, a Resolution out.

Each task gives rows ``A qdot ~= b`` with row weights (:class:`TaskRows`); the limits give the
joint-rate bounds of the step (:class:`~solvers.joint_bounds.StepBounds`) and, optionally,
inequality rows ``G qdot <= h`` (:class:`Inequalities`, for collision and workspace limits).
The levels are solved one after another, each exactly within the optimal set of those above
it (Kanoun, Lamiraux & Wieber 2011; Escande, Mansard & Wieber 2014): a level's rows, stacked
and row-weighted, are factorised once (:class:`~solvers.jacobian_svd.JacobianSVD`), and the
next level moves only in their null space, so it cannot change their achieved rates.

The top level (level 0):

1. its least-squares rates of least norm, exact, are the answer when they are inside the
   bounds (the box-free optimum: no QP is built);
2. otherwise the QP (:mod:`solvers.qp`, :mod:`solvers.direction`), solved by the backend:

   - direction-preserving (default, and standing still allowed): with w the exact rates,
     :math:`\dot q = u\,c\,w + V_n y`, maximise :math:`u \in [0, 1]` subject to the bounds
     (and rows); the task velocity is :math:`u c` times the command's, whatever y, so the
     hand slows down along the command instead of veering (Drake's formulation; the null
     space parametrised, so no rank-deficient equality rows). The cap c <= 1 keeps u of order
     one for absurd commands. Without a null space, or with one of one dimension (seven
     joints, six rows), the largest feasible u is computed directly (no QP). Near a
     singularity (:class:`~solvers.jacobian_svd.Damping`: a weak singular direction, and
     exact rates beyond the bounds) w is the damped rates instead (``damped``): along the
     exact ones a step crosses the singularity and the next one comes back;
   - least squares (tracking mode, weighted priorities, or a joint recovering into its
     range): :math:`\min \|A\dot q - b\|^2 + \epsilon\|\dot q\|^2` within the bounds,
     exactly the least squares of the tasks' costs (a damping task adds Levenberg-Marquardt
     damping).

3. If the backend fails (an exception, no solution, or an answer outside the bounds beyond
   its tolerance), the fallbacks answer in order: ``scipy`` (the same problem, exactly, by
   scipy.optimize: the direction LP by HiGHS, the largest u with any y; or the bounded least
   squares by BVLS), ``dls`` (the rates clipped), ``scaling`` (the rates scaled uniformly
   into the bounds), and always last ``hold`` (the feasible rates nearest zero). Nothing
   raises for numerical trouble.

The lower levels (strict priorities): :math:`\dot q = x + N^T z` with x the answer so far
and N the rows spanning the null space of every level above; the level's least squares in z
within the bounds (box-free optimum first, then the backend). A level that fails keeps the
answer of the levels above (recorded in ``attempts``).

Every answer is finally clipped into the bounds (the clip size is reported), so it is
exactly feasible whatever the backend's tolerance.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from solvers.direction import direction_lp, direction_qp, line_scale, uniform_scale
from solvers.errors import InputError, ProblemError
from solvers.jacobian_svd import Damping, JacobianSVD, normal_rates
from solvers.joint_bounds import ON_LIMIT, StepBounds
from solvers.qp import QP, Decoding
from solvers.qp_backends import QPBackend
from solvers.resolution import (
    EXACT_TOL,
    METHODS,
    Method,
    Resolution,
    Status,
    TaskRows,
    norm,
    scale_along,
)

Array = npt.NDArray[np.float64]

FEASIBILITY_TOL = 1e-6
"""A backend's answer may leave the bounds by this much times (1 + the norm of the velocity
limits) before it counts as a failure (it is clipped back in either way)."""

ROUNDING = 1e-12
"""[rad/s] Slack given to the rows of a lower level's QP, whose start z = 0 sits on its
bounds wherever a joint is at a bound."""

LEAST_NORM = 1e-6
"""Weight of the least-norm term of the least-squares QPs, relative to the trace of their P
(at least the rows' largest squared singular value): it makes P definite where the rows
leave joints free, and keeps DAQP's factorisation well conditioned (at 1e-9 it declared some
feasible lower levels infeasible). The box-free optimum, used whenever it is inside the
bounds, has no such term."""


HUGE = 1e150
"""A direction-preserving command longer than this is resolved for its direction (divided by
its largest entry): its exact rates would overflow, and the bounds set the answer's speed
either way."""


class Inequalities(NamedTuple):
    """Rows ``G qdot <= h`` that every answer must satisfy (collision, workspace walls).

    Attributes:
        G: Rows (p, n).
        h: Bounds (p,); ``h >= 0`` where standing still is allowed.
    """

    G: Array
    h: Array


DEFAULT_FALLBACKS: tuple[Method, ...] = ("scipy", "scaling")
"""The fallbacks tried after the QP by default: the same problem solved exactly by scipy,
then the uniform scale of the (damped) rates; ``hold`` ends every chain."""


@dataclass(frozen=True)
class ResolveOptions:
    """How the pipeline solves (module docstring).

    Attributes:
        direction_preserving: Top level as the direction-preserving QP (else least squares).
        damping: Damping near singularities, or None for none.
        fallbacks: Methods tried in order after the QP (names of
            :data:`~solvers.resolution.METHODS` except ``qp``); ``hold`` always ends.

    Raises:
        InputError: An unknown or repeated fallback, ``qp`` among them, or ``hold`` before
            another one (nothing after it would run).
    """

    direction_preserving: bool = True
    damping: Damping | None = field(default_factory=Damping)
    fallbacks: Sequence[Method] = DEFAULT_FALLBACKS

    def __post_init__(self) -> None:
        given: Sequence[str] = self.fallbacks
        try:
            fallbacks = (given,) if isinstance(given, str) else tuple(given)
        except TypeError:
            got = self.fallbacks
            raise InputError("fallbacks", f"expected method names, got {got!r}") from None
        for name in fallbacks:
            if name not in METHODS or name == "qp":
                choices = ", ".join(m for m in METHODS if m != "qp")
                raise InputError("fallbacks", f"unknown method {name!r}; expected {choices}")
        if len(set(fallbacks)) != len(fallbacks):
            raise InputError("fallbacks", f"repeated method in {fallbacks}")
        if "hold" in fallbacks[:-1]:
            raise InputError("fallbacks", f"'hold' always answers, so it comes last: {fallbacks}")
        if self.damping is not None and not isinstance(self.damping, Damping):
            raise InputError("damping", f"expected a solvers Damping or None, got {self.damping!r}")
        if not isinstance(self.direction_preserving, bool):
            raise InputError(
                "direction_preserving", f"expected True or False, got {self.direction_preserving!r}"
            )
        chain = fallbacks if fallbacks[-1:] == ("hold",) else (*fallbacks, "hold")
        object.__setattr__(self, "fallbacks", chain)


@dataclass(slots=True)
class _Solved:
    """What one level's solve produced (mutable while the pipeline runs).

    ``qdot`` is within the bounds (clipped, ``clip`` the size of the clip).
    """

    qdot: Array
    clip: float = 0.0
    backend: str = ""
    iterations: int = 0
    solve_time: float = 0.0

    def absorb(self, other: _Solved) -> None:
        """Count ``other``'s backend work (iterations, time) as this answer's too."""
        self.backend = self.backend or other.backend
        self.iterations += other.iterations
        self.solve_time += other.solve_time


class _Failed(Exception):
    """A method did not produce a usable answer (internal control flow)."""


_NUMERICAL = (_Failed, ProblemError, np.linalg.LinAlgError, ArithmeticError)
"""What a method may fail with (numerical trouble): the pipeline records it and goes on."""


@dataclass(slots=True)
class _TopLevel:
    """The top level's rows, its exact rates, and the damping near singularities."""

    A: Array  # stacked, row-weighted rows
    b: Array
    exact: Array  # the least-squares rates of least norm
    fits: bool  # the exact rates satisfy the bounds and rows: the answer
    factor: JacobianSVD | None  # the SVD, once a step needs it (see svd)
    lam: Array | None = None  # squared damping per singular direction where it may help
    damping_svd: JacobianSVD | None = None  # the SVD lam is for (rows without clamped joints)
    damped: bool = False  # the damped rates answered

    @property
    def svd(self) -> JacobianSVD:
        """The SVD of the rows (computed on first use: most steps do not need it)."""
        if self.factor is None:
            self.factor = JacobianSVD(self.A)
        return self.factor

    @property
    def smooth(self) -> Array:
        """The damped rates where damping may help, else the exact ones (for fallbacks)."""
        if self.lam is None or self.damping_svd is None:
            return self.exact
        return self.damping_svd.rates(self.b, self.lam)

    @property
    def lambda_sq(self) -> float:
        """The largest squared damping applied (0 when undamped)."""
        return float(np.max(self.lam)) if self.damped and self.lam is not None else 0.0


def resolve(
    levels: Sequence[Sequence[TaskRows]],
    bounds: StepBounds,
    backend: QPBackend,
    options: ResolveOptions,
    *,
    weighted: bool = False,
    rows: Inequalities | None = None,
    joint_names: tuple[str, ...] | None = None,
    copy_rows: bool = True,
) -> Resolution:
    """Joint rates serving ``levels`` in priority order within ``bounds`` (module docstring).

    Inputs are not checked here (the caller validates them): every array finite, shapes
    consistent, at least one level of at least one task.

    Args:
        levels: Task rows per priority level, highest first (one level when ``weighted``).
        bounds: Joint-rate bounds of the step.
        backend: The QP backend (warm-started across calls).
        options: How to solve.
        weighted: One level whose tasks trade off by their weights (least squares, no
            direction preservation).
        rows: Inequality rows every answer must satisfy, or None.
        joint_names: Names for the report.
        copy_rows: Keep copies of the rows in the resolution (the caller may change its
            arrays); False for rows nobody changes (the resolver's fresh Jacobian).

    Returns:
        The :class:`~solvers.resolution.Resolution`; never raises for numerical trouble.
    """
    t0 = time.perf_counter()
    attempts: list[tuple[str, str]] = []
    solved: _Solved | None = None
    top: _TopLevel | None = None
    method: Method = "qp"
    direction = options.direction_preserving and not weighted and bounds.contains_zero
    if rows is not None and (rows.h < 0.0).any():
        direction = False  # standing still would violate a row: least squares
    try:
        top = _top_level(levels[0], bounds, options, rows, direction)
        solved = _solve_top(top, bounds, backend, options, direction, rows)
    except _NUMERICAL as exc:
        attempts.append(("qp", str(exc)))
    if solved is None:
        for name in options.fallbacks:
            try:
                solved = _fallback(name, top, bounds, rows, direction)
                method = name
                break
            except _NUMERICAL as exc:
                attempts.append((name, str(exc)))
    assert solved is not None  # "hold" always answers
    if method == "qp" and len(levels) > 1:
        null = top.svd.null_basis() if top is not None else None
        for k, level in enumerate(levels[1:], start=1):
            if null is None or null.shape[0] == 0:
                break
            try:
                last = k == len(levels) - 1
                null = _lower_level(level, solved, null, bounds, backend, rows, k, last)
            except _NUMERICAL as exc:
                attempts.append((f"level {k}", f"{exc}; the levels above kept"))
                break
    solved.qdot.flags.writeable = False
    kept = _copies(levels) if copy_rows else tuple(tuple(level) for level in levels)
    return _report(
        kept, bounds, method, top, solved, attempts, time.perf_counter() - t0, joint_names,
        weighted,
    )  # fmt: skip


def _stack(tasks: Sequence[TaskRows]) -> tuple[Array, Array]:
    """Rows and rates of ``tasks`` stacked, each row times the square root of its weight."""
    As, bs = [], []
    for t in tasks:
        if t.weight is None:
            As.append(t.A)
            bs.append(t.b)
        else:
            root = np.sqrt(t.weight)
            As.append(t.A * root[:, None])
            bs.append(t.b * root)
    if len(As) == 1:
        return As[0], bs[0]
    return np.vstack(As), np.concatenate(bs)


def _clipped(x: Array, bounds: StepBounds) -> tuple[Array, float]:
    """``x`` clipped into the bounds, and the Euclidean size of the clip (NaN for NaN)."""
    y = np.minimum(np.maximum(x, bounds.lb), bounds.ub)
    return y, norm(y - x)


def _rows_hold(x: Array, rows: Inequalities | None, tol: float = 0.0) -> bool:
    return rows is None or bool((rows.G @ x <= rows.h + tol).all())


def _inside(x: Array, bounds: StepBounds, rows: Inequalities | None) -> bool:
    """Whether the rates ``x`` satisfy the bounds and the rows exactly (False for NaN)."""
    within = zip(bounds.lb.tolist(), x.tolist(), bounds.ub.tolist(), strict=True)
    return all(lo <= v <= hi for lo, v, hi in within) and _rows_hold(x, rows)


def _scaled(w: Array, bounds: StepBounds) -> _Solved:
    """The rates ``w`` scaled uniformly to the largest fraction in [0, 1] within the bounds."""
    return _Solved(*_clipped(uniform_scale(w, bounds.lb, bounds.ub) * w, bounds))


def _top_level(
    tasks: Sequence[TaskRows],
    bounds: StepBounds,
    options: ResolveOptions,
    rows: Inequalities | None,
    damp: bool,
) -> _TopLevel:
    """The top level's exact rates, and (if ``damp``) the damping it may need."""
    A, b = _stack(tasks)
    size = norm(b) if damp else 0.0
    if size > HUGE:  # the direction problem depends on the command's direction only
        b = b / float(np.abs(b).max())
    factor = None
    exact = normal_rates(A, b)
    if exact is None:  # not well posed for the normal equations: the SVD
        factor = JacobianSVD(A)
        exact = factor.rates(b)
    fits = size <= HUGE and _inside(exact, bounds, rows)
    top = _TopLevel(A, b, exact, fits, factor)
    if damp and not fits and options.damping is not None:
        svd, rates = _clamped(top, bounds)
        top.lam = options.damping.lambda_sq(
            svd, bounds.velocity, rates, bounds.lb, bounds.ub, bounds.dt
        )
        top.damping_svd = svd
    return top


def _clamped(top: _TopLevel, bounds: StepBounds) -> tuple[JacobianSVD, Array]:
    """The rows' SVD and exact rates for the damping, with clamped joints taken out.

    A joint is clamped where the exact rates push it against a bound that holds it still
    (to :data:`~solvers.joint_bounds.ON_LIMIT` over the step: a joint that one step brought
    to its limit may stop an ulp short of it), Baerlocher & Boulic 2004's clamping, as long
    as the rows keep their rank without it (else the command needs it, and the rows' own
    SVD serves: the answer stops). Such a joint is lost to the command, and the singularity
    that matters is that of the other joints (rolling rrc_k1607's hand with joint 7 on its
    limit: without the clamp the damping saw a regular Jacobian, and the joints flipped
    between opposite rate limits at 283 of 300 ticks, the hand at 0.3 % of the command).
    """
    exact, still = top.exact, ON_LIMIT / bounds.dt  # a bound within rounding of zero holds
    joints = zip(bounds.lb.tolist(), exact.tolist(), bounds.ub.tolist(), strict=True)
    pushed = [j for j, (lo, w, hi) in enumerate(joints)
              if (w > 0.0 and hi <= still) or (w < 0.0 and lo >= -still)]  # fmt: skip
    # fewer free joints than the rank: the rank is lost for sure, no SVD needed to know it
    if not pushed or exact.size - len(pushed) < top.svd.rank:
        return top.svd, exact
    A = top.A.copy()
    A[:, pushed] = 0.0
    svd = JacobianSVD(A)
    if svd.rank < top.svd.rank:  # the command needs them: the original problem (it stops)
        return top.svd, exact
    return svd, svd.rates(top.b)


def _solve_top(
    top: _TopLevel,
    bounds: StepBounds,
    backend: QPBackend,
    options: ResolveOptions,
    direction: bool,
    rows: Inequalities | None,
) -> _Solved:
    """The top level's answer: the exact rates, or the QP (module docstring)."""
    if top.fits:  # the box-free optimum: no QP
        return _Solved(top.exact)
    if not direction:
        qp, decoding = _least_squares_qp(top, bounds, rows)
        return _backend_solve(qp, decoding, bounds, backend, rows)

    def along(w: Array) -> _Solved:  # the exact rates are known not to fit (top.fits)
        inside = w is not top.exact and _inside(w, bounds, rows)
        return _Solved(w) if inside else _along(w, top, bounds, backend, rows)

    return _damped_or_exact(top, along)


def _damped_or_exact(top: _TopLevel, along: Callable[[Array], _Solved]) -> _Solved:
    """The direction problem ``along(w)``: w the damped rates near a singularity, else exact.

    Near a singularity (``top.lam``: a weak direction, and exact rates beyond the bounds) not
    along the exact rates, whatever their first-order progress: a step along them crosses
    the singularity and the next one comes back (Barker's stretched elbow pushed outward,
    measured: the joints flipped between opposite rate limits on 178 of 250 ticks, the hand
    at 2-4 % of the command). Along the exact ones only where the damped rates cannot move
    at all (a joint on its limit that they push further) and the exact ones can.
    """
    if top.lam is None:
        return along(top.exact)
    top.damped = True
    damped = top.smooth
    solved = along(damped)
    size = float(damped @ damped)
    if float(solved.qdot @ damped) > EXACT_TOL * size or size == 0.0:
        return solved  # moving along the damped rates (their fraction: qdot . w / |w|^2)
    other = along(top.exact)
    if _progress(other, top) <= _progress(solved, top):
        return solved
    top.damped = False
    other.absorb(solved)  # the damped direction's QP ran too
    return other


def _progress(solved: _Solved, top: _TopLevel) -> float:
    """How far along the top level's command an answer goes (its scale)."""
    return scale_along(top.A @ solved.qdot, top.b)


def _along(
    w: Array, top: _TopLevel, bounds: StepBounds, backend: QPBackend, rows: Inequalities | None
) -> _Solved:
    """The direction-preserving problem along the rates ``w`` (solvers.direction)."""
    null = top.svd.null_basis()
    if rows is None and null.shape[0] == 0:  # no null space: the largest uniform scale
        return _scaled(w, bounds)
    if rows is None and null.shape[0] == 1:  # one null direction: exactly, no QP; against
        # the QP, panda's benchmark median -24 % and p99 -17 %, rrc_k1607's -9 % / -16 %
        u, y = line_scale(w, null[0], bounds.lb, bounds.ub)
        return _tolerated(_Solved(*_clipped(u * w + y * null[0], bounds)), bounds, None, "exact")
    d, n = null.shape
    qp, decoding = direction_qp(w, null, bounds.lb, bounds.ub, f"direction:{n}:{d}")
    if rows is not None:
        C, lo, hi = _rows_of(decoding.M, bounds, rows, None)  # type: ignore[arg-type]
        qp = qp._replace(C=C, l=lo, u=hi)
    solved = _backend_solve(qp, decoding, bounds, backend, rows)
    if rows is None:  # u with y = 0 is feasible: an accurate backend does at least as well
        wc = decoding.M[:, -1]  # type: ignore[index]
        u_floor = uniform_scale(wc, bounds.lb, bounds.ub)
        if float(solved.qdot @ wc) < u_floor * float(wc @ wc) * (1.0 - EXACT_TOL):
            solved.qdot, solved.clip = _clipped(wc * u_floor, bounds)
    return solved


def _least_squares_qp(
    top: _TopLevel, bounds: StepBounds, rows: Inequalities | None
) -> tuple[QP, Decoding]:
    """The tracking QP over qdot: min |A qdot - b|^2 + damping + eps |qdot|^2, box = bounds."""
    A = top.A
    n = A.shape[1]
    P = _with_least_norm(A.T @ A)
    q = -(top.b @ A)
    if rows is None:
        qp = QP(P, q, None, None, None, bounds.lb, bounds.ub, f"least_squares:{n}")
    else:
        qp = QP(P, q, rows.G, np.full(rows.h.size, -np.inf), rows.h, bounds.lb, bounds.ub,
                f"least_squares:{n}:{rows.h.size}")  # fmt: skip
    return qp, Decoding(None, None)


def _with_least_norm(P: Array) -> Array:
    """``P`` (d, d), the normal matrix of some rows, plus the least-norm term.

    The term is :data:`LEAST_NORM` times P's trace (at least 1): the sum of the rows'
    squared singular values, at least the largest and at most rank times it (LAPACK's
    largest eigenvalue instead, dsyevr, cost as much as DAQP's solve on baxter's 15 x 15 P:
    9 % of its weighted step).
    """
    P.flat[:: P.shape[0] + 1] += LEAST_NORM * max(float(P.trace()), 1.0)
    return P


def _rows_of(
    M: Array, bounds: StepBounds, rows: Inequalities | None, x0: Array | None
) -> tuple[Array, Array, Array]:
    """Constraint rows ``l <= C z <= u`` of rates ``x0 + M z``: the bounds, then ``G``."""
    lo = bounds.lb if x0 is None else bounds.lb - x0
    hi = bounds.ub if x0 is None else bounds.ub - x0
    if rows is None:
        return M, lo, hi
    h = rows.h if x0 is None else rows.h - rows.G @ x0
    return (
        np.vstack([M, rows.G @ M]),
        np.concatenate([lo, np.full(h.size, -np.inf)]),
        np.concatenate([hi, h]),
    )


def _backend_solve(
    qp: QP, decoding: Decoding, bounds: StepBounds, backend: QPBackend, rows: Inequalities | None
) -> _Solved:
    """The backend's answer, clipped into the bounds; a failure beyond its tolerance."""
    sol = backend.solve(qp)
    if sol.x is None:
        raise _Failed(f"{sol.backend}: {sol.status}")
    qdot, clip = _clipped(decoding.rates(sol.x), bounds)
    solved = _Solved(qdot, clip, sol.backend, sol.iterations, sol.solve_time)
    return _tolerated(solved, bounds, rows, sol.backend)


def _tolerated(solved: _Solved, bounds: StepBounds, rows: Inequalities | None, who: str) -> _Solved:
    """``solved``, if it was outside the bounds and rows by at most the tolerance.

    The tolerance is :data:`FEASIBILITY_TOL` relative to the velocity limits; beyond it (NaN
    included) the answer is a failure of ``who``.
    """
    tol = FEASIBILITY_TOL * (1.0 + norm(bounds.velocity))
    if not (solved.clip <= tol and _rows_hold(solved.qdot, rows, tol)):
        raise _Failed(f"{who}: answer outside the bounds by {solved.clip:.3g}")
    return solved


def _lower_level(
    tasks: Sequence[TaskRows],
    solved: _Solved,
    null: Array,
    bounds: StepBounds,
    backend: QPBackend,
    rows: Inequalities | None,
    k: int,
    last: bool,
) -> Array | None:
    """Serve one lower level in the null space ``null`` (d, n) of the levels above.

    Updates ``solved`` in place; returns the null space left for the next level (None after
    the ``last`` one, whose SVD is then not needed when the normal equations answer).
    """
    A, b = _stack(tasks)
    x = solved.qdot
    B = A @ null.T
    c = b - A @ x
    svd = None
    z = normal_rates(B, c) if last else None
    if z is None:
        svd = JacobianSVD(B)
        z = svd.rates(c)
    candidate, clip = x + z @ null, 0.0
    if not _inside(candidate, bounds, rows):
        d, n = null.shape
        P = _with_least_norm(B.T @ B)
        C, lo, hi = _rows_of(null.T, bounds, rows, x)
        # z = 0 (the answer so far) is feasible: keep it so for the backend's tolerance where
        # joints sit exactly on their bounds (the final clip restores them exactly)
        lo, hi = np.minimum(lo, 0.0) - ROUNDING, np.maximum(hi, 0.0) + ROUNDING
        free = np.full(d, np.inf)
        qp = QP(P, -(c @ B), C, lo, hi, -free, free, f"level{k}:{n}:{d}")
        answer = _backend_solve(qp, Decoding(x, null.T), bounds, backend, rows)
        candidate, clip = answer.qdot, max(answer.clip, solved.clip)
        solved.backend = answer.backend or solved.backend  # the last backend that answered
        solved.absorb(answer)
    solved.qdot, solved.clip = candidate, clip
    if last:
        return None
    assert svd is not None  # only the last level may skip the SVD
    return svd.null_basis() @ null


def _fallback(
    name: Method,
    top: _TopLevel | None,
    bounds: StepBounds,
    rows: Inequalities | None,
    direction: bool,
) -> _Solved:
    """One fallback method's answer (module docstring); raises _Failed when it cannot."""
    if name == "hold":  # the last resort: it answers even where zero breaks a row
        return _Solved(np.minimum(np.maximum(0.0, bounds.lb), bounds.ub))
    if top is None:
        raise _Failed("no factorisation of the top level")
    if name == "scipy" and direction:  # the backend's direction problem, by HiGHS
        return _damped_or_exact(top, lambda w: _Solved(*_clipped(_scipy_lp(w, top, bounds, rows),
                                                                  bounds)))  # fmt: skip
    if name == "scipy":
        return _Solved(*_clipped(_scipy_bvls(top, bounds, rows), bounds))
    if name == "dls":
        solved = _Solved(*_clipped(top.smooth, bounds))
    elif not bounds.contains_zero:
        raise _Failed("zero rates are outside the bounds: the uniform scale has no start")
    else:
        solved = _scaled(top.smooth, bounds)
    if not _rows_hold(solved.qdot, rows):
        raise _Failed(f"{name}: the answer breaks an inequality row")
    return solved


def _scipy_lp(w: Array, top: _TopLevel, bounds: StepBounds, rows: Inequalities | None) -> Array:
    """The direction problem along ``w`` solved exactly by scipy's HiGHS."""
    _, decoding = direction_qp(w, top.svd.null_basis(), bounds.lb, bounds.ub, "")
    assert decoding.M is not None
    C, lo, hi = _rows_of(decoding.M, bounds, rows, None)
    return direction_lp(decoding.M, C, lo, hi)


def _scipy_bvls(top: _TopLevel, bounds: StepBounds, rows: Inequalities | None) -> Array:
    """The top level's bounded least squares solved exactly by scipy's BVLS."""
    if rows is not None:
        raise _Failed("scipy's bounded least squares takes no inequality rows")
    from scipy.optimize import lsq_linear

    x: Array = bounds.lb.copy()  # joints with lb == ub are fixed there; BVLS takes the others
    free = bounds.lb < bounds.ub
    if free.any():
        A = top.A[:, free]
        try:
            rhs = top.b - top.A[:, ~free] @ x[~free]
            result = lsq_linear(A, rhs, bounds=(bounds.lb[free], bounds.ub[free]), method="bvls")
        except ValueError as exc:  # data lsq_linear refuses (non-finite entries)
            raise _Failed(f"lsq_linear: {exc}") from exc
        if not result.success:
            raise _Failed(f"lsq_linear: {result.message}")
        x[free] = result.x
    return x


def _report(
    levels: tuple[tuple[TaskRows, ...], ...],
    bounds: StepBounds,
    method: Method,
    top: _TopLevel | None,
    solved: _Solved,
    attempts: list[tuple[str, str]],
    elapsed: float,
    names: tuple[str, ...] | None,
    weighted: bool,
) -> Resolution:
    """The Resolution: the status decided here where the pipeline knows it, else on access."""
    status: Status | None = None
    if method != "qp":
        status = "fallback"
    elif bounds.recovering:
        status = "recovering"
    elif top is not None and top.damped:
        status = "damped"
    elif not weighted and top is not None and _outside_range(top):
        status = "singular"
    elif not weighted and top is not None and top.fits and len(levels) == 1:
        status = "exact"  # the box-free optimum of a full-rank command
    return Resolution(
        solved.qdot, method, solved.backend, solved.iterations, tuple(attempts), solved.clip,
        top.lambda_sq if top is not None else 0.0, elapsed - solved.solve_time,
        solved.solve_time, bounds, levels, names, status,
    )  # fmt: skip


def _outside_range(top: _TopLevel) -> bool:
    """Whether part of the top level's command is outside the range of its rows.

    At a singularity, or with more rows than joints; that part is the residual of the
    least-squares rates of least norm.
    """
    m, n = top.A.shape
    if m <= n and (top.factor is None or top.factor.rank == m):
        return False  # full row rank (the normal equations answered only if so)
    return norm(top.b - top.A @ top.exact) > EXACT_TOL * (1.0 + norm(top.b))


def _copies(levels: Sequence[Sequence[TaskRows]]) -> tuple[tuple[TaskRows, ...], ...]:
    """The levels with copies of their rows and rates: the resolution is a snapshot."""
    return tuple(
        tuple(TaskRows(t.A.copy(), t.b.copy(), t.weight, t.name) for t in level)
        for level in levels
    )
