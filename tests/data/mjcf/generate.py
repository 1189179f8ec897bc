"""The MJCF files beside this script, written by MuJoCo from the project's own URDFs.

Run: ``python tests/data/mjcf/generate.py`` (writes them; needs ``pip install mujoco``),
``python tests/data/mjcf/generate.py --check`` (compares, as numbers within 1e-12).
MuJoCo's URDF importer reads each ``urdf/<arm>.urdf`` with its fixed links kept
(``fusestatic`` off: the tool frame stays a body) and ``MjSpec.to_xml`` writes the MJCF.
MuJoCo prints numbers with 6 significant digits (``%g``), so the MJCF carries the URDF's
geometry to about 1e-6 (tests/test_loading.py measures it).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
URDF = HERE.parents[2] / "urdf"
NUMBER = re.compile(r"-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")


def mjcf_of(urdf: Path) -> str:
    """The MJCF text MuJoCo writes for the URDF at ``urdf``."""
    import mujoco

    spec = mujoco.MjSpec.from_file(str(urdf))
    spec.compiler.fusestatic = False
    spec.compile()
    text: str = spec.to_xml()
    return text


def same(a: str, b: str, tol: float = 1e-12) -> bool:
    """Whether two texts are the same but for their numbers, which agree within ``tol``."""
    if NUMBER.sub("#", a) != NUMBER.sub("#", b):
        return False
    x, y = NUMBER.findall(a), NUMBER.findall(b)
    return all(
        abs(float(p) - float(q)) <= tol * max(1.0, abs(float(q))) for p, q in zip(x, y, strict=True)
    )


def main(check: bool) -> int:
    """Write (or with ``check`` compare) one MJCF per committed URDF; 1 where one differs."""
    status = 0
    for urdf in sorted(URDF.glob("*.urdf")):
        out = HERE / f"{urdf.stem}.xml"
        text = mjcf_of(urdf)
        if check:
            ok = out.is_file() and same(text, out.read_text())
            print(f"{out.name}: {'same' if ok else 'DIFFERS'}")
            status |= not ok
        else:
            out.write_text(text)
            print(f"written {out}")
    return status


if __name__ == "__main__":
    sys.exit(main("--check" in sys.argv[1:]))
