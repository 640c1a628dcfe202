"""Screenshots of the roaster's page for docs/app.md, and its measured speed (make app-screens).

Starts ``roastlab app``'s server on a temporary data folder (the SYNTHETIC paper batch and model,
and where ../shared/data/real exists, a Bullet log with a model fitted on the 490 g logs), drives
Debian's chromium with Playwright, saves docs/app-*.png (app-tablet.png the first screen at a tablet's
820 px) and prints:

* page ready: from starting the server to the curves drawn (numba's disk cache warm);
* what-if: from an input change to the new curve drawn in the browser, median of 20 changes,
  and the server's own share;
* transfer: on the page against the library call for the same case.
"""

from __future__ import annotations

import shutil
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
REAL = ROOT.parent / "shared" / "data" / "real" / "bullet"
ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
        "--disable-component-update", "--disable-sync"]  # fmt: skip


#: Where the heater's longest step is on the page, in screen pixels, and three levels below it.
DRAG_SPOT = """() => { const gd = document.getElementById('plot'), sh = gd._fullLayout.shapes;
  let k = -1, best = -1;
  sh.forEach((s, i) => { if (s.name && s.name.startsWith('heater:') && s.x1 - s.x0 > best) { best = s.x1 - s.x0; k = i; } });
  const s = sh[k], xa = gd._fullLayout.xaxis, ya = gd._fullLayout.yaxis3, r = gd.getBoundingClientRect();
  return { x: r.left + xa._offset + xa.l2p((s.x0 + s.x1) / 2), y: r.top + ya._offset + ya.l2p(s.y0),
           y_to: r.top + ya._offset + ya.l2p(s.y0 - 3) }; }"""


def long_roast(src: Path, dst: Path) -> None:
    """The paper's SYNTHETIC batch 1 (15 min, a sample every 30 s) on a 1 s grid, as densely as
    Artisan logs: the 15-minute roast the what-if latency target names (inputs and BT linearly
    interpolated; still synthetic, and the file says so)."""
    import numpy as np
    import pandas as pd

    df = pd.read_csv(src, comment="#")
    t = np.arange(0.0, df["time_s"].iloc[-1] + 0.5, 1.0)
    out = pd.DataFrame({c: np.interp(t, df["time_s"], df[c]) for c in df.columns})
    head = "## SYNTHETIC DATA: roastlab's paper batch 1 interpolated onto a 1 s grid (docs/app_screens.py)\n"
    dst.write_text(head + out.to_csv(index=False, float_format="%.4f", lineterminator="\n"))


def data_folder(d: Path) -> tuple[str, str]:
    """Fill ``d``; return the (log, model) the screenshots open."""
    import roastlab
    from roastlab.io.importers import load_map
    from roastlab.workflows.model import FittedModel, load_log

    shutil.copy(ROOT / "src/roastlab/datasets/paper-synthetic/dataset-I/batch1.csv", d / "batch1.csv")
    FittedModel.paper("120kg").save(d / "paper-model.json")
    long_roast(d / "batch1.csv", d / "paper-15min-1s.csv")
    if not REAL.is_dir():
        return "batch1.csv", "paper-model.json"
    ex = ROOT / "examples" / "bullet"
    cmap = load_map(ex / "map.toml")
    logs = sorted(p for p in REAL.glob("*.json") if p.name.endswith(("_490g.json", "_500g.json")))
    fit = roastlab.fit([load_log(p, cmap) for p in logs[0::2]], ex / "plant.toml", ex / "fit.toml", column_map=cmap)
    fit.model.save(d / "bullet-model.json")
    shutil.copy(REAL / "bullet_2020-10-01_2053_500g.json", d / "bullet_2020-10-01_2053_500g.json")
    (d / "skywalker").mkdir()
    for p in sorted((REAL.parent / "skywalker").glob("*.alog"))[:6]:
        shutil.copy(p, d / "skywalker" / p.name)  # temporary copies, removed at the end
    return "bullet_2020-10-01_2053_500g.json", "bullet-model.json"


def latencies(page, field: str, values) -> tuple[list, list]:
    """One change of ``field`` per value: from each input change to the new curve drawn [ms]
    (the page's own mark), and the server's part of it [ms]."""
    lat, server = [], []
    for v in values:
        before = page.evaluate("Number(document.body.dataset.updates || 0)")
        page.fill(field, f"{v:.4f}")
        page.dispatch_event(field, "input" if field == "#batch_kg" else "change")
        page.wait_for_function(f"Number(document.body.dataset.updates || 0) > {before}")
        page.wait_for_function("document.body.dataset.latency !== undefined")
        lat.append(float(page.evaluate("document.body.dataset.latency")))
        page.evaluate("delete document.body.dataset.latency")
        server.append(float(page.inner_text("#timing").split()[1]))
    return lat, server


def batch_steps(kg: float, n: int = 20) -> list[float]:
    """``n`` batch sizes 1 %, 2 %, ... above ``kg``."""
    return [kg * (1.0 + 0.01 * (k + 1)) for k in range(n)]


def main() -> int:
    import uvicorn
    from playwright.sync_api import sync_playwright

    from roastlab.app.server import create_app

    chromium = shutil.which("chromium")
    if chromium is None:
        print("no chromium: apt-get install chromium", file=sys.stderr)
        return 2
    d = Path(tempfile.mkdtemp(prefix="roastlab-app-"))
    log, model = data_folder(d)
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium, args=ARGS)
        page = browser.new_page(viewport={"width": 1400, "height": 1050})
        t_start = time.perf_counter()
        srv = uvicorn.Server(uvicorn.Config(create_app(d), host="127.0.0.1", port=8799, log_level="warning"))
        threading.Thread(target=srv.run, daemon=True).start()
        while not srv.started:
            time.sleep(0.01)
        page.goto("http://127.0.0.1:8799/")
        page.wait_for_function("document.getElementById('log').options.length > 0")
        page.select_option("#log", log)
        page.select_option("#model", model)
        page.click("#open")
        page.wait_for_function("document.body.dataset.opened !== undefined")
        ready_s = time.perf_counter() - t_start
        page.screenshot(path=str(DOCS / "app-open.png"), full_page=True)
        page.set_viewport_size({"width": 820, "height": 1180})  # a tablet beside the roaster: its first screen
        page.wait_for_function("document.getElementById('plot').clientWidth < 820")
        time.sleep(0.5)  # the figure's redraw at the new width
        page.screenshot(path=str(DOCS / "app-tablet.png"))
        page.set_viewport_size({"width": 1400, "height": 1050})
        page.wait_for_function("document.getElementById('plot').clientWidth > 820")
        time.sleep(0.5)

        # what-if latency: input change -> curve drawn, 20 changes
        kg = float(page.input_value("#batch_kg") or 1.0)
        lat, server = latencies(page, "#batch_kg", batch_steps(kg))
        page.fill("#batch_kg", f"{kg * 1.2:.4f}")
        page.dispatch_event("#batch_kg", "input")
        page.fill("#heater", "+1@4:00")
        page.dispatch_event("#heater", "change")
        time.sleep(0.5)
        page.screenshot(path=str(DOCS / "app-whatif.png"), full_page=True)

        page.click("#reset")  # back to the log as run, then drag the heater's longest step down
        page.wait_for_function("document.body.dataset.opened !== undefined")
        time.sleep(0.3)
        spot = page.evaluate(DRAG_SPOT)
        n = page.evaluate("Number(document.body.dataset.updates || 0)")
        page.mouse.click(spot["x"], spot["y"])
        page.mouse.move(spot["x"], spot["y"])
        page.mouse.down()
        page.mouse.move(spot["x"], spot["y_to"], steps=10)
        page.mouse.up()
        page.wait_for_function(f"Number(document.body.dataset.updates || 0) > {n}")
        time.sleep(0.3)
        page.screenshot(path=str(DOCS / "app-drag.png"), full_page=True)

        page.fill("#tr_batch_kg", f"{kg * 1.6:.3f}")
        t0 = time.perf_counter()
        page.click("#run-transfer")
        # poll every 50 ms, not on every animation frame: the server runs in a thread of this process,
        # and playwright's frame-rate polling took the GIL from it (a 0.2 s transfer measured 8.7 s)
        page.wait_for_function("document.body.dataset.transfer === 'done'", timeout=120_000, polling=50)
        page_transfer_s = time.perf_counter() - t0
        page.locator("#transfer-summary").scroll_into_view_if_needed()
        page.screenshot(path=str(DOCS / "app-transfer.png"), full_page=True)
        sky = [
            o for o in page.eval_on_selector_all("#fit_logs option", "os => os.map(o => o.value)") if "skywalker/" in o
        ]
        fit_s = None
        if sky:
            page.select_option("#fit_logs", sky)
            page.fill("#fit_name", "skywalker")
            page.check("#fit_by_size")  # the 150-152 g logs fitted, the 200 g one predicted: one fit more
            t0 = time.perf_counter()
            page.click("#run-fit")
            page.wait_for_function("document.body.dataset.fitted !== undefined", timeout=300_000)
            fit_s = time.perf_counter() - t0
            page.locator("#fit-report").scroll_into_view_if_needed()
            page.screenshot(path=str(DOCS / "app-fit.png"), full_page=True)
            fitted = page.evaluate("document.body.dataset.fitted")
            page.evaluate("delete document.body.dataset.opened")
            _ = page.select_option("#log", sky[-1]), page.select_option("#model", fitted)
            page.click("#open")
            page.wait_for_function("document.body.dataset.opened !== undefined")
            time.sleep(0.3)
            page.screenshot(path=str(DOCS / "app-skywalker.png"), full_page=True)
            sky_len = page.evaluate("[state.open.curves.time_s.length, state.open.curves.time_s.at(-1)]")
            sky_lat, sky_server = latencies(page, "#batch_kg", batch_steps(float(page.input_value("#batch_kg"))))
        page.evaluate("delete document.body.dataset.opened")
        page.select_option("#log", "paper-15min-1s.csv")
        page.select_option("#model", "paper-model.json")
        page.click("#open")
        page.wait_for_function("document.body.dataset.opened !== undefined")
        long_len = page.evaluate("[state.open.curves.time_s.length, state.open.curves.time_s.at(-1)]")
        long_lat, long_server = latencies(page, "#tgi", range(1, 21))  # inlet +1 ... +20 degC
        browser.close()
    srv.should_exit = True

    from roastlab.workflows.model import load_log, load_model
    from roastlab.workflows.transfer import transfer

    m = load_model(d / model)
    b = load_log(d / log, m.column_map) if m.column_map else load_log(d / log)
    t0 = time.perf_counter()
    transfer(m, b, batch_kg=kg * 1.6)
    lib_s = time.perf_counter() - t0
    print(f"page ready {ready_s:.2f} s after the server started (warm numba cache)")
    print(f"what-if: input change to curve drawn, median of 20: {statistics.median(lat):.1f} ms "
          f"(server {statistics.median(server):.2f} ms)")  # fmt: skip
    print(f"transfer: {page_transfer_s:.2f} s on the page, {lib_s:.2f} s as a library call")
    if fit_s is not None:
        print(f"fit on the page: 6 Skywalker logs (init + fit-roaster --by-size) in {fit_s:.1f} s")
        print(f"what-if on a Skywalker log ({sky_len[0]} samples, {sky_len[1] / 60:.1f} min), median of 20: "
              f"{statistics.median(sky_lat):.1f} ms (server {statistics.median(sky_server):.2f} ms)")  # fmt: skip
    print(f"what-if on the 15-minute synthetic roast ({long_len[0]} samples, {long_len[1] / 60:.1f} min), median of "
          f"20: {statistics.median(long_lat):.1f} ms (server {statistics.median(long_server):.2f} ms)")  # fmt: skip
    print(
        "wrote docs/app-open.png, docs/app-tablet.png, docs/app-whatif.png, docs/app-drag.png, docs/app-transfer.png, docs/app-fit.png, docs/app-skywalker.png"
    )
    shutil.rmtree(d, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
