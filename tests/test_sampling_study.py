"""Nguyen & Zhou section 5 (benchmarks/sampling_study.py): the order of each error in dt.

Quick settings: a 2 s stretch of the study's trajectory at the report's 1, 10 and 100 ms.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

import rrc_pin

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
try:
    import bench_study
    import sampling_study as st
finally:
    sys.path.remove(str(ROOT / "benchmarks"))

DTS = (0.001, 0.01, 0.1)
FIRST_ORDER = ("v_x", "v", "w_x", "w", "qdot_sampling", "w_quat")
SECOND_ORDER = ("v_mid", "w_mid", "ds_beta", "ds_gamma")
NO_ORDER = ("qdot_pinv_jac", "qdot1_pinv_jac")


@pytest.fixture(scope="module")
def quick():
    t = st.TRAJECTORY
    traj = st.Trajectory(t.theta0, t.amplitude, t.period, t.phase, duration=2.0)
    arm = rrc_pin.load(st.ARM)
    runs = {dt: st.sample(arm, traj, dt) for dt in DTS}
    errors = {name: [runs[dt].errors[name] for dt in DTS] for name in st.ERRORS}
    return arm, traj, runs, errors


def test_parts_1_and_3_are_first_order_in_the_sampling_time(quick):
    """A backward difference against the Jacobian at t_k: a half-sample lag, O(dt)."""
    _, _, _, errors = quick
    for name in FIRST_ORDER:
        assert st.fitted_order(DTS, errors[name]) == pytest.approx(1.0, abs=0.1), name


def test_centred_comparison_and_quaternion_components_are_second_order(quick):
    _, _, _, errors = quick
    for name in SECOND_ORDER:
        assert st.fitted_order(DTS, errors[name]) == pytest.approx(2.0, abs=0.1), name


def test_part_2_pseudo_inverse_loses_the_self_motion_whatever_dt(quick):
    """J^+ J qdot misses qdot by its null-space part, the same at every dt (order 0); the
    sampling part (J^+ of Part 1's error) is first order (checked above)."""
    arm, traj, runs, errors = quick
    for name in NO_ORDER:
        assert abs(st.fitted_order(DTS, errors[name])) < 0.05, name
    s = runs[0.01]
    q = traj.q(s.t)
    J = np.array([arm.jacobian(qk) for qk in q])
    null = s.qdot - np.einsum("kij,kj->ki", np.linalg.pinv(J), np.einsum("kij,kj->ki", J, s.qdot))
    assert np.max(np.linalg.norm(null, axis=1)) == pytest.approx(errors["qdot_pinv_jac"][1])
    assert errors["qdot_pinv_jac"][1] > 0.1  # the trajectory has self-motion: the test can fail


def test_part_1_error_is_half_a_sample_of_acceleration(quick):
    """(p_k - p_k-1)/dt - v(t_k) = -(dt/2) a(t_k) + O(dt^2): at 1 ms within 1%."""
    arm, traj, runs, _ = quick
    s = runs[0.001]
    h = 1e-5

    def v(t):
        J = np.array([arm.jacobian(q) for q in traj.q(t)])
        return np.einsum("kij,kj->ki", J, traj.qdot(t))[:, :3]

    t = s.t[::200]
    accel = (v(t + h) - v(t - h)) / (2 * h)
    err = (s.v_diff - s.v_jac)[::200]
    np.testing.assert_allclose(err, -0.001 / 2 * accel, atol=0.01 * np.max(np.abs(err)))


def test_study_json_renders_its_docs_section(tmp_path):
    """The recorded study.json has the documented keys and renders without error; the
    recorded orders are those of the theory."""
    results = json.loads((ROOT / "benchmarks" / "results" / "study.json").read_text())
    for key in ("machine", "source", "dts", "errors", "orders", "bounds", "by_speed", "trajectory"):
        assert key in results, key
    assert set(results["errors"]) == set(st.ERRORS) and set(results["orders"]) == set(st.ERRORS)
    for name in FIRST_ORDER:
        assert results["orders"][name] == pytest.approx(1.0, abs=0.05), name
    text = bench_study.docs_section(results)
    assert "Does 10 ms hold?" in text and "| Part 3 |" in text


def test_bad_sampling_time_is_refused():
    with pytest.raises(ValueError, match="dt"):
        st.sample(rrc_pin.load(st.ARM), st.TRAJECTORY, 0.0)
