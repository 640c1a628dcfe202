"""The fleet store, per-batch fleet fits (in-process and on Dask), drift alarms and outliers."""

import json
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from roastlab.io.plants import load_plant

duckdb = pytest.importorskip("duckdb")

from roastlab.fleet import fit_fleet, fleet_report, fleet_spec, ingest  # noqa: E402
from roastlab.fleet.drift import CUSUM_H, cusum_alarms  # noqa: E402
from roastlab.fleet.synthetic import make_fleet  # noqa: E402

REAL = Path(__file__).resolve().parents[2] / "shared" / "data" / "real"


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    """A SYNTHETIC fleet of 500 batches (100 per machine, three with an injected change), ingested and fitted."""
    d = tmp_path_factory.mktemp("fleet")
    truth = make_fleet(d / "data", 500, seed=3)
    db = d / "f.duckdb"
    rep = ingest(db, d / "data" / "manifest.csv")
    assert rep.added == 500 and not rep.rejected
    fit = fit_fleet(db, chunk=40)
    assert fit.fitted == 500
    return d, db, truth


def _counts(db):
    con = duckdb.connect(str(db), read_only=True)
    try:
        return {t: con.execute(f"SELECT count(*) FROM {t}").fetchone()[0] for t in ("machines", "batches", "series")}
    finally:
        con.close()


def _fits(db):
    con = duckdb.connect(str(db), read_only=True)
    try:
        vals = con.execute(
            "SELECT b.sha256, v.parameter, v.value, v.stderr FROM fit_values v JOIN batches b USING (batch_id) "
            "ORDER BY b.sha256, v.parameter"
        ).fetchall()
        fits = con.execute(
            "SELECT b.sha256, f.SSR, f.FIT, f.MAE, f.simulations FROM fits f JOIN batches b USING (batch_id) "
            "ORDER BY b.sha256"
        ).fetchall()
        return vals, fits
    finally:
        con.close()


def test_ingest_stores_every_sample_and_reingest_is_a_no_op(fleet):
    d, db, _ = fleet
    before = _counts(db)
    assert before["machines"] == 5 and before["batches"] == 500
    con = duckdb.connect(str(db), read_only=True)
    n_rows = con.execute("SELECT sum(n_samples) FROM batches").fetchone()[0]
    row = con.execute("SELECT source, initial_json, green_kg FROM batches ORDER BY batch_id LIMIT 1").fetchone()
    con.close()
    assert before["series"] == n_rows
    assert set(json.loads(row[1])) == {"Tm0_C", "X0", "Tb0_C"} and row[2] > 100  # the log's metadata kept
    rep = ingest(db, d / "data" / "manifest.csv")
    assert rep.added == 0 and rep.already == 500
    assert _counts(db) == before


def test_a_failed_ingest_keeps_its_committed_chunks_and_a_rerun_completes_it(fleet, tmp_path, monkeypatch):
    """Ingest commits chunk by chunk (memory flat in the manifest's length, issue 26): a failure
    after two chunks keeps exactly those, and running the same manifest again leaves the store as
    one uninterrupted ingest does."""
    import roastlab.fleet.store as store

    d, db, _ = fleet
    copy, whole = tmp_path / "copy.duckdb", tmp_path / "whole.duckdb"
    copy.write_bytes(db.read_bytes())
    whole.write_bytes(db.read_bytes())
    before = _counts(copy)
    make_fleet(tmp_path / "more", 50, seed=99)
    manifest = tmp_path / "more" / "manifest.csv"
    monkeypatch.setattr(store, "INGEST_CHUNK", 10)
    real_flush = store._flush
    calls = {"n": 0}

    def failing_flush(*args):
        calls["n"] += 1
        if calls["n"] == 3:
            raise RuntimeError("disk full")
        return real_flush(*args)

    monkeypatch.setattr(store, "_flush", failing_flush)
    with pytest.raises(RuntimeError):
        ingest(copy, manifest)
    assert calls["n"] == 3
    partial = _counts(copy)
    assert partial["batches"] == before["batches"] + 20  # the two committed chunks of 10 batches, no more
    monkeypatch.setattr(store, "_flush", real_flush)
    rep = ingest(copy, manifest)
    assert rep.already == 20 and rep.added == 30
    ingest(whole, manifest)
    assert _counts(copy) == _counts(whole)


def test_bad_manifest_rows_are_reported_one_line_each_and_good_rows_ingest(cli, tmp_path):
    make_fleet(tmp_path / "data", 10, seed=5)
    lines = (tmp_path / "data" / "manifest.csv").read_text().splitlines()
    (tmp_path / "data" / "truncated.csv").write_text("time_s,Gg_kg_s,Tgi_C,Ta_C\n0,0.4,400,25\n30,0.4,4")
    bad = [
        "roaster-A/missing.csv,roaster-A,120kg,2024-01-01T08:00:00",
        lines[2].replace(",120kg,", ",200kg,"),
        lines[3].rsplit(",", 1)[0] + ",yesterday",
        "truncated.csv,roaster-A,120kg,2024-01-01T09:00:00",
    ]
    manifest = tmp_path / "data" / "m.csv"
    manifest.write_text("\n".join([lines[0], lines[1], *bad, *lines[4:]]) + "\n")
    code, out, err = cli("fleet", "ingest", "--db", tmp_path / "f.duckdb", "--manifest", manifest)
    assert code == 2
    rejected = [e for e in err.splitlines() if "rejected" in e]
    assert len(rejected) == 4 and "Traceback" not in err
    for line_no, word in zip((3, 4, 5, 6), ("file not found", "unknown plant", "ISO 8601", "truncated.csv")):
        hit = [e for e in rejected if f"line {line_no}:" in e]
        assert hit and word in hit[0], (line_no, rejected)
    # line 4 is one good file with a bad plant, line 5 one with a bad date: 10 files - 2 rejected ingest
    assert "8 batch(es) ingested" in out
    assert _counts(tmp_path / "f.duckdb")["batches"] == 8


def test_manifest_without_its_columns_and_a_non_store_db_are_one_line_errors(cli, tmp_path):
    m = tmp_path / "m.csv"
    m.write_text("path,machine\nx.csv,a\n")
    code, _, err = cli("fleet", "ingest", "--db", tmp_path / "f.duckdb", "--manifest", m)
    assert code == 2 and "plant, started_at" in err and err.count("\n") == 1
    code, _, err = cli("fleet", "ingest", "--db", m, "--manifest", m)
    assert code == 2 and "input" in err and err.count("\n") == 1
    log = tmp_path / "log.csv"
    log.write_text("time_s,Gg_kg_s,Tgi_C\n0,0.4,400\n")
    code, _, err = cli("fleet", "fit", "--db", log)
    assert code == 2 and "not a DuckDB file" in err and log.read_text().startswith("time_s")
    code, _, err = cli("fleet", "report", "--db", tmp_path / "nothing.duckdb")
    assert code == 2 and "no such fleet store" in err
    huge = tmp_path / "huge.csv"  # a field over the csv module's 128 KiB limit
    huge.write_text("path,machine,plant,started_at\n" + "x" * 200_000 + ",a,120kg,2024-01-01T00:00:00\n")
    code, _, err = cli("fleet", "ingest", "--db", tmp_path / "g.duckdb", "--manifest", huge)
    assert code == 2 and "unreadable CSV" in err and err.count("\n") == 1, err


def test_drift_is_flagged_within_15_batches_and_only_where_injected(fleet):
    d, db, truth = fleet
    report = fleet_report(db).to_json_dict()
    by_name = {m["machine"]: m for m in report["machines"]}
    for m in truth["machines"]:
        alarms = by_name[m["name"]]["alarms"]
        if not m["changes"]:
            assert alarms == [], (m["name"], alarms)
            continue
        for change in m["changes"]:
            hits = [a for a in alarms if a["parameter"] == change["parameter"]]
            assert len(hits) == 1, (m["name"], alarms)
            delay = hits[0]["batch_index"] - change["batch_index"]
            assert 0 <= delay <= 15, (m["name"], delay)
            assert hits[0]["direction"] == ("down" if change["factor"] < 1 else "up")
            assert set(hits[0]) >= {"parameter", "batch_index", "started_at", "direction"}


def test_the_self_starting_cusum_holds_its_false_alarm_rate():
    """In-control series of 20,000 values: no alarm at h = 12 (normal); at most one in 60,000
    heavy-tailed (Student t, 4 dof) values; a 2-sd step is found within 15 values."""
    rng = np.random.default_rng(0)
    for _ in range(3):
        assert cusum_alarms(1.0 + 0.05 * rng.standard_normal(20000)) == []
    assert sum(len(cusum_alarms(1.0 + 0.05 * rng.standard_t(4, 20000))) for _ in range(3)) <= 1
    x = 1.0 + 0.05 * rng.standard_normal(400)
    x[200:] += 0.1
    alarms = cusum_alarms(x)
    assert len(alarms) == 1 and 200 <= alarms[0]["index"] <= 215 and alarms[0]["direction"] == "up"
    # the threshold matters: a much lower h raises false alarms on the same in-control series
    assert cusum_alarms(1.0 + 0.05 * rng.standard_normal(20000), h=2.0) != [] and CUSUM_H > 2.0


def test_probe_faults_are_outliers_not_drift(tmp_path):
    """A batch whose probe reading jumps is listed as an outlier, with its reason."""
    import roastlab.fleet.synthetic as syn

    old = syn.PROBE_FAULT_RATE
    syn.PROBE_FAULT_RATE = 0.2
    try:
        make_fleet(tmp_path / "data", 40, seed=8, machines=syn.MACHINES[:1])
    finally:
        syn.PROBE_FAULT_RATE = old
    # the machine's plant as a file (its 120kg geometry) whose name is not the file's: the report names
    # the plant by its own name (the figure's title was the file name, "plant.toml" for every init folder)
    preset = load_plant(syn.MACHINES[0].plant)
    shop = tmp_path / "data" / "plant.toml"
    shop.write_text(
        'name = "shop-drum"\n'
        + "".join(f"{k} = {getattr(preset, k)}\n" for k in ("Mb_kg", "Dch_m", "Lch_m", "Hflap_m", "Sflap_m", "Mm_kg"))
    )
    manifest = tmp_path / "data" / "manifest.csv"
    manifest.write_text(manifest.read_text().replace(f",{syn.MACHINES[0].plant},", f",{shop},"))
    db = tmp_path / "f.duckdb"
    ingest(db, manifest)
    fit_fleet(db)
    m = fleet_report(db).to_json_dict()["machines"][0]
    assert len(m["outliers"]) >= 4 and m["alarms"] == []
    assert m["plant"] == str(shop) and m["plant_name"] == "shop-drum"
    assert all("fit" in o["reason"] or "residual" in o["reason"] for o in m["outliers"])


def test_dask_and_in_process_store_identical_fits(fleet, tmp_path):
    pytest.importorskip("distributed")
    d, db, _ = fleet
    other = tmp_path / "dask.duckdb"
    ingest(other, d / "data" / "manifest.csv")
    rep = fit_fleet(other, workers=2, chunk=25)
    assert rep.where.startswith("dask (2 workers)") and rep.fitted == 500
    assert _fits(other) == _fits(db)


def test_population_simulations_on_dask_are_identical():
    pytest.importorskip("distributed")
    from distributed import Client, LocalCluster

    from roastlab.io.batch import Batch
    from roastlab.model.parameters import THETA_START
    from roastlab.sim.population import pack_batches, simulate_population

    t = np.arange(0, 601, 10.0)
    b = Batch("b", t, np.full_like(t, 0.4), np.full_like(t, 450.0))
    pk = pack_batches([b, b], "120kg", THETA_START)
    values = np.random.default_rng(1).uniform([0.01, 0.01], [0.1, 0.05], (16, 2, 2))  # Monte Carlo sets
    here = simulate_population(pk, ["hgm", "hbm"], values)
    with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None, processes=False) as c, Client(c) as cl:
        there = simulate_population(pk, ["hgm", "hbm"], values, client=cl)
    np.testing.assert_array_equal(there, here)


KILL = textwrap.dedent(
    """
    import os, signal, sys
    from roastlab.fleet import fit_fleet

    def stop(n):
        if n >= 60:  # three chunks of 20 committed: kill -9, no clean-up at all
            os.kill(os.getpid(), signal.SIGKILL)

    fit_fleet(sys.argv[1], chunk=20, on_commit=stop)
    """
)


def test_killed_fit_resumes_without_refitting_or_losing_batches(fleet, tmp_path):
    d, _, _ = fleet
    db = tmp_path / "k.duckdb"
    ingest(db, d / "data" / "manifest.csv")
    run = subprocess.run([sys.executable, "-c", KILL, str(db)], env={**os.environ}, capture_output=True, timeout=300)
    assert run.returncode == -9, run.stderr.decode()[-500:]
    rep = fit_fleet(db, chunk=20)
    assert rep.already == 60 and rep.fitted == 440
    con = duckdb.connect(str(db), read_only=True)
    n, distinct = con.execute("SELECT count(*), count(DISTINCT batch_id) FROM fits").fetchone()
    con.close()
    assert n == distinct == 500
    assert fit_fleet(db).fitted == 0


def test_a_report_on_a_missing_store_leaves_no_folder_behind(cli, tmp_path):
    code, _, err = cli("fleet", "report", "--db", tmp_path / "none.duckdb", "--plot", tmp_path / "NEW" / "SUB")
    assert code == 2 and "no such fleet store" in err and err.count("\n") == 1, err
    assert not (tmp_path / "NEW").exists()


def test_cli_report_writes_json_and_figures(cli, fleet, tmp_path):
    _, db, _ = fleet
    code, out, err = cli("fleet", "report", "--db", db, "--json", tmp_path / "r.json", "--plot", tmp_path / "figs")
    assert code == 0, err
    doc = json.loads((tmp_path / "r.json").read_text())
    assert [m["machine"] for m in doc["machines"]] == [f"roaster-{c}" for c in "ABCDE"]
    assert doc["detector"]["h"] == CUSUM_H
    assert sorted(p.name for p in (tmp_path / "figs").iterdir()) == [f"roaster-{c}.png" for c in "ABCDE"]
    assert "hbm down" in out
    from roastlab.fleet.drift import WARMUP

    assert f"drift watched from batch {WARMUP} on" in out  # the report says when the detector starts


def test_a_fit_spec_frees_other_parameters_per_batch_and_refuses_X0(tmp_path, fleet):
    from roastlab.errors import InputError

    d, _, _ = fleet
    spec = tmp_path / "fit.toml"
    spec.write_text("[free]\nhbm = [0.005, 0.2, 0.02]\nKt = [0.005, 0.2, 0.02]\n")
    s = fleet_spec(spec)
    assert s.names == ("hbm", "Kt") and dict(s.fixed)["hgm"] == 0.01
    db = tmp_path / "s.duckdb"
    con_rows = (d / "data" / "manifest.csv").read_text().splitlines()[:11]
    (d / "data" / "ten.csv").write_text("\n".join(con_rows) + "\n")
    ingest(db, d / "data" / "ten.csv")
    fit_fleet(db, {"roaster-A": s})
    con = duckdb.connect(str(db), read_only=True)
    params = {r[0] for r in con.execute("SELECT DISTINCT parameter FROM fit_values").fetchall()}
    con.close()
    assert params == {"hbm", "Kt"}
    spec.write_text("[free]\nX0 = [0.05, 0.15, 0.1]\n")
    with pytest.raises(InputError, match="cannot be fitted per batch"):
        fleet_spec(spec)


def test_per_batch_standard_errors_match_the_multi_batch_identifier():
    """On one batch the compiled fitter's s^2 (J'J)^-1 agrees with identify()'s (SciPy's Jacobian)."""
    import roastlab
    from roastlab.fit.batchfit import identify_each
    from roastlab.fit.identify import build_free_parameters, identify
    from roastlab.model.parameters import THETA_START
    from roastlab.sim.population import pack_batches

    ds = roastlab.read_dataset(roastlab.default_dataset_root() / "dataset-I")
    pk = pack_batches(ds.batches[:1], "120kg", (THETA_START.hgm, THETA_START.hbm, 0.5793))
    each = identify_each(pk, names=["hgm", "hbm"])
    free, fixed = build_free_parameters({"Pbm": 0.5793}, None)
    one = identify(pk, free, fixed, seed=0, n_starts=2)
    for j, name in enumerate(["hgm", "hbm"]):
        assert each.theta[0, j] == pytest.approx(one.values[name], rel=2e-3)
        assert each.stderr[0, j] == pytest.approx(one.stderr[name], rel=0.1)


@pytest.mark.skipif(not (REAL / "skywalker").is_dir(), reason="real logs not present")
def test_real_logs_ingest_as_two_machines(tmp_path):
    root = Path(__file__).resolve().parents[1]
    rows = ["path,machine,plant,started_at,map"]
    for f in sorted((REAL / "skywalker").glob("*.alog"))[:3]:
        rows.append(
            f"{f},skywalker,{root}/examples/skywalker/plant.toml,2025-01-01T10:00:00,{root}/examples/skywalker/map.toml"
        )
    for f in sorted((REAL / "bullet").glob("*.json"))[:3]:
        rows.append(f"{f},bullet,{root}/examples/bullet/plant.toml,2025-01-02T10:00:00,{root}/examples/bullet/map.toml")
    (tmp_path / "m.csv").write_text("\n".join(rows) + "\n")
    before = {f: f.stat().st_mtime_ns for f in (REAL / "skywalker").glob("*.alog")}
    rep = ingest(tmp_path / "f.duckdb", tmp_path / "m.csv")
    assert rep.added == 6 and not rep.rejected and sorted(rep.machines_added) == ["bullet", "skywalker"]
    assert {f: f.stat().st_mtime_ns for f in before} == before


def test_fleet_spec_refuses_output_weights(tmp_path):
    """A fleet fit scores the probe alone, so a spec weighting a second reading is refused, not ignored."""
    from roastlab.errors import InputError
    from roastlab.fleet.fitting import fleet_spec

    spec = tmp_path / "fit.toml"
    spec.write_text("[free]\nhbm = [0.002, 0.1, 0.01]\n[weights]\nTb2 = 1.0\n")
    with pytest.raises(InputError, match="fit.toml.*Ta. alone"):
        fleet_spec(spec)
    spec.write_text("[free]\nhbm = [0.002, 0.1, 0.01]\n[weights]\nTa = 1.0\n")
    assert fleet_spec(spec).names == ("hbm",)


@pytest.mark.parametrize("address", ["localhost", "http://localhost:8786", "tcp://host"])
def test_a_scheduler_address_without_protocol_or_port_is_one_line(cli, fleet, address):
    _, db, _ = fleet
    code, _, err = cli("fleet", "fit", "--db", db, "--scheduler", address)
    assert code == 2 and "tcp://host:8786" in err and err.count("\n") == 1, err


def _small_store(fleet, path):
    """A copy of the module's fitted store (the fixture's own file is never touched)."""
    import shutil

    _, db, _ = fleet
    shutil.copyfile(db, path)
    return path


def _digest(path):
    import hashlib

    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def test_a_foreign_database_or_another_schema_version_is_refused_untouched(cli, fleet, tmp_path):
    other = tmp_path / "analytics.duckdb"
    con = duckdb.connect(str(other))
    con.execute("CREATE TABLE sales (day DATE, amount DOUBLE)")
    con.execute("INSERT INTO sales VALUES ('2024-01-01', 3.5)")
    con.close()
    before = _digest(other)
    for args in (("fit",), ("ingest", "--manifest", fleet[0] / "data" / "manifest.csv"), ("report",)):
        code, _, err = cli("fleet", args[0], "--db", other, *args[1:])
        assert code == 2 and "not a roastlab fleet store" in err and "sales" in err and err.count("\n") == 1, err
    assert _digest(other) == before
    newer = _small_store(fleet, tmp_path / "newer.duckdb")
    con = duckdb.connect(str(newer))
    con.execute("UPDATE meta SET value = '7' WHERE key = 'schema_version'")
    con.close()
    before = _digest(newer)
    code, _, err = cli("fleet", "fit", "--db", newer)
    assert code == 2 and "newer roastlab" in err and err.count("\n") == 1, err
    assert _digest(newer) == before


@pytest.mark.parametrize("damage", ["view", "column", "half", "blocks"])
def test_a_damaged_store_is_one_line_naming_it(cli, fleet, tmp_path, damage):
    db = _small_store(fleet, tmp_path / "d.duckdb")
    if damage in ("view", "column"):
        con = duckdb.connect(str(db))
        if damage == "view":
            con.execute("ALTER TABLE series RENAME TO series_old")
            con.execute("CREATE VIEW series AS SELECT * FROM series_old")
        else:
            con.execute("ALTER TABLE fits DROP COLUMN MAE")
        con.close()
    else:
        raw = bytearray(db.read_bytes())
        if damage == "half":
            raw = raw[: len(raw) // 2]
        else:  # overwrite blocks past the headers with noise
            rng = np.random.default_rng(0)
            a = len(raw) // 3
            raw[a : a + 200_000] = rng.integers(0, 256, min(200_000, len(raw) - a), dtype=np.uint8).tobytes()
        db.write_bytes(bytes(raw))
    for what in ("report", "fit"):
        code, out, err = cli("fleet", what, "--db", db)
        assert code == 2 and str(db) in err and err.count("\n") == 1 and "Traceback" not in err, (what, err)


def test_a_store_locked_by_another_process_says_so_and_can_be_waited_for(cli, fleet, tmp_path):
    import time

    db = _small_store(fleet, tmp_path / "l.duckdb")
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import duckdb,sys,time; c=duckdb.connect(sys.argv[1]); print('held', flush=True); "
            "time.sleep(float(sys.argv[2]))",
            str(db),
            "3",
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout.readline().strip() == "held"
        code, _, err = cli("fleet", "report", "--db", db)
        assert code == 2 and "in use by another process" in err and f"PID {holder.pid}" in err, err
        assert err.count("\n") == 1 and "--wait" in err
        t0 = time.monotonic()
        code, out, err = cli("fleet", "fit", "--db", db, "--wait", "60")
        assert code == 0, err
        assert time.monotonic() - t0 >= 1.0  # it waited for the holder rather than failing
    finally:
        holder.kill()
        holder.wait()
        holder.stdout.close()


def test_sigterm_during_a_long_command_cleans_up_like_ctrl_c(tmp_path):
    """SIGTERM (what a service manager, a CI runner or `kill` sends) leaves nothing behind."""
    import signal
    import time

    out = tmp_path / "data"
    proc = subprocess.Popen(
        [sys.executable, "-m", "roastlab", "fleet", "synthetic", "--out", out, "--batches", "50000"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 120
    while not any(p.name.startswith(".data.") for p in tmp_path.iterdir()):  # its staging folder
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.05)
    time.sleep(0.5)
    proc.send_signal(signal.SIGTERM)
    try:
        _, err = proc.communicate(timeout=60)
    finally:  # a process the signal did not end is ended here, not left to the next test
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 128 + signal.SIGTERM and "terminated" in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name, raised", [("SIGTERM", "Terminated"), ("SIGINT", "KeyboardInterrupt")])
def test_a_signal_that_lands_in_a_compilers_callback_is_sent_again(monkeypatch, name, raised):
    """Raised inside Python code that C calls back into (llvmlite's, while numba compiles), the
    exception would be printed and lost, and the command would run on: there the handler sends the
    signal again shortly instead; anywhere else it raises at once (SIGTERM as Terminated, Ctrl-C as
    a KeyboardInterrupt)."""
    import importlib
    import signal

    cli_main = importlib.import_module("roastlab.cli.main")  # the module (roastlab.cli.main is also the function)
    signum = getattr(signal, name)
    sent = []
    monkeypatch.setattr(cli_main, "RESEND_S", 0.0)
    monkeypatch.setattr(cli_main.os, "kill", lambda pid, sig: sent.append((pid, sig)))

    def frame_in(filename):  # a real frame whose code comes from ``filename``
        namespace = {"sys": sys}
        exec(compile("def here():\n    return sys._getframe()\n", filename, "exec"), namespace)
        return namespace["here"]()

    callback = frame_in(os.path.join("site-packages", "llvmlite", "binding", "executionengine.py"))
    assert cli_main._on_signal(signum, callback) is None
    deadline = time.monotonic() + 5
    while not sent and time.monotonic() < deadline:
        time.sleep(0.01)
    assert sent == [(os.getpid(), signum)]
    with pytest.raises(KeyboardInterrupt) as info:
        cli_main._on_signal(signum, sys._getframe())
    assert type(info.value).__name__ == raised
    assert len(sent) == 1


def test_ctrl_c_is_taken_where_python_takes_it_and_left_ignored_where_the_parent_ignores_it(monkeypatch):
    """The handler takes SIGINT only from Python's own handler: a command started as a shell's
    background job (SIGINT ignored) keeps ignoring it, as Python itself would."""
    import importlib
    import signal

    cli_main = importlib.import_module("roastlab.cli.main")
    monkeypatch.setattr(signal, "getsignal", lambda signum: signal.default_int_handler)
    assert cli_main._handled_signals() == [signal.SIGTERM, signal.SIGINT]
    monkeypatch.setattr(signal, "getsignal", lambda signum: signal.SIG_IGN)
    assert cli_main._handled_signals() == [signal.SIGTERM]


def test_ctrl_c_while_the_command_line_loads_its_libraries_ends_without_a_traceback(monkeypatch, capsys):
    """`import roastlab.cli` loads no numerical library (the package's names load on first use), so the
    command line's signal handling is in place before the half second of NumPy, SciPy and numba that
    building its parser takes; a Ctrl-C there ends as anywhere else: one line, exit code 130 (SIGTERM's
    143; tried by hand on `roastlab validate --help`, signalled 0.06-0.3 s after its start). And
    ``roastlab.fit`` stays the function though the subpackage of that name loads first."""
    import importlib

    code = (
        "import sys, roastlab.cli; heavy = [m for m in ('numpy', 'scipy', 'numba') if m in sys.modules]; "
        "import roastlab.fit.identify, roastlab; print(heavy, callable(roastlab.fit), roastlab.fit.__module__)"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout.split() == ["[]", "True", "roastlab.workflows.fitting"], run.stdout + run.stderr
    cli_main = importlib.import_module("roastlab.cli.main")

    def loading(raised):
        def build():
            raise raised

        return build

    monkeypatch.setattr(cli_main, "build_parser", loading(KeyboardInterrupt()))
    assert cli_main.main(["simulate", "--help"]) == 130
    assert capsys.readouterr().err == "roastlab: interrupted\n"
    # Python 3.11 wraps a signal that lands in a class's __set_name__ (numba defines classes as it
    # imports) in a RuntimeError; it ends the same way, and any other RuntimeError goes on up
    wrapped = RuntimeError("Error calling __set_name__")
    wrapped.__cause__ = cli_main.Terminated()
    monkeypatch.setattr(cli_main, "build_parser", loading(wrapped))
    assert cli_main.main(["simulate", "--help"]) == 128 + 15
    assert capsys.readouterr().err == "roastlab: terminated\n"
    monkeypatch.setattr(cli_main, "build_parser", loading(RuntimeError("a bug")))
    with pytest.raises(RuntimeError, match="a bug"):
        cli_main.main(["simulate", "--help"])


def test_batches_are_fitted_under_the_machine_model_as_validate_applies_it(cli, tmp_path, fleet):
    """With --model, a batch's fleet fit is the model file with the batch's own free values: its
    stored FIT is what `validate` gives that model with those values, bed laws and all."""
    import roastlab
    from roastlab.errors import InputError
    from roastlab.io.batch import read_batch_csv

    d, _, _ = fleet
    rows = (d / "data" / "manifest.csv").read_text().splitlines()
    mine = [r for r in rows[1:] if r.split(",")[1] == "roaster-A"][:4]
    (d / "data" / "four.csv").write_text("\n".join([rows[0], *mine]) + "\n")
    model = roastlab.FittedModel.paper("120kg").with_values(Kt=0.03, h_probe_m=0.5)
    model.bed = "probe=tumbling,probe_gas=mean"
    model.save(tmp_path / "model.json")
    spec = tmp_path / "fleet.toml"
    spec.write_text("[free]\nhgm = [0.001, 0.2, 0.02]\nhbm = [0.001, 0.2, 0.02]\n")
    db = tmp_path / "m.duckdb"
    ingest(db, d / "data" / "four.csv")
    code, out, err = cli(
        "fleet", "fit", "--db", db, "--spec", f"roaster-A={spec}", "--model", f"roaster-A={tmp_path / 'model.json'}"
    )
    assert code == 0, err
    con = duckdb.connect(str(db), read_only=True)
    got = con.execute(
        "SELECT b.source, f.FIT, max(CASE WHEN v.parameter = 'hgm' THEN v.value END), "
        "max(CASE WHEN v.parameter = 'hbm' THEN v.value END) FROM fits f JOIN batches b USING (batch_id) "
        "JOIN fit_values v USING (batch_id, spec_id) GROUP BY b.source, f.FIT ORDER BY b.source"
    ).fetchall()
    document = json.loads(con.execute("SELECT spec_json FROM fit_specs").fetchone()[0])
    con.close()
    assert len(got) == 4 and document["model"]["bed"]["probe"] == "tumbling"
    for source, fit, hgm, hbm in got:
        batch = read_batch_csv(source)
        again = model.with_values(hgm=hgm, hbm=hbm).validate([batch]).rows[0]["FIT"]
        assert fit == pytest.approx(again, abs=1e-6)
        paper_bed = model.with_values(hgm=hgm, hbm=hbm)
        paper_bed.bed = "paper"
        assert abs(paper_bed.validate([batch]).rows[0]["FIT"] - fit) > 0.01  # the bed laws were applied
    # the spec holds nothing of its own beside a model; a model of another plant is refused
    spec.write_text("[free]\nhbm = [0.001, 0.2, 0.02]\n[fixed]\nKt = 0.02\n")
    with pytest.raises(InputError, match=r"\[fixed\].*machine model holds"):
        fleet_spec(spec, tmp_path / "model.json")
    spec.write_text("[free]\nhbm = [0.001, 0.2, 0.02]\n")
    roastlab.FittedModel.paper("360kg").save(tmp_path / "other.json")
    code, out, err = cli(
        "fleet", "fit", "--db", db, "--spec", f"roaster-A={spec}", "--model", f"roaster-A={tmp_path / 'other.json'}"
    )
    assert code == 2 and "fitted on plant 360kg" in err and len(err.strip().splitlines()) == 1
    code, out, err = cli("fleet", "fit", "--db", db, "--model", f"roaster-A={tmp_path / 'model.json'}")
    assert code == 2 and "give the machine's --spec too" in err


def test_a_spec_without_a_model_applies_its_bed_laws(fleet):
    """A fleet spec's [bed] was read and then dropped; it now reaches the simulator and the spec's identity."""
    import roastlab
    from roastlab.fleet.fitting import fit_chunk

    d, _, _ = fleet
    rows = (d / "data" / "manifest.csv").read_text().splitlines()[1:3]
    batches = [roastlab.io.batch.read_batch_csv(d / "data" / r.split(",")[0]) for r in rows]
    text = "[free]\nhbm = [0.005, 0.2, 0.02]\n[fixed]\nh_probe_m = 0.5\n"
    paper, bed = d / "paper.toml", d / "bed.toml"
    paper.write_text(text)
    bed.write_text(text + '[bed]\nprobe = "tumbling"\n')
    a, b = fleet_spec(paper), fleet_spec(bed)
    assert "bed" not in a.document() and b.document()["bed"] == {"probe": "tumbling"} and a.spec_id != b.spec_id
    fa, fb = (fit_chunk([1, 2], batches, "120kg", s)["SSR"] for s in (a, b))
    assert np.all(np.abs(fa - fb) > 1e-6 * fa)


@pytest.mark.skipif(not (REAL / "bullet").is_dir(), reason="real logs not present")
def test_a_batch_its_plant_cannot_take_is_rejected_at_ingest_naming_the_log(cli, tmp_path):
    """A 490 g roast listed under the paper's 120 kg plant: one line naming the manifest row and the
    log (a model's apply would refuse it in the middle of a fleet fit), the other rows ingest."""
    root = Path(__file__).resolve().parents[1]
    logs = sorted((REAL / "bullet").glob("*_490g.json"))[:2]
    rows = ["path,machine,plant,started_at,map"]
    rows += [f"{logs[0]},wrong,120kg,2025-01-01T10:00:00,{root}/examples/bullet/map.toml"]
    rows += [f"{logs[1]},bullet,{root}/examples/bullet/plant.toml,2025-01-02T10:00:00,{root}/examples/bullet/map.toml"]
    (tmp_path / "m.csv").write_text("\n".join(rows) + "\n")
    code, out, err = cli("fleet", "ingest", "--db", tmp_path / "f.duckdb", "--manifest", tmp_path / "m.csv")
    assert code == 2 and "1 batch(es) ingested" in out
    (line,) = [e for e in err.splitlines() if "rejected" in e]
    assert "line 2:" in line and logs[0].name in line and "0.49 kg batch is far outside 120kg" in line
