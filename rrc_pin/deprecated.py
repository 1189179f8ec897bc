"""Renamed names kept for one release: each use warns and names the replacement (CHANGELOG.md)."""

from __future__ import annotations

import warnings


def warn_renamed(old: str, new: str, stacklevel: int = 3) -> None:
    """Warn (``DeprecationWarning``) that ``old`` is now ``new`` and goes in the next release.

    Args:
        old: The old name as the caller wrote it (e.g. ``"Controller.step(frame=)"``).
        new: Its replacement.
        stacklevel: The frame to blame: 3 is the caller of the function that warns.
    """
    warnings.warn(f"{old} is deprecated and goes in the next release: use {new}",
                  DeprecationWarning, stacklevel=stacklevel)  # fmt: skip
