"""The roaster's page (roastlab app): its server through Starlette's test client, and the page
itself in a real browser (Playwright driving Debian's chromium; skipped with a message without it).
"""

from __future__ import annotations

import json
import shutil
import socket
import threading
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

pytest.importorskip("starlette", reason="the page needs the app extra: pip install 'roastlab[app]'")

from conftest import REAL_DATA, drop_events, rewritten_alog  # noqa: E402
from roastlab.app.server import create_app  # noqa: E402
from roastlab.workflows.model import FittedModel  # noqa: E402

SYNTHETIC = Path(__file__).resolve().parents[1] / "src" / "roastlab" / "datasets" / "paper-synthetic"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
#: Debian chromium's flags for a closed network (no background connections, no sandbox as root).
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


@pytest.fixture(scope="module")
def data_dir(tmp_path_factory):
    """A data folder: the SYNTHETIC paper batch with the paper's model, and where the shared real
    logs exist, a Bullet log with a model fitted on two other 490 g logs."""
    d = tmp_path_factory.mktemp("appdata")
    shutil.copy(SYNTHETIC / "dataset-I" / "batch1.csv", d / "batch1.csv")
    FittedModel.paper("120kg").save(d / "paper-model.json")
    bullet = REAL_DATA / "bullet"
    if bullet.is_dir():
        import roastlab
        from roastlab.io.importers import load_map
        from roastlab.workflows.model import load_log

        ex = Path(__file__).resolve().parents[1] / "examples" / "bullet"
        cmap = load_map(ex / "map.toml")
        logs = sorted(bullet.glob("*_490g.json"))
        fit = roastlab.fit([load_log(p, cmap) for p in logs[:2]], ex / "plant.toml", ex / "fit.toml", column_map=cmap)
        fit.model.save(d / "bullet-model.json")
        (d / "logs").mkdir()
        shutil.copy(bullet / "bullet_2020-10-01_2053_500g.json", d / "logs" / "bullet-500g.json")  # a temp copy
        shutil.copy(bullet / "bullet_2021-01-21_2313_800g.json", d / "logs" / "bullet-800g-unit2054.json")
        shutil.copy(logs[1], d / "logs" / "renamed-fitted-490g.json")  # a roast the model was fitted on
    return d


@pytest.fixture
def client(data_dir):
    from starlette.testclient import TestClient

    return TestClient(create_app(data_dir))


H = {"X-Session": "test-session-a"}


def test_open_whatif_and_table_through_the_api(client):
    files = client.get("/api/files", headers=H).json()
    assert "batch1.csv" in files["logs"] and "paper-model.json" in files["models"]
    r = client.post("/api/open", json={"log": "batch1.csv", "model": "paper-model.json"}, headers=H).json()
    assert "error" not in r, r
    assert len(r["curves"]["BT_model"]) == len(r["curves"]["time_s"]) == len(r["curves"]["BT_measured"])
    w = client.post("/api/whatif", json={"tgi": 20}, headers=H).json()
    assert "error" not in w, w
    rows = {(x["reading"], x["key"]): x for x in w["table"]["rows"]}
    assert rows["beans", "DROP_C"]["changed"] > rows["beans", "DROP_C"]["as_run"]  # hotter inlet, hotter beans
    assert w["server_ms"] < 1000


def test_a_what_if_dropped_elsewhere_through_the_api(client):
    """The page's DROP field (roastlab whatif --drop-at / --drop-bt): a later DROP carries the changed curves
    on to it, the table gains its DROP row and says where; a BT to drop at ends them where the changed
    BT, read as the log's probe, reaches it; a DROP that is no time is one error, not a traceback."""
    r = client.post("/api/open", json={"log": "batch1.csv", "model": "paper-model.json"}, headers=H).json()
    end = r["curves"]["time_s"][-1]
    w = client.post("/api/whatif", json={"drop_at": "+1:00"}, headers=H).json()
    assert "error" not in w, w
    assert w["curves"]["time_s"][-1] == pytest.approx(end + 60.0) and w["table"]["drop_s"] == pytest.approx(end + 60.0)
    rows = {(x["reading"], x["key"]): x for x in w["table"]["rows"]}
    assert rows["probe", "DROP_s"]["changed"] - rows["probe", "DROP_s"]["as_run"] == pytest.approx(60.0)
    bt = np.array(r["curves"]["BT_measured"], dtype=float)
    t = np.array(r["curves"]["time_s"], dtype=float)
    at = float(np.interp(0.8 * end, t, bt))  # the BT the log read at 80 % of the roast
    w = client.post("/api/whatif", json={"drop_bt": at}, headers=H).json()
    assert "error" not in w, w
    assert w["table"]["drop_s"] < end and w["curves"]["time_s"][-1] == pytest.approx(w["table"]["drop_s"])
    bad = client.post("/api/whatif", json={"drop_at": "soon"}, headers=H)
    assert bad.status_code == 400 and "not a time" in bad.json()["error"]


def test_open_gives_phases_band_fit_figures_and_the_machines_controls(client, data_dir):
    if not (data_dir / "bullet-model.json").exists():
        pytest.skip("../shared/data/real is absent")
    r = client.post("/api/open", json={"log": "logs/bullet-500g.json", "model": "bullet-model.json"}, headers=H).json()
    assert "error" not in r, r
    names = [p["name"] for p in r["phases"]]
    assert names == ["drying", "Maillard", "development"]
    assert all(a["to_s"] == b["from_s"] for a, b in zip(r["phases"], r["phases"][1:]))
    assert r["phases"][-1]["to_s"] == pytest.approx(r["curves"]["time_s"][-1])
    band = r["band"]
    lower, upper = (np.array(band[k], dtype=float) for k in ("lower", "upper"))
    bt = np.array(r["curves"]["BT_model"], dtype=float)
    assert np.all(lower <= bt + 1e-9) and np.all(bt <= upper + 1e-9) and band["median_width_C"] > 0.5
    assert 0 < r["metrics"]["FIT_pct"] <= 100 and r["metrics"]["MAE_C"] > 0
    assert r["actuators"]["heater"]["unit"] == "level" and r["actuators"]["heater"]["step"] == 1
    assert r["metrics"]["fitted_on"] is False
    assert r["model"] == "bullet-model.json"  # the page names the model its figures are from
    # the IR curve is named as the figures name it (report.figures.second_bean_reading), not as a mark
    assert (r["curves"]["beans_measured_label"], r["curves"]["beans_measured_few"]) == (
        "beans measured (second reading)",
        False,
    )
    # a roast the model was fitted on, under another name: its figures are said not to be held out
    f = client.post("/api/open", json={"log": "logs/renamed-fitted-490g.json", "model": "bullet-model.json"}, headers=H)
    assert f.json()["metrics"]["fitted_on"] is True


def test_a_program_step_through_the_api_holds_for_its_span_only(client, data_dir):
    if not (data_dir / "bullet-model.json").exists():
        pytest.skip("../shared/data/real is absent")
    r = client.post("/api/open", json={"log": "logs/bullet-500g.json", "model": "bullet-model.json"}, headers=H).json()
    t, logged = np.array(r["curves"]["time_s"]), np.array(r["curves"]["heater"])
    step = {"setting": "heater", "value": 2, "from_s": 120, "until_s": 400}
    w = client.post("/api/whatif", json={"program": [step]}, headers=H).json()
    assert "error" not in w, w
    heater = np.array(w["curves"]["heater"])
    inside = (t >= 120) & (t < 400)
    assert np.all(heater[inside] == 2) and np.array_equal(heater[~inside], logged[~inside])
    rows = {(x["reading"], x["key"]): x for x in w["table"]["rows"]}
    assert rows["beans", "DROP_C"]["changed"] < rows["beans", "DROP_C"]["as_run"]
    banded = client.post("/api/whatif", json={"program": [step], "band": True}, headers=H).json()
    lower, upper = (np.array(banded["band"][k], dtype=float) for k in ("lower", "upper"))
    bt = np.array(banded["curves"]["BT_model"], dtype=float)
    assert np.all(lower <= bt + 1e-9) and np.all(bt <= upper + 1e-9) and banded["band"]["median_width_C"] > 0.5
    assert w["band"] is None  # asked for only: the live what-if stays fast
    assert "note" not in banded["band"] and "note" not in r["band"]  # the fitted batch size
    heavier = client.post("/api/whatif", json={"batch_kg": 0.8, "band": True}, headers=H).json()
    assert "0.8 kg lies outside the batch sizes" in heavier["band"]["note"] and "unit" not in heavier["band"]["note"]
    other = client.post("/api/open", json={"log": "logs/bullet-800g-unit2054.json", "model": "bullet-model.json"},
                        headers=H).json()  # fmt: skip
    assert "0.8 kg lies outside" in other["band"]["note"] and "unit 2054 is not the roaster" in other["band"]["note"]
    bad = client.post("/api/whatif", json={"program": [{"setting": "heater", "value": "lots"}]}, headers=H)
    assert bad.status_code == 400 and "program step 1" in bad.json()["error"]
    off = client.post("/api/whatif", json={"program": [{**step, "value": 40}]}, headers=H)
    assert off.status_code == 400 and "range" in off.json()["error"]


def test_transfer_limits_and_charge_state_from_the_page(client, data_dir):
    if not (data_dir / "bullet-model.json").exists():
        pytest.skip("../shared/data/real is absent")
    r = client.post("/api/open", json={"log": "logs/bullet-500g.json", "model": "bullet-model.json"}, headers=H).json()
    lim = r["transfer_limits"]
    assert lim["decide"] == "heater" and lim["unit"] == "level" and lim["high"] > 6
    assert r["ranges"]["Tm0_C"][0] < r["Tm0_C"] < r["ranges"]["Tm0_C"][1]
    free = client.post("/api/transfer", json={"batch_kg": 0.8}, headers=H).json()
    held = client.post("/api/transfer", json={"batch_kg": 0.8, "limit_high": 6}, headers=H).json()
    assert "error" not in held, held
    assert max(free["program"]) > 6 >= max(held["program"])  # the ceiling the page gave is the program's
    assert held["metrics"]["rmse_C"] > free["metrics"]["rmse_C"]
    # the heater program as Artisan alarms, beside the program and the background: P6 moves the slider to 60
    (alrm,) = [u for u in held["downloads"] if u.endswith("-program.alrm")]
    alarms = client.get(alrm).json()
    assert alarms["alarmactions"] and set(alarms["alarmactions"]) <= {3, 6}  # Air, Burner sliders
    burner = [float(v.split(" # ")[0]) for v, a in zip(alarms["alarmstrings"], alarms["alarmactions"]) if a == 6]
    assert max(burner) <= 60 and all(v % 10 == 0 for v in burner)
    bad = client.post("/api/transfer", json={"limit_low": 7, "limit_high": 3}, headers=H)
    assert bad.status_code == 400 and "inverted" in bad.json()["error"]
    out = client.post("/api/transfer", json={"plant_to": "../plant.toml"}, headers=H)
    assert out.status_code == 400 and "outside" in out.json()["error"]
    warm = client.post("/api/whatif", json={"Tb0_C": 50}, headers=H).json()
    rows = {(x["reading"], x["key"]): x for x in warm["table"]["rows"]}
    assert rows["beans", "DRY_s"]["changed"] < rows["beans", "DRY_s"]["as_run"]  # warmer beans dry sooner


def test_the_page_transfers_another_logs_curve_with_the_programs_band(client, data_dir):
    """The page's "follow the curve of": another log's BT (unit 2054's 800 g roast) from the open log's
    settings and charge state (transfer --target), with the predicted BT's band around its prediction."""
    if not (data_dir / "bullet-model.json").exists():
        pytest.skip("../shared/data/real is absent")
    client.post("/api/open", json={"log": "logs/bullet-500g.json", "model": "bullet-model.json"}, headers=H)
    own = client.post("/api/transfer", json={"batch_kg": 0.5}, headers=H).json()
    other = client.post("/api/transfer", json={"batch_kg": 0.5, "target": "logs/bullet-800g-unit2054.json"},
                        headers=H).json()  # fmt: skip
    assert "error" not in other, other
    assert len(other["target"]) != len(own["target"])  # the other roast's span, not the open log's
    assert "bullet-800g-unit2054" in other["summary"].splitlines()[0]
    assert all(u.split("/")[-1].startswith("bullet-800g-unit2054-0.5kg") for u in other["downloads"])
    lower, upper, pred = (np.array(x, dtype=float) for x in (other["band"]["lower"], other["band"]["upper"],
                                                              other["predicted"]))  # fmt: skip
    assert np.all(lower <= pred + 0.01) and np.all(pred <= upper + 0.01) and other["band"]["median_width_C"] > 1
    out = client.post("/api/transfer", json={"target": "../../etc/passwd"}, headers=H)
    assert out.status_code == 400 and "data folder" in out.json()["error"]


def test_a_port_in_use_is_one_line_and_port_0_serves_on_a_free_one(cli, tmp_path):
    """roastlab app on a port another program holds: one line saying so and how to choose, exit 2,
    and no URL printed for a page that is not there. --port 0 takes a free port, prints it and
    serves the page there (127.0.0.1 only)."""
    import subprocess
    import sys

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        code, out, err = cli("app", "--data-dir", tmp_path, "--port", port, "--no-browser")
    assert code == 2 and f"port {port} on 127.0.0.1 is in use" in err and "--port 0" in err
    assert len(err.strip().splitlines()) == 1 and "http://" not in err
    code, _, err = cli("app", "--data-dir", tmp_path, "--host", "no-such-host.invalid", "--no-browser")
    assert code == 2 and "not an address of this machine" in err and len(err.strip().splitlines()) == 1
    cmd = [sys.executable, "-m", "roastlab", "app", "--data-dir", str(tmp_path), "--port", "0", "--no-browser"]
    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True)
    try:
        line = proc.stderr.readline()
        url = line.split()[2]
        assert url.startswith("http://127.0.0.1:") and not url.endswith(":0/"), line
        import urllib.request

        deadline = time.monotonic() + 20
        while True:
            try:
                with urllib.request.urlopen(url, timeout=5) as page:
                    assert page.status == 200 and b"roastlab" in page.read()
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.1)
    finally:
        proc.terminate()
        proc.wait(timeout=10)
        proc.stderr.close()


def test_tabs_do_not_share_state(client):
    client.post("/api/open", json={"log": "batch1.csv", "model": "paper-model.json"}, headers=H)
    other = client.post("/api/whatif", json={"tgi": 10}, headers={"X-Session": "test-session-b"}).json()
    assert "open a log" in other["error"]


@pytest.mark.parametrize(
    "body",
    [
        {"log": "../../etc/passwd", "model": "paper-model.json"},
        {"log": "/etc/passwd", "model": "paper-model.json"},
        {"log": "batch1.csv", "model": "../paper-model.json"},
    ],
)
def test_paths_outside_the_data_folder_are_refused(client, body):
    r = client.post("/api/open", json=body, headers=H)
    assert r.status_code == 400 and "data folder" in r.json()["error"]


def test_a_symlink_out_of_the_data_folder_is_refused(client, data_dir, tmp_path):
    outside = tmp_path / "secret.csv"
    outside.write_text("x\n")
    link = data_dir / "escape.csv"
    if not link.exists():
        link.symlink_to(outside)
    r = client.post("/api/open", json={"log": "escape.csv", "model": "paper-model.json"}, headers=H)
    assert r.status_code == 400 and "outside the data folder" in r.json()["error"]
    assert "escape.csv" not in client.get("/api/files", headers=H).json()["logs"]
    assert client.get("/downloads/../paper-model.json").status_code == 404


def test_a_bad_upload_is_a_message_and_is_not_kept(client, data_dir):
    r = client.post("/api/upload?name=bad.alog&model=paper-model.json", content=b"not a roast", headers=H)
    assert r.status_code == 400 and "bad.alog" in r.json()["error"]
    assert not (data_dir / "uploads" / "bad.alog").exists()
    r = client.post("/api/upload?name=run.exe", content=b"x", headers=H)
    assert r.status_code == 400 and "upload a log" in r.json()["error"]
    assert client.get("/api/files", headers=H).status_code == 200  # still answering


def test_a_log_uploaded_before_any_model_is_kept_for_a_fit(client, data_dir):
    """A roaster's first visit: no model chosen yet, a log uploaded to fit one. It is read as `init` reads
    a log, kept and listed (it was refused: "the model has none (it was fitted on batch CSVs)"); a file
    that is no roast is still refused."""
    sky = REAL_DATA / "skywalker"
    if not sky.is_dir():
        pytest.skip("../shared/data/real is absent")
    log = sorted(sky.glob("*.alog"))[0]
    r = client.post(f"/api/upload?name={log.name}", content=log.read_bytes(), headers=H)
    assert r.status_code == 200, r.json()
    assert r.json()["path"] in client.get("/api/files", headers=H).json()["logs"]
    r = client.post("/api/upload?name=bad.alog", content=b"not a roast", headers=H)
    assert r.status_code == 400 and not (data_dir / "uploads" / "bad.alog").exists()


# ------------------------------------------------------------------------------- in a browser
def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def server(data_dir):
    import uvicorn

    port = _free_port()
    srv = uvicorn.Server(uvicorn.Config(create_app(data_dir), host="127.0.0.1", port=port, log_level="warning"))
    thread = threading.Thread(target=srv.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 20
    while not srv.started and time.monotonic() < deadline:
        time.sleep(0.05)
    yield f"http://127.0.0.1:{port}"
    srv.should_exit = True
    thread.join(timeout=10)


@pytest.fixture(scope="module")
def browser():
    if CHROMIUM is None:
        pytest.skip("no chromium: install Debian's with 'apt-get install chromium' to run the browser tests")
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        yield b
        b.close()


@pytest.fixture
def page(browser, server, tmp_path):
    context = browser.new_context(accept_downloads=True, viewport={"width": 1400, "height": 1000})
    pg = context.new_page()
    pg.goto(server + "/")
    yield pg
    context.close()


def _open(page, log, model):
    page.wait_for_function("document.getElementById('log').options.length > 0")
    page.select_option("#log", log)
    page.select_option("#model", model)
    page.evaluate("delete document.body.dataset.opened")  # the page's own first Open may have set it
    page.click("#open")
    page.wait_for_function("document.body.dataset.opened !== undefined && document.getElementById('plot').data")


def _traces(page) -> dict:
    return page.evaluate("Object.fromEntries(document.getElementById('plot').data.map(t => [t.name, t.y]))")


def _longest_heater_step(page) -> dict:
    """The heater's longest program step: its shape's name and level, the middle of it on screen
    (x, y, in the window's pixels), and where three levels lower is (y_to)."""
    return page.evaluate(
        """() => { const gd = document.getElementById('plot'), sh = gd._fullLayout.shapes;
        let k = -1, best = -1;
        sh.forEach((s, i) => { if (s.name && s.name.startsWith('heater:') && s.x1 - s.x0 > best) { best = s.x1 - s.x0; k = i; } });
        const s = sh[k], xa = gd._fullLayout.xaxis, ya = gd._fullLayout.yaxis3, r = gd.getBoundingClientRect();
        return { name: s.name, level: s.y0, x: r.left + xa._offset + xa.l2p((s.x0 + s.x1) / 2),
                 y: r.top + ya._offset + ya.l2p(s.y0), y_to: r.top + ya._offset + ya.l2p(s.y0 - 3) }; }"""
    )


@pytest.mark.slow
def test_the_page_draws_a_real_log_and_follows_a_what_if(page, data_dir, tmp_path):
    if not (data_dir / "bullet-model.json").exists():
        pytest.skip("../shared/data/real is absent")
    _open(page, "logs/bullet-500g.json", "bullet-model.json")
    traces = _traces(page)
    assert {"BT measured", "BT model, as run", "heater [steps]", "fan [steps]", "90 % band, as run"} <= set(traces)
    assert len(traces["BT measured"]) > 50
    before = page.inner_text("tr[data-key='beans-DROP_C'] td.changed")
    updates = page.evaluate("Number(document.body.dataset.updates || 0)")
    page.fill("#batch_kg", "0.6")
    page.dispatch_event("#batch_kg", "input")
    page.wait_for_function(f"Number(document.body.dataset.updates || 0) > {updates}")
    after = page.inner_text("tr[data-key='beans-DROP_C'] td.changed")
    assert float(after) < float(before) - 5.0  # a heavier batch: cooler beans at DROP, in the table
    changed = _traces(page)["BT model, changed"]
    assert not np.allclose(np.array(changed, dtype=float), np.array(traces["BT model, as run"], dtype=float))
    # once the change stands still, the changed curve gets its own band, around it
    page.wait_for_function("Number(document.body.dataset.bands || 0) > 0", timeout=10_000)
    now = _traces(page)
    upper = np.array(now["90 % band, changed"], dtype=float)
    assert np.all(upper >= np.array(now["BT model, changed"], dtype=float) - 1e-6)
    assert "changed:" in page.inner_text("#figures")
    assert page.inner_text("#figures").startswith("model bullet-model.json as run against this log")
    page.screenshot(path=str(tmp_path / "whatif.png"), full_page=True)
    assert (tmp_path / "whatif.png").stat().st_size > 20_000
    # heater and fan in one unit share the settings' scale; in two (a burner in kPa, the fan in steps)
    # each its own, the fan's on the right
    layout = "document.getElementById('plot')._fullLayout"
    assert page.evaluate(f"{layout}.yaxis4 === undefined")
    model = json.loads((data_dir / "bullet-model.json").read_text())
    model["map"]["heater"]["unit"] = "kPa"
    (data_dir / "bullet-kpa-model.json").write_text(json.dumps(model))
    page.reload()
    _open(page, "logs/bullet-500g.json", "bullet-kpa-model.json")
    assert page.evaluate(f"[{layout}.yaxis3.title.text, {layout}.yaxis4.title.text]") == [
        "heater [kPa] (drag a step)",
        "fan [steps]",
    ]


def test_the_page_drops_the_changed_roast_later(page, tmp_path):
    """Type +1:00 in the DROP field: the changed curves run a minute past the logged DROP, a "DROP changed"
    mark stands there, and the table's DROP row says +1:00."""
    _open(page, "batch1.csv", "paper-model.json")
    updates = page.evaluate("Number(document.body.dataset.updates || 0)")
    page.fill("#drop", "+1:00")
    page.dispatch_event("#drop", "change")
    page.wait_for_function(f"Number(document.body.dataset.updates || 0) > {updates}")
    ends = page.evaluate(
        "Object.fromEntries(document.getElementById('plot').data.map(t => [t.name, t.x[t.x.length - 1]]))"
    )
    assert ends["BT model, changed"] == pytest.approx(ends["BT model, as run"] + 1.0, abs=1e-6)
    notes = page.evaluate("document.getElementById('plot')._fullLayout.annotations.map(a => a.text)")
    assert any(n.startswith("DROP changed") for n in notes)
    row = page.inner_text("tr[data-key='probe-DROP_s']")
    assert "+1:00" in row
    page.screenshot(path=str(tmp_path / "drop.png"), full_page=True)


@pytest.mark.slow
def test_a_program_step_dragged_with_the_mouse_changes_the_prediction(page, data_dir, tmp_path):
    """Drag the heater's longest step down with the mouse: it snaps to the machine's levels (P
    steps), the server predicts with it, and the table's changed column follows."""
    if not (data_dir / "bullet-model.json").exists():
        pytest.skip("../shared/data/real is absent")
    _open(page, "logs/bullet-500g.json", "bullet-model.json")
    before = page.inner_text("tr[data-key='beans-DROP_C'] td.changed")
    spot = _longest_heater_step(page)
    updates = page.evaluate("Number(document.body.dataset.updates || 0)")
    page.mouse.click(spot["x"], spot["y"])  # activate the step, then drag it three levels down
    page.mouse.move(spot["x"], spot["y"])
    page.mouse.down()
    page.mouse.move(spot["x"], spot["y_to"], steps=10)
    page.mouse.up()
    page.wait_for_function(f"Number(document.body.dataset.updates || 0) > {updates}")
    k = int(spot["name"].split(":")[1])
    step = page.evaluate(f"state.program.heater[{k}]")
    assert step["value"] == round(step["value"]) and step["value"] < spot["level"]  # snapped to a P level, lower
    heater = np.array(_traces(page)["heater [steps]"], dtype=float)
    t = np.array(page.evaluate("state.open.curves.time_s"), dtype=float)
    inside = (t >= step["from_s"]) & (t < step["until_s"])
    assert np.all(heater[inside] == step["value"])
    after = page.inner_text("tr[data-key='beans-DROP_C'] td.changed")
    assert float(after) < float(before)  # less heat: cooler beans at DROP
    page.screenshot(path=str(tmp_path / "drag.png"), full_page=True)


@pytest.mark.slow
def test_a_program_step_dragged_with_a_finger_changes_the_prediction(browser, server):
    """On a tablet a finger lands a few pixels off a 5-px step: it still takes the step, moves it three
    levels down (snapped to the machine's steps) with the prediction following, and the page does not
    scroll under it; sideways, it moves the step along time. A swipe away from every step leaves the program alone and scrolls the page (Plotly's
    default drag zoomed the curves instead, so the page could not be scrolled from them)."""
    if not (REAL_DATA / "bullet").is_dir():
        pytest.skip("../shared/data/real is absent")
    context = browser.new_context(viewport={"width": 820, "height": 1180}, has_touch=True, is_mobile=True)
    try:
        page = context.new_page()
        page.goto(server + "/")
        _open(page, "logs/bullet-500g.json", "bullet-model.json")
        spot = _longest_heater_step(page)
        cdp = context.new_cdp_session(page)

        def swipe(x, y0, y1, x1=None):
            x1 = x if x1 is None else x1
            cdp.send("Input.dispatchTouchEvent", {"type": "touchStart", "touchPoints": [{"x": x, "y": y0}]})
            for i in range(1, 11):
                point = {"x": x + (x1 - x) * i / 10, "y": y0 + (y1 - y0) * i / 10}
                cdp.send("Input.dispatchTouchEvent", {"type": "touchMove", "touchPoints": [point]})
            cdp.send("Input.dispatchTouchEvent", {"type": "touchEnd", "touchPoints": []})

        program = page.evaluate("JSON.stringify(state.program)")
        ranges = "JSON.stringify(['xaxis', 'yaxis'].map((a) => document.getElementById('plot')._fullLayout[a].range))"
        zoom = page.evaluate(ranges)
        top = page.evaluate(
            "(() => { const gd = document.getElementById('plot'); return gd.getBoundingClientRect().top + gd._fullLayout.yaxis._offset; })()"
        )
        swipe(spot["x"], top + 200, top + 80)  # up, over the temperature panel, far from any step
        page.wait_for_timeout(300)
        assert page.evaluate("JSON.stringify(state.program)") == program
        # it scrolls the page, as a swipe does anywhere else, rather than zooming the curves
        assert page.evaluate("window.scrollY") > 60
        assert page.evaluate(ranges) == zoom
        page.evaluate("window.scrollTo(0, 0)")
        updates = page.evaluate("Number(document.body.dataset.updates || 0)")
        miss = 9.0  # px below the step's line, where a fingertip lands
        swipe(spot["x"], spot["y"] + miss, spot["y_to"] + miss)
        page.wait_for_function(f"Number(document.body.dataset.updates || 0) > {updates}")
        page.wait_for_function("!state.busy && !state.pending")
        k = int(spot["name"].split(":")[1])
        step = page.evaluate(f"state.program.heater[{k}]")
        assert step["value"] == spot["level"] - 3  # snapped to a P level, three lower
        assert page.evaluate("window.scrollY") == 0  # the finger moved the step, not the page
        heater = np.array(_traces(page)["heater [steps]"], dtype=float)
        t = np.array(page.evaluate("state.open.curves.time_s"), dtype=float)
        assert np.all(heater[(t >= step["from_s"]) & (t < step["until_s"])] == step["value"])
        # sideways (a little off the line again): the step starts later by as much as the finger moved, on
        # the 5-s grid, as long as it was and at its level
        updates = page.evaluate("Number(document.body.dataset.updates || 0)")
        minutes = page.evaluate(
            "(() => { const xa = document.getElementById('plot')._fullLayout.xaxis; return xa.p2l(60) - xa.p2l(0); })()"
        )
        swipe(spot["x"], spot["y_to"] - miss, spot["y_to"] - miss + 3, spot["x"] + 60)
        page.wait_for_function(f"Number(document.body.dataset.updates || 0) > {updates}")
        page.wait_for_function("!state.busy && !state.pending")
        moved = page.evaluate(f"state.program.heater[{k}]")
        assert moved["from_s"] == round((step["from_s"] / 60 + minutes) * 60 / 5) * 5 > step["from_s"]
        assert (
            moved["until_s"] - moved["from_s"] == step["until_s"] - step["from_s"] and moved["value"] == step["value"]
        )
        heater = np.array(_traces(page)["heater [steps]"], dtype=float)
        assert np.all(heater[(t >= moved["from_s"]) & (t < moved["until_s"])] == step["value"])
    finally:
        context.close()


@pytest.mark.slow
def test_the_page_runs_a_transfer_and_its_downloads_load(page, tmp_path):
    from roastlab.io.importers.artisan import read_alog

    _open(page, "batch1.csv", "paper-model.json")
    page.fill("#tr_batch_kg", "100")
    page.click("#run-transfer")
    page.wait_for_function("document.body.dataset.transfer === 'done'", timeout=60_000)
    assert "RMSE" in page.inner_text("#transfer-summary")
    # the figure takes its box's width (drawn once its box is shown, not sized in a hidden one)
    drawn = page.evaluate("document.querySelector('#transfer-plot .main-svg').getBoundingClientRect().width")
    assert drawn > 0.95 * page.evaluate("document.getElementById('transfer-plot').clientWidth") > 900
    links = page.locator("#downloads a")
    assert links.count() == 2
    saved = []
    for i in range(2):
        with page.expect_download() as info:
            links.nth(i).click()
        path = tmp_path / info.value.suggested_filename
        info.value.save_as(path)
        saved.append(path)
    program = pd.read_csv(saved[0], comment="#")
    assert {"time_s", "Tgi_C", "Ta_pred_C"} <= set(program.columns) and len(program) > 50
    log = read_alog(saved[1])
    assert len(log.time_s) == len(program)


@pytest.mark.slow
def test_the_page_saves_the_what_if_as_an_artisan_background(page, tmp_path):
    """The button under the what-if writes the changed roast as an Artisan background and links it;
    the file downloads and loads; a further change takes the link away (it would be another roast's)."""
    from roastlab.io.importers.artisan import read_alog

    _open(page, "batch1.csv", "paper-model.json")
    updates = page.evaluate("Number(document.body.dataset.updates || 0)")
    page.fill("#tgi", "20")
    page.dispatch_event("#tgi", "change")
    page.wait_for_function(f"Number(document.body.dataset.updates || 0) > {updates}")
    page.click("#whatif-background")
    page.wait_for_function("document.body.dataset.background === 'done'")
    link = page.locator("#whatif_downloads a")
    assert link.count() == 1
    with page.expect_download() as info:
        link.click()
    path = tmp_path / info.value.suggested_filename
    info.value.save_as(path)
    changed = np.array(_traces(page)["BT model, changed"], dtype=float)
    assert np.max(np.abs(read_alog(path).channels["BT"] - changed)) < 0.01
    updates = page.evaluate("Number(document.body.dataset.updates || 0)")
    page.fill("#tgi", "10")
    page.dispatch_event("#tgi", "change")
    page.wait_for_function(f"Number(document.body.dataset.updates || 0) > {updates}")
    assert page.locator("#whatif_downloads a").count() == 0


@pytest.mark.slow
def test_the_page_fits_a_tablet_beside_the_roaster(browser, server):
    """At a tablet's width (820 px, portrait) the page fits the screen, and at a phone's (390 px): nothing runs off its right edge,
    the curves take the screen's width under the what-if's controls, the legend lies below the time axis's title,
    and on a wider screen (a window made wider) the figure follows the new width; made narrower, its time
    axis's ticks and the phases' names are chosen again, none running into another."""
    context = browser.new_context(viewport={"width": 820, "height": 1180})
    page = context.new_page()
    try:
        page.goto(server + "/")
        _open(page, "batch1.csv", "paper-model.json")
        assert page.evaluate("document.documentElement.scrollWidth") <= 820
        width = page.evaluate("document.getElementById('plot').clientWidth")
        assert width > 0.9 * 820
        box = "(s) => { const r = document.querySelector(s).getBoundingClientRect(); return [r.top, r.bottom]; }"
        title = page.evaluate(f"({box})('#plot .xtitle')")
        legend = page.evaluate(f"({box})('#plot .legend')")
        assert legend[0] >= title[1]
        # the what-if's controls above the curves they move, both on the first screen; the fit's and
        # the transfer's controls below, each above its own output
        top = "(s) => document.querySelector(s).getBoundingClientRect().top"
        where = {
            s: page.evaluate(f"({top})('{s}')")
            for s in (
                "#whatif-controls",
                "#plot",
                "#fit-controls",
                "#fit-output",
                "#transfer-controls",
                "#transfer-output",
            )
        }
        assert list(where) == sorted(where, key=where.get)
        assert where["#plot"] < 1180 - 400
        page.set_viewport_size({"width": 1400, "height": 1000})
        page.wait_for_function(
            "Math.abs(document.querySelector('#plot .main-svg').getBoundingClientRect().width"
            f" - document.getElementById('plot').clientWidth) < 2 && document.getElementById('plot').clientWidth > {width + 100}"
        )
        ticks = "JSON.stringify(document.getElementById('plot')._fullLayout.xaxis.tickvals)"
        assert json.loads(page.evaluate(ticks))[:3] == [0, 1, 2]  # a tick a minute where there is room
        # a phone: still nothing off the right edge (a fieldset's and a grid column's own minimum widths);
        # the page chooses its time axis's ticks again for the narrower figure (they ran into each other
        # and Plotly turned them on end), and the phases' names shrink to what their bands hold
        page.set_viewport_size({"width": 390, "height": 844})
        page.wait_for_function("document.documentElement.scrollWidth <= 390")
        page.wait_for_function(f"JSON.parse({ticks})[1] > 1")

        def apart(selector):  # the boxes of the texts ``selector`` finds, none over another
            boxes = page.evaluate(
                f"Array.from(document.querySelectorAll('{selector}')).map((e) => {{ const r = e.getBoundingClientRect(); return [r.left, r.right, r.top, r.bottom]; }})"
            )
            boxes = [b for b in boxes if b[1] > b[0]]
            over = [
                (a, b)
                for i, a in enumerate(boxes)
                for b in boxes[i + 1 :]
                if a[0] < b[1] and b[0] < a[1] and a[2] < b[3] and b[2] < a[3]
            ]
            return len(boxes) > 1 and not over

        assert apart("#plot .xtick text")
        if (REAL_DATA / "bullet").is_dir():  # a real log's phases: drying, Maillard, development
            _open(page, "logs/bullet-500g.json", "bullet-model.json")
            page.wait_for_function(f"JSON.parse({ticks})[1] > 1")
            page.wait_for_timeout(400)  # past the resize's redraw (150 ms after the last resize)
            # the legend's dozen rows under the curves leave them most of a tablet's height (233 px at 560)
            assert page.evaluate("document.getElementById('plot')._fullLayout._size.h") > 380
            assert apart("#plot .xtick text") and apart("#plot .annotation-text-g text")
    finally:
        context.close()


def _fahrenheit_log(folder: Path) -> tuple[str, str]:
    """SYNTHETIC: an Artisan log recorded in degF of a 120 kg batch (fake_alog's BT and ET), and the paper's
    model with a map that reads it (BT the probe, ET the inlet gas); their paths under ``folder``'s parent."""
    import ast

    from test_importers import fake_alog

    folder.mkdir(exist_ok=True)
    doc = ast.literal_eval(
        fake_alog(
            "F", n=600, bt=[260.0 - 0.3 * i if i < 30 else 251.0 + 0.3 * (i - 30) for i in range(600)], et=[842.0] * 600
        )
    )
    doc["weight"] = [120.0, 100.0, "Kg"]
    (folder / "roast-F.alog").write_text(repr(doc))
    FittedModel.paper("120kg").save(folder / "paper-F.json")
    model = json.loads((folder / "paper-F.json").read_text())
    model["map"] = {"format": "alog", "Ta": {"column": "BT"}, "Tgi": {"column": "ET"}, "Gg": {"constant_kg_s": 3.5}}
    (folder / "paper-F.json").write_text(json.dumps(model))
    return f"{folder.name}/roast-F.alog", f"{folder.name}/paper-F.json"


@pytest.mark.slow
def test_the_last_open_wins_when_an_earlier_answer_arrives_late(page, data_dir):
    """The page opens a log by itself as it loads; a roaster who picks another log meanwhile must see
    that one. Here the answer to an Open of the SYNTHETIC paper batch is held back until a log in degF
    has been opened and shown: arriving late, it changes nothing (before, it replaced the log the
    roaster chose last)."""
    log, model = _fahrenheit_log(data_dir / "fahrenheit")
    held = []

    def hold_the_first_paper_batch(route):
        if not held and "paper-model.json" in (route.request.post_data or ""):
            held.append(route)
        else:
            route.continue_()

    page.route("**/api/open", hold_the_first_paper_batch)
    page.reload()
    page.wait_for_function("document.getElementById('log').options.length > 0")
    page.select_option("#log", "batch1.csv")
    page.select_option("#model", "paper-model.json")
    page.click("#open")
    page.select_option("#log", log)
    page.select_option("#model", model)
    page.evaluate("delete document.body.dataset.opened")
    page.click("#open")
    page.wait_for_function("document.body.dataset.opened === 'roast-F'")
    assert held and page.input_value("#units") == "F"
    held[0].continue_()  # the earlier Open's answer arrives now
    page.wait_for_timeout(1500)
    assert page.evaluate("[document.body.dataset.opened, state.open.log]") == ["roast-F", "roast-F"]
    assert page.input_value("#units") == "F"


@pytest.mark.slow
def test_a_log_in_fahrenheit_opens_in_fahrenheit_and_its_fields_speak_it(page, data_dir):
    """An Artisan log recorded in degF opens with the page in degF: the curves, the table and the what-if's
    temperature fields (the drum at CHARGE shown in degF, asked of the server in degC); switched to degC
    the fields keep what they hold and the notes under the table follow, and a log in degC opened after keeps
    the unit the roaster chose."""
    log, model = _fahrenheit_log(data_dir / "fahrenheit")
    page.reload()  # the page lists the folder's files as it loads
    _open(page, log, model)
    assert page.input_value("#units") == "F" and "[°F]" in page.inner_text("label:has(#Tm0_C)")
    opened = page.evaluate("state.open")
    assert float(page.input_value("#Tm0_C")) == pytest.approx(opened["Tm0_C"] * 9 / 5 + 32, abs=0.05)
    assert page.evaluate("document.getElementById('plot').layout.yaxis.title.text") == "temperature [°F]"
    # 18 degF more drum at CHARGE is 10 degC more for the model
    n = page.evaluate("Number(document.body.dataset.updates || 0)")
    page.fill("#Tm0_C", str(float(page.input_value("#Tm0_C")) + 18.0))
    page.dispatch_event("#Tm0_C", "input")
    page.wait_for_function(f"Number(document.body.dataset.updates || 0) > {n}")
    assert page.evaluate("changes().Tm0_C") == pytest.approx(opened["Tm0_C"] + 10.0, abs=0.05)
    # the notes under the table speak its unit (a change within the model's error on this log, in degF)
    assert "°F against" in page.inner_text("#warnings") and "°C" not in page.inner_text("#warnings")
    page.select_option("#units", "C")
    assert float(page.input_value("#Tm0_C")) == pytest.approx(opened["Tm0_C"] + 10.0, abs=0.05)
    assert "[°C]" in page.inner_text("label:has(#Tm0_C)")
    assert "°C against" in page.inner_text("#warnings") and "°F" not in page.inner_text("#warnings")
    _open(page, "batch1.csv", "paper-model.json")
    assert page.input_value("#units") == "C"


@pytest.mark.slow
def test_a_fit_report_fits_a_phone(browser, tmp_path):
    """fit-roaster's report.html, opened on a phone (390 px): its wide tables scroll in place and the page
    is no wider than the screen (the viewport is the device's, not a desktop's 980 px zoomed out)."""
    from roastlab.report.markdown import html_document

    head = "| log | " + " | ".join(f"a long column heading {k}" for k in range(8)) + " |"
    rows = ["|---" * 9 + "|", "| roast_25-10-04_1155.alog | " + " | ".join(["85.4"] * 8) + " |"]
    (tmp_path / "report.html").write_text(html_document("report", "\n".join(["# a report", "", head, *rows]), {}))
    context = browser.new_context(viewport={"width": 390, "height": 844}, is_mobile=True)
    try:
        page = context.new_page()
        page.goto((tmp_path / "report.html").as_uri())
        assert page.evaluate("window.innerWidth") == 390  # the page says it fits the device's width
        assert page.evaluate("document.documentElement.scrollWidth") <= 390
        assert page.evaluate("document.querySelector('table').scrollWidth") > 390  # the table scrolls in place
    finally:
        context.close()


@pytest.mark.slow
def test_a_bad_upload_shows_a_message_and_the_page_keeps_working(page, tmp_path):
    _open(page, "batch1.csv", "paper-model.json")
    bad = tmp_path / "broken.alog"
    bad.write_text("{'timex': [1, 2], 'temp2': 'oops'}")
    page.set_input_files("#upload", str(bad))
    page.wait_for_function("document.getElementById('message').textContent.includes('broken.alog')")
    assert json.loads(page.evaluate("fetch('/api/files', {headers: {'X-Session': 'probe-12345'}}).then(r => r.text())"))


def test_the_server_is_not_one_run(data_dir):
    """`roastlab app` starts as a CLI command (which remembers every input it reads so no output can
    replace one) and then serves for hours: create_app ends that run, or a roaster could not be
    fitted again into the folder whose map the last fit read (seen on the page: 'map.toml is an
    input of this run'). Each of the server's writes names its own inputs instead."""
    from roastlab.app.server import create_app
    from roastlab.io.files import begin_run, inputs_read, read_input_text

    begin_run()  # as roastlab.cli.main does before the app command
    read_input_text(next(p for p in data_dir.rglob("*") if p.is_file()))
    assert inputs_read()
    create_app(data_dir)
    assert inputs_read() == []


@pytest.mark.slow
def test_a_model_is_fitted_on_the_page_in_the_background(client, data_dir):
    """roastlab init + fit-roaster behind the page: progress to poll, the report, a model listed."""
    sky = REAL_DATA / "skywalker"
    if not sky.is_dir():
        pytest.skip("../shared/data/real is absent")
    (data_dir / "sky").mkdir(exist_ok=True)
    logs = []
    for p in sorted(sky.glob("*.alog"))[:4]:
        shutil.copy(p, data_dir / "sky" / p.name)  # a temporary copy in the test's data folder
        logs.append(f"sky/{p.name}")
    r = client.post("/api/fit", json={"logs": logs, "name": "sky"}, headers=H).json()
    assert r.get("started"), r
    deadline = time.monotonic() + 180
    while True:
        st = client.get("/api/fit-status", headers=H).json()
        if not st.get("running") or time.monotonic() > deadline:
            break
        time.sleep(0.2)
    assert "error" not in st, st
    assert "held out" in st["report"] and st["held_out"]["FIT"] > 0
    assert st["model"] in client.get("/api/files", headers=H).json()["models"]
    assert st["every_log"] is None and "Every log held out once" not in st["report"]
    # the report as the page shows it: its tables as tables, its figure in place, embedded
    html = st["report_html"]
    assert "<table>" in html and "| set |" not in html and html.count('<img src="data:image/png;base64,') == 1
    # Open on the model the fit wrote shows the same report
    opened = client.post("/api/open", json={"log": logs[0], "model": st["model"]}, headers=H).json()
    assert opened["report_html"] == html
    assert st["verdict"] is None and "Not usable" not in st["report"]  # it beats the first-order baseline
    assert "| model MAE °C |" in st["report"]  # °C logs, no unit asked: the logs' own
    # the page's "also hold each log out once": fit-roaster --every-log behind it, the report in the
    # page's unit (°F chosen on the page)
    body = {"logs": logs, "name": "sky", "every_log": True, "units": "F"}
    assert client.post("/api/fit", json=body, headers=H).json()["started"]
    deadline = time.monotonic() + 300
    while (st := client.get("/api/fit-status", headers=H).json()).get("running") and time.monotonic() < deadline:
        time.sleep(0.2)
    assert "error" not in st, st
    assert "## Every log held out once" in st["report"] and -100 < st["every_log"]["FIT"] <= 100
    assert "| model MAE °F |" in st["report"] and "Temperatures in °F" in st["report"]
    # the page's "also predict other batch sizes": fit-roaster --by-size behind it; four logs of one size
    # (150-152 g) cannot, and the page says why
    one_size = ["roast_25-09-27_1236_R14", "roast_25-10-04_1155", "roast_25-10-04_1229", "roast_25-10-25_1544"]
    sized = []
    for stem in [*one_size, "roast_25-10-25_1609", "roast_25-11-16_1235"]:  # two more: 150 g and 200 g
        shutil.copy(sky / f"{stem}.alog", data_dir / "sky" / f"{stem}.alog")
        sized.append(f"sky/{stem}.alog")
    body = {"logs": sized[:4], "name": "sky", "by_size": True}
    assert client.post("/api/fit", json=body, headers=H).json()["started"]
    while (st := client.get("/api/fit-status", headers=H).json()).get("running"):
        time.sleep(0.2)
    assert "all one batch size (0.15-0.152 kg)" in st["error"], st
    assert client.post("/api/fit", json={**body, "logs": sized}, headers=H).json()["started"]
    deadline = time.monotonic() + 180
    while (st := client.get("/api/fit-status", headers=H).json()).get("running") and time.monotonic() < deadline:
        time.sleep(0.2)
    assert "error" not in st, st
    assert "## Across batch sizes" in st["report"] and "fitted on 0.15-0.152 kg (3 logs)" in st["across_sizes"]
    assert st["report_html"].count('<img src="data:image/png;base64,') == 2  # held out, FIT by batch size
    # logs with no heater or fan setting: ET drives the model, worse than the baseline here, and the page says so
    (data_dir / "bare").mkdir(exist_ok=True)
    bare = []
    for p in sorted(sky.glob("*.alog"))[:6]:
        rewritten_alog(p, data_dir / "bare" / p.name, drop_events)
        bare.append(f"bare/{p.name}")
    assert client.post("/api/fit", json={"logs": bare, "name": "bare"}, headers=H).json()["started"]
    deadline = time.monotonic() + 180
    while (st := client.get("/api/fit-status", headers=H).json()).get("running") and time.monotonic() < deadline:
        time.sleep(0.2)
    assert "error" not in st, st
    assert "no heater setting is logged" in st["verdict"] and st["report"].count("**Not usable**") == 1
    one = client.post("/api/fit", json={"logs": logs[:1]}, headers=H)
    assert one.status_code == 400 and "at least two logs" in one.json()["error"]


def test_the_fit_report_is_html_with_its_figures_in_place_and_the_logs_text_escaped(tmp_path):
    """report.md on the page: tables become tables, a figure beside the report is embedded, a
    picture naming anything else is dropped, HTML quoted from a log is shown as text; Open gives the
    report only for a model fit-roaster wrote, and not where the model was written after it."""
    import base64
    import os

    from starlette.testclient import TestClient

    from roastlab.app.server import report_html

    data = tmp_path / "data"
    folder = data / "roasters" / "r"
    folder.mkdir(parents=True)
    assert report_html(folder) is None
    png = b"\x89PNG\r\n\x1a\n" + b"figure"
    (folder / "heldout.png").write_bytes(png)
    (data / "roasters" / "outside.png").write_bytes(png)
    (folder / "report.md").write_text(
        "# r\n\nLeft out: <script>alert(1)</script>.json\n\n| log | FIT % |\n|---|---|\n| a | 90.0 |\n\n"
        "![held out](heldout.png)\n\n![x](../outside.png) ![y](report.md)\n",
        encoding="utf-8",
    )
    html = report_html(folder)
    assert "<script>" not in html and "&lt;script&gt;alert(1)&lt;/script&gt;" in html
    assert "<td>a</td>" in html and "<td>90.0</td>" in html
    assert html.count("<img") == 1 and f'src="data:image/png;base64,{base64.b64encode(png).decode()}"' in html
    assert "outside" not in html and 'src="report.md"' not in html
    # through Open: beside model.json, as fit-roaster writes them
    shutil.copy(SYNTHETIC / "dataset-I" / "batch1.csv", data / "batch1.csv")
    FittedModel.paper("120kg").save(folder / "model.json")
    FittedModel.paper("120kg").save(data / "paper-model.json")
    stamp = (folder / "model.json").stat().st_mtime
    os.utime(folder / "report.md", (stamp, stamp))
    client = TestClient(create_app(data))

    def shown(model):
        r = client.post("/api/open", json={"log": "batch1.csv", "model": model}, headers=H).json()
        assert "error" not in r, r
        return r["report_html"]

    assert shown("roasters/r/model.json") == html
    assert shown("paper-model.json") is None  # not a model fit-roaster wrote
    os.utime(folder / "report.md", (stamp - 60, stamp - 60))  # the model written again after its report
    assert shown("roasters/r/model.json") is None


def test_the_file_list_takes_a_roastime_file_without_a_suffix_for_a_log(tmp_path):
    """RoasTime keeps its roasts without a suffix: such a file is listed among the logs by its
    content; a LICENSE beside it is not."""
    from roastlab.app.server import list_files

    (tmp_path / "zl9ZdStWgBkMIm5TrsOR").write_text(json.dumps({"beanTemperature": [20.0, 21.0], "sampleRate": 2}))
    (tmp_path / "LICENSE").write_text("MIT License\n")
    assert list_files(tmp_path)["logs"] == ["zl9ZdStWgBkMIm5TrsOR"]


def test_the_what_ifs_changed_roast_is_written_as_an_artisan_background(client, data_dir, tmp_path):
    """SYNTHETIC paper batch: the page's background of a 20 degC hotter inlet is the what-if's changed
    curve (BT) and the inlet the model sees (ET, the paper model's), read back with the project's Artisan
    importer; it is served from the tab's downloads folder."""
    from roastlab.io.importers.artisan import read_alog

    assert (
        "error"
        not in client.post("/api/open", json={"log": "batch1.csv", "model": "paper-model.json"}, headers=H).json()
    )
    w = client.post("/api/whatif", json={"tgi": 20}, headers=H).json()
    r = client.post("/api/whatif-background", json={"tgi": 20}, headers=H).json()
    assert "error" not in r, r
    assert r["download"].startswith("/downloads/") and r["download"].endswith("-whatif-background.alog")
    got = client.get(r["download"])
    assert got.status_code == 200
    (tmp_path / "bg.alog").write_bytes(got.content)
    log = read_alog(tmp_path / "bg.alog")
    np.testing.assert_allclose(log.channels["BT"], np.array(w["curves"]["BT_model"], dtype=float), atol=0.006)
    np.testing.assert_allclose(log.channels["ET"], np.array(w["curves"]["ET_model"], dtype=float), atol=0.006)
    assert "Tgi +20" in r["changes"][0]
    assert r["alarms"] is None  # the paper's plant has no heater or fan slider to move
    assert client.post("/api/whatif-background", json={}, headers={"X-Session": "no-log-open"}).json()["error"]


def test_the_what_ifs_changed_settings_are_written_as_artisan_alarms(client, data_dir):
    """A Bullet log with the heater one step lower from 4:00: beside the background, the changed settings
    as Artisan alarms; the Burner slider's last value before 4:00 is one step (10, in tens) above the
    first after it."""
    if not (data_dir / "bullet-model.json").exists():
        pytest.skip("../shared/data/real is absent")
    client.post("/api/open", json={"log": "logs/bullet-500g.json", "model": "bullet-model.json"}, headers=H)
    r = client.post("/api/whatif-background", json={"heater": "-1@4:00"}, headers=H).json()
    assert "error" not in r, r
    assert r["alarms"].startswith("/downloads/") and r["alarms"].endswith("-whatif-settings.alrm")
    alarms = client.get(r["alarms"]).json()
    burner = [(s, float(v.split(" # ")[0])) for s, a, v in
              zip(alarms["alarmoffsets"], alarms["alarmactions"], alarms["alarmstrings"]) if a == 6]  # fmt: skip
    assert all(v % 10 == 0 for _, v in burner)
    before = [v for s, v in burner if s < 240][-1]
    assert [v for s, v in burner if s == 240] == [before - 10]


def test_a_second_bean_reading_is_named_as_what_it_is():
    """One rule names a batch's second bean reading on the figures and the page: a curve of readings (an
    IR sensor), the first-crack mark read as the beans (a map's [Tb2] first_crack), or none."""
    from types import SimpleNamespace

    from roastlab.model.constants import FIRST_CRACK_BEAN_C
    from roastlab.report.figures import second_bean_reading

    t = np.arange(0.0, 600.0, 5.0)
    mark = np.where(t == 480.0, FIRST_CRACK_BEAN_C, np.nan)
    ir = 30.0 + 0.3 * t
    assert second_bean_reading(SimpleNamespace(Tb2_C=ir, events={})) == ("beans measured (second reading)", False)
    label, few = second_bean_reading(SimpleNamespace(Tb2_C=mark, events={"FCs": 480.0}))
    assert few and label.startswith("beans at first crack") and "FCs" in label
    assert second_bean_reading(SimpleNamespace(Tb2_C=None, events={})) is None


def test_the_validation_figure_draws_each_second_bean_reading_as_it_is():
    """SYNTHETIC batches (the paper's model's own probe as the measurement): validate --plot drew the
    model's beans and a second reading only where that reading was scored as an output, so a first-crack
    mark read as the beans (one sample, too few to score) was missing from the figure the page and the
    what-if figure show it on. It is now a marker under the shared name; a curve of readings stays a curve."""
    from roastlab import FittedModel
    from roastlab.io.batch import Batch
    from roastlab.model.constants import FIRST_CRACK_BEAN_C
    from roastlab.report.figures import plot_fit

    model = FittedModel.paper()
    t = np.arange(0.0, 901.0, 30.0)
    base = Batch("fc", t, np.full_like(t, 0.4), np.full_like(t, 450.0))
    ta = model.predict(base).Ta_C
    mark = np.where(t == 600.0, FIRST_CRACK_BEAN_C, np.nan)
    marked = Batch("fc", t, base.Gg_kg_s, base.Tgi_C, Ta_C=ta, Tb2_C=mark, events={"FCs": 600.0})
    curve = Batch("ir", t, base.Gg_kg_s, base.Tgi_C, Ta_C=ta, Tb2_C=ta + 10.0)
    for batch, wanted, style in (
        (marked, "beans at first crack", "D"),
        (curve, "beans measured (second reading)", "None"),
    ):
        fig = plot_fit(model.validate([batch]))
        labels = [text.get_text() for text in fig.legends[0].get_texts()]
        assert "bean predicted (model Tb)" in labels and any(s.startswith(wanted) for s in labels), labels
        line = next(ln for ln in fig.axes[0].get_lines() if ln.get_label().startswith(wanted))
        assert line.get_marker() == style
