"""The compiled kernels' decorator, and a machine-code cache that cannot break the library.

``@kernel`` is ``numba.njit(cache=True)`` (``@kernel(nogil=True)`` adds ``nogil``), the one
decorator of every compiled kernel of the project; it keeps the function's signature for the
type checker. Under ``NUMBA_DISABLE_JIT=1`` it returns the function itself, as numba does.

Where the machine code is cached, first writable place first:

1. numba's own places: ``NUMBA_CACHE_DIR`` if set, else the module's ``__pycache__``, else
   numba's cache in the user's home (``~/.cache/numba``);
2. a private folder of this user in the temporary directory, ``rrc-pin-numba-<uid>``
   (created with mode 0700 and used only while owned by the user and closed to others: the
   cache holds pickles, which another user must not be able to plant), handed to numba
   through ``numba.config.CACHE_DIR`` while the kernel is decorated;
3. nowhere: the kernel is compiled in memory in each process.

So a read-only install with a read-only home still imports and runs. A cache entry that
cannot be read back (truncated, empty, random bytes, unreadable, a directory in its place)
is a miss: the kernel is compiled again and the new entry written over the old where the
folder is writable (a damaged index emptied first); where it is not, caching is off for
that kernel in this process. Nothing the cache holds can make an import or a call fail.

numba offers no public hook on reading a cache entry (a damaged one raises from inside
``Dispatcher.compile``, whatever pickle or LLVM raise), so three of its internals are used:
the class ``numba.core.caching.FunctionCache`` (subclassed, its ``load_overload`` and
``save_overload`` guarded), the dispatcher's ``_cache`` attribute (set to it, as
``Dispatcher.enable_caching`` does) and the cache file's ``_source_stamp``. tests/test_compiled.py
pins them.

numba stamps an entry with its function's source file only (modification time and size), but
a kernel calls kernels of other modules (the collision pass calls the narrow phase, the damper
rows, ...), whose machine code is compiled into the caller's entry: changed, they would leave
the caller's entry stale. The stamp here is that of every file of this package the kernel's
module reaches through its globals (kernels and modules it imports, and theirs), so an entry
is compiled again when any of them changes.

A bit flipped inside an entry's machine code that still unpickles is not detected: numba
keeps no checksum of its entries.
"""

from __future__ import annotations

import functools
import os
import stat
import sys
import tempfile
import threading
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any, TypeVar, cast, overload

import numba
from numba.core import caching

F = TypeVar("F", bound=Callable[..., Any])
numba_config: Any = numba.config
"""numba's settings (``DISABLE_JIT``, ``CACHE_DIR``), untyped to the type checker."""
njit: Any = numba.njit
FunctionCache: Any = caching.FunctionCache

PRIVATE_PREFIX = "rrc-pin-numba-"
"""Name of the fallback cache folder in the temporary directory, before the user id."""
_SETTING = threading.Lock()
"""Held while ``numba.config.CACHE_DIR`` is changed (modules may be imported in threads)."""


PACKAGE = __name__.rpartition(".")[0]
"""The package whose modules a kernel's stamp covers (this module's)."""


class GuardedCache(FunctionCache):  # type: ignore[misc]  # an untyped base
    """numba's cache of one function, where a damaged entry is a miss and never an error.

    Stamped with the sources the function's module reaches (module docstring).
    """

    def __init__(self, py_func: Callable[..., Any]) -> None:
        super().__init__(py_func)
        cache_file = getattr(self, "_cache_file", None)
        if cache_file is not None:
            cache_file._source_stamp = source_stamp(sys.modules[py_func.__module__])

    def load_overload(self, sig: Any, target_context: Any) -> Any:
        """The cached compile result of ``sig``, or None (not cached, or not readable).

        None makes numba compile ``sig`` and save it: over the damaged data file, where the
        index is whole.
        """
        try:
            return super().load_overload(sig, target_context)
        except Exception:  # a damaged entry raises whatever unpickling or LLVM raise
            return None

    def save_overload(self, sig: Any, data: Any) -> None:
        """Write the compile result of ``sig``.

        numba reads the function's index before writing it: a damaged index is emptied and
        the write tried once more; a folder that refuses both turns caching off.
        """
        try:
            super().save_overload(sig, data)
        except Exception:  # a damaged index, or an unwritable folder
            try:
                self.flush()
                super().save_overload(sig, data)
            except Exception:  # read-only, or a directory where a file should be
                self.disable()


def source_stamp(module: ModuleType) -> tuple[tuple[str, float, int], ...]:
    """(module, modification time, size of its file) of ``module`` and the modules it reaches.

    Every module of :data:`PACKAGE` reached through the globals of ``module`` and of those
    modules (kernels called, modules imported), sorted by name.
    """
    reached: dict[str, ModuleType] = {}
    todo = [module]
    while todo:
        current = todo.pop()
        reached[current.__name__] = current
        for value in vars(current).values():
            name = value.__name__ if isinstance(value, ModuleType) else getattr(
                value, "__module__", None)  # fmt: skip
            inside = isinstance(name, str) and (name == PACKAGE or name.startswith(PACKAGE + "."))
            if inside and name not in reached and name in sys.modules:
                todo.append(sys.modules[name])
    stamps = []
    for name, reached_module in sorted(reached.items()):
        path = getattr(reached_module, "__file__", None)
        if path:
            st = os.stat(path)
            stamps.append((name, st.st_mtime, st.st_size))
    return tuple(stamps)


@overload
def kernel(function: F, /) -> F: ...
@overload
def kernel(*, nogil: bool = False) -> Callable[[Callable[..., Any]], Any]: ...


def kernel(function: Callable[..., Any] | None = None, /, *, nogil: bool = False) -> Any:
    """``numba.njit(cache=True)`` with the cache policy of this module.

    Args:
        function: The kernel (``@kernel``); None for ``@kernel(nogil=True)``.
        nogil: Release the GIL while the kernel runs (threads run kernels side by side).

    Returns:
        The numba dispatcher (the function itself under ``NUMBA_DISABLE_JIT=1``), typed as
        ``function``; or, when ``function`` is None, the decorator (whose dispatcher is
        untyped, as numba's ``njit(...)`` is: the maps' kernels are typed by their wrappers).
    """

    def compile_(f: F) -> F:
        dispatcher = njit(nogil=nogil)(f)
        if not numba_config.DISABLE_JIT:
            cache = function_cache(f)
            if cache is not None:
                dispatcher._cache = cache
        return cast(F, dispatcher)

    return compile_ if function is None else compile_(function)


def inlined(function: F) -> F:
    """A kernel compiled into each compiled caller, at numba's IR (``inline="always"``).

    For the compiled tick's glue between its kernels. A kernel that calls another links the
    callee's machine code into its own and LLVM optimises it again there, so along a chain of
    compiled wrappers the kernels at its end are optimised once per link; inlined, the glue is
    optimised once, in the tick's entry (docs/api.md, "One compiled pass per tick"); likewise a
    kernel's private steps called from it alone. Called from Python, it compiles and caches as
    any kernel.
    """
    dispatcher = njit(inline="always")(function)
    if not numba_config.DISABLE_JIT:
        cache = function_cache(function)
        if cache is not None:
            dispatcher._cache = cache
    return cast(F, dispatcher)


def function_cache(f: Callable[..., Any]) -> GuardedCache | None:
    """The cache of ``f`` in the first writable place (module docstring), or None."""
    with _SETTING:
        try:
            return GuardedCache(f)
        except (RuntimeError, OSError):  # numba's "cannot cache function ...: no locator"
            pass
        folder = private_folder()
        if folder is None:
            return None
        saved = numba_config.CACHE_DIR
        numba_config.CACHE_DIR = str(folder)
        try:
            return GuardedCache(f)
        except (RuntimeError, OSError):
            return None
        finally:
            numba_config.CACHE_DIR = saved


@functools.cache
def private_folder() -> Path | None:
    """The user's fallback cache folder in the temporary directory, or None if unusable.

    Refused unless it is a real directory (not a link), owned by the user, closed to group
    and others.
    """
    uid = os.getuid() if hasattr(os, "getuid") else None
    path = Path(tempfile.gettempdir()) / f"{PRIVATE_PREFIX}{uid if uid is not None else 'user'}"
    try:
        path.mkdir(mode=0o700, exist_ok=True)
        st = path.lstat()
    except OSError:
        return None
    private = stat.S_ISDIR(st.st_mode) and not st.st_mode & 0o077
    if not private or (uid is not None and st.st_uid != uid):
        return None
    return path
