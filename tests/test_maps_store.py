"""The Zarr store of a map: written and read back bit-identical, foreign paths refused."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("zarr")

from rrc_pin import maps
from rrc_pin.errors import InvalidInput

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
