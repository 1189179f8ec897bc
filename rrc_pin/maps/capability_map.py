"""The capability map of one tool frame: voxel statistics, derived fields, queries, summary.

``CapabilityMap.at(points)`` answers per point [m, base frame] the statistics of its voxel
(NaN, or 0 for counts, where nothing was reached or the point is outside the grid), by one
vectorised lookup: a key per point, then the columns at those keys.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.maps.voxels import Grid, VoxelStats
from rrc_pin.solvers.maps.batch import BINS, NONE, Chain
from rrc_pin.solvers.maps.sampling import Plan, sample_at

Array = npt.NDArray[np.float64]


class MapQuery(NamedTuple):
    """Statistics at query points, one entry per point (N,).

    Attributes:
        inside: The point lies in the map's grid.
        samples: Samples in its voxel (0: not reached).
        coverage: Zacharias's reachability index: share of the 54 direction bins reached [0, 1].
        manipulability_max: Best manipulability ``prod(sigma)`` (NaN: none, or not computed).
        manipulability_mean: Mean manipulability.
        sigma_min_max: Best smallest singular value of the task Jacobian.
        sigma_min_mean: Mean smallest singular value.
        margin_max: Best joint-limit margin, relative to each joint's range (<= 0.5).
    """

    inside: npt.NDArray[np.bool_]
    samples: npt.NDArray[np.int64]
    coverage: Array
    manipulability_max: Array
    manipulability_mean: Array
    sigma_min_max: Array
    sigma_min_mean: Array
    margin_max: Array


def popcount(bits: npt.NDArray[np.uint64]) -> npt.NDArray[np.int64]:
    """Bits set in each uint64 (N,)."""
    b = np.ascontiguousarray(bits, dtype=np.uint64)
    out: npt.NDArray[np.int64] = (
        np.unpackbits(b.view(np.uint8)).reshape(b.shape[0], 64).sum(axis=1, dtype=np.int64)
    )
    return out


@dataclass(repr=False)
class CapabilityMap:
    """Reachability, dexterity and singularity statistics of one tool frame, per voxel.

    Its ``repr`` is a one-line summary (the arrays: :attr:`stats`, :meth:`column`).

    Attributes:
        grid: The voxels (aligned on multiples of the voxel edge, base frame).
        stats: The dense statistics (:class:`~rrc_pin.maps.voxels.VoxelStats`).
        chain: The arm's chain (its joints' limits; the witnesses are drawn again from it).
        meta: What the map is: arm, frame, samples, seed, voxel, block size, the statistics
            computed, quanta, conditions and their tolerances, versions, timings.
    """

    grid: Grid
    stats: VoxelStats
    chain: Chain
    meta: dict[str, Any] = field(default_factory=dict)

    def __repr__(self) -> str:
        shape = "x".join(map(str, self.grid.shape))
        return (
            f"CapabilityMap(arm={self.meta.get('arm')!r}, frame={self.meta.get('frame')!r}, "
            f"samples={int(self.meta.get('samples', 0)):,}, voxel={self.grid.voxel} m, "
            f"grid {shape}, {int(np.count_nonzero(self.reached)):,} voxels reached, "
            f"{self.volume():.4g} m^3)"
        )

    @property
    def plan(self) -> Plan:
        """The map's blocks."""
        return Plan(int(self.meta["samples"]), int(self.meta["block_size"]))

    @property
    def dexterity(self) -> bool:
        """Whether manipulability and sigma_min were computed."""
        return bool(self.meta.get("dexterity", True))

    @cached_property
    def reached(self) -> npt.NDArray[np.bool_]:
        """Voxels reached by a sample (V,)."""
        out: npt.NDArray[np.bool_] = self.stats.count > 0
        return out

    @cached_property
    def coverage(self) -> Array:
        """Share of the direction bins reached per voxel (V,), 0 where not reached."""
        out: Array = popcount(self.stats.dirs) / BINS
        return out

    def column(self, name: str) -> npt.NDArray[Any]:
        """A statistic by name (V,): a stored column, ``coverage``, or a ``*_mean``.

        Maxima and means are NaN where the voxel was not reached (or not computed).
        """
        if name == "coverage":
            return self.coverage
        if name.endswith("_mean"):
            return self._mean(name.removesuffix("_mean"))
        col = self.stats.arrays()[name]
        if col.dtype == np.float64:
            return np.where(np.isfinite(col), col, np.nan)
        return col

    def _mean(self, what: str) -> Array:
        j = {"manipulability": 0, "sigma_min": 1}[what]
        if not self.dexterity:
            return np.full(self.grid.size, np.nan)
        quantum = float(self.meta["quanta"][j])
        with np.errstate(invalid="ignore", divide="ignore"):
            out: Array = np.where(
                self.reached, self.stats.isum[:, j] * quantum / self.stats.count, np.nan
            )
        return out

    @cached_property
    def _query_columns(self) -> dict[str, npt.NDArray[Any]]:
        """The columns :meth:`at` reads, by :class:`MapQuery` field."""
        names = {"samples": "count"}
        return {f: self.column(names.get(f, f)) for f in MapQuery._fields if f != "inside"}

    def at(self, points: npt.ArrayLike) -> MapQuery:
        """Statistics of the voxels holding ``points`` (N, 3) or one point (3,) [m].

        Returns:
            A :class:`MapQuery` of (N,) arrays (N = 1 for one point).

        Raises:
            InvalidInput: ``points`` is not a finite (N, 3) or (3,) array.
        """
        from rrc_pin.errors import InvalidInput

        P = np.asarray(points, dtype=float)
        if P.ndim not in (1, 2) or P.shape[-1] != 3 or not np.all(np.isfinite(P)):
            raise InvalidInput("points", f"expected finite (N, 3) positions [m], got {P.shape}")
        keys = self.grid.keys_of(P)
        inside = keys >= 0
        k = np.where(inside, keys, 0)
        cols = self._query_columns
        values: dict[str, Any] = {"inside": inside}
        for name, col in cols.items():
            v = col[k]
            values[name] = np.where(inside, v, 0 if v.dtype.kind == "i" else np.nan)
        return MapQuery(**values)

    def volume(self, mask: npt.NDArray[np.bool_] | None = None) -> float:
        """Volume of the voxels reached (or of ``mask``) [m^3]."""
        n = int(np.count_nonzero(self.reached if mask is None else mask))
        return n * self.grid.voxel**3

    def witnesses(self, keys: npt.ArrayLike, column: str = "witness") -> Array:
        """The chain's joint positions (k, n) of the witness samples of ``keys`` (reached).

        ``column``: ``witness`` (the voxel's first sample), or a condition's
        (``eq32_witness``...). Raises ValueError where the voxel has none.
        """
        idx = self.stats.arrays()[column][np.asarray(keys, dtype=np.int64)]
        if np.any(idx == NONE):
            raise ValueError(f"no {column} sample in some of these voxels")
        return sample_at(self.chain, int(self.meta["seed"]), self.plan, list(idx))

    def summary(self) -> dict[str, Any]:
        """The map in numbers (JSON-ready)."""
        reached = self.reached
        n = int(np.count_nonzero(reached))
        cov = self.coverage[reached]
        out: dict[str, Any] = {
            "arm": self.meta.get("arm"),
            "frame": self.meta.get("frame"),
            "samples": int(self.meta["samples"]),
            "voxel_m": self.grid.voxel,
            "voxels_reached": n,
            "volume_m3": self.volume(),
            "samples_outside": int(self.stats.outside),
            "coverage_mean": float(cov.mean()) if n else 0.0,
            "voxels_coverage_50": int(np.count_nonzero(cov >= 0.5)),
            "margin_best": float(np.nanmax(self.column("margin_max"))) if n else None,
        }
        if self.dexterity and n:
            out["manipulability_best"] = float(np.nanmax(self.column("manipulability_max")))
            out["sigma_min_best"] = float(np.nanmax(self.column("sigma_min_max")))
        for c in self.meta.get("conditions", []):
            out[f"voxels_{c}"] = int(np.count_nonzero(self.stats.arrays()[f"{c}_count"]))
        return out

    def summary_table(self) -> str:
        """:meth:`summary` as a two-column Markdown table."""
        rows = ["| statistic | value |", "| --- | ---: |"]
        for key, value in self.summary().items():
            text = f"{value:.4g}" if isinstance(value, float) else str(value)
            rows.append(f"| {key} | {text} |")
        return "\n".join(rows)
