"""The documents are true: every Python block of the README and docs/ runs, what they name exists.

A fenced block is ```python (run here, each in a fresh namespace from an empty working
directory, its temporary files in a temporary folder), ```python-signature (a signature sketch
whose names are placeholders: not run, by design), ```bash or plain text. What a block shows
is checked beside it where it says a number (:data:`CHECKS`).
"""

from __future__ import annotations

import re
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```([\w-]*)\n(.*?)^```[ \t]*$", re.M | re.S)
KINDS = ("python", "python-signature", "bash", "")
"""The fences a document may use: run, a signature sketch (not run), shell, text."""


def blocks(kind: str) -> list[tuple[str, str]]:
    """``(where, code)`` of every block of ``kind``: where is ``path:line``."""
    out = []
    for path in DOCUMENTS:
        text = path.read_text()
        for match in FENCE.finditer(text):
            if match.group(1) == kind:
                line = text.count("\n", 0, match.start()) + 1
                out.append((f"{path.relative_to(ROOT)}:{line}", match.group(2)))
    return out


PYTHON = blocks("python")


def compiled_only(code: str) -> list[pytest.MarkDecorator]:
    """Maps of 10^5 samples: seconds compiled, too slow as plain Python (pyproject's marker)."""
    return [pytest.mark.compiled] if "maps.capability(" in code else []


def reaches(ns: dict) -> bool:
    T, goal = ns["arm"].fk(ns["q"]), ns["goal"]
    return bool(np.linalg.norm(T[:3, 3] - goal[:3, 3]) < 1e-4)


CHECKS: dict[str, Callable[[dict], bool]] = {
    # the README's tour: the two-level answer reads exact, the posture traded
    'baxter = rrc_pin.load("baxter")': lambda ns: (
        ns["r"].status == "exact" and ns["r"].levels == ("met", "traded")
        and [t.served for t in ns["r"].tasks] == ["met", "met", "traded"]
        and ns["Qdot"].shape == (1000, 6)),
    "target=goal, gain=5.0": reaches,
    '"gsfc_dual", dt=0.01)         # two': lambda ns: (
        ns["dual"].log[-1].grip["object"] < 1e-9 and ns["step"].resolution.status == "exact"),
    "rrc_pin.make_cell(arms,": lambda ns: (
        ns["r"].status == "exact" and ns["ctl"].log[-1].grip["box"] < 1e-9),
    "buildSampleModelManipulator": lambda ns: (
        ns["r"].status == "exact" and ns["arm5"].nq == 5 and ns["arm5"].tool_frame == "tool0"),
    "class FloorLimit(Limit)": lambda ns: (
        ns["r"].active_rows[0].name == "floor:panda_hand_tcp"
        and ns["arm"].fk(ns["q"])[2, 3] >= ns["floor"].height - 1e-12),
    'add_box(T_table, (0.3, 0.6, 0.05), name="table")': lambda ns: (
        min(row.distance for row in ns["res"].active_rows) > 0.0199),
    "TrajectoryLog.load(path)": lambda ns: len(ns["log"]) == 500 and ns["back"].reached,
}


def test_every_fence_is_of_a_known_kind():
    for path in DOCUMENTS:
        text = path.read_text()
        found = [m.group(1) for m in FENCE.finditer(text)]
        assert set(found) <= set(KINDS), (path, found)
        assert 2 * len(found) == len(re.findall(r"^```", text, re.M)), path  # all paired
    assert len(PYTHON) >= 11


@pytest.mark.parametrize(("where", "code"),
                         [pytest.param(w, c, id=w, marks=compiled_only(c)) for w, c in PYTHON])
def test_every_python_block_of_the_documents_runs(where, code, tmp_path, monkeypatch):
    cwd, temp = tmp_path / "cwd", tmp_path / "temp"
    cwd.mkdir()
    temp.mkdir()
    monkeypatch.chdir(cwd)
    monkeypatch.setattr(tempfile, "tempdir", str(temp))  # the block's temporary files
    monkeypatch.syspath_prepend(str(cwd))
    namespace: dict = {"__name__": "__docs__"}
    exec(compile(code, where, "exec"), namespace)
    assert list(cwd.iterdir()) == [], f"{where} wrote into the working directory"
    for key, check in CHECKS.items():
        if key in code:
            assert check(namespace), (where, key)


def test_every_check_meets_its_block():
    """A check whose block was edited away would pass by never running."""
    for key in CHECKS:
        assert sum(key in code for _, code in PYTHON) == 1, key


def test_the_readme_lists_every_example():
    table = (ROOT / "README.md").read_text().split("### Examples", 1)[1].split("\n## ", 1)[0]
    listed = re.findall(r"^\| `(\w+\.py)` \|", table, re.M)
    assert sorted(listed) == sorted(p.name for p in (ROOT / "examples").glob("*.py"))


def test_no_development_tool_is_named():
    """The project's documents name no tool its users do not have."""
    for path in [*DOCUMENTS, ROOT / "CHANGELOG.md"]:
        text = path.read_text()
        for word in ("farm-studio", "duplicates D", "issues show", "issues note"):
            assert word not in text, (path, word)


def test_the_readme_says_what_robot_accepts():
    """The README said Robot refuses free-flyer joints; it accepts one as the root."""
    text = (ROOT / "README.md").read_text()
    assert "refuses (a free flyer)" not in text and "a free-flyer root" in text


def test_every_erratum_names_existing_tests():
    text = (ROOT / "docs" / "errata.md").read_text()
    rows = [line for line in text.splitlines() if line.startswith("| ") and "---" not in line]
    rows = [row for row in rows if not row.startswith("| document ")]
    assert len(rows) >= 25
    for row in rows:
        refs = re.findall(r"(tests/test_\w+\.py)::(\w+)", row)
        assert refs, f"no test named in: {row[:120]}"
        for path, name in refs:
            source = (ROOT / path).read_text()
            assert re.search(rf"def {name}\b", source), f"{path}::{name} does not exist"


def test_documents_stand_alone():
    """A clone has no ../shared: the README and docs never point there."""
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        assert "../shared" not in path.read_text(), path


def test_readme_command_table_says_which_extra_each_command_needs():
    """Issue 33 item 9: `rrc-pin bench` failed after the README's set-up with "pink not
    installed": the table names the extra of every command."""
    from rrc_pin.cli import parser

    text = (ROOT / "README.md").read_text()
    table = text.split("## Command line", 1)[1].split("\n\n", 2)[1]
    lines = table.splitlines()
    assert lines[0] == "| command | needs | what it does |"
    rows = {line.split("|")[1].strip().split()[1].strip("`"): line.split("|")[2].strip()
            for line in lines[2:]}  # fmt: skip
    commands = parser()._subparsers._group_actions[0].choices  # every command of the CLI
    assert set(rows) == set(commands)
    assert rows["bench"] == "`[bench]`" and "`[plot]`" in rows["demo"]
    assert all(rows[c] == "-" for c in ("arms", "check", "urdf", "guidance"))
