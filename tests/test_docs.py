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
