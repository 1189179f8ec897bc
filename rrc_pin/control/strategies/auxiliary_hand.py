r"""Auxiliary hand control near the stretched elbow (Barker eqs (45)-(46)).

In the elbow region (eq. (33) within ``region * L``) the arm no longer follows the closed
form; with :math:`(TVEL)_{X2}, (TVEL)_{Y2}` the wrist-centre velocity along X2 (outward along
the upper arm) and Y2 (eqs (B27)-(B29) corrected, ``BarkerClosedForm.tvel_frame2``):

.. math::

    \dot\theta_3 = \begin{cases} 0 & \text{at the singular point, outward command} \\
                                 K_3\,(TVEL)_{X2} & \text{otherwise} \end{cases}
    \qquad (45)

    \dot\theta_2 = -\frac{WE}{WE + ES}\,\dot\theta_3 + K_2\,\frac{(TVEL)_{Y2}}{WE + ES}
    \qquad (46)

The first term of eq. (46) retracts the hand in nearly a straight line toward the shoulder;
the second pitches the extended arm. Barker gives the azimuth to eq. (39); with its rows as
corrected here (docs/errata.md) eq. (39) is the in-plane horizontal row, where theta1 acts
through the small offset F2 and would turn every mismatch of the in-plane motion into a
large sideways swing; theta1 is taken instead from the lateral row of eq. (25) turned by
theta1, ``tb = -F1 thetadot_1``, the azimuth movement he describes. The sign of K3 flips each
time the arm enters the region, so the operator chooses the elbow bend by extending and
backing up.

An outward command with the elbow bent (inside the region but not at the singular point)
straightens the elbow toward the singular point and stops there, so that an impossible
outward command never bends the arm back (Barker's ``0`` case, reached in finite steps). The
wrist follows the closed form with the arm's rotation removed (eq. (48)).
"""

from __future__ import annotations

import math

import numpy as np

from rrc_pin.control.strategies.barker_arm import (
    barker_closed_form,
    elbow_singular_angle,
    nearness,
)
from rrc_pin.control.strategies.base import Decision, Situation, Strategy
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import finite_number
from rrc_pin.solvers.closed_form.barker import BarkerClosedForm
from rrc_pin.solvers.closed_form.barker_equations import f_terms, joint_trig, turn1

AT_SINGULAR = 1e-9
"""[rad] theta3 this close to the singular angle counts as at the singular point."""


class AuxiliaryHand(Strategy):
    """Barker's auxiliary hand control (module docstring).

    Args:
        k3: Gain K3 [rad/m] of eq. (45), > 0 (its sign flips on each entry; it starts
            negative so that the first entry bends the elbow with K3 > 0).
        k2: Gain K2 [1] of eq. (46), >= 0.
        region: Width of the elbow region, relative to the reach ``L``, in (0, 0.5).

    Raises:
        InvalidInput: A bad argument, named.
    """

    name = "auxiliary_hand"
    chooses_rates = True

    def __init__(self, k3: float = 20.0, k2: float = 1.0, region: float = 0.05) -> None:
        self.k3 = -finite_number(k3, "k3", 0.0, False)
        self.k2 = finite_number(k2, "k2", 0.0)
        self.region = finite_number(region, "region", 0.0, False, 0.5)
        self.inside = False
        self.entries = 0
        self.closed_form: BarkerClosedForm | None = None

    def check(self, robot: Robot) -> None:
        """Refuse an arm without Barker's closed form."""
        self.closed_form = barker_closed_form(robot, self.name)

    def reset(self) -> None:
        """Forget whether the arm is inside the region (K3 keeps its sign)."""
        self.inside = False

    def decide(self, situation: Situation) -> Decision:
        """Eqs (45), (46) and the azimuth row in the elbow region; the closed form outside."""
        cf = self.closed_form or barker_closed_form(situation.robot, self.name)
        q, twist = situation.q, situation.twist
        inside = nearness(cf, q).elbow < self.region
        if inside and not self.inside:
            self.k3, self.entries = -self.k3, self.entries + 1
        self.inside = inside
        if not inside:
            return Decision(rates=cf.joint_rates(q, twist))
        g = cf.geometry
        tx2, ty2, _ = cf.tvel_frame2(q, twist[:3])
        offset = q[2] - elbow_singular_angle(cf)
        if tx2 <= 0.0:  # inward (or across): eq. (45), the bend chosen by K3's sign
            th3 = self.k3 * tx2
        elif abs(offset) <= AT_SINGULAR:  # eq. (45): an impossible outward command
            th3 = 0.0
        else:  # outward with the elbow bent: straighten, stopping at the singular point
            th3 = -math.copysign(min(abs(self.k3 * tx2), abs(offset) / situation.dt), offset)
        th2 = (-g.we * th3 + self.k2 * ty2) / (g.we + g.es)  # eq. (46)
        t = joint_trig(q)
        F = f_terms(g, t)
        lateral = turn1(t, twist[0], twist[1])[1]  # -F1 thetadot_1: only theta1 moves it
        th1 = -lateral / F.f1 if abs(F.f1) > AT_SINGULAR else 0.0
        arm = np.array([th1, th2, th3])
        wrist = cf.wrist_rates(q, cf.rvel_tilde(q, arm, twist[3:]))
        note = f"auxiliary: K3 {self.k3:+g}, entry {self.entries}"
        return Decision(rates=np.concatenate([arm, wrist]), note=note)

