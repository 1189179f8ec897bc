"""Base placement of a second arm: each placement one task, the same samples for every one."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("distributed")

from rrc_pin import maps
from rrc_pin.errors import InvalidInput

pytestmark = pytest.mark.compiled


@pytest.fixture(scope="module")
def first():
    return maps.capability("kr5_3r", 2**17, 0.1, seed=1, progress=False, workers=2)


def test_placements_are_scored_by_the_shared_dexterous_volume(first):
    region = ((0.3, -0.3, 0.0), (0.7, 0.3, 0.4))
    T = maps.placements_grid([0.9, 1.0, 4.0], [0.0], [np.pi, 0.0])
    search = maps.base_placement(first, "kr5_3r", region, T, samples=2**16, min_coverage=0.05,
                                 workers=2)  # fmt: skip
    assert search.shared_volume.shape == (6,)
    assert np.all(search.region.keys_of(np.array(region)) >= 0)  # the region's corners
    assert np.all(search.shared_volume[4:] == 0)  # 4 m away: nothing shared
    assert search.shared_volume[:4].max() > 0
    assert search.best in (0, 1, 2, 3)
    assert "| 1 |" in search.table(3)
    text = repr(search)
    assert "\n" not in text and len(text) < 200 and f"6 placements, best #{search.best}" in text
    again = maps.base_placement(first, "kr5_3r", region, T[:2], samples=2**16,
                                min_coverage=0.05, workers=1)  # fmt: skip
    assert np.array_equal(again.shared_volume, search.shared_volume[:2])


def test_bad_placement_arguments(first):
    T = maps.placements_grid([1.0], [0.0])
    for kwargs, argument in (
        ({"region": ((0, 0, 0), (-1, 0, 0))}, "region"),
        ({"placements": np.eye(3)}, "placements"),
        ({"min_coverage": 0.0}, "min_coverage"),
        ({"samples": 0}, "samples"),
    ):
        call = {"region": ((0, 0, 0), (0.2, 0.2, 0.2)), "placements": T, **kwargs}
        with pytest.raises(InvalidInput) as err:
            maps.base_placement(first, "kr5_3r", **call)
        assert err.value.argument == argument
