"""Every output option of every subcommand, pointed at each input of its run, is refused.

The parser is walked, so a new subcommand or option cannot slip past: each option must be
classified below as an input, an output or a plain value, and each subcommand needs a
working invocation in :data:`RUNS`. For each output option and each input file of the run
the test points the output at the input, and checks exit code 2, one line naming the file,
and the input byte-for-byte unchanged; then at a sidecar of the first input (``<input>.wal``,
as a database's write-ahead log), at a FIFO, at a symbolic link and at ``/dev/null``
(existing non-regular files), which must be refused the same way.
"""

import argparse
import hashlib
import os
import shutil
from pathlib import Path

import pytest

from roastlab.cli import build_parser
from test_bad_input import GOOD_ALOG, GOOD_ROWS, HEADER, PLANT

#: Options that name a file or folder the command writes.
OUTPUTS = {"--out", "--json", "--plot", "--predictions", "--save", "--alog", "--alarms", "--db"}
#: Options that name a file or folder the command reads.
INPUTS = {"--model", "--theta", "--plant", "--inputs", "--map", "--spec", "--data", "batches", "log", "plant"}
INPUTS |= {"laws"}  # compile: fit specs or model files whose laws to compile
INPUTS |= {
    "--from",
    "--to",
    "--reference",
    "--target",
    "--scenario",
    "--scenarios",
    "--manifest",
    "--data-dir",
    "logs",
    "dir",
}
#: Options that take no path: numbers, names, choices and flags.
VALUES = {
    "--processes",
    "--every-log",
    "--by-size",
    "--fit-size-kg",
    "--unit",
    "--batch-capacity-kg",
    "--drum-diameter-m",
    "--drum-length-m",
    "--heater-unit",
    "--fan-unit",
    "--host",
    "--port",
    "--no-browser",
    "--tgi-offset",
    "--heat-flows",
    "--x0",
    "--baseline",
    "--method",
    "--seed",
    "--starts",
    "--fix",
    "--bounds",
    "--weight",
    "--estimate-tm0",
    "--per-batch",
    "--name",
    "--tb0",
    "--tm0",
    "--hgm",
    "--hbm",
    "--pbm",
    "--hold",
    "--bed",
    "--variant",
    "--group-step-kg",
    "--group-by",
    "--band",
    "--moisture",
    "--heater",
    "--fan",
    "--set",
    "--tgi",
    "--drop-at",
    "--drop-bt",
    "--batch-kg",
    "--tm0-range",
    "--decide",
    "--units",
    "--tgi-min",
    "--tgi-max",
    "--tgi-rate",
    "--heater-min",
    "--heater-max",
    "--heater-rate",
    "--gg",
    "--gg-min",
    "--gg-max",
    "--interval-s",
    "--tolerance",
    "--only",
    "--controller",
    "--controllers",
    "--oracle",
    "--ror-weight",
    "--workers",
    "--scheduler",
    "--chunk",
    "--wait",
    "--batches",
    "--help",
    "-h",
}


def subcommands(parser, prefix=()):
    """(path of subcommand names, its parser) for every leaf subcommand, and for every command
    whose subcommand is optional (``control`` runs alone or as ``control compare``)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from subcommands(sub, prefix + (name,))
            if action.required:
                return
    yield prefix, parser


def option_names(parser):
    for action in parser._actions:
        if not isinstance(action, argparse._SubParsersAction):  # subcommands are walked, not options
            yield from (action.option_strings or [action.dest])


def output_options(parser):
    """Options in OUTPUTS that take a path (a flag such as ``bench --json`` writes no file)."""
    for action in parser._actions:
        if action.nargs != 0:
            yield from (o for o in action.option_strings if o in OUTPUTS)


#: A short reference roast for the control commands (time, inputs, BT).
REF_CSV = "time_s,Gg_kg_s,Tgi_C,Ta_C\n" + "".join(
    f"{t},0.4,{400 + t / 10:.1f},{30 + 0.15 * t:.2f}\n" for t in range(0, 301, 20)
)
SMALL_PLANT = "Mb_kg = 0.2\nDch_m = 0.16\nLch_m = 0.2\nHflap_m = 0.02\nSflap_m = 0.1\nMm_kg = 1.5\n"


@pytest.fixture(scope="module")
def model_text(tmp_path_factory):
    """A model file fitted on the small log with the map (made once per module)."""
    from roastlab.cli import main

    d = tmp_path_factory.mktemp("model")
    _inputs(d)
    code = main(
        ["identify", "--plant", f"{d}/small.toml", "--map", f"{d}/map.toml", f"{d}/log.alog"]
        + ["--spec", f"{d}/spec.toml", "--out", f"{d}/model.json", "--starts", "1"]
    )
    assert code == 0
    return (d / "model.json").read_text()


def _inputs(d: Path) -> None:
    """Small good inputs of every kind in folder d."""
    (d / "ds").mkdir()
    for k in (1, 2):
        (d / "ds" / f"b{k}.csv").write_text(HEADER + GOOD_ROWS)
    (d / "ds" / "dataset.toml").write_text('plant = "120kg"\n[[batch]]\nfile = "b1.csv"\n[[batch]]\nfile = "b2.csv"\n')
    (d / "plant.toml").write_text(PLANT)
    (d / "spec.toml").write_text("[free]\nhbm = [0.01, 0.35, 0.02]\n")
    (d / "log.alog").write_text(GOOD_ALOG)
    (d / "map.toml").write_text('[Ta]\ncolumn = "BT"\n[Tgi]\ncolumn = "ET"\n[Gg]\nconstant_kg_s = 0.4\n')
    (d / "small.toml").write_text(SMALL_PLANT)
    (d / "sc").mkdir()
    (d / "sc" / "s.toml").write_text('name = "quick"\n[actuator]\nsample_s = 20.0\n')
    (d / "ref.csv").write_text(REF_CSV)
    (d / "manifest.csv").write_text("path,machine,plant,started_at\nds/b1.csv,m1,120kg,2024-01-01T08:00:00\n")
    data = d / "data"
    for name in ("dataset-I", "dataset-V"):
        shutil.copytree(d / "ds", data / name)


def _fixtures(d: Path, model_text: str) -> None:
    _inputs(d)
    (d / "model.json").write_text(model_text)


# subcommand -> (argv with {d} for the folder, the input files it reads)
RUNS = {
    ("simulate",): (
        "simulate --model {d}/model.json --plant {d}/small.toml --inputs {d}/log.alog --map {d}/map.toml "
        "--out {d}/o.csv --plot {d}/f.png",
        ["model.json", "small.toml", "log.alog", "map.toml"],
    ),
    ("plant",): ("plant {d}/plant.toml", ["plant.toml"]),
    ("identify",): (
        "identify --plant {d}/plant.toml --spec {d}/spec.toml {d}/ds --out {d}/m.json",
        ["plant.toml", "spec.toml", "ds/dataset.toml", "ds/b1.csv", "ds/b2.csv"],
    ),
    ("compare-models",): (
        "compare-models --plant {d}/plant.toml --spec {d}/spec.toml {d}/ds --json {d}/c.json --plot {d}/c.png",
        ["plant.toml", "spec.toml", "ds/dataset.toml", "ds/b1.csv", "ds/b2.csv"],
    ),
    ("validate",): (
        "validate --model {d}/model.json --map {d}/map.toml {d}/log.alog --json {d}/v.json --plot {d}/v.png "
        "--predictions {d}/pred",
        ["model.json", "map.toml", "log.alog"],
    ),
    ("reproduce",): (
        "reproduce --data {d}/data --out {d}/rep",
        ["data/dataset-I/dataset.toml", "data/dataset-V/b1.csv"],
    ),
    ("bench",): ("bench --save {d}/bench.json", []),
    ("whatif",): (
        "whatif {d}/log.alog --model {d}/model.json --map {d}/map.toml --tgi 10 --json {d}/w.json --plot {d}/w.png",
        ["log.alog", "model.json", "map.toml"],
    ),
    ("transfer",): (
        "transfer --model {d}/model.json --from {d}/plant.toml --to {d}/plant.toml --batch-kg 100 "
        "--reference {d}/ds/b1.csv --interval-s 10 --out {d}/p.csv --json {d}/m.json --plot {d}/t.png "
        "--alog {d}/bg.alog",
        ["model.json", "plant.toml", "ds/b1.csv"],
    ),
    ("import",): ("import {d}/log.alog --map {d}/map.toml --out {d}/b.csv", ["log.alog", "map.toml"]),
    ("datasets", "make-paper"): ("datasets make-paper --out {d}/synthetic", []),
    ("control",): (
        "control --model {d}/model.json --plant {d}/plant.toml --reference {d}/ref.csv --scenario {d}/sc/s.toml "
        "--controller pid --out {d}/trace.csv --json {d}/m.json --plot {d}/c.png",
        ["model.json", "plant.toml", "ref.csv", "sc/s.toml"],
    ),
    ("control", "compare"): (
        "control compare --model {d}/model.json --plant {d}/plant.toml --reference {d}/ref.csv --scenarios {d}/sc "
        "--controllers replay --json {d}/t.json --plot {d}/c.png",
        ["model.json", "plant.toml", "ref.csv", "sc/s.toml"],
    ),
    ("fleet", "ingest"): ("fleet ingest --db {d}/f.duckdb --manifest {d}/manifest.csv", ["manifest.csv", "ds/b1.csv"]),
    ("fleet", "fit"): ("fleet fit --db {d}/f.duckdb --spec {d}/spec.toml", ["spec.toml"]),
    ("fleet", "report"): ("fleet report --db {d}/f.duckdb --json {d}/r.json --plot {d}/figs", []),
    ("fleet", "synthetic"): ("fleet synthetic --out {d}/syn --batches 5", []),
    # a server: no output option, so no case is generated (its writes are tested in test_app.py)
    ("app",): ("app --data-dir {d} --no-browser", []),
    ("init",): ("init {d}/log.alog --out {d}/cfg --batch-kg 0.2", ["log.alog"]),
    # writes into the folder init made (no output option): tested in test_roaster_setup.py
    ("fit-roaster",): ("fit-roaster {d}/cfg {d}/log.alog", []),
    # writes only the compile cache (no output option): tested in test_precompile.py
    ("compile",): ("compile --processes 1", []),
}

PARSER = build_parser()
LEAVES = dict(subcommands(PARSER))


def test_every_option_is_classified_and_every_subcommand_has_a_run():
    for path, sub in LEAVES.items():
        unknown = set(option_names(sub)) - OUTPUTS - INPUTS - VALUES - {"help"}
        assert not unknown, f"{' '.join(path)}: classify {sorted(unknown)} in tests/test_outputs.py"
        assert path in RUNS, f"add a working invocation of '{' '.join(path)}' to RUNS"


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _cases():
    for path, (_argv, inputs) in RUNS.items():
        for opt in output_options(LEAVES[path]):
            for target in [*inputs, *(f"{i}.wal" for i in inputs[:1]), "FIFO", "LINK", "/dev/null"]:
                yield pytest.param(path, opt, target, id=f"{' '.join(path)} {opt}->{target}")


@pytest.mark.parametrize("path, option, target", list(_cases()))
def test_output_pointed_at_an_input_is_refused(cli, tmp_path, model_text, path, option, target):
    _fixtures(tmp_path, model_text)
    argv = RUNS[path][0].format(d=tmp_path).split()
    if target == "FIFO":
        dest = tmp_path / "fifo"
        os.mkfifo(dest)
    elif target == "LINK":  # a link to a fresh file: the final rename would replace the link itself
        dest = tmp_path / "link"
        (tmp_path / "linked").write_text("keep\n")
        dest.symlink_to(tmp_path / "linked")
    elif target.startswith("/"):
        dest = Path(target)
    else:
        dest = tmp_path / target
    before = {p: _digest(p) for p in tmp_path.rglob("*") if p.is_file() and not p.is_fifo()}
    i = argv.index(option) if option in argv else None
    argv = argv[: i + 1] + [str(dest)] + argv[i + 2 :] if i is not None else [*argv, option, str(dest)]
    code, _, err = cli(*argv)
    assert code == 2, (argv, code, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert dest.name in err, err
    after = {p: _digest(p) for p in tmp_path.rglob("*") if p.is_file() and not p.is_fifo()}
    assert {p: h for p, h in after.items() if p in before} == before, "an input changed"
    assert set(after) == set(before), f"left behind: {sorted(set(after) - set(before))}"
    if target == "FIFO":
        assert dest.is_fifo()  # not replaced by a regular file
    if target == "LINK":
        assert dest.is_symlink() and (tmp_path / "linked").read_text() == "keep\n"


@pytest.mark.parametrize(
    "argv",
    [
        "simulate --plant 120kg --inputs {d}/ds/b1.csv --out {d}/o.csv --plot {d}/f.png",
        "validate --plant 120kg {d}/ds --json {d}/v.json --plot {d}/v.png",
    ],
)
def test_a_failing_figure_leaves_no_earlier_output(cli, tmp_path, monkeypatch, argv):
    """The figure is rendered last; when rendering fails nothing at all is written."""
    import roastlab.report.figures as figures
    from roastlab.errors import InputError

    _inputs(tmp_path)
    before = set(tmp_path.rglob("*"))

    def broken(fig, path):
        raise InputError("cannot render the figure (disk full)", path)

    monkeypatch.setattr(figures, "figure_bytes", broken)
    code, _, err = cli(*argv.format(d=tmp_path).split())
    assert code == 2 and "disk full" in err and err.count("\n") == 1, err
    assert set(tmp_path.rglob("*")) == before, "an output or a temporary file was left behind"


def test_an_output_that_is_a_link_is_refused_and_the_link_kept(cli, tmp_path):
    """`--out /dev/stdout > prog.csv` would replace the /dev/stdout link itself: any link is refused."""
    target = tmp_path / "real.csv"
    target.write_text("keep\n")
    link = tmp_path / "link.csv"
    link.symlink_to(target)
    src = tmp_path / "in.csv"
    src.write_text(HEADER + GOOD_ROWS)
    code, _, err = cli("import", src, "--out", link)
    assert code == 2 and "symbolic link" in err and err.count("\n") == 1, err
    assert link.is_symlink() and target.read_text() == "keep\n"


def test_a_sidecar_of_an_input_is_refused(tmp_path):
    """A database's write-ahead log (``S.duckdb.wal``) or temporary file beside an input is the input's."""
    from roastlab.errors import InputError
    from roastlab.io.files import Outputs

    store = tmp_path / "S.duckdb"
    store.write_bytes(b"x")
    with pytest.raises(InputError, match="sidecar"):
        Outputs([store]).check(tmp_path / "S.duckdb.wal")
    Outputs([store]).check(tmp_path / "S.json")  # another name beside it is fine
