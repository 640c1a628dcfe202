"""Small file helpers: atomic writes that never leave a partial output behind."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from .errors import InputError


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder and a rename."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise InputError("output folder does not exist", path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    except OSError as exc:
        raise InputError(f"cannot write output ({exc.strerror})", path) from None
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise InputError(f"cannot write output ({exc.strerror})", path) from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_text(path: str | Path, text: str) -> None:
    atomic_write_bytes(path, text.encode("utf-8"))


def check_output_path(out: str | Path, inputs: list[str | Path]) -> Path:
    """Refuse an output path that is one of the inputs or lies in a missing folder."""
    out = Path(out)
    for src in inputs:
        try:
            if Path(src).exists() and out.exists() and os.path.samefile(src, out):
                raise InputError(f"output path is the same file as input {src}; refusing to overwrite an input", out)
        except OSError:
            pass
        if Path(src).resolve() == out.resolve():
            raise InputError(f"output path is the same file as input {src}; refusing to overwrite an input", out)
    folder = out.parent if str(out.parent) else Path(".")
    if not folder.is_dir():
        raise InputError("output folder does not exist", out)
    if not os.access(folder, os.W_OK):
        raise InputError("output folder is not writable", out)
    return out


#: Largest input file roastlab reads [bytes]; larger ones are refused before reading.
MAX_INPUT_BYTES = 200 * 1024 * 1024


def read_input_bytes(path: str | Path) -> bytes:
    """Read a user's input file, refusing missing files, folders and files over 200 MB."""
    path = Path(path)
    try:
        size = path.stat().st_size
    except FileNotFoundError:
        raise InputError("file not found", path) from None
    except OSError as exc:
        raise InputError(f"cannot read ({exc.strerror})", path) from None
    if path.is_dir():
        raise InputError("is a directory, expected a file", path)
    if size > MAX_INPUT_BYTES:
        raise InputError(f"file is {size / 1e6:.0f} MB, over the {MAX_INPUT_BYTES // (1024 * 1024)} MB limit", path)
    try:
        return path.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read ({exc.strerror})", path) from None


def read_input_text(path: str | Path) -> str:
    """An input file as text: UTF-8 (with or without BOM), else Latin-1 (old loggers)."""
    raw = read_input_bytes(path)
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        return raw.decode("latin-1")


def read_toml(path: str | Path) -> dict:
    """Parse a user's TOML file; every failure is one InputError naming the file."""
    import tomllib

    try:
        return tomllib.loads(read_input_text(path))
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"not valid TOML ({exc})", path) from None
