"""URDF generation: committed files equal the generated text; rpy conversion; refusals."""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin.dh import DHChain, DHRow, rot_x, rot_z
from rrc_pin.errors import InvalidInput
from rrc_pin.models import CATALOGUE
from rrc_pin.models.arm_spec import ArmSpec
from rrc_pin.urdf_export import COMMITTED_DIR, check, rpy_from_matrix, to_urdf, write


def rpy_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """URDF's fixed-axis convention: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    cp, sp = np.cos(pitch), np.sin(pitch)
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    return rot_z(yaw)[:3, :3] @ Ry @ rot_x(roll)[:3, :3]


def test_committed_urdfs_match_their_dh_tables():
    assert check(COMMITTED_DIR, list(CATALOGUE.values())) == []


def test_check_reports_a_tampered_file(tmp_path):
    specs = [CATALOGUE["kr5_3r"]]
    write(tmp_path, specs)
    path = tmp_path / "kr5_3r.urdf"
    path.write_text(path.read_text().replace('velocity="6.5"', 'velocity="7.5"'))
    problems = check(tmp_path, specs)
    assert len(problems) == 1
    assert "joint[joint1]/limit@velocity: committed '7.5', generated '6.5'" in problems[0]


def test_rpy_round_trip_including_gimbal_lock(rng):
    angles = [rng.uniform(-np.pi, np.pi, 3) for _ in range(500)]
    angles += [
        np.array([r, s * np.pi / 2, y]) for r, y in rng.uniform(-3, 3, (20, 2)) for s in (1, -1)
    ]
    for roll, pitch, yaw in angles:
        R = rpy_matrix(roll, pitch, yaw)
        np.testing.assert_allclose(rpy_matrix(*rpy_from_matrix(R)), R, atol=1e-12)


def test_urdf_has_limits_inertia_visuals_and_tool_frames():
    text = to_urdf(CATALOGUE["barker6"])
    assert text.count('type="revolute"') == 6
    assert text.count("<inertial>") == 6 and text.count("<visual>") >= 6
    assert 'velocity="2"' in text and 'effort="' in text
    assert '<link name="tool"/>' in text and '<link name="flange"/>' in text


def test_screw_joints_are_refused():
    spec = CATALOGUE["kr5_3r"]
    rows = (DHRow(0.1, 0.0, 0.0, 0.0, kind="screw", pitch=0.01),)
    screw = ArmSpec(
        "screwy", DHChain("nadkarni", rows), (-1.0,), (1.0,), (1.0,), (1.0,), spec.source
    )
    with pytest.raises(InvalidInput, match="screw"):
        to_urdf(screw)
