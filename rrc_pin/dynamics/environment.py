"""A compliant environment: a spring-damper plane the tool can press on."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import as_vector, finite_number

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class ContactPlane:
    """A frictionless plane; the half-space behind it pushes back like a spring-damper.

    With the tool point ``p`` and velocity ``pdot``, the penetration is
    ``delta = (point - p) . normal``; for ``delta > 0`` the plane pushes the tool with
    ``F = max(0, stiffness delta - damping pdot . normal) normal`` (never pulls).

    Attributes:
        point: A point of the surface (3,) [m], base frame.
        normal: Unit normal (3,) pointing out of the surface, into free space.
        stiffness: Surface stiffness [N/m], > 0.
        damping: Surface damping [N s/m], >= 0.

    Raises:
        InvalidInput: At construction, a bad field (named); ``normal`` is normalised if its
            norm is within 1e-6 of 1, refused otherwise.
    """

    point: Array
    normal: Array
    stiffness: float
    damping: float = 0.0

    def __post_init__(self) -> None:
        as_vector(self.point, "point", 3)
        n = as_vector(self.normal, "normal", 3)
        if abs(np.linalg.norm(n) - 1.0) > 1e-6:
            raise InvalidInput("normal", f"expected a unit vector, got norm {np.linalg.norm(n)}")
        finite_number(self.stiffness, "stiffness", 0.0, inclusive=False)
        finite_number(self.damping, "damping", 0.0)

    def force_on_tool(self, p: Array, pdot: Array) -> Array:
        """Force (3,) [N] the plane applies to a tool point at ``p`` moving at ``pdot``."""
        n = np.asarray(self.normal, dtype=float)
        depth = float(np.dot(np.asarray(self.point, dtype=float) - p, n))
        if depth <= 0.0:
            return np.zeros(3)
        push = self.stiffness * depth - self.damping * float(np.dot(pdot, n))
        return max(push, 0.0) * n
