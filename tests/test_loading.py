"""rrc_pin.load and rrc_pin.arms: catalogue, example-robot-data (offline), files, errors."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.errors import FrameNotFound, UnknownArm, URDFError
from rrc_pin.loading import INSTALLED
from rrc_pin.urdf_export import COMMITTED_DIR

EXPECTED_DOF = {
    "panda": 7,
    "ur3": 6,
    "ur5": 6,
    "ur10": 6,
    "kinova": 6,
    "xarm7": 7,
    "z1": 6,
    "so101": 5,
    "baxter_left": 7,
    "baxter_right": 7,
}


def test_arms_lists_catalogue_then_installed():
    names = rrc_pin.arms()
    assert names[:5] == ["barker6", "rrc_k1607", "kr5_3r", "nadkarni_c1", "nadkarni_c2"]
    assert set(EXPECTED_DOF) <= set(names)


@pytest.mark.parametrize("name", sorted(EXPECTED_DOF))
def test_installed_arms_load_from_the_package(name):
    arm = rrc_pin.load(name)
    assert arm.nq == EXPECTED_DOF[name]
    assert arm.tool_frame == INSTALLED[name].tool_frame
    assert "example-robot-data" in arm.source
    assert np.all(np.isfinite(arm.velocity_limit)) and np.all(arm.velocity_limit > 0)
    assert np.isfinite(arm.jacobian(arm.neutral())).all()


def test_baxter_arms_lock_everything_else():
    left, right = rrc_pin.load("baxter_left"), rrc_pin.load("baxter_right")
    assert all(n.startswith("left_") for n in left.joint_names)
    assert all(n.startswith("right_") for n in right.joint_names)


def test_any_urdf_path_loads_with_last_link_as_tool():
    arm = rrc_pin.load(COMMITTED_DIR / "kr5_3r.urdf")
    assert arm.name == "kr5_3r" and arm.tool_frame == "tool" and arm.nq == 3
    arm = rrc_pin.load(str(COMMITTED_DIR / "barker6.urdf"), tool_frame="flange")
    assert arm.tool_frame == "flange"


def test_catalogue_parameters_build_a_variant():
    arm = rrc_pin.load("barker6", alpha3=np.deg2rad(88))
    assert arm.spec.parameters["alpha3"] == pytest.approx(np.deg2rad(88))
    assert arm.spec.chain.rows[2].alpha == pytest.approx(np.deg2rad(88))


def test_unknown_name_lists_the_available_ones():
    with pytest.raises(UnknownArm, match="puma.*available: barker6, rrc_k1607.*panda"):
        rrc_pin.load("puma")


def test_missing_urdf_names_the_path(tmp_path):
    path = tmp_path / "missing.urdf"
    with pytest.raises(URDFError, match=f"{path}: no such file"):
        rrc_pin.load(path)


def test_malformed_urdf_gives_path_and_parser_message(tmp_path):
    path = tmp_path / "broken.urdf"
    path.write_text('<robot name="x"><link name="a"/><joint name="j" type="revolute">')
    with pytest.raises(URDFError, match=f"{path}: Pinocchio could not parse it: .+"):
        rrc_pin.load(path)


def test_unknown_tool_frame():
    with pytest.raises(FrameNotFound, match="^tool_frame: no frame 'hand'"):
        rrc_pin.load("ur5", tool_frame="hand")


def test_parameters_for_non_catalogue_arms_are_refused():
    with pytest.raises(URDFError, match="catalogue arms only"):
        rrc_pin.load("ur5", alpha3=1.0)
