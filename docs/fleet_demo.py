"""The real fleet demonstration of docs/fleet.md: every shared Skywalker and Bullet log as two machines.

Run from the repository root: ``.venv/bin/python docs/fleet_demo.py``. The logs are read in
place from ../shared/data/real (never copied); started_at comes from each file's name (the
logs' own date fields are not uniform across the two loggers). Each machine's model is first
identified with its example's files (``roastlab identify``, on the logs docs/real_roaster.py fits
on: every other Skywalker log, every other 490-500 g Bullet log), and every batch is then fitted
under it (``fleet fit --model``). Writes the store, the models and the report into a temporary
folder and the two figures into docs/.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data" / "real"
sys.path.insert(0, str(ROOT / "docs"))

import real_roaster  # noqa: E402  (the fit logs of docs/real-roaster.md)


def started_at(path: Path) -> str:
    m = re.search(r"(\d{2})-(\d{2})-(\d{2})(?:_(\d{2})(\d{2}))?", path.name)  # roast_25-09-27_1236
    if path.suffix == ".json":
        m = re.search(r"(\d{4})-(\d{2})-(\d{2})_(\d{2})(\d{2})", path.name)  # bullet_2020-04-07_2124
        y, mo, d, h, mi = m.groups()
    else:
        y, mo, d, h, mi = m.groups()
        y = "20" + y
    return f"{y}-{mo}-{d}T{h or '12'}:{mi or '00'}:00"


def main() -> int:
    tmp = Path(tempfile.mkdtemp(prefix="roastlab-fleet-demo-"))
    rows = ["path,machine,plant,started_at,map"]
    sky, bul = ROOT / "examples" / "skywalker", ROOT / "examples" / "bullet"
    for f in sorted((DATA / "skywalker").glob("*.alog")):
        rows.append(f"{f},skywalker,{sky / 'plant.toml'},{started_at(f)},{sky / 'map.toml'}")
    for f in sorted((DATA / "bullet").glob("*.json")):
        rows.append(f"{f},bullet,{bul / 'plant.toml'},{started_at(f)},{bul / 'map.toml'}")
    (tmp / "manifest.csv").write_text("\n".join(rows) + "\n")
    exe = str(Path(sys.executable).parent / "roastlab")
    fit_logs = {
        "skywalker": real_roaster.split(real_roaster.skywalker_logs())[0],
        "bullet": real_roaster.split(real_roaster.nominal_logs())[0],
    }
    for name, example in (("skywalker", sky), ("bullet", bul)):
        argv = ["identify", "--plant", str(example / "plant.toml"), "--map", str(example / "map.toml")]
        argv += ["--spec", str(example / "fit.toml"), "--out", str(tmp / f"{name}-model.json")]
        print(f"$ roastlab {' '.join(argv)} <{len(fit_logs[name])} {name} logs>", flush=True)
        code = subprocess.run([exe, *argv, *map(str, fit_logs[name])], stdout=subprocess.DEVNULL).returncode
        if code:
            return code
    db = str(tmp / "fleet.duckdb")
    fit = ["fit", "--db", db]
    for name, example in (("skywalker", sky), ("bullet", bul)):
        fit += ["--spec", f"{name}={example / 'fleet.toml'}", "--model", f"{name}={tmp / f'{name}-model.json'}"]
    for argv in (
        ["ingest", "--db", db, "--manifest", str(tmp / "manifest.csv")],
        fit,
        ["report", "--db", db, "--json", str(tmp / "report.json"), "--plot", str(tmp / "figs")],
    ):
        print("$ roastlab fleet " + " ".join(argv), flush=True)
        # ingest exits 2 for the one Bullet log without a green weight (rejected, the rest ingest)
        code = subprocess.run([exe, "fleet", *argv]).returncode
        if code not in ((0, 2) if argv[0] == "ingest" else (0,)):
            return code
    for name in ("skywalker", "bullet"):
        (ROOT / "docs" / f"fleet-{name}.png").write_bytes((tmp / "figs" / f"{name}.png").read_bytes())
    print(f"report: {tmp / 'report.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
