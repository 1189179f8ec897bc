r"""Mimic joints' own limits, kept through the joints they follow.

A URDF ``<mimic>`` joint follows its primary joint, :math:`q_m = k\,q_p + o` (multiplier k,
offset o); Pinocchio models it without a coordinate of its own (``JointModelMimic``) and
drops its ``<limit>``. Its own limits are kept here as limits of the primary, the only joint
the resolver moves:

.. math::

    l_m \le k\,q_p + o \le u_m \iff q_p \in \Big[\tfrac{l_m - o}{k}, \tfrac{u_m - o}{k}\Big]
    \text{ (ends swapped for } k < 0), \qquad
    |k\,\dot q_p| \le v_m \iff |\dot q_p| \le v_m / |k|,

intersected with the primary's own box and those of its other mimics. Each end is nudged
inward until :math:`k\,q_p + o` computed in floating point is within the mimic's limits (and
:math:`|k|\,\dot q_p` within its speed): rounding is monotone, so every primary value within
the tightened box keeps the mimic within its own.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import InvalidInput, URDFError

Array = npt.NDArray[np.float64]

MimicLimits = Mapping[str, tuple[float, float, float]]
"""A mimic joint's own limits by name: (lower, upper, velocity) [rad or m, rad/s or m/s],
-inf, inf and inf where it has none."""

NUDGES = 8
"""Steps of one ulp an end may move inward to absorb the rounding of :math:`k q_p + o`."""


class Mimic(NamedTuple):
    """A joint that follows another: ``q = multiplier * q_primary + offset``.

    Attributes:
        name: The mimic joint's name.
        primary: The name of the joint it follows (one of the robot's ``joint_names``).
        multiplier: k [1] (any sign; 0 holds the mimic at its offset).
        offset: o [rad or m].
        lower: Its own lower position limit [rad or m] (-inf where none).
        upper: Its own upper position limit [rad or m] (inf where none).
        velocity: Its own speed limit [rad/s or m/s] (inf where none).
    """

    name: str
    primary: str
    multiplier: float
    offset: float
    lower: float = -math.inf
    upper: float = math.inf
    velocity: float = math.inf

    def position(self, q_primary: float) -> float:
        """The mimic's position [rad or m] at the primary's ``q_primary``."""
        return self.multiplier * q_primary + self.offset

    def primary_bounds(self) -> tuple[float, float, float]:
        """Bounds ``(lower, upper, velocity)`` on the primary keeping this joint within its own.

        Module docstring; unbounded where it has none, or where ``multiplier`` is 0.
        """
        k = self.multiplier
        if k == 0.0:
            return -math.inf, math.inf, math.inf
        ends = sorted(((self.lower - self.offset) / k, (self.upper - self.offset) / k))
        lo, hi = ends[0], ends[1]
        for _ in range(NUDGES):
            if math.isfinite(lo) and not self.lower <= self.position(lo) <= self.upper:
                lo = math.nextafter(lo, math.inf)
            if math.isfinite(hi) and not self.lower <= self.position(hi) <= self.upper:
                hi = math.nextafter(hi, -math.inf)
        speed = self.velocity / abs(k)
        while math.isfinite(speed) and abs(k) * speed > self.velocity:
            speed = math.nextafter(speed, 0.0)
        return lo, hi, speed


def mimics_of(model: pin.Model, limits: MimicLimits | None = None) -> tuple[Mimic, ...]:
    """The mimic joints of ``model`` with their own ``limits`` (by name; none where absent).

    Raises:
        InvalidInput: ``limits`` is not a mapping of this model's mimic joints to three
            numbers (lower <= upper, velocity > 0, none NaN).
    """
    pairs = zip(model.mimicking_joints, model.mimicked_joints, strict=True) if hasattr(
        model, "mimicking_joints") else ()  # fmt: skip
    out = []
    for j, primary in pairs:
        joint = model.joints[j].extract()
        out.append(Mimic(str(model.names[j]), str(model.names[primary]), float(joint.scaling),
                         float(joint.offset)))  # fmt: skip
    if limits is None:
        return tuple(out)
    if not isinstance(limits, Mapping):
        raise InvalidInput("mimic_limits", f"expected a mapping name -> (lower, upper, "
                           f"velocity), got {limits!r}")  # fmt: skip
    names = {m.name for m in out}
    for name, value in limits.items():
        if name not in names:
            raise InvalidInput("mimic_limits", f"{name!r} is not a mimic joint of the model "
                               f"(mimic joints: {sorted(names)})")  # fmt: skip
        try:
            lower, upper, velocity = (float(x) for x in value)
        except (TypeError, ValueError) as exc:
            raise InvalidInput("mimic_limits", f"{name!r}: expected (lower, upper, velocity), "
                               f"got {value!r}") from exc  # fmt: skip
        if not (lower <= upper and velocity > 0.0):  # NaN fails both
            raise InvalidInput("mimic_limits", f"{name!r}: expected lower <= upper and "
                               f"velocity > 0, got {value!r}")  # fmt: skip
    return tuple(m._replace(lower=lim[0], upper=lim[1], velocity=lim[2]) if (lim := limits.get(
        m.name)) is not None else m for m in out)  # fmt: skip


def tightened(
    model: pin.Model, mimics: tuple[Mimic, ...], source: str, unbounded: float
) -> pin.Model:
    """``model``, or a copy whose primaries' limits keep each mimic within its own.

    The primaries' position and velocity limits, tightened as the module docstring says.

    Args:
        model: The Pinocchio model (not changed).
        mimics: Its mimic joints with their own limits (:func:`mimics_of`).
        source: Where the model came from, for messages.
        unbounded: A limit beyond +-this counts as none (and a speed of 0).

    Raises:
        URDFError: A mimic joint whose limits no position of its primary within the primary's
            own keeps (named), or a position-limited mimic of a continuous joint.
    """
    if all(m.primary_bounds() == (-math.inf, math.inf, math.inf) for m in mimics):
        _check_held(mimics, source)
        return model
    out = pin.Model(model)
    lower, upper = out.lowerPositionLimit.copy(), out.upperPositionLimit.copy()
    velocity = out.velocityLimit.copy()
    for m in mimics:
        lo, hi, speed = m.primary_bounds()
        joint = out.joints[out.getJointId(m.primary)]
        i, v = joint.idx_q, joint.idx_v
        if joint.nq != 1 and (math.isfinite(lo) or math.isfinite(hi)):
            raise URDFError(source, f"mimic joint {m.name!r} has position limits [{m.lower}, "
                            f"{m.upper}] but follows the continuous joint {m.primary!r}, "
                            "whose angle has no limits to keep them by")  # fmt: skip
        if joint.nq == 1:
            own_lo = lower[i] if abs(lower[i]) <= unbounded else -math.inf
            own_hi = upper[i] if abs(upper[i]) <= unbounded else math.inf
            lower[i], upper[i] = max(own_lo, lo), min(own_hi, hi)
            if lower[i] > upper[i]:
                raise URDFError(source, f"mimic joint {m.name!r} (= {m.multiplier} * "
                                f"{m.primary} + {m.offset}) stays within [{m.lower}, {m.upper}]"
                                f" for {m.primary} in [{lo:.6g}, {hi:.6g}] only, outside "
                                f"{m.primary}'s own limits [{own_lo}, {own_hi}]")  # fmt: skip
        own = velocity[v] if 0.0 < velocity[v] < unbounded else math.inf
        velocity[v] = min(own, speed)
    _check_held(mimics, source)
    out.lowerPositionLimit, out.upperPositionLimit, out.velocityLimit = lower, upper, velocity
    if hasattr(out, "lowerVelocityLimit"):  # Pinocchio 4 checks lower <= upper (velocityLimit)
        out.lowerVelocityLimit = np.minimum(out.lowerVelocityLimit, velocity)
    return out


def _check_held(mimics: tuple[Mimic, ...], source: str) -> None:
    """Refuse a mimic joint held at its offset (multiplier 0) outside its own limits."""
    for m in mimics:
        if m.multiplier == 0.0 and not m.lower <= m.offset <= m.upper:
            raise URDFError(
                source, f"mimic joint {m.name!r} is held at its offset {m.offset} (multiplier "
                f"0), outside its limits [{m.lower}, {m.upper}]",
            )  # fmt: skip


def velocity_caps(model: pin.Model, mimics: tuple[Mimic, ...]) -> Array:
    """The speed limits (nv,) the mimic joints put on their primaries, inf where none."""
    caps = np.full(model.nv, math.inf)
    for m in mimics:
        v = model.joints[model.getJointId(m.primary)].idx_v
        caps[v] = min(caps[v], m.primary_bounds()[2])
    return caps


def urdf_mimic_limits(root: ET.Element, source: str) -> dict[str, tuple[float, float, float]]:
    """The own limits of a URDF's mimic joints, by name (:data:`MimicLimits`).

    ``lower`` and ``upper`` as urdfdom reads them (0 where a revolute or prismatic joint's
    ``<limit>`` omits them; none for a continuous joint or without ``<limit>``); a
    ``velocity`` of 0 or none is no limit.

    Raises:
        URDFError: A limit that is not a number, or lower above upper (naming the joint).
    """
    out: dict[str, tuple[float, float, float]] = {}
    for joint in root.iter("joint"):
        kind = joint.get("type")
        if joint.find("mimic") is None or kind not in ("revolute", "prismatic", "continuous"):
            continue
        name = joint.get("name") or ""
        limit = joint.find("limit")
        if limit is None:
            continue
        try:
            lower, upper = (float(limit.get(side, "0")) for side in ("lower", "upper"))
            velocity = float(limit.get("velocity", "0"))
        except ValueError as exc:
            raise URDFError(source, f"joint {name!r}: a <limit> is not a number: {exc}") from exc
        if kind == "continuous":
            lower, upper = -math.inf, math.inf
        if not lower <= upper:
            raise URDFError(source, f"joint {name!r}: <limit> lower {lower} > upper {upper}")
        out[name] = (lower, upper, velocity if velocity > 0.0 else math.inf)
    return out
