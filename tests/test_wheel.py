"""The distribution: ``python -m build`` makes an sdist and a wheel that hold the whole package.

The numerics' folder is imported as ``rrc_pin.solvers`` through a link in the checkout; the
sdist and the wheel must hold its files under ``rrc_pin/solvers/`` (a link would point outside
an installed package). Built from the checkout as a user would, into a temporary folder (the
wheel is built from the sdist, so the checkout gets no ``build/``). ``.ci/run`` installs this
wheel into a fresh, read-only environment and runs the demo there.
"""

from __future__ import annotations

import subprocess
import sys
import tarfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SOLVERS = {p.relative_to(ROOT).as_posix() for p in (ROOT / "solvers").rglob("*.py")}


def test_the_wheel_and_the_sdist_hold_the_numerics_as_files(tmp_path):
    done = subprocess.run([sys.executable, "-m", "build", "--outdir", str(tmp_path), str(ROOT)],
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    (wheel,) = tmp_path.glob("rrc_pin-*-py3-none-any.whl")
    (sdist,) = tmp_path.glob("rrc_pin-*.tar.gz")
    names = set(zipfile.ZipFile(wheel).namelist())
    assert {f"rrc_pin/{name}" for name in SOLVERS} <= names  # every numerics module
    assert "rrc_pin/solvers/tick/pipeline.py" in names and "rrc_pin/py.typed" in names
    assert not any(n.startswith(("solvers/", "tests/", "benchmarks/")) for n in names)
    entry = next(n for n in names if n.endswith(".dist-info/entry_points.txt"))
    assert "rrc-pin = rrc_pin.cli:main" in zipfile.ZipFile(wheel).read(entry).decode()
    with tarfile.open(sdist) as archive:
        members = {m.name.split("/", 1)[1]: m for m in archive.getmembers() if "/" in m.name}
    pipeline = members["rrc_pin/solvers/tick/pipeline.py"]
    assert pipeline.isfile() and not members["rrc_pin/solvers"].issym()
