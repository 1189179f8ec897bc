"""The demo's cell figure: the base's pose, the joint angles, the closed chains, with units."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest
from matplotlib.figure import Figure

import rrc_pin
from rrc_pin.cells import CellController
from rrc_pin.cells.closure import ClosureBound
from rrc_pin.demo_figure import draw_cell


@pytest.fixture
def drawn(monkeypatch):
    """The figures ``savefig`` is called on, kept open for inspection."""
    matplotlib.use("Agg")
    figures: list[Figure] = []
    save = Figure.savefig

    def keep(self, *args, **kwargs):
        figures.append(self)
        return save(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", keep)
    return figures


@pytest.mark.parametrize("name", ["gsfc_dual", "yeh_tripod"])
def test_the_cell_figure_has_labelled_panels_with_units_and_shows_a_lost_chain(
    name, drawn, tmp_path
):
    ctl = CellController(name, 0.01)
    command = "object" if name == "gsfc_dual" else "body"
    for _ in range(20):
        ctl.step({command: [0.02, 0.0, 0.01, 0.0, 0.05, 0.0]})
    ctl.closure = ClosureBound(1e-14, 1e-14)  # the next tick finds the chain beyond it
    for _ in range(3):
        ctl.step({command: np.zeros(6)})
    assert draw_cell(ctl, tmp_path / "cell.png") and (tmp_path / "cell.png").stat().st_size > 20_000
    axes = drawn[0].axes
    labels = [ax.get_ylabel() for ax in axes if ax.get_ylabel()]
    assert labels == ["position [m]", "angle [rad]", "joint angle [rad]",
                      "error at the tick's start"]  # fmt: skip
    titles = " ".join(ax.get_title() for ax in axes)
    assert ("body" if name == "yeh_tripod" else "held object 'object'") in titles
    legend = [t.get_text() for t in axes[3].get_legend().get_texts()]
    assert legend[:2] == ["position [m]", "rotation [rad]"]
    assert "chain lost: the cell held still" in legend
    joints = [t.get_text() for t in axes[2].get_legend().get_texts()]
    cell = rrc_pin.load(name)
    assert len(joints) == int(cell.actuated.sum()) and joints[0].endswith("joint1")
