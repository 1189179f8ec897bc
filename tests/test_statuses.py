"""rrc_pin.solvers.tick.statuses: its codes name the pipeline's statuses, its rules against plain
numpy references; and problem.cap, the cap on huge commands both ticks share, against numpy."""

from __future__ import annotations

from typing import get_args

import numpy as np
import pytest

from rrc_pin.solvers.tick import statuses
from rrc_pin.solvers.tick.pipeline import LevelStatus, Status, served
from rrc_pin.solvers.tick.problem import LARGE, SATURATION, cap
from rrc_pin.solvers.tick.statuses import scale_and_veer

SEEDS = [20261206, int(np.random.SeedSequence().entropy % 2**63)]


def test_codes_index_the_pipelines_statuses() -> None:
    names = get_args(Status)
    codes = {"exact": statuses.EXACT, "scaled": statuses.SCALED, "sliding": statuses.SLIDING,
             "damped": statuses.DAMPED, "singular": statuses.SINGULAR,
             "least_squares": statuses.LEAST_SQUARES, "recovering": statuses.RECOVERING,
             "fallback": statuses.FALLBACK}  # fmt: skip
    for name, code in codes.items():
        assert names[code] == name
    levels = {"met": statuses.MET, "scaled": statuses.SCALED_LEVEL, "traded": statuses.TRADED,
              "dropped": statuses.DROPPED}  # fmt: skip
    for name, code in levels.items():
        assert get_args(LevelStatus)[code] == name


def served_reference(y: np.ndarray, b: np.ndarray, rate_factor: float) -> int:
    """The lower level's rule in numpy (the scale and angle on b's own size)."""
    peak = max(float(np.abs(b).max()), float(np.abs(y).max()), 1e-300)
    ys, bs = y / peak, b / peak
    if np.linalg.norm(ys - bs) <= 1e-9 * (1.0 / peak + np.linalg.norm(bs)):
        return statuses.MET if rate_factor == 1.0 else statuses.SCALED_LEVEL
    if not b.any() or not ys.any():
        return statuses.TRADED
    cos = float(ys @ bs) / (np.linalg.norm(ys) * np.linalg.norm(bs))
    veer = float(np.arccos(np.clip(cos, -1.0, 1.0)))
    return statuses.SCALED_LEVEL if veer <= 1e-6 and ys @ bs > 0.0 else statuses.TRADED


@pytest.mark.parametrize("seed", SEEDS)
def test_served_against_numpy(seed: int) -> None:
    """Met, scaled along the command (slower or faster), turned off it, or a zero command:
    the kernel's code is the numpy rule's, the pipeline's word names it."""
    rng = np.random.default_rng(seed)
    seen = set()
    for _ in range(400):
        m = int(rng.integers(1, 7))
        b = rng.normal(size=m) * 10.0 ** rng.uniform(-3, 3)
        case = int(rng.integers(5))
        y = [b.copy(), b * rng.uniform(0.1, 0.9), b + rng.normal(size=m) * np.abs(b).max(),
             -b, np.zeros(m)][case]  # fmt: skip
        if case == 4:
            b = np.zeros(m) if rng.random() < 0.5 else b
            y = rng.normal(size=m) if rng.random() < 0.5 else y
        factor = 1.0 if rng.random() < 0.7 else float(rng.uniform(1e-6, 0.5))
        code = statuses.served(y, b, factor)
        assert code == served_reference(y, b, factor), (seed, case, y, b, factor)
        seen.add(code)
        if factor == 1.0:
            assert served(y, b) == get_args(LevelStatus)[code]
    assert seen == {statuses.MET, statuses.SCALED_LEVEL, statuses.TRADED}, seed


def test_a_met_top_level_is_exact_only_for_the_command_itself() -> None:
    assert statuses.met_top(1.0) == statuses.EXACT
    for factor in (0.5, 1e-200, 1.0 - 2.0**-52):
        assert statuses.met_top(factor) == statuses.SCALED


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("normalised", [True, False])
def test_cap_against_numpy(seed: int, normalised: bool) -> None:
    """Below the threshold the rates are kept; above it they are divided to the rows' reach
    (1 + max|A| sum of the box's finite sides) times SATURATION, at most LARGE in the direction
    level."""
    rng = np.random.default_rng(seed)
    for _ in range(200):
        m, n = int(rng.integers(1, 7)), int(rng.integers(1, 8))
        A = rng.normal(size=(m, n))
        lb, ub = -rng.uniform(0.1, 2.0, n), rng.uniform(0.1, 2.0, n)
        lb[rng.random(n) < 0.2] = -np.inf
        factor = 1.0 if rng.random() < 0.5 else float(rng.uniform(1e-3, 1.0))
        command = 10.0 ** rng.uniform(0, 305)
        peak = command * factor
        sides = np.maximum(-lb, ub)
        limit = SATURATION * (1.0 + np.abs(A).max() * sides[np.isfinite(sides)].sum())
        limit = min(limit, LARGE) if normalised else limit
        below = command <= (LARGE if normalised else SATURATION) or command <= limit
        want = 1.0 if below else limit / peak
        got = cap(A, peak, factor, normalised, lb, ub)
        assert got == pytest.approx(want, rel=1e-14), (seed, command, factor)
        if not below:
            assert command * factor * got == pytest.approx(limit, rel=1e-14)


@pytest.mark.parametrize("seed", SEEDS)
def test_borne_out_against_numpy(seed: int) -> None:
    """An exact or scaled report of a command whose rates are all subnormal is refused
    (the fallbacks in the direction mode, else least_squares); an exact one whose scale the
    shrink into the rows took below 1 is scaled; every other report kept."""
    rng = np.random.default_rng(seed)
    for _ in range(400):
        m = int(rng.integers(1, 7))
        b = rng.normal(size=m) * 10.0 ** rng.choice([-320.0, -310.0, -12.0, 0.0, 90.0])
        b[rng.random(m) < 0.2] = 0.0
        y = b * rng.uniform(0.0, 1.0)
        status = [statuses.EXACT, statuses.SCALED, statuses.DAMPED][int(rng.integers(3))]
        scale = float(rng.choice([1.0, 1.0 - 1e-12, 1.0 - 1e-6, 0.5, 0.0]))
        direction = bool(rng.random() < 0.7)
        got = statuses.borne_out(status, y, b, direction, 1.0, scale, 0.25)
        peak = float(np.abs(b).max())
        claims = status in (statuses.EXACT, statuses.SCALED)
        if claims and 0.0 < peak < np.finfo(np.float64).tiny:
            want = statuses.FAILED if direction else statuses.LEAST_SQUARES
        elif status == statuses.EXACT and scale < 1.0 - statuses.EXACT_TOL:
            want = statuses.SCALED
        else:
            want = status
        assert got == (want, scale, 0.25), (seed, status, b, direction, scale)


def test_a_subnormal_command_met_to_one_task_unit_is_refused() -> None:
    """The command of seed 2431896685595554185, step 47 (so101): its rates 46 % off, and
    zero rates, both within EXACT_TOL of it: not exact."""
    b = np.array([-1e-310, -5e-324, -1e-310])
    y = np.array([-1.46e-310, -8.06e-312, -1.75e-311])
    for rates in (y, np.zeros(3)):
        assert statuses.met(rates, b)
        assert statuses.borne_out(statuses.EXACT, rates, b, True, 1.0, 1.0, 0.0)[0] == (
            statuses.FAILED)  # fmt: skip
        assert statuses.borne_out(statuses.EXACT, rates, b, False, 1.0, 1.0, 0.0)[0] == (
            statuses.LEAST_SQUARES)  # fmt: skip


def scale_and_veer_reference(y: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """The scale and veer in plain numpy (the pipeline's former Python implementation)."""
    top_b = float(np.abs(b).max()) if b.size else 0.0
    if top_b == 0.0:
        return 1.0, 0.0
    top_y = float(np.abs(y).max())
    if top_y == 0.0:
        return 0.0, 0.0
    bn, yn = b / top_b, y / top_y
    cosine = float(yn @ bn) / (np.linalg.norm(yn) * np.linalg.norm(bn))
    veer = float(np.arccos(np.clip(cosine, -1.0, 1.0)))
    with np.errstate(over="ignore"):
        ratio = float(np.float64(top_y) / top_b) * float(yn @ bn) / float(bn @ bn)
    return min(max(ratio, 0.0), 1.0), veer


def test_scale_and_veer_against_numpy(rng: np.random.Generator) -> None:
    for _ in range(2000):
        m = int(rng.integers(1, 13))
        b = rng.normal(size=m) * 10.0 ** rng.uniform(-300, 300)
        y = (rng.uniform(-0.5, 1.5) * b + rng.normal(size=m) * rng.choice([0.0, 1e-6, 1.0])
             * np.abs(b).max())  # fmt: skip
        y = y / np.abs(y).max() * 10.0 ** rng.uniform(-300, 300) if rng.random() < 0.3 else y
        scale, veer = scale_and_veer(y, b)
        reference = scale_and_veer_reference(y, b)
        assert scale == pytest.approx(reference[0], rel=1e-12, abs=1e-300)
        assert veer == pytest.approx(reference[1], abs=1e-7)  # acos near 0: sqrt of rounding
        factor = rng.uniform(0.01, 100.0, m)  # a level's metric: command first divided down
        peak = max(1.0, float(np.abs(b).max()))
        scale, veer = scale_and_veer(y, b, factor)
        reference = scale_and_veer_reference(factor * (y / peak), factor * (b / peak))
        assert scale == pytest.approx(reference[0], rel=1e-12, abs=1e-300)
        assert veer == pytest.approx(reference[1], abs=1e-7)
    assert scale_and_veer(np.zeros(0), np.zeros(0)) == (1.0, 0.0)
    huge = np.array([1.7e308, -1.7e308])  # times 100 would overflow
    scale, veer = scale_and_veer(0.5 * huge, huge, np.full(2, 100.0))
    assert scale == pytest.approx(0.5) and veer < 1e-7
    assert scale_and_veer(np.array([1.0, 0.0]), np.array([5e-324, 0.0])) == (1.0, 0.0)
    assert scale_and_veer(np.array([5e-324, 0.0]), np.array([1e308, 0.0]))[0] == 0.0
