"""URDFs compared as trees: a few ulps pass, 1e-9 or any structural change fails, named."""

from __future__ import annotations

import re

import pytest

from rrc_pin.urdf_compare import ABSOLUTE, RELATIVE, compare_urdf
from rrc_pin.urdf_export import COMMITTED_DIR

NUMBER = re.compile(r"(?<![\w.])-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?(?![\w.])")
ATTRIBUTE = re.compile(r'="([^"]*)"')
FILES = sorted(COMMITTED_DIR.glob("*.urdf"))


def numbers_in_attributes(text: str) -> list[re.Match[str]]:
    """(start, end, text) of every number in an attribute value, after the XML declaration."""
    out = []
    for attr in ATTRIBUTE.finditer(text, text.index("?>")):
        for m in NUMBER.finditer(attr.group(1)):
            out.append((attr.start(1) + m.start(), attr.start(1) + m.end(), m.group()))
    return out


def perturb(text: str, factor_of) -> str:
    """``text`` with every attribute number x replaced by ``repr(x * factor_of(i))``."""
    pieces, last = [], 0
    for i, (start, end, token) in enumerate(numbers_in_attributes(text)):
        pieces += [text[last:start], repr(float(token) * float(factor_of(i)))]
        last = end
    return "".join(pieces) + text[last:]


def test_the_five_committed_files_are_there() -> None:
    assert [f.stem for f in FILES] == [
        "barker6", "kr5_3r", "nadkarni_c1", "nadkarni_c2", "rrc_k1607",
    ]  # fmt: skip


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_every_number_moved_by_a_few_ulps_still_matches(path, rng) -> None:
    text = path.read_text()
    assert len(numbers_in_attributes(text)) > 50
    signs = rng.choice([-1.0, 1.0], size=10_000)
    moved = perturb(text, lambda i: 1.0 + 1e-15 * signs[i])
    assert moved != text
    assert compare_urdf(text, moved) == []


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_any_one_number_moved_by_1e_9_is_named(path) -> None:
    text = path.read_text()
    numbers = numbers_in_attributes(text)
    checked = 0
    for k, (_, _, token) in enumerate(numbers):
        if abs(float(token)) < 1e-4:  # 1e-9 of it would be below the absolute floor
            continue
        moved = perturb(text, lambda i, k=k: 1.0 + 1e-9 if i == k else 1.0)
        lines = compare_urdf(text, moved)
        assert len(lines) == 1, (token, lines)
        assert "committed" in lines[0] and "@" in lines[0] and lines[0].startswith("/robot/")
        checked += 1
    assert checked > 30


def test_structure_and_names_must_be_equal() -> None:
    text = (COMMITTED_DIR / "kr5_3r.urdf").read_text()
    cases = {
        "renamed link": (text.replace('<link name="link2">', '<link name="linkB">', 1), "link"),
        "renamed joint": (text.replace('name="joint3"', 'name="joint_3"', 1), "joint_3"),
        "joint type": (text.replace('type="revolute"', 'type="prismatic"', 1), "@type"),
        "element dropped": (re.sub(r"\s*<axis [^>]*/>", "", text, count=1), "children"),
        "element added": (text.replace("</robot>", '<link name="extra"/></robot>'), "children"),
        "attribute added": (text.replace("<axis ", '<axis a="1" ', 1), "@a"),
        "fewer numbers": (text.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0"/>', 1), "@xyz"),
    }
    for label, (changed, named) in cases.items():
        assert changed != text, label
        lines = compare_urdf(text, changed)
        assert lines and any(named in line for line in lines), (label, lines)
    assert compare_urdf(text, "<robot") == [
        "not a URDF (XML error: unclosed token: line 1, column 0)"
    ]


def test_tolerance_is_relative_with_an_absolute_floor() -> None:
    def one(a: float, b: float) -> bool:
        return compare_urdf(f'<robot x="{a!r}"/>', f'<robot x="{b!r}"/>') == []

    assert RELATIVE == 1e-12 and ABSOLUTE == 1e-14
    assert one(1.0, 1.0 + 0.9e-12) and not one(1.0, 1.0 + 1.1e-12)
    assert one(1e6, 1e6 * (1 + 0.9e-12)) and not one(1e6, 1e6 * (1 + 1.1e-12))
    assert one(0.0, 0.9e-14) and not one(0.0, 1.1e-14)
    assert not one(1.0, float("nan")) and one(float("inf"), float("inf"))  # inf: same text
    assert compare_urdf('<robot x="a b"/>', '<robot x="a  b"/>') != []  # text stays text
