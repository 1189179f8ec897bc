"""Singularity strategies of the controller, one per module behind :class:`Strategy`.

:func:`make_strategy` builds one by name (:data:`STRATEGIES`).
"""

from __future__ import annotations

from collections.abc import Callable

from rrc_pin.control.strategies.auxiliary_hand import AuxiliaryHand
from rrc_pin.control.strategies.base import Decision, Situation, Strategy
from rrc_pin.control.strategies.freezing import Freezing
from rrc_pin.control.strategies.generalized_inverse import GeneralizedInverse
from rrc_pin.control.strategies.resolver_only import ResolverOnly
from rrc_pin.control.strategies.slowdown import Slowdown
from rrc_pin.control.strategies.uncoupled import Uncoupled
from rrc_pin.control.strategies.wrist_choice import WristChoice
from rrc_pin.errors import InvalidInput

STRATEGIES: dict[str, Callable[[], Strategy]] = {
    "resolver": ResolverOnly,
    "slowdown": Slowdown,
    "generalized_inverse": GeneralizedInverse,
    "freezing": Freezing,
    "auxiliary_hand": AuxiliaryHand,
    "wrist_choice": WristChoice,
    "uncoupled": Uncoupled,
}
"""Names :func:`make_strategy` takes, with the strategy each builds (default settings)."""


def make_strategy(strategy: Strategy | str | None) -> Strategy:
    """A strategy: ``strategy`` itself, the one it names, or (None) :class:`ResolverOnly`.

    Raises:
        InvalidInput: An unknown name (the error lists them) or another type, naming
            ``strategy``.
    """
    if strategy is None:
        return ResolverOnly()
    if isinstance(strategy, Strategy):
        return strategy
    if isinstance(strategy, str) and strategy in STRATEGIES:
        return STRATEGIES[strategy]()
    raise InvalidInput(
        "strategy", f"expected a Strategy or one of {', '.join(STRATEGIES)}, got {strategy!r}"
    )


__all__ = [
    "STRATEGIES",
    "AuxiliaryHand",
    "Decision",
    "Freezing",
    "GeneralizedInverse",
    "ResolverOnly",
    "Situation",
    "Slowdown",
    "Strategy",
    "Uncoupled",
    "WristChoice",
    "make_strategy",
]
