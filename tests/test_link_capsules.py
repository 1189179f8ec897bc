"""rrc_pin.link_capsules: capsules along the DH offsets, and the pairs that always touch."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin import models
from rrc_pin.errors import InvalidInput
from rrc_pin.geometry import CollisionModel
from rrc_pin.link_capsules import always_touching, link_capsules


def test_barker_links_follow_his_offsets():
    spec = models.CATALOGUE["barker6"]
    lengths = {}
    for c in link_capsules(spec):
        lengths.setdefault(c.link, []).append(round(c.length, 6))
    p = spec.parameters
    assert lengths == {"link1": [p["no"]], "link2": [p["sn"], p["es"]], "link3": [p["a3"]],
                       "link4": [p["we"]], "link5": [0.0], "link6": [p["hw"]]}  # fmt: skip
    assert always_touching(spec) == (("link2", "link4"), ("link4", "link6"))


@pytest.mark.parametrize("name", list(models.CATALOGUE))
def test_pairs_said_to_always_touch_do_touch_at_random_configurations(name, rng):
    """Checked with coal on the capsules, the pairs left out as ``always`` included."""
    robot = rrc_pin.load(name)
    touching = set(always_touching(robot.spec))
    cm = CollisionModel(robot)
    link = {str(o.name): str(robot.model.frames[o.parentFrame].name)
            for o in cm.scene.geometry.geometryObjects}  # fmt: skip
    always = [p for p, r in cm.excluded.items() if r == "always"]
    assert {tuple(link[x] for x in p) for p in always} == touching
    probe = pin.GeometryModel()
    for obj in cm.scene.geometry.geometryObjects:
        probe.addGeometryObject(obj)
    index = {n: i for i, n in enumerate(cm.bodies)}
    for a, b in always:
        probe.addCollisionPair(pin.CollisionPair(index[a], index[b]))
    for _ in range(50):
        data = probe.createData()
        pin.computeDistances(robot.model, robot.model.createData(), probe, data,
                             robot.to_pinocchio(robot.random_q(rng)))  # fmt: skip
        per_link: dict[tuple[str, str], float] = {}
        for (a, b), r in zip(always, data.distanceResults, strict=True):
            key = (link[a], link[b])
            per_link[key] = min(per_link.get(key, np.inf), r.min_distance)
        assert all(d <= 1e-12 for d in per_link.values()), per_link


def test_radii_are_checked():
    spec = models.CATALOGUE["kr5_3r"]
    with pytest.raises(InvalidInput) as info:
        dataclasses.replace(spec, collision_radii=(0.1, 0.0, 0.1))
    assert info.value.argument == "collision_radii"
    assert link_capsules(dataclasses.replace(spec, collision_radii=())) == ()
