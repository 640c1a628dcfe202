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
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
from pathlib import Path

import numba
from numba.core import config

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
    rather than a stale one, when that folder cannot be written)."""

    def decorate(function):
        path = cache_dir()
        if path is None:
            return numba.njit(cache=False, **options)(function)
        with _cache_dir_set(path):  # numba picks the cache folder when the function is decorated
            return numba.njit(cache=True, **options)(function)

    if args and callable(args[0]):
        return decorate(args[0])
    return decorate
