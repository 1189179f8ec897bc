"""Sampling in fixed blocks: which samples a capability map draws, whatever the workers.

A map of ``samples`` draws is cut into blocks of ``block_size`` (2^15 by default; the last
block shorter). Block ``b`` draws its uniforms from its own stream,
``numpy.random.default_rng(SeedSequence(seed, spawn_key=(b,)))``, as ``random((len_b, n))``
rows, and takes ``q = lower + (upper - lower) u`` joint by joint (a continuous joint over
[-pi, pi]). A block's samples therefore depend on (seed, b) only: never on which worker draws
it, in which task, or in which order. Sample ``i`` of the map is row ``i mod block_size`` of
block ``i // block_size`` (its *global index*, the witnesses' unit), and the first ``k`` rows
of a block's stream do not depend on its length, so any one sample can be drawn again alone
(:func:`sample_at`).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.maps.batch import Chain

Array = npt.NDArray[np.float64]

BLOCK = 2**15
"""Samples per block, the unit of seeding, work and resumption."""


@dataclass(frozen=True)
class Plan:
    """The blocks of a map.

    Attributes:
        samples: Samples of the map (>= 1).
        block_size: Samples per block (the last block holds the rest).
    """

    samples: int
    block_size: int = BLOCK

    @property
    def blocks(self) -> int:
        """Number of blocks."""
        return -(-self.samples // self.block_size)

    def first(self, block: int) -> int:
        """Global index of the first sample of ``block``."""
        return block * self.block_size

    def length(self, block: int) -> int:
        """Samples in ``block``."""
        return min(self.block_size, self.samples - block * self.block_size)

    def tasks(self, blocks: Iterable[int], per_task: int) -> list[list[int]]:
        """``blocks`` in increasing order, cut into runs: the work of one task each.

        A run holds at most ``per_task`` consecutive blocks; a gap starts a new run.
        """
        out: list[list[int]] = []
        for b in sorted(blocks):
            if out and len(out[-1]) < per_task and out[-1][-1] == b - 1:
                out[-1].append(b)
            else:
                out.append([b])
        return out


def block_stream(seed: int, block: int) -> np.random.Generator:
    """The generator of ``block``: ``default_rng(SeedSequence(seed, spawn_key=(block,)))``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(block,)))


def block_samples(chain: Chain, seed: int, plan: Plan, block: int) -> Array:
    """The joint positions (len, n) [rad or m] of ``block``: uniform within the limits."""
    u = block_stream(seed, block).random((plan.length(block), chain.n))
    out: Array = chain.lower + (chain.upper - chain.lower) * u
    return out


def sample_at(chain: Chain, seed: int, plan: Plan, index: int | Sequence[int]) -> Array:
    """The samples of global indices ``index`` (one, (n,); several, (k, n)), drawn again.

    Raises:
        ValueError: An index outside ``[0, samples)``.
    """
    many = not isinstance(index, (int, np.integer))
    indices = np.atleast_1d(np.asarray(index, dtype=np.int64))
    if indices.size and (np.min(indices) < 0 or np.max(indices) >= plan.samples):
        raise ValueError(f"sample index outside [0, {plan.samples})")
    out = np.empty((indices.size, chain.n))
    blocks, rows = np.divmod(indices, plan.block_size)
    for block in np.unique(blocks):  # each block's stream drawn once, up to its last row
        sel = blocks == block
        u = block_stream(seed, int(block)).random((int(rows[sel].max()) + 1, chain.n))
        out[sel] = chain.lower + (chain.upper - chain.lower) * u[rows[sel]]
    return out if many else out[0]
