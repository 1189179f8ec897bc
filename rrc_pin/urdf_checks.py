"""What a URDF's parser would refuse, said in the error: the tree checked first, its stderr kept.

Pinocchio parses URDFs with urdfdom (C++), which prints its reasons on the process's standard
error (file descriptor 2) and raises only "does not contain a valid URDF model". The links and
joints are checked here before it runs (:func:`check_tree`), naming the joint and the link;
what else it refuses, its own messages say, captured from descriptor 2 while it parses
(:func:`parser_messages`) and put in the exception.
"""

from __future__ import annotations

import contextlib
import os
import re
import sys
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Iterator

from rrc_pin.errors import URDFError


def check_tree(root: ET.Element, path: str) -> None:
    """Refuse a URDF whose links and joints do not make one tree.

    Args:
        root: The ``<robot>`` element.
        path: The file, for the error.

    Raises:
        URDFError: A link or joint without a name or named twice, a joint whose parent or
            child is not a link of the file, a link that is the child of two joints, or links
            that do not hang from one root.
    """
    links = _names(root.findall("link"), "link", path)
    joints = root.findall("joint")
    _names(joints, "joint", path)
    parent_of: dict[str, str] = {}
    for joint in joints:
        name = joint.get("name")
        ends = {}
        for end in ("parent", "child"):
            element = joint.find(end)
            link = None if element is None else element.get("link")
            if link not in links:
                said = "has none" if link is None else f"{link!r} is not a link of the file"
                raise URDFError(path, f"joint {name!r}: its {end} link {said}")
            ends[end] = link
        if ends["child"] in parent_of:
            raise URDFError(path, f"link {ends['child']!r} is the child of two joints "
                            f"({parent_of[ends['child']]!r} and {name!r})")  # fmt: skip
        parent_of[ends["child"]] = name  # type: ignore[assignment]
    roots = [link for link in links if link not in parent_of]
    if len(roots) != 1:
        raise URDFError(path, f"the links hang from {len(roots)} roots "
                        f"({', '.join(roots) or 'none: a loop'}); a URDF is one tree")  # fmt: skip


def _names(elements: list[ET.Element], kind: str, path: str) -> set[str]:
    """The ``name`` attributes of ``elements``, each present and given once.

    Raises:
        URDFError: A ``kind`` without a name, or two of the same name.
    """
    names: set[str] = set()
    for element in elements:
        name = element.get("name")
        if not name:
            raise URDFError(path, f"a <{kind}> has no name")
        if name in names:
            raise URDFError(path, f"two <{kind}> elements are named {name!r}")
        names.add(name)
    return names


@contextlib.contextmanager
def parser_messages() -> Iterator[list[str]]:
    """Capture what is written on file descriptor 2 while the block runs (a C++ parser's).

    The list yielded gets the messages when the block ends, one per line, without urdfdom's
    ``Error:`` prefix and the source locations of its build. Process-wide while it runs: what
    another thread prints then is captured too (:func:`replay` gives it back).
    """
    said: list[str] = []
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 2)
        try:
            yield said
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            text = sink.read().decode(errors="replace")
            said += [line for line in text.splitlines() if line.strip()]


def readable(said: list[str]) -> str:
    """The parser's messages as one sentence: its ``Error:`` prefixes and source lines dropped."""
    kept = [re.sub(r"^\s*(Error|Warning):\s*", "", line) for line in said
            if not re.match(r"^\s*at line \d+ in ", line)]  # fmt: skip
    return "; ".join(line.strip() for line in kept if line.strip())


def replay(said: list[str]) -> None:
    """Write captured messages back to standard error (a parse that succeeded)."""
    if said:
        print("\n".join(said), file=sys.stderr)
