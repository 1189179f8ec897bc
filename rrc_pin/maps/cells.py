"""The map of a cell: every tool frame of a robot mapped on one grid, and what they share.

A cell is any robot with several tool frames: a :func:`rrc_pin.combine` of arms at their
bases, a robot with two hands (baxter, pr2), or a named cell of the catalogue. Each tool
frame is mapped by :func:`~rrc_pin.maps.capability` over its own chain's joints (the joints
that move it; a joint shared by two chains, pr2's torso, is sampled in each), all on the
union of their grids (voxels aligned on multiples of the edge in the cell's base frame) and
with the same seed. A voxel of the cell holds:

- ``arms``: how many tool frames reach it; ``shared``: at least two;
- ``combined_coverage``: where it is shared, the smallest orientation coverage of the
  frames that reach it (the weaker hand's), else 0;
- ``combined_manipulability``: the same for the best manipulability (NaN where not shared).
"""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.loading import load
from rrc_pin.maps.capability import ProgressArg, capability
from rrc_pin.maps.capability_map import CapabilityMap
from rrc_pin.maps.kinematics import chain_of
from rrc_pin.maps.voxels import Grid, chain_grid
from rrc_pin.robot import Robot
from rrc_pin.solvers.maps.sampling import BLOCK

Array = npt.NDArray[np.float64]


class CellQuery(NamedTuple):
    """A cell's statistics at query points (N,), per frame (N, A) where so shaped.

    Attributes:
        inside: The point lies in the grid.
        arms: Tool frames reaching its voxel.
        coverage: Orientation coverage of each frame (N, A).
        combined_coverage: The smallest coverage of the frames, where at least two reach.
        combined_manipulability: The smallest best manipulability of the frames, where at
            least two reach (NaN elsewhere).
    """

    inside: npt.NDArray[np.bool_]
    arms: npt.NDArray[np.int64]
    coverage: Array
    combined_coverage: Array
    combined_manipulability: Array


@dataclass(repr=False)
class CellMap:
    """The maps of a cell's tool frames on one grid, and their combination.

    Its ``repr`` is a one-line summary.

    Attributes:
        name: The cell (robot) name.
        frames: Its tool frames, in order.
        maps: One :class:`CapabilityMap` per frame (same grid).
    """

    name: str
    frames: tuple[str, ...]
    maps: tuple[CapabilityMap, ...]

    def __repr__(self) -> str:
        shared = np.count_nonzero(self.shared) * self.grid.voxel**3
        return (
            f"CellMap({self.name!r}, frames={list(self.frames)}, "
            f"samples={int(self.maps[0].meta.get('samples', 0)):,} per frame, "
            f"voxel={self.grid.voxel} m, shared {shared:.4g} m^3)"
        )

    @property
    def grid(self) -> Grid:
        """The common grid."""
        return self.maps[0].grid

    @cached_property
    def arms(self) -> npt.NDArray[np.int64]:
        """Frames reaching each voxel (V,)."""
        out: npt.NDArray[np.int64] = np.sum([m.reached for m in self.maps], axis=0)
        return out

    @property
    def shared(self) -> npt.NDArray[np.bool_]:
        """Voxels reached by at least two frames (V,)."""
        out: npt.NDArray[np.bool_] = self.arms >= 2
        return out

    def _combined(self, values: list[Array]) -> Array:
        """Smallest of ``values`` over the frames that reach a voxel, where two or more do."""
        stack = np.stack([np.where(m.reached, v, np.inf) for m, v in zip(self.maps, values,
                                                                          strict=True)])
        out: Array = np.where(self.shared, stack.min(axis=0), np.nan)
        return out

    @cached_property
    def combined_coverage(self) -> Array:
        """The weaker frame's orientation coverage where shared, 0 elsewhere (V,)."""
        out: Array = np.nan_to_num(self._combined([m.coverage for m in self.maps]), nan=0.0)
        return out

    @cached_property
    def combined_manipulability(self) -> Array:
        """The weaker frame's best manipulability where shared, NaN elsewhere (V,)."""
        return self._combined([m.column("manipulability_max") for m in self.maps])

    def at(self, points: npt.ArrayLike) -> CellQuery:
        """The cell's statistics at ``points`` (N, 3) or (3,) [m], base frame of the cell.

        Raises:
            InvalidInput: ``points`` is not a finite (N, 3) or (3,) array.
        """
        per = [m.at(points) for m in self.maps]
        keys = self.grid.keys_of(np.asarray(points, dtype=float))
        inside = keys >= 0
        k = np.where(inside, keys, 0)
        return CellQuery(
            inside,
            np.where(inside, self.arms[k], 0),
            np.nan_to_num(np.stack([p.coverage for p in per], axis=1), nan=0.0),
            np.where(inside, self.combined_coverage[k], 0.0),
            np.where(inside, self.combined_manipulability[k], np.nan),
        )

    def summary(self) -> dict[str, Any]:
        """The cell in numbers (JSON-ready)."""
        v3 = self.grid.voxel**3
        shared = self.shared
        out: dict[str, Any] = {
            "cell": self.name,
            "frames": list(self.frames),
            "samples_per_frame": int(self.maps[0].meta["samples"]),
            "voxel_m": self.grid.voxel,
        }
        for f, m in zip(self.frames, self.maps, strict=True):
            out[f"volume_m3[{f}]"] = m.volume()
        out["shared_volume_m3"] = float(np.count_nonzero(shared) * v3)
        cov = self.combined_coverage[shared]
        out["combined_coverage_mean"] = float(cov.mean()) if cov.size else 0.0
        out["shared_coverage_50_m3"] = float(np.count_nonzero(cov >= 0.5) * v3)
        man = self.combined_manipulability[shared]
        if np.isfinite(man).any():
            out["combined_manipulability_best"] = float(np.nanmax(man))
        return out

    def summary_table(self) -> str:
        """:meth:`summary` as a two-column Markdown table."""
        rows = ["| statistic | value |", "| --- | ---: |"]
        for key, value in self.summary().items():
            text = f"{value:.4g}" if isinstance(value, float) else str(value)
            rows.append(f"| {key} | {text} |")
        return "\n".join(rows)


def frame_folder(index: int, frame: str) -> str:
    """Sub-folder of frame ``index`` in a cell's output folder (``0_left-panda_hand_tcp``)."""
    return f"{index}_" + re.sub(r"[^A-Za-z0-9_.-]+", "-", frame)


def cell_map(
    cell: Robot | str,
    samples: int = 10**7,
    voxel: float = 0.05,
    scheduler: object = None,
    *,
    seed: int = 0,
    out: str | os.PathLike[str] | None = None,
    workers: int | None = None,
    dexterity: bool = True,
    progress: ProgressArg = True,
    block_size: int = BLOCK,
    dashboard: str | None = None,
) -> CellMap:
    """The map of every tool frame of ``cell`` on one grid, and their combination.

    Args:
        cell: A robot with several tool frames (or one: a cell of one arm), or a name.
        samples: Samples per frame.
        voxel: Voxel edge [m].
        scheduler: As :func:`~rrc_pin.maps.capability`.
        seed: The seed, the same for every frame.
        workers: As :func:`~rrc_pin.maps.capability`.
        dexterity: As :func:`~rrc_pin.maps.capability`.
        progress: As :func:`~rrc_pin.maps.capability` (one bar per frame).
        block_size: As :func:`~rrc_pin.maps.capability`.
        dashboard: As :func:`~rrc_pin.maps.capability`.
        out: Folder: each frame's map in ``<index>_<frame>/`` (resumable each) and the
            cell's ``summary.md``/``.json`` (plots: :func:`~rrc_pin.maps.plot_cell`).

    Raises:
        InvalidInput, ForeignMap, SchedulerUnreachable, MissingExtra: As
            :func:`~rrc_pin.maps.capability`.
    """
    robot = cell if isinstance(cell, Robot) else load(_name(cell))
    if not isinstance(voxel, (int, float)) or isinstance(voxel, bool) or not voxel > 0:
        raise InvalidInput("voxel", f"expected a finite length > 0 [m], got {voxel!r}")
    grid: Grid | None = None
    for frame in robot.tool_frames:
        g = chain_grid(chain_of(robot, frame)[0], float(voxel))
        grid = g if grid is None else grid.union(g)
    folder = None if out is None else Path(out)
    maps = []
    for i, frame in enumerate(robot.tool_frames):
        sub = None if folder is None else folder / frame_folder(i, frame)
        maps.append(capability(
            robot, samples, float(voxel), scheduler, seed=seed, out=sub, workers=workers,
            dexterity=dexterity, frame=frame, progress=progress, block_size=block_size,
            grid=grid, dashboard=dashboard,
        ))  # fmt: skip
    result = CellMap(robot.name, tuple(robot.tool_frames), tuple(maps))
    if folder is not None:
        (folder / "summary.md").write_text(result.summary_table() + "\n")
        (folder / "summary.json").write_text(json.dumps(result.summary(), indent=1) + "\n")
    return result


def _name(cell: object) -> str:
    if not isinstance(cell, str):
        raise InvalidInput("cell", f"expected a Robot, a name or a path, got {cell!r}")
    return cell
