"""The controller's trajectory log: every field saved to CSV and NPZ and loaded back exactly."""

from __future__ import annotations

import gc
import tracemalloc

import numpy as np
import pytest

import rrc_pin
from rrc_pin.control import Controller, LogRecord, TrajectoryLog


@pytest.fixture(scope="module")
def log() -> TrajectoryLog:
    arm = rrc_pin.load("barker6")
    ctl = Controller(arm, q0=np.deg2rad([20.0, 30.0, 60.0, 10.0, 2.0, 0.0]), strategy="slowdown")
    for _ in range(30):
        ctl.step([0.02, 0.0, -0.01, 0.0, -0.4, 0.1], ref="local")
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
        ctl.step([0.02, 0.0, 0.0, 0.0, 0.0, 0.1], ref="local")
    assert len(ctl.log.records) == 5  # derived
    for _ in range(3):
        ctl.step([0.0, 0.02, 0.0, 0.0, 0.1, 0.0], ref="local")  # pending
    tail = ctl.log.positions(6)
    assert ctl.log._pending == 3  # still pending: nothing derived
    wanted = [r.q for r in ctl.log.records[-6:]]
    assert len(tail) == 6 and all(np.array_equal(a, b) for a, b in zip(tail, wanted, strict=True))
    assert ctl.log.positions(0) == [] and len(log.positions(60)) == 60


def test_the_log_keeps_its_capacity_and_its_memory_stays_flat():
    """Issue 28 item 6: the log grew about 2.9 kB a tick with no cap (measured here: 2.9 kB
    a pending tick, 1.5 kB a derived record); it is a ring of ``capacity`` ticks now."""
    ctl = Controller(rrc_pin.load("panda"))
    assert ctl.log.capacity == 60_000  # 10 minutes at 100 Hz
    ctl.log.capacity = 100
    command = [0.01, 0.0, 0.0, 0.0, 0.0, 0.05]
    for _ in range(300):
        ctl.step(command, ref="local")
    assert len(ctl.log) == 100 and ctl.log.dropped == 200
    t = ctl.log.column("t")  # the last 100 ticks, oldest first
    np.testing.assert_allclose(t, 0.01 * np.arange(200, 300), atol=1e-9)
    tracemalloc.start()
    try:
        for _ in range(100):  # the ring refilled with ticks allocated under tracemalloc
            ctl.step(command, ref="local")
        gc.collect()
        before = tracemalloc.get_traced_memory()[0]
        for _ in range(400):
            ctl.step(command, ref="local")
        gc.collect()
        grown = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert len(ctl.log) == 100 and ctl.log.dropped == 700
    assert grown / 400 < 100  # bytes a tick once full (about 0.5; 2,900 without the cap)


def test_reverse_retraces_within_the_ring():
    ctl = Controller(rrc_pin.load("barker6"))
    ctl.log.capacity = 50
    for _ in range(120):
        ctl.step([0.02, 0.0, 0.0, 0.0, 0.0, 0.1], ref="local")
    start = ctl.log.positions(30)[0]  # the configuration of tick 90
    done = ctl.reverse(0.3)
    assert done.reached and np.abs(ctl.q - start).max() <= 1e-9
    with pytest.raises(rrc_pin.InvalidInput, match="^seconds: .*the record holds 50 ticks"):
        ctl.reverse(0.6)  # beyond what the ring keeps
    smaller = TrajectoryLog(["a"], capacity=3)
    for k in range(5):
        smaller.append(_record(k))
    assert [r.t for r in smaller.records] == [2.0, 3.0, 4.0] and smaller.dropped == 2
    smaller.capacity = 2
    assert [r.t for r in smaller.records] == [3.0, 4.0] and smaller.dropped == 3


def _record(t: float) -> LogRecord:
    return LogRecord(t=float(t), q=np.zeros(1), qdot=np.zeros(1), commanded=np.zeros(6),
                     achieved=np.zeros(6), scale=1.0, factor=1.0, sigma_min=1.0,
                     manipulability=1.0, drift_position=0.0, drift_rotation=0.0, mode="teleop",
                     method="qp", status="exact", active="", singularity="", note="")  # fmt: skip


@pytest.mark.parametrize(
    ("path", "message"),
    [
        ("/nonexistent/dir/x.csv", "^path: cannot write '/nonexistent/dir/x.csv': No such file"),
        ("/nonexistent/dir/x.npz", "^path: cannot write '/nonexistent/dir/x.npz': No such file"),
        (3, "^path: expected a file name"),
        (np.array(["x.csv"]), "^path: expected a file name"),
        ("", "^path: expected a file name"),
        ("run.txt", r"^path: expected a \.csv or \.npz file"),
    ],
)
def test_save_errors_are_the_packages_naming_path(log, path, message):
    """Issue 33 item 4, issue 28 item 8: FileNotFoundError and TypeError before."""
    with pytest.raises(rrc_pin.InvalidInput, match=message) as info:
        log.save(path)
    assert info.value.argument == "path"


def test_load_errors_are_the_packages_naming_path(log, tmp_path):
    """Issue 33 item 4, issue 28 item 8: FileNotFoundError, KeyError, ValueError before."""
    good = log.save(tmp_path / "good.npz")
    data = dict(np.load(good))
    del data["q"]
    np.savez(tmp_path / "no_q.npz", **data)
    data = dict(np.load(good))
    data["q"] = data["q"][:, :2]
    np.savez(tmp_path / "narrow.npz", **data)
    (tmp_path / "junk.npz").write_bytes(b"not a zip file")
    lines = log.save(tmp_path / "good.csv").read_text().splitlines()
    (tmp_path / "short_row.csv").write_text("\n".join([lines[0], "1.0,2.0"]) + "\n")
    text = lines[1].split(",")
    text[1] = "abc"
    (tmp_path / "text.csv").write_text("\n".join([lines[0], ",".join(text)]) + "\n")
    (tmp_path / "folder.csv").mkdir()
    cases = {
        "/nonexistent.npz": "cannot read '/nonexistent.npz': No such file",
        str(tmp_path / "missing.csv"): "No such file",
        str(tmp_path / "folder.csv"): "cannot read .*Is a directory",
        str(tmp_path / "no_q.npz"): "does not hold a trajectory log .no field 'q'",
        str(tmp_path / "narrow.npz"): r"does not hold a trajectory log .q has shape \(2,\)",
        str(tmp_path / "junk.npz"): "does not hold a trajectory log",
        str(tmp_path / "short_row.csv"): "does not hold a trajectory log .row 2 has 2 fields",
        str(tmp_path / "text.csv"): "does not hold a trajectory log .could not convert",
    }
    for path, message in cases.items():
        with pytest.raises(rrc_pin.InvalidInput, match=f"^path: .*{message}") as info:
            TrajectoryLog.load(path)
        assert info.value.argument == "path", path
    for bad in (None, 3, np.array(["x.npz"]), "x.json"):
        with pytest.raises(rrc_pin.InvalidInput, match="^path: "):
            TrajectoryLog.load(bad)


def test_columns_names_and_capacity_are_checked(log):
    """Issue 28 item 8: an array as a column name raised 'truth value is ambiguous'."""
    for name in (np.array(["t", "q"]), ["t"], 3, None):
        with pytest.raises(rrc_pin.InvalidInput, match="^name: no column") as info:
            log.column(name)
        assert info.value.argument == "name"
    for capacity in (0, -1, 2.5, True, "10"):
        with pytest.raises(rrc_pin.InvalidInput, match="^capacity: expected an integer >= 1"):
            TrajectoryLog(["a"], capacity=capacity)
    for names in ("ab", [1, 2], None):
        with pytest.raises(rrc_pin.InvalidInput, match="^joint_names: "):
            TrajectoryLog(names)
    with pytest.raises(rrc_pin.InvalidInput, match="^record: expected a LogRecord"):
        TrajectoryLog(["a"]).append((0.0, np.zeros(1)))
    with pytest.raises(rrc_pin.InvalidInput, match="^n: expected an integer >= 0"):
        log.positions(np.array([3]))
