"""The rrc-pin command line: arms, urdf --check, check, demo."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import rrc_pin
from rrc_pin.cli import EXIT_BROKEN_PIPE, main
from rrc_pin.urdf_export import COMMITTED_DIR


def test_arms_table_lists_tool_frames_sources_and_assumptions(capsys):
    assert main(["arms"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[:5] == ["name", "dof", "joints", "tool", "frames"]
    rows = {line.split()[0]: line for line in lines[1:]}
    assert list(rows) == rrc_pin.arms()
    assert rows["barker6"].split()[1:4] == ["6", "RRRRRR", "tool"]
    assert "PUMA 560 values" in rows["barker6"]
    assert rows["nadkarni_c2"].split()[1:3] == ["6", "PPPRRR"]
    assert "panda_hand_tcp" in rows["panda"] and "example-robot-data" in rows["panda"]
    assert rows["baxter"].split()[1:5] == ["15", "R" * 15, "left_gripper,", "right_gripper"]
    assert "l_gripper_tool_frame, r_gripper_tool_frame" in rows["pr2"]
    assert "locked: head, laser tilt, grippers" in rows["pr2"]


def run_console_script(*args: str, close_stdout: bool = False) -> subprocess.CompletedProcess:
    exe = shutil.which("rrc-pin", path=str(Path(sys.executable).parent))
    if exe is None:
        pytest.fail("the rrc-pin console script is not installed next to this Python")
    if not close_stdout:
        return subprocess.run([exe, *args], capture_output=True, text=True, timeout=300)
    proc = subprocess.Popen([exe, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # the reader goes away before the first line: `rrc-pin ... | head -0`
    err = proc.stderr.read().decode()
    proc.wait(timeout=300)
    return subprocess.CompletedProcess(proc.args, proc.returncode, "", err)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["demo", "--arm", "ur55"], "rrc-pin demo: name_or_path: unknown arm 'ur55'"),
        (["check", "--samples", "0"], "rrc-pin check: samples: expected an integer >= 1, got 0"),
        (["check", "--samples", "-3"], "rrc-pin check: samples: expected an integer >= 1"),
    ],
)
def test_errors_are_one_line_and_exit_code_2(args, message, capsys):
    """Issue 7 item 7, issue 18 item 12: a traceback, or a check of nothing that passed."""
    assert main(args) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(message), err


def test_errors_are_one_line_from_the_console_script_too():
    out = run_console_script("demo", "--arm", "ur55")
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert out.stderr.splitlines() == [out.stderr.strip()]
    assert out.stderr.startswith("rrc-pin demo: name_or_path: unknown arm 'ur55'")


def test_a_closed_stdout_ends_quietly():
    """Issue 18 item 12: `rrc-pin check | head -1` ended in BrokenPipeError."""
    out = run_console_script("check", "--samples", "2", close_stdout=True)
    assert out.stderr == "" and out.returncode == EXIT_BROKEN_PIPE


def test_demo_help_says_what_arm_does(capsys):
    with pytest.raises(SystemExit) as info:
        main(["demo", "--help"])
    assert info.value.code == 0
    help_text = " ".join(capsys.readouterr().out.split())
    assert "--arm NAME print only the kinematics row of this arm" in help_text
    assert "instead of the tour" in help_text


def test_urdf_check_passes_on_the_committed_files(capsys):
    assert main(["urdf", "--check"]) == 0
    assert "5/5 URDFs" in capsys.readouterr().out


def test_urdf_check_fails_on_a_changed_file_and_write_repairs_it(tmp_path, capsys):
    folder = tmp_path / "urdf"
    shutil.copytree(COMMITTED_DIR, folder)
    (folder / "barker6.urdf").write_text("<robot/>")
    assert main(["urdf", "--check", "--dir", str(folder)]) == 1
    assert "barker6.urdf" in capsys.readouterr().err
    assert main(["urdf", "--write", "--dir", str(folder)]) == 0
    assert main(["urdf", "--check", "--dir", str(folder)]) == 0


def scaled_numbers(text: str, factor: float, only: int | None = None) -> str:
    """``text`` with the numbers in attribute values (after the XML declaration) times ``factor``
    (all of them, or only the ``only``-th of those above 1e-3)."""
    head, body = text.split("?>", 1)
    count = iter(range(10**6))

    def scale(m: re.Match[str]) -> str:
        x = float(m.group())
        if only is None or (abs(x) > 1e-3 and next(count) == only):
            return repr(x * factor)
        return m.group()

    number = r"(?<=[\s\"])-?\d+(?:\.\d*)?(?:e[-+]?\d+)?(?=[\s\"])"
    return head + "?>" + re.sub(number, scale, body)


def test_urdf_check_compares_numbers_with_a_tolerance(tmp_path, capsys):
    folder = tmp_path / "urdf"
    shutil.copytree(COMMITTED_DIR, folder)
    for path in folder.glob("*.urdf"):
        path.write_text(scaled_numbers(path.read_text(), 1.0 + 1e-15))  # a few ulps
    assert main(["urdf", "--check", "--dir", str(folder)]) == 0
    path = folder / "rrc_k1607.urdf"
    path.write_text(scaled_numbers(path.read_text(), 1.0 + 1e-9, only=40))
    capsys.readouterr()
    assert main(["urdf", "--check", "--dir", str(folder)]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err[0] == f"{path}: differs from its DH table" and len(err) == 2
    assert err[1].startswith("/robot/") and "committed" in err[1] and "generated" in err[1]


def test_urdf_with_a_bad_folder_is_one_line(tmp_path, capsys):
    assert main(["urdf", "--check", "--dir", str(tmp_path / "nothing")]) == 2
    assert main(["urdf", "--write", "--dir", str(COMMITTED_DIR / "barker6.urdf")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2 and all("is not a folder" in line for line in err)
    (tmp_path / "empty").mkdir()
    assert main(["urdf", "--check", "--dir", str(tmp_path / "empty")]) == 1
    assert capsys.readouterr().err.count("missing") == 5


def test_check_command_cross_validates(capsys):
    assert main(["check", "--samples", "20"]) == 0
    out = capsys.readouterr().out
    assert out.count(" ok") == 5


def test_demo_runs_as_a_console_script():
    out = run_console_script("demo")
    assert out.returncode == 0, out.stderr
    assert "nan" not in out.stdout.lower()
    rows = [
        line.split()
        for line in out.stdout.splitlines()
        if " rad/s about " in line or " m/s along " in line
    ]
    assert len(rows) == 4
    for row in rows:
        unit_at = row.index("rad") if "rad" in row[:9] else row.index("m")
        asked, done, veer, excess = (
            float(row[unit_at - 1]),
            float(row[unit_at + 1]),
            float(row[unit_at + 3]),
            float(row[unit_at + 5]),
        )
        assert excess <= 1e-12 and done <= asked * (1 + 1e-3) and veer < 1.0, row
    closed_form_rows = [line.split() for line in out.stdout.splitlines() if "ClosedForm" in line]
    assert len(closed_form_rows) == 3 and all(float(r[-1]) < 1e-9 for r in closed_form_rows)
