r"""Closing a cell's closed chains inside the tick's limits: the correction and its bound.

A grip (two hands on one object) and a foot in support close a kinematic chain. The
resolver keeps their rows, :math:`C\dot q = 0`, at every answer: the chains stay closed to
first order. What opens them is the integration, :math:`q_{k+1} = q_k \oplus u\,\Delta t`.
With :math:`e(q)` a chain's pose error to its goal (the grip, the foot's anchor:
:class:`~rrc_pin.limits.contact_limit.Closure`) and :math:`s(u) = D^2p[u, u]` its second
derivative along the step (the frames' classical accelerations at :math:`\ddot q = 0`,
:func:`~rrc_pin.cells.closure_kernels.second_order`),

.. math::

    e_{k+1} = e_k - C u\,\Delta t - \tfrac12 \Delta t^2\, s(u)
              - \tfrac16 \Delta t^3\, D^3p[u, u, u] + O(\Delta t^4).

Left alone (:math:`u = \dot q`, :math:`C\dot q = 0`) every tick adds its second-order
remainder, and the chain drifts (gsfc_dual's grip 1e-5 m a tick at the commanded speeds).
The correction :math:`\delta` (:func:`close`) takes the measured error and the second order
out within the same step, :math:`C\delta = e_k/\Delta t - \tfrac12 \Delta t\, s(\dot q +
\delta)` (two passes: the second order along the corrected step), inside the tick's limits:

.. math::

    lb - \dot q \le \delta \le ub - \dot q,\qquad |\delta_i| \le \rho_i,\qquad
    G\delta \le \max(h - G\dot q, 0),

the box the resolver's rates leave (its velocity and one-step position bounds, exact in
floating point), the trust region :math:`\rho_i` = :data:`TRUST` times each joint's velocity
limit, and the constraint rows (a collision limit's). It is solved as a damped least squares,
in the resolver's metric (a chain's position rows divided by its reach): the chains' rates
first, then, in their null space, the top level's task rates kept (:math:`A\delta = 0`: the
commanded motion unchanged), each a damped least squares pulled toward itself (damping
:data:`DAMPING` of its rows' mean squared singular value,
:func:`~rrc_pin.cells.closure_kernels.damped`: exact to second order where the rows are well
conditioned, bounded near a singular chain); where that leaves the box, the point of the box
nearest it in the chains' metric, then the top level's (weight
:data:`KEEP`; :func:`~rrc_pin.solvers.tick.slide_kernels.project`). Zero is always feasible:
the correction never moves a joint beyond its limits.

The bound. What is left after a corrected tick is the third-order remainder. Each derivative
of a point on a chain of revolute joints is a cross product with a unit axis, so with
:math:`\ell` the chain's length (both arms' for a grip)

.. math::

    \|e_{k+1}\| \le \tfrac16 \Big(\Delta t \sum_i |u_i|\Big)^3 \ell

(and without :math:`\ell` for the rotation): 2.7 mm with every joint of gsfc_dual at its
velocity limit at 100 Hz, some 3e-5 m at its commanded speeds; measured at most 5e-6 m and
6e-6 rad (docs/api.md, "Cells"), eight times less per halving of the period.
:class:`ClosureBound` is what a cell states and enforces, 2e-5 m and 2e-5 rad: a tick that
starts with a chain open beyond it stops the cell (``grip_lost`` / ``contact_lost``), never a
jump and never a silent drift.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.cells import closure_kernels
from rrc_pin.cells.closure_kernels import DAMPING, KEEP, PASSES, TRUST, largest
from rrc_pin.kinematics import Kinematics
from rrc_pin.limits.contact_limit import Closure
from rrc_pin.limits.frame_columns import frame_poses
from rrc_pin.solvers.checks import finite_number
from rrc_pin.solvers.tick.problem import Box, Rows

Array = npt.NDArray[np.float64]

__all__ = ["DAMPING", "KEEP", "PASSES", "TRUST", "ChainFrames", "ClosureBound", "close",
           "compile_correction", "correct", "largest"]


@dataclass(frozen=True)
class ClosureBound:
    """How far a closed chain may be open at the start of a tick (module docstring).

    Attributes:
        position: [m] > 0, each chain's position error.
        rotation: [rad] > 0, each chain's rotation error.

    Raises:
        InvalidInput: A field that is not a finite number > 0, named.
    """

    position: float = 2e-5
    rotation: float = 2e-5

    def __post_init__(self) -> None:
        for name in ("position", "rotation"):
            finite_number(getattr(self, name), name, 0.0, inclusive=False)

    def level(self, error: Array) -> float:
        """The largest error of chains ``error`` (6 k,) relative to the bound (<= 1: held)."""
        position, rotation = largest(error)
        return max(position / self.position, rotation / self.rotation)


class ChainFrames(NamedTuple):
    """The frames a cell's closed chains close, as the compiled correction reads them.

    Made once per set of chains (:meth:`of`), read at every tick.

    Attributes:
        frames: Pinocchio frame indices of the chains' frames (each once).
        support: (k, nv) True where a joint rate moves frame i (the joints of its chain).
        joint: (nv,) the joint each rate belongs to.
        contacts: The contacts' rows in ``frames`` (the rows' order: contacts first).
        grips: (g, 2) each grip's frames a and b, rows in ``frames``.
    """

    frames: tuple[int, ...]
    support: npt.NDArray[np.bool_]
    joint: npt.NDArray[np.int64]
    contacts: npt.NDArray[np.int64]
    grips: npt.NDArray[np.int64]

    @classmethod
    def of(cls, model: pin.Model, contacts: tuple[int, ...],
           grips: tuple[tuple[int, int], ...]) -> ChainFrames:  # fmt: skip
        """The chains of contact frames ``contacts`` and grip frame pairs ``grips``."""
        frames = tuple(dict.fromkeys([*contacts, *(f for pair in grips for f in pair)]))
        row = {f: i for i, f in enumerate(frames)}
        joint = np.zeros(model.nv, dtype=np.int64)
        for j in range(1, model.njoints):
            start = model.joints[j].idx_v
            joint[start : start + model.joints[j].nv] = j
        support = np.zeros((len(frames), model.nv), dtype=bool)
        for i, f in enumerate(frames):
            for j in model.supports[model.frames[f].parentJoint][1:]:
                support[i, joint == j] = True
        return cls(frames, support, joint, np.array([row[f] for f in contacts], dtype=np.int64),
                   np.array([[row[a], row[b]] for a, b in grips], dtype=np.int64).reshape(-1, 2))


def close(
    kin: Kinematics, frames: ChainFrames, closure: Closure, qdot: Array, top: Array, box: Box,
    rows: Rows | None, dt: float,
) -> tuple[Array, Array, Array]:  # fmt: skip
    r"""The correction that closes the chains within the step, and their error after it.

    The least squares of the module docstring, in the resolver's metric (each chain's position
    rows divided by its reach): the chains' rates first; among the corrections with those
    rates, the one that keeps the top level's rates; each damped (:data:`DAMPING`); where that
    leaves the box (the resolver's, less its rates, within the trust region) or breaks a row,
    the point of the box nearest it in the chains' metric, then the top level's
    (:func:`rrc_pin.solvers.tick.slide_kernels.project`). :data:`PASSES` passes, each with the
    second order along the step corrected by the last (its cross terms with the correction,
    :math:`\Delta t^2 |\dot q| |\delta|`, were the largest error left after one: 2.1e-5 m and
    2.4e-5 rad against 4.1e-6 m and 5.0e-6 rad after two, gsfc_dual at 100 Hz, 3,000 ticks).
    One compiled call (:func:`~rrc_pin.cells.closure_kernels.correction`), the second order
    from the tick's world Jacobian (:func:`~rrc_pin.cells.closure_kernels.chain_motion`).

    Args:
        kin: The tick's kinematics (its world Jacobian and frame poses are read).
        frames: The chains' frames, contacts first, then grips.
        closure: The chains' rows, errors and units, measured at ``kin`` by the tick's limits.
        qdot: The resolver's rates (nv,), inside ``box`` and ``rows``.
        top: The top level's task rows (m, nv) in their metric, kept where the box allows.
        box: The tick's joint-rate bounds.
        rows: The tick's constraint rows ``G qdot <= h``, or None.
        dt: The step [s].

    Returns:
        The correction (nv,), zero where the projection finds none (``qdot + delta`` inside
        the box); the chains' error after the step (6 k,), predicted to second order; the
        rates applied, ``qdot + delta`` clipped into the box (against its rounding).
    """
    n = qdot.size
    data = kin.data
    poses = frame_poses(data, frames.frames)
    G, h = (np.zeros((0, n)), np.zeros(0)) if rows is None else (rows.G, rows.h)
    return correct(data.J, frames, poses, closure, top, qdot,
                   np.array([box.lb, box.ub, box.velocity]), G, h, dt)  # fmt: skip


def correct(
    J: Array, frames: ChainFrames, poses: Array, closure: Closure, top: Array, qdot: Array,
    box: Array, G: Array, h: Array, dt: float,
) -> tuple[Array, Array, Array]:  # fmt: skip
    """:func:`close` from the tick's arrays: the correction, the chains' error after the step
    and the rates applied (:func:`~rrc_pin.cells.closure_kernels.correction`).

    Args:
        J: The tick's world Jacobian of every joint (6, nv) (``data.J``).
        frames: The chains' frames.
        poses: Their poses (k, 4, 4) in the world frame [m], in ``frames.frames``' order.
        closure: The chains' rows, errors and units.
        top: The top level's task rows (m, nv) in their metric.
        qdot: The resolver's rates (nv,).
        box: (3, nv) the tick's lower and upper bounds and velocity limits.
        G: The constraint rows (p, nv), ``G qdot <= h``.
        h: Their bounds (p,).
        dt: The step [s].
    """  # noqa: D205
    n = qdot.size
    delta, after, applied = np.empty(n), np.empty(closure.error.size), np.empty(n)
    closure_kernels.correction(
        J, frames.support, frames.joint, poses, frames.contacts, frames.grips,
        np.ascontiguousarray(closure.C), closure.error, closure.unit, np.ascontiguousarray(top),
        qdot, box, np.ascontiguousarray(G), np.array(h), dt, delta, after, applied,
    )  # fmt: skip
    return delta, after, applied


def compile_correction(nv: int) -> None:
    """Compile the correction's kernels now (or load them from the cache), for ``nv`` rates.

    With the arrays' types a tick passes (Pinocchio's world Jacobian in column order, the
    resolver's rates read-only), so that a controller's first tick does not compile it.
    """
    qdot = np.zeros(nv)
    qdot.flags.writeable = False
    empty, rows = np.zeros(0), np.zeros((0, nv))
    ints = np.zeros(0, dtype=np.int64)
    closure_kernels.correction(
        np.zeros((6, nv), order="F"), np.zeros((0, nv), dtype=bool), np.zeros(nv, dtype=np.int64),
        np.zeros((0, 4, 4)), ints, ints.reshape(0, 2), rows, empty, empty, rows, qdot,
        np.zeros((3, nv)), rows, empty, 0.01, np.empty(nv), np.empty(0), np.empty(nv),
    )  # fmt: skip
    largest(np.zeros(0))
