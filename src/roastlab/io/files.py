"""The two guards every file passes through: bounded input reads and transactional outputs.

Inputs: :func:`read_input_bytes` opens without blocking, checks with ``fstat`` on the open
descriptor (not a racy ``stat`` of the name) that it is a regular file, and reads at most
:data:`MAX_INPUT_BYTES` + 1 bytes whatever the file claims, so a pipe, a device such as
``/dev/zero`` or a growing file can neither hang a run nor fill memory. Every file read is
remembered for the run (:func:`inputs_read`) so no output can overwrite it.

Outputs: :class:`Outputs` plans every output of a command before anything is written,
refuses one that is an input of the run, an existing non-regular file (a FIFO, a device) or
a folder, writes each to a temporary file in its own folder, and renames them all into
place only when every one was produced. A failure at any point leaves nothing behind.
"""

from __future__ import annotations

import collections
import hashlib
import math
import os
import stat
import tempfile
from pathlib import Path

from ..errors import InputError

#: Largest data file roastlab reads (batch CSV, roast log, Parquet, model file) [bytes]; a
#: larger one is refused without reading it all. Real logs are 20-100 kB and an hour at 10 Hz
#: is ~2 MB, so this leaves room while keeping the parse of the largest accepted file of each
#: format in bounded memory (tests/test_memory.py measures it under a hard cap).
MAX_INPUT_BYTES = 16 * 1024 * 1024
#: Largest configuration file (plant, map, fit spec, dataset index, scenario; TOML) [bytes].
CONFIG_MAX_BYTES = 1024 * 1024

_READ: dict[tuple[int, int], str] = {}  # (device, inode) -> path of every input read in this run
_RUN = {"active": False}
_DIGESTS: collections.OrderedDict[str, str] = collections.OrderedDict()  # path -> SHA-256 (provenance)
#: Most input digests kept for model-file provenance (the latest reads): a long-running process
#: that reads a fleet's logs must not grow with them (a fit reads far fewer).
MAX_DIGESTS = 16_384


def input_digest(path: str | Path) -> str | None:
    """SHA-256 (hex) of the bytes last read from ``path`` by :func:`read_input_bytes`, if any."""
    return _DIGESTS.get(str(path))


def inputs_read() -> list[str]:
    """Paths of every input file read since :func:`begin_run` (empty outside a run)."""
    return list(_READ.values()) if _RUN["active"] else []


def begin_run() -> None:
    """Start a command: from now on no output may replace any file it reads (the CLI calls it)."""
    _READ.clear()
    _RUN["active"] = True


def end_run() -> None:
    """Stop remembering inputs. A long-running server is not one command: it reads and writes files
    for many requests over its life (the page re-fits a roaster into the folder whose map it read
    for the last fit), so each of its writes names its own inputs (``Outputs(inputs)``) instead."""
    _READ.clear()
    _RUN["active"] = False


def as_path(value, what: str = "path") -> Path:
    """``value`` as a Path if it is one (a str or os.PathLike); else the project's own error."""
    if isinstance(value, Path):
        return value
    if isinstance(value, (str, os.PathLike)) and not isinstance(value, bool):
        return Path(value)
    raise InputError(f"{what} must be a file path (str or Path), got {type(value).__name__} {str(value)[:40]!r}")


def read_input_bytes(path: str | Path, limit: int = MAX_INPUT_BYTES) -> bytes:
    """Read a user's input file in bounded memory and time.

    Refuses missing files, folders, anything that is not a regular file (pipes, devices,
    sockets) and files over ``limit`` bytes (counted while reading, not taken from stat).
    """
    path = as_path(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0))
    except FileNotFoundError:
        raise InputError("file not found", path) from None
    except IsADirectoryError:
        raise InputError("is a directory, expected a file", path) from None
    except OSError as exc:
        raise InputError(f"cannot read ({exc.strerror})", path) from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise InputError("is a directory, expected a file", path)
        if not stat.S_ISREG(st.st_mode):
            raise InputError("not a regular file (a pipe, device or socket); give a file", path)
        if st.st_size > limit:  # a regular file's size is a lower bound: refuse early, without reading
            raise InputError(f"file is {st.st_size / 1e6:.0f} MB, over the {limit // (1024 * 1024)} MB limit", path)
        chunks, total = [], 0
        while True:
            chunk = os.read(fd, min(1 << 20, limit + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
            if total > limit:
                raise InputError(f"file grew over the {limit // (1024 * 1024)} MB limit while being read", path)
        if _RUN["active"]:  # only a command's outputs are checked against its inputs
            _READ[(st.st_dev, st.st_ino)] = str(path)
        data = b"".join(chunks)
        _DIGESTS[str(path)] = hashlib.sha256(data).hexdigest()
        _DIGESTS.move_to_end(str(path))
        if len(_DIGESTS) > MAX_DIGESTS:
            _DIGESTS.popitem(last=False)
        return data
    except OSError as exc:
        raise InputError(f"cannot read ({exc.strerror})", path) from None
    finally:
        os.close(fd)


def decode_text(raw: bytes, path: str | Path, what: str = "text") -> str:
    """Bytes of an input file as text: UTF-8 (with or without BOM), else Latin-1 (old loggers).

    A NUL byte in the first 4 KiB means a binary file given where text is expected.
    """
    if b"\x00" in raw[:4096]:
        raise InputError(f"binary file, expected {what}", path)
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        return raw.decode("latin-1")


def read_input_text(path: str | Path, what: str = "text", limit: int = MAX_INPUT_BYTES) -> str:
    """An input file as text (see :func:`read_input_bytes` and :func:`decode_text`)."""
    return decode_text(read_input_bytes(path, limit), path, what)


def finite_number(v, path, where: str) -> float:
    """A parsed value (JSON, TOML) as a finite float; else one InputError naming file and key."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise InputError(f"must be a number, got {str(v)[:40]!r}", path, where)
    try:
        x = float(v)
    except OverflowError:
        raise InputError("number out of range", path, where) from None
    if not math.isfinite(x):
        raise InputError(f"must be finite, got {v}", path, where)
    return x


def read_toml(path: str | Path) -> dict:
    """Parse a user's TOML file; every failure is one InputError naming the file."""
    import tomllib

    try:
        return tomllib.loads(read_input_text(path, "TOML text", CONFIG_MAX_BYTES))
    except InputError:  # missing, a folder, too big: the reader's own one line
        raise
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"not valid TOML ({str(exc)[:120]})", path) from None
    except (RecursionError, MemoryError, OverflowError, ValueError):
        raise InputError("TOML nested too deeply or with numbers out of range", path) from None


def _same_file(a: Path, b: Path) -> bool:
    try:
        if os.path.samefile(a, b):
            return True
    except OSError:
        pass
    return a.resolve() == b.resolve()


def umask_now() -> int:
    """The process umask (read without changing it for good)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


class Outputs:
    """The outputs of one command, written all together or not at all.

    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> with Outputs() as out:
    ...     _ = out.write_text(d / "a.csv", "x\\n")
    ...     _ = out.write_text(d / "b.json", "{}\\n")
    >>> sorted(p.name for p in d.iterdir())
    ['a.csv', 'b.json']
    """

    def __init__(self, inputs: list[str | Path] | None = None):
        self.inputs = [Path(p) for p in (inputs or []) if p]
        self._pending: list[tuple[Path, str]] = []  # (final path, temporary path)
        self._created: list[Path] = []  # folders made by :meth:`folder`, removed again if left empty

    def folder(self, path: str | Path, create: bool = True) -> Path:
        """Check (and with ``create`` make) a folder that outputs go into.

        Refuses a path that is an input of the run or that exists as anything but a folder (a
        file, a FIFO, a device). Folders made here are removed again, if still empty, when the
        outputs are discarded.
        """
        out = Path(path)
        self._refuse_inputs(out, "write into it")
        if out.exists() or out.is_symlink():
            if not out.is_dir():
                raise InputError("exists and is not a folder; give a folder for this output", out)
            return out
        if not create:
            raise InputError("not an existing folder (create it first)", out)
        missing = [out, *(p for p in out.parents if not p.exists())]
        try:
            out.mkdir(parents=True)
        except OSError as exc:
            raise InputError(f"cannot create output folder ({exc.strerror})", out) from None
        self._created += missing
        return out

    def _refuse_inputs(self, out: Path, doing: str) -> None:
        """Refuse ``out`` if it is an input of this run or a sidecar of one (``<input>.<anything>``
        beside it: a database's write-ahead log, its temporary files)."""
        for src in self.inputs + [Path(p) for p in inputs_read()]:
            if src.exists() and _same_file(src, out):
                raise InputError(f"is an input of this run ({src}); refusing to {doing}", out)
            if src.is_file() and out.name.startswith(src.name + ".") and _same_file(src.parent, out.parent):
                raise InputError(f"is a sidecar file of an input of this run ({src}); refusing to write it", out)

    def check(self, path: str | Path) -> Path:
        """Refuse an output that is an input or a sidecar of one (a database's ``.wal``, its
        temporary files: ``<input>.<anything>`` beside it), a symbolic link (the final rename
        would replace the link itself, e.g. ``/dev/stdout``), a folder or a special file, or
        that sits in a missing folder."""
        out = Path(path)
        if str(out) == "" or out.name in ("", ".", ".."):
            raise InputError("not a file name", out)
        self._refuse_inputs(out, "overwrite an input")
        if out.is_symlink():
            raise InputError(
                f"is a symbolic link (to {os.readlink(out)}); refusing to replace a link: give the file's own path", out
            )
        if out.is_dir():
            raise InputError("is a directory; give a file name", out)
        if out.exists():
            mode = os.stat(out).st_mode
            if not stat.S_ISREG(mode):
                raise InputError("exists and is not a regular file (a pipe or device); refusing to replace it", out)
        folder = out.parent if str(out.parent) else Path(".")
        if not folder.is_dir():
            raise InputError("output folder does not exist", out)
        if not os.access(folder, os.W_OK):
            raise InputError("output folder is not writable", out)
        return out

    def write_bytes(self, path: str | Path, data: bytes) -> Path:
        """Write ``data`` to a temporary file beside ``path``; it becomes ``path`` on commit."""
        out = self.check(path)
        folder = out.parent if str(out.parent) else Path(".")
        try:
            fd, tmp = tempfile.mkstemp(prefix=f".{out.name[:60]}.", suffix=".tmp", dir=folder)
        except OSError as exc:
            raise InputError(f"cannot write output ({exc.strerror})", out) from None
        self._pending.append((out, tmp))
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
            os.chmod(tmp, 0o666 & ~umask_now())
        except OSError as exc:
            raise InputError(f"cannot write output ({exc.strerror})", out) from None
        return out

    def write_text(self, path: str | Path, text: str) -> Path:
        return self.write_bytes(path, text.encode("utf-8"))

    def commit(self) -> None:
        """Re-check every output against the inputs read meanwhile, then rename all into place."""
        try:
            for out, _ in self._pending:
                self.check(out)
            for out, tmp in self._pending:
                os.replace(tmp, out)
        except OSError as exc:
            raise InputError(f"cannot write output ({exc.strerror})", self._pending[0][0]) from None
        finally:
            self.discard()

    def discard(self) -> None:
        """Remove every temporary file not yet renamed into place, and folders left empty."""
        for _, tmp in self._pending:
            Path(tmp).unlink(missing_ok=True)
        self._pending = []

    def _remove_created_folders(self) -> None:
        for folder in sorted(self._created, key=lambda p: len(p.parts), reverse=True):
            try:
                folder.rmdir()  # only when empty
            except OSError:
                pass
        self._created = []

    def __enter__(self) -> Outputs:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            try:
                self.commit()
            except BaseException:
                self._remove_created_folders()
                raise
        else:
            self.discard()
            self._remove_created_folders()


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write one output through the output guard (temporary file, then rename)."""
    with Outputs() as out:
        out.write_bytes(path, data)


def atomic_write_text(path: str | Path, text: str) -> None:
    atomic_write_bytes(path, text.encode("utf-8"))
