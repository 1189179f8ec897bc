"""What a benchmark run ran on: CPU, cores, Python and library versions, load, code measured."""

from __future__ import annotations

import hashlib
import importlib
import os
import platform
import subprocess
from pathlib import Path
from typing import Any

CHECKOUT = Path(__file__).resolve().parents[1]
SOURCES = ("rrc_pin", "solvers")
"""Folders whose Python files are the code measured (hashed into :func:`source_state`)."""


def machine_info(*packages: str) -> dict[str, Any]:
    """CPU, Python, numpy and Pinocchio versions, plus those of ``packages`` (None if absent).

    Also the BLAS thread setting (the benchmarks pin it to 1 before numpy is imported).
    """
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    info: dict[str, Any] = {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "platform": platform.platform(),
        "python": platform.python_version(),
        "blas_threads": os.environ.get("OPENBLAS_NUM_THREADS"),
    }
    for name in ("numpy", "pinocchio", *packages):
        info[name] = package_version(name)
    return info


def package_version(name: str) -> str | None:
    """``name.__version__``, or the distribution's version, or None when it is not installed."""
    try:
        module = importlib.import_module(name)
    except ImportError:
        return None
    version = getattr(module, "__version__", None)
    if version is None:
        from importlib import metadata

        for dist in (name, name.replace("_", "-"), f"pin-{name}", name.removeprefix("py")):
            try:
                return metadata.version(dist)
            except metadata.PackageNotFoundError:
                continue
    return None if version is None else str(version)


def load_average() -> list[float]:
    """The 1, 5 and 15-minute load averages (processes waiting for or running on a core)."""
    return [round(x, 2) for x in os.getloadavg()]


def source_state() -> dict[str, Any]:
    """The code measured: git commit, whether the work tree differs from it, and a hash.

    The hash (sha256, first 12 hex digits) covers every ``*.py`` under :data:`SOURCES`, so
    that two runs on uncommitted code can still be told apart.
    """
    digest = hashlib.sha256()
    for folder in SOURCES:
        for path in sorted((CHECKOUT / folder).rglob("*.py")):
            digest.update(str(path.relative_to(CHECKOUT)).encode())
            digest.update(path.read_bytes())
    state: dict[str, Any] = {"source_sha256": digest.hexdigest()[:12], "commit": None}
    try:
        commit = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"],
            cwd=CHECKOUT,
            capture_output=True,
            text=True,
            check=True,
            timeout=10,
        )
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--", *SOURCES],
            cwd=CHECKOUT,
            capture_output=True,
            text=True,
            check=True,
            timeout=10,
        )
    except (OSError, subprocess.SubprocessError):
        return state
    state["commit"] = commit.stdout.strip()
    changed = [line[3:] for line in dirty.stdout.splitlines() if line.strip()]
    state["uncommitted_changes"] = bool(changed)
    state["changed_files"] = changed
    return state
