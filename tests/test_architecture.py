"""Layering, exports and lint: the architecture of docs/api.md cannot drift."""

from __future__ import annotations

import ast
import importlib
import pkgutil
import re
import subprocess
import sys
from pathlib import Path

import pytest

import rrc_pin
import rrc_pin.solvers as solvers

ROOT = Path(__file__).resolve().parents[1]
UPPER = {"resolver", "control", "controller", "guidance", "cell", "cli", "demo", "dynamics",
         "maps", "console"}  # fmt: skip
TOP = {"console", "cli"}
"""The entry points: nothing else in rrc_pin imports them."""
LOWER = {"dh", "models", "urdf_export", "urdf_compare", "urdf_checks", "mimic", "robot",
         "loading", "errors", "cross_check", "link_capsules", "combined", "kinematics",
         "geometry", "deprecated"}  # fmt: skip
GEOMETRY_BELOW = {"tasks", "limits", *UPPER}
"""What the geometry layer never imports: it sits above robot, below the tasks and limits."""


def modules(package) -> list[str]:
    return [m.name for m in pkgutil.walk_packages(package.__path__, package.__name__ + ".")]


def test_solvers_never_imports_pinocchio_or_rrc_pin():
    """The numerics import nothing of rrc_pin above them: only the package's lazy root, which
    imports nothing itself."""
    code = (
        "import importlib, sys\n"
        f"for name in {modules(solvers)!r}: importlib.import_module(name)\n"
        "bad = sorted(m for m in sys.modules if m.split('.')[0] == 'pinocchio'\n"
        "             or (m.startswith('rrc_pin.') and not m.startswith('rrc_pin.solvers')))\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_lower_layers_never_import_upper_ones():
    for path in (ROOT / "rrc_pin").rglob("*.py"):
        rel = path.relative_to(ROOT / "rrc_pin").with_suffix("")
        if rel.parts[0] not in LOWER:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            for name in names:
                parts = name.split(".")
                assert not (parts[0] == "rrc_pin" and len(parts) > 1 and parts[1] in UPPER), (
                    rel,
                    name,
                )


def test_geometry_sits_below_the_tasks_and_limits():
    for path in (ROOT / "rrc_pin").rglob("*.py"):
        rel = path.relative_to(ROOT / "rrc_pin").with_suffix("")
        below = rel.parts[0] in ("geometry", "link_capsules", "combined", "mimic", "robot",
                                 "kinematics")
        for name in imported_names(path):
            parts = name.split(".")
            if below:
                assert not (parts[0] == "rrc_pin" and len(parts) > 1
                            and parts[1] in GEOMETRY_BELOW), (rel, name)  # fmt: skip
            if rel.parts[0] in ("models", "dh", "urdf_export", "mimic", "robot", "loading"):
                assert not (parts[:2] == ["rrc_pin", "geometry"]), (rel, name)


def imported_names(path: Path) -> list[str]:
    names = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module:
            names += [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            names += [a.name for a in node.names]
    return names


def test_only_the_entry_points_import_the_maps():
    """The capability maps sit above the resolver and the control loop (beside guidance and
    dynamics): only they themselves and the entry points (cli, console) import them; and
    the maps import no entry point."""
    for path in (ROOT / "rrc_pin").rglob("*.py"):
        rel = path.relative_to(ROOT / "rrc_pin").with_suffix("")
        names = imported_names(path)
        if rel.parts[0] in ("maps", "cli", "console"):
            if rel.parts[0] == "maps":
                assert not any(n.split(".")[:2] in (["rrc_pin", "cli"], ["rrc_pin", "console"])
                               for n in names), rel  # fmt: skip
            continue
        assert not any(n.startswith("rrc_pin.maps") for n in names), (rel, names)


def test_only_the_entry_points_import_the_console():
    """The console is the top layer beside the command line (DESIGN.md's layering)."""
    for path in (ROOT / "rrc_pin").rglob("*.py"):
        rel = path.relative_to(ROOT / "rrc_pin").with_suffix("")
        if rel.parts[0] in TOP:
            continue
        for name in imported_names(path):
            parts = name.split(".")
            assert not (parts[0] == "rrc_pin" and len(parts) > 1 and parts[1] == "console"), (
                rel,
                name,
            )


@pytest.mark.parametrize("package", [rrc_pin, solvers])
def test_every_module_imports(package):
    for name in modules(package):
        importlib.import_module(name)


def test_star_import_exports_exist():
    namespace: dict = {}
    exec("from rrc_pin import *", namespace)
    assert set(rrc_pin.__all__) <= set(namespace)
    assert rrc_pin.__all__ == sorted(rrc_pin.__all__)


def test_mypy_is_clean():
    """Strict typing of both packages (pyproject.toml's [tool.mypy])."""
    out = subprocess.run(
        [sys.executable, "-m", "mypy", "--no-incremental"],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stdout + out.stderr


def test_ruff_is_clean():
    out = subprocess.run(
        [sys.executable, "-m", "ruff", "check", "--no-cache", "."],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stdout + out.stderr


TIMING = re.compile(r"\d(\.\d+)? ?(us|µs|ns)\b")
"""A duration in micro- or nanoseconds: a measurement, which docs/api.md keeps, not the code."""


def test_the_package_holds_no_timings():
    """Measurements go stale with the code around them: docs/api.md ("One tick's cost") and
    docs/benchmarks.md keep them, with the machine and what was measured."""
    found = []
    for folder in (Path(rrc_pin.__file__).parent, Path(solvers.__file__).parent):
        for path in sorted(folder.rglob("*.py")):
            for k, line in enumerate(path.read_text().splitlines(), 1):
                if TIMING.search(line):
                    found.append(f"{path.relative_to(ROOT)}:{k}: {line.strip()}")
    assert not found, "\n".join(found)


LONGEST_FUNCTION = 60
"""The lines of code (after its docstring) a function of the package takes at most: a tick a
reader can follow, each stage a function (docs/api.md, "Layout")."""


def _code_lines(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    """The lines of ``node`` from its first statement after the docstring to its end."""
    first = node.body[0]
    docstring = (isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant)
                 and isinstance(first.value.value, str))  # fmt: skip
    start = first.end_lineno + 1 if docstring and len(node.body) > 1 else first.lineno
    return node.end_lineno - start + 1


def test_functions_are_short():
    """No function of the package (its kernels too) runs over LONGEST_FUNCTION lines."""
    found = []
    for folder in (Path(rrc_pin.__file__).parent, Path(solvers.__file__).parent):
        for path in sorted(folder.rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    lines = _code_lines(node)
                    if lines > LONGEST_FUNCTION:
                        found.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name}: {lines}")
    assert not found, "\n".join(found)


def test_a_users_solvers_module_beside_a_script_does_not_break_the_import(tmp_path):
    """Issue 40: a top-level package named ``solvers`` was shadowed by a user's solvers.py
    (``ModuleNotFoundError: No module named 'solvers.errors'``)."""
    (tmp_path / "solvers.py").write_text("raise RuntimeError('the user solvers.py was imported')\n")
    (tmp_path / "script.py").write_text(
        "import rrc_pin\n"
        "arm = rrc_pin.load('panda')\n"
        "r = rrc_pin.Resolver(arm).solve(arm.ready(), [0.0, 0.0, 0.01, 0.0, 0.0, 0.0])\n"
        "print(r.status, type(rrc_pin.errors.InvalidInput('x', 'y')).__module__)\n"
    )
    done = subprocess.run([sys.executable, "script.py"], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["exact", "rrc_pin.solvers.errors"]
