"""Partial results on disk: parts, checkpoints, resumption, foreign folders refused."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rrc_pin.errors import ForeignMap
from rrc_pin.maps.blocks import BlockStore, fingerprint
from rrc_pin.maps.voxels import VoxelStats
from rrc_pin.solvers.maps.batch import Fields, Sparse


def _part(keys, value):
    k = np.asarray(keys, dtype=np.int64)
    n = len(k)
    return Sparse(k, np.full(n, 2, np.int64), np.ones(n, np.uint64), np.full((n, 3), value),
                  np.ones((n, 2), np.int64), np.full((n, 1), 5, np.int64), 1)  # fmt: skip


def test_parts_checkpoint_and_load(tmp_path):
    store = BlockStore(tmp_path / "blocks", {"arm": "x", "seed": 1}, Fields(), 50)
    store.check()
    store.create()
    store.write_part([0, 1], _part([3, 4], 0.5))
    store.write_part([2], _part([4, 9], 0.7))
    stats, done = store.load()
    assert done == {0, 1, 2} and stats.count[4] == 4 and stats.fmax[4, 0] == 0.7
    assert stats.outside == 2
    store.checkpoint(stats, done)
    assert not list((tmp_path / "blocks").glob("part-*"))
    store.write_part([3], _part([9], 0.9))
    again, done2 = store.load()
    assert done2 == {0, 1, 2, 3} and again.count[9] == 4 and again.fmax[9, 0] == 0.9
    # a part left over after a checkpoint that already holds it is not counted twice
    store.checkpoint(again, done2)
    store.write_part([3], _part([9], 0.9))
    third, _ = store.load()
    assert third.same_as(again)


def test_foreign_folders_are_refused(tmp_path):
    mine = {"arm": "panda", "seed": 1, "voxel": 0.05}
    store = BlockStore(tmp_path / "blocks", mine, Fields(), 10)
    store.create()
    manifest = json.loads((tmp_path / "blocks" / "manifest.json").read_text())
    assert manifest["fingerprint"] == fingerprint(mine)
    other = BlockStore(tmp_path / "blocks", {**mine, "seed": 2}, Fields(), 10)
    with pytest.raises(ForeignMap) as err:
        other.check()
    assert err.value.argument == "out" and "seed" in str(err.value)
    (tmp_path / "blocks" / "manifest.json").write_text("{broken")
    with pytest.raises(ForeignMap, match="unreadable"):
        store.check()
    bare = tmp_path / "bare"
    bare.mkdir()
    (bare / "state.npz").write_bytes(b"")
    with pytest.raises(ForeignMap, match="without a manifest"):
        BlockStore(bare, mine, Fields(), 10).check()
    BlockStore(tmp_path / "new", mine, Fields(), 10).check()  # absent or empty: fine
    assert not (tmp_path / "new").exists()


def test_a_stats_checkpoint_is_sparse(tmp_path):
    stats = VoxelStats.empty(10_000, Fields())
    stats.merge(_part([1, 9000], 0.3))
    store = BlockStore(tmp_path, {"a": 1}, Fields(), 10_000)
    store.create()
    store.checkpoint(stats, {0})
    with np.load(tmp_path / "state.npz") as z:
        assert z["keys"].tolist() == [1, 9000]
