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
    a: Array,
    b: Array,
    c: Array,
    d: Array,
    g0: Array,
    g1: Array,
    rcond: float,
    floor: Array | float = 0.0,
) -> tuple[Array, Array, Array]:
    """Apply the truncated pseudo-inverse of ``A = [[a, b], [c, d]]`` to ``g = (g0, g1)``.

    Closed form, vectorised over any broadcast shape, of the truncated SVD solution
    ``sum_{sigma_i > cutoff} v_i u_i^T g / sigma_i`` with ``cutoff = rcond sqrt(max(sigma_1^2,
    floor))``: ``numpy.linalg.pinv(A, rcond) @ g`` for ``floor = 0``; a ``floor`` sets an
    absolute scale, so that a matrix that is small as a whole (M1 at the double singularity)
    is not inverted. With ``A^T A = [[p, r], [r, s]]``, the squared singular values are
    ``(p + s) / 2 +- h``, ``h = sqrt(((p - s) / 2)^2 + r^2)``; ``sigma_2 = |det A| / sigma_1``.
    Where ``sigma_2 > cutoff`` the answer is ``A^-1 g``; where only ``sigma_1 > cutoff`` it is
    ``v v^T A^T g / sigma_1^2`` with ``v`` the top right singular vector; else zero
    (Barker's M1*, eq. (44), and M2*, eq. (60)).

    Args:
        a: Entry (0, 0) of A.
        b: Entry (0, 1) of A.
        c: Entry (1, 0) of A.
        d: Entry (1, 1) of A.
        g0: First entry of the right-hand side.
        g1: Second entry of the right-hand side.
        rcond: Relative cutoff of the singular values, in [0, 1).
        floor: Squared singular value below which the cutoff does not scale down.

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
    ref = np.maximum(lam, floor)
    regular = np.abs(det) > rcond * np.sqrt(ref * lam)
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
            keep = (den > 0.0) & (lam > rcond * rcond * ref)
            k = np.where(keep, (v0 * h0 + v1 * h1) / np.where(keep, den, 1.0), 0.0)
            x0 = np.where(regular, x0, k * v0)
            x1 = np.where(regular, x1, k * v1)
    return x0, x1, regular


def pinv2_apply_scalar(
    a: float, b: float, c: float, d: float, g0: float, g1: float, rcond: float, floor: float = 0.0
) -> tuple[float, float]:
    """Scalar (Python float) version of :func:`pinv2_apply`, returning ``(x0, x1)``."""
    det = a * d - b * c
    p = a * a + c * c
    r = a * b + c * d
    s = b * b + d * d
    half = 0.5 * (p - s)
    h = (half * half + r * r) ** 0.5
    lam = 0.5 * (p + s) + h
    ref = lam if lam > floor else floor
    if abs(det) > rcond * (ref * lam) ** 0.5:
        return (d * g0 - b * g1) / det, (a * g1 - c * g0) / det
    if p >= s:
        v0, v1 = half + h, r
    else:
        v0, v1 = r, h - half
    den = (v0 * v0 + v1 * v1) * lam
    if den <= 0.0 or lam <= rcond * rcond * ref:
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
