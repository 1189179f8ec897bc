r"""Compiled kernels of the capability maps.

A serial chain's pose and Jacobian, singular values, voxel and direction bins, and the exact
accumulation of samples into voxels. Every function is ``@njit(cache=True, nogil=True)``
(numba): arrays in, arrays out, the caller preallocates; no Python object inside. ``nogil``
lets the threads of a local Dask scheduler run the kernels side by side. The same source runs
as plain Python under ``NUMBA_DISABLE_JIT=1`` (tests/test_maps_kernels.py checks both against
numpy and Pinocchio references). The typed entry points are :mod:`solvers.map_batch`; mypy
ignores this module (pyproject.toml): numba's decorator is untyped.

Sources, cited once here:

- The chain (:func:`chain_pose`): the product of each joint's fixed placement and its motion,
  ``T = M_1 X_1(q_1) M_2 X_2(q_2) ... M_n X_n(q_n) M_tool`` (Craig, *Introduction to
  Robotics*, 3rd ed., ch. 3, with Pinocchio's joint placements as the link transforms). Every
  joint moves about or along the z axis of its own frame (the caller turns a joint frame
  whose axis is another one, as a DH frame would be): ``X(q) = Rot_z(q)`` or ``Trans_z(q)``.
- The Jacobian (:func:`chain_jacobian`): column k is :math:`[z_k \times (p - o_k);\ z_k]`
  for a revolute joint, :math:`[z_k;\ 0]` for a prismatic one, :math:`z_k`, :math:`o_k` the
  joint's axis and origin in base axes (Siciliano et al., *Robotics: Modelling, Planning
  and Control*, 2009, sec. 3.1.3; Barker eqs (14)-(17)): rows [v; w] of the tool origin in
  base axes (``world_aligned``).
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
from numba import njit

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


@njit(cache=True, nogil=True)
def compose(R, p, Rm, pm):
    """``(R, p) = (R, p) (Rm, pm)`` in place: the pose followed by the placement (3, 3), (3,)."""
    x, y, z = pm[0], pm[1], pm[2]
    for i in range(3):
        a, b, c = R[i, 0], R[i, 1], R[i, 2]
        p[i] += a * x + b * y + c * z
        R[i, 0] = a * Rm[0, 0] + b * Rm[1, 0] + c * Rm[2, 0]
        R[i, 1] = a * Rm[0, 1] + b * Rm[1, 1] + c * Rm[2, 1]
        R[i, 2] = a * Rm[0, 2] + b * Rm[1, 2] + c * Rm[2, 2]


@njit(cache=True, nogil=True)
def chain_pose(rot, trans, kind, q, R, p, origins, axes):
    """Pose of the tool and the joints' origins and axes at ``q``, all in the base frame.

    Args:
        rot: Placements' rotations (n + 1, 3, 3): joint k's frame in joint k-1's moved frame
            (the first in the base frame), the last the tool frame in joint n's.
        trans: Their translations (n + 1, 3) [m].
        kind: :data:`REVOLUTE` (about z) or :data:`PRISMATIC` (along z), (n,).
        q: Joint positions (n,) [rad or m].
        R: Out: the tool's rotation (3, 3).
        p: Out: the tool's origin (3,) [m].
        origins: Out: the joints' origins (n, 3) [m].
        axes: Out: the joints' axes (n, 3).
    """
    n = q.shape[0]
    for i in range(3):
        p[i] = 0.0
        for j in range(3):
            R[i, j] = 1.0 if i == j else 0.0
    for k in range(n):
        compose(R, p, rot[k], trans[k])
        for i in range(3):
            origins[k, i] = p[i]
            axes[k, i] = R[i, 2]
        if kind[k] == REVOLUTE:  # R Rot_z(q): the first two columns turn
            c, s = math.cos(q[k]), math.sin(q[k])
            for i in range(3):
                x, y = R[i, 0], R[i, 1]
                R[i, 0] = c * x + s * y
                R[i, 1] = c * y - s * x
        else:
            for i in range(3):
                p[i] += R[i, 2] * q[k]
    compose(R, p, rot[n], trans[n])


@njit(cache=True, nogil=True)
def chain_jacobian(origins, axes, kind, p, J):
    """Geometric Jacobian rows [v; w] into ``J`` (m, n): m = 3 (position rows only) or 6.

    Column k is ``[z_k x (p - o_k); z_k]`` (revolute) or ``[z_k; 0]`` (prismatic).
    """
    m, n = J.shape
    for k in range(n):
        zx, zy, zz = axes[k, 0], axes[k, 1], axes[k, 2]
        if kind[k] == REVOLUTE:
            dx, dy, dz = p[0] - origins[k, 0], p[1] - origins[k, 1], p[2] - origins[k, 2]
            J[0, k] = zy * dz - zz * dy
            J[1, k] = zz * dx - zx * dz
            J[2, k] = zx * dy - zy * dx
            if m == 6:
                J[3, k], J[4, k], J[5, k] = zx, zy, zz
        else:
            J[0, k], J[1, k], J[2, k] = zx, zy, zz
            if m == 6:
                J[3, k], J[4, k], J[5, k] = 0.0, 0.0, 0.0


@njit(cache=True, nogil=True)
def chain_batch(rot, trans, kind, Q, R, P, J):
    """Poses and Jacobians of many configurations (:func:`chain_pose`, :func:`chain_jacobian`).

    ``Q`` (N, n) -> ``R`` (N, 3, 3), ``P`` (N, 3) [m], ``J`` (N, m, n).
    """
    n = Q.shape[1]
    origins = np.empty((n, 3))
    axes = np.empty((n, 3))
    for s in range(Q.shape[0]):
        chain_pose(rot, trans, kind, Q[s], R[s], P[s], origins, axes)
        chain_jacobian(origins, axes, kind, P[s], J[s])


@njit(cache=True, nogil=True)
def singular_values(J, W, norms, sv):
    """Singular values of ``J`` (m, n), m <= n, into ``sv`` (m,), descending.

    One-sided Jacobi on the rows, in ``W`` (m, n) with their squared norms in ``norms`` (m,):
    each pair with ``g = r_i . r_j`` above :data:`JACOBI_TOL` is rotated by ``zeta =
    (|r_j|^2 - |r_i|^2) / (2 g)``, ``t = sign(zeta) / (|zeta| + sqrt(1 + zeta^2))``,
    ``c = 1 / sqrt(1 + t^2)``, ``s = c t`` (the squared norms become ``|r_i|^2 - t g`` and
    ``|r_j|^2 + t g``); the sweeps stop when one rotates nothing.
    """
    m, n = J.shape
    for i in range(m):
        acc = 0.0
        for k in range(n):
            W[i, k] = J[i, k]
            acc += J[i, k] * J[i, k]
        norms[i] = acc
    for _ in range(JACOBI_SWEEPS):
        rotated = False
        for i in range(m - 1):
            for j in range(i + 1, m):
                g = 0.0
                for k in range(n):
                    g += W[i, k] * W[j, k]
                a, b = norms[i], norms[j]
                if g == 0.0 or abs(g) <= JACOBI_TOL * math.sqrt(a * b):
                    continue
                rotated = True
                zeta = (b - a) / (2.0 * g)
                t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                c = 1.0 / math.sqrt(1.0 + t * t)
                s = c * t
                for k in range(n):
                    x, y = W[i, k], W[j, k]
                    W[i, k] = c * x - s * y
                    W[j, k] = s * x + c * y
                norms[i] = a - t * g
                norms[j] = b + t * g
        if not rotated:
            break
    for i in range(m):  # the norms recomputed, sorted descending (insertion: m <= 6)
        acc = 0.0
        for k in range(n):
            acc += W[i, k] * W[i, k]
        value = math.sqrt(acc)
        j = i
        while j > 0 and sv[j - 1] < value:
            sv[j] = sv[j - 1]
            j -= 1
        sv[j] = value


@njit(cache=True, nogil=True)
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


@njit(cache=True, nogil=True)
def voxel_key(p, origin, voxel, shape):
    """Linear index ``(ix ny + iy) nz + iz`` of the voxel holding ``p`` (3,), or -1 outside.

    ``ix = floor((p_x - origin_x) / voxel)`` and alike; ``shape`` (3,) the grid's voxels.
    """
    key = 0
    for i in range(3):
        c = math.floor((p[i] - origin[i]) / voxel)
        if c < 0 or c >= shape[i]:
            return -1
        key = key * shape[i] + int(c)
    return key


@njit(cache=True, nogil=True)
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


@njit(cache=True, nogil=True)
def sample_row(
    s, p, R, q, J, W, norms, sv, lower, span, origin, voxel, shape, dexterity, quanta, first,
    keys, dirs, fmax, isum, imin,
):  # fmt: skip
    """Row ``s`` of a block from one sample's tool pose ``(R, p)``, joints ``q``, Jacobian ``J``.

    The key of the voxel of ``p`` (3,) [m]; the bit of the direction bin of the tool's z axis
    (the third column of ``R`` (3, 3)); the joint-limit margin of ``q``; the sample's global
    index ``first + s`` (the voxel's witness); with ``dexterity`` the manipulability
    ``prod(sigma)`` and ``sigma_min`` of ``J`` (m, n), as maxima and in fixed point
    (``round(value / quantum)``), else ``-inf`` and 0. Condition columns are the caller's.
    """
    keys[s] = voxel_key(p, origin, voxel, shape)
    dirs[s] = np.uint64(1) << np.uint64(direction_bin(R[0, 2], R[1, 2], R[2, 2]))
    fmax[s, 2] = limit_margin(q, lower, span)
    imin[s, 0] = first + s
    if dexterity:
        singular_values(J, W, norms, sv)
        rows = sv.shape[0]
        w = 1.0
        for i in range(rows):
            w *= sv[i]
        fmax[s, 0] = w
        fmax[s, 1] = sv[rows - 1]
        isum[s, 0] = np.int64(round(w / quanta[0]))
        isum[s, 1] = np.int64(round(sv[rows - 1] / quanta[1]))
    else:
        fmax[s, 0] = -np.inf
        fmax[s, 1] = -np.inf
        isum[s, 0] = 0
        isum[s, 1] = 0


@njit(cache=True, nogil=True)
def chain_rows(
    rot, trans, kind, Q, lower, span, origin, voxel, shape, rows, dexterity, quanta, first,
    keys, dirs, fmax, isum, imin,
):  # fmt: skip
    """The rows (:func:`sample_row`) of a block of samples of a serial chain.

    Args:
        rot: The chain's placement rotations (:func:`chain_pose`).
        trans: The chain's placement translations.
        kind: The chain's joint kinds.
        Q: Joint positions of the block (N, n) [rad or m].
        lower: Joint lower limits (n,).
        span: Joint ranges (n,), 0 where a joint has no finite range.
        origin: Corner of the grid's first voxel (3,) [m] (:func:`voxel_key`).
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
    n = Q.shape[1]
    R = np.empty((3, 3))
    p = np.empty(3)
    origins = np.empty((n, 3))
    axes = np.empty((n, 3))
    J = np.empty((rows, n))
    W = np.empty((rows, n))
    norms = np.empty(rows)
    sv = np.empty(rows)
    for s in range(Q.shape[0]):
        chain_pose(rot, trans, kind, Q[s], R, p, origins, axes)
        if dexterity:
            chain_jacobian(origins, axes, kind, p, J)
        sample_row(s, p, R, Q[s], J, W, norms, sv, lower, span, origin, voxel, shape,
                   dexterity, quanta, first, keys, dirs, fmax, isum, imin)  # fmt: skip


@njit(cache=True, nogil=True)
def batch_rows(
    P, R, J, flags, Q, lower, span, origin, voxel, shape, dexterity, quanta, first,
    keys, dirs, fmax, isum, imin,
):  # fmt: skip
    """The rows (:func:`sample_row`) of a block evaluated by a batch closed form.

    Args:
        P: Tool origins (N, 3) [m].
        R: Tool rotations (N, 3, 3).
        J: Task Jacobians (N, rows, n), read only with ``dexterity``.
        flags: Conditions that hold at each sample (N, C) (Barker's singular conditions):
            their counts go to ``isum[:, 2:]``, their first samples to ``imin[:, 1:]``.
        Q: The samples (N, n) [rad] (their joint-limit margins).
        lower: Joint lower limits (n,).
        span: Joint ranges (n,).
        origin: Corner of the grid's first voxel (3,) [m].
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
    rows, n = J.shape[1], J.shape[2]
    W = np.empty((rows, n))
    norms = np.empty(rows)
    sv = np.empty(rows)
    for s in range(P.shape[0]):
        sample_row(s, P[s], R[s], Q[s], J[s], W, norms, sv, lower, span, origin, voxel, shape,
                   dexterity, quanta, first, keys, dirs, fmax, isum, imin)  # fmt: skip
        for c in range(flags.shape[1]):
            isum[s, 2 + c] = 1 if flags[s, c] else 0
            imin[s, 1 + c] = first + s if flags[s, c] else NONE


@njit(cache=True, nogil=True)
def accumulate(keys, count, dirs, fmax, isum, imin, table, tmax):
    """Add rows into a hash table of voxels, exactly; returns (slots filled, samples outside).

    A row (key, count, direction bits, maxima, fixed-point sums, minima) goes to the slot of
    its key (Fibonacci hash of the key, then the next slots until the key or an empty one):
    counts and sums added (int64), bits or'ed, maxima and minima taken. Each of these is
    associative and commutative on its type, so any grouping and order of the same samples
    gives the same bits. Rows with key -1 (outside the grid) are only counted.

    A slot's integers are one row of ``table`` and its maxima one row of ``tmax``: a sample
    touches two cache lines of the table, not one per column (2^15 rows over 20,000 voxels
    into 2^16 slots, on the project's loaded 2-core machine: 44 ns a row, against 420 ns
    with one array per column).

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
