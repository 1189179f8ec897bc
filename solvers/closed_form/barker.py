"""Barker's closed-form resolved-rate equations (NASA TM-85685, 1983) for his PUMA-type arm.

Standard DH (Barker eq. (1)): alpha = (90, 0, alpha3, 90, 90, 0) deg, a = (0, ES, A3, 0, 0, 0),
r = (NO, SN, R3, WE, 0, 0), theta'_i = theta_i + (180, 90, 90, 180, 180, 0) deg; q is Barker's
theta_i. The controlled point is the wrist centre (origin of frames 4, 5, 6), so the
Jacobian is block lower-triangular (eq. (22)): the arm rates solve ``M thetadot_123 = TVEL^``
(eq. (25)) and the wrist rates solve ``W thetadot_456 = RVEL~`` (eqs (47), (48)).

Paths (``method``):

- ``"full"`` (default): eqs (34)-(36) for the arm, eqs (49)-(51) for the wrist. Where the arm
  block is singular (``|det M| <= rcond ||M||_F^3``) the arm uses M* (eq. (38)); where
  ``|S5| <= rcond (1 + |C5|)`` the wrist uses M2* (eq. (60)). The result always equals the
  decoupled truncated pseudo-inverse solution ``pinv(M, rcond) TVEL^`` then
  ``pinv(W, rcond) RVEL~``: the exact inverse where J is regular, finite minimum-norm
  least squares at a singularity, never NaN.
- ``"reduced"``: eq. (39) + eq. (44) with the 2x2 M1* for the arm (eqs (40)-(43) corrected,
  see :func:`~solvers.closed_form.barker_kernels.arm_rates_reduced`), eq. (49) + eq. (60)
  with M2* for the wrist. Exact where J is regular; at an arm singularity it gives the
  least-squares solution of eq. (25) satisfying eq. (39) with least (thetadot_2,
  thetadot_3) norm, which is the minimum-norm one at eq. (33) for commands M can realise,
  but not at eq. (32) nor at the double singularity (there M* spreads the rate over
  thetadot_1 and thetadot_2).

At an arm singularity both paths answer Barker's decoupled problem (arm block first, then the
wrist with the arm's rotation removed, eq. (48)); the minimum-norm least-squares solution of
the whole 6x6 system, ``pinv(J) xdot``, trades the arm residual against the wrist and differs.

Singular set (Appendix D): ``det J = det M det W = ES (S2 ES + F5)(SAL3 WE S3 + A3 C3) S5``
(up to sign), for any R3 and alpha3: conditions (32), (33) and S5 = 0.
"""

from __future__ import annotations

from typing import Literal, NamedTuple

import numpy as np
import numpy.typing as npt

from solvers.closed_form import barker_kernels as K
from solvers.closed_form.barker_batch import joint_rates_full
from solvers.closed_form.barker_kernels import BarkerGeometry, FTerms
from solvers.closed_form.barker_scalar import (
    arm_scalar,
    constants,
    jacobian_scalar,
    joint_rates_full_scalar,
    joint_rates_scalar,
    rvel_tilde_scalar,
    trig_scalar,
    wrist_scalar,
)
from solvers.closed_form.base import ClosedForm
from solvers.errors import InputError
from solvers.validation import as_array, as_float_list, as_vector, finite_number

Array = npt.NDArray[np.float64]
Method = Literal["full", "reduced"]
METHODS: tuple[str, ...] = ("full", "reduced")


class BarkerSingularity(NamedTuple):
    """Values of Barker's singularity conditions at one configuration (floats) or N (arrays).

    Attributes:
        eq32: S2 ES + F5 = F1 [m]; zero on condition (32).
        eq33: SAL3 WE S3 + A3 C3 [m]; zero on condition (33).
        s5: sin(theta_5); zero on the wrist singularity.
        det_m: det M = ES eq32 eq33 [m^3] (eq. (D9)).
        arm_singular: ``|det M| <= rcond ||M||_F^3``: eqs (34)-(36) not used, M* answers.
        wrist_singular: ``|S5| <= rcond (1 + |C5|)``: M2* truncates the wrist block.
    """

    eq32: Array | float
    eq33: Array | float
    s5: Array | float
    det_m: Array | float
    arm_singular: npt.NDArray[np.bool_] | bool
    wrist_singular: npt.NDArray[np.bool_] | bool


class BarkerClosedForm(ClosedForm):
    """Closed-form Jacobian and joint rates of Barker's arm, wrist centre as tool frame.

    Frames: twists ``[TVEL^; RVEL^]`` are ``world_aligned`` (wrist-centre velocity and
    angular velocity in base axes); operator commands in hand axes (``local``) go through
    :meth:`hand_twist_to_base` (eq. (20)).

    Args:
        no: Neck-to-base length NO = r1 [m].
        es: Elbow-to-shoulder length ES = a2 [m].
        sn: Shoulder-to-neck length SN = r2 [m].
        we: Wrist-to-elbow length WE = r4 [m].
        a3: Link length A3 = a3 [m].
        r3: Offset R3 = r3 [m].
        alpha3: Twist alpha3 [rad].
        rcond: Relative singular-value cutoff of the generalized inverses, in [0, 0.5).

    Raises:
        InputError: A parameter is not a finite number (or ``rcond`` out of range), naming it.
    """

    nq = 6
    task_dim = 6

    def __init__(
        self,
        *,
        no: float,
        es: float,
        sn: float,
        we: float,
        a3: float,
        r3: float,
        alpha3: float,
        rcond: float = 1e-10,
    ) -> None:
        values = {"no": no, "es": es, "sn": sn, "we": we, "a3": a3, "r3": r3, "alpha3": alpha3}
        checked = {name: finite_number(value, name) for name, value in values.items()}
        rcond = finite_number(rcond, "rcond", 0.0, upper=0.5)
        self.geometry = BarkerGeometry.from_parameters(**checked)
        self.rcond = rcond
        self._k = constants(self.geometry)
        scale = sum(abs(v) for k, v in checked.items() if k != "alpha3")
        self._has_reduced = abs(self.geometry.f2) > 1e-12 * scale  # eq. (39) divides by F2

    def __repr__(self) -> str:
        g = self.geometry
        return (
            f"BarkerClosedForm(no={g.no}, es={g.es}, sn={g.sn}, we={g.we}, a3={g.a3}, "
            f"r3={g.r3}, alpha3={g.alpha3}, rcond={self.rcond})"
        )

    # -- Jacobian and the arm block -------------------------------------------------------

    def jacobian(self, q: npt.ArrayLike) -> Array:
        """Wrist-centre Jacobian (6, 6) at ``q`` (6,) [rad], rows [v; w], base axes (eq. (22)).

        Raises:
            InputError: ``q`` is not a finite (6,) vector.
        """
        return jacobian_scalar(self._k, as_float_list(q, "q", 6))

    def jacobian_batch(self, Q: npt.ArrayLike) -> Array:
        """Wrist-centre Jacobians (N, 6, 6) at ``Q`` (N, 6) [rad], rows [v; w], base axes.

        Raises:
            InputError: ``Q`` is not a finite (N, 6) array.
        """
        Q, _ = self._check_batch(Q)
        return K.jacobian(self.geometry, K.trig(Q))

    def f_terms(self, q: npt.ArrayLike) -> FTerms:
        """F1..F7 (eqs (27)-(31), (41), (37)) [m] at ``q`` (6,), as floats."""
        F = self.f_terms_batch(as_vector(q, "q", 6)[None])
        return FTerms(*(float(v[0]) for v in F))

    def f_terms_batch(self, Q: npt.ArrayLike) -> FTerms:
        """F1..F7 [m] at ``Q`` (N, 6), each (N,)."""
        Q, _ = self._check_batch(Q)
        return K.f_terms(self.geometry, K.trig(Q))

    def m_matrix(self, q: npt.ArrayLike) -> Array:
        """Barker's M (3, 3) [m], eq. (26): ``TVEL^ = M thetadot_123``."""
        return self.m_matrix_batch(as_vector(q, "q", 6)[None])[0]

    def m_matrix_batch(self, Q: npt.ArrayLike) -> Array:
        """Barker's M at ``Q`` (N, 6): (N, 3, 3) [m]."""
        Q, _ = self._check_batch(Q)
        t = K.trig(Q)
        return K.m_matrix(t, K.f_terms(self.geometry, t))

    def det_m(self, q: npt.ArrayLike) -> float:
        """Determinant of M [m^3] in the factored form of eq. (D9)."""
        return float(self.det_m_batch(as_vector(q, "q", 6)[None])[0])

    def det_m_batch(self, Q: npt.ArrayLike) -> Array:
        """Determinant of M (eq. (D9)) at ``Q`` (N, 6): (N,) [m^3]."""
        Q, _ = self._check_batch(Q)
        t = K.trig(Q)
        return K.det_m(self.geometry, t, K.f_terms(self.geometry, t))

    def singularity(self, q: npt.ArrayLike) -> BarkerSingularity:
        """Values of conditions (32), (33) and S5 at ``q`` (6,), as Python scalars."""
        s = self.singularity_batch(as_vector(q, "q", 6)[None])
        return BarkerSingularity(
            *(float(v[0]) for v in s[:4]), bool(s.arm_singular[0]), bool(s.wrist_singular[0])
        )

    def singularity_batch(self, Q: npt.ArrayLike) -> BarkerSingularity:
        """Values of conditions (32), (33) and S5 at ``Q`` (N, 6), each (N,)."""
        Q, _ = self._check_batch(Q)
        g, t = self.geometry, K.trig(Q)
        F = K.f_terms(g, t)
        det = K.det_m(g, t, F)
        fro2 = 2.0 * F.f1**2 + g.f2**2 + F.f3**2 + F.f4**2 + F.f5**2
        return BarkerSingularity(
            eq32=F.f1,
            eq33=K.eq33(g, t),
            s5=t.s5,
            det_m=det,
            arm_singular=np.abs(det) <= self.rcond * fro2 * np.sqrt(fro2),
            wrist_singular=np.abs(t.s5) <= self.rcond * (1.0 + np.abs(t.c5)),
        )

    # -- joint rates ------------------------------------------------------------------------

    def arm_rates(self, q: npt.ArrayLike, tvel: npt.ArrayLike, method: Method = "full") -> Array:
        """thetadot_1..3 (3,) [rad/s] realising the wrist-centre velocity ``tvel`` (3,) [m/s].

        ``method="full"``: eqs (34)-(36), M* (eq. (38)) where singular; ``"reduced"``:
        eqs (39), (44) with M1*. ``tvel`` is TVEL^ in base axes.

        Raises:
            InputError: Bad ``q``, ``tvel`` or ``method``.
        """
        reduced = self._reduced(method)
        tr = trig_scalar(as_float_list(q, "q", 6))
        tv = as_float_list(tvel, "tvel", 3)
        return np.array(arm_scalar(self._k, tr, tv, reduced, self.rcond))

    def arm_rates_batch(
        self, Q: npt.ArrayLike, TVEL: npt.ArrayLike, method: Method = "full"
    ) -> Array:
        """Batch :meth:`arm_rates`: ``Q`` (N, 6), ``TVEL`` (N, 3) -> (N, 3) [rad/s]."""
        reduced = self._reduced(method)
        Q, _ = self._check_batch(Q)
        TVEL = as_array(TVEL, "TVEL", (Q.shape[0], 3))
        kernel = K.arm_rates_reduced if reduced else K.arm_rates_full
        return kernel(self.geometry, K.trig(Q), TVEL, self.rcond)[0]

    def rvel_tilde(self, q: npt.ArrayLike, arm_rates: npt.ArrayLike, rvel: npt.ArrayLike) -> Array:
        """RVEL~ = RVEL^ - z0 thetadot_1 - z1 thetadot_2 - z2 thetadot_3 (eq. (48)), (3,)."""
        tr = trig_scalar(as_float_list(q, "q", 6))
        arm = as_float_list(arm_rates, "arm_rates", 3)
        rvel_hat = as_float_list(rvel, "rvel", 3)
        return np.array(rvel_tilde_scalar(tr, (arm[0], arm[1], arm[2]), rvel_hat))

    def wrist_rates(
        self, q: npt.ArrayLike, rvel_tilde: npt.ArrayLike, method: Method = "full"
    ) -> Array:
        """thetadot_4..6 (3,) [rad/s] from RVEL~ (eq. (48)) (3,) [rad/s], base axes.

        ``method="full"``: eqs (49)-(51), M2* (eq. (60)) where S5 is negligible;
        ``"reduced"``: eqs (49), (60). Both equal ``pinv(W, rcond) @ rvel_tilde``.

        Raises:
            InputError: Bad ``q``, ``rvel_tilde`` or ``method``.
        """
        reduced = self._reduced(method)
        tr = trig_scalar(as_float_list(q, "q", 6))
        rt = as_float_list(rvel_tilde, "rvel_tilde", 3)
        return np.array(wrist_scalar(self._k, tr, (rt[0], rt[1], rt[2]), reduced, self.rcond))

    def wrist_rates_batch(
        self, Q: npt.ArrayLike, RVEL_TILDE: npt.ArrayLike, method: Method = "full"
    ) -> Array:
        """Batch :meth:`wrist_rates`: ``Q`` (N, 6), ``RVEL_TILDE`` (N, 3) -> (N, 3) [rad/s]."""
        reduced = self._reduced(method)
        Q, _ = self._check_batch(Q)
        rt = as_array(RVEL_TILDE, "RVEL_TILDE", (Q.shape[0], 3))
        return K.wrist_rates(self.geometry, K.trig(Q), rt, self.rcond, reduced)[0]

    def joint_rates(self, q: npt.ArrayLike, xdot: npt.ArrayLike, method: Method = "full") -> Array:
        """Joint rates (6,) [rad/s] realising the twist ``xdot = [TVEL^; RVEL^]`` (6,) at ``q``.

        Args:
            q: Joint positions (6,) [rad], Barker's theta_i.
            xdot: Wrist-centre velocity [m/s] and angular velocity [rad/s], base axes
                (``world_aligned``).
            method: ``"full"`` (eqs (34)-(36), (49)-(51), generalized inverses where singular)
                or ``"reduced"`` (eqs (39), (44), (49), (60)); see the module docstring.

        Returns:
            thetadot (6,): exact where J is regular; finite at singularities, never NaN.

        Raises:
            InputError: Bad ``q``, ``xdot`` or ``method``.
        """
        reduced = self._reduced(method)
        qv, x = as_float_list(q, "q", 6), as_float_list(xdot, "xdot", 6)
        if reduced:
            return np.array(joint_rates_scalar(self._k, qv, x, True, self.rcond))
        return np.array(joint_rates_full_scalar(self._k, qv, x, self.rcond))

    def joint_rates_batch(
        self, Q: npt.ArrayLike, X: npt.ArrayLike, method: Method = "full"
    ) -> Array:
        """Batch :meth:`joint_rates`: ``Q`` (N, 6), ``X`` (N, 6) -> (N, 6) [rad/s].

        ``method="full"`` runs blocked and in place
        (:func:`~solvers.closed_form.barker_batch.joint_rates_full`); the configurations it
        flags as possibly singular are recomputed by the general kernels, so that the result
        is the one of :meth:`joint_rates` everywhere.

        Raises:
            InputError: Bad ``Q``, ``X`` or ``method``.
        """
        reduced = self._reduced(method)
        Q = as_array(Q, "Q", (None, 6))
        X = as_array(X, "X", (Q.shape[0], 6))
        if reduced:
            return self._rates_composed(Q, X, reduced=True)
        out, suspect = joint_rates_full(self._k, Q, X, self.rcond)
        if suspect.size:  # possibly singular: generalized inverses where needed
            out[suspect] = self._rates_composed(Q[suspect], X[suspect], reduced=False)
        return out

    def _rates_composed(self, Q: Array, X: Array, reduced: bool) -> Array:
        """Joint rates (N, 6) by the arm kernel, eq. (48), then the wrist kernel."""
        g, t = self.geometry, K.trig(Q)
        kernel = K.arm_rates_reduced if reduced else K.arm_rates_full
        arm = kernel(g, t, X[:, :3], self.rcond)[0]
        wrist = K.wrist_rates(g, t, K.rvel_tilde(t, arm, X[:, 3:]), self.rcond, reduced)[0]
        return np.concatenate([arm, wrist], axis=1)

    # -- hand frame (Appendix B) ------------------------------------------------------------

    def hand_to_base(self, q: npt.ArrayLike) -> Array:
        """R0_6 (3, 3) by eqs (B2)-(B24): hand (frame 6) axes in base axes."""
        return self.hand_to_base_batch(as_vector(q, "q", 6)[None])[0]

    def hand_to_base_batch(self, Q: npt.ArrayLike) -> Array:
        """R0_6 at ``Q`` (N, 6): (N, 3, 3)."""
        Q, _ = self._check_batch(Q)
        return K.hand_to_base(self.geometry, K.trig(Q, roll=True))

    def hand_twist_to_base(self, q: npt.ArrayLike, twist: npt.ArrayLike) -> Array:
        """Operator command ``[TVEL; RVEL]`` (6,) in hand axes -> base axes, eq. (20)."""
        twist = as_vector(twist, "twist", 6)
        R = self.hand_to_base(q)
        return np.concatenate([R @ twist[:3], R @ twist[3:]])

    def tvel_frame2(self, q: npt.ArrayLike, tvel: npt.ArrayLike) -> Array:
        """TVEL^ (3,) [m/s] resolved along X2, Y2, Z2 (eqs (B27)-(B29) corrected), (3,)."""
        q = as_vector(q, "q", 6)
        return self.tvel_frame2_batch(q[None], as_vector(tvel, "tvel", 3)[None])[0]

    def tvel_frame2_batch(self, Q: npt.ArrayLike, TVEL: npt.ArrayLike) -> Array:
        """Batch :meth:`tvel_frame2`: ``Q`` (N, 6), ``TVEL`` (N, 3) -> (N, 3) [m/s]."""
        Q, _ = self._check_batch(Q)
        TVEL = as_array(TVEL, "TVEL", (Q.shape[0], 3))
        return K.tvel_frame2(K.trig(Q), TVEL)

    def _reduced(self, method: str) -> bool:
        if method == "full":
            return False
        if method != "reduced":
            raise InputError("method", f"expected one of {', '.join(METHODS)}, got {method!r}")
        if not self._has_reduced:
            raise InputError(
                "method", "the reduced path divides by F2 = SN + R3 + cos(alpha3) WE = 0"
            )
        return True

