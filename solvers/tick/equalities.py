r"""The compiled tick's top level within equality rows :math:`C\dot q = d` (contacts, grips).

The pipeline's stage (:mod:`rrc_pin.solvers.tick.pipeline`: "equality rows come first of all")
as kernels: the rates that meet the rows are :math:`\dot q = x_0 + N^Tz`, :math:`x_0` the
least-norm solution of :math:`C\dot q = d` and N (r', n) orthonormal rows spanning C's null
space (:func:`space`; :func:`~rrc_pin.solvers.tick.pipeline._equality_space`). The top level
is then solved in z, its rows :math:`AN^T`, the box and the constraint rows kept on the
rates :math:`\dot q` themselves:

- the direction mode (:func:`direction_within`, where :math:`d = 0` so that standing still
  meets the rows): the least-norm z of :math:`AN^Tz = b`, its rates :math:`w = N^Tz`; where
  they cross a row the command slides along (a collision pair), the sliding stage first
  (:func:`sliding_within`: the command becomes what the box and those rows let it keep, their
  least squares in z, ``sliding``); the rates the answer where they keep the box and rows;
  else the largest scale along w, the motions that keep the task rates (the null space of
  :math:`AN^T`, times N) free (:func:`~rrc_pin.solvers.tick.top.scaled_along`); past the
  damping threshold the damped rates scaled instead (the rows' own condition number: no joint
  is clamped out, a column of :math:`AN^T` is no joint);
- the other modes (:func:`least_squares_within`): the least squares within the subspace
  (:func:`~rrc_pin.solvers.tick.levels.least_squares`, as a lower level is solved). The
  pipeline's relaxing of a collision pair asked apart (a slide row below zero) where that
  fails is not here: the compiled tick does not take such a row with equality rows
  (:meth:`rrc_pin.compiled_tick.CompiledTick.answers`).

The lower levels then move in the top level's null space, which lies inside N's span: every
level keeps the equality rows. Each function calls the kernels the pipeline's class methods
call, in the same order; the products with N are the compiled ones
(:func:`~rrc_pin.solvers.tick.levels.product`), so the answers agree with the pipeline's to
rounding, not bit for bit.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from numba import objmode

from rrc_pin.solvers.compiled import inlined, kernel
from rrc_pin.solvers.errors import NumericalFailure
from rrc_pin.solvers.linalg import row_values
from rrc_pin.solvers.tick import backend_calls, factor, feasibility, statuses, top
from rrc_pin.solvers.tick.levels import least_squares, product
from rrc_pin.solvers.tick.statuses import (
    DAMPED,
    EXACT,
    EXACT_TOL,
    LEAST_SQUARES,
    RECOVERING,
    SCALED,
    SINGULAR,
    SLIDING,
)
from rrc_pin.solvers.tick.top import FAILED, Rows, Top

Array = npt.NDArray[np.float64]

CONTRADICTED = "the equality rows contradict each other"
"""The failure recorded where no rates meet the equality rows (the fallbacks then answer)."""


def contradicted() -> None:
    """Record :data:`CONTRADICTED` as the pipeline's failure (a ``qp`` attempt)."""
    backend_calls._failed(backend_calls.TOP, NumericalFailure(CONTRADICTED))


@kernel
def space(C: Array, d: Array) -> tuple[Array, Array, bool]:
    """The least-norm rates x0 (n,) of ``C x = d``, the null space N (r', n) of C, and
    whether x0 meets the rows (:func:`~rrc_pin.solvers.tick.pipeline._equality_space`).
    """  # noqa: D205
    f, x0 = factor.least_norm(factor.qr(C), d)
    met = statuses.met(row_values(C, x0), d)
    return x0, factor.null_basis(f)[1], met


@inlined
def sliding_within(A: Array, b: Array, N: Array, rows: Rows, G: Array, h: Array) -> Array:
    """The sliding stage within the rows' null space N (d, n): what the box and the rows the
    command slides along (``G``, ``h``) let it keep, their least squares in the rates
    ``N^T z`` (the pipeline's ``_slide`` within equality rows); empty where the backend failed
    (recorded: the command kept as given).
    """  # noqa: D205
    n = A.shape[1]
    # np.int64: not a literal, so one compiled signature serves every level
    kept, _ = least_squares(np.int64(backend_calls.SLIDE), A, b, np.zeros(n), N, rows.lb,  # type: ignore[arg-type, unused-ignore]
                            rows.ub, G, h, rows.tol, False)  # fmt: skip
    return kept


@inlined
def direction_within(A: Array, b: Array, N: Array, rows: Rows, dt: float, threshold: float,
                     rate_factor: float, need_null: bool) -> Top:  # fmt: skip
    """The direction mode's top level in the rates ``N^T z`` (module docstring; the pipeline's
    ``_top`` with an equality space).
    """  # noqa: D205
    n, d = A.shape[1], N.shape[0]
    Nt = np.ascontiguousarray(N.T)
    f, z = factor.least_norm(factor.qr(product(A, Nt)), b)
    w = row_values(Nt, z)
    command, slid = b, False
    G, h = top.slide_rows(rows)
    if h.size and not feasibility.rows_hold(G, w, h, 0.0):  # the sliding stage changes b
        kept = sliding_within(A, b, N, rows, G, h)
        if kept.size:
            if rows.slide.all() or feasibility.rows_hold(rows.G, kept, rows.h, rows.tol):
                null = product(factor.null_basis(f)[1], N) if need_null else np.empty((0, n))
                return top.answer(A, command, kept, SLIDING, rate_factor, null, 0.0)
            b, slid = row_values(A, kept), True
            f, z = factor.least_norm(f, b)
            w = row_values(Nt, z)
    outside_range = not f.regular and not top.met(f.J, z, b)
    if feasibility.inside(w, rows.lb, rows.ub) and feasibility.rows_hold(rows.G, w, rows.h, 0.0):
        null = product(factor.null_basis(f)[1], N) if need_null else np.empty((0, n))
        if slid:
            return top.answer(A, command, w, SLIDING, rate_factor, null, 0.0)
        if outside_range:
            return top.answer(A, b, w, SINGULAR, rate_factor, null, 0.0)
        return top.met_top(w, rate_factor, null)
    f, free = factor.null_basis(f)
    null = product(free, N)
    qdot, u, veer = top.scaled_along(A, w, null, rows)
    if u < 0.0:
        return top.passing(w, null)
    if slid:
        return top.answer(A, command, qdot, SLIDING, rate_factor, null, 0.0)
    if not outside_range and u >= 1.0 - EXACT_TOL:
        return top.met_top(qdot, rate_factor, null)
    unbounded = np.full(d, np.inf)  # z has no bounds: no column of A N^T is clamped
    within = Rows(-unbounded, unbounded, np.empty((0, d)), rows.h[:0], rows.slide[:0], rows.tol,
                  rows.solved)
    usable, lam = top.damping(f, b, z, u, within, dt, threshold)
    if lam.size:
        damped, damped_u, _ = top.scaled_along(A, row_values(Nt, factor.rates(usable, b, lam)),
                                               null, rows)  # fmt: skip
        if damped_u < 0.0:
            return top.passing(w, null)
        return top.answer(A, b, damped, DAMPED, rate_factor, null, float(np.max(lam)))
    if outside_range:
        return top.answer(A, b, qdot, SINGULAR, rate_factor, null, 0.0)
    return Top(qdot, SCALED, u * rate_factor, veer, 0.0, null)


@inlined
def least_squares_within(A: Array, b: Array, per_unit: Array, x0: Array, N: Array, rows: Rows,
                         recovering: bool, rate_factor: float, need_null: bool) -> Top:  # fmt: skip
    """The top level of the other modes in the rates ``x0 + N^T z``: its least squares within
    the box and rows (``recovering`` where a joint or row must be restored).
    """  # noqa: D205
    qdot, null = least_squares(np.int64(backend_calls.TOP), A, b, x0, N, rows.lb, rows.ub,  # type: ignore[arg-type, unused-ignore]
                               rows.G, rows.h, rows.tol, need_null)  # fmt: skip
    if qdot.size == 0:
        return top.passing(qdot, null)
    if recovering or (rows.h < 0.0).any():
        status = RECOVERING
    else:
        status = EXACT if top.met(A, qdot, b) and rate_factor == 1.0 else LEAST_SQUARES
    scale, veer = top.along_command(A, b, qdot, per_unit, rate_factor)
    return Top(qdot, status, scale, veer, 0.0, null)


@kernel
def record_contradiction() -> None:
    """:func:`contradicted` from inside a kernel."""
    with objmode():
        contradicted()


@inlined
def within(A: Array, b: Array, per_unit: Array, C: Array, d: Array, rows: Rows, direction: bool,
           recovering: bool, dt: float, threshold: float, rate_factor: float,
           need_null: bool) -> Top:  # fmt: skip
    """The top level within the equality rows ``C``, ``d`` (module docstring): the direction
    mode where ``direction``, else the least squares; :data:`FAILED` (recorded) where no rates
    meet the rows.
    """  # noqa: D205
    x0, N, met = space(C, d)
    if not met:
        record_contradiction()
        return top.passing(x0, np.empty((0, x0.size)))
    if direction:
        return direction_within(A, b, N, rows, dt, threshold, rate_factor, need_null)
    return least_squares_within(A, b, per_unit, x0, N, rows, recovering, rate_factor, need_null)


__all__ = ["CONTRADICTED", "FAILED", "space", "within"]
