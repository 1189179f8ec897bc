"""The resolver answers recorded ticks as the code that recorded them did.

tests/data/tick_answers.npz holds the first 20 ticks of every case of
benchmarks/tick_answers.py (every catalogue arm in each of its modes, and two collision scenes;
80 for those), their inputs and the answers of the tick before it was compiled as one pass:
a change of the tick's shape must change its speed, not its answers. ``python
benchmarks/tick_answers.py compare`` runs the same comparison on any recording (10,000 ticks
and more); here, every recorded tick is answered again in its order, by a fresh resolver per
case.

Two changes since move the answers of ticks DAQP answered: a row the levels above hold (a
joint they keep at its bound, to the rounding of their null space) is no longer in a level's
QP, and a square level's tie-broken QP is projected by the kernel where well conditioned. A
tick answered otherwise must serve every level at least as well as the recording: level by
level, the first task error that differs is the new answer's smaller, or within 1e-6
(``tick_answers.shortfall``).
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
"""Relative difference of the rates and scales allowed: the kernels' answers agree to 1e-14 on
the recording's machine, and another CPU rounds otherwise. Where the old tick's answer came from
the backend (DAQP), its answer moves with the last bits of its data (up to 7.5e-9 on the
humanoids' three-level stacks). A rate beyond it must serve the levels no worse (module
docstring)."""
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
    changed = found["per_tick"] > TOL
    short = found["short"][changed]
    assert (short == 0.0).all(), f"{name}: ticks {np.flatnonzero(changed)} short by {short}"
    assert found["differ"].get("status", []) == [], f"{name}: ticks with another status"
    assert found["scale"] <= TOL and found["veer"] <= VEER_TOL
