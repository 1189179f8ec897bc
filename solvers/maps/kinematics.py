"""Batch kinematics of a capability map's blocks: every sample evaluated without a Python loop.

Two evaluators, one interface (:class:`ArmKinematics`), numpy and numba only (so that a Dask
worker process imports no Pinocchio):

- :class:`BarkerKinematics`: ``barker6`` through its batch closed form (Barker's wrist centre
  ``(F7, F6, NO + F3)``, the hand's z axis z5 of eq. (C13) and the Jacobian of eq. (22),
  vectorised over the block), with his singular conditions (32), (33) and theta_5 = 0
  evaluated at each sample;
- :class:`ChainKinematics`: any serial chain through the compiled kernel
  (:mod:`rrc_pin.solvers.maps.kernels`); ``rrc_pin.maps.kinematics.chain_of`` builds the chain from
  a
  Pinocchio model.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.closed_form.barker import BarkerClosedForm
from rrc_pin.solvers.maps import batch as map_batch
from rrc_pin.solvers.maps.batch import Chain, GridArrays, Rows

Array = npt.NDArray[np.float64]


def task_rows(nq: int) -> int:
    """Task rows of a chain of ``nq`` joints: 6 (full twist) from six joints, else 3.

    The resolver's default task: the full twist for arms of six joints or more, the linear
    velocity below.
    """
    return 6 if nq >= 6 else 3


class ArmKinematics(ABC):
    """What a map needs of an arm: its chain, task rows, conditions, and a block's rows.

    Attributes:
        chain: The serial chain to the tool frame (limits, bounds of reach and Jacobian).
        rows: Task rows of the Jacobian (3 or 6).
        conditions: Names of the per-sample conditions counted per voxel (none, or
            Barker's ``eq32``, ``eq33``, ``s5``).
        tolerances: The condition's threshold on |value| (same order) [m or 1].
        method: How a block is evaluated (``closed_form`` or ``chain``), for the metadata.
    """

    chain: Chain
    rows: int
    conditions: tuple[str, ...] = ()
    tolerances: tuple[float, ...] = ()
    method: str = ""

    @abstractmethod
    def block_rows(
        self,
        Q: Array,
        grid: GridArrays,
        dexterity: bool,
        quanta: Array,
        first: int,
        out: Rows,
    ) -> None:
        """Fill ``out``'s first N rows from the samples ``Q`` (N, n) [rad or m].

        Args:
            Q: Joint positions of the chain's joints (N, n).
            grid: The voxel grid.
            dexterity: Compute manipulability and sigma_min.
            quanta: Fixed-point quanta (2,) of their sums.
            first: Global index of the first sample.
            out: Rows (at least N; as many condition columns as :attr:`conditions`).
        """


@dataclass
class ChainKinematics(ArmKinematics):
    """Any serial chain, by the compiled kernel (one pass over the block's samples)."""

    chain: Chain
    rows: int
    method: str = "chain"

    def block_rows(
        self, Q: Array, grid: GridArrays, dexterity: bool, quanta: Array, first: int, out: Rows
    ) -> None:
        """See :meth:`ArmKinematics.block_rows`."""
        map_batch.chain_rows(self.chain, Q, grid, self.rows, dexterity, quanta, first, out)


@dataclass
class BarkerKinematics(ArmKinematics):
    """barker6 by its batch closed form, with conditions (32), (33) and S5 at each sample.

    A condition holds at a sample when its value is within its tolerance: ``|F1|`` (eq. 32)
    and ``|SAL3 WE S3 + A3 C3|`` (eq. 33) within ``band`` times the arm's reach L, ``|S5|``
    within ``band``: the closed form's singular bands (``BarkerClosedForm.band``, 0.01 by
    default: 8.6 mm on the PUMA arm, 0.57 deg of theta_5).

    Attributes:
        closed_form: The arm's closed form.
    """

    closed_form: BarkerClosedForm
    chain: Chain
    rows: int = 6
    conditions: tuple[str, ...] = ("eq32", "eq33", "s5")
    tolerances: tuple[float, ...] = ()
    method: str = "closed_form"

    def __post_init__(self) -> None:
        g, band = self.closed_form.geometry, self.closed_form.band
        self.tolerances = (band * g.reach, band * g.reach, band)

    def block_rows(
        self, Q: Array, grid: GridArrays, dexterity: bool, quanta: Array, first: int, out: Rows
    ) -> None:
        """See :meth:`ArmKinematics.block_rows`."""
        cf, n = self.closed_form, Q.shape[0]
        P = cf.wrist_centre_batch(Q)
        Z = np.ascontiguousarray(cf.hand_to_base_batch(Q)[:, :, 2])  # R0_6's z (eq. C13)
        J = cf.jacobian_batch(Q) if dexterity else np.empty((n, 6, 6))
        s = cf.singularity_batch(Q)
        values = np.abs(np.stack([s.eq32, s.eq33, s.s5], axis=1))
        flags = values <= np.asarray(self.tolerances)
        map_batch.batch_rows(P, Z, J, flags, Q, self.chain, grid, dexterity, quanta, first, out)
