"""What every command of the ``roastlab`` command line shares: the parser class, argument types, the
progress bar, the JSON and figure outputs, and the model, batch and initial-state options."""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from pathlib import Path

from ..errors import InputError, ParameterError, RoastlabError

MODEL_HELP = "fitted model file from 'roastlab identify' (roastlab-model/1; a THETA.json of roastlab 0.1 also loads)"


#: A value that starts with a minus and a digit: a signed change such as ``-1@5:00`` or ``-2.5``. No option
#: of roastlab starts so, but argparse takes any dash-led word but a plain number for an option and
#: ``--heater -1@5:00`` failed with "expected one argument".
SIGNED_VALUE = re.compile(r"^-\.?\d")


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors (exit 2) instead of a usage block, and a signed value taken as
    the value of the option before it (``--heater -1@5:00`` read as ``--heater=-1@5:00``)."""

    def error(self, message: str):  # noqa: D102
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")

    def parse_known_args(self, args=None, namespace=None):  # noqa: D102
        args = list(sys.argv[1:] if args is None else args)
        return super().parse_known_args(self._attach_signed_values(args), namespace)

    def _attach_signed_values(self, args: list[str]) -> list[str]:
        """``OPTION VALUE`` as ``OPTION=VALUE`` where the option takes one value and the value is
        signed (:data:`SIGNED_VALUE`); everything after ``--`` as it is."""
        out: list[str] = []
        i = 0
        while i < len(args):
            word = args[i]
            if word == "--":
                return out + args[i:]
            action = self._option_string_actions.get(word)
            takes_one = action is not None and action.nargs is None and word.startswith("--")
            if takes_one and i + 1 < len(args) and SIGNED_VALUE.match(args[i + 1]):
                out.append(f"{word}={args[i + 1]}")
                i += 2
                continue
            out.append(word)
            i += 1
        return out


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


#: The suffixes a temperature on the command line may carry, and the unit each names.
TEMPERATURE_SUFFIXES = (("°F", "F"), ("°C", "C"), ("F", "F"), ("C", "C"))


def temperature_arg(name: str, delta: bool = False):
    """A temperature option [degC]: a number, or one with its unit after it (``400F``, ``204C``, ``400 °F``)
    for a roaster who reads degF, converted here (:func:`roastlab.metrics.profile.celsius_of`).
    ``delta``: a difference or an offset (``+36F`` is 20 degC), converted without the 32 degF."""

    def parse(text: str) -> float:
        from ..metrics.profile import celsius_delta_of, celsius_of

        bare, unit = text.strip(), "C"
        for suffix, named in TEMPERATURE_SUFFIXES:
            if bare.upper().endswith(suffix.upper()):
                bare, unit = bare[: -len(suffix)].strip(), named
                break
        v = float_arg(name)(bare if bare else text)
        return float(celsius_delta_of(v, unit) if delta else celsius_of(v, unit))

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


#: How long a first run's compile takes, as the first-run note and ``compile --help`` say it (measured:
#: 150-163 s for a first fit-roaster on 2 cores, 2026-11-28/29; docs/your-roaster.md).
FIRST_COMPILE = "1-3 minutes on a small machine"

#: Work shorter than this shows no progress [s].
PROGRESS_DELAY_S = 2.0
#: Off a terminal (a log file, CI) long work writes one plain progress line at most this often [s].
PROGRESS_LINE_S = 60.0


def progress(desc: str):
    """A progress callback ``update(done, total, text)`` drawing a tqdm bar on a terminal, shown only
    for work over :data:`PROGRESS_DELAY_S`. ``total`` 0 opens a stage of unknown length (``text`` says
    what it is: "fitting 8 logs"), its elapsed time kept ticking until the next call, so that work
    which reports nothing for a while (a first run's compile) is seen to be alive. Off a terminal
    (stderr redirected to a file) there is no bar to redraw: :func:`progress_lines` writes a plain line
    instead, at most every :data:`PROGRESS_LINE_S`."""
    if not (hasattr(sys.stderr, "isatty") and sys.stderr.isatty()):
        return progress_lines(desc)
    import threading
    import time

    from tqdm import tqdm

    state: dict = {}

    def close() -> None:
        if (ticker := state.pop("ticker", None)) is not None:
            ticker.set()
        if (bar := state.pop("bar", None)) is not None:
            bar.close()

    def tick(bar, stop: threading.Event) -> None:  # redraw the open stage's clock once a second
        while not stop.wait(1.0):
            if time.monotonic() - state["since"] >= PROGRESS_DELAY_S:
                bar.refresh()
                bar.last_print_t = bar._time()  # drawn: its close clears the line (tqdm keys that on this)

    def update(done: int, total: int, text: str = "") -> None:
        bar = state.get("bar")
        if total == 0:  # a stage of unknown length
            close()
            bar = state["bar"] = tqdm(
                desc=f"{desc}: {text}",
                file=sys.stderr,
                delay=PROGRESS_DELAY_S,
                leave=False,
                bar_format="{desc} [{elapsed}]",
            )
            state["since"], stop = time.monotonic(), threading.Event()
            state["ticker"] = stop
            threading.Thread(target=tick, args=(bar, stop), daemon=True).start()
            return
        if bar is None or bar.total != total or done < bar.n:  # the first call, or the next stage of the work
            close()
            bar = state["bar"] = tqdm(total=total, desc=desc, file=sys.stderr, delay=PROGRESS_DELAY_S, leave=False)
        bar.set_postfix_str(text[:60], refresh=False)
        bar.update(done - bar.n)
        if done >= total:
            close()

    return update


def progress_lines(desc: str):
    """:func:`progress` off a terminal: a plain line ``desc: done/total text [elapsed]`` on stderr at a call
    :data:`PROGRESS_LINE_S` or more after the start and after the last line, so that a run of many minutes
    redirected to a log (``make real-roaster``'s comparisons, an hour of fits) says that it is alive and how
    far it has got, and a short one writes nothing."""
    import time

    from tqdm import tqdm

    start = last = time.monotonic()

    def update(done: int, total: int, text: str = "") -> None:
        nonlocal last
        now = time.monotonic()
        if now - last < PROGRESS_LINE_S:
            return
        last = now
        count = f" {done}/{total}" if total else ""
        note = f" {text}" if text else ""  # a line, not a bar's postfix: said whole
        print(f"{desc}:{count}{note} [{tqdm.format_interval(now - start)}]", file=sys.stderr, flush=True)

    return update


def json_text(doc) -> str:
    """A JSON output file's text: NumPy values made plain, NaN refused, one space indent."""
    from ..io.modelfile import jsonable

    return json.dumps(jsonable(doc), indent=1, allow_nan=False) + "\n"


def check_targets(outputs, *targets, plot=None) -> None:
    """Refuse a run's output targets before any work: each given path (:meth:`Outputs.check`: not
    an input, a link, a folder ...) and the figure's suffix (``plot``, one Matplotlib can write)."""
    from ..report.figures import check_figure_path

    for target in (*targets, plot):
        if target:
            outputs.check(target)
    if plot:
        check_figure_path(plot)


def write_json_and_plot(out, args, doc, figure, **options) -> None:
    """Write ``--json`` (``doc``) and ``--plot`` (``figure.plot``, given ``options``) through ``out`` when
    asked for."""
    if args.json:
        out.write_text(args.json, json_text(doc))
    if args.plot:
        figure.plot(args.plot, outputs=out, **options)


def write_artisan_files(out, args, result) -> None:
    """Write ``--alog`` (``result.alog_text()``, an Artisan background) and ``--alarms``
    (``result.alarms_text()``, an Artisan alarm set) through ``out`` when asked for: what ``whatif``
    and ``transfer`` hand a roaster to roast against."""
    if args.alog:
        out.write_text(args.alog, result.alog_text())
    if args.alarms:
        out.write_text(args.alarms, result.alarms_text())


def say(notes) -> None:
    for note in notes:
        print(f"note: {note}", file=sys.stderr)


# ----------------------------------------------------------------------------- shared options
def level_arg(text: str) -> float:
    """argparse type of --band: a number (float_arg) that is a band level (evaluate.bands.check_level)."""
    from ..evaluate.bands import check_level

    try:
        return check_level(float_arg("--band")(text))
    except ParameterError as exc:
        raise argparse.ArgumentTypeError(exc.problem) from None


def add_starts_option(p: argparse.ArgumentParser, per: str = "") -> None:
    """``--starts N``: the starts a global search chooses for a local polish (``per``: e.g. " per fit")."""
    from ..model.parameters import N_STARTS

    p.add_argument(
        "--starts",
        type=count_arg("--starts", 1, 100),
        default=N_STARTS,
        help=f"starts chosen for a local polish{per} (default {N_STARTS}); a start inside the basin of an optimum "
        "already found is skipped, and a polish that reaches one stops there",
    )


def add_band_option(p: argparse.ArgumentParser, what: str, where: str) -> None:
    """``--band [LEVEL]``: ``what`` of this level (default BAND_LEVEL), from the model file's
    parameter covariance and roast-to-roast spread (:mod:`roastlab.evaluate.bands`); ``where``
    says where it shows."""
    from ..evaluate.bands import BAND_LEVEL

    p.add_argument(
        "--band",
        type=level_arg,
        nargs="?",
        const=BAND_LEVEL,
        metavar="LEVEL",
        help=f"also {what} of this level (default {BAND_LEVEL:g}), from the model file's parameter covariance and "
        f"roast-to-roast spread: {where}",
    )


def add_units_option(p: argparse.ArgumentParser, help: str) -> None:
    """``--units {C,F}`` (:data:`roastlab.metrics.profile.DISPLAY_UNITS`): the unit temperatures are
    shown in; ``help`` says where, and what the default is."""
    from ..metrics.profile import DISPLAY_UNITS

    p.add_argument("--units", choices=DISPLAY_UNITS, help=help)


def add_model_options(p: argparse.ArgumentParser, with_model: bool = True) -> None:
    if with_model:
        p.add_argument("--model", "--theta", dest="model", metavar="MODEL.json", help=MODEL_HELP)
        p.add_argument("--hgm", type=float_arg("--hgm"), help="gas-metal coefficient [kW/(m2 K)]; overrides the model")
        p.add_argument("--hbm", type=float_arg("--hbm"), help="metal-bean coefficient [kW/(m2 K)]; overrides the model")
        p.add_argument(
            "--pbm", type=float_arg("--pbm"), help="bean-metal contact fraction in (0, 1); overrides the model"
        )
    add_initial_options(p)
    p.add_argument(
        "--moisture",
        choices=("schwartzberg", "printed"),
        help="moisture law, eq. 13 (default: the model's, else schwartzberg)",
    )
    p.add_argument(
        "--hold", choices=("linear", "zoh"), help="input hold between samples (default: the model's, else linear)"
    )
    p.add_argument(
        "--bed",
        type=bed_arg,
        metavar="LAWS",
        help="bed laws, e.g. 'contact=wall,probe=tumbling' or 'paper' (roastlab.model.bed; "
        "default: the model's or the fit spec's, else the paper's)",
    )


def bed_arg(text: str):
    """argparse type of --bed: the laws, or the parse error as argparse's one line."""
    from ..model.bed import BedLaws

    try:
        return BedLaws.parse(text)
    except RoastlabError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def variant_arg(text: str):
    """argparse type of compare-models' --variant: bed laws and parameter overrides
    (:class:`roastlab.workflows.compare.Variant`), or the parse error as argparse's one line."""
    from ..workflows.compare import Variant

    try:
        return Variant.parse(text)
    except RoastlabError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_initial_options(p: argparse.ArgumentParser) -> None:
    """--tb0, --tm0, --x0: the charge state (read back by :func:`initial_changes`)."""
    from ..model.quantities import default

    p.add_argument(
        "--tb0",
        type=temperature_arg("--tb0"),
        help=f"initial bean temperature [degC; 72F for degF] (default: the model's, else {default('Tb0_C'):g})",
    )
    p.add_argument(
        "--tm0",
        type=temperature_arg("--tm0"),
        help="initial drum metal temperature, the preheat [degC; 400F for degF] (default: the model's or the log's, "
        f"else {default('Tm0_C'):g})",
    )
    p.add_argument(
        "--x0",
        type=float_arg("--x0"),
        help=f"initial moisture [kg/kg dry] (default: the model's, else {default('X0'):g})",
    )


def initial_changes(args) -> dict:
    from ..model.limits import check_value

    changes = {}
    for opt, name in (("tb0", "Tb0_C"), ("tm0", "Tm0_C"), ("x0", "X0")):
        v = getattr(args, opt, None)
        if v is not None:
            changes[name] = check_value(name, v, f"--{opt}")
    return changes


def failed_fit_status(failed: str | None, path) -> int:
    """The exit status of a command that fitted: 0, or 1 with one line naming the model file
    ``path``, why the fit failed (:attr:`FitResult.failed`) and what to try (each check of
    :func:`roastlab.metrics.profile.implausible_states` says it)."""
    if not failed:
        return 0
    print(f"error: {path}: the fit failed, {failed}", file=sys.stderr)
    return 1


def warn_if_failed(model, path) -> None:
    """One warning line when the model file's fit failed (:attr:`FittedModel.failed`)."""
    if model.failed:
        print(
            f"warning: {path}: this model's fit failed ({model.failed}); do not trust its predictions", file=sys.stderr
        )


def model_from_args(args, plant_spec):
    """The model of a command: --model (or the paper's theta*), with --hgm/--hbm/--pbm and variants applied."""
    from ..workflows.model import FittedModel, load_model

    if getattr(args, "model", None):
        model = load_model(args.model)
        warn_if_failed(model, args.model)
    else:
        if plant_spec is None:
            raise InputError("--plant is required without --model", "command line")
        model = FittedModel.paper(plant_spec)
    overrides = {
        k: getattr(args, o)
        for k, o in (("hgm", "hgm"), ("hbm", "hbm"), ("Pbm", "pbm"))
        if getattr(args, o, None) is not None
    }
    if overrides:
        model = model.with_values(**overrides)
        try:
            model.theta  # noqa: B018 - validates the overridden theta
        except RoastlabError as exc:
            raise InputError(str(exc), "command line") from None
    for key in ("moisture", "hold"):
        if getattr(args, key, None):
            model.doc[key] = getattr(args, key)
            setattr(model, key, getattr(args, key))
    if getattr(args, "bed", None) is not None:
        model.bed = args.bed
    return model


def parse_assignments(items, option: str, ranged: bool):
    """Parse ``name=value`` (or ``name=lo:hi`` when ``ranged``) options."""
    out = {}
    for item in items or []:
        name, sep, text = item.partition("=")
        if not sep or not name:
            raise InputError(
                f"{option} expects NAME={'LO:HI' if ranged else 'VALUE'}, got {item[:60]!r}", "command line"
            )
        if ranged:
            out[name.strip()] = range_arg(text, f"{option} {name[:30]}")
            continue
        try:
            value = float(text)
        except (ValueError, OverflowError):
            raise InputError(f"{option} {name[:30]}: cannot read {text[:40]!r} as a number", "command line") from None
        if not math.isfinite(value):
            raise InputError(f"{option} {name[:30]}: values must be finite", "command line")
        out[name.strip()] = value
    return out


def range_arg(text: str, label: str) -> tuple[float, float]:
    """``LO:HI`` as two finite floats with LO < HI; ``label`` names the option in errors."""
    lo, sep, hi = text.partition(":")
    try:
        if not sep:
            raise ValueError
        value = (float(lo), float(hi))
    except (ValueError, OverflowError):
        raise InputError(f"{label}: cannot read {text[:40]!r} as LO:HI", "command line") from None
    if not all(math.isfinite(v) for v in value):
        raise InputError(f"{label}: values must be finite", "command line")
    if not value[0] < value[1]:
        raise InputError(f"{label}: inverted or empty bounds {value[0]:g}:{value[1]:g} (need LO < HI)", "command line")
    return value


def load_batches(args, model=None):
    """The BATCH arguments as batches, and the plant spec to use (--plant, else the dataset's)."""
    from ..io.batch import expand_batch_args
    from ..io.importers.mapping import reads_as_log
    from ..workflows.model import load_log

    if getattr(args, "map", None) or (
        model is not None and model.column_map is not None and not any(Path(p).is_dir() for p in args.batches)
    ):
        cmap = args.map if args.map else model.column_map
        if not args.map and not any(reads_as_log(p, cmap) for p in args.batches):  # batch CSVs
            batches, dataset_plant = expand_batch_args(args.batches, require_Ta=True)
        else:
            batches, dataset_plant = [load_log(p, cmap) for p in args.batches], None
        from ..workflows.roaster import grouped_notes

        for line in grouped_notes({b.source: b.notes for b in batches}):  # one line for a note said alike on many
            print(f"warning: {line}", file=sys.stderr)
    else:
        batches, dataset_plant = expand_batch_args(args.batches, require_Ta=True)
    return batches, args.plant or dataset_plant


def fit_inputs(args) -> list:
    return [*args.batches, args.map, getattr(args, "spec", None), args.plant, getattr(args, "model", None)]


def weights_arg(items) -> dict:
    """``--weight OUTPUT=W`` options as checked output weights (errors name the command line); W may be
    ``residual`` for an output other than Ta (set from a first fit's residuals, as in a fit spec)."""
    from ..fit.identify import check_weights
    from ..model.parameters import RESIDUAL_REFERENCE, RESIDUAL_REFERENCE_WHY, RESIDUAL_WEIGHT, by_residuals

    pairs = [(name.strip(), w.strip()) for name, _, w in (i.partition("=") for i in items or [])]
    if (RESIDUAL_REFERENCE, RESIDUAL_WEIGHT) in pairs:
        raise InputError(f"--weight {RESIDUAL_REFERENCE}={RESIDUAL_WEIGHT}: {RESIDUAL_REFERENCE_WHY}", "command line")
    residual = {name: w for name, w in pairs if by_residuals(name, w)}
    given = parse_assignments([f"{n}={w}" for n, w in pairs if n not in residual], "--weight", False)
    try:
        check_weights({**given, **dict.fromkeys(residual, 1.0)})
    except ParameterError as exc:
        raise InputError(f"--weight: {exc.problem}", "command line") from None
    return {**given, **residual}


FIT_HELP = "batch CSVs (time_s,Gg_kg_s,Tgi_C,Ta_C) and/or dataset folders with a dataset.toml; raw logs with --map"


def add_batch_options(p, baseline_help: str) -> None:
    """Options shared by identify and validate: the batches, their plant, a map, the baseline."""
    p.add_argument("batches", nargs="+", metavar="BATCH", help=FIT_HELP)
    p.add_argument("--plant", help="plant preset or PLANT.toml (default: the model's plant, else the dataset's)")
    p.add_argument(
        "--map",
        metavar="MAP.toml",
        help="the BATCH arguments are raw logs (Artisan .alog/.csv, CSV, Parquet) read with this column map",
    )
    p.add_argument("--baseline", choices=("first-order",), help=baseline_help)


def read_inputs(path, map_path, model):
    """A batch CSV, or a raw log read with --map or with the map the model was fitted with."""
    from ..workflows.model import load_log, load_log_for

    return load_log(path, map_path) if map_path else load_log_for(path, model)
