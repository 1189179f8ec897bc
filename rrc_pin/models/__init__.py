"""The catalogue of paper arms: one module per arm, one registry."""

from rrc_pin.models import (
    barker6,
    gsfc_dual,
    kr5_3r,
    nadkarni_c1,
    nadkarni_c2,
    rrc_k1607,
    yeh_tripod,
)
from rrc_pin.models.arm_spec import INCH, ArmSpec
from rrc_pin.models.cell_spec import CellSpec

CATALOGUE: dict[str, ArmSpec] = {
    module.SPEC.name: module.SPEC
    for module in (barker6, rrc_k1607, kr5_3r, nadkarni_c1, nadkarni_c2)
}
"""Catalogue name -> the arm's spec, in the order the papers are listed."""

CELLS: dict[str, CellSpec] = {module.SPEC.name: module.SPEC for module in (gsfc_dual, yeh_tripod)}
"""Cell name -> the ready-made cell's spec (:class:`~rrc_pin.models.cell_spec.CellSpec`)."""

__all__ = ["CATALOGUE", "CELLS", "INCH", "ArmSpec", "CellSpec"]
