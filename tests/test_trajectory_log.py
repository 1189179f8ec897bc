"""The controller's trajectory log: every field saved to CSV and NPZ and loaded back exactly."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.control import Controller, LogRecord, TrajectoryLog


@pytest.fixture(scope="module")
def log() -> TrajectoryLog:
    arm = rrc_pin.load("barker6")
    ctl = Controller(arm, q0=np.deg2rad([20.0, 30.0, 60.0, 10.0, 2.0, 0.0]), strategy="slowdown")
    for _ in range(30):
        ctl.step([0.02, 0.0, -0.01, 0.0, -0.4, 0.1])
    for _ in range(10):
        ctl.step([5.0, 0.0, 0.0, 0.0, 0.0, 0.0], ref="world_aligned")  # beyond the limits
    ctl.reverse(0.2)
    return ctl.log


def test_the_log_records_every_tick(log):
    assert len(log) == 60
    assert log.column("q").shape == (60, 6) and log.column("commanded").shape == (60, 6)
    assert set(log.column("mode")) == {"teleop", "reverse"}
    assert {"scaled", "damped"} & set(log.column("status")) and any(log.column("active"))
    assert "wrist (S5 = 0)" in set(log.column("singularity"))
    assert np.allclose(np.diff(log.column("t")), 0.01, atol=1e-12)


@pytest.mark.parametrize("suffix", [".csv", ".npz"])
def test_save_and_load_give_the_same_records(log, tmp_path, suffix):
    path = log.save(tmp_path / f"run{suffix}")
    back = TrajectoryLog.load(path)
    assert back.joint_names == log.joint_names and len(back) == len(log)
    for name in LogRecord._fields:
        a, b = log.column(name), back.column(name)
        if a.dtype.kind == "U":
            assert list(a) == list(b), name
        else:
            assert np.array_equal(a, b), name  # repr() round-trips floats exactly


def test_bad_paths_and_columns_are_refused(log, tmp_path):
    with pytest.raises(rrc_pin.InvalidInput) as info:
        log.save(tmp_path / "run.txt")
    assert info.value.argument == "path"
    (tmp_path / "other.csv").write_text("a,b\n1,2\n")
    with pytest.raises(rrc_pin.InvalidInput, match="does not hold a trajectory log"):
        TrajectoryLog.load(tmp_path / "other.csv")
    with pytest.raises(rrc_pin.InvalidInput, match="columns: t, q"):
        log.column("speed")


def test_positions_of_the_last_ticks_need_no_records(log):
    """The last q's, from derived records and pending ticks alike, oldest first."""
    arm = rrc_pin.load("panda")
    ctl = Controller(arm, q0=np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.8, 0.7]))
    for _ in range(5):
        ctl.step([0.02, 0.0, 0.0, 0.0, 0.0, 0.1])
    assert len(ctl.log.records) == 5  # derived
    for _ in range(3):
        ctl.step([0.0, 0.02, 0.0, 0.0, 0.1, 0.0])  # pending
    tail = ctl.log.positions(6)
    assert len(ctl.log._ticks) == 3  # still pending: nothing derived
    wanted = [r.q for r in ctl.log.records[-6:]]
    assert len(tail) == 6 and all(np.array_equal(a, b) for a, b in zip(tail, wanted, strict=True))
    assert ctl.log.positions(0) == [] and len(log.positions(60)) == 60
