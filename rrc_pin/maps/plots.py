"""Pictures of a map (matplotlib, PNG): three orthogonal slices and a 3-D view.

- ``slices.png``: the slices through the first joint's origin (x-y, x-z, y-z), coloured by
  the orientation coverage (top row) and by the best manipulability, or the best joint-limit
  margin when dexterity was not computed (bottom row); voxels not reached are left white.
- ``view3d.png``: the voxels reached, as points coloured by coverage (at most
  :data:`MAX_POINTS`, every k-th voxel in key order).

Without matplotlib nothing is drawn (the functions return False).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from rrc_pin.maps.capability_map import CapabilityMap
from rrc_pin.maps.voxels import Grid

if TYPE_CHECKING:
    from rrc_pin.maps.cells import CellMap

MAX_POINTS = 30_000
"""Points of the 3-D view at most."""
_AXES = ("x", "y", "z")


def _pyplot() -> Any:
    try:
        import matplotlib
    except ImportError:
        return None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_map(m: CapabilityMap, folder: Path) -> bool:
    """Write ``slices.png`` and ``view3d.png`` into ``folder``; False without matplotlib."""
    plt = _pyplot()
    if plt is None:
        return False
    title = _title(m)
    centre = m.chain.trans[0]
    second = "manipulability_max" if m.dexterity else "margin_max"
    labels = {
        "coverage": "orientation coverage (share of 54 direction bins)",
        "manipulability_max": "best manipulability prod(sigma)",
        "margin_max": "best joint-limit margin (share of range)",
    }
    columns = [
        (labels["coverage"], m.coverage, (0.0, 1.0)),
        (labels[second], m.column(second), None),
    ]
    slice_figure(plt, m.grid, m.reached, centre, columns, title, folder / "slices.png")
    view_figure(plt, m.grid, m.reached, m.coverage, labels["coverage"], title,
                folder / "view3d.png")  # fmt: skip
    return True


def plot_cell(cell: CellMap, folder: Path) -> bool:
    """Write ``cell_slices.png`` and ``cell_view3d.png`` into ``folder`` (False: no matplotlib)."""
    plt = _pyplot()
    if plt is None:
        return False
    m0 = cell.maps[0]
    title = (
        f"cell {cell.name}: {len(cell.frames)} tool frames, {int(m0.meta['samples']):,} "
        f"samples each, {100 * cell.grid.voxel:g} cm voxels"
    )
    reached = cell.arms > 0
    centre = np.mean([m.chain.trans[0] for m in cell.maps], axis=0)
    columns = [
        ("tool frames reaching the voxel", cell.arms.astype(float), (0.0, len(cell.frames))),
        ("combined coverage (the weaker frame's, where shared)", cell.combined_coverage,
         (0.0, 1.0)),
    ]  # fmt: skip
    slice_figure(plt, cell.grid, reached, centre, columns, title, folder / "cell_slices.png")
    view_figure(plt, cell.grid, cell.shared, cell.combined_coverage,
                "combined coverage (shared voxels)", title, folder / "cell_view3d.png")  # fmt: skip
    return True


def _title(m: CapabilityMap) -> str:
    return (
        f"{m.meta.get('arm')} ({m.meta.get('frame')}): {int(m.meta['samples']):,} samples, "
        f"{100 * m.grid.voxel:g} cm voxels"
    )


def slice_values(grid: Grid, values: npt.NDArray[Any], axis: int, at: float) -> npt.NDArray[Any]:
    """The 2-D slice of ``values`` (V,) normal to ``axis`` through the coordinate ``at`` [m].

    Indexed by the two other axes, in order.
    """
    cube = values.reshape(grid.shape)
    i = int(np.clip(np.floor(at / grid.voxel) - grid.start[axis], 0, grid.shape[axis] - 1))
    out: npt.NDArray[Any] = np.take(cube, i, axis=axis)
    return out


def slice_figure(
    plt: Any,
    grid: Grid,
    reached: npt.NDArray[np.bool_],
    centre: npt.ArrayLike,
    columns: Sequence[tuple[str, npt.NDArray[Any], tuple[float, float] | None]],
    title: str,
    path: Path,
) -> None:
    """Three slices (x-y, x-z, y-z through ``centre`` [m]) per column, in one figure.

    A row per ``(label, values (V,), colour range or None)`` of ``columns``; voxels not
    ``reached`` are left white.
    """
    c = np.asarray(centre, dtype=float)
    fig, axes = plt.subplots(len(columns), 3, figsize=(15, 4.6 * len(columns)), squeeze=False)
    for row, (label, data, limits) in enumerate(columns):
        shown_values = np.where(reached, data.astype(float), np.nan)
        finite = shown_values[np.isfinite(shown_values)]
        if limits is None:
            limits = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
        for col, normal in enumerate((2, 1, 0)):
            ax = axes[row][col]
            u, v = (a for a in range(3) if a != normal)
            img = slice_values(grid, shown_values, normal, c[normal])
            extent = (
                grid.origin[u], grid.origin[u] + grid.shape[u] * grid.voxel,
                grid.origin[v], grid.origin[v] + grid.shape[v] * grid.voxel,
            )  # fmt: skip
            shown = ax.imshow(img.T, origin="lower", extent=extent, vmin=limits[0],
                              vmax=limits[1], cmap="viridis", interpolation="nearest")  # fmt: skip
            ax.set_xlabel(f"{_AXES[u]} [m]")
            ax.set_ylabel(f"{_AXES[v]} [m]")
            ax.set_aspect("equal")
            ax.set_title(f"{_AXES[u]}-{_AXES[v]} slice at {_AXES[normal]} = {c[normal]:.2f} m")
            ax.plot([0.0], [0.0], "r+", markersize=12, markeredgewidth=2)
        fig.colorbar(shown, ax=list(axes[row]), shrink=0.85, label=label)
    fig.suptitle(f"{title}\nwhite: not reached; red +: the base origin's projection")
    fig.savefig(path, dpi=90)
    plt.close(fig)


def view_figure(
    plt: Any, grid: Grid, shown: npt.NDArray[np.bool_], values: npt.NDArray[Any], label: str,
    title: str, path: Path,
) -> None:  # fmt: skip
    """The ``shown`` voxels (V,) as points coloured by ``values`` (V,)."""
    keys = np.flatnonzero(shown)
    step = max(1, -(-keys.size // MAX_POINTS))
    keys = keys[::step]
    P = grid.centres(keys)
    fig = plt.figure(figsize=(8, 7))
    ax = fig.add_subplot(projection="3d")
    points = ax.scatter(P[:, 0], P[:, 1], P[:, 2], c=values[keys], s=2, cmap="viridis",
                        vmin=0.0, depthshade=False)  # fmt: skip
    for i, name in enumerate(("set_xlabel", "set_ylabel", "set_zlabel")):
        getattr(ax, name)(f"{_AXES[i]} [m]")
    if P.size:
        lo, hi = P.min(axis=0), P.max(axis=0)
        half = float(np.max(hi - lo)) / 2 or grid.voxel
        mid = (lo + hi) / 2
        ax.set_xlim(mid[0] - half, mid[0] + half)
        ax.set_ylim(mid[1] - half, mid[1] + half)
        ax.set_zlim(mid[2] - half, mid[2] + half)
    fig.colorbar(points, ax=ax, shrink=0.7, label=label)
    note = "" if step == 1 else f", every {step}th shown"
    ax.set_title(f"{title}\n{np.count_nonzero(shown):,} voxels{note}", fontsize=10)
    fig.savefig(path, dpi=90)
    plt.close(fig)
