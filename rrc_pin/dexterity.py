r"""How well a frame can move: its Jacobian's singular values and their exact gradients.

The frame's world_aligned Jacobian (6, nv) is taken in the resolver's metric: its selected
rows, the linear ones divided by the frame's reach [m] (:func:`rrc_pin.kinematics.reach`),
so that a singular value is dimensionless (1 m/s at the reach compares with 1 rad/s) and
its columns restricted to the joints' rates (a floating base's six are left out: the body
itself is not a joint of the arm). Its singular values :math:`\sigma_1 \ge \dots \ge
\sigma_k` give Yoshikawa's measure (1985) and the smallest one:

.. math:: w = \sqrt{\det(J J^T)} = \prod_i \sigma_i, \qquad \sigma_{min} = \sigma_k .

Their gradients are exact, from the Jacobian's derivative (:func:`jacobian_derivative`) and
the singular vectors :math:`u_i, v_i` (a simple singular value's derivative, Magnus 1985):

.. math:: \frac{\partial \sigma_i}{\partial q_j} = u_i^T \frac{\partial J}{\partial q_j} v_i,
    \qquad \frac{\partial w}{\partial q_j} = \sum_i \Big(\prod_{l \ne i}\sigma_l\Big)
    \frac{\partial \sigma_i}{\partial q_j},

the second finite at a singularity (it is the derivative of a determinant, smooth where
singular values cross). Derivatives are along the joints' rates (the tangent space: a
floating base's twist in body axes), the resolver's unknowns.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.kinematics import Kinematics

Array = npt.NDArray[np.float64]


class Dexterity(NamedTuple):
    """A frame's singular values at one configuration, in the resolver's metric.

    Attributes:
        sigma: Singular values (k,), descending, dimensionless (module docstring).
        gradients: Their gradients (k, nv) [1/rad or 1/m] along the joint rates.
    """

    sigma: Array
    gradients: Array

    @property
    def manipulability(self) -> float:
        """Yoshikawa's measure, the product of the singular values (dimensionless)."""
        return float(np.prod(self.sigma))

    def manipulability_gradient(self) -> Array:
        """The measure's gradient (nv,) [1/rad or 1/m] (module docstring)."""
        k = self.sigma.size
        others = np.array([np.prod(np.delete(self.sigma, i)) for i in range(k)])
        out: Array = others @ self.gradients
        return out


def dexterity(
    kin: Kinematics, frame: str, selected: tuple[int, ...] = (0, 1, 2, 3, 4, 5)
) -> Dexterity:
    """The singular values of ``frame``'s Jacobian rows ``selected`` and their gradients.

    Args:
        kin: The tick's kinematics.
        frame: A frame of the robot.
        selected: Rows of the twist [v; w] (indices in 0..5).
    """
    J = kin.jacobian(frame, "world_aligned")
    dJ = jacobian_derivative(kin, frame, J)
    factor = metric(kin, frame, selected)
    columns = _columns(kin)
    Jm = factor[:, None] * J[list(selected)][:, columns]
    U, sigma, Vt = np.linalg.svd(Jm, full_matrices=False)
    dJm = factor[None, :, None] * dJ[:, list(selected)][:, :, columns]  # (nv, m, c)
    gradients = np.einsum("mi,jmc,ic->ij", U, dJm, Vt)
    return Dexterity(sigma, gradients)


def metric(kin: Kinematics, frame: str, selected: tuple[int, ...]) -> Array:
    """The rows' factors (m,) into the resolver's metric: 1 / reach for linear rows [1/m]."""
    reach = kin.layout.reach[frame]
    return np.array([1.0 / reach if r < 3 else 1.0 for r in selected])


def jacobian_derivative(kin: Kinematics, frame: str, J: Array | None = None) -> Array:
    r"""The derivative (nv, 6, nv) of ``frame``'s world_aligned Jacobian along each joint rate.

    ``out[j]`` is :math:`\partial J / \partial q_j`. From the spatial Jacobian's columns
    :math:`\xi_i = (v_i, \omega_i)` (Pinocchio's ``WORLD``): a joint moves every column after
    it on its chain, :math:`\partial \xi_i/\partial q_j = \xi_j \times \xi_i` (the motion
    cross product) where joint j is joint i's or an ancestor of it (Murray, Li & Sastry 1994,
    the product of exponentials; a multi-dof joint's rates in body axes, as Pinocchio's); the
    world_aligned column :math:`(v_i + \omega_i \times p,\ \omega_i)` at the frame's origin
    :math:`p` also moves with :math:`\partial p / \partial q_j`, the frame's linear velocity
    column j.

    Args:
        kin: The tick's kinematics.
        frame: A frame of the robot.
        J: The frame's world_aligned Jacobian (6, nv) if already computed.
    """
    if J is None:
        J = kin.jacobian(frame, "world_aligned")
    W = pin.getFrameJacobian(kin.model, kin.data, kin.layout.frames[frame], pin.WORLD)
    p = kin.pose(frame)[:3, 3]
    v, w = W[:3].T, W[3:].T  # (nv, 3): row i is column i
    moves = _moves(kin.model)  # moves[j, i]: rate j moves column i
    wj, vj = w[:, None, :], v[:, None, :]  # index j (the rate), then i (the column)
    wi, vi = w[None, :, :], v[None, :, :]
    dw = moves[..., None] * np.cross(wj, wi)
    dv = moves[..., None] * (np.cross(wj, vi) + np.cross(vj, wi))
    dp = J[:3].T  # (nv, 3): the frame origin's velocity per rate
    dlin = dv + np.cross(dw, p) + np.cross(wi, dp[:, None, :])
    out = np.empty((W.shape[1], 6, W.shape[1]))
    out[:, :3, :] = np.transpose(dlin, (0, 2, 1))
    out[:, 3:, :] = np.transpose(dw, (0, 2, 1))
    return out


def _moves(model: pin.Model) -> npt.NDArray[np.bool_]:
    """(nv, nv) mask: rate j's joint is rate i's joint or an ancestor of it.

    Every column outside the frame's chain is zero, and on one chain an ancestor has the
    smaller joint index (Pinocchio's depth-first order): comparing indices is enough.
    """
    joint = np.empty(model.nv, dtype=np.int64)
    for jid in range(1, model.njoints):
        start = model.joints[jid].idx_v
        joint[start : start + model.joints[jid].nv] = jid
    return joint[:, None] <= joint[None, :]


def _columns(kin: Kinematics) -> npt.NDArray[np.bool_] | slice:
    """The joints' columns: every one, or the actuated ones beside a floating base."""
    actuated = kin.layout.actuated
    return slice(None) if actuated is None else actuated
