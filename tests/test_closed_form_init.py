"""The exports of rrc_pin.solvers.closed_form: every name in ``__all__`` exists, sorted,
complete."""

from __future__ import annotations

import inspect

import rrc_pin.solvers.closed_form as package
from rrc_pin.solvers.closed_form import barker, base, quaternion, rrc_k1607, three_r


def test_star_import_provides_every_exported_name():
    namespace: dict = {}
    exec("from rrc_pin.solvers.closed_form import *", namespace)
    assert set(package.__all__) <= set(namespace)
    assert package.__all__ == sorted(package.__all__)
    assert len(set(package.__all__)) == len(package.__all__)


def test_exports_are_the_defining_objects():
    assert package.BarkerClosedForm is barker.BarkerClosedForm
    assert package.RrcK1607ClosedForm is rrc_k1607.RrcK1607ClosedForm
    assert package.ThreeRClosedForm is three_r.ThreeRClosedForm
    assert package.ClosedForm is base.ClosedForm
    for cls in (package.BarkerClosedForm, package.RrcK1607ClosedForm, package.ThreeRClosedForm):
        assert issubclass(cls, package.ClosedForm)


def test_every_public_quaternion_function_is_exported():
    public = {
        name
        for name, obj in vars(quaternion).items()
        if inspect.isfunction(obj) and obj.__module__ == quaternion.__name__
        and not name.startswith("_")
    }
    assert public == {"differential_rotation", "matrix_from_quaternion", "quaternion_difference",
                      "quaternion_from_matrix", "rotation_vector", "small_rotation"}  # fmt: skip
    assert public <= set(package.__all__)
