r"""Barker's closed-form resolved-rate equations (NASA TM-85685, 1983) for his PUMA-type arm.

The closed form :class:`BarkerClosedForm`; its equations are in
:mod:`rrc_pin.solvers.closed_form.barker_equations`.

Paths (``method``): ``"full"`` (default), eqs (34)-(36) for the arm and (49)-(51) for the
wrist; ``"reduced"``, eq. (39) + eq. (44) with the 2x2 M1 for the arm (eqs (40)-(43)
corrected), the same wrist. Both answer Barker's decoupled problem (the arm block first, then
the wrist with the arm's rotation removed, eq. (48)).

Singular neighbourhoods (the band). Each block has a measure ``s`` of its smallest singular
value: ``s^2 = det(M)^2 / ||adj M||_F^2 <= sigma_min(M)^2`` for M (equal to first order near
conditions (32), (33)), ``|det M1| / ||M1||_F`` for M1, and exactly
``s^2 = 1 - |C5| = S5^2 / (1 + |C5|)`` for the wrist's M2 (eq. (58)). With
``eps = band * L`` for the arm (``L = |ES| + hypot(SAL3 WE, A3)`` [m], the reach from joint 2
to the wrist centre) and ``eps = band`` for the wrist:

- outside the band (``s > eps``) the closed forms above answer, exactly;
- inside it (default, ``exact=False``) the block is solved by damped least squares
  ``(A^T A + lambda^2 I)^-1 A^T b`` with ``lambda^2 = eps^2 - s^2``: zero at the edge of the
  band, ``eps^2`` on the singular set. The rates are continuous in q across every
  singularity, and no block amplifies its command by more than ``1 / eps`` (Barker's
  "maximum angular rate penalty", text after eq. (51)); on the singular set the null
  direction gets no rate, as with the generalized inverses M*, M1*, M2*, and the other
  directions are damped by ``sigma^2 / (sigma^2 + eps^2)``;
- ``exact=True``: the exact inverse wherever ``s > rcond`` (times L for the arm), else the
  truncated pseudo-inverse (M* of eq. (38), M1* of eq. (44), M2* of eq. (60), singular
  values ``<= rcond`` dropped): finite, but as large as ``1 / s`` near a singularity.

``band = 0.01`` (default): the arm is damped where ``sigma_min(M) < 8.6 mm`` for the PUMA
values (2.8 % of random configurations within the limits), the wrist where
``|theta_5| < 0.81 deg`` (0.8 %); rates are at most 116 rad/m times ``|TVEL|`` and 100 times
``|RVEL~|``. Smaller bands are more exact near singularities and allow larger rates.

"""

from __future__ import annotations

from typing import Any, Literal, NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.checks import as_array, as_vector, choice, finite_number, flag
from rrc_pin.solvers.closed_form import barker_equations as eqs
from rrc_pin.solvers.closed_form.barker_equations import BarkerGeometry, FTerms
from rrc_pin.solvers.closed_form.base import (
    Array,
    ClosedForm,
    finite_rates,
    first,
    row,
    vector,
)
from rrc_pin.solvers.errors import InvalidInput

Method = Literal["full", "reduced"]
METHODS: tuple[str, ...] = ("full", "reduced")
MIN_BAND = 1e-4
"""Smallest ``band``: the damped solves lose about ``eps / band^2`` relative."""


class BarkerSingularity(NamedTuple):
    """Values of Barker's singularity conditions at one configuration (floats) or N (arrays).

    Attributes:
        eq32: S2 ES + F5 = F1 [m]; zero on condition (32).
        eq33: SAL3 WE S3 + A3 C3 [m]; zero on condition (33).
        s5: sin(theta_5); zero on the wrist singularity.
        det_m: det M = ES eq32 eq33 [m^3] (eq. (D9)).
        arm_singular: Inside the arm's band (module docstring): the default path damps M.
        wrist_singular: Inside the wrist's band: the default path damps M2.
    """

    eq32: Any
    eq33: Any
    s5: Any
    det_m: Any
    arm_singular: Any
    wrist_singular: Any


class BarkerClosedForm(ClosedForm):
    """Closed-form Jacobian and joint rates of Barker's arm, wrist centre as tool frame.

    Frames: :attr:`frame` is the generated URDF's ``"tool"`` frame, the wrist centre with the
    axes of frame 6. Twists ``[TVEL^; RVEL^]`` are ``world_aligned`` (wrist-centre velocity
    and angular velocity in base axes); operator commands in hand axes (``local``) go through
    :meth:`hand_twist_to_base` (eq. (20)).

    Every method is one call of a compiled kernel of
    :mod:`~rrc_pin.solvers.closed_form.barker_equations`; a ``_batch`` method loops over its rows
    inside the kernel, and the other methods of one configuration are a batch of one, except
    :meth:`jacobian` and :meth:`joint_rates`, which call their kernel directly.

    Args:
        no: Neck-to-base length NO = r1 [m].
        es: Elbow-to-shoulder length ES = a2 [m].
        sn: Shoulder-to-neck length SN = r2 [m].
        we: Wrist-to-elbow length WE = r4 [m].
        a3: Link length A3 = a3 [m].
        r3: Offset R3 = r3 [m].
        alpha3: Twist alpha3 [rad].
        rcond: Singular-value cutoff of the exact path, in [0, 0.5) (module docstring).
        band: Relative width of the damped singular neighbourhoods, in [1e-4, 0.5).

    Raises:
        InvalidInput: A parameter is not a finite number, or ``rcond``, ``band`` out of range,
            naming it.
    """

    nq = 6
    task_dim = 6

    def __init__(
        self, *, no: float, es: float, sn: float, we: float, a3: float, r3: float,
        alpha3: float, rcond: float = 1e-10, band: float = 1e-2,
    ) -> None:  # fmt: skip
        values = {"no": no, "es": es, "sn": sn, "we": we, "a3": a3, "r3": r3, "alpha3": alpha3}
        checked = {name: finite_number(value, name) for name, value in values.items()}
        self.rcond = finite_number(rcond, "rcond", 0.0, upper=0.5)
        self.band = finite_number(band, "band", MIN_BAND, upper=0.5)
        self.geometry = BarkerGeometry.from_parameters(**checked)
        self._p = eqs.parameters(self.geometry, self.band, self.rcond)
        scale = sum(abs(v) for k, v in checked.items() if k != "alpha3")
        self._has_reduced = abs(self.geometry.f2) > 1e-12 * scale  # eq. (39) divides by F2

    def __repr__(self) -> str:
        g = self.geometry
        return (
            f"BarkerClosedForm(no={g.no}, es={g.es}, sn={g.sn}, we={g.we}, a3={g.a3}, "
            f"r3={g.r3}, alpha3={g.alpha3}, rcond={self.rcond}, band={self.band})"
        )

    def jacobian(self, q: npt.ArrayLike) -> Array:
        """Wrist-centre Jacobian (6, 6) at ``q`` (6,) [rad], rows [v; w], base axes (eq. (22)).

        Raises:
            InvalidInput: ``q`` is not a finite (6,) vector.
        """
        qv = vector(q, "q", 6)
        J = np.empty((6, 6))
        if not eqs.jacobian_at(self._p, qv, J):
            as_vector(q, "q", 6)  # raises, naming the entry
        return J

    def jacobian_batch(self, Q: npt.ArrayLike) -> Array:
        """Wrist-centre Jacobians (N, 6, 6) at ``Q`` (N, 6) [rad], rows [v; w], base axes.

        Raises:
            InvalidInput: ``Q`` is not a finite (N, 6) array.
        """
        Q = as_array(Q, "Q", (None, 6))
        out = np.empty((Q.shape[0], 6, 6))
        eqs.jacobian_batch(self._p, Q, out)
        return out

    def wrist_centre(self, q: npt.ArrayLike) -> Array:
        """The wrist centre p06 (3,) [m] in base coordinates at ``q`` (6,) [rad]."""
        return first(self.wrist_centre_batch(row(q, "q", 6)))

    def wrist_centre_batch(self, Q: npt.ArrayLike) -> Array:
        """The wrist centres (N, 3) [m] at ``Q`` (N, 6): ``(F7, F6, NO + F3)``.

        Raises:
            InvalidInput: ``Q`` is not a finite (N, 6) array.
        """
        Q = as_array(Q, "Q", (None, 6))
        out = np.empty((Q.shape[0], 3))
        eqs.wrist_centre_batch(self._p, Q, out)
        return out

    def f_terms(self, q: npt.ArrayLike) -> FTerms:
        """F1..F7 (eqs (27)-(31), (41), (37)) [m] at ``q`` (6,), as floats."""
        return FTerms(*self._f_terms(row(q, "q", 6))[0].tolist())

    def f_terms_batch(self, Q: npt.ArrayLike) -> FTerms:
        """F1..F7 [m] at ``Q`` (N, 6), each (N,)."""
        return FTerms(*np.ascontiguousarray(self._f_terms(Q).T))

    def _f_terms(self, Q: npt.ArrayLike) -> Array:
        """F1..F7 [m] at ``Q`` (N, 6) as the columns of an (N, 7) array."""
        Q = as_array(Q, "Q", (None, 6))
        out = np.empty((Q.shape[0], 7))
        eqs.f_terms_batch(self._p, Q, out)
        return out

    def m_matrix(self, q: npt.ArrayLike) -> Array:
        """Barker's M (3, 3) [m], eq. (26): ``TVEL^ = M thetadot_123``."""
        return first(self.m_matrix_batch(row(q, "q", 6)))

    def m_matrix_batch(self, Q: npt.ArrayLike) -> Array:
        """Barker's M at ``Q`` (N, 6): (N, 3, 3) [m]."""
        Q = as_array(Q, "Q", (None, 6))
        out = np.empty((Q.shape[0], 3, 3))
        eqs.m_matrix_batch(self._p, Q, out)
        return out

    def det_m(self, q: npt.ArrayLike) -> float:
        """Determinant of M [m^3] in the factored form of eq. (D9)."""
        return float(self.det_m_batch(row(q, "q", 6))[0])

    def det_m_batch(self, Q: npt.ArrayLike) -> Array:
        """Determinant of M (eq. (D9)) at ``Q`` (N, 6): (N,) [m^3]."""
        return np.asarray(self.singularity_batch(Q).det_m)

    def singularity(self, q: npt.ArrayLike) -> BarkerSingularity:
        """Values of conditions (32), (33) and S5 at ``q`` (6,), as Python scalars."""
        s = self.singularity_batch(row(q, "q", 6))
        return BarkerSingularity(*(np.asarray(v)[0].item() for v in s))

    def singularity_batch(self, Q: npt.ArrayLike) -> BarkerSingularity:
        """Values of conditions (32), (33) and S5 at ``Q`` (N, 6), each (N,); band flags."""
        Q = as_array(Q, "Q", (None, 6))
        values = np.empty((4, Q.shape[0])).T  # columns stored apart: each field contiguous
        flags = np.empty((2, Q.shape[0]), dtype=np.bool_).T
        eqs.singularity_batch(self._p, Q, values, flags)
        return BarkerSingularity(*values.T, *flags.T)

    def arm_rates(
        self, q: npt.ArrayLike, tvel: npt.ArrayLike, method: Method = "full", exact: bool = False
    ) -> Array:
        """thetadot_1..3 (3,) [rad/s] realising the wrist-centre velocity ``tvel`` (3,) [m/s].

        ``method="full"``: eqs (34)-(36); ``"reduced"``: eqs (39), (44). ``tvel`` is TVEL^ in
        base axes. In the arm's band: damped, or M* / M1* with ``exact`` (module docstring).

        Raises:
            InvalidInput: Bad ``q``, ``tvel`` or ``method``.
        """
        return first(self.arm_rates_batch(row(q, "q", 6), row(tvel, "tvel", 3), method, exact))

    def arm_rates_batch(
        self, Q: npt.ArrayLike, TVEL: npt.ArrayLike, method: Method = "full", exact: bool = False
    ) -> Array:
        """Batch :meth:`arm_rates`: ``Q`` (N, 6), ``TVEL`` (N, 3) -> (N, 3) [rad/s]."""
        reduced = self._reduced(method)
        Q = as_array(Q, "Q", (None, 6))
        T = as_array(TVEL, "TVEL", (Q.shape[0], 3))
        out = np.empty((Q.shape[0], 3))
        eqs.arm_rates_batch(self._p, Q, T, reduced, flag(exact, "exact"), out)
        return out

    def rvel_tilde(self, q: npt.ArrayLike, arm_rates: npt.ArrayLike, rvel: npt.ArrayLike) -> Array:
        """RVEL~ = RVEL^ - z0 thetadot_1 - z1 thetadot_2 - z2 thetadot_3 (eq. (48)), (3,)."""
        return first(self.rvel_tilde_batch(
            row(q, "q", 6), row(arm_rates, "arm_rates", 3), row(rvel, "rvel", 3)
        ))

    def rvel_tilde_batch(
        self, Q: npt.ArrayLike, ARM: npt.ArrayLike, RVEL: npt.ArrayLike
    ) -> Array:
        """Batch :meth:`rvel_tilde`: ``Q`` (N, 6), ``ARM``, ``RVEL`` (N, 3) -> (N, 3) [rad/s]."""
        Q = as_array(Q, "Q", (None, 6))
        A = as_array(ARM, "ARM", (Q.shape[0], 3))
        R = as_array(RVEL, "RVEL", (Q.shape[0], 3))
        out = np.empty((Q.shape[0], 3))
        eqs.rvel_tilde_batch(Q, A, R, out)
        return out

    def wrist_rates(
        self, q: npt.ArrayLike, rvel_tilde: npt.ArrayLike, exact: bool = False
    ) -> Array:
        """thetadot_4..6 (3,) [rad/s] from RVEL~ (eq. (48)) (3,) [rad/s], base axes.

        Eqs (49)-(51), the wrist of both methods of :meth:`joint_rates`; in the wrist's band
        damped, or M2* (eq. (60)) with ``exact`` (``pinv(W, rcond) @ rvel_tilde``).

        Raises:
            InvalidInput: Bad ``q`` or ``rvel_tilde``.
        """
        return first(self.wrist_rates_batch(row(q, "q", 6), row(rvel_tilde, "rvel_tilde", 3),
                                            exact))  # fmt: skip

    def wrist_rates_batch(
        self, Q: npt.ArrayLike, RVEL_TILDE: npt.ArrayLike, exact: bool = False
    ) -> Array:
        """Batch :meth:`wrist_rates`: ``Q`` (N, 6), ``RVEL_TILDE`` (N, 3) -> (N, 3) [rad/s]."""
        Q = as_array(Q, "Q", (None, 6))
        R = as_array(RVEL_TILDE, "RVEL_TILDE", (Q.shape[0], 3))
        out = np.empty((Q.shape[0], 3))
        eqs.wrist_rates_batch(self._p, Q, R, flag(exact, "exact"), out)
        return out

    def joint_rates(
        self, q: npt.ArrayLike, xdot: npt.ArrayLike, method: Method = "full", exact: bool = False
    ) -> Array:
        """Joint rates (6,) [rad/s] realising the twist ``xdot = [TVEL^; RVEL^]`` (6,) at ``q``.

        Args:
            q: Joint positions (6,) [rad], Barker's theta_i.
            xdot: Wrist-centre velocity [m/s] and angular velocity [rad/s], base axes
                (``world_aligned``).
            method: ``"full"`` (eqs (34)-(36), (49)-(51)) or ``"reduced"`` (eqs (39), (44),
                (49)-(51)); see the module docstring.
            exact: In the singular bands, the exact inverse (truncated at ``rcond``) instead
                of the damped one.

        Returns:
            thetadot (6,): exact outside the bands; continuous in ``q`` and at most
            ``1 / band`` times the command inside them (``exact``: finite, never NaN).

        Raises:
            InvalidInput: Bad ``q``, ``xdot`` or ``method``.
        """
        reduced = self._reduced(method)
        qv, xv = vector(q, "q", 6), vector(xdot, "xdot", 6)
        out = np.empty(6)
        if not eqs.joint_rates_at(self._p, qv, xv, reduced, flag(exact, "exact"), out):
            as_vector(q, "q", 6)  # one of the two raises, naming the entry
            as_vector(xdot, "xdot", 6)
        return finite_rates(out, "xdot")

    def joint_rates_batch(
        self, Q: npt.ArrayLike, X: npt.ArrayLike, method: Method = "full", exact: bool = False
    ) -> Array:
        """Batch :meth:`joint_rates`: ``Q`` (N, 6), ``X`` (N, 6) -> (N, 6) [rad/s].

        Raises:
            InvalidInput: Bad ``Q``, ``X`` or ``method``.
        """
        reduced = self._reduced(method)
        Q, X = self._check_batch(Q, X)
        out = np.empty((Q.shape[0], 6))
        eqs.joint_rates_batch(self._p, Q, X, reduced, flag(exact, "exact"), out)
        return finite_rates(out, "X")

    def hand_to_base(self, q: npt.ArrayLike) -> Array:
        """R0_6 (3, 3) by eqs (B2)-(B24): hand (frame 6) axes in base axes."""
        return first(self.hand_to_base_batch(row(q, "q", 6)))

    def hand_to_base_batch(self, Q: npt.ArrayLike) -> Array:
        """R0_6 at ``Q`` (N, 6): (N, 3, 3)."""
        Q = as_array(Q, "Q", (None, 6))
        out = np.empty((Q.shape[0], 3, 3))
        eqs.hand_to_base_batch(self._p, Q, out)
        return out

    def hand_twist_to_base(self, q: npt.ArrayLike, twist: npt.ArrayLike) -> Array:
        """Operator command ``[TVEL; RVEL]`` (6,) in hand axes -> base axes, eq. (20)."""
        return first(self.hand_twist_to_base_batch(row(q, "q", 6), row(twist, "twist", 6)))

    def hand_twist_to_base_batch(self, Q: npt.ArrayLike, TWIST: npt.ArrayLike) -> Array:
        """Batch :meth:`hand_twist_to_base`: ``Q`` (N, 6), ``TWIST`` (N, 6) -> (N, 6)."""
        Q = as_array(Q, "Q", (None, 6))
        T = as_array(TWIST, "TWIST", (Q.shape[0], 6)).reshape(-1, 2, 3)
        out: Array = np.einsum("nij,nkj->nki", self.hand_to_base_batch(Q), T).reshape(-1, 6)
        return out

    def tvel_frame2(self, q: npt.ArrayLike, tvel: npt.ArrayLike) -> Array:
        """TVEL^ (3,) [m/s] resolved along X2, Y2, Z2 (eqs (B27)-(B29) corrected), (3,)."""
        return first(self.tvel_frame2_batch(row(q, "q", 6), row(tvel, "tvel", 3)))

    def tvel_frame2_batch(self, Q: npt.ArrayLike, TVEL: npt.ArrayLike) -> Array:
        """Batch :meth:`tvel_frame2`: ``Q`` (N, 6), ``TVEL`` (N, 3) -> (N, 3) [m/s]."""
        Q = as_array(Q, "Q", (None, 6))
        T = as_array(TVEL, "TVEL", (Q.shape[0], 3))
        out = np.empty((Q.shape[0], 3))
        eqs.tvel_frame2_batch(Q, T, out)
        return out

    def _reduced(self, method: str) -> bool:
        if choice(method, "method", METHODS) == "full":
            return False
        if not self._has_reduced:
            raise InvalidInput(
                "method", "the reduced path divides by F2 = SN + R3 + cos(alpha3) WE = 0"
            )
        return True
