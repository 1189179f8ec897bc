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
