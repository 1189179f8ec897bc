"""The batch machinery of the closed forms (solvers/closed_form/_batch.py): blocks, cos_sin.

``cos_sin`` is checked against sines and cosines computed in 50-digit decimal arithmetic,
so that neither it nor libm is the reference.
"""

from __future__ import annotations

from decimal import Decimal, localcontext

import numpy as np
import pytest

from solvers.closed_form import _batch
from solvers.closed_form._batch import CHUNK, LIMIT, TABLE_SIZE, blocks, cos_sin

PI = Decimal("3.14159265358979323846264338327950288419716939937510582097494459")
TOL = 1.2e-16  # reached: 1.11e-16, the same as numpy.sin / numpy.cos against the exact values


def exact_sin(x: float | Decimal) -> float:
    """sin(x) in 50-digit arithmetic, rounded to a float."""
    with localcontext() as ctx:
        ctx.prec = 50
        x = Decimal(x)
        x -= (x / (2 * PI)).to_integral_value() * 2 * PI
        total, term, i = Decimal(0), x, 1
        while abs(term) > Decimal(10) ** -45:
            total += term
            term = -term * x * x / ((i + 1) * (i + 2))
            i += 2
        return float(total)


def exact_cos_sin(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c = np.array([exact_sin(Decimal(v) + PI / 2) for v in q.ravel()]).reshape(q.shape)
    s = np.array([exact_sin(v) for v in q.ravel()]).reshape(q.shape)
    return c, s


def test_blocks_cover_the_range_in_order():
    for n, size in ((0, 8), (1, 8), (8, 8), (9, 8), (20_000, CHUNK), (5, 0)):
        rows = list(blocks(n, size))
        covered = np.concatenate([np.arange(n)[r] for r in rows]) if rows else np.empty(0)
        np.testing.assert_array_equal(covered, np.arange(n))
        assert all(r.stop - r.start <= max(size, 1) for r in rows)
    assert [r.stop for r in blocks(20_000)] == [8192, 16384, 20000]


def test_reduction_constants_and_tables():
    with localcontext() as ctx:
        ctx.prec = 50
        step = PI / (TABLE_SIZE // 2)
        assert abs(Decimal(_batch._P1) + Decimal(_batch._P2) - step) < Decimal("1e-27")
        assert abs(Decimal(_batch._INV_STEP) - 1 / step) < Decimal("1e-13")
    mantissa = np.frexp(_batch._P1)[0] * 2.0**27  # k * _P1 exact for |k| < 2^26
    assert mantissa == np.floor(mantissa)
    assert LIMIT * _batch._INV_STEP < 2.0**26
    k = np.arange(TABLE_SIZE)
    ref_s = np.array([exact_sin(Decimal(int(j)) * PI / (TABLE_SIZE // 2)) for j in k])
    ref_c = np.array([exact_sin(Decimal(int(j)) * PI / (TABLE_SIZE // 2) + PI / 2) for j in k])
    assert np.abs(_batch._SIN - ref_s).max() <= 1.2e-16  # reached: 1.1e-16 (an ulp near 1)
    assert np.abs(_batch._COS - ref_c).max() <= 1.2e-16
    quarter = TABLE_SIZE // 4
    assert _batch._SIN[0] == _batch._SIN[2 * quarter] == 0.0  # exact zeros and ones
    assert _batch._COS[quarter] == _batch._COS[3 * quarter] == 0.0
    assert _batch._SIN[quarter] == _batch._COS[0] == 1.0


@pytest.mark.parametrize("scale", [np.pi, 10.0, 1e3, LIMIT])
def test_cos_sin_against_exact_values(scale):
    rng = np.random.default_rng(int(scale))
    q = rng.uniform(-scale, scale, 600)
    c, s = cos_sin(q)
    ref_c, ref_s = exact_cos_sin(q)
    assert np.abs(c - ref_c).max() <= TOL
    assert np.abs(s - ref_s).max() <= TOL


def test_cos_sin_at_table_nodes_and_special_angles():
    nodes = np.arange(-1100, 1100) * (np.pi / 512)  # k pi / 512 in floats, and their neighbours
    edges = (np.arange(-1100, 1100) + 0.5) * (np.pi / 512)  # where the reduction rounds
    special = [0.0, -0.0, 5e-324, 1e-300, -1e-8, np.pi, -np.pi, np.pi / 2, 2 * np.pi]
    q = np.concatenate([nodes, np.nextafter(nodes, np.inf), np.nextafter(nodes, -np.inf),
                        edges, special])  # fmt: skip
    c, s = cos_sin(q)
    ref_c, ref_s = exact_cos_sin(q)
    assert np.abs(c - ref_c).max() <= TOL
    assert np.abs(s - ref_s).max() <= TOL
    c, s = cos_sin(np.array([0.0, np.pi]))
    assert c[0] == 1.0 and s[0] == 0.0 and c[1] == -1.0
    # sin of the float pi is 1.22e-16: absolute error 3e-26 (the reduction's third part,
    # 6.4e-29 per step, is left out), not relative accuracy
    assert abs(s[1] - 1.2246467991473532e-16) < 1e-25


def test_beyond_the_limit_falls_back_to_numpy():
    rng = np.random.default_rng(5)
    q = np.concatenate([rng.uniform(-1.0, 1.0, 100), [LIMIT * 1.5, -1e12, 1e300]])
    c, s = cos_sin(q)  # one block containing large angles: numpy's values for all of it
    np.testing.assert_array_equal(c, np.cos(q))
    np.testing.assert_array_equal(s, np.sin(q))


def test_shapes_blocks_and_out_arrays():
    rng = np.random.default_rng(11)
    Q = rng.uniform(-4.0, 4.0, (3 * CHUNK + 17, 7))
    C, S = cos_sin(Q.T)  # non-contiguous input, several blocks and a short last one
    assert C.shape == S.shape == (7, 3 * CHUNK + 17)
    np.testing.assert_allclose(C, np.cos(Q.T), rtol=0, atol=2.3e-16)
    np.testing.assert_allclose(S, np.sin(Q.T), rtol=0, atol=2.3e-16)
    out = (np.full((7, 3 * CHUNK + 17), np.nan), np.full((7, 3 * CHUNK + 17), np.nan))
    assert cos_sin(np.ascontiguousarray(Q.T), out) is out
    np.testing.assert_array_equal(out[0], C)
    np.testing.assert_array_equal(out[1], S)
    c, s = cos_sin(np.empty((0, 3)))
    assert c.shape == s.shape == (0, 3)
    c, s = cos_sin(np.float64(0.5))
    assert c.shape == () and abs(s - np.sin(0.5)) <= 1.2e-16
