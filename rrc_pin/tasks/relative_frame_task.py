"""RelativeFrameTask: the twist of one frame relative to another, on one model."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.kinematics import Kinematics, Layout
from rrc_pin.solvers.checks import positive, rigid_transform
from rrc_pin.solvers.tick.problem import TaskRows
from rrc_pin.tasks.frame_task import FrameTask
from rrc_pin.tasks.relative_frame_kernels import relative_rows
from rrc_pin.tasks.task import Task

Array = npt.NDArray[np.float64]


class RelativeFrameTask(Task):
    r"""The motion of frame ``frame_b`` as seen from frame ``frame_a``, in ``frame_a``'s axes.

    With :math:`T_a, T_b` the two poses in the base frame and :math:`p_{ab} = R_a^T(p_b - p_a)`,
    the task's twist is :math:`[\dot p_{ab};\ R_a^T(\omega_b - \omega_a)]`, so its rows are

    .. math::

        J_{ab} = \begin{bmatrix} R_a^T (J_b^v - J_a^v + [p_b - p_a]_\times J_a^\omega) \\
                 R_a^T (J_b^\omega - J_a^\omega) \end{bmatrix}

    (Jacobians ``world_aligned``). A zero twist keeps :math:`T_a^{-1}T_b` constant to first
    order: two hands holding one object keep their grip while the pair moves, up to the
    integration's error. With a ``target`` pose :math:`T^*` of b in a, the commanded
    relative twist gets the feedback :math:`k\,[p^* - p_{ab};\ \log(R^* R_{ab}^T)]` (in a's
    axes), which removes that drift.

    Args:
        frame_a: The reference frame (e.g. the left hand).
        frame_b: The moving frame (e.g. the right hand).
        twist: Relative twist (6,) [m/s, rad/s] or the selected rows; default zero.
        rows: Row selection as in :class:`FrameTask`.
        weight: Cost > 0, scalar or per selected row.
        target: Pose (4, 4) of frame b in frame a to hold (e.g. the grasp), or None.
        gain: k > 0 [1/s], the fraction of the pose error corrected per second.
        name: Name in the report (default ``"frame_b/frame_a"``).

    Raises:
        InvalidInput: Bad twist, rows, weight, target or gain.
    """

    def __init__(
        self,
        frame_a: str,
        frame_b: str,
        twist: npt.ArrayLike | None = None,
        *,
        rows: str | Sequence[int] | Sequence[bool] = "full",
        weight: float | npt.ArrayLike = 1.0,
        target: npt.ArrayLike | None = None,
        gain: float = 10.0,
        name: str | None = None,
    ) -> None:
        for label, frame in (("frame_a", frame_a), ("frame_b", frame_b)):
            if not isinstance(frame, str):
                raise InvalidInput(label, f"expected a frame name, got {frame!r}")
        # b's twist, rows and weights, checked and selected as a FrameTask's
        self._spec = FrameTask(
            frame_b, twist, rows=rows, weight=weight,
            name=f"{frame_b}/{frame_a}" if name is None else name,
        )  # fmt: skip
        self.frame_a, self.frame_b = frame_a, frame_b
        self.target = None if target is None else rigid_transform(target, "target")
        self.gain = positive(gain, "gain")
        self.name = self._spec.name

    @property
    def twist(self) -> Array:
        """The commanded relative twist (its selected rows)."""
        return self._spec.twist

    @property
    def weight(self) -> float | Array:  # type: ignore[override]
        """Cost of the squared residual, scalar or per selected row."""
        return self._spec.weight

    @property
    def selected(self) -> tuple[int, ...]:
        """The selected rows of the relative twist."""
        return self._spec.selected

    def set_twist(self, twist: npt.ArrayLike) -> None:
        """Command a new relative twist (checked): keep a task across ticks.

        Raises:
            InvalidInput: Wrong shape or a non-finite entry; the task is then unchanged.
        """
        self._spec.set_twist(twist)

    def set_target(self, target: npt.ArrayLike | None) -> None:
        """Hold frame b at pose ``target`` (4, 4) in frame a [m], or None for none.

        Raises:
            InvalidInput: Not a rigid transform; the task is then unchanged.
        """
        self.target = None if target is None else rigid_transform(target, "target")

    def frames(self) -> tuple[str, ...]:
        """Both frames."""
        return (self.frame_a, self.frame_b)

    def rows(self, kin: Kinematics) -> TaskRows:
        """The relative Jacobian rows (class docstring) and the commanded relative twist.

        One compiled call (:func:`~rrc_pin.tasks.relative_frame_kernels.relative_rows`).
        """
        a, b = self.frame_a, self.frame_b
        Ja, Jb = kin.jacobian(a), kin.jacobian(b)
        oMf, index = kin.data.oMf, kin.layout.frames  # both placed by the Jacobians' pass
        J = np.empty_like(Ja)
        target = _NO_TARGET if self.target is None else self.target
        error = np.empty(6)
        relative_rows(Ja, Jb, oMf[index[a]].homogeneous, oMf[index[b]].homogeneous, target, J,
                      error)  # fmt: skip
        if self.target is None:
            rates = self.twist.copy()
        else:
            rates = self.twist + self.gain * (error if len(self.selected) == 6
                                              else error[list(self.selected)])  # fmt: skip
        return self._spec.rows_from(J, rates, self.reach(kin.layout))

    def reach(self, layout: Layout) -> float:
        """The pair's reach [m], the unit of its position rows: the longer chain's."""
        return max(layout.reach[self.frame_a], layout.reach[self.frame_b])


_NO_TARGET = np.zeros((0, 4))
"""The kernel's target argument of a task without one."""
