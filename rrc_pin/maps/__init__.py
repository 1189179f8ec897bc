"""Capability maps: reachability, dexterity and singularity maps of arms and cells, on Dask.

``maps.capability(arm, samples, voxel, scheduler)`` samples the joints in fixed blocks,
evaluates them in batches (barker6's closed form, a compiled serial chain for any other arm),
reduces every voxel's statistics exactly and returns a :class:`CapabilityMap` (queried with
``map.at(points)``); ``maps.cell_map`` maps every tool frame of a cell on one grid;
``maps.base_placement`` scores placements of a second arm; ``maps.audit`` confirms voxels by
resolved-rate IK through :class:`rrc_pin.Resolver`. docs/api.md ("Capability maps") says how
blocks, seeds, reductions, memory and resumption work.

Needs the ``maps`` extra (dask[distributed], zarr; matplotlib for the plots).
"""

from rrc_pin.maps.audit import AuditReport, audit, refine
from rrc_pin.maps.capability import capability
from rrc_pin.maps.capability_map import CapabilityMap, MapQuery
from rrc_pin.maps.cells import CellMap, CellQuery, cell_map
from rrc_pin.maps.placement import PlacementSearch, base_placement, placements_grid
from rrc_pin.maps.plots import plot_cell, plot_map
from rrc_pin.maps.store import load_map, save_map

__all__ = [
    "AuditReport",
    "CapabilityMap",
    "CellMap",
    "CellQuery",
    "MapQuery",
    "PlacementSearch",
    "audit",
    "base_placement",
    "capability",
    "cell_map",
    "load_map",
    "placements_grid",
    "plot_cell",
    "plot_map",
    "refine",
    "save_map",
]
