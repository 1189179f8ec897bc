r"""The jerk stage's per-joint step, compiled (:mod:`rrc_pin.control.smoothing` calls it).

Each joint's rate :math:`v` follows its target rate with the acceleration that reaches it
soonest without overshoot, :math:`a^*` solving :math:`a\,\Delta t + a|a|/(2 j_{max}) = e`
(:math:`e` the target minus the rate: the rate gained this tick plus while the acceleration
ramps back to zero), clipped into the jerk's interval :math:`[a - j_{max}\Delta t,\ a +
j_{max}\Delta t]` and the acceleration's :math:`[-a_{max}, a_{max}]`; and the target slowed
before a position limit to a rate the joint can stop from in the distance :math:`d` left,
:math:`v^2/(2a_b) + v\,\ell \le d`. Written as the numpy expressions they replace (the same
operations in the same order: the same floats).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import kernel

Array = npt.NDArray[np.float64]


@kernel
def jerk_step(v: Array, a: Array, target: Array, dt: float, a_max: Array, j_max: Array,
              out: Array) -> None:  # fmt: skip
    """``out`` (n,): each rate ``v`` (n,) one tick of ``dt`` [s] on toward ``target`` (n,).

    ``a`` (n,) the rates' acceleration over the last tick, ``a_max`` and ``j_max`` (n,) the
    bounds (module docstring).
    """
    for i in range(v.shape[0]):
        e = target[i] - v[i]
        j = j_max[i]
        sign = 1.0 if e > 0.0 else (-1.0 if e < 0.0 else 0.0)
        wanted = sign * j * (math.sqrt(dt * dt + 2.0 * abs(e) / j) - dt)
        step = min(max(wanted, a[i] - j * dt), a[i] + j * dt)
        step = min(max(step, -a_max[i]), a_max[i])
        out[i] = v[i] + step * dt


@kernel
def braked(command: Array, position: Array, lower: Array, upper: Array, brake: Array,
           lead: Array, out: Array) -> None:  # fmt: skip
    r"""``out`` (n,): each rate of ``command`` (n,) within what stops it before its limits.

    The fastest rate toward a limit at distance d: :math:`-a_b\ell + \sqrt{(a_b\ell)^2 +
    2 a_b d}` (the positive root of :math:`v^2/(2a_b) + v\ell = d`), ``brake`` :math:`a_b`
    and ``lead`` :math:`\ell` (n,) per joint, ``position``, ``lower``, ``upper`` (n,).
    """
    for i in range(command.shape[0]):
        a, lead_i = brake[i], lead[i]
        up = max(upper[i] - position[i], 0.0)
        down = max(position[i] - lower[i], 0.0)
        fastest_up = -a * lead_i + math.sqrt((a * lead_i) ** 2 + 2.0 * a * up)
        fastest_down = -a * lead_i + math.sqrt((a * lead_i) ** 2 + 2.0 * a * down)
        out[i] = max(min(command[i], fastest_up), -fastest_down)
