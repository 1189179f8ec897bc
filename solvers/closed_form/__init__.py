"""Closed-form fast paths of the paper arms, one module per arm.

- :class:`BarkerClosedForm`: Barker's PUMA-type arm (NASA TM-85685), wrist centre as tool.
- :class:`RrcK1607ClosedForm`: the 7-DOF RRC K-1607 (Nguyen & Zhou), minimum-norm and
  weighted rates.
- :class:`ThreeRClosedForm`: the 3R arm of the Robotics I exam (linear velocity task).
- Nguyen's weighted pseudo-inverse for any Jacobian (eqs. 21-23): :func:`weighted_rates`,
  :func:`weighted_pseudo_inverse`, :func:`null_space_projector`, :func:`weight_factor`.
- Nguyen's quaternion tools (eqs. 24-37): :func:`quaternion_from_matrix` and the rest.

Every closed form implements :class:`ClosedForm`.
"""

from rrc_pin.solvers.closed_form.barker import BarkerClosedForm, BarkerSingularity
from rrc_pin.solvers.closed_form.base import ClosedForm
from rrc_pin.solvers.closed_form.quaternion import (
    differential_rotation,
    matrix_from_quaternion,
    quaternion_difference,
    quaternion_from_matrix,
    rotation_vector,
    small_rotation,
)
from rrc_pin.solvers.closed_form.rrc_k1607 import RrcK1607ClosedForm
from rrc_pin.solvers.closed_form.three_r import AngularRates, ThreeRClosedForm, minimum_norm_shift
from rrc_pin.solvers.closed_form.weighted import (
    null_space_projector,
    weight_factor,
    weighted_pseudo_inverse,
    weighted_rates,
)

__all__ = [
    "AngularRates",
    "BarkerClosedForm",
    "BarkerSingularity",
    "ClosedForm",
    "RrcK1607ClosedForm",
    "ThreeRClosedForm",
    "differential_rotation",
    "matrix_from_quaternion",
    "minimum_norm_shift",
    "null_space_projector",
    "quaternion_difference",
    "quaternion_from_matrix",
    "rotation_vector",
    "small_rotation",
    "weight_factor",
    "weighted_pseudo_inverse",
    "weighted_rates",
]
