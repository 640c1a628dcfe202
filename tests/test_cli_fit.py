"""identify / validate / reproduce / datasets on the command line."""

import json

from roastlab.workflows.reproduce import default_dataset_root

DATA = default_dataset_root()


def test_identify_then_validate(cli, tmp_path):
    theta = tmp_path / "theta.json"
    code, out, err = cli("identify", "--plant", "120kg", DATA / "dataset-I", "--out", theta, "--seed", "3")
    assert code == 0, err
    doc = json.loads(theta.read_text())
    assert doc["format"] == "roastlab-model/1"
    assert {"plant", "parameters", "initial", "fit", "metrics", "provenance"} <= set(doc)
    assert {"SSR", "correlation", "warnings", "evaluations", "wall_s"} <= set(doc["fit"])
    assert doc["plant"]["Mb_kg"] == 120.0 and doc["parameters"]["hbm"]["stderr"] > 0
    hashes = {i["path"]: i["sha256"] for i in doc["provenance"]["inputs"]}
    assert len(hashes) == 5 and all(len(h) == 64 for h in hashes.values())
    assert "summed SSR" in out
    metrics = tmp_path / "m.json"
    code, out, err = cli(
        "validate",
        "--plant",
        "360kg",
        "--model",
        theta,
        DATA / "dataset-V",
        "--json",
        metrics,
        "--plot",
        tmp_path / "f.png",
    )
    assert code == 0, err
    m = json.loads(metrics.read_text())
    assert [b["name"] for b in m["batches"]] == ["batch1", "batch2"]
    assert set(m["batches"][0]) >= {"name", "n", "SSR", "norm", "MAE", "MPE", "MAPE", "FIT", "rho"}
    assert set(m["average"]) >= {"SSR", "MAE", "FIT"}
    assert "average" in out and (tmp_path / "f.png").exists()


def test_identify_with_csv_list_fix_and_bounds(cli, tmp_path):
    files = sorted((DATA / "dataset-I").glob("batch*.csv"))[:2]
    theta = tmp_path / "t.json"
    code, out, err = cli(
        "identify",
        "--plant",
        "120kg",
        *files,
        "--out",
        theta,
        "--fix",
        "hgm=0.02",
        "--bounds",
        "hbm=0.01:0.5",
        "--method",
        "de",
    )
    assert code == 0, err
    doc = json.loads(theta.read_text())
    hgm = doc["parameters"]["hgm"]
    assert hgm["value"] == 0.02 and hgm["how"] == "fixed" and doc["fit"]["method"] == "de"
    assert doc["parameters"]["hbm"]["bounds"] == [0.01, 0.5]


def test_identify_bad_options(cli, tmp_path):
    base = ["identify", "--plant", "120kg", DATA / "dataset-I", "--out", tmp_path / "t.json"]
    for extra, needle in (
        (["--bounds", "hbm=0.3:0.1"], "inverted"),
        (["--fix", "nope=1"], "unknown parameter"),
        (["--fix", "hgm"], "NAME=VALUE"),
        (["--weight", "ET=auto"], "--weight ET: cannot read 'auto' as a number"),
        (
            ["--weight", "Ta=residual"],
            "--weight Ta=residual: the probe is what weights from the residuals are relative to",
        ),
        (["--weight", "ET=residual"], "the ET output has a weight but no batch has an ET reading"),
    ):
        code, _, err = cli(*base, *extra)
        assert code == 2 and needle in err and err.count("\n") == 1, err
    assert not (tmp_path / "t.json").exists()


def test_batch_without_ta_is_refused(cli, tmp_path):
    f = tmp_path / "noTa.csv"
    f.write_text("time_s,Gg_kg_s,Tgi_C\n0,0.4,450\n30,0.4,450\n")
    code, _, err = cli("identify", "--plant", "120kg", f, "--out", tmp_path / "t.json")
    assert code == 2 and "noTa.csv" in err and "Ta_C" in err


def test_reproduce_writes_everything(cli, tmp_path):
    out = tmp_path / "rep"
    code, stdout, err = cli("reproduce", "--out", out)
    assert code == 0, err
    for name in ("model.json", "metrics.json", "report.md", "fig2_profiles.png", "fig3_errors.png"):
        assert (out / name).exists(), name
    report = (out / "report.md").read_text()
    assert "SYNTHETIC" in report and "Table 1" in report and "Table 4" in report
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["synthetic_data"] is True
    assert metrics["dataset-V"]["average"]["FIT"] > 50
    # the report's average rows carry this run's own figures (not text copied from the paper)
    for key in ("dataset-I", "dataset-V"):
        assert f"{metrics[key]['average']['FIT']:.2f}" in report
    assert "dataset-V" in stdout


def test_identify_per_batch(cli, tmp_path):
    out = tmp_path / "fleet.json"
    code, stdout, err = cli("identify", DATA / "dataset-I", "--per-batch", "--fix", "hgm=0.01", "--out", out)
    assert code == 0, err
    doc = json.loads(out.read_text())
    assert doc["mode"] == "per-batch" and len(doc["batches"]) == 5
    assert {"hgm", "hbm", "Pbm", "SSR", "FIT"} <= set(doc["batches"][0])
    assert all(b["hgm"] == 0.01 for b in doc["batches"])  # --fix with --per-batch (was refused)
    assert "mean" in stdout


def test_a_weight_from_the_residuals_is_read_from_the_command_line():
    """--weight ET=residual is the fit spec's ET = "residual" (set from a first fit's residuals)."""
    from roastlab.cli.common import weights_arg

    assert weights_arg(["ET=residual", "Tb2=0.5"]) == {"ET": "residual", "Tb2": 0.5}


def test_a_stage_of_unknown_length_shows_its_elapsed_time_and_clears_its_line(monkeypatch):
    """``progress(desc)``'s callback with total 0 opens a stage ("fitting 8 logs") whose clock keeps
    ticking on a terminal while the work reports nothing (a first run's compile); the next call closes
    it and clears its line. Off a terminal it draws nothing."""
    import io
    import sys
    import time

    from roastlab.cli import common

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    for stream, shown in ((Terminal(), True), (io.StringIO(), False)):
        monkeypatch.setattr(sys, "stderr", stream)
        monkeypatch.setattr(common, "PROGRESS_DELAY_S", 0.5)
        update = common.progress("fit-roaster")
        update(0, 0, "fitting 8 logs")
        time.sleep(2.2)  # the clock redrawn at 1 and 2 s
        update(1, 1, "done")
        drawn = stream.getvalue()
        assert ("fit-roaster: fitting 8 logs [00:01]" in drawn and "[00:02]" in drawn) == shown, drawn
        assert drawn.endswith("\r") if shown else drawn == ""


def test_long_work_off_a_terminal_writes_a_plain_line_now_and_then(monkeypatch):
    """Off a terminal (stderr a log file) no bar is drawn, but work longer than ``PROGRESS_LINE_S`` writes
    one plain line with its count and elapsed time at most that often; short work writes nothing."""
    import io
    import sys
    import time

    from roastlab.cli import common

    stream = io.StringIO()
    monkeypatch.setattr(sys, "stderr", stream)
    monkeypatch.setattr(common, "PROGRESS_LINE_S", 1.0)
    update = common.progress("compare-models")
    update(1, 4, "paper: all logs")  # at once: nothing
    time.sleep(1.1)
    update(2, 4, "paper: without 0.2 kg")
    update(3, 4, "paper: without 0.35 kg")  # within a second of the last line: nothing
    lines = stream.getvalue().splitlines()
    assert lines == ["compare-models: 2/4 paper: without 0.2 kg [00:01]"], lines
    time.sleep(1.1)
    update(0, 0, "fitting 8 logs")  # a stage of unknown length: no count
    assert stream.getvalue().splitlines()[1:] == ["compare-models: fitting 8 logs [00:02]"]


def test_a_first_run_says_it_compiles_on_a_terminal(monkeypatch):
    """A command that compiles the kernels, on a machine whose cache holds none yet, says so on a
    terminal before the minute or two it takes; not off a terminal, not once the cache holds kernels,
    not for a command that compiles nothing (init), nor fit-roaster, whose progress says it."""
    import io

    from roastlab.cli.main import first_run_note
    from roastlab.sim import cache

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    monkeypatch.setattr(cache, "cold", lambda: True)
    assert "first run compiles" in first_run_note("validate", Terminal())
    assert first_run_note("validate", io.StringIO()) is None
    assert first_run_note("init", Terminal()) is None and first_run_note("fit-roaster", Terminal()) is None
    monkeypatch.setattr(cache, "cold", lambda: False)
    assert first_run_note("validate", Terminal()) is None
