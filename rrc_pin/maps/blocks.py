"""A map's partial results on disk: written as its blocks complete, read back to resume.

The folder ``<out>/blocks/`` holds:

- ``manifest.json``: what map the blocks belong to (its definition and fingerprint, a
  sha256 of that definition); a folder holding another map's manifest, or blocks without
  one, is refused before anything is written (:class:`~rrc_pin.errors.ForeignMap`);
- ``part-<first>-<last>.npz``: the sparse result of one task (blocks ``first..last``), each
  written to a temporary name and renamed, so a part is whole or absent;
- ``state.npz``: a checkpoint, the sparse sum of the parts folded into it and the list of
  their blocks, rewritten the same way every so many parts; the parts it holds are then
  deleted (a part left by a stop between the two is recognised by its blocks and skipped).

Resuming reads the checkpoint and the parts, and leaves only the other blocks to compute:
since the reductions are exact, the resumed map is bit-identical to an uninterrupted one.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import ForeignMap
from rrc_pin.maps.voxels import VoxelStats
from rrc_pin.solvers.maps.batch import Fields, Sparse

FORMAT = 1
"""Version of the folder's layout."""
_PART = re.compile(r"part-(\d+)-(\d+)\.npz$")


def fingerprint(definition: dict[str, Any]) -> str:
    """sha256 of a map's definition as canonical JSON (sorted keys)."""
    text = json.dumps(definition, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


@dataclass
class BlockStore:
    """The partial results of one map in ``folder``.

    Attributes:
        folder: ``<out>/blocks``.
        definition: The map's definition (what the manifest records).
        fields: The statistics' columns.
        size: Voxels of the grid.
    """

    folder: Path
    definition: dict[str, Any]
    fields: Fields
    size: int

    @property
    def key(self) -> str:
        """The map's fingerprint."""
        return fingerprint(self.definition)

    def check(self) -> None:
        """Refuse a folder that holds another map's blocks; change nothing.

        Raises:
            ForeignMap: The manifest is another map's, unreadable, or missing while parts or
                a checkpoint are there.
        """
        manifest = self.folder / "manifest.json"
        if manifest.exists():
            try:
                found = json.loads(manifest.read_text())
            except (OSError, ValueError) as exc:
                raise ForeignMap(self.folder, f"unreadable manifest ({exc})") from exc
            if found.get("fingerprint") != self.key:
                theirs = found.get("definition", {})
                diff = sorted(
                    k for k in set(theirs) | set(self.definition)
                    if theirs.get(k) != self.definition.get(k)
                )  # fmt: skip
                raise ForeignMap(self.folder, "another map's blocks (differs in: "
                                 + ", ".join(diff or ["its fingerprint"]) + ")")  # fmt: skip
        elif self.folder.exists() and any(self.folder.iterdir()):
            raise ForeignMap(self.folder, "files without a manifest")

    def create(self) -> None:
        """Create the folder and write the manifest (after :meth:`check`)."""
        self.folder.mkdir(parents=True, exist_ok=True)
        manifest = self.folder / "manifest.json"
        if not manifest.exists():
            text = json.dumps(
                {"format": FORMAT, "fingerprint": self.key, "definition": self.definition},
                indent=1, sort_keys=True,
            )  # fmt: skip
            _atomic_write(manifest, text.encode())

    def load(self) -> tuple[VoxelStats, set[int]]:
        """The statistics and blocks already computed (checkpoint, then the other parts)."""
        stats = VoxelStats.empty(self.size, self.fields)
        done: set[int] = set()
        state = self.folder / "state.npz"
        if state.exists():
            with np.load(state) as z:
                stats.merge(_sparse(z))
                done.update(int(b) for b in z["blocks"])
        for path, blocks in self.parts():
            if set(blocks) <= done:  # folded into the checkpoint before a stop
                continue
            with np.load(path) as z:
                stats.merge(_sparse(z))
            done.update(blocks)
        return stats, done

    def parts(self) -> list[tuple[Path, list[int]]]:
        """The part files and their blocks."""
        out = []
        for path in sorted(self.folder.glob("part-*.npz")):
            m = _PART.match(path.name)
            if m:
                out.append((path, list(range(int(m[1]), int(m[2]) + 1))))
        return out

    def write_part(self, blocks: list[int], part: Sparse) -> Path:
        """Write one task's result (blocks ``blocks``, consecutive)."""
        path = self.folder / f"part-{blocks[0]:09d}-{blocks[-1]:09d}.npz"
        _atomic_npz(path, _arrays(part))
        return path

    def checkpoint(self, stats: VoxelStats, done: set[int]) -> None:
        """Fold everything into ``state.npz``; delete the parts it now holds."""
        arrays = _arrays(stats.sparse())
        arrays["blocks"] = np.array(sorted(done), dtype=np.int64)
        _atomic_npz(self.folder / "state.npz", arrays)
        for path, blocks in self.parts():
            if set(blocks) <= done:
                path.unlink(missing_ok=True)


def _arrays(part: Sparse) -> dict[str, npt.NDArray[Any]]:
    return {
        "keys": part.keys, "count": part.count, "dirs": part.dirs, "fmax": part.fmax,
        "isum": part.isum, "imin": part.imin, "outside": np.array(part.outside, np.int64),
    }  # fmt: skip


def _sparse(z: Any) -> Sparse:
    return Sparse(
        z["keys"], z["count"], z["dirs"], z["fmax"], z["isum"], z["imin"], int(z["outside"])
    )


def _atomic_write(path: Path, data: bytes) -> None:
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def _atomic_npz(path: Path, arrays: dict[str, npt.NDArray[Any]]) -> None:
    tmp = path.with_name(f".{path.stem}.tmp{os.getpid()}.npz")
    np.savez(tmp, **arrays)  # type: ignore[arg-type]
    os.replace(tmp, path)
