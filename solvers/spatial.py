"""Reference-frame changes of twists and Jacobians (rows ordered [v; w]).

Three frames, named as Pinocchio names them (README, "Conventions"):

- ``world_aligned``: velocity of the tool-frame origin ``p``, in base-frame axes.
- ``local``: the same velocity in tool-frame axes ``R``.
- ``world``: spatial velocity at the base origin, base axes: ``v_0 = v_p - w x p``.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.errors import InvalidInput

Array = npt.NDArray[np.float64]
Reference = Literal["world_aligned", "local", "world"]
REFERENCES: tuple[str, ...] = ("world_aligned", "local", "world")


def check_reference(ref: str) -> Reference:
    """Return ``ref`` if it names one of :data:`REFERENCES`, else raise naming ``ref``."""
    if not isinstance(ref, str) or ref not in REFERENCES:
        raise InvalidInput("ref", f"expected one of {', '.join(REFERENCES)}, got {ref!r}")
    return ref  # type: ignore[return-value]


def from_world_aligned(M: Array, rotation: Array, position: Array, ref: Reference) -> Array:
    """Express twists or Jacobian columns given in ``world_aligned`` in frame ``ref``.

    Args:
        M: (6,) twist or (6, n) Jacobian, rows [v; w], ``world_aligned``.
        rotation: (3, 3) tool orientation in the base frame.
        position: (3,) tool-frame origin in the base frame [m].
        ref: Target frame.

    Returns:
        Array of the shape of ``M`` in frame ``ref``.
    """
    if ref == "world_aligned":
        return M
    v, w = M[:3], M[3:]
    if ref == "local":
        return np.concatenate([rotation.T @ v, rotation.T @ w])
    return np.concatenate([v - np.cross(w, position, axis=0), w])



def to_world_aligned(M: Array, rotation: Array, position: Array, ref: Reference) -> Array:
    """Express a twist (6,) given in frame ``ref`` in ``world_aligned``.

    The inverse of :func:`from_world_aligned`.

    Args:
        M: (6,) twist, rows [v; w], in frame ``ref``.
        rotation: (3, 3) tool orientation in the base frame.
        position: (3,) tool-frame origin in the base frame [m].
        ref: Its frame.

    Returns:
        (6,) twist in ``world_aligned``: ``[R v; R w]`` from ``local``, ``[v + w x p; w]``
        from ``world``.
    """
    if ref == "world_aligned":
        return M
    v, w = M[:3], M[3:]
    if ref == "local":
        return np.concatenate([rotation @ v, rotation @ w])
    return np.concatenate([v + np.cross(w, position), w])
