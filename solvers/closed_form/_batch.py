"""Shared machinery of the batch paths: cache-sized blocks and a fast cosine-and-sine.

Elementwise numpy on N = 10^5 configurations is bound by memory and by libm, not by the
flops of the closed forms: every intermediate of N doubles (800 kB) streams through memory
and ``numpy.sin`` / ``numpy.cos`` cost 10-15 ns per element each (scalar libm calls), more
than all the arithmetic of a closed form together. Hence:

- :func:`blocks`: the batch methods work on blocks of :data:`CHUNK` configurations, whose
  intermediates stay in the cache;
- :func:`cos_sin`: both functions of an angle from one table lookup and two short
  polynomials, about 25 vectorised operations (a third to a half of the time of
  ``numpy.cos`` + ``numpy.sin``), within about 1.1e-16 of them.

Measured with ``benchmarks/bench_closed_form.py``'s batches (N = 10^5, the project's 2-core
machine): without the blocks the batch paths run 2.2x (rrc_k1607) to 3.2x (kr5_3r) slower,
with ``numpy.cos`` and ``numpy.sin`` instead of :func:`cos_sin` 1.3x (rrc_k1607) to 2.3x
(kr5_3r) slower. Nothing else in the closed forms is tuned.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]

CHUNK = 8192
"""Configurations per block in the batch methods: tens of (CHUNK,) intermediates fit in the
cache, and 8192 doubles (64 kB) stay below glibc's default mmap threshold (128 kB), so that
no intermediate costs a fresh mapping and its page faults."""

TABLE_SIZE = 1024
"""Table entries per turn: angles are reduced to ``|r| <= pi / 1024`` about ``k pi / 512``."""
_P1 = 0.006135923147667199  # pi / 512 to 27 significant bits (0x1.921fb54p-8)
_P2 = 3.875365545627111e-12  # pi / 512 - _P1, rounded; the rest is 6.4e-29
_INV_STEP = 162.97466172610083  # 512 / pi
_ROUND = 6755399441055744.0  # 1.5 * 2^52: x + _ROUND is x rounded, in the low mantissa bits
LIMIT = 1.0e5
"""Largest ``|angle|`` [rad] of the fast reduction (``k _P1`` is exact for ``|k| < 2^26``);
beyond it :func:`cos_sin` falls back to ``numpy.cos`` and ``numpy.sin``."""


def _tables() -> tuple[Array, Array]:
    """``cos(k pi / 512)`` and ``sin(k pi / 512)`` for k = 0..1023, within an ulp.

    A quarter wave from libm at the two-part angle ``k _P1 + k _P2`` (``k _P1`` exact, the
    small part added to second order), the rest by symmetry, so that zeros and ones are
    exact.
    """
    quarter = TABLE_SIZE // 4
    k = np.arange(quarter + 1, dtype=np.float64)
    hi, lo = k * _P1, k * _P2
    sq = np.sin(hi) * (1.0 - 0.5 * lo * lo) + np.cos(hi) * lo  # sin(k pi / 512), k <= 256
    sq[0] = 0.0
    sq[quarter] = 1.0
    half = np.concatenate([sq, sq[-2:0:-1]])  # [0, pi): sin(pi - x) = sin(x)
    sin = np.concatenate([half, -half])
    cos = np.roll(sin, -quarter)  # cos(x) = sin(x + pi / 2)
    return np.ascontiguousarray(cos), np.ascontiguousarray(sin)


_COS, _SIN = _tables()
_MASK = TABLE_SIZE - 1


def blocks(n: int, size: int = CHUNK) -> Iterator[slice]:
    """Slices ``lo:hi`` covering ``range(n)`` in blocks of ``size`` >= 1 (the last shorter)."""
    step = max(size, 1)
    for lo in range(0, n, step):
        yield slice(lo, min(lo + step, n))


def cos_sin(q: Array, out: tuple[Array, Array] | None = None) -> tuple[Array, Array]:
    r"""Cosines and sines of the angles ``q`` [rad], elementwise, any shape.

    With ``k = round(q 512 / pi)`` and ``r = q - k pi / 512`` (Cody-Waite reduction in two
    parts, exact for ``|q| <=`` :data:`LIMIT`), ``|r| <= pi / 1024`` and

    .. math::
        \sin q = S_k + (S_k (\cos r - 1) + C_k \sin r), \quad
        \cos q = C_k + (C_k (\cos r - 1) - S_k \sin r)

    with ``S_k, C_k`` from a :data:`TABLE_SIZE`-entry table and the Taylor polynomials
    ``sin r = r - r^3/6 + r^5/120``, ``cos r - 1 = -r^2/2 + r^4/24``, truncated below
    2e-18. Absolute error: within about 1.1e-16 of ``numpy.sin`` / ``numpy.cos`` (an ulp of
    the table entry plus the final rounding); near a multiple of ``pi`` the sine is exact to
    that absolute error, not to its own ulp. Works in blocks of :data:`CHUNK` elements.

    Args:
        q: Angles, float64, finite (any shape; validated by the caller).
        out: Optional ``(cos, sin)``: C-contiguous float64 arrays of ``q``'s shape.

    Returns:
        ``(cos q, sin q)``, each of ``q``'s shape (``out`` when given).
    """
    shape = np.shape(q)
    if out is None:
        out = (np.empty(shape), np.empty(shape))
    flat = np.ascontiguousarray(q).reshape(-1)
    c_all, s_all = out[0].reshape(-1), out[1].reshape(-1)
    n = flat.shape[0]
    m = max(min(n, CHUNK), 1)
    y: Array = np.empty(m)
    r: Array = np.empty(m)
    r2: Array = np.empty(m)
    t: Array = np.empty(m)
    k: npt.NDArray[np.int64] = np.empty(m, dtype=np.int64)
    for rows in blocks(n, m):
        x, c, s = flat[rows], c_all[rows], s_all[rows]
        size = x.shape[0]
        if size < m:
            y, r, r2, t, k = y[:size], r[:size], r2[:size], t[:size], k[:size]
        if np.max(x) > LIMIT or np.min(x) < -LIMIT:
            np.cos(x, out=c)
            np.sin(x, out=s)
            continue
        np.multiply(x, _INV_STEP, out=y)
        y += _ROUND
        np.bitwise_and(y.view(np.int64), _MASK, out=k)  # k mod 1024, also for k < 0
        y -= _ROUND  # k, as a float
        np.subtract(x, np.multiply(y, _P1, out=t), out=r)
        r -= np.multiply(y, _P2, out=t)
        np.take(_SIN, k, out=s, mode="clip")
        np.take(_COS, k, out=c, mode="clip")
        np.multiply(r, r, out=r2)
        sr = y  # sin r = r + r r2 (r2 / 120 - 1/6)
        np.multiply(r2, 1.0 / 120.0, out=sr)
        sr -= 1.0 / 6.0
        sr *= r2
        sr *= r
        sr += r
        cm = r  # cos r - 1 = r2 (r2 / 24 - 1/2)
        np.multiply(r2, 1.0 / 24.0, out=cm)
        cm -= 0.5
        cm *= r2
        np.multiply(s, cm, out=t)  # S_k (cos r - 1) + C_k sin r
        t += np.multiply(c, sr, out=r2)
        np.multiply(c, cm, out=cm)  # C_k (cos r - 1) - S_k sin r
        cm -= np.multiply(s, sr, out=r2)
        s += t
        c += cm
    return out
