"""A map's partial results on disk: written as its blocks complete, checked when read back.

The folder ``<out>/blocks/`` holds:

- ``manifest.json``: what map the blocks belong to (its definition and fingerprint, a
  sha256 of that definition) and the folds written, sealed (:mod:`rrc_pin.maps.checksums`:
  any changed byte is seen); a folder holding another map's manifest, or another map's
  blocks, is refused before anything is written (:class:`~rrc_pin.errors.ForeignMap`);
- ``part-<first>-<last>-<sha>.npz``: the sparse result of one task (blocks ``first..last``);
- ``fold-<n>-<sha>.npz``: every so many parts reduced into one (exactly), the parts then
  deleted (a part left by a stop between the two is recognised by its blocks and skipped).
  Each fold holds a bounded number of blocks, so a damaged one costs only those.

Every data file holds the map's fingerprint and its blocks, carries the sha256 of its own
bytes in its name (the first 32 hex digits), and is written to a temporary name and renamed
(whole or absent); its bytes are checked before they are parsed.

Resuming (:meth:`BlockStore.load`) reads the manifest, the folds and the parts, and repairs
what it finds damaged, with a warning naming each file: a data file whose bytes differ from
its name, or that holds another map's blocks, is set aside (renamed ``<name>.damaged``); a
fold the manifest lists but the folder lacks is reported missing; a damaged or missing
manifest is written again. The blocks of the files lost are computed again, and only those:
since the reductions are exact, the repaired map is bit-identical to an uninterrupted one.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import re
import warnings
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import ForeignMap
from rrc_pin.maps import checksums
from rrc_pin.maps.voxels import VoxelStats
from rrc_pin.solvers.maps.batch import Fields, Sparse

FORMAT = 2
"""Version of the folder's layout (2: checksums, folds)."""
MANIFEST = "manifest.json"
DAMAGED = ".damaged"
"""Suffix of a data file set aside."""
_PART = re.compile(r"part-(\d{9})-(\d{9})-([0-9a-f]{32})\.npz$")
_FOLD = re.compile(r"fold-(\d{6})-([0-9a-f]{32})\.npz$")


def fingerprint(definition: dict[str, Any]) -> str:
    """sha256 of a map's definition as canonical JSON (sorted keys)."""
    text = json.dumps(definition, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


class Data(NamedTuple):
    """A data file's content: whose blocks, which, and their sparse result."""

    key: str
    blocks: list[int]
    sparse: Sparse


@dataclass
class BlockStore:
    """The partial results of one map in ``folder``.

    Attributes:
        folder: ``<out>/blocks``.
        definition: The map's definition (what the manifest records).
        fields: The statistics' columns.
        size: Voxels of the grid.
        damaged: The files found damaged or missing by :meth:`load` (names).
    """

    folder: Path
    definition: dict[str, Any]
    fields: Fields
    size: int
    damaged: list[str] = field(default_factory=list)
    _folds: list[str] = field(default_factory=list)
    _folded: set[int] = field(default_factory=set)

    @property
    def key(self) -> str:
        """The map's fingerprint."""
        return fingerprint(self.definition)

    def check(self) -> None:
        """Refuse a folder that holds another map's blocks; change nothing.

        Raises:
            ForeignMap: The manifest is another map's (or another layout's), or, without a
                whole manifest, a file is not a data file or a whole one is another map's.
        """
        manifest = self._manifest()
        if manifest is not None:
            if manifest.get("fingerprint") != self.key:
                theirs = manifest.get("definition", {})
                diff = sorted(
                    k for k in set(theirs) | set(self.definition)
                    if theirs.get(k) != self.definition.get(k)
                )  # fmt: skip
                raise ForeignMap(self.folder, "another map's blocks (differs in: "
                                 + ", ".join(diff or ["its fingerprint"]) + ")")  # fmt: skip
            if manifest.get("format") != FORMAT:
                raise ForeignMap(self.folder, f"blocks of layout {manifest.get('format')}")
            return
        if not self.folder.is_dir():
            return
        for path in self._files():
            if not (_PART.match(path.name) or _FOLD.match(path.name)):
                raise ForeignMap(self.folder, "files without a manifest")
            data = _read(path)
            if data is not None and data.key != self.key:
                raise ForeignMap(self.folder, "another map's blocks")

    def load(self) -> tuple[VoxelStats, set[int]]:
        """The statistics and blocks already computed, the damaged files set aside.

        Creates the folder and the manifest (after :meth:`check`); see the module docstring
        for what is repaired. Each file found damaged or missing is named in a
        ``RuntimeWarning`` and in :attr:`damaged`.
        """
        self.folder.mkdir(parents=True, exist_ok=True)
        manifest = self._manifest()
        listed = set(manifest["folds"]) if manifest is not None else set()
        stats = VoxelStats.empty(self.size, self.fields)
        done: set[int] = set()
        self.damaged, self._folds = [], []
        folds = sorted(p for p in self.folder.iterdir() if _FOLD.match(p.name))
        for name in sorted(listed - {p.name for p in folds}):
            self._report(name, "missing: its blocks are computed again")
        for path in folds:
            if self._take(path, stats, done):
                self._folds.append(path.name)
        self._folded = set(done)
        for path, blocks in self.parts():
            if set(blocks) <= self._folded:  # folded before a stop
                path.unlink(missing_ok=True)
            else:
                self._take(path, stats, done)
        if manifest is None or listed != set(self._folds):
            if manifest is None and (self.folder / MANIFEST).exists():
                self._report(MANIFEST, "damaged: written again")
            elif manifest is None and done:
                self._report(MANIFEST, "missing: written again")
            self._write_manifest()
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
        return self._write(f"part-{blocks[0]:09d}-{blocks[-1]:09d}", blocks, part)

    def fold(self) -> None:
        """Reduce the parts written since the last fold into one fold file; delete them.

        A part found damaged is set aside: its blocks, already merged by the run, are
        computed again only by a later resume.
        """
        taken: list[tuple[Path, Data]] = []
        for path, blocks in self.parts():
            if set(blocks) <= self._folded:
                path.unlink(missing_ok=True)
                continue
            data = _read(path)
            if data is None or data.key != self.key:
                self._set_aside(path)
            else:
                taken.append((path, data))
        if not taken:
            return
        blocks = sorted(b for _, data in taken for b in data.blocks)
        sparse = VoxelStats.combine([data.sparse for _, data in taken], self.fields)
        seq = 1 + max((_number(n) for n in self._folds), default=0)
        self._folds.append(self._write(f"fold-{seq:06d}", blocks, sparse).name)
        self._folded.update(blocks)
        self._write_manifest()
        for path, _ in taken:
            path.unlink(missing_ok=True)

    def _manifest(self) -> dict[str, Any] | None:
        """The manifest if whole (its seal holds), else None (missing or damaged)."""
        path = self.folder / MANIFEST
        return checksums.unseal(path.read_bytes()) if path.is_file() else None

    def _write_manifest(self) -> None:
        doc = {"format": FORMAT, "fingerprint": self.key, "definition": self.definition,
               "folds": sorted(self._folds)}  # fmt: skip
        _atomic_write(self.folder / MANIFEST, checksums.seal(doc))

    def _files(self) -> list[Path]:
        """The folder's files but the manifest, temporary files and files set aside."""
        return [p for p in sorted(self.folder.iterdir()) if p.name != MANIFEST
                and not p.name.startswith(".") and not p.name.endswith(DAMAGED)]  # fmt: skip

    def _take(self, path: Path, stats: VoxelStats, done: set[int]) -> bool:
        """Merge a data file into ``stats`` if whole, this map's and new; else set it aside."""
        data = _read(path)
        if data is None or data.key != self.key or not done.isdisjoint(data.blocks):
            self._set_aside(path)
            return False
        stats.merge(data.sparse)
        done.update(data.blocks)
        return True

    def _set_aside(self, path: Path) -> None:
        os.replace(path, path.with_name(path.name + DAMAGED))
        self._report(path.name, f"damaged: set aside as {path.name}{DAMAGED}, its blocks "
                     "computed again")  # fmt: skip

    def _report(self, name: str, what: str) -> None:
        self.damaged.append(name)
        warnings.warn(f"{self.folder / name} {what}", RuntimeWarning, stacklevel=2)

    def _write(self, stem: str, blocks: list[int], sparse: Sparse) -> Path:
        buffer = io.BytesIO()
        arrays: dict[str, npt.NDArray[Any]] = {
            "map": np.array(self.key), "blocks": np.array(blocks, dtype=np.int64),
            "keys": sparse.keys, "count": sparse.count, "dirs": sparse.dirs,
            "fmax": sparse.fmax, "isum": sparse.isum, "imin": sparse.imin,
            "outside": np.array(sparse.outside, np.int64),
        }  # fmt: skip
        np.savez(buffer, **arrays)  # type: ignore[arg-type]
        data = buffer.getvalue()
        path = self.folder / f"{stem}-{checksums.digest(data)[:32]}.npz"
        _atomic_write(path, data)
        return path


def _number(name: str) -> int:
    """The number of a fold file."""
    m = _FOLD.match(name)
    return int(m[1]) if m else 0


def _read(path: Path) -> Data | None:
    """A data file's content, or None if its bytes differ from the digest in its name."""
    m = _PART.match(path.name) or _FOLD.match(path.name)
    try:
        raw = path.read_bytes()
    except OSError:
        return None
    if m is None or checksums.digest(raw)[:32] != m[m.re.groups]:
        return None
    try:
        with np.load(io.BytesIO(raw)) as z:
            sparse = Sparse(z["keys"], z["count"], z["dirs"], z["fmax"], z["isum"], z["imin"],
                            int(z["outside"]))  # fmt: skip
            return Data(str(z["map"]), [int(b) for b in z["blocks"]], sparse)
    except (OSError, ValueError, KeyError, zipfile.BadZipFile):  # whole, but not ours
        return None


def _atomic_write(path: Path, data: bytes) -> None:
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    tmp.write_bytes(data)
    os.replace(tmp, path)
