"""Typed entry points of the capability maps' compiled kernels (:mod:`.kernels`).

- :class:`Chain`: a serial chain as arrays (joint placements, kinds, limits), every joint
  about or along its frame's z axis; its pose and Jacobian at one configuration, and bounds
  of its reach and of its Jacobian's norm.
- :class:`Rows`: the per-sample rows of one block (voxel key, direction bit, maxima,
  fixed-point sums, minima), filled by :func:`chain_rows` or :func:`batch_rows`.
- :class:`VoxelTable`: the exact accumulation of rows into voxels (a hash table that grows),
  and :class:`Sparse`, what it holds: one aggregate per voxel reached.

Numpy and numba only: no Pinocchio, no files.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.maps import kernels as _k

Array = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
BitArray = npt.NDArray[np.uint64]

REVOLUTE = _k.REVOLUTE
PRISMATIC = _k.PRISMATIC
BINS = _k.BINS
NONE = _k.NONE
MAX_KEYS = _k.MAX_KEYS
FMAX = ("manipulability_max", "sigma_min_max", "margin_max")
"""The maxima of a row, in column order (float64; ``-inf`` when not computed)."""
ISUM = ("manipulability_sum", "sigma_min_sum")
"""The fixed-point sums of a row, before the conditions' counts (int64)."""
IMIN = ("witness",)
"""The minima of a row, before the conditions' first samples (int64)."""


@dataclass(frozen=True)
class Chain:
    """A serial chain of joints, each turning about or sliding along its frame's z axis.

    Attributes:
        rot: Placement rotations (n + 1, 3, 3): joint k's frame in joint k-1's moved frame
            (the first in the base frame); the last, the tool frame in joint n's.
        trans: Placement translations (n + 1, 3) [m].
        kind: :data:`REVOLUTE` or :data:`PRISMATIC` per joint (n,), int64.
        lower: Joint lower limits (n,) [rad or m], finite.
        upper: Joint upper limits (n,) [rad or m], finite (a continuous joint: [-pi, pi]).
        bounded: Whether a joint's range is a limit (n,): False for continuous joints, whose
            margin to a limit is not counted.
    """

    rot: Array
    trans: Array
    kind: IntArray
    lower: Array
    upper: Array
    bounded: npt.NDArray[np.bool_]

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.kind.shape[0])

    @property
    def span(self) -> Array:
        """Ranges of the bounded joints (n,) [rad or m], 0 for the others (the margins')."""
        return np.where(self.bounded, self.upper - self.lower, 0.0)

    def pose(self, q: npt.ArrayLike) -> tuple[Array, Array]:
        """The tool's rotation (3, 3) and origin (3,) [m] at ``q`` (n,), in the base frame."""
        R, P, _ = self.batch(np.reshape(q, (1, self.n)))
        return R[0], P[0]

    def jacobian(self, q: npt.ArrayLike, rows: int = 6) -> Array:
        """Geometric Jacobian (rows, n) of the tool origin, rows [v; w] in base axes.

        ``rows`` = 6 (full twist) or 3 (linear velocity only).
        """
        J: Array = self.batch(np.reshape(q, (1, self.n)), rows)[2][0]
        return J

    def batch(self, Q: npt.ArrayLike, rows: int = 6) -> tuple[Array, Array, Array]:
        """Tool rotations (N, 3, 3), origins (N, 3) [m] and Jacobians (N, rows, n) at ``Q``.

        ``Q`` (N, n): the configurations, evaluated in one compiled loop.
        """
        Qa = np.ascontiguousarray(Q, dtype=np.float64).reshape(-1, self.n)
        N = Qa.shape[0]
        R, P, J = np.empty((N, 3, 3)), np.empty((N, 3)), np.empty((N, rows, self.n))
        _k.chain_batch(self.rot, self.trans, self.kind, Qa, R, P, J)
        return R, P, J

    def reach(self) -> float:
        """Bound on the tool's distance to the first joint's origin [m].

        The placements after the first joint and the tool's, plus the largest travel of
        every prismatic joint: ``|p - o_1| <= sum_k |t_k| + sum_prismatic max|q_k|``.
        """
        travel = np.maximum(np.abs(self.lower), np.abs(self.upper))
        return float(
            np.linalg.norm(self.trans[1:], axis=1).sum()
            + travel[self.kind == PRISMATIC].sum()
        )

    def jacobian_bound(self, rows: int) -> float:
        """Bound on the task Jacobian's Frobenius norm (>= its largest singular value).

        A revolute column is ``[z x (p - o); z]``: its squared norm is at most the squared
        reach from that joint plus 1 (with the angular rows); a prismatic one's at most 1.
        """
        travel = np.maximum(np.abs(self.lower), np.abs(self.upper))
        lengths = np.linalg.norm(self.trans, axis=1)
        total = 0.0
        for k in range(self.n):
            if self.kind[k] == PRISMATIC:
                total += 1.0
                continue
            after = lengths[k + 1 :].sum() + travel[k + 1 :][self.kind[k + 1 :] == PRISMATIC].sum()
            total += after**2 + (1.0 if rows == 6 else 0.0)
        return float(np.sqrt(total))


@dataclass(frozen=True)
class Fields:
    """The columns of a map's statistics: the common ones and one pair per condition.

    Attributes:
        conditions: Condition names (barker6: ``eq32``, ``eq33``, ``s5``).
    """

    conditions: tuple[str, ...] = ()

    @property
    def fmax(self) -> tuple[str, ...]:
        """Names of the maxima."""
        return FMAX

    @property
    def isum(self) -> tuple[str, ...]:
        """Names of the sums."""
        return ISUM + tuple(f"{c}_count" for c in self.conditions)

    @property
    def imin(self) -> tuple[str, ...]:
        """Names of the minima."""
        return IMIN + tuple(f"{c}_witness" for c in self.conditions)


@dataclass
class Rows:
    """The per-sample rows of one block: its samples' voxels, directions and statistics.

    Attributes:
        keys: Voxel keys (N,), -1 outside the grid.
        count: Samples per row (N,): ones.
        dirs: The bit of each sample's direction bin (N,), uint64.
        fmax: Maxima (N, 3): :data:`FMAX`.
        isum: Fixed-point sums and condition counts (N, 2 + C): :data:`ISUM`, then one per
            condition.
        imin: Minima (N, 1 + C): :data:`IMIN` (the sample's global index), then per condition
            the index where it holds (:data:`NONE` elsewhere).
    """

    keys: IntArray
    count: IntArray
    dirs: BitArray
    fmax: Array
    isum: IntArray
    imin: IntArray

    @classmethod
    def empty(cls, n: int, conditions: int = 0) -> Rows:
        """Buffers for ``n`` rows with ``conditions`` condition columns."""
        return cls(
            np.empty(n, np.int64),
            np.ones(n, np.int64),
            np.empty(n, np.uint64),
            np.empty((n, len(FMAX))),
            np.empty((n, len(ISUM) + conditions), np.int64),
            np.empty((n, len(IMIN) + conditions), np.int64),
        )

    def head(self, n: int) -> Rows:
        """The first ``n`` rows (views)."""
        return Rows(
            self.keys[:n], self.count[:n], self.dirs[:n], self.fmax[:n], self.isum[:n],
            self.imin[:n],
        )  # fmt: skip


@dataclass(frozen=True)
class GridArrays:
    """A voxel grid as the kernels take it.

    Attributes:
        start: Index (3,) of the grid's first voxel along x, y, z, int64: voxels are
            aligned on multiples of ``voxel`` in the base frame, voxel ``(i, j, k)`` of the
            grid spans ``[(start_x + i) voxel, (start_x + i + 1) voxel)`` and alike.
        voxel: Edge of a voxel [m].
        shape: Voxels along x, y, z (3,), int64; keys are ``(ix ny + iy) nz + iz``.
    """

    start: IntArray
    voxel: float
    shape: IntArray


def chain_rows(
    chain: Chain,
    Q: Array,
    grid: GridArrays,
    rows: int,
    dexterity: bool,
    quanta: Array,
    first: int,
    out: Rows,
) -> None:
    """Fill ``out``'s first N rows from the samples ``Q`` (N, n) of ``chain``.

    Args:
        chain: The serial chain.
        Q: Joint positions (N, n) [rad or m], C-contiguous float64.
        grid: The voxel grid.
        rows: Task rows: 3 (position) or 6 (full twist).
        dexterity: Compute manipulability and sigma_min (one-sided Jacobi SVD per sample).
        quanta: Fixed-point quanta (2,) of the manipulability and sigma_min sums.
        first: Global index of the first sample.
        out: Rows with at least N rows and no condition columns.
    """
    _k.chain_rows(
        chain.rot, chain.trans, chain.kind, Q, chain.lower, chain.span, grid.start,
        grid.voxel, grid.shape, rows, dexterity, quanta, first, out.keys, out.dirs, out.fmax,
        out.isum, out.imin,
    )  # fmt: skip


def batch_rows(
    P: Array,
    Z: Array,
    J: Array,
    flags: npt.NDArray[np.bool_],
    Q: Array,
    chain: Chain,
    grid: GridArrays,
    dexterity: bool,
    quanta: Array,
    first: int,
    out: Rows,
) -> None:
    """Fill ``out``'s first N rows from kinematics computed by a batch closed form.

    Args:
        P: Tool origins (N, 3) [m].
        Z: Tool z axes (N, 3) (the third column of the tool's rotation).
        J: Task Jacobians (N, rows, n) (read with ``dexterity`` only).
        flags: Conditions holding at each sample (N, C), counted and witnessed per voxel.
        Q: The samples (N, n) [rad] (their joint-limit margins).
        chain: The arm's chain (its limits).
        grid: The voxel grid.
        dexterity: Compute manipulability and sigma_min from ``J``.
        quanta: Fixed-point quanta (2,) of their sums.
        first: Global index of the first sample.
        out: Rows with at least N rows and C condition columns.
    """
    _k.batch_rows(
        P, Z, J, flags, Q, chain.lower, chain.span, grid.start, grid.voxel, grid.shape,
        dexterity, quanta, first, out.keys, out.dirs, out.fmax, out.isum, out.imin,
    )  # fmt: skip


def singular_values(J: npt.ArrayLike) -> Array:
    """Singular values of ``J`` (m, n), m <= n, descending, by one-sided Jacobi (m,)."""
    A = np.array(J, dtype=np.float64)[:, :, None]  # a tile of one matrix
    sv = np.zeros((A.shape[0], 1))
    _k.singular_values(A, 1, sv)
    out: Array = sv[:, 0]
    return out


def direction_bins(Z: npt.ArrayLike) -> IntArray:
    """Direction bin (0..53) of each unit direction, rows of ``Z`` (N, 3)."""
    D = np.asarray(Z, dtype=np.float64).reshape(-1, 3)
    return np.array([_k.direction_bin(x, y, z) for x, y, z in D], dtype=np.int64)


@dataclass
class Sparse:
    """Aggregates of the voxels reached, one row per voxel (keys distinct, in no order).

    Attributes:
        keys: Voxel keys (K,).
        count: Samples per voxel (K,).
        dirs: Direction bins reached, as bits (K,), uint64.
        fmax: Maxima (K, 3) (:data:`FMAX`).
        isum: Sums (K, S) (:data:`ISUM`, then condition counts).
        imin: Minima (K, M) (:data:`IMIN`, then the conditions' first samples).
        outside: Samples that fell outside the grid.
    """

    keys: IntArray
    count: IntArray
    dirs: BitArray
    fmax: Array
    isum: IntArray
    imin: IntArray
    outside: int = 0

    @property
    def nbytes(self) -> int:
        """Size of the arrays [bytes]."""
        return sum(
            a.nbytes for a in (self.keys, self.count, self.dirs, self.fmax, self.isum, self.imin)
        )


class VoxelTable:
    """Rows accumulated exactly into voxels: an open-addressing hash table that doubles.

    A slot is one row of an int64 array (key, count, direction bits, the sums, the minima)
    and one row of a float64 array (the maxima). The capacity is a power of two kept at least
    twice the voxels the table may hold after the next rows, so a probe always ends; it grows
    (by re-adding its own slots into a table twice as large) before a batch of rows could fill
    it past half. Memory: ``8 (3 + S + M + F)`` bytes a slot (72 for a chain, 120 for
    barker6), two to four slots per distinct voxel added, so at most that for
    ``min(voxels of the grid, rows added)`` voxels.

    Args:
        sums: Sum columns (S, at least 2).
        minima: Minimum columns (M, at least 1).
        capacity: Initial slots (rounded up to a power of two).
    """

    def __init__(self, sums: int, minima: int, capacity: int = 1 << 12) -> None:
        self._sums, self._minima = sums, minima
        self.filled = 0
        self.outside = 0
        self._alloc(1 << max(int(capacity - 1).bit_length(), 1))

    def _alloc(self, cap: int) -> None:
        self.table: IntArray = np.zeros((cap, 3 + self._sums + self._minima), np.int64)
        self.table[:, 0] = _k.EMPTY
        self.tmax: Array = np.empty((cap, len(FMAX)))

    @property
    def capacity(self) -> int:
        """Slots of the table."""
        return int(self.table.shape[0])

    @property
    def nbytes(self) -> int:
        """Memory of the table [bytes]."""
        return int(self.table.nbytes + self.tmax.nbytes)

    def add(self, rows: Rows) -> None:
        """Accumulate ``rows`` (their ``count`` column says how many samples each stands for)."""
        need = 2 * (self.filled + rows.keys.shape[0])
        if need > self.capacity:
            self._grow(need)
        filled, outside = _k.accumulate(
            rows.keys, rows.count, rows.dirs, rows.fmax, rows.isum, rows.imin, self.table,
            self.tmax,
        )  # fmt: skip
        self.filled += int(filled)
        self.outside += int(outside)

    def add_sparse(self, sparse: Sparse) -> None:
        """Accumulate another table's content."""
        self.add(
            Rows(sparse.keys, sparse.count, sparse.dirs, sparse.fmax, sparse.isum, sparse.imin)
        )
        self.outside += sparse.outside

    def _grow(self, need: int) -> None:
        old = self.sparse()
        cap = self.capacity
        while cap < need:
            cap *= 2
        self._alloc(cap)
        self.filled = 0
        self.add(Rows(old.keys, old.count, old.dirs, old.fmax, old.isum, old.imin))
        self.outside = old.outside

    def sparse(self) -> Sparse:
        """The voxels held, as a :class:`Sparse` (copies, columns apart)."""
        used = np.flatnonzero(self.table[:, 0] != _k.EMPTY)
        t = self.table[used]
        s = 3 + self._sums
        return Sparse(
            np.ascontiguousarray(t[:, 0]), np.ascontiguousarray(t[:, 1]),
            np.ascontiguousarray(t[:, 2]).view(np.uint64), self.tmax[used],
            np.ascontiguousarray(t[:, 3:s]), np.ascontiguousarray(t[:, s:]), self.outside,
        )  # fmt: skip
