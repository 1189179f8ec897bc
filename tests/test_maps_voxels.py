"""Voxel grid and dense statistics: aligned voxels, exact merges, fixed-point bounds."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.maps.kinematics import chain_of
from rrc_pin.maps.voxels import SUM_BITS, Grid, VoxelStats, chain_grid, quanta
from rrc_pin.solvers.maps.batch import NONE, Fields, Rows, VoxelTable


def test_grid_is_aligned_and_keys_round_trip(rng):
    g = Grid.around([0.13, -0.2, 0.31], 0.9, 0.05)
    assert np.allclose(g.origin / 0.05, np.round(g.origin / 0.05))
    P = rng.uniform(-1.0, 1.0, size=(3000, 3))
    keys = g.keys_of(P)
    inside = keys >= 0
    assert inside.any() and not inside.all()
    C = g.centres(keys[inside])
    assert np.all(np.abs(C - P[inside]) <= 0.025 + 1e-12)
    assert np.array_equal(g.keys_of(C), keys[inside])
    u = g.union(Grid.around([2.0, 0.0, 0.0], 0.3, 0.05))
    assert u.size > g.size and np.array_equal(u.keys_of(C) >= 0, np.ones(len(C), bool))
    assert Grid.from_dict(g.to_dict()) == g


def test_the_chain_grid_holds_every_position_and_quanta_bound_the_values(rng):
    for name in ("panda", "nadkarni_c2", "kr5_3r"):
        robot = rrc_pin.load(name)
        chain, _ = chain_of(robot)
        rows = 6 if chain.n >= 6 else 3
        g = chain_grid(chain, 0.05)
        Q = chain.lower + (chain.upper - chain.lower) * rng.random((3000, chain.n))
        _, P, J = chain.batch(Q, rows)
        assert np.all(g.keys_of(P) >= 0)
        sv = np.linalg.svd(J, compute_uv=False)
        q = quanta(chain, rows)
        assert np.all(sv.prod(axis=1) / q[0] <= 2.0**SUM_BITS)
        assert np.all(sv[:, 0] / q[1] <= 2.0**SUM_BITS)


def test_merge_is_exact_whatever_the_grouping(rng):
    fields = Fields(("c",))
    rows = Rows.empty(4000, 1)
    rows.keys[:] = rng.integers(-1, 300, 4000)
    rows.dirs[:] = np.uint64(1) << rng.integers(0, 54, 4000).astype(np.uint64)
    rows.fmax[:] = rng.random((4000, 3))
    rows.isum[:] = rng.integers(0, 2**31, (4000, 3))
    rows.imin[:] = rng.integers(0, 10**6, (4000, 2))
    results = []
    for cuts in ([2000], [7, 1500, 3999], list(range(100, 4000, 100))):
        stats = VoxelStats.empty(300, fields)
        for idx in reversed(np.split(np.arange(4000), cuts)):
            t = VoxelTable(3, 2)
            t.add(Rows(*(getattr(rows, f)[idx] for f in ("keys", "count", "dirs", "fmax",
                                                          "isum", "imin"))))  # fmt: skip
            stats.merge(t.sparse())
        results.append(stats)
    assert all(results[0].same_as(r) for r in results[1:])
    assert results[0].count.sum() + results[0].outside == 4000
    empty = VoxelStats.empty(300, fields)
    assert np.all(empty.imin == NONE) and np.all(np.isneginf(empty.fmax))
    back = VoxelStats.from_arrays(results[0].arrays(), fields)
    back.outside = results[0].outside
    assert back.same_as(results[0])
    assert set(results[0].arrays()) == {"count", "directions", "manipulability_max",
        "sigma_min_max", "margin_max", "manipulability_sum", "sigma_min_sum", "c_count",
        "witness", "c_witness"}  # fmt: skip
    with pytest.raises(ValueError):
        VoxelStats.empty(2**31 + 1, fields)
