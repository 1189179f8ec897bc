r"""The top level of the compiled tick: its stages in order, each answering or passing on.

The direction mode (:func:`direction`; the math of :mod:`rrc_pin.solvers.tick.pipeline`'s
module docstring, stage by stage):

1. **exact**: the least-norm rates w (:func:`~rrc_pin.solvers.tick.factor.fitted`) where they
   keep every constraint (``exact``; ``singular`` where part of the command is outside the
   rows' range);
2. **sliding**: where w crosses a row the command may slide along (a collision pair), the
   command becomes what the slide rows and the box let it keep (:func:`slid_command`), met or
   scaled (``sliding``);
3. **scaled**: the largest scale u of w within the constraints (:func:`scaled_along`): ``exact``
   at u = 1, ``scaled`` below it while the rows are well conditioned;
4. **damped**: past the damping threshold the damped rates scaled along themselves
   (:func:`damping`);
5. **singular**: part of the command outside the rows' range, the rest scaled.

The other modes' top level is a least squares (:func:`least_squares_top`). A stage whose QP the
kernels do not answer hands it to the backend (:mod:`rrc_pin.solvers.tick.backend_calls`);
where the backend fails, the top level fails (:data:`FAILED`) and the fallbacks answer.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt
from numba import objmode

from rrc_pin.solvers.compiled import inlined, kernel
from rrc_pin.solvers.linalg import row_values
from rrc_pin.solvers.tick import backend_calls, factor, feasibility, statuses
from rrc_pin.solvers.tick.damping import clamp_pushed, damping_lambda_sq
from rrc_pin.solvers.tick.direction import line_scale, solved_along, uniform_scale
from rrc_pin.solvers.tick.factor import Factor
from rrc_pin.solvers.tick.joint_box import ON_LIMIT
from rrc_pin.solvers.tick.levels import least_squares
from rrc_pin.solvers.tick.slide_kernels import MARGIN, SOLVED, project, slide_metric
from rrc_pin.solvers.tick.statuses import (
    DAMPED,
    EXACT,
    EXACT_TOL,
    LEAST_SQUARES,
    RECOVERING,
    SCALED,
    SINGULAR,
    SLIDING,
    STILL_SCALE,
    scale_and_veer,
)
from rrc_pin.solvers.tick.statuses import FAILED as FAILED  # where the ticks import it

Array = npt.NDArray[np.float64]

SLIDE_DAMPING = 1e-2
r"""Weight :math:`\mu` of the sliding stage's damping
(:data:`rrc_pin.solvers.tick.pipeline.SLIDE_DAMPING`)."""

class Top(NamedTuple):
    """The top level's answer and its report.

    Attributes:
        qdot: The rates (n,).
        status: A status code (module constants), or :data:`FAILED`.
        scale: The fraction of the command achieved along it.
        veer: The angle [rad] between the achieved and commanded task rates.
        lambda_sq: The largest squared damping applied.
        null: The next level's free directions (d, n) (none: d = 0).
    """

    qdot: Array
    status: int
    scale: float
    veer: float
    lambda_sq: float
    null: Array


class Rows(NamedTuple):
    """The tick's constraints: a box and rows ``G qdot <= h``.

    Attributes:
        lb: Lower bounds (n,).
        ub: Upper bounds (n,).
        G: Rows (p, n), p = 0 for none.
        h: Their bounds (p,).
        slide: Per row, nonzero where the command may slide along it (p,).
        tol: How far a kernel's answer may leave the box and rows
            (:func:`rrc_pin.solvers.qp_backends.qp.tolerance`).
        solved: Out (2,): the QPs the compiled active-set solver answered in the tick, and its
            steps (:func:`scaled_along`), added to.
    """

    lb: Array
    ub: Array
    G: Array
    h: Array
    slide: Array
    tol: float
    solved: Array


@kernel
def met(A: Array, x: Array, b: Array) -> bool:
    """Whether ``A x`` meets ``b`` (:func:`rrc_pin.solvers.tick.statuses.met`)."""
    return statuses.met(row_values(A, x), b)


@kernel
def along_command(A: Array, b: Array, qdot: Array, per_unit: Array, rate_factor: float
                  ) -> tuple[float, float]:  # fmt: skip
    """The top level's scale and veer of ``qdot`` in its normalised metric: the rows times
    ``per_unit`` (their units' inverses), or as they are where it is empty (the direction
    mode's rows are in that metric already).
    """  # noqa: D205
    y = row_values(A, qdot)
    if per_unit.size:
        scale, veer = scale_and_veer(y, b, per_unit)
    else:
        scale, veer = scale_and_veer(y, b)
    return scale * rate_factor, veer


@inlined
def answer(A: Array, b: Array, qdot: Array, status: int, rate_factor: float, null: Array,
           lambda_sq: float) -> Top:  # fmt: skip
    """The top level's answer ``qdot`` with its scale and veer along the command."""
    scale, veer = along_command(A, b, qdot, b[:0], rate_factor)
    return Top(qdot, status, scale, veer, lambda_sq, null)


@kernel
def met_top(qdot: Array, rate_factor: float, null: Array) -> Top:
    """The top level's stacked command met (:func:`rrc_pin.solvers.tick.statuses.met_top`)."""
    return Top(qdot, statuses.met_top(rate_factor), rate_factor, 0.0, 0.0, null)


@kernel
def passing(w: Array, null: Array) -> Top:
    """A stage's "not mine": the next stage answers."""
    return Top(w, FAILED, 0.0, 0.0, 0.0, null)


@kernel
def backend_slide(where: int, B: Array, target: Array, lb: Array, ub: Array, G: Array,
                  h: Array) -> Array:  # fmt: skip
    """The sliding stage's QP by the backend (:func:`rrc_pin.solvers.tick.backend_calls.slide`)."""
    with objmode(x="float64[::1]"):
        x = backend_calls.slide(where, B, target, lb, ub, G, h)
    return x


@kernel
def backend_direction(A: Array, w: Array, null: Array, lb: Array, ub: Array, G: Array,
                      h: Array) -> tuple[Array, float, float]:  # fmt: skip
    """The direction problem by the backend
    (:func:`rrc_pin.solvers.tick.backend_calls.direction`).
    """  # noqa: D205
    with objmode(qdot="float64[::1]", u="float64", veer="float64"):
        qdot, u, veer = backend_calls.direction(A, w, null, lb, ub, G, h)
    return qdot, u, veer


@kernel
def slide_rows(rows: Rows) -> tuple[Array, Array]:
    """The rows the command may slide along, ``(G, h)``."""
    keep = np.flatnonzero(rows.slide)
    G, h = np.empty((keep.size, rows.G.shape[1])), np.empty(keep.size)
    for i in range(keep.size):
        G[i] = rows.G[keep[i]]
        h[i] = rows.h[keep[i]]
    return G, h


@kernel
def slid_command(where: int, A: Array, b: Array, G: Array, h: Array, rows: Rows, f: Factor,
                 threshold: float) -> tuple[int, Array, Factor]:  # fmt: skip
    r"""What the slide rows ``G``, ``h`` and the box let the command keep (the sliding stage).

    :math:`\min \|A\dot q - b\|^2 + (\dot q - t)^TD(\dot q - t)` within them, D damping A's
    null space and its directions past the damping ``threshold`` (0: none)
    (:func:`rrc_pin.solvers.tick.pipeline._slide`,
    :func:`~rrc_pin.solvers.tick.slide_kernels.slide_metric`): the projection of its optimum
    (:func:`~rrc_pin.solvers.tick.slide_kernels.project`), else the backend's QP.

    Returns:
        ``(code, rates, f)``: 0 and the rates (n,), or :data:`FAILED` (the backend failed:
        recorded as ``where``'s failure); and A's factorisation with its SVD.
    """
    m, n = A.shape
    f = factor.with_svd(f)
    f, null = factor.null_basis(f)
    B: Array = np.empty((m + n, n))
    target = np.empty(n)
    kappa = threshold if threshold > 0.0 else np.inf
    count = slide_metric(A, f.US, f.sigma, f.right, f.rank, null, b, SLIDE_DAMPING, kappa, B,
                         target)  # fmt: skip
    B = B[:count]
    x: Array = np.empty(n)
    if project(B, 0.0, target, rows.lb, rows.ub, G, h, MARGIN, x) == SOLVED:
        feasibility.clip_into(x, rows.lb, rows.ub)  # by the kernel's rounding at most
        return 0, x, f
    x = backend_slide(where, B, target, rows.lb, rows.ub, G, h)
    return (0 if x.size else FAILED), x, f


@kernel
def scaled_along(A: Array, w: Array, null: Array, rows: Rows) -> tuple[Array, float, float]:
    """The direction problem along ``w``: its rates, scale u (u < 0: the backend failed), veer.

    The veer [rad] is measured where the backend answered, else 0 (along w by construction).

    Without rows: the uniform scale (no null space) or the exact line scale (one null
    direction) (:func:`rrc_pin.solvers.tick.direction.along`); else the direction QP by the
    compiled active-set solver (:func:`rrc_pin.solvers.tick.direction.solved_along`, counted in
    ``rows.solved``), or where it does not answer by the backend
    (:func:`rrc_pin.solvers.tick.backend_calls.direction`).
    """
    if rows.h.size or null.shape[0] > 1:
        qdot, u, veer, steps = solved_along(A, w, null, rows.lb, rows.ub, rows.G, rows.h,
                                            rows.tol)  # fmt: skip
        if u >= 0.0:
            rows.solved[0] += 1.0
            rows.solved[1] += steps
            return qdot, u, veer
        return backend_direction(A, w, null, rows.lb, rows.ub, rows.G, rows.h)
    if null.shape[0] == 0:
        u = uniform_scale(w, rows.lb, rows.ub)
        return u * w, u, 0.0
    u, y = line_scale(w, null[0], rows.lb, rows.ub)
    return u * w + y * null[0], u, 0.0


@kernel
def columns_used(J: Array) -> int:
    """How many columns of ``J`` have a nonzero entry (its rank is at most that)."""
    count = 0
    for j in range(J.shape[1]):
        for i in range(J.shape[0]):
            if J[i, j] != 0.0:
                count += 1
                break
    return count


@inlined
def clamped(f: Factor, w: Array, rows: Rows, dt: float, threshold: float
            ) -> tuple[Factor, bool]:  # fmt: skip
    """The rows without the joints ``w`` pushes against a bound that holds them, where they
    keep their rank (:func:`rrc_pin.solvers.tick.pipeline._clamped`), else ``f``; and whether
    their condition number is surely within ``threshold`` (:func:`factor.surely_conditioned`:
    where it is, the SVDs would choose the same rows).
    """  # noqa: D205
    J = np.empty_like(f.J)
    if not clamp_pushed(f.J, w, rows.lb, rows.ub, ON_LIMIT / dt, J):
        return f, factor.surely_conditioned(f, threshold)
    used = columns_used(J)
    if used < J.shape[0]:  # the clamped rows are short of rank: their rank is at most used
        if factor.surely_conditioned(f, threshold):
            return f, True
        f = factor.with_svd(f)
        if f.rank > used:  # above any the clamped rows' SVD could count: f is chosen
            return f, False
    c = factor.qr(J)
    if factor.surely_conditioned(c, threshold):  # of full rank
        return c, True
    c = factor.with_svd(c)
    if c.rank == min(J.shape[0], J.shape[1]):
        return c, False
    f = factor.with_svd(f)
    return (c if c.rank >= f.rank else f), False


@kernel
def damping(f: Factor, b: Array, w: Array, u: float, rows: Rows, dt: float, threshold: float
            ) -> tuple[Factor, Array]:  # fmt: skip
    """The damping (k,) a command that cannot be met needs (empty where none), and the
    factorisation it applies to (:func:`rrc_pin.solvers.tick.pipeline._damping`).
    """  # noqa: D205
    if threshold <= 0.0:
        return f, np.empty(0)
    usable, conditioned = clamped(f, w, rows, dt, threshold)
    if conditioned:
        return usable, np.empty(0)
    usable = factor.with_svd(usable)
    if factor.condition(usable) <= threshold:
        return usable, np.empty(0)
    m, k = usable.US.shape
    along = np.empty(k)
    for i in range(k):
        s = 0.0
        for r in range(m):
            s += b[r] * usable.US[r, i]
        along[i] = abs(s) / max(usable.sigma[i], 1e-300)
    lam = np.empty(k)
    if not damping_lambda_sq(usable.sigma, usable.rank, u, along, dt, threshold, lam):
        return usable, np.empty(0)
    return usable, lam


@inlined
def exact(A: Array, command: Array, f: Factor, w: Array, fits: bool, rows: Rows, slid: bool,
          outside_range: bool, rate_factor: float, need_null: bool) -> Top:  # fmt: skip
    """Stage 1: the exact rates where they keep every constraint, else pass on (the scale and
    veer reported along ``command``, the top level's as given).
    """  # noqa: D205
    if not (fits and feasibility.rows_hold(rows.G, w, rows.h, 0.0)):
        return passing(w, A[:0])
    null = factor.null_basis(f)[1] if need_null else A[:0]
    if slid:
        return answer(A, command, w, SLIDING, rate_factor, null, 0.0)
    if outside_range:
        return answer(A, command, w, SINGULAR, rate_factor, null, 0.0)
    return met_top(w, rate_factor, null)


@inlined
def scaled(A: Array, command: Array, b: Array, f: Factor, w: Array, boxed: Array, u_box: float,
           rows: Rows, slid: bool, outside_range: bool, dt: float, threshold: float,
           rate_factor: float) -> Top:  # fmt: skip
    """Stages 3-5, where w does not keep the constraints: scaled, damped, singular (``b`` the
    command served, ``command`` the one reported along).
    """  # noqa: D205
    f, null = factor.null_basis(f)
    qdot, u, veer = (boxed, u_box, 0.0) if u_box >= 0.0 else scaled_along(A, w, null, rows)
    if u < 0.0:
        return passing(w, null)
    if slid:
        return answer(A, command, qdot, SLIDING, rate_factor, null, 0.0)
    if not outside_range and u >= 1.0 - EXACT_TOL:
        return met_top(qdot, rate_factor, null)
    usable, lam = damping(f, b, w, u, rows, dt, threshold)
    if lam.size:
        damped_qdot, damped_u, _ = scaled_along(A, factor.rates(usable, b, lam), null, rows)
        if damped_u < 0.0:
            return passing(w, null)
        if u_box < 0.0 or not damped_u <= STILL_SCALE < u:
            return answer(A, command, damped_qdot, DAMPED, rate_factor, null,
                          float(np.max(lam)))  # fmt: skip
    if outside_range:
        return answer(A, command, qdot, SINGULAR, rate_factor, null, 0.0)
    return Top(qdot, SCALED, u * rate_factor, veer, 0.0, null)


@inlined
def direction(A: Array, b: Array, rows: Rows, dt: float, threshold: float, rate_factor: float,
              need_null: bool) -> Top:  # fmt: skip
    """The direction mode's top level: the stages of the module docstring, in order."""
    f, w, fits, boxed, u_box = factor.fitted(A, b, rows.lb, rows.ub)
    if rows.h.size:
        u_box = -1.0
    command, z, slid = b, w, False
    G, h = slide_rows(rows)
    if h.size and not feasibility.rows_hold(G, w, h, 0.0):  # stage 2 changes the command
        code, kept, f = slid_command(backend_calls.SLIDE, A, b, G, h, rows, f, threshold)
        if code == 0:
            if rows.slide.all() or feasibility.rows_hold(rows.G, kept, rows.h, rows.tol):
                null = factor.null_basis(f)[1] if need_null else np.empty((0, A.shape[1]))
                return answer(A, b, kept, SLIDING, rate_factor, null, 0.0)
            b, slid = row_values(A, kept), True
            f, z = factor.least_norm(f, b)
            w = z
            fits = feasibility.inside(w, rows.lb, rows.ub)
    return command_stages(A, command, b, f, w, z, fits, boxed, u_box, rows, slid, dt, threshold,
                          rate_factor, need_null)  # fmt: skip


@inlined
def direction_box(A: Array, b: Array, rows: Rows, dt: float, threshold: float,
                  rate_factor: float) -> Top:  # fmt: skip
    """The direction mode's one level within the box alone: no row, so no sliding stage."""
    f, w, fits, boxed, u_box = factor.fitted(A, b, rows.lb, rows.ub)
    return command_stages(A, b, b, f, w, w, fits, boxed, u_box, rows, False, dt, threshold,
                          rate_factor, False)  # fmt: skip


@inlined
def command_stages(A: Array, command: Array, b: Array, f: Factor, w: Array, z: Array,
                   fits: bool, boxed: Array, u_box: float, rows: Rows, slid: bool, dt: float,
                   threshold: float, rate_factor: float, need_null: bool) -> Top:  # fmt: skip
    """Stages 1 and 3-5 on the command ``b`` as it stands (``slid``: the sliding stage's; the
    report along ``command``, the one given).
    """  # noqa: D205
    outside_range = not f.regular and not met(f.J, z, b)
    top = exact(A, command, f, w, fits, rows, slid, outside_range, rate_factor, need_null)
    if top.status == FAILED:
        top = scaled(A, command, b, f, w, boxed, u_box, rows, slid, outside_range, dt,
                     threshold, rate_factor)  # fmt: skip
    return top


@inlined
def least_squares_top(A: Array, b: Array, per_unit: Array, rows: Rows, recovering: bool,
                      rate_factor: float, need_null: bool, threshold: float) -> Top:  # fmt: skip
    """The top level of the tracking and weighted modes: its least squares within the
    constraints (with slide rows: damped where the optimum breaks them, as the sliding stage;
    ``recovering`` where a joint or row must be restored).
    """  # noqa: D205
    n = A.shape[1]
    if rows.slide.any():
        f, w = factor.least_norm(factor.qr(A), b)
        if not (feasibility.inside(w, rows.lb, rows.ub)
                and feasibility.rows_hold(rows.G, w, rows.h, 0.0)):  # fmt: skip
            # where no rates meet them all, the pairs asked apart are only kept apart
            # (rrc_pin.solvers.tick.pipeline._damped_within)
            relaxed = np.where((rows.slide != 0.0) & (rows.h < 0.0), 0.0, rows.h)
            relaxes = (relaxed != rows.h).any()
            where = backend_calls.SLIDE_RELAXING if relaxes else backend_calls.TOP
            code, w, f = slid_command(where, A, b, rows.G, rows.h, rows, f, threshold)
            if code != 0 and relaxes:
                code, w, f = slid_command(backend_calls.TOP, A, b, rows.G, relaxed, rows, f,
                                          threshold)  # fmt: skip
            if code != 0:
                return passing(w, np.empty((0, n)))
        null = factor.null_basis(f)[1] if need_null else np.empty((0, n))
        qdot = w
    else:
        # np.int64: not a literal, so one compiled signature serves every level
        qdot, null = least_squares(np.int64(backend_calls.TOP), A, b, np.zeros(n),  # type: ignore[arg-type, unused-ignore]
                                   np.empty((0, n)), rows.lb, rows.ub, rows.G, rows.h, rows.tol,
                                   need_null)  # fmt: skip
        if qdot.size == 0:
            return passing(qdot, null)
    if recovering or (rows.h < 0.0).any():
        status = RECOVERING
    else:
        status = EXACT if met(A, qdot, b) and rate_factor == 1.0 else LEAST_SQUARES
    scale, veer = along_command(A, b, qdot, per_unit, rate_factor)
    return Top(qdot, status, scale, veer, 0.0, null)
