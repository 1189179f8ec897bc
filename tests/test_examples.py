"""Every script in examples/ runs, in its quick size, as a user would run it (issue 33 item 1).

Each example is found by its file (adding one is adding the file), run as ``__main__`` with
``RRC_PIN_EXAMPLES_QUICK=1`` from an empty working directory, matplotlib hidden (the README's
first set-up command installs none; an example that draws says which extra it needs and runs
without it); those that draw run once more with it. None may write into the working
directory or the checkout.
"""

from __future__ import annotations

import os
import re
import runpy
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))


def checkout_files() -> set[str]:
    """The checkout's files, but where tools write (git, venvs, caches; not walked)."""
    out = set()
    for folder, subfolders, files in os.walk(ROOT):
        subfolders[:] = [d for d in subfolders
                         if not d.startswith((".git", ".venv", ".pytest", ".mypy", ".ruff",
                                               ".hypothesis"))
                         and d != "__pycache__" and not d.endswith(".egg-info")]  # fmt: skip
        out.update(os.path.relpath(os.path.join(folder, f), ROOT) for f in files)
    return out


def run_example(path: Path, tmp_path: Path, monkeypatch, matplotlib: bool) -> None:
    cwd, temp = tmp_path / "cwd", tmp_path / "temp"
    cwd.mkdir(parents=True)
    temp.mkdir(parents=True)
    monkeypatch.chdir(cwd)
    monkeypatch.setattr(tempfile, "tempdir", str(temp))  # the example's temporary folders
    monkeypatch.setenv("RRC_PIN_EXAMPLES_QUICK", "1")
    monkeypatch.setattr(sys, "argv", [str(path)])
    if not matplotlib:
        monkeypatch.setitem(sys.modules, "matplotlib", None)  # import fails: not installed
    runpy.run_path(str(path), run_name="__main__")
    assert list(cwd.iterdir()) == [], f"{path.name} wrote into the working directory"


def test_there_are_examples_of_each_kind():
    names = {p.stem for p in EXAMPLES}
    assert {"one_twist_with_limits", "teleoperation", "two_arms_strict_priorities",
            "custom_task", "guidance", "control_schemes"} <= names  # fmt: skip


SESSIONS = {"tripod_balance", "tripod_walk"}
"""Examples that run a cell for thousands of ticks: minutes with the kernels as plain Python."""


@pytest.mark.parametrize(
    "path",
    [pytest.param(p, marks=pytest.mark.compiled) if p.stem in SESSIONS else p for p in EXAMPLES],
    ids=[p.stem for p in EXAMPLES],
)
def test_the_example_runs_and_says_what_it_shows(path, tmp_path, monkeypatch, capsys):
    text = path.read_text()
    doc = text.split('"""')[1]
    assert f"Run: ``python examples/{path.name}``" in doc  # how to run it, said at its top
    assert "pip install -e ." in doc  # what it needs
    before = checkout_files()
    if "matplotlib" in text:  # it draws when it can, into its temporary folder
        run_example(path, tmp_path / "plot", monkeypatch, matplotlib=True)
        written = re.findall(r"written to (\S+\.png)", capsys.readouterr().out)
        assert written and all(Path(p).is_file() for p in written)
        assert all(Path(p).is_relative_to(tmp_path) for p in written)
    run_example(path, tmp_path, monkeypatch, matplotlib=False)
    out = capsys.readouterr().out
    assert len(out.splitlines()) >= 3 and "nan" not in out.lower(), out
    assert checkout_files() == before, f"{path.name} wrote into the checkout"
