"""The benchmarks' figures say what their run measured (issue 33 item 7), drawn from the
recorded JSON (and a quick run's settings) without running a benchmark."""

from __future__ import annotations

import copy
import importlib
import json
from pathlib import Path

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
from matplotlib.figure import Figure

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"


@pytest.fixture
def bench(monkeypatch):
    """A benchmark module by name (benchmarks/ on the path for its own imports)."""
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    return importlib.import_module


@pytest.fixture
def drawn(monkeypatch):
    """The figures ``savefig`` is called on, kept open for inspection."""
    figures: list[Figure] = []
    save = Figure.savefig

    def keep(self, *args, **kwargs):
        self.canvas.draw()
        self.kept_renderer = self.canvas.get_renderer()  # the canvas goes with plt.close
        figures.append(self)
        return save(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", keep)
    return figures


def recorded(name: str) -> dict:
    return json.loads((RESULTS / f"{name}.json").read_text())


def test_the_quick_control_schemes_figure_and_tables_say_what_ran(bench, drawn, tmp_path):
    """The quick run picks the payload up at 0.5 s of 1 s: the figure said "at 2 s", and the
    tables called every recovery "never" (recovery_s = inf: none fits in 0.5 s)."""
    schemes = bench("bench_control_schemes")
    quick = copy.deepcopy(recorded("control_schemes"))
    quick["quick"] = True
    quick["settings"]["tracking"] = dict(schemes.QUICK_TRACKING)
    for row in quick["rows"]:
        if row["scenario"] == "tracking":
            row["recovery_s"] = float("inf")
    assert schemes.plot(quick, tmp_path / "quick.png")
    tracking = drawn[-1].axes[0]
    assert tracking.get_title() == "barker6: tracking, 2.5 kg picked up at 0.5 s"
    assert [line.get_xdata()[0] for line in tracking.lines if line.get_linestyle() == ":"] == [0.5]
    assert drawn[-1]._suptitle.get_text().startswith("quick run (a smoke test, not a result)")
    text = schemes.markdown(quick)
    assert "never" not in text and "inf" not in text
    assert "(2.5 kg at t = 0.5 s of 1 s)" in text and "| > 0.50 |" in text
    assert "Quick run (a smoke test, not a result)" in text
    full = recorded("control_schemes")  # recorded before the settings held the times
    assert schemes.tracking_settings(full)["change_at"] == 2.0  # the full run's
    assert "| > 2.00 |" in schemes.markdown(full) and "never" not in schemes.markdown(full)


@pytest.mark.parametrize(("name", "module"), [("controller", "bench_controller"),
                                              ("resolver", "bench_resolver"),
                                              ("tasks", "bench_tasks")])  # fmt: skip
def test_the_timing_legends_hide_no_axis_label(bench, drawn, tmp_path, name, module):
    """controller.png's legend sat on its x-axis label; one legend now, below every label
    (resolver.png draws through the same timing_chart)."""
    assert bench(module).plot(recorded(name), tmp_path / f"{name}.png")
    fig = drawn[-1]
    renderer = fig.kept_renderer
    legends = fig.legends + [ax.get_legend() for ax in fig.axes if ax.get_legend()]
    assert len(legends) == 1
    box = legends[0].get_window_extent(renderer)
    for ax in fig.axes:
        for label in (ax.xaxis.label, *ax.get_xticklabels()):
            assert not box.overlaps(label.get_window_extent(renderer)), (name, label.get_text())
    if name == "controller":  # no peers in this one
        assert "peers" not in " ".join(t.get_text() for t in legends[0].get_texts())
        medians = [c["median_us"] for arm in recorded(name)["arms"]
                   for c in arm["contenders"].values()]  # fmt: skip
        left = 10.0 ** np.floor(np.log10(min(medians) / 2.0))  # the decade below half the fastest
        assert all(ax.get_xlim()[0] == left for ax in fig.axes), left


def test_replot_draws_a_figure_from_its_json(bench, tmp_path, capsys):
    """benchmarks/replot.py: a figure drawn again from recorded numbers, nothing measured."""
    (tmp_path / "controller.json").write_text((RESULTS / "controller.json").read_text())
    assert bench("replot").main(["controller", "--results", str(tmp_path)]) == 0
    assert (tmp_path / "controller.png").stat().st_size > 10_000
    assert capsys.readouterr().out == f"wrote {tmp_path / 'controller.png'}\n"


def test_the_collision_figure_and_table_say_where_no_pair_came_near(bench, drawn, tmp_path):
    """Issue 40: a quick run's pink never came within the detection distance (its minimum
    distance inf), and the figure dropped it without a word."""
    collision = bench("bench_collision")
    quick = copy.deepcopy(recorded("collision"))
    for row in quick["rows"]:
        if row["contender"].startswith("pink") and row["pairs"] < 50:
            row["min_distance_m"] = float("inf")
    assert collision.plot(quick, tmp_path / "quick.png")
    labels = drawn[-1].axes[1].get_legend().get_texts()
    pink = next(t.get_text() for t in labels if t.get_text().startswith("pink"))
    assert pink.endswith("(no pair within 100 mm at [9, 36] pairs: not drawn)"), pink
    table = collision.readme_table(quick)
    assert "inf" not in table and "no pair came within the detection distance (100 mm)" in table
