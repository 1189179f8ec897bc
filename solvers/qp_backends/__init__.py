"""QP backends behind one interface, and the dispatcher that picks one by name.

``"osqp"`` is OSQP through its native API (:mod:`.osqp_native`, warm-started workspace);
every other name is a solver that ``qpsolvers.available_solvers`` lists
(:mod:`.qpsolvers_backend`).
"""

from __future__ import annotations

from typing import Any

from solvers.errors import BackendNotFound
from solvers.qp_backends.base import QPBackend, QPSolution, structure_key
from solvers.qp_backends.osqp_native import OSQPBackend
from solvers.qp_backends.qpsolvers_backend import QpsolversBackend


def installed_backends() -> list[str]:
    """Names :func:`make_backend` accepts: ``"osqp"`` first, then qpsolvers' other solvers."""
    names: list[str] = []
    try:
        import osqp  # noqa: F401

        names.append("osqp")
    except ImportError:  # pragma: no cover - osqp is a hard dependency
        pass
    try:
        import qpsolvers

        names += sorted(s for s in qpsolvers.available_solvers if s != "osqp")
    except ImportError:  # pragma: no cover - qpsolvers is a hard dependency
        pass
    return names


def make_backend(name: str, **options: Any) -> QPBackend:
    """A fresh backend (with its own warm-start state) by name.

    Args:
        name: One of :func:`installed_backends`.
        **options: Backend settings (OSQP settings, or the qpsolvers solver's options).

    Raises:
        BackendNotFound: ``name`` is not installed; the error lists the installed ones.
    """
    installed = installed_backends()
    if not isinstance(name, str) or name not in installed:
        raise BackendNotFound(str(name), installed)
    if name == "osqp":
        return OSQPBackend(**options)
    return QpsolversBackend(name, **options)


__all__ = [
    "OSQPBackend",
    "QPBackend",
    "QPSolution",
    "QpsolversBackend",
    "installed_backends",
    "make_backend",
    "structure_key",
]
