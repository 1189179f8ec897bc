"""Blocked default joint rates of Barker's arm (solvers/closed_form/barker_batch.py).

Reference: the general kernels of barker_kernels.py composed as before (arm rates with the
exact singularity test and M*, eq. (48), wrist rates with M2*), which
tests/test_closed_form_barker.py checks against Pinocchio.
"""

from __future__ import annotations

import numpy as np
import pytest

from solvers.closed_form import barker_kernels as K
from solvers.closed_form._batch import CHUNK
from solvers.closed_form.barker import BarkerClosedForm
from solvers.closed_form.barker_batch import joint_rates_full, screen_bounds

PUMA = {"no": 0.6718, "es": 0.4318, "sn": 0.15, "we": 0.4318, "a3": 0.0203, "r3": 0.0,
        "alpha3": np.pi / 2}  # fmt: skip
GEOMETRIES = {
    "puma": PUMA,
    "variant": {**PUMA, "alpha3": np.deg2rad(88.0), "a3": 0.02, "r3": 0.01},
    "signs": {**PUMA, "es": -0.4, "a3": -0.05, "alpha3": 2.5, "r3": -0.3},
}


@pytest.fixture(scope="module", params=list(GEOMETRIES))
def cf(request: pytest.FixtureRequest) -> BarkerClosedForm:
    return BarkerClosedForm(**GEOMETRIES[request.param])


def composed(cf: BarkerClosedForm, Q: np.ndarray, X: np.ndarray) -> np.ndarray:
    """The general kernels: exact singularity tests, generalized inverses where singular."""
    g, t = cf.geometry, K.trig(Q)
    arm = K.arm_rates_full(g, t, X[:, :3], cf.rcond)[0]
    wrist = K.wrist_rates(g, t, K.rvel_tilde(t, arm, X[:, 3:]), cf.rcond, False)[0]
    return np.concatenate([arm, wrist], axis=1)


def singular(cf: BarkerClosedForm, rng: np.random.Generator, n: int) -> np.ndarray:
    """n configurations on each of conditions (32), (33), S5 = 0 and their double (S2 = 0)."""
    g = cf.geometry
    Q = rng.uniform(-np.pi, np.pi, (4, n, 6))
    Q[0, :, 4] = rng.choice([0.0, np.pi, -np.pi], n)  # S5 = 0
    Q[1:3, :, 2] = np.arctan2(-g.a3, g.swe)  # eq. (33)
    Q[2, :, 1] = 0.0  # with S2 = 0: F1 = 0 too
    s3, c3 = np.sin(Q[3, :, 2]), np.cos(Q[3, :, 2])  # eq. (32): F1 = 0
    Q[3, :, 1] = np.arctan2(-(g.swe * s3 + g.a3 * c3), g.es + g.swe * c3 - g.a3 * s3)
    return Q.reshape(-1, 6)


def test_screen_bounds_imply_the_exact_tests(cf: BarkerClosedForm) -> None:
    rng = np.random.default_rng(85685)
    Q = rng.uniform(-np.pi, np.pi, (50_000, 6))
    F = K.f_terms(cf.geometry, K.trig(Q))
    fro2 = 2.0 * F.f1**2 + cf.geometry.f2**2 + F.f3**2 + F.f4**2 + F.f5**2
    det_min, s5_min = screen_bounds(cf._k, cf.rcond)
    worst = cf.rcond * fro2.max() ** 1.5
    assert worst <= det_min  # |det| > det_min implies |det| > rcond ||M||_F^3
    assert worst > 0.9 * det_min  # and the bound is nearly reached (not a loose screen)
    assert s5_min == 2.0 * cf.rcond  # >= rcond (1 + |C5|)


def test_regular_configurations_equal_the_general_kernels(cf: BarkerClosedForm) -> None:
    rng = np.random.default_rng(1983)
    Q = rng.uniform(-np.pi, np.pi, (20_000, 6))
    X = rng.normal(size=(20_000, 6))
    out, suspect = joint_rates_full(cf._k, Q, X, cf.rcond)
    ref = composed(cf, Q, X)
    keep = np.setdiff1d(np.arange(len(Q)), suspect)
    assert len(keep) >= 19_990  # random configurations are almost never flagged
    err = np.linalg.norm(out[keep] - ref[keep], axis=1) / np.linalg.norm(ref[keep], axis=1)
    assert err.max() < 1e-11  # reached: ~1e-13 (near-singular rows amplify rounding)
    assert np.median(err) < 1e-15


def test_every_singular_configuration_is_flagged(cf: BarkerClosedForm) -> None:
    rng = np.random.default_rng(32)
    S = singular(cf, rng, 50)
    Q = np.concatenate([rng.uniform(-np.pi, np.pi, (300, 6)), S])
    Q = Q[rng.permutation(len(Q))]
    X = rng.normal(size=(len(Q), 6))
    out, suspect = joint_rates_full(cf._k, Q, X, cf.rcond, chunk=64)
    s = cf.singularity_batch(Q)
    exact = np.flatnonzero(s.arm_singular | s.wrist_singular)
    assert len(exact) >= 190  # the constructed ones (a few of eq. (32) may round off it)
    assert np.isin(exact, suspect).all()
    assert np.array_equal(suspect, np.unique(suspect))  # sorted, no repeats
    keep = np.setdiff1d(np.arange(len(Q)), suspect)
    assert np.isfinite(out[keep]).all()
    np.testing.assert_allclose(out[keep], composed(cf, Q[keep], X[keep]), rtol=1e-9, atol=1e-9)


def test_block_size_does_not_change_the_result(cf: BarkerClosedForm) -> None:
    rng = np.random.default_rng(7)
    Q = np.concatenate([rng.uniform(-3.0, 3.0, (CHUNK + 1000, 6)), singular(cf, rng, 5)])
    X = rng.normal(size=(len(Q), 6))
    out, suspect = joint_rates_full(cf._k, Q, X, cf.rcond)
    finite = np.isfinite(out)
    for chunk, n in ((1, 300), (7, len(Q)), (1000, len(Q)), (3 * CHUNK, len(Q))):
        other, other_suspect = joint_rates_full(cf._k, Q[-n:], X[-n:], cf.rcond, chunk=chunk)
        np.testing.assert_array_equal(other_suspect, suspect[suspect >= len(Q) - n] - len(Q) + n)
        np.testing.assert_array_equal(other[finite[-n:]], out[-n:][finite[-n:]])  # bit for bit
    out, suspect = joint_rates_full(cf._k, Q[:0], X[:0], cf.rcond)
    assert out.shape == (0, 6) and suspect.shape == (0,)


def test_joint_rates_batch_repairs_the_flagged_rows(cf: BarkerClosedForm) -> None:
    rng = np.random.default_rng(60)
    Q = np.concatenate([rng.uniform(-np.pi, np.pi, (500, 6)), singular(cf, rng, 25)])
    X = rng.normal(size=(len(Q), 6))
    out = cf.joint_rates_batch(Q, X)
    ref = composed(cf, Q, X)
    assert np.isfinite(out).all()
    err = np.linalg.norm(out - ref, axis=1) / np.maximum(np.linalg.norm(ref, axis=1), 1e-300)
    assert err.max() < 1e-11
    assert cf.joint_rates_batch(Q[:0], X[:0]).shape == (0, 6)
