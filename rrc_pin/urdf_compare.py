r"""Two URDF texts compared as trees: names and structure exactly, numbers within a tolerance.

A committed URDF and the one regenerated from its DH table on another machine differ in the
last bits of their numbers (numpy's BLAS and SIMD kernels are chosen per CPU), so they are
compared as XML trees, never as text: every element, attribute name and non-numeric value
must be equal (comments are not compared); every number (an attribute whose value is a
blank-separated list of floats) must agree within

.. math:: |a - b| \le \max(r \max(|a|, |b|),\ f)

with :data:`RELATIVE` r and :data:`ABSOLUTE` f.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

RELATIVE = 1e-12
"""Relative tolerance of a number. Numbers are written at 15 significant digits (rounding
error <= 5e-16 relative) and differ between CPUs by an ulp or two (~2e-16) before rounding,
so two honest writings differ by at most ~1e-15: 1e-12 is a thousand times that, and a
thousand times below the smallest change the check must catch (1e-9 relative)."""

ABSOLUTE = 1e-14
"""Absolute floor [m, rad, kg, kg m^2] for numbers near zero, where a relative tolerance means
nothing: the writer shows |x| < 1e-15 as 0, so float noise written as 0 on one machine and as
1e-15 on another is still equal."""


def compare_urdf(
    committed: str, generated: str, relative: float = RELATIVE, absolute: float = ABSOLUTE
) -> list[str]:
    """Differences between two URDF texts beyond the tolerance, one readable line each.

    Args:
        committed: Text of the committed file.
        generated: Text generated from the DH table.
        relative: Relative tolerance of numbers.
        absolute: Absolute floor of the tolerance of numbers.

    Returns:
        Lines ``path: committed ..., generated ...`` naming the element (by its ``name``
        attribute where it has one) and attribute that differ; empty when equivalent. A text
        that is not XML gives one line saying so.
    """
    try:
        a, b = ET.fromstring(committed), ET.fromstring(generated)
    except ET.ParseError as exc:
        return [f"not a URDF (XML error: {exc})"]
    out: list[str] = []
    _compare(a, b, f"/{a.tag}", relative, absolute, out)
    return out


def _label(element: ET.Element, index: int, same_tag: int) -> str:
    tag = str(element.tag)
    if "name" in element.attrib:
        return f"{tag}[{element.attrib['name']}]"
    return f"{tag}[{index + 1}]" if same_tag > 1 else tag


def _compare(
    a: ET.Element, b: ET.Element, path: str, rel: float, floor: float, out: list[str]
) -> None:
    if a.tag != b.tag:
        out.append(f"{path}: committed <{a.tag}>, generated <{b.tag}>")
        return
    if (a.text or "").strip() != (b.text or "").strip():
        out.append(f"{path}: committed text {a.text!r}, generated {b.text!r}")
    for key in sorted(a.attrib.keys() | b.attrib.keys()):
        x, y = a.attrib.get(key), b.attrib.get(key)
        if x is None or y is None or not _same_value(x, y, rel, floor):
            out.append(f"{path}@{key}: committed {x!r}, generated {y!r}")
    kids_a, kids_b = list(a), list(b)
    if [k.tag for k in kids_a] != [k.tag for k in kids_b]:
        names_a = [_label(k, 0, 1) for k in kids_a]
        names_b = [_label(k, 0, 1) for k in kids_b]
        out.append(f"{path}: committed children {names_a}, generated {names_b}")
        return
    for i, (child_a, child_b) in enumerate(zip(kids_a, kids_b, strict=True)):
        same_tag = sum(k.tag == child_a.tag for k in kids_a)
        index = sum(k.tag == child_a.tag for k in kids_a[:i])
        label = _label(child_a, index, same_tag)
        _compare(child_a, child_b, f"{path}/{label}", rel, floor, out)


def _same_value(x: str, y: str, rel: float, floor: float) -> bool:
    """Equal strings, or lists of numbers of one length that agree within the tolerance."""
    if x == y:
        return True
    a, b = _numbers(x), _numbers(y)
    if a is None or b is None or len(a) != len(b):
        return False
    pairs = zip(a, b, strict=True)
    return all(abs(u - v) <= max(rel * max(abs(u), abs(v)), floor) for u, v in pairs)


def _numbers(text: str) -> list[float] | None:
    try:
        values = [float(t) for t in text.split()]
    except ValueError:
        return None
    return values if values and all(map(math.isfinite, values)) else None
