"""The ``roastlab`` command line: a thin layer that parses, calls the library, formats.

One module per command or command group (:mod:`.simulate`, :mod:`.fit`, :mod:`.data`,
:mod:`.whatif`, :mod:`.transfer`, :mod:`.control`, :mod:`.fleet`, :mod:`.bench`, :mod:`.app`), each with its
``add_parsers(sub)`` and ``cmd_*`` functions; what they share is in :mod:`.common`.

Every :class:`~roastlab.errors.RoastlabError` becomes one line on stderr and exit code 2.
Every command plans its outputs first (:class:`roastlab.io.files.Outputs`): an output that is
one of the run's inputs, a folder or a special file is refused before any work, and the
outputs are written together at the end or not at all.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading

from ..errors import RoastlabError
from . import app, bench, control, data, fit, fleet, precompile, roaster, simulate, transfer, whatif
from .common import FIRST_COMPILE, Parser


def build_parser() -> argparse.ArgumentParser:
    from .. import __version__

    parser = Parser(
        prog="roastlab",
        description="Simulate, identify and validate the scalable coffee-roasting-chamber model "
        "(Procedia Computer Science 2021) on plants of any size. A fit is one model file (MODEL.json, "
        "from 'identify'); simulate and validate take it with --model and apply all of it the same way.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="examples:\n"
        "  roastlab reproduce                       the paper end to end on the shipped SYNTHETIC data\n"
        "  roastlab simulate --plant 120kg --inputs in.csv --out out.csv --plot out.png\n"
        "  roastlab identify --plant 120kg dataset-I/ --out model.json\n"
        "  roastlab validate --model model.json --plant 360kg dataset-V/\n"
        "  roastlab simulate --model model.json --inputs batch.csv --out pred.csv --tgi-offset 20\n"
        "  roastlab import roast.alog --map map.toml --out batch.csv\n"
        "  roastlab init roasts/*.alog --out myroaster   your roaster's map, plant, fit and fleet specs from its logs\n"
        "  roastlab fit-roaster myroaster roasts/*.alog  fit, hold out, report\n"
        "  roastlab app --data-dir roasts/               the page: curves, live what-if, transfer\n"
        "  roastlab bench                           speed against solve_ivp (about a minute)\n\n"
        "Every command: bad input gives one line naming the file and the problem, exit code 2.",
    )
    parser.add_argument("--version", action="version", version=f"roastlab {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    sub.required = True

    for module in (simulate, fit, roaster, data, whatif, transfer, control, fleet, bench, app, precompile):
        module.add_parsers(sub)
    return parser


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the program is, so that every output and temporary folder is
    cleaned up exactly as on Ctrl-C (a KeyboardInterrupt) instead of the process just ending."""


#: Packages whose Python code C calls back into while numba compiles (llvmlite's object-cache
#: callbacks, ``ExecutionEngine._raw_object_cache_notify``): an exception raised there is printed by
#: ctypes as "Exception ignored" and the program runs on. The rule takes any of the package's frames,
#: the wrappers around its C calls too: a signal held back there arrives 50 ms later. A SIGTERM that
#: lands there on a first run's compile was lost, and a 50,000-batch `fleet synthetic` ran on past the
#: test's minute (CI on 2026-12-01); Ctrl-C (SIGINT) goes through the same rule.
CALLBACK_PACKAGES = ("llvmlite",)
#: How soon a signal that landed in a callback is sent again [s].
RESEND_S = 0.05


def in_callback(frame, depth: int = 4) -> bool:
    """Whether ``frame`` or one of the ``depth`` frames under it runs code of :data:`CALLBACK_PACKAGES`."""
    for _ in range(depth):
        if frame is None:
            return False
        if any(f"{os.sep}{name}{os.sep}" in frame.f_code.co_filename for name in CALLBACK_PACKAGES):
            return True
        frame = frame.f_back
    return False


def _on_signal(signum, frame):
    """SIGTERM raises :class:`Terminated`, SIGINT a KeyboardInterrupt (Python's own rule), where the
    program is; inside a callback (:func:`in_callback`) the same signal is sent again instead."""
    if in_callback(frame):  # raised here it would be lost: the same signal again, once out of the callback
        timer = threading.Timer(RESEND_S, os.kill, (os.getpid(), signum))
        timer.daemon = True
        timer.start()
        return
    raise Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()


def _handled_signals() -> list[int]:
    """The signals :func:`_on_signal` takes: SIGTERM, and SIGINT where Python's own handler has it (a
    SIGINT the parent ignores, as a shell's background job does, stays ignored)."""
    if threading.current_thread() is not threading.main_thread():
        return []
    return [signal.SIGTERM] + ([signal.SIGINT] if signal.getsignal(signal.SIGINT) is signal.default_int_handler else [])


#: Commands that run no compiled code (and fit-roaster and compile, whose own progress says a first run's compile).
NOT_COMPILING = ("plant", "init", "import", "fit-roaster", "compile")


def first_run_note(command: str, stream=None) -> str | None:
    """The line a terminal gets before a command that compiles the model's kernels on a machine that has
    none in its cache yet (:func:`roastlab.sim.cache.cold`), a minute or two of nothing on screen
    otherwise; None off a terminal, for a command that compiles nothing, or once the cache holds kernels."""
    stream = sys.stderr if stream is None else stream
    if command in NOT_COMPILING or not (hasattr(stream, "isatty") and stream.isatty()):
        return None
    from ..sim.cache import cold

    if not cold():
        return None
    return (
        f"roastlab: a first run compiles the model's kernels first ({FIRST_COMPILE}, once; later runs "
        "load them; 'roastlab compile' does it ahead on every core)"
    )


def main(argv: list[str] | None = None) -> int:
    # the signals first: building the parser imports the numerical libraries (about half a second),
    # and a Ctrl-C there ends like one anywhere else, without a traceback
    previous = {signum: signal.signal(signum, _on_signal) for signum in _handled_signals()}
    command = ""
    try:
        from ..io.files import begin_run

        args = build_parser().parse_args(argv)
        command = f" {args.command}"
        begin_run()
        if note := first_run_note(args.command):
            print(note, file=sys.stderr)
        return int(args.func(args) or 0)
    except RoastlabError as exc:
        print(f"roastlab{command}: error: {_one_line(str(exc))}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        return _stopped(exc)
    except RuntimeError as exc:
        # Python 3.11 wraps what a class's __set_name__ raises in a RuntimeError, so a signal that lands
        # while an imported module defines a class (numba's, as the parser is built) arrives as its cause
        if not isinstance(exc.__cause__, KeyboardInterrupt):
            raise
        return _stopped(exc.__cause__)
    except BrokenPipeError:
        return 0
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _stopped(exc: KeyboardInterrupt) -> int:
    """The line and exit code of a command stopped by a signal: SIGTERM (:class:`Terminated`) or Ctrl-C."""
    if isinstance(exc, Terminated):
        print("roastlab: terminated", file=sys.stderr)
        return 128 + signal.SIGTERM
    print("roastlab: interrupted", file=sys.stderr)
    return 130


def _one_line(text: str, limit: int = 400) -> str:
    """An error message as one printable line of at most ``limit`` characters."""
    flat = "".join(c if c.isprintable() else "?" for c in text.replace("\n", " "))
    return flat if len(flat) <= limit else flat[: limit - 1] + "…"
