"""What every command of the ``roastlab`` command line shares: the parser class, argument types,
the progress bar and the JSON and figure outputs."""

from __future__ import annotations

import argparse
import json
import math
import sys

MODEL_HELP = "fitted model file from 'roastlab identify' (roastlab-model/1; a THETA.json of roastlab 0.1 also loads)"


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors (exit 2) instead of a usage block."""

    def error(self, message: str):  # noqa: D102
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")


def float_arg(name: str):
    def parse(text: str) -> float:
        try:
            v = float(text)
        except (ValueError, OverflowError):
            raise argparse.ArgumentTypeError(f"{name} must be a number, got {text[:40]!r}") from None
        if not math.isfinite(v):
            raise argparse.ArgumentTypeError(f"{name} must be finite, got {text[:40]!r}")
        return v

    return parse


def seed_arg(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--seed must be an integer, got {text[:40]!r}") from None
    if not 0 <= v < 2**32:
        raise argparse.ArgumentTypeError(f"--seed must be in 0..{2**32 - 1}, got {text[:40]}")
    return v


def count_arg(name: str, lo: int, hi: int):
    def parse(text: str) -> int:
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be an integer, got {text[:40]!r}") from None
        if not lo <= v <= hi:
            raise argparse.ArgumentTypeError(f"{name} must be in {lo}..{hi}, got {v}")
        return v

    return parse


def progress(desc: str):
    """A progress callback drawing a tqdm bar on a terminal, shown only for work over ~2 s."""
    from tqdm import tqdm

    state: dict = {}

    def update(done: int, total: int, text: str = "") -> None:
        bar = state.get("bar")
        if bar is None:
            bar = state["bar"] = tqdm(total=total, desc=desc, file=sys.stderr, delay=2.0, disable=None, leave=False)
        bar.set_postfix_str(text[:60], refresh=False)
        bar.update(done - bar.n)
        if done >= total:
            bar.close()

    return update


def json_text(doc) -> str:
    """A JSON output file's text: NumPy values made plain, NaN refused, one space indent."""
    from ..io.modelfile import jsonable

    return json.dumps(jsonable(doc), indent=1, allow_nan=False) + "\n"


def write_json_and_plot(out, args, doc, figure) -> None:
    """Write ``--json`` (``doc``) and ``--plot`` (``figure.plot``) through ``out`` when asked for."""
    if args.json:
        out.write_text(args.json, json_text(doc))
    if args.plot:
        figure.plot(args.plot, outputs=out)
