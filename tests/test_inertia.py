"""Link inertial data: consistency checks, the PUMA 560 mapping onto Barker's frames, URDFs."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.errors import InvalidInput
from rrc_pin.models import CATALOGUE
from rrc_pin.models import puma560_inertia as puma
from rrc_pin.models.inertia import LinkInertial, cylinder, make


@pytest.mark.parametrize(
    ("mass", "moments", "field"),
    [
        (0.0, (1.0, 1.0, 1.0), "mass"),
        (-1.0, (1.0, 1.0, 1.0), "mass"),
        (1.0, (1.0, 1.0, -0.1), "inertia"),
        (1.0, (0.1, 0.1, 1.0), "inertia"),  # triangle inequality
    ],
)
def test_unphysical_bodies_are_refused(mass, moments, field):
    with pytest.raises(InvalidInput, match=field):
        make(mass, np.zeros(3), np.diag(moments))


def test_asymmetric_inertia_is_refused():
    with pytest.raises(InvalidInput, match="inertia"):
        LinkInertial(1.0, (0.0, 0.0, 0.0), ((1.0, 0.5, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))


def test_moving_a_body_keeps_its_mass_moments_and_com_distance(rng):
    body = cylinder(2.0, 0.05, (0.3, 0.1, -0.2))
    R = pin.exp3(rng.normal(size=3))
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, rng.normal(size=3)
    moved = body.moved(T)
    assert moved.mass == body.mass
    assert np.allclose(
        np.linalg.eigvalsh(moved.inertia_array), np.linalg.eigvalsh(body.inertia_array)
    )
    assert np.allclose(moved.com_array, R @ body.com_array + T[:3, 3])


def test_cylinder_moments():
    body = cylinder(3.0, 0.1, (0.0, 0.0, 0.6))
    assert np.allclose(body.com_array, (0.0, 0.0, 0.3))
    assert np.allclose(np.diag(body.inertia_array), (3 * (0.03 + 0.36) / 12,) * 2 + (0.015,))


def test_corke_frames_ride_on_barkers_links(rng):
    """The stated correspondence is right: X_i is the same at every configuration.

    Tolerance 1e-4 m: Corke's shoulder offset is 0.15005 m, Barker's PUMA value 0.15 m.
    """
    chain = CATALOGUE["barker6"].chain
    corke = puma.corke_chain(chain.rows[0].d)
    X = puma.link_to_corke(chain)
    for _ in range(20):
        q = rng.uniform(-np.pi, np.pi, 6)
        F_b, F_c = chain.frames(q), corke.frames(puma.SIGNS * q + puma.OFFSETS)
        for i in range(1, 7):
            assert np.abs(np.linalg.inv(F_b[i]) @ F_c[i] - X[i - 1]).max() < 1e-4


def test_barker_mapping_is_a_mirror_and_keeps_the_published_masses():
    X = puma.link_to_corke(CATALOGUE["barker6"].chain)
    assert all(np.isclose(np.linalg.det(x[:3, :3]), -1.0) for x in X)
    masses = [b.mass for b in puma.barker_inertials(CATALOGUE["barker6"].chain)]
    assert masses == [1.0, 17.4, 4.8, 0.82, 0.34, 0.09]


def test_generated_urdfs_carry_the_inertial_data():
    """Pinocchio reads back the masses and the gravity torque of the data in the URDF."""
    barker = rrc_pin.load("barker6")
    assert [round(i.mass, 6) for i in barker.model.inertias[1:]] == [
        1.0,
        17.4,
        4.8,
        0.82,
        0.34,
        0.09,
    ]
    k1607 = rrc_pin.load("rrc_k1607")
    assert sum(i.mass for i in k1607.model.inertias[1:]) == pytest.approx(21.5)
    # Arm horizontal (Barker q2 = 90 deg): link 2's 17.4 kg sit 0.068 m from the shoulder
    # axis (0.4318 - 0.3638: the source measures from the elbow), links 3-6 (6.05 kg) about
    # 0.5 m out: some 12 + 30 N m about joint 2.
    q = np.zeros(6)
    q[1] = np.pi / 2
    g = pin.computeGeneralizedGravity(barker.model, barker.model.createData(), q)
    assert 35.0 < abs(g[1]) < 60.0


def test_published_puma_link3_breaks_the_triangle_inequality():
    """docs/errata.md: the source's link 3 moments are refused; the raised Izz is accepted.

    Link 1 as published (mass 0) is refused too; the data used are physical.
    """
    with pytest.raises(InvalidInput, match="triangle"):
        make(4.8, np.zeros(3), np.diag([0.066, 0.086, 0.0125]))
    with pytest.raises(InvalidInput, match="mass"):
        make(0.0, np.zeros(3), np.diag([0.0, 0.35, 0.0]))
    used = puma.corke_inertials()
    assert np.allclose(np.diag(used[2].inertia_array), (0.066, 0.086, 0.020))
    assert np.allclose(np.diag(used[0].inertia_array), (0.175, 0.35, 0.175))
