"""CellResolution: a cell tick's resolution, with its closed chains' correction and its hands.

The resolver answers a cell's tick with the tasks it was given: a held object's frame task at
the top level, the grip as equality rows. What a cell adds to that answer:

- the **correction** the closed chains took inside the step (:mod:`rrc_pin.cells.closure`),
  added to the resolver's rates: the configuration moves by :attr:`CellResolution.applied`;
- each held object's **hands** as tasks of the top level in the report
  (:attr:`CellResolution.tasks`): each hand's commanded twist is the object's, carried to the
  hand's origin on the rigid grasp, and its scale is what the resolver's rates achieve of it
  (the same common scale for both hands, the object's).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.tick.problem import TaskRows
from rrc_pin.solvers.tick.resolution import Resolution, TaskReport

Array = npt.NDArray[np.float64]


class CellResolution(Resolution):
    """The resolver's answer to a cell's tick (its fields), and what the cell adds to it.

    Make one with :meth:`of_tick`. Its ``qdot`` is the resolver's (zero on a tick held still by a
    lost chain, status ``grip_lost`` / ``contact_lost``); the configuration moves by
    :attr:`applied`.

    Attributes:
        applied: The rates (nv,) [rad/s or m/s] the configuration moved by over the tick: the
            resolver's and the closed chains' correction, inside the tick's box (read-only).
    """

    applied: Array

    @classmethod
    def of_tick(
        cls, r: Resolution, applied: Array,
        hands: Callable[[], tuple[TaskRows, ...]] | None = None,
    ) -> CellResolution:  # fmt: skip
        """``r`` with the rates ``applied`` and the hands' rows.

        Args:
            r: The resolver's answer (or the tick held still).
            applied: The rates (nv,): ``r.qdot`` and the closed chains' correction, inside
                its box.
            hands: Makes the held objects' hands' rows when :attr:`tasks` is read (each
                hand's Jacobian rows and commanded rates), or None.
        """
        out = cls._make(r)
        applied.flags.writeable = False
        object.__setattr__(out, "applied", applied)
        object.__setattr__(out, "_hands", hands)
        return out

    @property
    def correction(self) -> Array:
        """The rates (nv,) the closed chains' correction added: ``applied - qdot``."""
        out: Array = self.applied - self.qdot
        return out

    @cached_property
    def tasks(self) -> tuple[TaskReport, ...]:
        """One report per task: the resolver's, with each held object's hands in the top
        level after its tasks (their scale the object's, their residual the hands').
        """  # noqa: D205
        hands = self.__dict__["_hands"]
        resolved = Resolution(*self)
        if hands is None:
            return resolved.tasks
        problem = self.problem
        levels = ((*problem.levels[0], *hands()), *problem.levels[1:])
        return resolved._replace(source=problem._replace(levels=levels)).tasks
