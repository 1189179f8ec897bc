"""Collision geometry, obstacles, virtual walls and distances (coal through Pinocchio).

One concept per module:

- :mod:`~rrc_pin.geometry.collision_model`: :class:`CollisionModel`, the public entry point;
- :mod:`~rrc_pin.geometry.robot_geometry`: a robot's geometry on its model (paper arms'
  capsules, URDF meshes or hulls, a cell's arms), with its filtered pairs;
- :mod:`~rrc_pin.geometry.pairs`: the rules that leave pairs out (rigid, adjacent, SRDF, ...);
- :mod:`~rrc_pin.geometry.capsules`: cylinder-and-spheres triples merged into capsules;
- :mod:`~rrc_pin.geometry.hulls`: meshes as convex hulls, cached per process;
- :mod:`~rrc_pin.geometry.shapes`: obstacle shapes and bounding spheres;
- :mod:`~rrc_pin.geometry.scene`: the frozen scene a query reads;
- :mod:`~rrc_pin.geometry.proximity`: one tick's query, :class:`Proximity`;
- :mod:`~rrc_pin.geometry.walls`: virtual walls, :class:`Wall`.

A layer above :mod:`rrc_pin.robot` and below the tasks and limits.
"""

from rrc_pin.geometry.collision_model import CollisionModel
from rrc_pin.geometry.proximity import CollisionData, Proximity
from rrc_pin.geometry.walls import Wall

__all__ = ["CollisionData", "CollisionModel", "Proximity", "Wall"]
