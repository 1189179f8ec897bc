"""The map's pictures: slices and a 3-D view, for an arm and a cell."""

from __future__ import annotations

import pytest

pytest.importorskip("matplotlib")
pytest.importorskip("distributed")

import numpy as np

import rrc_pin
from rrc_pin import maps


def test_plots_are_written(tmp_path):
    kr5 = rrc_pin.load("kr5_3r")
    m = maps.capability(kr5, 2**13, 0.2, seed=1, progress=False, workers=1, block_size=2**13)
    assert maps.plot_map(m, tmp_path)
    for name in ("slices.png", "view3d.png"):
        assert (tmp_path / name).stat().st_size > 10_000
    T = np.eye(4)
    T[0, 3] = 1.0
    cell = rrc_pin.combine({"a": (kr5, np.eye(4)), "b": (rrc_pin.load("kr5_3r"), T)})
    c = maps.cell_map(cell, 2**13, 0.2, seed=1, progress=False, workers=1, block_size=2**13)
    assert maps.plot_cell(c, tmp_path)
    assert (tmp_path / "cell_slices.png").stat().st_size > 10_000
