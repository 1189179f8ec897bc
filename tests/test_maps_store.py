"""The Zarr store of a map: written and read back bit-identical, foreign paths refused, every
file checked: a damaged store is an error naming the file, repaired by running the map again."""

from __future__ import annotations

import shutil
import warnings

import numpy as np
import pytest

pytest.importorskip("zarr")

from rrc_pin import maps
from rrc_pin.errors import CorruptStore, InvalidInput
from rrc_pin.maps import driver

pytestmark = pytest.mark.compiled


def test_round_trip(tmp_path):
    m = maps.capability("barker6", 3000, 0.1, seed=2, block_size=1024, progress=False,
                        workers=1)  # fmt: skip
    path = maps.save_map(m, tmp_path / "m.zarr")
    back = maps.load_map(path)
    assert back.grid == m.grid and back.stats.same_as(m.stats)
    assert back.meta["arm"] == "barker6" and back.meta["conditions"] == ["eq32", "eq33", "s5"]
    assert np.array_equal(back.chain.rot, m.chain.rot)
    k = np.flatnonzero(m.reached)[:5]
    assert np.array_equal(back.witnesses(k), m.witnesses(k))
    P = m.grid.centres(k)
    for a, b in zip(back.at(P), m.at(P), strict=True):
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f")


def test_a_path_that_is_not_a_map_is_refused(tmp_path):
    with pytest.raises(InvalidInput) as err:
        maps.load_map(tmp_path / "nothing.zarr")
    assert err.value.argument == "path"


# -- a finished store, damaged at random --------------------------------------------------

SMALL = {"samples": 24 * 2**10, "voxel": 0.1, "seed": 3, "block_size": 2**10,
         "blocks_per_task": 1, "progress": False}  # fmt: skip
"""24 blocks, one a task: 24 parts, folded four by four (six folds)."""


@pytest.fixture(scope="module")
def client():
    distributed = pytest.importorskip("distributed")
    with driver.local_cluster(1) as cluster, distributed.Client(cluster) as c:
        yield c


@pytest.fixture(scope="module")
def finished(tmp_path_factory, client):
    """A finished map's folder (the store, its blocks, its summary) and the map."""
    folder = tmp_path_factory.mktemp("finished")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(driver, "FOLD_PARTS", 4)
        m = maps.capability("kr5_3r", out=folder, scheduler=client, **SMALL)
    assert len(list((folder / "blocks").glob("fold-*.npz"))) == 6
    return folder, m


def _damage(path, kind, rng):
    data = bytearray(path.read_bytes())
    if kind == "delete":
        path.unlink()
    elif kind == "truncate":
        path.write_bytes(bytes(data[: int(rng.integers(len(data)))]))
    else:  # one to four bytes flipped
        for i in rng.choice(len(data), size=min(len(data), int(rng.integers(1, 5))),
                            replace=False):  # fmt: skip
            data[i] ^= int(rng.integers(1, 256))
        path.write_bytes(bytes(data))


def test_random_damage_is_detected_named_and_repaired_exactly(finished, client, tmp_path):
    """100 corruptions (bytes flipped, truncated, files deleted), each of a fresh copy of a
    finished map's folder: a damaged file of the store is named by ``load_map`` (never a
    wrong value); a damaged file of its blocks by the resume; the resume computes again only
    the blocks of the file damaged and gives the same bits as the map never damaged."""
    folder, whole = finished
    seed = int(np.random.SeedSequence().entropy % 2**63)
    rng = np.random.default_rng(seed)
    areas = {a: sorted(p.relative_to(folder) for p in (folder / a).rglob("*") if p.is_file())
             for a in ("map.zarr", "blocks")}  # fmt: skip
    for trial in range(100):
        case = tmp_path / f"case{trial}"
        shutil.copytree(folder, case)
        files = areas["map.zarr" if rng.random() < 0.5 else "blocks"]
        name = files[int(rng.integers(len(files)))]
        kind = str(rng.choice(["flip", "truncate", "delete"]))
        why = f"seed {seed}, trial {trial}: {kind} {name}"
        lost = 0
        if name.name.startswith("fold-"):
            with np.load(case / name) as z:
                lost = z["blocks"].size
        _damage(case / name, kind, rng)
        if name.parts[0] == "map.zarr":
            with pytest.raises(CorruptStore) as err:
                maps.load_map(case / "map.zarr")
            inside = name.relative_to("map.zarr").as_posix()
            assert inside in err.value.files and inside in str(err.value), why
            assert "again" in err.value.repair, why
        else:
            assert maps.load_map(case / "map.zarr").stats.same_as(whole.stats), why
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            resumed = maps.capability("kr5_3r", out=case, scheduler=client, **SMALL)
        run = resumed.meta["run"]
        if name.parts[0] == "blocks":
            assert name.name in run["damaged"], why
            assert any(name.name in str(w.message) for w in caught), why
        assert run["blocks_computed"] == lost and run["blocks_resumed"] == 24 - lost, why
        assert resumed.stats.same_as(whole.stats), why
        assert maps.load_map(case / "map.zarr").stats.same_as(whole.stats), why
        shutil.rmtree(case)
