"""A map as a Zarr store: one 3-D array per statistic, chunks of 16^3, metadata attributes.

Layout of ``<path>`` (a Zarr group, zarr-python 2 or 3, each in its default format):

- attributes: ``rrc_pin_map`` (the layout's version), ``grid`` (start, shape, voxel),
  ``meta`` (arm, frame, samples, seed, voxel, block size, statistics, quanta, conditions,
  versions, timings);
- arrays (nx, ny, nz): ``count``, ``directions`` (uint64 bits), the maxima, sums and minima
  of :mod:`rrc_pin.maps.voxels`;
- ``chain/``: the arm's chain (placements, joint kinds and limits), so the witnesses can be
  drawn again from the store alone.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput, MissingExtra
from rrc_pin.maps.capability_map import CapabilityMap
from rrc_pin.maps.voxels import Grid, VoxelStats
from rrc_pin.solvers.maps.batch import Chain, Fields

LAYOUT = 1
"""Version of the store's layout (attribute ``rrc_pin_map``)."""
CHUNK = 16
"""Voxels along each axis of a chunk."""
_CHAIN = ("rot", "trans", "kind", "lower", "upper", "bounded")


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
    """Write ``m`` to the Zarr store ``path``; returns the path.

    A map store already at ``path`` is replaced; anything else there (a file, a folder that
    is not a map store: the current folder for ``"."``) is refused, never deleted (Zarr's
    ``mode="w"`` empties the folder it is given).

    Raises:
        InvalidInput: ``m`` is not a :class:`CapabilityMap`, or ``path`` not a file name, or
            something other than a map store is there (each named).
    """
    if not isinstance(m, CapabilityMap):
        raise InvalidInput("m", f"expected a CapabilityMap, got {type(m).__name__}")
    if not isinstance(path, (str, os.PathLike)) or not os.fspath(path):
        raise InvalidInput("path", f"expected a folder name (str or os.PathLike), got {path!r}")
    zarr = _zarr()
    path = Path(path)
    if path.exists() and not _is_map_store(path):
        raise InvalidInput("path", f"{str(path)!r} exists and is not a map store of rrc-pin:"
                           " it is not replaced (name a new folder, or delete it yourself)")
    group = zarr.open_group(str(path), mode="w")
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
    return path


def _is_map_store(path: Path) -> bool:
    """Whether ``path`` is a folder holding a map store (its ``rrc_pin_map`` attribute)."""
    if not path.is_dir():
        return False
    try:
        return bool(_zarr().open_group(str(path), mode="r").attrs.get("rrc_pin_map") == LAYOUT)
    except (KeyError, OSError, ValueError, TypeError):
        return False


def load_map(path: str | Path) -> CapabilityMap:
    """Read a map written by :func:`save_map`.

    Raises:
        InvalidInput: ``path`` is not such a store (names the argument ``path``).
    """
    zarr = _zarr()
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
