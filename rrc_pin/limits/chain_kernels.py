r"""The closed chains' equality rows of a tick, compiled: one call per limit.

Both read the tick's joint Jacobians ``data.J`` (6, nv_ext) and the chains' frame poses. A
frame's ``world_aligned`` Jacobian (:func:`frame_jacobian`) is Pinocchio's
``getFrameJacobian`` step by step (``details::translateJointJacobian``): each column of its
chain (:class:`~rrc_pin.limits.frame_columns.FrameColumns`) is that joint's world twist
:math:`[v; \omega]` carried to the frame's origin :math:`p`, :math:`[v - p\times\omega;\
\omega]`, a mimic joint's added into the column of the joint it follows.

- :func:`contact_rows`: each contact's Jacobian, and its pose error to its anchor
  (:func:`rrc_pin.solvers.exp_log.pose_error`), for :class:`~rrc_pin.limits.ContactLimit`;
- :func:`grip_rows`: each pair's rows relative to its first frame, and its grip's error
  (:func:`rrc_pin.tasks.relative_frame_kernels.relative_rows`, a
  :class:`~rrc_pin.tasks.RelativeFrameTask`'s), for :class:`~rrc_pin.limits.GripLimit`.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import inlined, kernel
from rrc_pin.solvers.exp_log import pose_error
from rrc_pin.tasks.relative_frame_kernels import relative_rows

Array = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]

NO_POSES = np.zeros((0, 4, 4))
"""The anchors or grips argument of chains without them (no error measured)."""
UNMEASURED = np.zeros(0)
"""The error argument where nothing is measured (never written)."""


@inlined
def frame_jacobian(Jw: Array, steps: Ints, start: int, end: int, p: Array, out: Array) -> None:
    """A frame's ``world_aligned`` Jacobian into ``out`` (6, nv), zero where it is written.

    Args:
        Jw: The joint Jacobians (6, nv_ext) in the world frame, rows [v; w] (``data.J``).
        steps: The frames' steps (s, 3) (:class:`~rrc_pin.limits.frame_columns.FrameColumns`).
        start: The frame's first step.
        end: One past its last.
        p: The frame's origin (3,) in the world frame [m].
        out: Out (6, nv), rows [v; w]: its chain's columns written, the others left (zero).
    """
    for s in range(start, end):
        src, dst = steps[s, 0], steps[s, 1]
        w0, w1, w2 = Jw[3, src], Jw[4, src], Jw[5, src]
        c0 = p[1] * w2 - p[2] * w1  # p x w
        c1 = p[2] * w0 - p[0] * w2
        c2 = p[0] * w1 - p[1] * w0
        if steps[s, 2]:  # a mimic joint's, into its leader's column
            out[0, dst] = (out[0, dst] + Jw[0, src]) - c0
            out[1, dst] = (out[1, dst] + Jw[1, src]) - c1
            out[2, dst] = (out[2, dst] + Jw[2, src]) - c2
            out[3, dst] += w0
            out[4, dst] += w1
            out[5, dst] += w2
        else:
            out[0, dst] = Jw[0, src] - c0
            out[1, dst] = Jw[1, src] - c1
            out[2, dst] = Jw[2, src] - c2
            out[3, dst], out[4, dst], out[5, dst] = w0, w1, w2


@kernel
def contact_rows(Jw: Array, steps: Ints, starts: Ints, poses: Array, anchors: Array, C: Array,
                 error: Array) -> None:  # fmt: skip
    """Each contact's Jacobian into ``C`` and its anchor's pose error into ``error``.

    Args:
        Jw: The joint Jacobians (6, nv_ext) in the world frame (``data.J``).
        steps: The contacts' steps (s, 3), ``starts`` (k + 1,) each contact's first.
        starts: See ``steps``.
        poses: The contacts' poses (k, 4, 4) in the world frame [m].
        anchors: Their anchors (k, 4, 4) [m], or (0, 4, 4): no error (``error`` untouched).
        C: Out (6 k, nv), zero on entry: contact i's ``world_aligned`` Jacobian in rows
            ``6 i : 6 i + 6``.
        error: Out (6 k,): ``[p* - p; log(R* R^T)]`` [m, rad] of each contact, world axes.
    """
    for i in range(poses.shape[0]):
        rows = C[6 * i : 6 * i + 6]
        frame_jacobian(Jw, steps, starts[i], starts[i + 1], poses[i, :3, 3], rows)
        if anchors.shape[0]:
            pose_error(anchors[i], poses[i], error[6 * i : 6 * i + 6])


@kernel
def grip_rows(Jw: Array, steps: Ints, starts: Ints, poses: Array, grips: Array, C: Array,
              error: Array) -> None:  # fmt: skip
    """Each pair's relative rows into ``C`` and its grip's error into ``error``.

    Args:
        Jw: The joint Jacobians (6, nv_ext) in the world frame (``data.J``).
        steps: The frames' steps (s, 3): pair i's frames a and b are frames ``2 i, 2 i + 1``.
        starts: (2 k + 1,) each frame's first step.
        poses: The frames' poses (2 k, 4, 4) in the world frame [m], a and b of each pair.
        grips: Each pair's grip (k, 4, 4), b's pose in a [m], or (0, 4, 4): no error
            (``error`` untouched).
        C: Out (6 k, nv): pair i's rows (b's twist relative to a, in a's axes) in rows
            ``6 i : 6 i + 6``.
        error: Out (6 k,): ``[p* - p_ab; log(R* R_ab^T)]`` [m, rad] of each pair, a's axes.
    """
    nv = C.shape[1]
    Ja, Jb = np.empty((6, nv)), np.empty((6, nv))
    none = np.zeros((0, 4))
    for i in range(C.shape[0] // 6):
        a, b = 2 * i, 2 * i + 1
        Ja[:], Jb[:] = 0.0, 0.0
        frame_jacobian(Jw, steps, starts[a], starts[a + 1], poses[a, :3, 3], Ja)
        frame_jacobian(Jw, steps, starts[b], starts[b + 1], poses[b, :3, 3], Jb)
        grip = grips[i] if grips.shape[0] else none
        relative_rows(Ja, Jb, poses[a], poses[b], grip, C[6 * i : 6 * i + 6],
                      error[6 * i : 6 * i + 6])  # fmt: skip
