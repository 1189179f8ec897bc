"""The documents point at things that exist: every test named in docs/errata.md is real."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


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


def test_readme_example_runs():
    text = (ROOT / "README.md").read_text()
    example = text.split("```python", 1)[1].split("```", 1)[0]
    namespace: dict = {}
    exec(compile(example, "README.md", "exec"), namespace)
    r = namespace["r"]
    assert r.qdot.shape == (15,) and r.method == "qp"
    assert [t.level for t in r.tasks] == [0, 0, 1]
    assert namespace["Qdot"].shape == (1000, 6)


def test_documents_stand_alone():
    """A clone has no ../shared: the README and docs never point there."""
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        assert "../shared" not in path.read_text(), path


def test_readme_runs_a_robot_from_any_pinocchio_model():
    """Issue 33 item 9: Robot(pinocchio.Model, tool_frames, ...) worked and was not documented."""
    text = (ROOT / "README.md").read_text()
    blocks = [b.split("```", 1)[0] for b in text.split("```python")[1:]]
    snippet = next(b for b in blocks if "rrc_pin.Robot(" in b)
    namespace: dict = {}
    exec(compile(snippet, "README.md", "exec"), namespace)
    assert namespace["r"].status == "exact" and namespace["r"].qdot.shape == (6,)
    assert namespace["arm5"].nq == 5 and namespace["arm5"].tool_frame == "tool0"
    assert "pinocchio.buildReducedModel" in text


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
