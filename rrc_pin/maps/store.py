"""A map as a Zarr store: arrays in chunks of 16^3, metadata, the sha256 of every file.

Layout of ``<path>`` (a Zarr group, zarr-python 2 or 3, each in its default format):

- attributes: ``rrc_pin_map`` (the layout's version), ``grid`` (start, shape, voxel),
  ``meta`` (arm, frame, samples, seed, voxel, block size, statistics, quanta, conditions,
  versions, timings);
- arrays (nx, ny, nz): ``count``, ``directions`` (uint64 bits), the maxima, sums and minima
  of :mod:`rrc_pin.maps.voxels`;
- ``chain/``: the arm's chain (placements, joint kinds and limits), so the witnesses can be
  drawn again from the store alone;
- ``checksums.json``: the sha256 of every other file (each chunk, each metadata file),
  sealed (:mod:`rrc_pin.maps.checksums`).

:func:`save_map` writes the store beside its place and moves it in whole. :func:`load_map`
checks every file against ``checksums.json`` before Zarr reads any: a changed, missing or
added file raises :class:`~rrc_pin.errors.CorruptStore` naming it, never a wrong value.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import CorruptStore, InvalidInput, MissingExtra
from rrc_pin.maps import checksums
from rrc_pin.maps.capability_map import CapabilityMap
from rrc_pin.maps.voxels import Grid, VoxelStats
from rrc_pin.solvers.maps.batch import Chain, Fields

LAYOUT = 2
"""Version of the store's layout (attribute ``rrc_pin_map``): 2 adds ``checksums.json``."""
CHUNK = 16
"""Voxels along each axis of a chunk."""
CHECKSUMS = "checksums.json"
"""The store's list of file digests."""
_CHAIN = ("rot", "trans", "kind", "lower", "upper", "bounded")
_ZARR_ROOTS = ("zarr.json", ".zgroup")
"""A Zarr group's own metadata file (format 3, format 2)."""


def _zarr() -> Any:
    try:
        import zarr
    except ImportError as exc:
        raise MissingExtra("maps", ["zarr"]) from exc
    return zarr


def write_array(group: Any, name: str, data: npt.NDArray[Any], chunks: tuple[int, ...]) -> None:
    """Create array ``name`` in ``group`` holding ``data`` (zarr-python 2 or 3)."""
    chunks = tuple(min(c, max(s, 1)) for c, s in zip(chunks, data.shape, strict=True))
    if hasattr(group, "create_array"):  # zarr-python 3
        arr = group.create_array(name, shape=data.shape, dtype=data.dtype, chunks=chunks)
    else:  # zarr-python 2
        arr = group.create_dataset(name, shape=data.shape, dtype=data.dtype, chunks=chunks)
    arr[...] = data


def save_map(m: CapabilityMap, path: str | os.PathLike[str]) -> Path:
    """Write ``m`` to the Zarr store ``path`` (a map store there is replaced); returns it.

    Raises:
        InvalidInput: ``path`` is a file, or a folder holding something else than a map.
    """
    zarr = _zarr()
    path = Path(path)
    if path.exists() and not (path.is_dir() and (_is_store(path) or not any(path.iterdir()))):
        raise InvalidInput("path", f"{path} exists and is not a map store: not replaced")
    new, old = (path.with_name(f".{path.name}.{what}{os.getpid()}") for what in ("new", "old"))
    shutil.rmtree(new, ignore_errors=True)
    group = zarr.open_group(str(new), mode="w")
    group.attrs.update(
        {"rrc_pin_map": LAYOUT, "grid": m.grid.to_dict(), "meta": _jsonable(m.meta)}
    )
    cube = (CHUNK, CHUNK, CHUNK)
    for name, col in m.stats.arrays().items():
        write_array(group, name, np.ascontiguousarray(col).reshape(m.grid.shape), cube)
    chain = group.create_group("chain")
    for name in _CHAIN:
        data = np.asarray(getattr(m.chain, name))
        write_array(chain, name, data, data.shape or (1,))
    (new / CHECKSUMS).write_bytes(checksums.seal({"files": checksums.tree(new)}))
    if path.exists():
        os.replace(path, old)
    os.replace(new, path)
    shutil.rmtree(old, ignore_errors=True)
    return path


def verify_store(path: str | os.PathLike[str]) -> None:
    """Check every file of the store ``path`` against its ``checksums.json``.

    Raises:
        InvalidInput: ``path`` is not a map store (names the argument ``path``).
        CorruptStore: A file changed, missing or added since the store was written (named,
            with the way to repair the store).
    """
    path = Path(path)
    if not path.is_dir() or not _is_store(path):
        raise InvalidInput("path", f"{path} is not a map store of rrc-pin")
    listing = path / CHECKSUMS
    doc = checksums.unseal(listing.read_bytes()) if listing.is_file() else None
    files = doc.get("files") if doc is not None else None
    if not isinstance(files, dict):
        why = "damaged" if listing.exists() else "missing (a store of an earlier rrc-pin?)"
        raise CorruptStore(path, {CHECKSUMS: why}, _repair(path))
    bad = checksums.damaged(path, files, frozenset({CHECKSUMS}))
    if bad:
        raise CorruptStore(path, bad, _repair(path))


def _is_store(path: Path) -> bool:
    return any((path / name).exists() for name in (CHECKSUMS, *_ZARR_ROOTS))


def _repair(path: Path) -> str:
    """How to repair the store ``path`` (written by a map run into ``path.parent``)."""
    folder = path.parent
    blocks = (folder / "blocks").is_dir()
    return (
        f"run the map that wrote it again with the same arguments and out={folder} (a cell's "
        f"map: the cell's folder; rrc-pin map ... --out): "
        + ("it computes again only the blocks of damaged files in its blocks folder and "
           "writes the store anew" if blocks else
           "its blocks folder is gone, so the whole map is computed again")
    )  # fmt: skip


def load_map(path: str | os.PathLike[str]) -> CapabilityMap:
    """Read a map written by :func:`save_map`, every file checked first.

    Raises:
        InvalidInput: ``path`` is not such a store (names the argument ``path``).
        CorruptStore: A file of the store is damaged (named; nothing is read).
    """
    zarr = _zarr()
    verify_store(path)
    try:
        group = zarr.open_group(str(path), mode="r")
        attrs = dict(group.attrs)
        if attrs.get("rrc_pin_map") != LAYOUT:
            raise KeyError("rrc_pin_map")
        grid = Grid.from_dict(attrs["grid"])
        meta = dict(attrs["meta"])
        fields = Fields(tuple(meta.get("conditions", ())))
        names = ("count", "directions", *fields.fmax, *fields.isum, *fields.imin)
        arrays = {n: np.asarray(group[n][...]).reshape(-1) for n in names}
        c = group["chain"]
        chain = Chain(**{n: np.asarray(c[n][...]) for n in _CHAIN})
    except (KeyError, OSError, ValueError, TypeError) as exc:
        raise InvalidInput("path", f"{path} is not a map store of rrc-pin ({exc!r})") from exc
    stats = VoxelStats.from_arrays(arrays, fields)
    stats.outside = int(meta.get("samples_outside", 0))
    return CapabilityMap(grid, stats, chain, meta)


def _jsonable(value: Any) -> Any:
    """``value`` with numpy scalars and arrays turned into JSON values."""
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    return value
