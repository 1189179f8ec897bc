r"""A cell's tick's rows in one compiled call, written into the resolver's workspace.

:func:`cell_rows` is what a :class:`~rrc_pin.cells.CellController` tick's tasks and chain limits
give the resolver, from the tick's joint Jacobians ``data.J`` and frame poses, written as the
resolver's :class:`~rrc_pin.solvers.tick.tick.Workspace` loads them (``load_levels``,
``load_equalities``), so that its tick (:func:`~rrc_pin.solvers.tick.tick.run_within`) runs on
them as loaded:

1. the top level's rows: each commanded frame's ``world_aligned`` Jacobian
   (:func:`~rrc_pin.limits.chain_kernels.frame_jacobian`) and its twist plus the gain times its
   pose error to its target (:func:`~rrc_pin.solvers.exp_log.pose_error`), a
   :class:`~rrc_pin.tasks.FrameTask`'s rows; below them the posture's, identity rows and the
   gain times ``q_ref - q`` (:class:`~rrc_pin.tasks.PostureTask`'s);
2. the closed chains' rows and errors, the contacts' then the grips'
   (:func:`~rrc_pin.limits.chain_kernels.contact_rows`,
   :func:`~rrc_pin.limits.chain_kernels.grip_rows`): the equality rows ``C qdot = 0``.

The same kernels as the tasks' and limits' own, on the same floats: the rows are the same bits.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.limits.chain_kernels import contact_rows, frame_jacobian, grip_rows
from rrc_pin.solvers.compiled import kernel
from rrc_pin.solvers.exp_log import pose_error
from rrc_pin.solvers.tick.tick import (
    CONSTRAINTS,
    LEVELS,
    POSITION,
    RATE,
    ROWS,
    STARTS,
    UNIT,
    UNITS,
    WEIGHT,
    WEIGHTED,
)

Array = npt.NDArray[np.float64]
Ints = npt.NDArray[np.int64]

# Entries of ``plan``: the counts, then each frame's row of ``poses`` (:func:`cell_rows`)
TASKS, CONTACTS, GRIPS, FRAMES = range(4)
# Entries of ``values``: the gains, then the rows' constants
GAIN, POSTURE_GAIN, CONSTANTS = range(3)


@kernel
def cell_rows(
    Jw: Array, poses: Array, steps: Ints, starts: Ints, plan: Ints, values: Array,
    twists: Array, targets: Array, anchors: Array, grips: Array, joints: Array,
    task_rows: Array, rates: Array, ints: Ints, E: Array, C: Array, error: Array,
) -> None:  # fmt: skip
    """One cell tick's rows (module docstring) into the workspace, the chains' into ``C``.

    Args:
        Jw: The joint Jacobians (6, nv_ext) in the world frame (``data.J``).
        poses: The frames' poses (u, 4, 4) in the world frame [m] (``data.oMf``), each once.
        steps: The frames' steps (s, 3) (:class:`~rrc_pin.limits.frame_columns.FrameColumns`
            of the t commanded frames, the c contacts and each of the g grips' frames a and b).
        starts: (t + c + 2 g + 1,) each of those frames' first step.
        plan: The counts t, c, g; then the row of ``poses`` of each commanded frame, each
            contact and each grip's a and b (t + c + 2 g,).
        values: The frame tasks' gain [1/s], the posture's, then each top row's unit (6 t),
            the posture's row weights (nv,) and its ``q_ref`` (nv,).
        twists: The commanded frames' twists (t, 6) [m/s, rad/s], ``world_aligned``.
        targets: Their target poses (t, 4, 4) [m].
        anchors: The contacts' anchors (c, 4, 4) [m].
        grips: The grips (g, 4, 4), b's pose in a [m].
        joints: The workspace's joints (its positions read), task rows, rates and sizes, with
            room for 6 t + nv task rows, and ``E`` (6 (c + g), nv + 1): written.
        task_rows: See ``joints``.
        rates: See ``joints``.
        ints: See ``joints``.
        E: See ``joints``.
        C: Out (6 (c + g), nv), zero on entry: the chains' rows.
        error: Out (6 (c + g),): their errors [m, rad].
    """
    t, c, g, n = plan[TASKS], plan[CONTACTS], plan[GRIPS], joints.shape[1]
    m_top, m, f = 6 * t, 6 * t + n, t + c + 2 * g
    placed = np.empty((f, 4, 4))  # each frame's pose: the tasks', the contacts', the grips'
    for i in range(f):
        placed[i] = poses[plan[FRAMES + i]]
    q = joints[POSITION]
    unit, weight = values[CONSTANTS : CONSTANTS + m_top], values[CONSTANTS + m_top :][:n]
    q_ref = values[CONSTANTS + m_top + n :]
    frame, e = np.zeros((6, n)), np.empty(6)
    for i in range(t):
        frame[:] = 0.0
        frame_jacobian(Jw, steps, starts[i], starts[i + 1], placed[i, :3, 3], frame)
        pose_error(targets[i], placed[i], e)
        for r in range(6):
            task_rows[6 * i + r] = frame[r]
            rates[RATE, 6 * i + r] = twists[i, r] + values[GAIN] * e[r]
            rates[WEIGHT, 6 * i + r] = 1.0
            rates[UNIT, 6 * i + r] = unit[6 * i + r]
    for r in range(n):
        task_rows[m_top + r] = 0.0
        task_rows[m_top + r, r] = 1.0
        rates[RATE, m_top + r] = (q_ref[r] - q[r]) * values[POSTURE_GAIN]
        rates[WEIGHT, m_top + r] = weight[r]
        rates[UNIT, m_top + r] = 1.0
    ints[LEVELS], ints[ROWS], ints[WEIGHTED], ints[UNITS], ints[CONSTRAINTS] = 2, m, 0, 1, 0
    ints[STARTS], ints[STARTS + 1], ints[STARTS + 2] = 0, m_top, m
    contact_rows(Jw, steps, starts[t : t + c + 1], placed[t : t + c], anchors, C[: 6 * c],
                 error[: 6 * c])  # fmt: skip
    grip_rows(Jw, steps, starts[t + c : f + 1], placed[t + c : f], grips, C[6 * c :],
              error[6 * c :])  # fmt: skip
    E[:, :n] = C
    E[:, n] = 0.0
