"""``rrc-pin demo`` (issue 8): the quick teleoperation session from the console script, its
outputs, and the numbers of its table recomputed from the trajectories it wrote."""

from __future__ import annotations

import csv
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rrc_pin
from rrc_pin.cli import main
from rrc_pin.control import TrajectoryLog
from rrc_pin.control.strategies import make_strategy
from rrc_pin.demo import HEADER, NOT_MEASURED, SESSIONS, Segment, Session, fixed
from rrc_pin.demo_figure import draw


@pytest.fixture(scope="module")
def quick_demo(tmp_path_factory):
    """``rrc-pin demo --quick`` without ``--out``, from an empty working directory, with the
    system's temporary directory pointed at a folder of the test's own."""
    cwd, temp = tmp_path_factory.mktemp("cwd"), tmp_path_factory.mktemp("temp")
    exe = shutil.which("rrc-pin", path=str(Path(sys.executable).parent))
    assert exe is not None, "the rrc-pin console script is not installed next to this Python"
    env = {**os.environ, "TMPDIR": str(temp)}
    done = subprocess.run([exe, "demo", "--quick"], capture_output=True, text=True, timeout=300,
                          cwd=cwd, env=env)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert list(cwd.iterdir()) == []  # issue 33 item 6: nothing written into the checkout
    out = Path(re.search(r"^written to (.+): ", done.stdout, re.M).group(1))
    assert out.parent == temp and out.name.startswith("rrc-pin-demo-")
    assert f"-> {out}" in done.stdout  # printed at the start too
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
        if make_strategy(strategy).chooses_rates:  # issue 33 item 6: not "0.0000"
            assert drift == "" and log.column("drift_position").max() == 0.0
            drift = NOT_MEASURED  # as printed
        else:
            assert abs(1e3 * log.column("drift_position").max() - float(drift)) <= 5e-5
        assert abs(np.min(np.minimum(q - robot.lower, robot.upper - q)) - float(margin)) <= 5e-7
        assert abs(np.max(np.abs(qdot) / robot.velocity_limit) - float(rate)) <= 5e-5
        # the printed line carries the same numbers, and the limits held
        line = next(x for x in stdout.splitlines() if x.split()[:2] == [arm, strategy])
        assert line.split()[2:6] == [steps, drift, margin, rate]
        assert float(margin) >= 0.02 - 1e-9 and float(rate) <= 1.0 + 1e-9
        assert statuses.split()[0] in ("exact", "scaled")
    assert sum(r[3] == "" for r in rows[1:]) == 5  # Barker's five strategies
    assert "'-': not measured" in " ".join(stdout.split())
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
    with pytest.raises(SystemExit):
        main(["demo", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--out DIR" in text and "--quick" in text


def test_out_is_where_the_demo_writes(tmp_path, monkeypatch, capsys):
    """``--out DIR`` still works (a one-segment script, to keep it short)."""
    import rrc_pin.demo

    short = Session("kr5_3r", None, (Segment("up", fixed([0, 0, 0.05, 0, 0, 0]), 0.5),),
                    ("resolver",))  # fmt: skip
    monkeypatch.setattr(rrc_pin.demo, "SESSIONS", (short,))
    monkeypatch.setattr(rrc_pin.demo, "REVERSE", 0.1)
    assert main(["demo", "--out", str(tmp_path / "here")]) == 0
    assert sorted(p.name for p in (tmp_path / "here").iterdir()) == [
        "kr5_3r-resolver.csv", "session.png", "summary.csv"]  # fmt: skip
    log = TrajectoryLog.load(tmp_path / "here" / "kr5_3r-resolver.csv")
    np.testing.assert_allclose(log.column("q")[0], rrc_pin.load("kr5_3r").ready())  # its start
    assert f"written to {tmp_path / 'here'}: " in capsys.readouterr().out


def test_an_arm_that_does_not_load_prints_nothing_but_its_error(capsys):
    """Issue 33 item 6: the table's header came out before the error."""
    assert main(["demo", "--arm", "nope"]) == 2
    printed = capsys.readouterr()
    assert printed.out == ""
    assert printed.err.startswith("rrc-pin demo: name_or_path: unknown arm 'nope'")
    assert printed.err.count("\n") == 1


def test_an_arm_given_by_path_keeps_the_table_intact(tmp_path, capsys):
    """Issue 33 item 6: a URDF's path went into the arm column and broke the table."""
    from rrc_pin.urdf_export import COMMITTED_DIR

    text = (COMMITTED_DIR / "kr5_3r.urdf").read_text().replace('name="kr5_3r"', 'name="x"', 1)
    long = tmp_path / "an_arm_with_a_rather_long_name_for_a_table.urdf"
    long.write_text(text)
    for path, name in ((COMMITTED_DIR / "barker6.urdf", "barker6"), (long, long.stem)):
        assert main(["demo", "--arm", str(path)]) == 0
        lines = capsys.readouterr().out.splitlines()
        assert len(lines) == 2 and lines[1].split()[:3] == [name, lines[1].split()[1], "ready"]
        assert str(path) not in lines[1]
        ends = {re.match(r"^\S+\s+(\d+|dof)", line).end() for line in lines}
        assert len(ends) == 1  # the dof column lines up under its header


def test_the_stages_and_barker_are_compiled_beside_the_first_session():
    """The second process of a demo loads or compiles two of the tick's stages and Barker's
    kernels and exits cleanly; none is started where nothing is compiled."""
    from rrc_pin import demo

    beside = demo.compiling_beside()
    if os.environ.get("NUMBA_DISABLE_JIT") == "1":
        assert beside is None
        return
    assert beside is not None
    assert beside.wait(timeout=300) == 0
