r"""The rows and pose error of a :class:`~rrc_pin.tasks.RelativeFrameTask`, compiled.

One call per task and tick (:func:`relative_rows`): frame b's motion seen from frame a, in
a's axes (the task's class docstring),

.. math::

    J_{ab} = \begin{bmatrix} R_a^T (J_b^v - J_a^v + [p_b - p_a]_\times J_a^\omega) \\
             R_a^T (J_b^\omega - J_a^\omega) \end{bmatrix},\qquad
    e = \begin{bmatrix} p^* - R_a^T (p_b - p_a) \\ \log(R^* (R_a^T R_b)^T) \end{bmatrix},

the pose error :func:`rrc_pin.solvers.exp_log.pose_error` (Pinocchio's logarithm).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import kernel
from rrc_pin.solvers.exp_log import pose_error

Array = npt.NDArray[np.float64]


@kernel
def relative_rows(Ja: Array, Jb: Array, Ta: Array, Tb: Array, target: Array, J: Array,
                  error: Array) -> None:  # fmt: skip
    """Frame b's rows relative to frame a into ``J`` (6, nv), its pose error into ``error`` (6,).

    Args:
        Ja: Frame a's ``world_aligned`` Jacobian (6, nv), rows [v; w].
        Jb: Frame b's, the same.
        Ta: Frame a's pose (4, 4) in the base frame [m].
        Tb: Frame b's.
        target: b's pose (4, 4) in a to hold [m], or (0, 4): no error (``error`` untouched).
        J: Out (6, nv): the relative rows (module docstring).
        error: Out (6,): ``[p* - p_ab; log(R* R_ab^T)]`` [m, rad] in a's axes.
    """
    nv = Ja.shape[1]
    d = Tb[:3, 3] - Ta[:3, 3]
    for c in range(nv):
        wa0, wa1, wa2 = Ja[3, c], Ja[4, c], Ja[5, c]
        v0 = Jb[0, c] - Ja[0, c] + (d[1] * wa2 - d[2] * wa1)  # + [d]x wa
        v1 = Jb[1, c] - Ja[1, c] + (d[2] * wa0 - d[0] * wa2)
        v2 = Jb[2, c] - Ja[2, c] + (d[0] * wa1 - d[1] * wa0)
        w0, w1, w2 = Jb[3, c] - wa0, Jb[4, c] - wa1, Jb[5, c] - wa2
        for i in range(3):  # R_a^T: a's columns
            J[i, c] = Ta[0, i] * v0 + Ta[1, i] * v1 + Ta[2, i] * v2
            J[3 + i, c] = Ta[0, i] * w0 + Ta[1, i] * w1 + Ta[2, i] * w2
    if target.shape[0] == 0:
        return
    Tab = np.zeros((4, 4))  # b's pose in a: R_a^T R_b, R_a^T (p_b - p_a)
    for i in range(3):
        Tab[i, 3] = Ta[0, i] * d[0] + Ta[1, i] * d[1] + Ta[2, i] * d[2]
        for j in range(3):
            Tab[i, j] = Ta[0, i] * Tb[0, j] + Ta[1, i] * Tb[1, j] + Ta[2, i] * Tb[2, j]
    pose_error(target, Tab, error)
