"""The map's pictures: without matplotlib nothing is drawn (the files themselves are drawn
and checked by tests/test_cli.py's `rrc-pin map` runs, an arm's and a cell's)."""

from __future__ import annotations

import sys

import numpy as np
import pytest

pytest.importorskip("distributed")

from rrc_pin import maps
from rrc_pin.maps import plots

pytestmark = pytest.mark.compiled


def test_without_matplotlib_nothing_is_drawn(tmp_path, monkeypatch):
    m = maps.capability("kr5_3r", 2**10, 0.3, seed=1, progress=False, workers=1,
                        block_size=2**10)  # fmt: skip
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    assert plots.plot_map(m, tmp_path) is False
    assert not list(tmp_path.iterdir())


def test_slices_cut_the_grid_through_a_point():
    m = maps.capability("kr5_3r", 2**12, 0.2, seed=1, progress=False, workers=1,
                        block_size=2**12)  # fmt: skip
    cut = plots.slice_values(m.grid, m.coverage, 2, 0.1)
    assert cut.shape == (m.grid.shape[0], m.grid.shape[1])
    k = m.grid.keys_of([[0.5, 0.3, 0.1]])[0]
    i, j, _ = np.unravel_index(k, m.grid.shape)
    assert cut[i, j] == m.coverage[k]
