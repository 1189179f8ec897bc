"""QP backends behind one interface, and the dispatcher that picks one by name.

``"daqp"`` and ``"osqp"`` are called through their own APIs (:mod:`.daqp_backend`,
:mod:`.osqp_backend`); every other name is a solver that ``qpsolvers.available_solvers``
lists (:mod:`.qpsolvers_backend`). :func:`make_backend` checks the options by solving a
small QP with them, so that a misspelt setting is refused at construction instead of
making every later solve fail.
"""

from __future__ import annotations

import importlib.util
from typing import Any

import numpy as np

from rrc_pin.solvers.errors import InvalidInput, NumericalFailure, ProblemError, UnknownBackend
from rrc_pin.solvers.qp_backends.base import QPBackend, QPSolution
from rrc_pin.solvers.qp_backends.daqp_backend import DaqpBackend
from rrc_pin.solvers.qp_backends.osqp_backend import OSQPBackend
from rrc_pin.solvers.qp_backends.qp import QP, checked
from rrc_pin.solvers.qp_backends.qpsolvers_backend import QpsolversBackend

NATIVE: dict[str, type[QPBackend]] = {"daqp": DaqpBackend, "osqp": OSQPBackend}
"""Backends called through their own Python API."""


def installed_backends() -> list[str]:
    """Names :func:`make_backend` accepts: daqp and osqp first, then qpsolvers' others."""
    import qpsolvers

    native = [name for name in NATIVE if importlib.util.find_spec(name) is not None]
    others = sorted(s for s in qpsolvers.available_solvers if s not in NATIVE)
    return native + others


def make_backend(name: str, time_limit: float | None = None, **options: Any) -> QPBackend:
    """A fresh backend (with its own warm starts) by name, its options checked.

    Args:
        name: One of :func:`installed_backends`.
        time_limit: [s] The most time one solve may take: an answer that took longer is
            refused (:func:`rrc_pin.solvers.qp_backends.qp.solve_checked`), or None for no limit.
            The backends'
            own time limits are not used: they make the answers depend on the machine's load;
            their iteration limits (each backend's defaults) bound the time instead.
        **options: Backend settings (e.g. DAQP's ``iter_limit``, OSQP's ``eps_abs``).

    Raises:
        UnknownBackend: ``name`` is not installed; the error lists the installed ones.
        InvalidInput: The backend refuses ``options`` (argument ``backend_options``).
    """
    installed = installed_backends()
    if not isinstance(name, str) or name not in installed:
        raise UnknownBackend(str(name), installed)
    try:
        backend = NATIVE[name](**options) if name in NATIVE else QpsolversBackend(name, **options)
        answer = backend.solve(_PROBE)  # every setting is read at the first solve
    except ProblemError as exc:
        reason = str(exc).splitlines()[0][:300]
        raise InvalidInput("backend_options", f"{name} refused {options}: {reason}") from exc
    try:
        probe = checked(answer, 2, name)
    except NumericalFailure as exc:
        reason = f"fails a 2-variable QP ({exc})"
    else:
        good = np.allclose(probe.x, [0.5, 0.5], atol=1e-3)
        reason = "" if good else f"fails a 2-variable QP (answers {probe.x.tolist()})"
    if reason:
        raise InvalidInput("backend_options", f"{name} with {options} {reason}")
    backend.reset()
    backend.time_limit = time_limit
    return backend


_PROBE = QP(
    P=np.eye(2), q=np.array([-1.0, -1.0]), C=np.array([[1.0, 1.0]]), l=np.array([-np.inf]),
    u=np.array([1.0]), lb=np.zeros(2), ub=np.ones(2), key="probe",
)  # fmt: skip
"""min |z|^2/2 - z1 - z2 s.t. z1 + z2 <= 1, 0 <= z <= 1: z = (0.5, 0.5)."""

__all__ = [
    "NATIVE",
    "DaqpBackend",
    "OSQPBackend",
    "QPBackend",
    "QPSolution",
    "QpsolversBackend",
    "installed_backends",
    "make_backend",
]
