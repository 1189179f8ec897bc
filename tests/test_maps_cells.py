"""Cell maps: every tool frame on one grid; an arm's map in a cell is its own map, placed."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("distributed")

import rrc_pin
from rrc_pin import maps

pytestmark = pytest.mark.compiled

KW = {"block_size": 2**12, "progress": False, "workers": 2, "seed": 6}


@pytest.fixture(scope="module")
def two_pandas():
    panda = rrc_pin.load("panda")
    T = np.eye(4)
    T[0, 3] = 1.0  # 20 voxels of 5 cm along x: the voxels of the two arms align
    cell = rrc_pin.combine({"left": (panda, np.eye(4)), "right": (rrc_pin.load("panda"), T)})
    return panda, cell


def test_cell_map_combines_the_frames(two_pandas, tmp_path):
    panda, cell = two_pandas
    c = maps.cell_map(cell, 8 * 2**12, 0.05, out=tmp_path, **KW)
    assert c.frames == ("left/panda_hand_tcp", "right/panda_hand_tcp")
    assert all(m.grid == c.grid for m in c.maps)
    assert np.array_equal(c.arms, c.maps[0].reached.astype(int) + c.maps[1].reached)
    assert c.shared.any() and not c.shared.all()
    weaker = np.minimum(c.maps[0].coverage, c.maps[1].coverage)
    assert np.all(c.combined_coverage[c.shared] <= weaker[c.shared])
    assert np.all(c.combined_coverage[~c.shared] == 0)
    both, only = np.flatnonzero(c.shared)[0], np.flatnonzero(c.arms == 1)[0]
    points = np.vstack([c.grid.centres([both, only]), [[5.0, 0.0, 0.0]]])
    mid = c.at(points)
    assert mid.arms.tolist() == [2, 1, 0] and mid.coverage.shape == (3, 2)
    text = repr(c)  # a summary, the arrays as attributes
    assert "\n" not in text and len(text) < 200 and "left/panda_hand_tcp" in text
    assert mid.combined_coverage[0] > 0 and np.isnan(mid.combined_manipulability[1])
    s = c.summary()
    assert 0 < s["shared_volume_m3"] < s["volume_m3[left/panda_hand_tcp]"]
    assert (tmp_path / "0_left-panda_hand_tcp" / "map.zarr").is_dir()
    assert (tmp_path / "summary.md").exists()
    # the left arm of the cell is panda's own map (same chain, seed and samples), on the
    # cell's larger grid: the same counts voxel by voxel
    alone = maps.capability(panda, 8 * 2**12, 0.05, **KW)
    keys = np.flatnonzero(alone.reached)
    inner = c.grid.keys_of(alone.grid.centres(keys))
    assert np.array_equal(c.maps[0].stats.count[inner], alone.stats.count[keys])
    assert c.maps[0].stats.count.sum() == alone.stats.count.sum()
    # the right arm is the same map shifted by 1 m (a few samples may round into a neighbour)
    right = c.grid.keys_of(alone.grid.centres(keys) + np.array([1.0, 0.0, 0.0]))
    same = c.maps[1].stats.count[right] == alone.stats.count[keys]
    assert same.mean() > 0.99


def test_one_frame_cell_and_bad_cell(two_pandas):
    with pytest.raises(rrc_pin.InvalidInput) as err:
        maps.cell_map(two_pandas[1], 1000, -1.0, **KW)
    assert err.value.argument == "voxel"
    one = maps.cell_map("kr5_3r", 2**12, 0.2, **KW)
    assert one.frames == ("tool",) and not one.shared.any()
