"""The QPs the compiled tick hands to the backend, called from inside it (numba's ``objmode``).

The kernels answer most of a tick; the direction problem with constraint rows or several null
directions, a least-squares level whose metric is semidefinite or whose projection the kernel
refuses, and the sliding stage's QP where its projection refuses, go to the resolver's QP
backend (DAQP by default) through the pipeline's own functions, which build and check them
(:func:`~rrc_pin.solvers.tick.pipeline.backend_along`,
:func:`~rrc_pin.solvers.tick.pipeline.backend_slide`,
:func:`~rrc_pin.solvers.tick.least_squares.least_squares`). The tick's backend and its record of
work and failures are this thread's :class:`Context` (:func:`enter`); a failure is recorded there
as the pipeline records it, and the compiled caller reads an empty answer.
"""

from __future__ import annotations

import threading

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.errors import NumericalFailure
from rrc_pin.solvers.qp_backends.base import QPBackend
from rrc_pin.solvers.qp_backends.qp import Work
from rrc_pin.solvers.tick.least_squares import Subspace, least_squares
from rrc_pin.solvers.tick.pipeline import backend_along, backend_slide
from rrc_pin.solvers.tick.problem import Box, Rows

Array = npt.NDArray[np.float64]

TOP, SLIDE, SLIDE_RELAXING = 0, -1, -2
"""Where a QP is asked for: the top level, the direction mode's sliding stage, a least-squares
top level's sliding stage that relaxes its rows where it fails; k > 0 is lower level k."""

_NO_KIND = np.zeros((2, 0), np.int8)
_EMPTY = np.empty(0)


class Context:
    """The backend a thread's compiled ticks hand their QPs to, and the record of its work.

    Args:
        backend: The QP backend.
        velocity: The velocity limits (n,) [rad/s or m/s] (the backend's tolerance).

    Attributes:
        work: What the backend did in the tick, and the failures; None until a QP is asked.
    """

    __slots__ = ("backend", "velocity", "work")

    def __init__(self, backend: QPBackend, velocity: Array) -> None:
        self.backend, self.velocity = backend, velocity
        self.work: Work | None = None


_LOCAL = threading.local()


def enter(context: Context) -> None:
    """Hand this thread's ticks' QPs to ``context`` (until :func:`leave`), its work cleared."""
    context.work = None
    _LOCAL.context = context


def leave() -> None:
    """End :func:`enter`'s hand-over."""
    _LOCAL.context = None


def compile_calls(context: Context) -> None:
    """Run each call once now on small problems of the context's rates.

    The kernels they reach are compiled (or loaded from numba's cache) before a tick hands a
    QP over; the backend's warm starts are then forgotten.

    The direction problem with a row (:func:`direction`); a least-squares level of one row
    (its metric semidefinite: the backend's QP) and of every rate (the projection's kernel),
    its rates beyond the box, on all rates and within a subspace, with a row and without
    (:func:`level`); the sliding stage's QP (:func:`slide`).
    """
    n = context.velocity.size
    lb, ub, x = np.full(n, -1.0), np.ones(n), np.zeros(n)
    rows = ((np.zeros((1, n)), np.ones(1)), (np.zeros((0, n)), np.zeros(0)))
    enter(context)
    try:
        direction(np.eye(n), np.full(n, 0.1), np.zeros((0, n)), lb, ub, *rows[0])
        for A in (np.eye(1, n), np.eye(n)):
            for where, N in ((TOP, np.zeros((0, n))), (1, np.eye(n))):
                for G, h in rows:
                    level(where, A, np.full(A.shape[0], 10.0), x, N, lb, ub, G, h, True)
        slide(SLIDE, np.eye(n), np.full(n, 0.1), lb, ub, *rows[0])
    finally:
        leave()
        context.backend.reset()


def _work() -> Work:
    context: Context = _LOCAL.context
    if context.work is None:
        context.work = Work()
    return context.work


def _box(lb: Array, ub: Array) -> Box:
    return Box(lb, ub, _NO_KIND, True, False, _LOCAL.context.velocity)


def _rows(G: Array, h: Array) -> Rows | None:
    return Rows(G, h, ()) if h.size else None


def _failed(where: int, exc: Exception) -> Array:
    """Record a failure where the pipeline does, and the empty answer of one."""
    reason = str(exc)
    if where == SLIDE:
        label, reason = "slide", f"{reason}; the command kept as given"
    elif where == SLIDE_RELAXING:
        label, reason = "slide", f"{reason}; the pairs asked apart only kept apart"
    elif where == TOP:
        label = "qp"
    else:
        label, reason = f"level {where}", f"{reason}; the levels above kept"
    _work().attempts.append((label, reason))
    return _EMPTY


def direction(A: Array, w: Array, null: Array, lb: Array, ub: Array, G: Array, h: Array
              ) -> tuple[Array, float, float]:  # fmt: skip
    """The direction problem along ``w`` by the backend, where the compiled active-set solver
    did not answer (:func:`rrc_pin.solvers.tick.pipeline.backend_along`): its rates (n,), their
    scale along the command and their veer off it [rad]; empty rates where it fails.
    """  # noqa: D205
    context = _LOCAL.context
    try:
        along = backend_along(A, w, null, _box(lb, ub), _rows(G, h), context.backend, _work(),
                              compiled=False)  # the tick's solver did not answer
    except NumericalFailure as exc:
        return _failed(TOP, exc), -1.0, 0.0
    return np.ascontiguousarray(along.qdot), float(along.u), float(along.veer)


def level(where: int, A: Array, b: Array, x: Array, N: Array, lb: Array, ub: Array, G: Array,
          h: Array, need_null: bool) -> tuple[Array, Array]:  # fmt: skip
    """A least-squares level whose QP the kernels do not answer, as the pipeline answers it
    (:func:`~rrc_pin.solvers.tick.least_squares.least_squares`, from the same inputs: the
    backend's QP meets the same floats): its rates and the null space left for the next level
    (none: (0, n)); empty rates where the backend fails.
    """  # noqa: D205
    context = _LOCAL.context
    box, rows = _box(lb, ub), _rows(G, h)
    space = Subspace(None, None) if N.shape[0] == 0 else Subspace(x, N)
    key = "least_squares" if where == TOP else "slide" if where == SLIDE else f"level{where}"
    try:
        qdot, null = least_squares(A, b, space, box, rows, context.backend, _work(), key,
                                   need_null)  # fmt: skip
    except NumericalFailure as exc:
        return _failed(where, exc), np.empty((0, x.size))
    none = np.empty((0, x.size))
    return np.ascontiguousarray(qdot), none if null is None else np.ascontiguousarray(null)


def slide(where: int, B: Array, target: Array, lb: Array, ub: Array, G: Array, h: Array
          ) -> Array:  # fmt: skip
    r"""The sliding stage's QP by the backend where its projection refused
    (:func:`rrc_pin.solvers.tick.pipeline.backend_slide`, the metric :math:`B^TB`): the rates,
    empty where it fails.
    """  # noqa: D205
    context = _LOCAL.context
    try:
        qdot = backend_slide(B, target, _box(lb, ub), Rows(G, h, ()), context.backend, _work())
    except NumericalFailure as exc:
        return _failed(where, exc)
    return np.ascontiguousarray(qdot)
