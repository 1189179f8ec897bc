"""Checksums of stored results: every file's sha256, written with it and checked before use.

- :func:`digest`: the sha256 of bytes, as hex.
- :func:`seal` / :func:`unseal`: a JSON document that carries the sha256 of its own content
  (key ``sha256``) and is written in one canonical form (sorted keys, one-space indent), so
  that any changed byte either changes the content (the hash no longer matches) or the form
  (the text is no longer the canonical one): :func:`unseal` answers None for both.
- :func:`tree` / :func:`damaged`: the digests of every file under a folder, and which files
  differ from such a list (changed, missing, or not written with it).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

SEAL = "sha256"
"""Key of a sealed document's own hash."""


def digest(data: bytes) -> str:
    """sha256 of ``data`` (64 hex digits)."""
    return hashlib.sha256(data).hexdigest()


def _canonical(doc: dict[str, Any]) -> bytes:
    return (json.dumps(doc, indent=1, sort_keys=True) + "\n").encode()


def _content_hash(doc: dict[str, Any]) -> str:
    body = {k: v for k, v in doc.items() if k != SEAL}
    return digest(json.dumps(body, sort_keys=True, separators=(",", ":")).encode())


def seal(doc: dict[str, Any]) -> bytes:
    """The bytes of ``doc`` (JSON values; no key ``sha256``) with its own hash."""
    return _canonical({**doc, SEAL: _content_hash(doc)})


def unseal(raw: bytes) -> dict[str, Any] | None:
    """The document :func:`seal` wrote, or None if ``raw`` is not exactly such bytes."""
    try:
        doc = json.loads(raw)
    except ValueError:  # not UTF-8 or not JSON
        return None
    if not isinstance(doc, dict) or doc.get(SEAL) != _content_hash(doc):
        return None
    if _canonical(doc) != raw:
        return None
    return {k: v for k, v in doc.items() if k != SEAL}


def tree(folder: Path) -> dict[str, str]:
    """sha256 of every file under ``folder``, by path relative to it (``/``-separated)."""
    return {
        path.relative_to(folder).as_posix(): digest(path.read_bytes())
        for path in sorted(folder.rglob("*"))
        if path.is_file()
    }


def damaged(folder: Path, listed: dict[str, str], skip: frozenset[str]) -> dict[str, str]:
    """The files under ``folder`` that differ from ``listed`` (path -> sha256), and how.

    Args:
        folder: The folder.
        listed: What was written (:func:`tree` then).
        skip: Paths not checked (the list's own file).

    Returns:
        Path -> ``"missing"``, ``"changed since written"`` or ``"not written with it"``.
    """
    out: dict[str, str] = {}
    for name, expected in listed.items():
        path = folder / name
        if not path.is_file():
            out[name] = "missing"
        elif digest(path.read_bytes()) != expected:
            out[name] = "changed since written"
    for path in sorted(folder.rglob("*")):
        name = path.relative_to(folder).as_posix()
        if path.is_file() and name not in listed and name not in skip:
            out[name] = "not written with it"
    return out
