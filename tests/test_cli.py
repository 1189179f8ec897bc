"""The rrc-pin command line: arms, urdf --check, check, demo."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from rrc_pin.cli import main
from rrc_pin.urdf_export import COMMITTED_DIR


def test_arms_table_lists_sources_and_assumptions(capsys):
    assert main(["arms"]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0].split()[:4] == ["name", "dof", "joints", "tool"]
    assert "barker6       6    RRRRRR" in out and "PUMA 560 values" in out
    assert "nadkarni_c2   6    PPPRRR" in out
    assert "panda" in out and "example-robot-data" in out


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
    exe = shutil.which("rrc-pin", path=str(Path(sys.executable).parent))
    if exe is None:
        pytest.fail("the rrc-pin console script is not installed next to this Python")
    out = subprocess.run([exe, "demo"], capture_output=True, text=True, timeout=300, check=True)
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
