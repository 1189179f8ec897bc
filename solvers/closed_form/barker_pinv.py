"""Generalized inverses for Barker's singular configurations: M* (eq. 38), M1* and M2* (eqs 44, 60).

Every generalized inverse here is the Moore-Penrose pseudo-inverse truncated like
``numpy.linalg.pinv(A, rcond)``: singular values ``sigma <= rcond * sigma_max`` count as zero.
The 2x2 ones (M1*, M2*) are in closed form; the 3x3 one (M*, only needed where det M is
negligible) uses the SVD of the few singular blocks.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]


def pinv2_apply(
    a: Array, b: Array, c: Array, d: Array, g0: Array, g1: Array, rcond: float
) -> tuple[Array, Array, Array]:
    """Apply the truncated pseudo-inverse of ``A = [[a, b], [c, d]]`` to ``g = (g0, g1)``.

    Closed form of ``numpy.linalg.pinv(A, rcond) @ g``, vectorised over any broadcast shape.
    With ``A^T A = [[p, r], [r, s]]``, the squared singular values are
    ``(p + s) / 2 +- h``, ``h = sqrt(((p - s) / 2)^2 + r^2)``; ``sigma_2 = |det A| / sigma_1``.
    Where ``sigma_2 > rcond sigma_1`` (``|det A| > rcond sigma_1^2``) the answer is
    ``A^-1 g``; elsewhere it is ``v v^T A^T g / sigma_1^2`` with ``v`` the top right singular
    vector (Barker's M1*, eq. (44), and M2*, eq. (60)).

    Args:
        a: Entry (0, 0) of A.
        b: Entry (0, 1) of A.
        c: Entry (1, 0) of A.
        d: Entry (1, 1) of A.
        g0: First entry of the right-hand side.
        g1: Second entry of the right-hand side.
        rcond: Relative cutoff of the singular values, in (0, 1).

    Returns:
        ``(x0, x1, regular)``: the solution and a boolean array, True where A was inverted.
    """
    det = a * d - b * c
    p = a * a + c * c
    r = a * b + c * d
    s = b * b + d * d
    half = 0.5 * (p - s)
    h = np.hypot(half, r)
    lam = 0.5 * (p + s) + h  # sigma_1^2
    regular = np.abs(det) > rcond * lam
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_det = np.where(regular, 1.0, 0.0) / np.where(regular, det, 1.0)
        x0 = (d * g0 - b * g1) * inv_det
        x1 = (a * g1 - c * g0) * inv_det
        if not np.all(regular):
            # top eigenvector of A^T A, no cancellation: (lam - s, r) if p >= s else (r, lam - p)
            big = p >= s
            v0 = np.where(big, half + h, r)
            v1 = np.where(big, r, h - half)
            h0 = a * g0 + c * g1  # A^T g
            h1 = b * g0 + d * g1
            den = (v0 * v0 + v1 * v1) * lam
            k = np.where(den > 0.0, (v0 * h0 + v1 * h1) / np.where(den > 0.0, den, 1.0), 0.0)
            x0 = np.where(regular, x0, k * v0)
            x1 = np.where(regular, x1, k * v1)
    return x0, x1, regular


def pinv2_apply_scalar(
    a: float, b: float, c: float, d: float, g0: float, g1: float, rcond: float
) -> tuple[float, float]:
    """Scalar (Python float) version of :func:`pinv2_apply`, returning ``(x0, x1)``."""
    det = a * d - b * c
    p = a * a + c * c
    r = a * b + c * d
    s = b * b + d * d
    half = 0.5 * (p - s)
    h = (half * half + r * r) ** 0.5
    lam = 0.5 * (p + s) + h
    if abs(det) > rcond * lam:
        return (d * g0 - b * g1) / det, (a * g1 - c * g0) / det
    if p >= s:
        v0, v1 = half + h, r
    else:
        v0, v1 = r, h - half
    den = (v0 * v0 + v1 * v1) * lam
    if den <= 0.0:
        return 0.0, 0.0
    k = (v0 * (a * g0 + c * g1) + v1 * (b * g0 + d * g1)) / den
    return k * v0, k * v1


def pinv3_apply(M: Array, x: Array, rcond: float) -> Array:
    """``numpy.linalg.pinv(M, rcond) @ x`` for a stack of 3x3 blocks: Barker's M*, eq. (38).

    Args:
        M: Blocks, shape (K, 3, 3).
        x: Right-hand sides, shape (K, 3).
        rcond: Relative cutoff of the singular values.

    Returns:
        Solutions, shape (K, 3).
    """
    return np.einsum("kij,kj->ki", np.linalg.pinv(M, rcond=rcond), x)
