r"""Compiled kernels of the capability maps.

A serial chain's pose and Jacobian, singular values, voxel and direction bins, and the exact
accumulation of samples into voxels. Every function is ``@kernel(nogil=True)``
(numba): arrays in, arrays out, the caller preallocates; no Python object inside. ``nogil``
lets the threads of a local Dask scheduler run the kernels side by side. The same source runs
as plain Python under ``NUMBA_DISABLE_JIT=1`` (tests/test_maps_kernels.py checks both against
numpy and Pinocchio references). The typed entry points are :mod:`rrc_pin.solvers.maps.batch`; mypy
ignores this module (pyproject.toml): numba's decorator is untyped.

Sources, cited once here:

- The chain (:func:`chain_tile`): the product of each joint's fixed placement and its motion,
  ``T = M_1 X_1(q_1) M_2 X_2(q_2) ... M_n X_n(q_n) M_tool`` (Craig, *Introduction to
  Robotics*, 3rd ed., ch. 3, with Pinocchio's joint placements as the link transforms). Every
  joint moves about or along the z axis of its own frame (the caller turns a joint frame
  whose axis is another one, as a DH frame would be): ``X(q) = Rot_z(q)`` or ``Trans_z(q)``.
- The Jacobian (:func:`chain_jacobian`): column k is :math:`[z_k \times (p - o_k);\ z_k]`
  for a revolute joint, :math:`[z_k;\ 0]` for a prismatic one, :math:`z_k`, :math:`o_k` the
  joint's axis and origin in base axes (Siciliano et al., *Robotics: Modelling, Planning
  and Control*, 2009, sec. 3.1.3; Barker eqs (14)-(17)): rows [v; w] of the tool origin in
  base axes (``world_aligned``).
- Sines and cosines (:func:`sincos`): fdlibm (Sun Microsystems 1993), ``e_rem_pio2.c``,
  ``k_sin.c``, ``k_cos.c``.
- Singular values (:func:`singular_values`): one-sided Jacobi (Hestenes 1958; Demmel &
  Veselić 1992, high relative accuracy): rows of J rotated pairwise until orthogonal; the
  singular values are then their norms.
- Direction bins (:func:`direction_bin`): Zacharias, Borst & Hirzinger 2007's reachability
  index counts the directions of a sphere that a voxel is reached in; here the tool's z axis
  is binned on an equal-angle cube map (6 faces x 3 x 3 cells, cell edges at atan(u) =
  +-15 deg), 54 bins held as the bits of one uint64.
- The accumulation (:func:`accumulate`): an open-addressing hash table with linear probing
  (Knuth, TAOCP vol. 3, 6.4, algorithm L), Fibonacci hashing (ibid., 6.4 (multiplicative)).
"""

from __future__ import annotations

import math

import numpy as np

from rrc_pin.solvers.compiled import kernel

REVOLUTE = 0
PRISMATIC = 1
FACE_CELLS = 3
BINS = 6 * FACE_CELLS * FACE_CELLS
"""Direction bins (54 <= 64: one uint64 per voxel)."""
EDGE = math.tan(math.pi / 12.0)
"""Cell edge of the equal-angle cube map: tan(15 deg), on the face coordinates u, v."""
JACOBI_TOL = 1e-15
"""One-sided Jacobi leaves a pair once ``|r_i . r_j| <= tol |r_i| |r_j|``."""
JACOBI_SWEEPS = 60
"""Sweeps at most (6 x 7 Jacobians take 4 to 8, the last one rotating nothing)."""
TILE = 256
"""Samples whose poses are computed together (:func:`chain_tile`): 9 + 3 arrays of 2 kB."""
INV_PIO2 = 6.36619772367581382433e-01
PIO2_1 = 1.57079632673412561417e00
"""The first 33 bits of pi/2 (fdlibm e_rem_pio2.c): ``k PIO2_1`` is exact."""
PIO2_2 = 6.07710050650619224932e-11
PIO2_3 = 2.02226624871116645580e-21
SIN = (-1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04,
       2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10)
"""fdlibm k_sin.c: sin r = r + r^3 (S1 + r^2 (S2 + ...)) on [-pi/4, pi/4]."""
COS = (4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05,
       -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11)
"""fdlibm k_cos.c: cos r = 1 - r^2 / 2 + r^4 (C1 + r^2 (C2 + ...)) on [-pi/4, pi/4]."""
NONE = np.iinfo(np.int64).max
"""The witness of no sample (the identity of the minimum)."""
EMPTY = -1
"""Key of an empty slot of the hash table."""
FIBONACCI = 2654435761
"""About 2^32 / golden ratio, the multiplier of Fibonacci hashing (Knuth's A)."""
MAX_KEYS = 2**31
"""Keys are below this (a grid of at most 2^31 voxels): ``key * FIBONACCI < 2^63``, no
overflow in int64."""

# The columns of a row (one sample, or one voxel's aggregate):
#   fmax: 0 manipulability, 1 sigma_min, 2 joint-limit margin         (maxima, float64)
#   isum: 0 manipulability, 1 sigma_min (fixed point), 2.. conditions (sums, int64)
#   imin: 0 witness (global sample index), 1.. first sample per condition (minima, int64)


@kernel(nogil=True)
def sincos(x, C, S):
    """Cosines ``C`` and sines ``S`` of the angles ``x`` [rad] (m,), to an ulp or two.

    fdlibm (Sun Microsystems, 1993): ``k = round(2 x / pi)``, ``r = x - k pi/2`` in three
    parts (``e_rem_pio2.c``'s medium case, exact for |x| < 2^19 pi/2), the minimax
    polynomials of ``k_sin.c`` and ``k_cos.c`` on [-pi/4, pi/4], the quadrant ``k mod 4``
    choosing and signing them. Branch-free, so the loop is vectorised, which libm's ``sin``
    and ``cos`` are not; within 2.3e-16 of numpy's.
    """
    for i in range(x.shape[0]):
        k = round(x[i] * INV_PIO2)
        r = ((x[i] - k * PIO2_1) - k * PIO2_2) - k * PIO2_3
        z = r * r
        sr = r + r * z * (SIN[0] + z * (SIN[1] + z * (SIN[2] + z * (SIN[3] + z * (SIN[4]
                                                                           + z * SIN[5])))))
        cr = 1.0 - 0.5 * z + z * z * (COS[0] + z * (COS[1] + z * (COS[2] + z * (COS[3] + z * (
            COS[4] + z * COS[5])))))
        q = int(k) & 3
        odd = (q & 1) == 1
        S[i] = (cr if odd else sr) * (-1.0 if q >= 2 else 1.0)
        C[i] = (sr if odd else cr) * (-1.0 if q == 1 or q == 2 else 1.0)


@kernel(nogil=True)
def chain_tile(rot, trans, kind, Q, lo, m, joints, X, C, S, R, P, Og, Ax):
    """Poses of the samples ``lo .. lo + m - 1`` of ``Q``, one array per entry (a tile).

    For each joint k in turn, over the tile's samples: ``p += R t_k``, ``R <- R M_k`` (its
    placement), then its motion, ``R <- R Rot_z(q_k)`` (the first two columns turn by q_k)
    or ``p += q_k z_k``; last the tool frame's placement. Each entry of the tile's poses is
    an array over its samples, small enough to stay in the L1 cache: the loops over samples
    are vectorised.

    Args:
        rot: Placements' rotations (n + 1, 3, 3): joint k's frame in joint k-1's moved frame
            (the first in the base frame), the last the tool frame in joint n's.
        trans: Their translations (n + 1, 3) [m].
        kind: :data:`REVOLUTE` (about z) or :data:`PRISMATIC` (along z), (n,).
        Q: Joint positions (N, n) [rad or m].
        lo: First sample of the tile.
        m: Samples in the tile (<= the buffers' length T).
        joints: Also record each joint's origin and axis (for the Jacobian).
        X: Scratch (T,).
        C: Scratch (T,).
        S: Scratch (T,).
        R: Out: the tool's rotations, entry (i, j) in row ``3 i + j`` (9, T).
        P: Out: the tool's origins (3, T) [m].
        Og: Out, with ``joints``: the joints' origins (n, 3, T) [m].
        Ax: Out, with ``joints``: the joints' axes (n, 3, T).
    """
    n = Q.shape[1]
    for s in range(m):
        for i in range(3):
            P[i, s] = 0.0
            for j in range(3):
                R[3 * i + j, s] = 1.0 if i == j else 0.0
    for k in range(n + 1):
        M, t = rot[k], trans[k]
        m00, m01, m02 = M[0, 0], M[0, 1], M[0, 2]
        m10, m11, m12 = M[1, 0], M[1, 1], M[1, 2]
        m20, m21, m22 = M[2, 0], M[2, 1], M[2, 2]
        t0, t1, t2 = t[0], t[1], t[2]
        for i in range(3):
            for s in range(m):
                a, b, c = R[3 * i, s], R[3 * i + 1, s], R[3 * i + 2, s]
                P[i, s] += a * t0 + b * t1 + c * t2
                R[3 * i, s] = a * m00 + b * m10 + c * m20
                R[3 * i + 1, s] = a * m01 + b * m11 + c * m21
                R[3 * i + 2, s] = a * m02 + b * m12 + c * m22
        if k == n:  # the tool frame's placement: no joint after it
            break
        if joints:
            for i in range(3):
                for s in range(m):
                    Og[k, i, s] = P[i, s]
                    Ax[k, i, s] = R[3 * i + 2, s]
        for s in range(m):
            X[s] = Q[lo + s, k]
        if kind[k] == REVOLUTE:
            sincos(X[:m], C, S)
            for i in range(3):
                for s in range(m):
                    x, y = R[3 * i, s], R[3 * i + 1, s]
                    R[3 * i, s] = C[s] * x + S[s] * y
                    R[3 * i + 1, s] = C[s] * y - S[s] * x
        else:
            for i in range(3):
                for s in range(m):
                    P[i, s] += R[3 * i + 2, s] * X[s]


@kernel(nogil=True)
def chain_jacobian(Og, Ax, kind, P, m, J):
    """Geometric Jacobians of a tile's samples, rows [v; w], into ``J`` (r, n, T), r = 3 or 6.

    Column k is ``[z_k x (p - o_k); z_k]`` (revolute) or ``[z_k; 0]`` (prismatic), with the
    tile's joint origins ``Og`` (n, 3, T), axes ``Ax`` (n, 3, T) and tool origins ``P``
    (3, T); the first ``m`` samples.
    """
    r, n = J.shape[0], J.shape[1]
    for k in range(n):
        if kind[k] == REVOLUTE:
            for s in range(m):
                zx, zy, zz = Ax[k, 0, s], Ax[k, 1, s], Ax[k, 2, s]
                dx, dy, dz = P[0, s] - Og[k, 0, s], P[1, s] - Og[k, 1, s], P[2, s] - Og[k, 2, s]
                J[0, k, s] = zy * dz - zz * dy
                J[1, k, s] = zz * dx - zx * dz
                J[2, k, s] = zx * dy - zy * dx
                if r == 6:
                    J[3, k, s], J[4, k, s], J[5, k, s] = zx, zy, zz
        else:
            for s in range(m):
                J[0, k, s], J[1, k, s], J[2, k, s] = Ax[k, 0, s], Ax[k, 1, s], Ax[k, 2, s]
                if r == 6:
                    J[3, k, s], J[4, k, s], J[5, k, s] = 0.0, 0.0, 0.0


@kernel(nogil=True)
def chain_batch(rot, trans, kind, Q, R, P, J):
    """Poses and Jacobians of many configurations (:func:`chain_tile`, :func:`chain_jacobian`).

    ``Q`` (N, n) -> ``R`` (N, 3, 3), ``P`` (N, 3) [m], ``J`` (N, r, n).
    """
    N, n = Q.shape
    r = J.shape[1]
    X, C, S = np.empty(TILE), np.empty(TILE), np.empty(TILE)
    Rt, Pt = np.empty((9, TILE)), np.empty((3, TILE))
    Og, Ax = np.empty((n, 3, TILE)), np.empty((n, 3, TILE))
    Jt = np.empty((r, n, TILE))
    for lo in range(0, N, TILE):
        m = min(TILE, N - lo)
        chain_tile(rot, trans, kind, Q, lo, m, True, X, C, S, Rt, Pt, Og, Ax)
        chain_jacobian(Og, Ax, kind, Pt, m, Jt)
        for s in range(m):
            for i in range(3):
                P[lo + s, i] = Pt[i, s]
                for j in range(3):
                    R[lo + s, i, j] = Rt[3 * i + j, s]
            for i in range(r):
                for k in range(n):
                    J[lo + s, i, k] = Jt[i, k, s]


@kernel(nogil=True)
def singular_values(W, m, sv):
    """Singular values of a tile's matrices ``W`` (r, n, T), r <= n, into ``sv`` (r, T).

    One-sided Jacobi on the rows of each of the first ``m`` matrices (``W`` is overwritten):
    for each pair of rows, ``a = |w_i|^2``, ``b = |w_j|^2``, ``g = w_i . w_j``; where ``|g|``
    is above :data:`JACOBI_TOL` ``sqrt(a b)`` the pair is rotated by ``zeta = (b - a) /
    (2 g)``, ``t = sign(zeta) / (|zeta| + sqrt(1 + zeta^2))``, ``c = 1 / sqrt(1 + t^2)``,
    ``s = c t``; the sweeps over the pairs repeat until one rotates nothing. The singular
    values are then the rows' norms, sorted descending. (The norms are computed afresh for
    each pair: updated along with the rotations instead, their rounding drifts below zero
    for a rank-deficient matrix and stops the sweeps early, sigma_min 1e-8 instead of 1e-16.)

    The samples of the tile go through the pairs together: a matrix whose pair needs no
    rotation gets ``c = 1, s = 0``, which leaves its rows exactly as they are, so each answer
    is the one the matrix alone would get.
    """
    r, n, T = W.shape
    a, b, g = np.empty(T), np.empty(T), np.empty(T)
    c, sn = np.empty(T), np.empty(T)
    for _ in range(JACOBI_SWEEPS):
        rotated = 0
        for i in range(r - 1):
            for j in range(i + 1, r):
                for s in range(m):
                    a[s], b[s], g[s] = 0.0, 0.0, 0.0
                for k in range(n):
                    for s in range(m):
                        x, y = W[i, k, s], W[j, k, s]
                        a[s] += x * x
                        b[s] += y * y
                        g[s] += x * y
                for s in range(m):
                    turn = abs(g[s]) > JACOBI_TOL * math.sqrt(a[s] * b[s])
                    zeta = (b[s] - a[s]) / (2.0 * (g[s] if turn else 1.0))
                    sign = 1.0 if zeta >= 0.0 else -1.0
                    ts = sign / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                    ts = ts if turn else 0.0
                    c[s] = 1.0 / math.sqrt(1.0 + ts * ts)
                    sn[s] = c[s] * ts
                    rotated += turn
                for k in range(n):
                    for s in range(m):
                        x, y = W[i, k, s], W[j, k, s]
                        W[i, k, s] = c[s] * x - sn[s] * y
                        W[j, k, s] = sn[s] * x + c[s] * y
        if rotated == 0:
            break
    for s in range(m):  # the norms, sorted descending (insertion: r <= 6)
        for i in range(r):
            acc = 0.0
            for k in range(n):
                acc += W[i, k, s] * W[i, k, s]
            value = math.sqrt(acc)
            j = i
            while j > 0 and sv[j - 1, s] < value:
                sv[j, s] = sv[j - 1, s]
                j -= 1
            sv[j, s] = value


@kernel(nogil=True)
def direction_bin(x, y, z):
    """Bin (0..53) of the unit direction ``(x, y, z)`` on the equal-angle cube map.

    Face: the axis of the largest component and its sign (+x, -x, +y, -y, +z, -z); on it the
    two other components divided by the largest, ``u, v`` in [-1, 1], each in one of three
    cells with edges at ``+-tan(15 deg)`` (three equal angles of 30 deg).
    """
    ax, ay, az = abs(x), abs(y), abs(z)
    if ax >= ay and ax >= az:
        face = 0 if x >= 0.0 else 1
        u, v = y / ax, z / ax
    elif ay >= az:
        face = 2 if y >= 0.0 else 3
        u, v = x / ay, z / ay
    else:
        face = 4 if z >= 0.0 else 5
        u, v = x / az, y / az
    iu = 0 if u < -EDGE else (1 if u <= EDGE else 2)
    iv = 0 if v < -EDGE else (1 if v <= EDGE else 2)
    return (face * FACE_CELLS + iu) * FACE_CELLS + iv


@kernel(nogil=True)
def voxel_key(x, y, z, start, voxel, shape):
    """Linear index ``(ix ny + iy) nz + iz`` of the voxel holding ``(x, y, z)``, or -1 outside.

    ``ix = floor(x / voxel) - start_x`` and alike (voxels aligned on multiples of ``voxel``,
    the same formula as the grid's numpy lookup); ``shape`` (3,) the grid's voxels.
    """
    ix = math.floor(x / voxel) - start[0]
    iy = math.floor(y / voxel) - start[1]
    iz = math.floor(z / voxel) - start[2]
    if ix < 0 or iy < 0 or iz < 0 or ix >= shape[0] or iy >= shape[1] or iz >= shape[2]:
        return -1
    return (ix * shape[1] + iy) * shape[2] + iz


@kernel(nogil=True)
def limit_margin(q, lower, span):
    """Smallest distance to a joint limit relative to the joint's range, in [0, 0.5].

    ``min_k min(q_k - lower_k, lower_k + span_k - q_k) / span_k`` over the joints with a
    finite range (``span_k > 0``); 0.5 when none has one.
    """
    out = 0.5
    for k in range(q.shape[0]):
        if span[k] > 0.0:
            d = min(q[k] - lower[k], lower[k] + span[k] - q[k]) / span[k]
            out = min(out, d)
    return out


@kernel(nogil=True)
def sample_row(
    s, px, py, pz, zx, zy, zz, q, sv, lower, span, start, voxel, shape, dexterity, quanta, first,
    keys, dirs, fmax, isum, imin,
):  # fmt: skip
    """Row ``s`` of a block from one sample's tool origin, tool z axis, joints, singular values.

    The key of the voxel of the tool origin ``(px, py, pz)`` [m]; the bit of the direction
    bin of the tool's z axis ``(zx, zy, zz)``; the joint-limit margin of ``q``; the sample's
    global index ``first + s`` (the voxel's witness); with ``dexterity`` the manipulability
    ``prod(sigma)`` and ``sigma_min`` of the task Jacobian's singular values ``sv`` (r,
    descending), as maxima and in fixed point (``round(value / quantum)``), else ``-inf`` and
    0. Condition columns are the caller's.
    """
    keys[s] = voxel_key(px, py, pz, start, voxel, shape)
    dirs[s] = np.uint64(1) << np.uint64(direction_bin(zx, zy, zz))
    fmax[s, 2] = limit_margin(q, lower, span)
    imin[s, 0] = first + s
    if dexterity:
        r = sv.shape[0]
        w = 1.0
        for i in range(r):
            w *= sv[i]
        fmax[s, 0] = w
        fmax[s, 1] = sv[r - 1]
        isum[s, 0] = np.int64(round(w / quanta[0]))
        isum[s, 1] = np.int64(round(sv[r - 1] / quanta[1]))
    else:
        fmax[s, 0] = -np.inf
        fmax[s, 1] = -np.inf
        isum[s, 0] = 0
        isum[s, 1] = 0


@kernel(nogil=True)
def chain_rows(
    rot, trans, kind, Q, lower, span, start, voxel, shape, rows, dexterity, quanta, first,
    keys, dirs, fmax, isum, imin,
):  # fmt: skip
    """The rows (:func:`sample_row`) of a block of samples of a serial chain.

    Args:
        rot: The chain's placement rotations (:func:`chain_tile`).
        trans: The chain's placement translations.
        kind: The chain's joint kinds.
        Q: Joint positions of the block (N, n) [rad or m].
        lower: Joint lower limits (n,).
        span: Joint ranges (n,), 0 where a joint has no finite range.
        start: Index of the grid's first voxel along x, y, z (3,) (:func:`voxel_key`).
        voxel: Voxel edge [m].
        shape: Voxels along x, y, z (3,).
        rows: Task rows of the Jacobian: 3 (position) or 6 (full twist).
        dexterity: Compute the Jacobian's singular values (manipulability, sigma_min).
        quanta: Fixed-point quanta (2,) of the manipulability and sigma_min sums.
        first: Global index of the block's first sample.
        keys: Out (N,): voxel keys (-1 outside the grid).
        dirs: Out (N,): the direction bin's bit.
        fmax: Out (N, 3): manipulability, sigma_min, joint-limit margin.
        isum: Out (N, 2): manipulability and sigma_min in fixed point.
        imin: Out (N, 1): the sample's global index.
    """
    N, n = Q.shape
    X, C, S = np.empty(TILE), np.empty(TILE), np.empty(TILE)
    R, P = np.empty((9, TILE)), np.empty((3, TILE))
    Og, Ax = np.empty((n, 3, TILE)), np.empty((n, 3, TILE))
    J = np.empty((rows, n, TILE))
    sv = np.zeros((rows, TILE))
    for lo in range(0, N, TILE):
        m = min(TILE, N - lo)
        chain_tile(rot, trans, kind, Q, lo, m, dexterity, X, C, S, R, P, Og, Ax)
        if dexterity:
            chain_jacobian(Og, Ax, kind, P, m, J)
            singular_values(J, m, sv)
        for s in range(m):
            sample_row(lo + s, P[0, s], P[1, s], P[2, s], R[2, s], R[5, s], R[8, s], Q[lo + s],
                       sv[:, s], lower, span, start, voxel, shape, dexterity, quanta, first,
                       keys, dirs, fmax, isum, imin)  # fmt: skip


@kernel(nogil=True)
def batch_rows(
    P, Z, J, flags, Q, lower, span, start, voxel, shape, dexterity, quanta, first,
    keys, dirs, fmax, isum, imin,
):  # fmt: skip
    """The rows (:func:`sample_row`) of a block evaluated by a batch closed form.

    Args:
        P: Tool origins (N, 3) [m].
        Z: Tool z axes (N, 3).
        J: Task Jacobians (N, rows, n), read only with ``dexterity``.
        flags: Conditions that hold at each sample (N, C) (Barker's singular conditions):
            their counts go to ``isum[:, 2:]``, their first samples to ``imin[:, 1:]``.
        Q: The samples (N, n) [rad] (their joint-limit margins).
        lower: Joint lower limits (n,).
        span: Joint ranges (n,).
        start: Index of the grid's first voxel along x, y, z (3,).
        voxel: Voxel edge [m].
        shape: Voxels along x, y, z (3,).
        dexterity: Compute the singular values of ``J``.
        quanta: Fixed-point quanta (2,).
        first: Global index of the first sample.
        keys: Out (N,), as :func:`chain_rows`.
        dirs: Out (N,).
        fmax: Out (N, 3).
        isum: Out (N, 2 + C).
        imin: Out (N, 1 + C).
    """
    N, rows, n = J.shape
    W = np.empty((rows, n, TILE))
    sv = np.zeros((rows, TILE))
    for lo in range(0, N, TILE):
        m = min(TILE, N - lo)
        if dexterity:
            for i in range(rows):
                for k in range(n):
                    for s in range(m):
                        W[i, k, s] = J[lo + s, i, k]
            singular_values(W, m, sv)
        for s in range(m):
            g = lo + s
            sample_row(g, P[g, 0], P[g, 1], P[g, 2], Z[g, 0], Z[g, 1], Z[g, 2], Q[g], sv[:, s],
                       lower, span, start, voxel, shape, dexterity, quanta, first, keys, dirs,
                       fmax, isum, imin)  # fmt: skip
            for c in range(flags.shape[1]):
                isum[g, 2 + c] = 1 if flags[g, c] else 0
                imin[g, 1 + c] = first + g if flags[g, c] else NONE


@kernel(nogil=True)
def accumulate(keys, count, dirs, fmax, isum, imin, table, tmax):
    """Add rows into a hash table of voxels, exactly; returns (slots filled, samples outside).

    A row (key, count, direction bits, maxima, fixed-point sums, minima) goes to the slot of
    its key (Fibonacci hash of the key, then the next slots until the key or an empty one):
    counts and sums added (int64), bits or'ed, maxima and minima taken. Each of these is
    associative and commutative on its type, so any grouping and order of the same samples
    gives the same bits. Rows with key -1 (outside the grid) are only counted.

    A slot's integers are one row of ``table`` and its maxima one row of ``tmax``: a sample
    touches two cache lines of the table, not one per column.

    Args:
        keys: The rows' voxel keys (N,), -1 outside.
        count: Samples each row stands for (N,): ones, or a table's slot counts.
        dirs: Direction bits (N,), uint64.
        fmax: Maxima (N, F).
        isum: Sums (N, S).
        imin: Minima (N, M).
        table: The slots' integers (C, 3 + S + M): key (:data:`EMPTY` where free), count,
            direction bits (as int64), the S sums, the M minima. C is a power of two up to
            2^32, kept at most half full by the caller (C >= 2 (filled + N)); keys are below
            :data:`MAX_KEYS`.
        tmax: The slots' maxima (C, F); a free slot's are overwritten when it is taken.

    Returns:
        How many slots the rows took that were free, and how many samples had key -1.
    """
    cap = table.shape[0]
    shift = 32 - round(math.log2(cap))
    mask = cap - 1
    S, M, F = isum.shape[1], imin.shape[1], fmax.shape[1]
    filled = 0
    outside = 0
    for r in range(keys.shape[0]):
        k = keys[r]
        if k < 0:
            outside += count[r]
            continue
        h = ((k * FIBONACCI) & 0xFFFFFFFF) >> shift  # Knuth: (A k mod 2^32) / 2^(32 - bits)
        while table[h, 0] != EMPTY and table[h, 0] != k:
            h = (h + 1) & mask
        slot = table[h]
        best = tmax[h]
        bits = np.int64(dirs[r])
        if slot[0] == EMPTY:
            filled += 1
            slot[0] = k
            slot[1] = count[r]
            slot[2] = bits
            for j in range(S):
                slot[3 + j] = isum[r, j]
            for j in range(M):
                slot[3 + S + j] = imin[r, j]
            for j in range(F):
                best[j] = fmax[r, j]
            continue
        slot[1] += count[r]
        slot[2] |= bits
        for j in range(S):
            slot[3 + j] += isum[r, j]
        for j in range(M):
            if imin[r, j] < slot[3 + S + j]:
                slot[3 + S + j] = imin[r, j]
        for j in range(F):
            if fmax[r, j] > best[j]:
                best[j] = fmax[r, j]
    return filled, outside
