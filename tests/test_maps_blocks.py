"""Partial results on disk: parts, folds, resumption, damaged files set aside and named, foreign
folders refused."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from rrc_pin.errors import ForeignMap
from rrc_pin.maps import checksums
from rrc_pin.maps.blocks import MANIFEST, BlockStore, fingerprint
from rrc_pin.maps.voxels import VoxelStats
from rrc_pin.solvers.maps.batch import Fields, Sparse


def _part(keys, value):
    k = np.asarray(keys, dtype=np.int64)
    n = len(k)
    return Sparse(k, np.full(n, 2, np.int64), np.ones(n, np.uint64), np.full((n, 3), value),
                  np.ones((n, 2), np.int64), np.full((n, 1), 5, np.int64), 1)  # fmt: skip


def _store(folder, definition=None, size=50):
    store = BlockStore(folder, definition or {"arm": "x", "seed": 1}, Fields(), size)
    store.check()
    return store


def test_parts_folds_and_load(tmp_path):
    store = _store(tmp_path / "blocks")
    stats, done = store.load()
    assert not done and (tmp_path / "blocks" / MANIFEST).is_file()
    store.write_part([0, 1], _part([3, 4], 0.5))
    store.write_part([2], _part([4, 9], 0.7))
    stats, done = _store(tmp_path / "blocks").load()
    assert done == {0, 1, 2} and stats.count[4] == 4 and stats.fmax[4, 0] == 0.7
    assert stats.outside == 2
    (left_over,) = [p for p, blocks in store.parts() if blocks == [2]]
    kept = left_over.read_bytes()
    store.fold()
    assert not store.parts() and len(list((tmp_path / "blocks").glob("fold-*.npz"))) == 1
    store.write_part([3], _part([9], 0.9))
    left_over.write_bytes(kept)  # a part a stop left after the fold that holds it
    again = _store(tmp_path / "blocks")
    with_fold, done2 = again.load()
    assert done2 == {0, 1, 2, 3} and with_fold.count[9] == 4 and with_fold.fmax[9, 0] == 0.9
    assert not left_over.exists() and not again.damaged
    again.fold()
    third, _ = _store(tmp_path / "blocks").load()
    assert third.same_as(with_fold)
    assert len(list((tmp_path / "blocks").glob("fold-*.npz"))) == 2


def test_a_fold_is_the_exact_reduction_of_its_parts():
    rng = np.random.default_rng(7)
    parts = []
    for _ in range(5):
        keys = rng.choice(200, size=40, replace=False)
        p = _part(keys, 0.0)
        p.fmax[:] = rng.normal(size=p.fmax.shape)
        p.imin[:] = rng.integers(0, 1000, size=p.imin.shape)
        parts.append(p)
    dense = VoxelStats.empty(200, Fields())
    for p in parts:
        dense.merge(p)
    folded = VoxelStats.empty(200, Fields())
    folded.merge(VoxelStats.combine(parts, Fields()))
    assert folded.same_as(dense)


def test_damaged_and_missing_files_are_set_aside_named_and_their_blocks_dropped(tmp_path):
    folder = tmp_path / "blocks"
    store = _store(folder)
    store.load()
    store.write_part([0], _part([1], 0.1))
    store.fold()
    (fold,) = folder.glob("fold-*.npz")
    store.write_part([1], _part([2], 0.2))
    store.write_part([2], _part([3], 0.3))
    (p1, _), (p2, _) = store.parts()
    data = bytearray(p1.read_bytes())
    data[len(data) // 2] ^= 0x40
    p1.write_bytes(bytes(data))
    fold.unlink()
    other = BlockStore(tmp_path / "x", {"arm": "y"}, Fields(), 50)
    other.load()
    stray = other.write_part([5], _part([7], 9.0))
    shutil.move(stray, folder / stray.name)  # another map's part in this folder
    again = _store(folder)
    with pytest.warns(RuntimeWarning) as record:
        stats, done = again.load()
    assert done == {2} and stats.count.sum() == 2
    messages = " ".join(str(w.message) for w in record)
    for path in (fold, p1, folder / stray.name):
        assert path.name in messages and path.name in again.damaged
    assert (folder / (p1.name + ".damaged")).is_file() and not p1.exists()
    assert p2.exists() and "missing" in messages


def test_a_damaged_or_missing_manifest_is_written_again(tmp_path):
    folder = tmp_path / "blocks"
    store = _store(folder)
    store.load()
    store.write_part([0], _part([1], 0.1))
    store.fold()
    whole = (folder / MANIFEST).read_bytes()
    for damage in (whole.replace(b'"seed": 1', b'"seed": 2'), whole[:-3], b"", None):
        if damage is None:
            (folder / MANIFEST).unlink()
        else:
            (folder / MANIFEST).write_bytes(damage)
        again = _store(folder)  # not refused: every whole file is this map's
        with pytest.warns(RuntimeWarning, match=MANIFEST):
            _, done = again.load()
        assert done == {0} and (folder / MANIFEST).read_bytes() == whole


def test_foreign_folders_are_refused(tmp_path):
    mine = {"arm": "panda", "seed": 1, "voxel": 0.05}
    store = BlockStore(tmp_path / "blocks", mine, Fields(), 10)
    store.load()
    manifest = checksums.unseal((tmp_path / "blocks" / MANIFEST).read_bytes())
    assert manifest is not None and manifest["fingerprint"] == fingerprint(mine)
    other = BlockStore(tmp_path / "blocks", {**mine, "seed": 2}, Fields(), 10)
    with pytest.raises(ForeignMap) as err:
        other.check()
    assert err.value.argument == "out" and "seed" in str(err.value)
    store.write_part([0], _part([1], 0.5))
    (tmp_path / "blocks" / MANIFEST).write_text("{broken")  # whose are the parts, then?
    store.check()  # this map's: fine
    with pytest.raises(ForeignMap, match="another map"):
        other.check()
    bare = tmp_path / "bare"
    bare.mkdir()
    (bare / "state.npz").write_bytes(b"")
    with pytest.raises(ForeignMap, match="without a manifest"):
        BlockStore(bare, mine, Fields(), 10).check()
    BlockStore(tmp_path / "new", mine, Fields(), 10).check()  # absent or empty: fine
    assert not (tmp_path / "new").exists()
    old = tmp_path / "old"
    old.mkdir()
    (old / MANIFEST).write_bytes(checksums.seal({"format": 1, "fingerprint": fingerprint(mine),
                                                 "definition": mine}))  # fmt: skip
    with pytest.raises(ForeignMap, match="layout 1"):
        BlockStore(old, mine, Fields(), 10).check()
    assert json.loads((old / MANIFEST).read_text())["format"] == 1
