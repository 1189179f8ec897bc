"""Multi-arm cells: named arms on one model, cooperative commands, master-slave mapping."""

from rrc_pin.cells.cell import Arm, Cell, Grasp, make_cell

__all__ = ["Arm", "Cell", "Grasp", "make_cell"]
