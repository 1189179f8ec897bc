"""``rrc-pin demo`` (issue 8): the quick teleoperation session from the console script, its
outputs, and the numbers of its table recomputed from the trajectories it wrote."""

from __future__ import annotations

import csv
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rrc_pin
from rrc_pin.control import TrajectoryLog
from rrc_pin.demo import HEADER, SESSIONS
from rrc_pin.demo_figure import draw


@pytest.fixture(scope="module")
def quick_demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    exe = shutil.which("rrc-pin", path=str(Path(sys.executable).parent))
    assert exe is not None, "the rrc-pin console script is not installed next to this Python"
    done = subprocess.run([exe, "demo", "--quick", "--out", str(out)], capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return out, done.stdout


def test_the_quick_demo_writes_every_output(quick_demo):
    out, stdout = quick_demo
    runs = [(s.arm, name) for s in SESSIONS for name in s.strategies]
    for arm, strategy in runs:
        assert (out / f"{arm}-{strategy}.csv").is_file()
    assert (out / "summary.csv").is_file() and (out / "session.png").stat().st_size > 10_000
    assert "nan" not in stdout.lower() and "session.png skipped" not in stdout
    assert f"[{len(runs):2d}/{len(runs)}]" in stdout  # progress


def test_the_table_holds_the_numbers_of_the_trajectories(quick_demo):
    out, stdout = quick_demo
    with (out / "summary.csv").open() as f:
        rows = list(csv.reader(f))
    assert tuple(rows[0]) == HEADER and len(rows) == 12
    for arm, strategy, steps, drift, margin, rate, statuses, _met in rows[1:]:
        robot = rrc_pin.load(arm)
        log = TrajectoryLog.load(out / f"{arm}-{strategy}.csv")
        q, qdot = log.column("q"), log.column("qdot")
        assert len(log) == int(steps)
        assert abs(1e3 * log.column("drift_position").max() - float(drift)) <= 5e-5
        assert abs(np.min(np.minimum(q - robot.lower, robot.upper - q)) - float(margin)) <= 5e-7
        assert abs(np.max(np.abs(qdot) / robot.velocity_limit) - float(rate)) <= 5e-5
        # the printed line carries the same numbers, and the limits held
        line = next(x for x in stdout.splitlines() if x.split()[:2] == [arm, strategy])
        assert line.split()[2:6] == [steps, drift, margin, rate]
        assert float(margin) >= 0.02 - 1e-9 and float(rate) <= 1.0 + 1e-9
        assert statuses.split()[0] in ("exact", "scaled")
    barker = {r[1]: r[7] for r in rows[1:] if r[0] == "barker6"}
    # the resolver's own handling scales a command along itself below the damping threshold
    # (condition number 100), so it slows down toward the shoulder singularity and reaches it
    # only past the quick script's time; the strategies that act on it meet it
    assert len(barker) == 7
    assert all("shoulder (eq. 32)" in met for name, met in barker.items() if name != "resolver")
    # the slowdown keeps the hand from the wrist singularity in the quick script's time
    assert all("wrist (S5 = 0)" in met for name, met in barker.items() if name != "slowdown")


def test_the_figure_is_skipped_without_matplotlib(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import fails as if not installed
    assert draw({}, tmp_path / "x.png") is False and not (tmp_path / "x.png").exists()


def test_demo_help_lists_out_and_quick(capsys):
    from rrc_pin.cli import main

    with pytest.raises(SystemExit):
        main(["demo", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--out DIR" in text and "--quick" in text
