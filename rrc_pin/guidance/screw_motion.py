"""Nadkarni's guidance Type II: the hand on the screw of its displacement (chapter IV).

A modified form of Pieper's iterative velocity method (the thesis's footnote): the screw of the
displacement is located once (chapter III) and each of the k steps is the same twist, a turn
``theta / k`` about the axis with the advance ``h theta / k`` along it (eqs (4-18), (4-19a));
a pure translation moves ``d / k`` along it (eq. (4-19b)).

Two readings of the step's vector B (``b_form``):

- ``"twist"``: eq. (4-19a) as printed, ``[dtheta U; h dtheta U - dtheta U x rho_n]``, the
  screw's twist (its exponential is the step's displacement exactly);
- ``"disp"``: what the thesis's program DISP computed (subroutine DISPM, Appendix I), found from
  Tables A2-6 and A2-9: eq. (4-19a) with the second-order term of the displacement of the base
  origin's point, as eq. (5-5) writes it for a joint,

  .. math::

      B = [dtheta U;  h dtheta U - dtheta U x rho_n - dtheta^2 / 2 U x (U x rho_n)]

  (rows reordered to our [v; w]). It depends on where the base origin is (``rho_n`` is the foot
  of the normal from it), which the twist does not.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.guidance.screw import Screw, check_screw, screw_from_poses, screw_twist
from rrc_pin.guidance.stepping import (
    MAX_STEPS,
    Array,
    Correction,
    GuidancePath,
    Kinematics,
    Solver,
    Step,
    check_q0,
    check_steps,
    on_frame,
    run_steps,
)
from rrc_pin.solvers.checks import choice, flag, integer, rigid_transform

BForm = Literal["twist", "disp"]


def disp_step(screw: Screw, k: int, b_form: BForm = "disp") -> Array:
    """The vector B (..., 6) [v; w], WORLD, of one of ``k`` equal steps along ``screw``.

    Args:
        screw: The screw (batched or not) of the whole displacement (base frame, SI).
        k: Number of steps >= 1.
        b_form: ``"twist"`` (eq. (4-19a), the screw's twist / k) or ``"disp"`` (with DISP's
            second-order term of the base origin's displacement, module docstring).

    Raises:
        InvalidInput: A bad ``screw``, ``k`` or ``b_form``.
    """
    k = check_steps(k, "k")
    screw = check_screw(screw)
    twist = screw_twist(screw) / k
    if check_b_form(b_form) == "twist":
        return twist
    u, rho = screw.u, screw.rho
    dtheta = screw.theta[..., None] / k
    out: Array = twist.copy()
    out[..., :3] -= 0.5 * dtheta**2 * np.cross(u, np.cross(u, rho))
    return out


def check_b_form(b_form: BForm) -> BForm:
    """``b_form`` checked.

    Raises:
        InvalidInput: Not ``"twist"`` or ``"disp"``.
    """
    return choice(b_form, "b_form", ("twist", "disp"))  # type: ignore[return-value]


def screw_step_b(screw: Screw, k: int, b_form: BForm, T: Array) -> Step:
    """Step from the hand pose ``T``: the vector B of ``disp_step`` and the exact target.

    The target (what the corrections aim at) is the screw's own ``k``-th part applied to ``T``,
    ``exp(twist / k) T``, whichever ``b_form``.
    """
    B = disp_step(screw, k, b_form)
    twist = screw_twist(screw) / k
    target = (pin.exp6(pin.Motion(twist)) * pin.SE3(T)).homogeneous
    return Step(np.asarray(B, dtype=np.float64), target)


def check_closing(closing: int) -> int:
    """``closing`` as an int in [0, MAX_STEPS].

    Raises:
        InvalidInput: Not an integer in [0, MAX_STEPS].
    """
    return integer(closing, "closing", 0, MAX_STEPS)


def screw_motion(
    arm: Kinematics,
    q0: npt.ArrayLike,
    goal: npt.ArrayLike,
    steps: int,
    *,
    relocate: bool = False,
    b_form: BForm = "twist",
    closing: int = 0,
    solver: Solver = "thesis",
    correction: Correction = "none",
    frame: str | None = None,
) -> GuidancePath:
    """Type II: from the hand's pose at ``q0`` to ``goal`` along their screw, in ``steps`` steps.

    Args:
        arm: A :class:`rrc_pin.Robot` or :class:`rrc_pin.dh.DHChain`.
        q0: Start configuration (nq,).
        goal: (4, 4) goal pose of the hand, base frame.
        steps: Number of steps k >= 1.
        relocate: False (the thesis): one screw, the same twist at every step, so the
            first-order errors add up (``correction="newton"`` removes them). True: the screw is
            located again from the hand reached, each step a ``1 / (k - i)`` share of it (the
            hand then ends on the goal, near the first screw).
        b_form: ``"twist"`` (eq. (4-19a)) or ``"disp"`` (DISP's B, module docstring).
        closing: Steps added after the k, each the whole screw from the hand reached to the
            goal in one step (DISP took one: Illustrations 4 and 5); 0 for none.
        solver: ``"thesis"``, a :class:`ThesisSolver` or a :class:`rrc_pin.Resolver`.
        correction: ``"newton"`` for the second-order correction (eq. (5-5)).
        frame: The frame to guide on a robot with several tool frames (a cell, a combined
            robot), or any frame of a :class:`rrc_pin.Robot`; None: its one tool frame.

    Returns:
        The path, ``k + closing`` steps.

    Raises:
        InvalidInput: A bad ``goal``, ``q0``, ``steps``, ``b_form`` or ``closing``, named.
    """
    arm = on_frame(arm, frame)
    target = rigid_transform(goal, "goal")
    k = check_steps(steps)
    extra = check_closing(closing)
    check_b_form(b_form)
    relocate = flag(relocate, "relocate")
    first = screw_from_poses(arm.fk(check_q0(arm, q0)), target)

    def twist(i: int, T: Array) -> Step:
        if i >= k:
            return screw_step_b(screw_from_poses(T, target), 1, b_form, T)
        if not relocate:
            return screw_step_b(first, k, b_form, T)
        return screw_step_b(screw_from_poses(T, target), k - i, b_form, T)

    return run_steps(arm, q0, twist, k + extra, solver=solver, correction=correction)
