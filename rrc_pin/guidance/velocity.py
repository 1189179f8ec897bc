"""Nadkarni's velocity analysis from the displacement analysis (chapter V, eqs (5-1)-(5-4))."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.guidance.stepping import Array
from rrc_pin.solvers.checks import finite_array, finite_number


def joint_rates(increments: npt.ArrayLike, hand_step: float, hand_speed: float) -> Array:
    """Joint rates of a hand moving at ``hand_speed`` along a step of the displacement analysis.

    .. math::

        |W_j| = (delta theta_j / delta theta) |W_H|   (5-3),
        |V_j| = (delta r_j / delta theta) |W_H|       (5-4, prismatic joints)

    For a pure translation of the hand, ``hand_step`` is its ``delta r`` and ``hand_speed``
    its ``|V_H|`` (the text after eq. (5-4)).

    Args:
        increments: (..., nq) joint increments of one step [rad or m] (eq. (4-11b)'s D).
        hand_step: The hand's rotation ``delta theta`` in that step [rad] (its translation
            ``delta r`` [m] for a pure translation), nonzero.
        hand_speed: ``|W_H|`` [rad/s] (``|V_H|`` [m/s] for a pure translation).

    Returns:
        (..., nq) joint rates [rad/s or m/s], signed as the increments.

    Raises:
        InvalidInput: Non-finite input, ``hand_step`` zero, or so small against the
            increments that the rates overflow.
    """
    D = finite_array(increments, "increments")
    step = finite_number(hand_step, "hand_step")
    if step == 0.0:
        raise InvalidInput("hand_step", "the hand must move in the step (nonzero)")
    speed = finite_number(hand_speed, "hand_speed")
    with np.errstate(over="ignore"):
        out: Array = D / step * speed
    if not np.isfinite(out).all():
        raise InvalidInput("increments, hand_step", f"the rates overflow: increments up to "
                           f"{np.abs(D).max():g} over a step of {step:g} at {speed:g}")  # fmt: skip
    return out
