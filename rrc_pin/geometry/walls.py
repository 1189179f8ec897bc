r"""Virtual walls: half-spaces a tool frame's origin stays inside.

A wall is a plane the tool may not cross: the tool's origin p (world frame, [m]) stays where

.. math:: n \cdot p \le o

with n the wall's unit normal pointing out of the allowed region and o its offset. A
workspace box gives six walls (its faces, normals outward); a single half-space is one wall.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]


class Wall(NamedTuple):
    """One virtual wall: the origin of ``frame`` stays where ``normal . p <= offset``.

    Attributes:
        name: The wall's name (a box's faces: ``<name>/+x``, ``<name>/-x``, ...).
        frame: The frame whose origin the wall holds (a tool frame, or any frame).
        normal: Unit normal (3,), world frame, pointing out of the allowed region.
        offset: Offset [m]: the wall is the plane ``normal . p = offset``.
    """

    name: str
    frame: str
    normal: Array
    offset: float


FACES: tuple[str, ...] = ("+x", "-x", "+y", "-y", "+z", "-z")
"""Suffixes of a workspace box's walls, in the order :func:`box_walls` returns them."""


def box_walls(name: str, frame: str, T: Array, size: Array) -> tuple[Wall, ...]:
    """The six walls of a box of sides ``size`` (3,) [m] at pose ``T`` (4, 4), normals outward.

    Inside the box, ``|R^T (p - t)|_k <= size_k / 2`` for each axis k: the face of axis k
    and sign s is the wall ``(s R e_k) . p <= (s R e_k) . t + size_k / 2``.
    """
    R, t = T[:3, :3], T[:3, 3]
    walls = []
    for k in range(3):
        for s, face in ((1.0, FACES[2 * k]), (-1.0, FACES[2 * k + 1])):
            n = s * R[:, k]
            n.flags.writeable = False
            walls.append(Wall(f"{name}/{face}", frame, n, float(n @ t + size[k] / 2.0)))
    return tuple(walls)


def plane_wall(name: str, frame: str, normal: Array, offset: float) -> Wall:
    """One wall: ``normal`` (3,) is made unit, ``offset`` divided by its norm."""
    norm = float(np.linalg.norm(normal))
    n = normal / norm
    n.flags.writeable = False
    return Wall(name, frame, n, offset / norm)
