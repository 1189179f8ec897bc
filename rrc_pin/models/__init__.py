"""The catalogue of paper arms: one module per arm, one registry."""

from rrc_pin.models import barker6, kr5_3r, nadkarni_c1, nadkarni_c2, rrc_k1607
from rrc_pin.models.arm_spec import INCH, ArmSpec

CATALOGUE: dict[str, ArmSpec] = {
    module.SPEC.name: module.SPEC
    for module in (barker6, rrc_k1607, kr5_3r, nadkarni_c1, nadkarni_c2)
}
"""Catalogue name -> the arm's spec, in the order the papers are listed."""

__all__ = ["CATALOGUE", "INCH", "ArmSpec"]
