"""What a benchmark run ran on: CPU, core count, Python and library versions."""

from __future__ import annotations

import importlib
import os
import platform
from pathlib import Path
from typing import Any


def machine_info(*packages: str) -> dict[str, Any]:
    """CPU, Python, numpy and Pinocchio versions, plus those of ``packages`` (None if absent)."""
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
    }
    for name in ("numpy", "pinocchio", *packages):
        try:
            info[name] = importlib.import_module(name).__version__
        except ImportError:
            info[name] = None
    return info
