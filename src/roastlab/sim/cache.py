"""Compiled code that cannot go stale: numba's disk cache keyed on the source it compiles.

numba keys a cached kernel on the file it is defined in, but the kernels compile the right-hand
side of :mod:`roastlab.model.rhs` inline: after an edit to ``rhs.py`` alone, ``kernels.py``'s
cache would still load the old equations. :func:`compiled` is ``numba.njit(cache=True)`` with
the cache in a folder of its own per hash of every source file the compiled code is built from
(:data:`COMPILED_SOURCES`) and of numba's version, so any edit there compiles afresh and an
unchanged checkout reuses its cache.

The folder is ``$XDG_CACHE_HOME/roastlab/numba/<hash>`` (``~/.cache`` when unset);
``NUMBA_CACHE_DIR``, when the user sets it, is honoured as the parent instead. Only roastlab's
kernels use it: other numba code in the same process keeps numba's own cache settings.

Inside it a kernel is filed by its module's place in the package (``sim/``, ``fit/``), not by the
absolute path of its file, which numba's own locators hash into the folder's name: the same sources
installed elsewhere (a fresh clone, the wheel, a second virtual environment) load what another
copy compiled instead of compiling for minutes again (:class:`SourceLocator`).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
from pathlib import Path

import numba
import numpy as np
from numba.core import caching, config

#: Subpackages whose files the compiled code is built from: the kernels (sim, fit) and the
#: right-hand side and layout they compile in (model). tests/test_cache.py checks every module
#: that compiles code lies inside them.
COMPILED_SOURCES = ("model", "sim", "fit")
_ROOT = Path(__file__).resolve().parents[1]


@functools.cache
def source_hash() -> str:
    """16 hex digits of SHA-256 over the compiled subpackages' ``.py`` files (paths and bytes)
    and numba's version."""
    h = hashlib.sha256(numba.__version__.encode())
    for sub in COMPILED_SOURCES:
        for path in sorted((_ROOT / sub).rglob("*.py")):
            h.update(str(path.relative_to(_ROOT)).encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()[:16]


@functools.cache
def cache_dir() -> Path | None:
    """The folder of this source's compiled kernels, created; None if it cannot be written."""
    parent = os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "roastlab", "numba"
    )
    path = Path(parent) / source_hash()
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return path if os.access(path, os.W_OK) else None


def cold() -> bool:
    """No kernel compiled into this source's cache folder yet (or no folder to cache in): the next run
    compiles them first, a minute or more on a small machine, and later runs load them."""
    folder = cache_dir()
    return folder is None or not any(folder.rglob("*.nbi"))


class SourceLocator(caching._CacheLocator):
    """numba's cache locator for roastlab's kernels: the folder :func:`cache_dir` plus the module's
    folder inside the package, and the module file's bytes as its stamp.

    numba's own locators file a kernel under a hash of its file's absolute path, so the same sources at
    another path compiled afresh; :func:`cache_dir`'s name already keys on every compiled source, so the
    path adds nothing. The stamp is the file's SHA-256, as numba 0.68's own (older releases stamped the
    file's modification time and size, and the time differs in every clone)."""

    def __init__(self, py_func, py_file: str, cache_path: Path):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = str(cache_path)

    def get_cache_path(self) -> str:
        return self._cache_path

    def get_source_stamp(self) -> str:
        return hashlib.sha256(Path(self._py_file).read_bytes()).hexdigest()

    def get_disambiguator(self) -> str:
        return str(self._lineno)

    @classmethod
    def from_function(cls, py_func, py_file):
        """This locator for a function defined in roastlab's compiled sources, None for any other
        (numba's own locators take those)."""
        folder = cache_dir()
        try:
            module_dir = Path(py_file).resolve().parent.relative_to(_ROOT)  # e.g. sim
        except (OSError, ValueError):
            return None
        if folder is None or not module_dir.parts or module_dir.parts[0] not in COMPILED_SOURCES:
            return None
        self = cls(py_func, py_file, folder / module_dir)
        try:
            self.ensure_cache_path()
        except OSError:
            return None
        return self


_IMPL = getattr(caching, "CacheImpl", None) or caching._CacheImpl  # older numba names it _CacheImpl
if SourceLocator not in _IMPL._locator_classes:
    _IMPL._locator_classes.insert(0, SourceLocator)


@contextlib.contextmanager
def _cache_dir_set(path: Path):
    before = config.CACHE_DIR
    config.CACHE_DIR = str(path)
    try:
        yield
    finally:
        config.CACHE_DIR = before


def compiled(*args, **options):
    """``numba.njit(cache=True, **options)`` with the cache in :func:`cache_dir` (no disk cache,
    rather than a stale one, when that folder cannot be written). numba's own folder setting points
    there too while a kernel is decorated, so that where ``NUMBA_CACHE_LOCATOR_CLASSES`` replaces
    :class:`SourceLocator` with numba's user-provided locator, the kernels still key on the sources."""

    def decorate(function):
        path = cache_dir()
        if path is None:
            return numba.njit(cache=False, **options)(function)
        with _cache_dir_set(path):  # numba picks the locator when the function is decorated
            return numba.njit(cache=True, **options)(function)

    if args and callable(args[0]):
        return decorate(args[0])
    return decorate


try:  # numba's dispatcher keys its compiled versions on this (C, about 0.15 us a value)
    from numba._dispatcher import compute_fingerprint as _fingerprint
except ImportError:  # pragma: no cover - numba without it

    def _fingerprint(a):
        """What numba's type of ``a`` depends on: an array's dtype, dimensions, layout, writability and
        alignment, another value's Python type."""
        if isinstance(a, np.ndarray):
            flags = a.flags
            return (a.dtype.str, a.ndim, flags.c_contiguous, flags.f_contiguous, flags.writeable, flags.aligned)
        return type(a)


_ENTRIES: dict = {}


def literal_entry(dispatcher, args: tuple, literal: int):
    """The compiled entry point of ``dispatcher`` for ``args``, whose entry ``literal`` (a whole
    number) is a compile-time constant of the code: loaded from the disk cache or compiled once for
    that value, and called as ``entry(*args)``. Asked for directly, rather than by calling the
    dispatcher, which would first compile for a value that is merely a number and only then, told by
    ``numba.literally``, for the constant: a failing attempt that costs as long as compiling. The
    entry is kept per value and per the arguments' :func:`_fingerprint` (typing the arguments anew
    took 130 us a call, a quarter of a sensitivity run of dataset-I; the fingerprints 3 us)."""
    from numba.core import types

    try:
        fingerprint = (id(dispatcher), int(args[literal]), *(_fingerprint(a) for a in args))
    except (TypeError, ValueError):  # a value numba's fingerprint does not cover: typed anew
        fingerprint = None
    entry = _ENTRIES.get(fingerprint)
    if entry is None:
        sig = tuple(types.literal(int(a)) if i == literal else numba.typeof(a) for i, a in enumerate(args))
        found = dispatcher.overloads.get(sig)
        entry = dispatcher.compile(sig) if found is None else found.entry_point
        if fingerprint is not None:
            _ENTRIES[fingerprint] = entry
    return entry
