"""The resolver answers recorded ticks as the code that recorded them did.

tests/data/tick_answers.npz holds the first 20 ticks of every case of
benchmarks/tick_answers.py (every catalogue arm in each of its modes, and two collision scenes;
80 for those), their inputs and the answers of the tick before it was compiled as one pass:
a change of the tick's shape must change its speed, not its answers. ``python
benchmarks/tick_answers.py compare`` runs the same comparison on any recording (10,000 ticks
and more); here, every recorded tick is answered again in its order, by a fresh resolver per
case.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
try:
    import tick_answers
finally:
    sys.path.remove(str(ROOT / "benchmarks"))

DATA = ROOT / "tests" / "data" / "tick_answers.npz"
TOL = 1e-8
"""Relative difference of the rates and scales allowed. The kernels' answers agree to 1e-14 on
the recording's machine; a QP the backend answers moves with the last bits of its data (the
compiled tick forms them in its own loops, not numpy's BLAS): up to 1.1e-9 here, on a strict
stack whose damped rates DAQP scales. Another CPU rounds otherwise too."""
VEER_TOL = 1e-7
"""[rad] The veer of rates along the command is the arccosine of a cosine within rounding of 1:
a difference of 1e-16 in it reads 1.5e-8 rad."""


@pytest.fixture(scope="module")
def recorded() -> dict[str, np.ndarray]:
    with np.load(DATA) as data:
        return {key: data[key] for key in data.files}


CASES = {case.name: case for case in tick_answers.cases()}


def test_every_case_is_recorded(recorded: dict[str, np.ndarray]) -> None:
    assert sorted(recorded["cases"].tolist()) == sorted(CASES)
    assert len(CASES) > 100


@pytest.mark.parametrize("name", sorted(CASES))
def test_recorded_ticks_answered_alike(recorded: dict[str, np.ndarray], name: str) -> None:
    now = tick_answers.replay(recorded, CASES[name])
    found = tick_answers.differences(recorded, name, now)
    assert found["ticks"] == len(recorded[f"{name}/qdot"]) >= 20
    assert found["differ"] == {}, f"{name}: ticks with another status, method or levels"
    assert found["rates"] <= TOL, f"{name}: tick {found['worst']}"
    assert found["scale"] <= TOL and found["veer"] <= VEER_TOL
