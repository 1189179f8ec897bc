"""Voxel statistics and their exact reductions: the grid, the fields, the dense accumulators.

What a voxel holds (its samples are those whose tool origin lies in it):

| field | type | reduction | meaning |
| --- | --- | --- | --- |
| ``count`` | int64 | sum | samples in the voxel |
| ``directions`` | uint64 | or | bits of the 54 direction bins of the tool's z axis reached |
| ``manipulability_max`` | float64 | max | best ``prod(sigma_i)`` of the task Jacobian |
| ``sigma_min_max`` | float64 | max | best smallest singular value |
| ``margin_max`` | float64 | max | best joint-limit margin (relative to each range, <= 0.5) |
| ``manipulability_sum`` | int64 | sum | ``round(w / quantum)`` summed: mean = sum quantum / count |
| ``sigma_min_sum`` | int64 | sum | the same for sigma_min |
| ``witness`` | int64 | min | global index of the voxel's first sample |
| ``<condition>_count`` | int64 | sum | samples where a condition holds (barker6: eq32, eq33, s5) |
| ``<condition>_witness`` | int64 | min | the first of them |

Every reduction is exact (integer sums, or, maxima, minima): the same samples give the same
bits in any grouping and order. Means come from integer sums in fixed point: each value is
rounded to a quantum of ``bound / 2^31`` (the bound of :func:`quanta`), so a sum of up to
2^32 samples per voxel stays below 2^63, and a mean is within half a quantum of the exact
mean of the values (0.5 ppb of the bound).

The grid's voxels are aligned on multiples of ``voxel`` in the base frame (voxel (i, j, k)
spans ``[i v, (i + 1) v)`` and alike), so the maps of several arms of one cell share their
voxels.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.maps.batch import MAX_KEYS, NONE, Chain, Fields, GridArrays, Sparse

Array = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

SUM_BITS = 31
"""A value's fixed point: ``round(value / quantum)``, quantum = bound / 2^SUM_BITS."""
MAX_SAMPLES = 2**32
"""Samples of a map at most: a voxel's fixed-point sum stays below 2^63."""


@dataclass(frozen=True)
class Grid:
    """A box of cubic voxels aligned on multiples of ``voxel`` in the base frame.

    Attributes:
        start: Index (3,) of the first voxel along x, y, z: its corner is ``start voxel`` [m].
        shape: Voxels along x, y, z (3,).
        voxel: Edge [m].
    """

    start: tuple[int, int, int]
    shape: tuple[int, int, int]
    voxel: float

    @classmethod
    def around(cls, centre: npt.ArrayLike, radius: float, voxel: float) -> Grid:
        """The aligned grid covering the ball of ``radius`` [m] about ``centre`` (3,) [m].

        One voxel of margin on the upper side, so a point exactly on the bound is inside.
        """
        c = np.asarray(centre, dtype=float)
        lo = np.floor((c - radius) / voxel).astype(np.int64)
        hi = np.floor((c + radius) / voxel).astype(np.int64) + 1
        return cls(_ints(lo), _ints(hi - lo + 1), float(voxel))

    def union(self, other: Grid) -> Grid:
        """The aligned grid covering both (same voxel)."""
        lo = np.minimum(self.start, other.start)
        hi = np.maximum(np.add(self.start, self.shape), np.add(other.start, other.shape))
        return Grid(_ints(lo), _ints(hi - lo), self.voxel)

    @property
    def size(self) -> int:
        """Number of voxels."""
        return int(np.prod(self.shape, dtype=np.int64))

    @property
    def origin(self) -> Array:
        """Corner of the first voxel (3,) [m]."""
        return np.asarray(self.start, dtype=float) * self.voxel

    @property
    def arrays(self) -> GridArrays:
        """The grid as the kernels take it."""
        start = np.asarray(self.start, dtype=np.int64)
        return GridArrays(start, self.voxel, np.asarray(self.shape, dtype=np.int64))

    def keys_of(self, points: npt.ArrayLike) -> IntArray:
        """Voxel keys (N,) of ``points`` (N, 3) [m]; -1 outside the grid."""
        P = np.asarray(points, dtype=float).reshape(-1, 3)
        idx = np.floor(P / self.voxel).astype(np.int64) - np.asarray(self.start)
        inside = np.all((idx >= 0) & (idx < np.asarray(self.shape)), axis=1)
        keys = np.ravel_multi_index(tuple(np.where(inside, idx.T, 0)), self.shape)
        out: IntArray = np.where(inside, keys, -1)
        return out

    def centres(self, keys: npt.ArrayLike) -> Array:
        """Centres (N, 3) [m] of the voxels ``keys`` (N,)."""
        idx = np.stack(np.unravel_index(np.asarray(keys, dtype=np.int64), self.shape), axis=1)
        return np.asarray((idx + np.asarray(self.start) + 0.5) * self.voxel, dtype=np.float64)

    def to_dict(self) -> dict[str, object]:
        """The grid as JSON-ready values."""
        return {"start": list(self.start), "shape": list(self.shape), "voxel": self.voxel}

    @classmethod
    def from_dict(cls, d: dict[str, object]) -> Grid:
        """Inverse of :meth:`to_dict`."""
        return cls(_ints(d["start"]), _ints(d["shape"]), float(d["voxel"]))  # type: ignore[arg-type]


def _ints(v: object) -> tuple[int, int, int]:
    a = [int(x) for x in v]  # type: ignore[attr-defined]
    return a[0], a[1], a[2]


def chain_grid(chain: Chain, voxel: float) -> Grid:
    """The grid holding every reachable tool position of ``chain``.

    About its first joint's origin, of radius :meth:`Chain.reach` (plus the first joint's own
    travel, if prismatic).
    """
    centre = chain.trans[0]
    travel = max(abs(chain.lower[0]), abs(chain.upper[0])) if chain.kind[0] == 1 else 0.0
    return Grid.around(centre, chain.reach() + travel, voxel)


def quanta(chain: Chain, rows: int) -> Array:
    """Fixed-point quanta (2,) of the manipulability and sigma_min sums.

    ``sigma_max <= ||J||_F <= B`` (:meth:`Chain.jacobian_bound`), and by the arithmetic and
    geometric means ``prod(sigma_i) <= (||J||_F^2 / m)^(m / 2)``; each bound over
    2^:data:`SUM_BITS`.
    """
    b = chain.jacobian_bound(rows)
    return np.array([(b * b / rows) ** (rows / 2), b]) / 2.0**SUM_BITS


@dataclass
class VoxelStats:
    """Dense statistics over every voxel of a grid, merged from sparse results exactly.

    Memory: ``8 (count) + 8 (directions) + 24 (maxima) + 8 S + 8 M`` bytes a voxel of the
    grid (S sums, M minima: 64 bytes, 112 for barker6), whatever the samples.

    Attributes:
        fields: The columns.
        count: (V,) int64.
        dirs: (V,) uint64 direction bits.
        fmax: (V, 3) float64, ``-inf`` where nothing was computed.
        isum: (V, S) int64.
        imin: (V, M) int64, :data:`NONE` where no sample.
        outside: Samples that fell outside the grid (0 for a grid of :func:`chain_grid`).
    """

    fields: Fields
    count: IntArray
    dirs: npt.NDArray[np.uint64]
    fmax: Array
    isum: IntArray
    imin: IntArray
    outside: int = 0

    @classmethod
    def empty(cls, size: int, fields: Fields) -> VoxelStats:
        """Statistics of ``size`` voxels before any sample."""
        if size > MAX_KEYS:
            raise ValueError(f"{size} voxels: at most {MAX_KEYS}")
        return cls(
            fields,
            np.zeros(size, np.int64),
            np.zeros(size, np.uint64),
            np.full((size, len(fields.fmax)), -np.inf),
            np.zeros((size, len(fields.isum)), np.int64),
            np.full((size, len(fields.imin)), NONE, np.int64),
        )

    @property
    def nbytes(self) -> int:
        """Memory of the arrays [bytes]."""
        return sum(a.nbytes for a in (self.count, self.dirs, self.fmax, self.isum, self.imin))

    def merge(self, part: Sparse) -> None:
        """Add a sparse result (distinct keys) into these statistics, exactly."""
        k = part.keys
        self.count[k] += part.count
        self.dirs[k] |= part.dirs
        self.fmax[k] = np.maximum(self.fmax[k], part.fmax)
        self.isum[k] += part.isum
        self.imin[k] = np.minimum(self.imin[k], part.imin)
        self.outside += part.outside

    @classmethod
    def combine(cls, parts: Sequence[Sparse], fields: Fields) -> Sparse:
        """Sparse results (each of distinct keys) as one, reduced exactly by :meth:`merge`.

        The statistics of the union of their keys only: memory of the parts, not the grid.
        """
        keys, inverse = np.unique(np.concatenate([p.keys for p in parts]), return_inverse=True)
        union = cls.empty(keys.size, fields)
        start = 0
        for p in parts:
            end = start + p.keys.size
            union.merge(Sparse(inverse[start:end], p.count, p.dirs, p.fmax, p.isum, p.imin,
                               p.outside))  # fmt: skip
            start = end
        return Sparse(keys, union.count, union.dirs, union.fmax, union.isum, union.imin,
                      union.outside)  # fmt: skip

    def arrays(self) -> dict[str, npt.NDArray[Any]]:
        """Every column by name, (V,) each."""
        out: dict[str, npt.NDArray[Any]] = {"count": self.count, "directions": self.dirs}
        for cols, names in ((self.fmax, self.fields.fmax), (self.isum, self.fields.isum),
                            (self.imin, self.fields.imin)):  # fmt: skip
            out.update({name: cols[:, j] for j, name in enumerate(names)})
        return out

    @classmethod
    def from_arrays(cls, arrays: Mapping[str, npt.NDArray[Any]], fields: Fields) -> VoxelStats:
        """Inverse of :meth:`arrays` (copies into the dense layout)."""

        def cols(names: Sequence[str], dtype: type) -> npt.NDArray[Any]:
            return np.ascontiguousarray(
                np.stack([np.asarray(arrays[n]).reshape(-1) for n in names], axis=1), dtype=dtype
            )

        return cls(
            fields,
            np.asarray(arrays["count"], dtype=np.int64).reshape(-1).copy(),
            np.asarray(arrays["directions"], dtype=np.uint64).reshape(-1).copy(),
            cols(fields.fmax, np.float64),
            cols(fields.isum, np.int64),
            cols(fields.imin, np.int64),
        )

    def same_as(self, other: VoxelStats) -> bool:
        """Bit-identical statistics (every column equal, maxima compared as bits)."""
        return (
            self.fields == other.fields
            and self.outside == other.outside
            and np.array_equal(self.count, other.count)
            and np.array_equal(self.dirs, other.dirs)
            and np.array_equal(self.fmax.view(np.int64), other.fmax.view(np.int64))
            and np.array_equal(self.isum, other.isum)
            and np.array_equal(self.imin, other.imin)
        )
