"""Multi-arm cells: named arms on one model, cooperative commands, master-slave mapping."""

from rrc_pin.cells.cell import Arm, Cell, Grasp, make_cell
from rrc_pin.cells.cell_log import CellLog, CellRecord
from rrc_pin.cells.controller import CellController, CellStep
from rrc_pin.cells.master_slave import MasterSlave

__all__ = ["Arm", "Cell", "CellController", "CellLog", "CellRecord", "CellStep", "Grasp",
           "MasterSlave", "make_cell"]  # fmt: skip
