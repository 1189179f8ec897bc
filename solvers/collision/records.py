"""The records the compiled collision pass reads and writes: joints, bodies, rows, settings.

One structured array holds every field of a kind (a body's shape, segment, radii, ...), so that
the pass takes a few arrays, not one per field: numba's call overhead grows with the number of
arguments. The kernels read each field as an array view
(``bodies["segment"]``, (ng, 2, 3)), as they would read a separate array.
"""

from __future__ import annotations

import numpy as np

JOINT = np.dtype([
    ("parent", np.int64),
    ("kind", np.int64),
    ("coordinate", np.int64),
    ("rotation", np.float64, (3, 3)),
    ("translation", np.float64, (3,)),
    ("axis", np.float64, (3,)),
])  # fmt: skip
"""A joint of a kinematic tree (:func:`~rrc_pin.solvers.collision.proximity_kernels.joint_poses`):
its parent joint, kind (``REVOLUTE``, ``PRISMATIC``), the coordinate of q that moves it, its
placement in the parent's frame (rotation, translation [m]) and its unit axis in its own frame."""

BODY = np.dtype([
    ("joint", np.int64),
    ("shape", np.int64),
    ("centre", np.float64, (3,)),
    ("bounding", np.float64),
    ("normal", np.float64, (3,)),
    ("offset", np.float64),
    ("segment", np.float64, (2, 3)),
    ("radius", np.float64),
    ("box", np.float64, (3, 4)),
    ("half", np.float64, (3,)),
])  # fmt: skip
"""A body of a scene: the joint it moves with (0: the world); its shape's code
(:mod:`~rrc_pin.solvers.collision.narrow_kernels`); its bounding sphere (centre in the joint's
frame [m], radius ``bounding`` [m], ``inf`` for a half-space); a half-space's unit outward
normal and offset (the solid ``normal . x <= offset``, world frame [m]); a sphere's or capsule's
segment end points in the joint's frame and radius [m] (a sphere: its centre twice); a box's
placement ``[R | t]`` in the joint's frame and half sides [m]. Fields a shape has not are
zero."""

FOUND = np.dtype([
    ("pair", np.int64),
    ("end", np.int64),
    ("joint_a", np.int64),
    ("joint_b", np.int64),
    ("distance", np.float64),
    ("point_a", np.float64, (3,)),
    ("point_b", np.float64, (3,)),
    ("normal", np.float64, (3,)),
    ("moved", np.bool_),
])  # fmt: skip
"""A row of a proximity query: its pair's index, 1 for a capsule end point's row, 2 for a box
feature's (:mod:`~rrc_pin.solvers.collision.narrow_kernels`; 0 for the pair's closest points),
the joints bodies A and B move with, the signed distance [m], the witness points on A and B and
the unit normal from A to B (world frame, ``p_b - p_a = d n``), and whether some joint rate
changes the distance (its damper row has an entry above ``still``, :data:`SETTINGS`)."""

SETTINGS = np.dtype([
    ("detection", np.float64),
    ("ends", np.bool_),
    ("rows", np.bool_),
    ("safety", np.float64),
    ("xi", np.float64),
    ("xi_end", np.float64),
    ("blend", np.float64),
    ("band", np.float64),
    ("recovery", np.float64),
    ("still", np.float64),
])  # fmt: skip
"""What a pass computes: the detection distance [m], whether capsules' end points get rows,
whether the damper rows are written; and the damper's parameters
(:func:`~rrc_pin.solvers.collision.damper_kernels.damper_rows`)."""

