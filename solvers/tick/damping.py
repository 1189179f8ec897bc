r"""Damping near singularities, and only there.

Near a singularity the exact rates of a command grow without bound, so the limits stop the
arm along a direction it can barely move. Damping trades the command's direction for speed;
it is therefore applied only where both hold:

1. the command cannot be met (the largest scale along it within the limits, the LP
   maximum :math:`u^*`, is below 1): a command the arm can follow is followed exactly,
   however close the singularity;
2. the level's rows are ill-conditioned: their condition number :math:`\sigma_1/\sigma_r`,
   in the level's metric (each row divided by its unit, the arm's reach for linear rows, so
   that metres and radians compare; and times the square root of its weight) exceeds
   :attr:`Damping.threshold` :math:`\kappa`. Below it a too-fast command is scaled along
   itself to :math:`u^*`, never damped.

A direction i whose singular value is below the onset :math:`\sigma_{on} = \sigma_1/\kappa`
gets the squared damping (Maciejewski & Klein 1988's smooth onset, with a floor for the
step)

.. math::

    \lambda_i^2 = \Big(1 - \big(\sigma_i/\sigma_{on}\big)^2\Big)\,
        \max\big(\sigma_{on}^2,\ \sigma_1 |u_i^T b|\,\Delta t\big)\,(1 - u^*),

zero at the threshold and for a command that can just be met (:math:`u^* = 1`), so the
answer is continuous in the configuration and in the command. The floor is for the step
:math:`\Delta t`: near a singularity :math:`\sigma_i` changes by about :math:`\sigma_1` per
radian along :math:`v_i`, so the singularity is :math:`\sigma_i/\sigma_1` away, and a step of
:math:`\Delta t\,\sigma_i |u_i^T b|/(\sigma_i^2 + \lambda_i^2)` along :math:`v_i` stays short
of it when :math:`\sigma_i^2 + \lambda_i^2 \ge \sigma_1 |u_i^T b| \Delta t`; a step that crosses
it is undone by the next (a stretched elbow pushed outward: the joints flipped between
opposite rate limits at most ticks). The damped rates
:math:`\sum_i \sigma_i/(\sigma_i^2 + \lambda_i^2)\,(u_i^T b)\,v_i` are then scaled along
themselves within the limits; the resolution reports the angle by which the motion veers
from the command.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.checks import as_array, finite_number, integer, positive
from rrc_pin.solvers.compiled import kernel
from rrc_pin.solvers.errors import InvalidInput

Array = npt.NDArray[np.float64]

MIN_THRESHOLD = 10.0
"""The smallest threshold accepted: rows this well conditioned are never damped."""


@dataclass(frozen=True)
class Damping:
    r"""Damping near singularities (module docstring).

    Attributes:
        threshold: :math:`\kappa` >= 10, the condition number of a level's normalised rows
            beyond which a command that cannot be met is damped. The default, 100, leaves
            every configuration of the catalogue arms that is further than about 2 deg from
            a singular one undamped (docs/api.md, "Damping").

    Raises:
        InvalidInput: ``threshold`` not a finite number >= 10.
    """

    threshold: float = 100.0

    def __post_init__(self) -> None:
        finite_number(self.threshold, "threshold", MIN_THRESHOLD)

    def lambda_sq(
        self, sigma: Array, rank: int, scale: float, along: Array, dt: float
    ) -> Array | None:
        """Squared damping per singular direction (k,), or None where none applies.

        The module docstring's schedule (:func:`damping_lambda_sq`).

        Args:
            sigma: Singular values (k,) of the level's normalised rows, descending.
            rank: How many of them count (the others are zero).
            scale: The LP maximum :math:`u^*` in [0, 1] of the exact command.
            along: :math:`|u_i^T b|` (k,), the command's size along each direction.
            dt: The step [s].

        Raises:
            InvalidInput: An argument of the wrong shape or type, non-finite or negative, a
                rank beyond ``sigma``'s size or a scale outside [0, 1], named (before the
                kernel reads them).
        """
        sigma, along = _singular(sigma, along)
        rank = integer(rank, "rank", 0, sigma.size)
        scale = finite_number(scale, "scale", 0.0, upper=math.nextafter(1.0, 2.0))
        dt = positive(dt, "dt")
        lam = np.empty(sigma.size)
        if not damping_lambda_sq(sigma, rank, scale, along, dt, float(self.threshold), lam):
            return None
        return np.minimum(lam, _HUGE, out=lam)  # finite where sigma_1 or the command overflow


_HUGE = float(np.finfo(np.float64).max)


def _singular(sigma: Array, along: Array) -> tuple[Array, Array]:
    """``sigma`` and ``along``: (k,) each, finite and >= 0.

    Raises:
        InvalidInput: Naming ``sigma, along`` where their sizes differ, else the one that is
            bad.
    """
    out = []
    for value, name in ((sigma, "sigma"), (along, "along")):
        arr = as_array(value, name, (None,))
        if (arr < 0.0).any():
            raise InvalidInput(name, f"expected values >= 0, got {arr}")
        out.append(arr)
    if out[0].size != out[1].size:
        raise InvalidInput("sigma, along", f"sizes differ: {out[0].size} and {out[1].size}")
    return out[0], out[1]


@kernel
def clamp_pushed(J: Array, w: Array, lb: Array, ub: Array, still: float, out: Array) -> bool:
    """J's columns of the joints that ``w`` pushes against a bound holding them still, zeroed.

    A joint is held where its bound on the side ``w`` moves it is within ``still`` of zero
    (Baerlocher & Boulic 2004's clamping).

    Args:
        J: The rows (m, n).
        w: The rates (n,).
        lb: Lower bounds (n,).
        ub: Upper bounds (n,).
        still: A bound within this of zero holds its joint.
        out: Out: J with those columns zeroed (m, n), set where True is returned.

    Returns:
        Whether any joint is held.
    """
    m, n = J.shape
    any_held = False
    for j in range(n):
        held = (w[j] > 0.0 and ub[j] <= still) or (w[j] < 0.0 and lb[j] >= -still)
        any_held = any_held or held
        for i in range(m):
            out[i, j] = 0.0 if held else J[i, j]
    return any_held


@kernel
def damping_lambda_sq(
    sigma: Array, rank: int, scale: float, along: Array, dt: float, threshold: float, lam: Array
) -> bool:
    r"""Squared damping per singular direction (the module docstring's schedule).

    With the onset :math:`\sigma_{on} = \sigma_1/\kappa`, every direction i < rank whose
    singular value is below it gets :math:`\lambda_i^2 = (1 - (\sigma_i/\sigma_{on})^2)\,
    \max(\sigma_{on}^2, \sigma_1 |u_i^T b|\,\Delta t)\,(1 - u^*)` (Maciejewski & Klein 1988's
    smooth onset, with a floor for the step), the others zero.

    Args:
        sigma: Singular values (k,), descending.
        rank: How many of them count.
        scale: The LP maximum :math:`u^*` in [0, 1].
        along: :math:`|u_i^T b|` (k,).
        dt: The step [s].
        threshold: :math:`\kappa`.
        lam: Out: the squared damping (k,), set where True is returned.

    Returns:
        False where none applies (no rank, :math:`u^* \ge 1`, or every counted singular value
        at or above the onset).
    """
    if rank == 0 or scale >= 1.0:
        return False
    onset = sigma[0] / threshold
    if sigma[rank - 1] >= onset:
        return False
    for i in range(sigma.size):
        lam[i] = 0.0
        if i < rank and sigma[i] < onset:
            floor = max(onset * onset, sigma[0] * along[i] * dt)
            ratio = sigma[i] / onset
            lam[i] = (1.0 - ratio * ratio) * floor * (1.0 - scale)
    return True
