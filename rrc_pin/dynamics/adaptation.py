r"""Seraji's decentralised adaptive PD law: one axis at a time, no dynamic model.

H. Seraji, "Decentralized adaptive control of manipulators: theory, simulation, and
experimentation", IEEE Trans. Robotics and Automation 5(2):183-201, 1989 (the law the Nguyen &
Zhou report cites for its Figs 11-13). For every axis, from the error ``e`` and its rate
``edot``, with the weighted error ``r = w_p e + w_v edot``:

.. math::
    f(t) &= f(0) + \delta_1 \int_0^t r\,dt + \delta_2 r \\
    k_p(t) &= k_p(0) + \alpha_1 \int_0^t r e\,dt + \alpha_2 r e \\
    k_v(t) &= k_v(0) + \beta_1 \int_0^t r \dot e\,dt + \beta_2 r \dot e \\
    u &= f(t) + k_p(t)\, e + k_v(t)\, \dot e

The auxiliary signal ``f`` absorbs gravity, payload and coupling; the gains grow while the
error persists. Seraji derives the law from a Lyapunov function of the model-reference error
(integral terms; the proportional ones speed up the transient). The feedforward terms of his
full law (adapted multiples of the desired position, velocity and acceleration) are left out,
as in Nguyen & Zhou's Fig. 11, which adapts the PD gains and the auxiliary signal only. One
safeguard is added and documented: the integrals are clipped so that ``0 <= k_p <= k_p,max``,
``0 <= k_v <= k_v,max`` and ``|f| <= f_max`` (a projection: the adapted values stay in the
box, the integrals do not wind up beyond it). Integrals are rectangle sums at the control
period.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rrc_pin.dynamics.controller import Array, gains
from rrc_pin.errors import InvalidInput


@dataclass(frozen=True)
class SerajiGains:
    """Gains of :class:`SerajiLaw`, per axis; scalars broadcast.

    Attributes:
        kp0: Initial stiffness, > 0.
        kv0: Initial damping, > 0.
        wp: Weight of ``e`` in ``r``, > 0.
        wv: Weight of ``edot`` in ``r``, >= 0.
        alpha: ``(alpha_1, alpha_2)``, each >= 0: stiffness adaptation (integral, proportional).
        beta: ``(beta_1, beta_2)``, each >= 0: damping adaptation.
        delta: ``(delta_1, delta_2)``, each >= 0: auxiliary-signal adaptation.
        kp_max: Stiffness bound, > 0.
        kv_max: Damping bound, > 0.
        f_max: Auxiliary-signal bound, > 0.
    """

    kp0: npt.ArrayLike
    kv0: npt.ArrayLike
    wp: npt.ArrayLike = 1.0
    wv: npt.ArrayLike = 0.0
    alpha: tuple[npt.ArrayLike, npt.ArrayLike] = (0.0, 0.0)
    beta: tuple[npt.ArrayLike, npt.ArrayLike] = (0.0, 0.0)
    delta: tuple[npt.ArrayLike, npt.ArrayLike] = (0.0, 0.0)
    kp_max: npt.ArrayLike = np.inf
    kv_max: npt.ArrayLike = np.inf
    f_max: npt.ArrayLike = np.inf


class SerajiLaw:
    """The adapted PD law on ``size`` axes (state: three clipped integrals per axis).

    Args:
        g: Its gains.
        size: Number of axes.
        dt: Integration period [s], > 0.
        f0: Initial auxiliary signal (size,) (default 0).

    Raises:
        InvalidInput: A bad gain, named by its field (``kp0``, ``alpha``...).
    """

    def __init__(self, g: SerajiGains, size: int, dt: float, f0: npt.ArrayLike = 0.0) -> None:
        self.kp0 = gains(g.kp0, "kp0", size)
        self.kv0 = gains(g.kv0, "kv0", size)
        self.wp = gains(g.wp, "wp", size)
        self.wv = gains(g.wv, "wv", size, sign="nonnegative")
        self.alpha = _pair(g.alpha, "alpha", size)
        self.beta = _pair(g.beta, "beta", size)
        self.delta = _pair(g.delta, "delta", size)
        self.kp_max = gains(g.kp_max, "kp_max", size, infinite=True)
        self.kv_max = gains(g.kv_max, "kv_max", size, infinite=True)
        self.f_max = gains(g.f_max, "f_max", size, infinite=True)
        self.f0 = np.clip(gains(f0, "f0", size, sign="any"), -self.f_max, self.f_max)
        self.dt = dt
        self.reset()

    def reset(self) -> None:
        """Back to the initial gains and auxiliary signal."""
        n = self.kp0.size
        zero: Array = np.zeros(n)
        self.int_f, self.int_kp, self.int_kv = zero, zero.copy(), zero.copy()
        self.f, self.kp, self.kv = self.f0.copy(), self.kp0.copy(), self.kv0.copy()

    def update(self, e: Array, edot: Array) -> Array:
        """One period: adapt on ``(e, edot)`` and return ``u = f + kp e + kv edot``."""
        r = self.wp * e + self.wv * edot
        self.int_f = np.clip(
            self.int_f + self.delta[0] * r * self.dt, -self.f_max - self.f0, self.f_max - self.f0
        )
        self.int_kp = np.clip(
            self.int_kp + self.alpha[0] * r * e * self.dt, -self.kp0, self.kp_max - self.kp0
        )
        self.int_kv = np.clip(
            self.int_kv + self.beta[0] * r * edot * self.dt, -self.kv0, self.kv_max - self.kv0
        )
        self.f = np.clip(self.f0 + self.int_f + self.delta[1] * r, -self.f_max, self.f_max)
        self.kp = np.clip(self.kp0 + self.int_kp + self.alpha[1] * r * e, 0.0, self.kp_max)
        self.kv = np.clip(self.kv0 + self.int_kv + self.beta[1] * r * edot, 0.0, self.kv_max)
        u: Array = self.f + self.kp * e + self.kv * edot
        return u


def _pair(pair: tuple[npt.ArrayLike, npt.ArrayLike], name: str, size: int) -> tuple[Array, Array]:
    """(integral, proportional) adaptation rates, each (size,) and >= 0."""
    if not isinstance(pair, tuple) or len(pair) != 2:
        raise InvalidInput(name, f"expected a pair (integral, proportional), got {pair!r}")
    return (
        gains(pair[0], name, size, sign="nonnegative"),
        gains(pair[1], name, size, sign="nonnegative"),
    )
