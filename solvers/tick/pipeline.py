r"""The numerics of one tick: a :class:`~.problem.Problem` in, an :class:`Answer` out.

The levels are solved in priority order, each exactly within the optimal set of those above
(Kanoun, Lamiraux & Wieber 2011; Escande, Mansard & Wieber 2014): a level's answer fixes its
task rates, and the next level moves only in the null space of its rows (a
:class:`Subspace`), so it cannot change them. Equality rows come first of all: every level
moves in their null space.

The top level of the ``direction`` mode (:mod:`rrc_pin.solvers.tick.direction`,
:mod:`rrc_pin.solvers.tick.damping`):

1. the exact rates (least-squares of least norm,
:class:`~rrc_pin.solvers.tick.factorization.Factorization`)
   are the answer when they satisfy the constraints (``exact``; ``singular`` where part of
   the command is outside the rows' range);
2. otherwise the LP maximum :math:`u^*` of the scale along them: ``exact`` at
   :math:`u^* = 1` (another solution of the same rates), else ``scaled`` while the rows'
   condition number is below the damping threshold;
3. beyond it, the damped rates scaled along themselves (``damped``, the veer reported).

Before 2, where the exact rates cross a constraint row marked ``slide`` (a collision pair, which
the command should slide along rather than stop at), the command is first projected onto what
the slide rows and the box allow, :math:`b' = A\dot q^*` with :math:`\dot q^*` the least
squares of :math:`A\dot q \approx b` within them, damped on A's null space and past the damping
threshold only (:data:`SLIDE_DAMPING`, :func:`_slide`,
:mod:`rrc_pin.solvers.tick.slide_kernels`: one answer, continuous in the data), and 1-2
run on :math:`b'` (``sliding``, the veer from :math:`b` reported). Without a crossed slide row
nothing changes: exact answers stay exact (0 veer).

A least-squares level (the other modes, and every lower level): its unconstrained optimum
(:mod:`rrc_pin.solvers.tick.least_squares`) when it satisfies the constraints, else the backend's
QP.

When the top level finds no usable answer (a backend fault, an infeasible problem, an answer
outside the constraints beyond :func:`~rrc_pin.solvers.qp_backends.qp.tolerance`), the fallbacks
answer it
(:mod:`rrc_pin.solvers.tick.fallbacks`); a lower level that fails keeps the answer of the levels
above
(``dropped``). Every answer is finally clipped into the box, the size of the clip reported.
Nothing here raises for numerical trouble.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal, NamedTuple, TypeVar, get_args

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.errors import InvalidInput, NumericalFailure
from rrc_pin.solvers.qp_backends import active_set
from rrc_pin.solvers.qp_backends.base import QPBackend
from rrc_pin.solvers.qp_backends.qp import QP, Decoding, Work, solve_within, tolerance
from rrc_pin.solvers.tick import feasibility, statuses
from rrc_pin.solvers.tick.damping import Damping, clamp_pushed
from rrc_pin.solvers.tick.direction import DIRECTION_TOL, Along, along, direction_qp, solved_along
from rrc_pin.solvers.tick.factorization import Factorization
from rrc_pin.solvers.tick.joint_box import ON_LIMIT
from rrc_pin.solvers.tick.least_squares import Subspace, least_squares
from rrc_pin.solvers.tick.problem import Box, Problem, Rows
from rrc_pin.solvers.tick.slide_kernels import MARGIN, SOLVED, project, slide_metric
from rrc_pin.solvers.tick.statuses import EXACT_TOL, STILL_SCALE, scale_and_veer

Array = npt.NDArray[np.float64]
_T = TypeVar("_T")

Method = Literal["qp", "scipy", "scaling", "hold"]
"""How the top level was answered: ``qp`` the pipeline (its exact kernels, or the backend),
then the fallbacks (:mod:`rrc_pin.solvers.tick.fallbacks`)."""

METHODS: tuple[Method, ...] = ("qp", "scipy", "scaling", "hold")

Status = Literal[
    "exact", "scaled", "sliding", "damped", "singular", "least_squares", "recovering", "fallback",
    "grip_lost", "contact_lost",
]
"""What the answer is for the top level (docs/api.md, "Reading a resolution"); how each lower
level fared is in ``levels`` (:data:`LevelStatus`):

- ``exact``: the top level's command is met;
- ``scaled``: the top level's direction is kept exactly, its speed reduced (``scale < 1``)
  to the largest the constraints allow;
- ``sliding``: the exact rates crossed a row the command may slide along (a collision pair):
  the command was replaced by what those rows and the box let it keep (its least squares
  within them), whose direction is then kept (met, or scaled); ``veer`` is the angle turned
  from the command, ``scale`` the fraction of the command achieved along it;
- ``damped``: near a singularity (the rows' condition number beyond the damping threshold)
  the command could not be met and its damped rates were scaled instead: the motion veers
  from the command by ``veer``;
- ``singular``: part of the top level's command is outside its rows' range (a singularity,
  or more rows than joints); the rest is met or scaled;
- ``least_squares``: the top level's least-squares optimum within the constraints, not its
  command (the tracking and weighted modes);
- ``recovering``: a joint outside its range, or a constraint row broken at the start, must
  be restored: the least-squares optimum within the constraints;
- ``fallback``: the pipeline found no usable answer for the top level; a fallback did
  (``attempts`` says why);
- ``grip_lost``, ``contact_lost``: never the pipeline's; a cell's controller
  (``rrc_pin.cells``) found a closed chain (two hands' grip, a foot in support) open beyond
  its bound: the cell holds still (zero rates) until a command closes it.
"""

LevelStatus = Literal["met", "scaled", "traded", "dropped"]
"""How one priority level was served: ``met`` (its command, to :data:`EXACT_TOL`), ``scaled``
(its command's direction, slower), ``traded`` (a least-squares optimum within the levels above
and the constraints; a zero command whose rows moved), ``dropped`` (its solve failed: the
answer of the levels above kept)."""

_STATUSES: tuple[Status, ...] = get_args(Status)
_LEVEL_STATUSES: tuple[LevelStatus, ...] = get_args(LevelStatus)

DEFAULT_FALLBACKS: tuple[Method, ...] = ("scipy", "scaling")
"""The fallbacks tried after the pipeline by default; ``hold`` ends every chain."""


@dataclass(frozen=True)
class Options:
    """How the pipeline solves.

    Attributes:
        damping: Damping near singularities, or None for none.
        fallbacks: Methods tried in order after the pipeline fails (names of :data:`METHODS`
            except ``qp``); ``hold`` always ends the chain.

    Raises:
        InvalidInput: An unknown or repeated fallback, ``qp`` among them, or ``hold`` before
            another one.
    """

    damping: Damping | None = field(default_factory=Damping)
    fallbacks: tuple[Method, ...] = DEFAULT_FALLBACKS

    def __post_init__(self) -> None:
        given = self.fallbacks
        if isinstance(given, str):
            given = (given,)
        if not isinstance(given, (tuple, list)) or not all(isinstance(m, str) for m in given):
            raise InvalidInput("fallbacks", f"expected a sequence of method names, got {given!r}")
        for name in given:
            if name not in METHODS or name == "qp":
                choices = ", ".join(m for m in METHODS if m != "qp")
                raise InvalidInput("fallbacks", f"unknown method {name!r}; expected {choices}")
        if len(set(given)) != len(given):
            raise InvalidInput("fallbacks", f"repeated method in {tuple(given)}")
        if "hold" in given[:-1]:
            raise InvalidInput("fallbacks", f"'hold' always answers, so it comes last: {given}")
        if self.damping is not None and not isinstance(self.damping, Damping):
            raise InvalidInput("damping", f"expected a Damping or None, got {self.damping!r}")
        chain = tuple(given) if given[-1:] == ("hold",) else (*given, "hold")
        object.__setattr__(self, "fallbacks", chain)


class Answer(NamedTuple):
    """What the numerics produced for one problem.

    Attributes:
        qdot: Joint rates (n,), finite, within the box (read-only).
        method: How the top level was answered.
        status: What the answer is (:data:`Status`).
        levels: How each priority level was served (:data:`LevelStatus`).
        scale: The top level's fraction of its command achieved along it, in [0, 1].
        veer: Angle [rad] between the top level's achieved and commanded rates (its metric).
        lambda_sq: The largest squared damping applied (0 when undamped).
        backend: The last backend that answered, or "".
        iterations: Backend iterations.
        solve_time: Time inside the backend [s].
        attempts: ``(method or level, reason)`` of every method that failed.
        clip: Size of the final clip into the box [rad/s].
    """

    qdot: Array
    method: Method
    status: Status
    levels: tuple[LevelStatus, ...]
    scale: float
    veer: float
    lambda_sq: float
    backend: str
    iterations: int
    solve_time: float
    attempts: tuple[tuple[str, str], ...]
    clip: float


class _Top(NamedTuple):
    """The top level's answer and its report."""

    qdot: Array
    status: Status
    scale: float
    veer: float
    lambda_sq: float
    null: Array | None  # the next level's free directions, or None if none are left


def solve(problem: Problem, backend: QPBackend, options: Options) -> Answer:
    """Joint rates serving ``problem``'s levels in priority order (module docstring).

    Args:
        problem: The tick's problem (:func:`rrc_pin.solvers.tick.problem.build`), its arrays finite.
        backend: The QP backend (warm-started across calls).
        options: Damping and fallbacks.

    Returns:
        The :class:`Answer`; never raises for numerical trouble.
    """
    work = Work()
    box, rows = problem.box, problem.rows
    top: _Top | None = None
    try:
        space = _equality_space(problem)
        top = _top(problem, space, backend, options, work)
    except (NumericalFailure, np.linalg.LinAlgError) as exc:
        work.attempts.append(("qp", str(exc)))
    if top is None:
        return fallback_answer(problem, options, work)
    qdot, levels = top.qdot, ["met" if top.status == "exact" else _level_status(top.status)]
    null = top.null
    for k in range(1, len(problem.levels)):
        if null is None or null.shape[0] == 0:
            levels.append(_served(problem, k, qdot))
            continue
        A, b = problem.stacked[k]
        try:
            qdot, null = least_squares(A, b, Subspace(qdot, null), box, rows, backend, work,
                                       f"level{k}", k < len(problem.levels) - 1)  # fmt: skip
        except (NumericalFailure, np.linalg.LinAlgError) as exc:
            work.attempts.append((f"level {k}", f"{exc}; the levels above kept"))
            levels.append("dropped")
            null = None
            continue
        levels.append(_served(problem, k, qdot))
    answer = _answer(problem, top, qdot, "qp", levels, work)
    A, b = problem.stacked[0]
    code = _STATUSES.index(answer.status)
    status, scale, veer = statuses.borne_out(code, A @ answer.qdot, b, problem.mode == "direction",
                                             problem.rate_factor, answer.scale, answer.veer)
    if status == statuses.FAILED:
        work.attempts.append(("qp", "its rates, clipped into the box, veer from the command"))
        return fallback_answer(problem, options, work)
    if status == code:
        return answer
    return answer._replace(status=_STATUSES[status], scale=scale, veer=veer,
                           levels=(_level_status(_STATUSES[status]), *answer.levels[1:]))


def fallback_answer(problem: Problem, options: Options, work: Work) -> Answer:
    """The answer of the fallbacks, where the pipeline found no usable answer for the top
    level (``work`` holds why); the lower levels dropped.
    """  # noqa: D205
    from rrc_pin.solvers.tick.fallbacks import fallback

    for name in options.fallbacks:
        try:
            qdot = fallback(name, problem, work)
        except (NumericalFailure, np.linalg.LinAlgError) as exc:
            work.attempts.append((name, str(exc)))
            continue
        top = _Top(qdot, "fallback", *_along_command(problem, qdot), 0.0, None)
        levels = [_level_status(top.status)] + ["dropped"] * (len(problem.levels) - 1)
        return _answer(problem, top, qdot, name, levels, work)
    raise AssertionError("'hold' always answers")  # the chain ends with it (Options)


def _answer(problem: Problem, top: _Top, qdot: Array, method: Method,
            levels: list[LevelStatus], work: Work) -> Answer:  # fmt: skip
    """The answer: the rates ``qdot`` of every level, clipped into the box and rows, and
    ``top``'s report; a shrink into the rows serves the lower levels anew."""  # noqa: D205, D209
    box = problem.box
    clip = feasibility.clip_into(qdot, box.lb, box.ub)  # the kernels' answers to rounding
    qdot, shrink = _within_rows(qdot, box, problem.rows)
    qdot.flags.writeable = False
    if shrink < 1.0 - statuses.EXACT_TOL:
        levels = levels[:1] + [level if level == "dropped" else _served(problem, k, qdot)
                               for k, level in enumerate(levels[1:], 1)]  # fmt: skip
    return Answer(
        qdot, method, top.status, tuple(levels), top.scale * shrink, top.veer, top.lambda_sq,
        work.backend, work.iterations, work.solve_time, tuple(work.attempts), clip,
    )  # fmt: skip


def _top(
    problem: Problem, space: Subspace, backend: QPBackend, options: Options, work: Work
) -> _Top:
    """The top level's answer (module docstring): the least squares of the other modes, or the
    direction problem's stages in turn, each answering or passing on.
    """  # noqa: D205
    if problem.mode != "direction":
        return _least_squares_top(problem, space, backend, options, work)
    exact = _exact(problem, space)
    slide = None if problem.rows is None else problem.rows.sliding
    if slide is not None:
        slid = _slid(problem, space, backend, options, work, exact, slide)
        if isinstance(slid, _Top):
            return slid
        exact = slid
    within = _exact_within(problem, space, exact)
    if within is not None:
        return within
    return _scaled_top(problem, space, backend, options, work, exact)


class _Exact(NamedTuple):
    """The direction problem's exact rates: the rows' factorisation, the rates in the level's
    free directions ``z`` and in the joints ``w``, whether ``w`` is inside the box, the
    problem along ``w`` where the box is all (the box's kernels), the command ``b`` they
    meet and whether it is a slid one (:func:`_slid`).
    """  # noqa: D205

    factor: Factorization
    z: Array
    w: Array
    fits: bool
    boxed: Along | None
    b: Array
    slid: bool

    @property
    def outside_range(self) -> bool:
        """Part of the command is outside the rows' range (``singular``)."""
        return not self.factor.regular and not statuses.met(self.factor.J @ self.z, self.b)


def _least_squares_top(
    problem: Problem, space: Subspace, backend: QPBackend, options: Options, work: Work
) -> _Top:
    """The top level of the tracking and weighted modes: its least squares within the
    constraints (damped where it breaks a slide row, as the sliding stage).
    """  # noqa: D205
    A, b = problem.stacked[0]
    box, rows = problem.box, problem.rows
    last = len(problem.levels) == 1
    if rows is not None and rows.sliding is not None:
        qdot, null = _damped_within(A, b, space, box, rows, backend, work, not last,
                                    options.damping)  # fmt: skip
    else:
        qdot, null = least_squares(A, b, space, box, rows, backend, work, "least_squares",
                                   not last)  # fmt: skip
    met = statuses.met(A @ qdot, b) and problem.rate_factor == 1.0
    status: Status = "recovering" if box.recovering or _broken(rows) else (
        "exact" if met else "least_squares")  # fmt: skip
    return _Top(qdot, status, *_along_command(problem, qdot), 0.0, null)


def _exact(problem: Problem, space: Subspace) -> _Exact:
    """Stage 1: the exact rates of the command (least squares of least norm)."""
    A, b = problem.stacked[0]
    box = problem.box
    if space.N is None:
        factor, w, fits, boxed = Factorization.fitted(A, b, box.lb, box.ub)
        return _Exact(factor, w, w, fits, boxed if problem.rows is None else None, b, False)
    factor = Factorization(A @ space.N.T)
    z = factor.least_norm(b)
    w = z @ space.N
    return _Exact(factor, z, w, feasibility.inside(w, box.lb, box.ub), None, b, False)


def _slid(
    problem: Problem, space: Subspace, backend: QPBackend, options: Options, work: Work,
    exact: _Exact, slide: Rows,
) -> _Top | _Exact:  # fmt: skip
    """Where the exact rates cross a row the command may slide along (of ``slide``, the
    problem's rows marked so): the command becomes what the slide rows and the box let it
    keep (:func:`_slide`); its rates, ``sliding``, where they meet every other row too, else
    its exact rates for the stages after. Where none cross (or the slide fails, reported),
    ``exact`` as it is.
    """  # noqa: D205
    A = problem.stacked[0][0]
    box, rows = problem.box, problem.rows
    assert rows is not None
    if feasibility.rows_hold(slide.G, exact.w, slide.h, 0.0):
        return exact
    try:
        kept = _slide(A, exact.b, space, box, slide, backend, work, exact.factor,
                      options.damping)  # fmt: skip
    except (NumericalFailure, np.linalg.LinAlgError) as exc:
        work.attempts.append(("slide", f"{exc}; the command kept as given"))
        return exact
    every = rows.slide is not None and bool(rows.slide.all())  # the least squares kept them all
    if every or feasibility.rows_hold(rows.G, kept, rows.h, tolerance(box)):
        null = _null(exact.factor, space) if len(problem.levels) > 1 else None
        return _Top(kept, "sliding", *_along_command(problem, kept), 0.0, null)
    b = A @ kept
    z = exact.factor.least_norm(b)
    w = z if space.N is None else z @ space.N
    return exact._replace(z=z, w=w, fits=feasibility.inside(w, box.lb, box.ub), b=b, slid=True)


def _exact_within(problem: Problem, space: Subspace, exact: _Exact) -> _Top | None:
    """Stage 1's answer where the exact rates are inside the box and rows: ``sliding``,
    ``singular`` or met; else None.
    """  # noqa: D205
    rows = problem.rows
    if not (exact.fits and (rows is None or feasibility.rows_hold(rows.G, exact.w, rows.h, 0.0))):
        return None
    null = _null(exact.factor, space) if len(problem.levels) > 1 else None
    w = exact.w
    if exact.slid:
        return _Top(w, "sliding", *_along_command(problem, w), 0.0, null)
    if exact.outside_range:
        return _Top(w, "singular", *_along_command(problem, w), 0.0, null)
    return _met_top(problem, w, null)


def _scaled_top(
    problem: Problem, space: Subspace, backend: QPBackend, options: Options, work: Work,
    exact: _Exact,
) -> _Top:  # fmt: skip
    """Stages 2 and 3: the LP maximum scale along the exact rates, met, ``scaled`` or
    ``singular``; past the damping threshold the damped rates scaled along themselves.
    """  # noqa: D205
    A = problem.stacked[0][0]
    box, rows = problem.box, problem.rows
    null = _null(exact.factor, space)
    u_w = exact.boxed if exact.boxed is not None else _scaled(A, exact.w, null, box, rows,
                                                              backend, work)  # fmt: skip
    if exact.slid:
        return _Top(u_w.qdot, "sliding", *_along_command(problem, u_w.qdot), 0.0, null)
    outside_range = exact.outside_range
    if not outside_range and u_w.u >= 1.0 - EXACT_TOL:
        return _met_top(problem, u_w.qdot, null)
    lam, usable = _damping(options.damping, exact.factor, exact.b, exact.w, u_w.u, box,
                           problem.dt, space.N is None)  # fmt: skip
    if lam is not None:
        z = usable.rates(exact.b, lam)
        damped = _scaled(A, z if space.N is None else z @ space.N, null, box, rows, backend, work)
        if exact.boxed is None or not damped.u <= STILL_SCALE < u_w.u:
            return _Top(damped.qdot, "damped", *_along_command(problem, damped.qdot),
                        float(np.max(lam)), null)  # fmt: skip
        # a bound stops the damped rates and not the command's own exact answer (the box's
        # kernels): that answer (docs/api.md, the direction problem's step 3; a backend's
        # inexact answer is not taken for the command's direction)
    if outside_range:
        return _Top(u_w.qdot, "singular", *_along_command(problem, u_w.qdot), 0.0, null)
    return _Top(u_w.qdot, "scaled", u_w.u * problem.rate_factor, u_w.veer, 0.0, null)


def _met_top(problem: Problem, qdot: Array, null: Array | None) -> _Top:
    """The top level's stacked command met (:func:`rrc_pin.solvers.tick.statuses.met_top`)."""
    status = _STATUSES[statuses.met_top(problem.rate_factor)]
    return _Top(qdot, status, problem.rate_factor, 0.0, 0.0, null)


SLIDE_DAMPING = 1e-2
r"""Weight :math:`\mu` of the sliding stage's damping, relative to the mean squared singular
value of the top level's rows (:func:`_slide`): the cost of a rate in their null space, and of
a direction past the damping threshold (toward :math:`\mu` at a singularity). Two facing
pandas' hands driven into each other (36 pairs, 600 ticks, with
rrc_pin.limits.collision.BLEND): the largest joint-rate change between two ticks 0.19 rad/s at
1e-3, 0.086 at 1e-2 (2.4 at 1e-4, 2.35 with the former least-squares tie-break alone)."""


def _slide(
    A: Array, b: Array, space: Subspace, box: Box, slide: Rows, backend: QPBackend, work: Work,
    factor: Factorization, damping: Damping | None,
) -> Array:  # fmt: skip
    r"""What the slide rows and the box let the command keep.

    .. math:: \min_{\dot q}\ \|A\dot q - b\|^2 + (\dot q - t)^TD(\dot q - t)
       \quad\text{s.t. the box and the slide rows}

    with ``t`` the damped least squares :math:`(A^TA + D)^{-1}A^Tb` and D
    (:func:`rrc_pin.solvers.tick.slide_kernels.slide_metric`) :data:`SLIDE_DAMPING` times the
    mean squared singular value of A on A's null space, the same on the directions past the
    damping threshold (the top level's onset, smoothly from zero there), zero on the others:
    a direction A moves well keeps all of what the constraints allow of its command, as the
    LP over the same rows would (with D = :math:`\mu I`, 0.93 of the tangential speed of a
    hand sliding down a wall was kept where an LP kept all of it). The problem is the
    projection of its unconstrained optimum onto the constraints in the metric
    :math:`A^TA + D` (:func:`rrc_pin.solvers.tick.slide_kernels.project`). Without D on the
    null space (the least squares alone, with a least-norm tie-break 1e-6 of the trace) the
    optimal rates formed a set along A's null space, and the answer moved anywhere in it from
    one tick to the next as rows entered and left (2.35 rad/s between two sliding ticks); with
    it the answer is one point, Lipschitz in the data. Pulled toward ``t`` rather than toward
    the exact rates, it stays bounded through a singularity (pulled toward the exact rates,
    which grow without bound there, a stretched panda's shoulder, elbow and wrist flipped
    between opposite rate limits every tick).

    The backend answers the same QP where the kernel refuses; within the equality rows' null
    space, the least squares alone (:func:`~rrc_pin.solvers.tick.least_squares.least_squares`).

    Raises:
        NumericalFailure: The backend found no usable answer.
    """
    if space.N is not None:
        kept, _ = least_squares(A, b, space, box, slide, backend, work, "slide", False)
        return kept
    m, n = A.shape
    US, sigma, right, rank = factor.svd
    B: Array = np.empty((m + n, n))
    target = np.empty(n)
    threshold = math.inf if damping is None else float(damping.threshold)
    rows = slide_metric(np.ascontiguousarray(A), US, sigma, right, rank,
                        np.ascontiguousarray(factor.null_basis()), b, SLIDE_DAMPING, threshold,
                        B, target)  # fmt: skip
    B = B[:rows]
    x = np.empty(n)
    if project(B, 0.0, target, box.lb, box.ub, slide.G, slide.h, MARGIN, x) == SOLVED:
        feasibility.clip_into(x, box.lb, box.ub)  # by the kernel's rounding at most (1e-9)
        return x
    return backend_slide(B, target, box, slide, backend, work)


def backend_slide(
    B: Array, target: Array, box: Box, slide: Rows, backend: QPBackend, work: Work
) -> Array:
    r"""The sliding stage's QP by the backend: the point of the box and slide rows nearest
    ``target`` in the metric :math:`B^TB` (where :func:`_slide`'s projection refuses).

    Raises:
        NumericalFailure: The backend found no usable answer.
    """  # noqa: D205
    n = target.size
    M = B.T @ B
    size = max(float(np.abs(M).max()), _TINY)
    qp = QP(M / size, -(M @ target) / size, slide.G, np.full(slide.h.size, -np.inf), slide.h,
            box.lb, box.ub, f"slide:{n}")  # fmt: skip
    return solve_within(qp, Decoding(None, None), box, slide, backend, work)


def _damped_within(
    A: Array, b: Array, space: Subspace, box: Box, rows: Rows, backend: QPBackend, work: Work,
    need_null: bool, damping: Damping | None,
) -> tuple[Array, Array | None]:  # fmt: skip
    """A least-squares top level with slide rows: its exact optimum where that holds every
    constraint, else the sliding stage's least squares within them all (:func:`_slide`).

    Most such problems are a collision pair just below its safety distance, its row asking it
    back out (``recovering``: standing still is not feasible and the problem is not a direction
    one). The least squares alone there, undamped, drove baxter's wrists at their 4 rad/s
    limits for a pair 2 um below the safety distance, and the step's second-order error took
    the pair 1.03 mm below it over four ticks (a 10-minute session); and a recovering tick
    between two sliding ones changed the rates by 2.9 rad/s and back. Where no rates meet every
    constraint, the slide rows that ask to move apart (a bound below zero) ask only not to
    approach (bound zero), and the least squares is solved again: a pair is pushed out where
    that is possible, and never holds the arm where it is not (two pairs asking for opposite
    motions; a joint at its limit). Within equality rows (``space``: a grip, a foot in
    support), the least squares within them, relaxed the same way where it fails.

    Returns:
        The rates (n,), and A's null space (d, n) for the next level (None when not needed).
    """  # noqa: D205
    if space.N is not None:
        return _relaxing(lambda kept: least_squares(A, b, space, box, kept, backend, work,
                                                    "least_squares", need_null), rows, work)
    factor = Factorization(A)
    w = factor.least_norm(b)
    if not (feasibility.inside(w, box.lb, box.ub)
            and feasibility.rows_hold(rows.G, w, rows.h, 0.0)):  # fmt: skip
        w = _relaxing(lambda kept: _slide(A, b, _EVERY_RATE, box, kept, backend, work, factor,
                                          damping), rows, work)  # fmt: skip
    return w, factor.null_basis() if need_null else None


def _relaxing(solved: Callable[[Rows], _T], rows: Rows, work: Work) -> _T:
    """``solved(rows)``; where it fails and a slide row asks a pair apart, ``solved`` of the
    rows that only keep the pairs apart (:func:`_not_approaching`), the failure recorded.

    Raises:
        NumericalFailure: No answer (none with the rows relaxed, or none to relax).
    """  # noqa: D205
    try:
        return solved(rows)
    except (NumericalFailure, np.linalg.LinAlgError) as exc:
        relaxed = _not_approaching(rows)
        if relaxed is None:
            raise
        work.attempts.append(("slide", f"{exc}; the pairs asked apart only kept apart"))
        return solved(relaxed)


def _not_approaching(rows: Rows) -> Rows | None:
    """``rows`` with every slide row's bound below zero raised to zero, or None if none is."""
    if rows.slide is None:
        return None
    pushed = rows.slide & (rows.h < 0.0)
    if not pushed.any():
        return None
    return rows._replace(h=np.where(pushed, 0.0, rows.h))


def _damping(
    damping: Damping | None, factor: Factorization, b: Array, w: Array, scale: float, box: Box,
    dt: float, clampable: bool,
) -> tuple[Array | None, Factorization]:  # fmt: skip
    """The damping a command that cannot be met needs, and the factorisation it applies to.

    The condition number is that of the joints the command can use: a joint that the exact
    rates ``w`` push against a bound holding it still is taken out of the rows (Baerlocher &
    Boulic 2004's clamping), as long as the rows keep their rank without it (else the command
    needs it and the rows' own factorisation serves). Such a joint is lost to the command,
    and the singularity that matters is that of the others: rolling rrc_k1607's hand with
    joint 7 on its limit, the full rows' condition number is 7 while the other six joints
    are near their own singularity; scaled along the exact rates, the joints flipped between
    opposite rate limits at every tick, the hand at 0.3 % of the command.
    """
    if damping is None:
        return None, factor
    usable = _clamped(factor, w, box, dt) if clampable else factor
    if usable.condition() <= damping.threshold:
        return None, usable
    US, sigma, _, rank = usable.svd
    along = np.abs(b @ US) / np.maximum(sigma, 1e-300)  # |u_i^T b|
    return damping.lambda_sq(sigma, rank, scale, along, dt), usable


def _clamped(factor: Factorization, w: Array, box: Box, dt: float) -> Factorization:
    """The rows without the joints ``w`` pushes against a bound that holds them (``_damping``)."""
    J = np.empty_like(factor.J)  # a bound within rounding of zero holds the joint
    if not clamp_pushed(factor.J, w, box.lb, box.ub, ON_LIMIT / dt, J):
        return factor
    clamped = Factorization(J)
    rank = clamped.svd[3]  # at most the rows' own: where full, theirs is not needed (one SVD)
    return clamped if rank == min(J.shape) or rank >= factor.svd[3] else factor




def _scaled(
    A: Array, w: Array, null: Array, box: Box, rows: Rows | None, backend: QPBackend, work: Work
) -> Along:
    """The direction problem along ``w``: exactly by the kernels, else by the backend.

    A backend's answer is decoded from the null space and w, so its task rates are a multiple
    of ``A w`` up to the null basis' rounding times the answer's size; its scale is read from
    them, and an answer off their direction by more than :data:`DIRECTION_TOL` of that size is
    refused. The answer is taken as decoded, not clipped into the box joint by joint (within
    the backend's tolerance of it: the pipeline's final clip, reported): a clip turns the
    direction, by 1e-11 relative to the rates' size, an angle of 1e-7 rad at a scale of 1e-3.

    Raises:
        NumericalFailure: The backend found no usable answer.
    """
    answer = along(w, null, box, rows)
    if answer is not None:
        return answer
    return backend_along(A, w, null, box, rows, backend, work)


def backend_along(
    A: Array, w: Array, null: Array, box: Box, rows: Rows | None, backend: QPBackend, work: Work,
    compiled: bool = True,
) -> Along:  # fmt: skip
    """The direction problem along ``w`` as a QP, its answer checked (:func:`_scaled`): by the
    compiled active-set solver where ``compiled`` and it answers
    (:func:`~rrc_pin.solvers.tick.direction.solved_along`), else by the backend.

    Raises:
        NumericalFailure: The backend found no usable answer.
    """  # noqa: D205
    if compiled:
        G, h = (A[:0], w[:0]) if rows is None else (rows.G, rows.h)
        qdot, u, veer, steps = solved_along(
            np.ascontiguousarray(A), w, np.ascontiguousarray(null), box.lb, box.ub,
            np.ascontiguousarray(G), h, tolerance(box))  # fmt: skip
        if u >= 0.0:
            work.backend = active_set.NAME
            work.iterations += steps
            return Along(qdot, u, veer)
    qp, decoding = direction_qp(w, null, box, rows)
    qdot = solve_within(qp, decoding, box, rows, backend, work, clip=False)
    y = A @ qdot
    scale, veer = scale_and_veer(y, A @ w)
    off = statuses.norm(y) * math.sin(min(veer, 0.5 * math.pi))  # the task rates off the direction
    if off > DIRECTION_TOL * statuses.norm(A.ravel()) * statuses.norm(qdot) and scale > STILL_SCALE:
        raise NumericalFailure(f"{work.backend}: answer veers by {veer:.3g} rad from the command")
    return Along(qdot, scale, veer)


def _null(factor: Factorization, space: Subspace) -> Array:
    """The null space of a level's rows in the joint rates, within ``space``."""
    null = factor.null_basis()
    return null if space.N is None else null @ space.N


def _equality_space(problem: Problem) -> Subspace:
    """The rates that meet the equality rows, ``x0 + N^T z`` (least norm x0), or all rates."""
    if problem.equalities is None:
        return _EVERY_RATE
    C, d = problem.equalities
    factor = Factorization(C)
    x0 = factor.least_norm(d)
    if not statuses.met(C @ x0, d):
        raise NumericalFailure("the equality rows contradict each other")
    return Subspace(x0, factor.null_basis())


_EVERY_RATE = Subspace(None, None)
"""The subspace of a problem without equality rows: every rate."""


def _broken(rows: Rows | None) -> bool:
    return rows is not None and bool((rows.h < 0.0).any())


def _level_status(status: Status) -> LevelStatus:
    return "scaled" if status == "scaled" else "traded"


def _served(problem: Problem, k: int, qdot: Array) -> LevelStatus:
    """How level ``k`` was served by ``qdot`` (:func:`rrc_pin.solvers.tick.statuses.served`)."""
    A, b = problem.stacked[k]
    return _LEVEL_STATUSES[statuses.served(A @ qdot, b, problem.factors[k])]


def served(y: Array, b: Array) -> LevelStatus:
    """How rates ``y`` serve the command ``b``: met, scaled along it, or traded
    (:func:`rrc_pin.solvers.tick.statuses.served`).
    """  # noqa: D205
    return _LEVEL_STATUSES[statuses.served(y, b, 1.0)]


def _along_command(problem: Problem, qdot: Array) -> tuple[float, float]:
    """The top level's scale and veer for ``qdot`` in its normalised metric.

    The direction problem's stacked rows are in that metric already; the other modes' rows are
    weighted, and their units divide them here. The scale is of the stacked rates, which the
    problem's ``rate_factor`` relates to the command's.
    """
    A, b = problem.stacked[0]
    level = problem.levels[0]
    per_unit = None
    if problem.mode != "direction" and any(t.unit is not None for t in level):
        per_unit = np.concatenate([np.ones(t.b.size) if t.unit is None else 1.0 / t.unit
                                   for t in level])  # fmt: skip
    scale, veer = scale_and_veer(A @ qdot, b, per_unit)
    return scale * problem.rate_factor, veer


def _within_rows(x: Array, box: Box, rows: Rows | None) -> tuple[Array, float]:
    """``x`` shrunk toward zero until the rows hold (:func:`feasibility.into_rows`), and the factor
    (zero feasible). A backend leaves the rows by up to its tolerance (1e-9); the shrink keeps
    the direction.
    """  # noqa: D205
    if rows is None or not box.contains_zero or bool((rows.h < 0.0).any()):
        return x, 1.0
    G, h, y = (np.require(a, np.float64, ("C", "W")) for a in (rows.G, rows.h, x))
    factor = feasibility.into_rows(G, h, y)  # its one compiled signature (Workspace.compile)
    return (x, 1.0) if factor == 1.0 else (x * factor, factor)


_TINY = float(np.finfo(np.float64).tiny)
