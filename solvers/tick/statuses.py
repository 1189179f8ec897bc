"""How a tick reports a level served: the rules the compiled tick and the Python pipeline share.

Each rule is one kernel, called from the compiled tick (:mod:`rrc_pin.solvers.tick.top`,
:mod:`rrc_pin.solvers.tick.tick`) and from plain Python
(:mod:`rrc_pin.solvers.tick.pipeline`), which names the codes by
:data:`~rrc_pin.solvers.tick.pipeline.Status` and
:data:`~rrc_pin.solvers.tick.pipeline.LevelStatus`:

- a command is **met** where the residual is within :data:`EXACT_TOL` of it (:func:`met`);
- a top level whose stacked command is met is ``exact`` where that is the command itself, else
  (a command divided down, :mod:`rrc_pin.solvers.tick.problem`) ``scaled`` by its factor
  (:func:`met_top`);
- a lower level is ``met``, ``scaled`` along its command or ``traded`` (:func:`served`); the
  top level as a level by its status (:func:`top_served`);
- a top level's ``exact`` or ``scaled`` is refused for a subnormal command (:func:`borne_out`):
  :func:`met` asks nothing of a command far below one task unit (a backend's answer to it is
  met by any rates within its tolerance, and the clip into the box turns them off it); an
  ``exact`` one shrunk into the rows by the last stage is ``scaled``.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import kernel

Array = npt.NDArray[np.float64]

EXACT, SCALED, SLIDING, DAMPED, SINGULAR, LEAST_SQUARES, RECOVERING, FALLBACK = range(8)
"""Codes of :data:`~rrc_pin.solvers.tick.pipeline.Status`, in its order."""

FAILED = -1
"""The top level found no usable answer: the fallbacks answer."""

MET, SCALED_LEVEL, TRADED, DROPPED = range(4)
"""Codes of :data:`~rrc_pin.solvers.tick.pipeline.LevelStatus`, in its order."""

EXACT_TOL = 1e-9
"""Relative residual under which a command counts as met, and a scale as 1."""

TINY = 2.2250738585072014e-308
"""The smallest normal float: below it a rate has fewer bits than a relative check asks."""

VEER_TOL = 1e-6
"""The angle [rad] off its command under which a lower level's rates are its command scaled."""

STILL_SCALE = 1e-9
"""A direction answer scaled below this stands still along the command: its task rates are the
rounding of a zero, and their direction is noise (not checked against the command's)."""


@kernel
def norm(x: Array) -> float:
    """Euclidean norm without overflow or underflow."""
    top = 0.0
    for i in range(x.size):
        top = max(top, abs(x[i]))
    if top == 0.0 or not math.isfinite(top):
        return top
    s = 0.0
    for i in range(x.size):
        s += (x[i] / top) ** 2
    return top * math.sqrt(s)


@kernel
def met(y: Array, b: Array) -> bool:
    """Whether the rows' rates ``y`` (m,) meet the command ``b`` (m,) to :data:`EXACT_TOL`."""
    return norm(y - b) <= EXACT_TOL * (1.0 + norm(b))


@kernel
def met_top(rate_factor: float) -> int:
    """The status code of a top level whose stacked command is met: :data:`EXACT` where
    ``rate_factor`` is 1, else :data:`SCALED` (by ``rate_factor``, its scale either way).
    """  # noqa: D205
    return EXACT if rate_factor == 1.0 else SCALED


@kernel
def top_served(status: int) -> int:
    """How a top level of status code ``status`` is served, as a level: :data:`MET` where
    ``exact``, :data:`SCALED_LEVEL` where ``scaled``, else :data:`TRADED`.
    """  # noqa: D205
    return MET if status == EXACT else SCALED_LEVEL if status == SCALED else TRADED


@kernel
def scale_and_veer(y: Array, b: Array, factor: Array | None = None) -> tuple[float, float]:
    r"""Fraction of ``b`` achieved along it by ``y`` (in [0, 1]) and the angle between them [rad].

    The scale is :math:`y^Tb/b^Tb` and the angle :math:`\arccos(y^Tb/(|y||b|))`, computed on
    both divided by their largest entries so that no product overflows; the ratio of those
    entries is formed with the larger one as divisor (a subnormal command's would overflow).

    Args:
        y: Achieved rates (m,).
        b: Commanded rates (m,).
        factor: Row factors (m,) of a level's metric, or None: the scale and angle of
            ``factor * y`` and ``factor * b``, both first divided by b's largest entry where
            it exceeds 1 (so that the factors cannot overflow a command near the float range;
            a subnormal one is not divided up: the achieved rates would overflow).

    Returns:
        (scale, veer): (1, 0) for a zero command, (0, 0) for zero rates.
    """
    m = b.size
    ys, bs = np.empty(m), np.empty(m)
    if factor is None:
        for i in range(m):
            ys[i] = y[i]
            bs[i] = b[i]
    else:
        peak = 1.0
        for i in range(m):
            peak = max(peak, abs(b[i]))
        for i in range(m):
            ys[i] = factor[i] * (y[i] / peak)
            bs[i] = factor[i] * (b[i] / peak)
    top_b = 0.0
    top_y = 0.0
    for i in range(m):
        top_b = max(top_b, abs(bs[i]))
        top_y = max(top_y, abs(ys[i]))
    if top_b == 0.0:
        return 1.0, 0.0
    if top_y == 0.0:
        return 0.0, 0.0
    yb = yy = bb = 0.0
    for i in range(m):
        yn, bn = ys[i] / top_y, bs[i] / top_b
        yb += yn * bn
        yy += yn * yn
        bb += bn * bn
    cosine = yb / (math.sqrt(yy) * math.sqrt(bb))
    veer = math.acos(min(max(cosine, -1.0), 1.0))
    along = yb / bb  # the scale, times top_b / top_y
    if along <= 0.0:
        return 0.0, veer
    if top_y <= top_b:
        return min(along * (top_y / top_b), 1.0), veer
    ratio = top_b / top_y
    return (along / ratio if along < ratio else 1.0), veer


@kernel
def served(y: Array, b: Array, rate_factor: float) -> int:
    """How rates ``y`` (m,) serve a level's command ``b`` (m,) (its rates times
    ``rate_factor``): a code of :data:`MET`, :data:`SCALED_LEVEL`, :data:`TRADED`.

    A command divided down and met is scaled; a zero command has no direction to scale along:
    not met, it is traded.
    """  # noqa: D205
    if met(y, b):
        return MET if rate_factor == 1.0 else SCALED_LEVEL
    scale, veer = scale_and_veer(y, b)
    return SCALED_LEVEL if veer <= VEER_TOL and scale > 0.0 and b.any() else TRADED


@kernel
def borne_out(status: int, y: Array, b: Array, direction: bool, rate_factor: float,
              scale: float, veer: float) -> tuple[int, float, float]:  # fmt: skip
    """The top level's ``(status, scale, veer)`` as its final rates ``y`` (m,) bear them out.

    A stacked command ``b`` (m,) whose rates are all subnormal (below :data:`TINY`: met to
    :data:`EXACT_TOL` by any small rates)
    is neither ``exact`` nor ``scaled``: in the direction mode :data:`FAILED` (the fallbacks
    answer), else ``least_squares``. An ``exact`` answer whose ``scale`` the shrink into the rows
    took below 1 (its rates that factor of the command's) is ``scaled``. Any other report is
    kept.
    """
    if status != EXACT and status != SCALED:
        return status, scale, veer
    if status == EXACT and scale < 1.0 - EXACT_TOL:
        status = SCALED
    peak = 0.0
    for i in range(b.size):
        peak = max(peak, abs(b[i]))
    if peak == 0.0 or peak >= TINY:
        return status, scale, veer
    return (FAILED if direction else LEAST_SQUARES), scale, veer
