"""A catalogue arm as data: DH chain, limits, named poses and where each value comes from."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from rrc_pin.dh import DHChain
from rrc_pin.errors import InvalidInput
from rrc_pin.models.inertia import LinkInertial
from rrc_pin.solvers.checks import finite_number

if TYPE_CHECKING:
    from rrc_pin.solvers.closed_form.base import ClosedForm

INCH = 0.0254
"""Metres per inch: the one place where the papers' inches become SI."""


@dataclass(frozen=True)
class ArmSpec:
    """A paper arm, transcribed once in SI units.

    Attributes:
        name: Catalogue name (also the URDF robot name and file stem).
        chain: Kinematics as a DH table.
        lower: Joint position lower limits (nq,) [rad or m].
        upper: Joint position upper limits (nq,) [rad or m].
        velocity_limit: Joint speed limits (nq,) [rad/s or m/s], > 0.
        effort_limit: Joint effort limits (nq,) [N m or N] (URDF needs one; none from the papers).
        source: Document and table the values come from.
        assumed: Human-readable list of values the paper does not give and that were chosen here.
        named_poses: Named configurations (nq,) from the paper, e.g. ``"paper_start"``.
        closed_form: Zero-argument factory of the paper's closed-form fast path, or None.
        parameters: The builder's keyword arguments (for variants and for the CLI table).
        inertials: One :class:`LinkInertial` per link, each in the DH frame i attached to link
            i (standard: at its far joint; modified: at its own joint), or empty for the
            placeholder inertia of :mod:`rrc_pin.urdf_export`.
        collision_radii: Radius of each link's collision capsules (nq,) [m], > 0, or empty for
            none; the capsules follow the DH offsets (:mod:`rrc_pin.link_capsules`). The
            papers give no link widths: every arm records its radii as assumed.
    """

    name: str
    chain: DHChain
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    velocity_limit: tuple[float, ...]
    effort_limit: tuple[float, ...]
    source: str
    assumed: tuple[str, ...] = ()
    named_poses: dict[str, tuple[float, ...]] = field(default_factory=dict)
    closed_form: Callable[[], ClosedForm] | None = None
    parameters: dict[str, float] = field(default_factory=dict)
    inertials: tuple[LinkInertial, ...] = ()
    collision_radii: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        n = self.chain.nq
        if self.inertials and len(self.inertials) != n:
            raise InvalidInput("inertials", f"expected {n} links, got {len(self.inertials)}")
        radii = np.asarray(self.collision_radii, dtype=float)
        if radii.size and (radii.shape != (n,) or not np.all(np.isfinite(radii) & (radii > 0))):
            raise InvalidInput(
                "collision_radii", f"expected {n} finite radii > 0 [m], got {self.collision_radii}"
            )
        for label in ("lower", "upper", "velocity_limit", "effort_limit"):
            values = np.asarray(getattr(self, label), dtype=float)
            if values.shape != (n,):
                raise InvalidInput(label, f"expected {n} values, got {values.shape}")
        if np.any(np.asarray(self.lower) >= np.asarray(self.upper)):
            raise InvalidInput("lower", "every lower limit must be below its upper limit")
        if np.any(np.asarray(self.velocity_limit) <= 0.0):
            raise InvalidInput("velocity_limit", "every velocity limit must be > 0")
        for pose_name, q in self.named_poses.items():
            if len(q) != n:
                raise InvalidInput(
                    "named_poses", f"{pose_name!r} has {len(q)} values, expected {n}"
                )

    @property
    def nq(self) -> int:
        """Number of joints."""
        return self.chain.nq

    @property
    def joint_kinds(self) -> tuple[str, ...]:
        """Kind of every joint: ``revolute``, ``prismatic`` or ``screw``."""
        return tuple(row.kind for row in self.chain.rows)


def check_parameters(values: dict[str, float]) -> dict[str, float]:
    """Return a builder's geometry ``values`` as floats, each finite and real.

    Builders call it first, so that a bad value is refused before any table is built.

    Raises:
        InvalidInput: A value is not a finite real number, naming its parameter.
    """
    return {key: finite_number(value, key) for key, value in values.items()}
