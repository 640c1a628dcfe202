"""Importers: the shared real Artisan logs, Artisan CSV, generic CSV/Parquet, Pitot flow."""

import ast
import json
from pathlib import Path

import numpy as np
import pytest

from conftest import REAL_DATA
from roastlab.errors import InputError
from roastlab.io.importers import gas_flow_pitot_kg_s, import_log, load_map
from roastlab.io.importers.artisan import ET_BEFORE_CHARGE, events_internal_to_external, read_alog, read_artisan_csv

SPOT = ["roast_25-09-27_1236_R14.alog", "roast_25-11-16_1235.alog", "roast_26-05-10_1438_R58_brazil_250.alog"]


def write_map(tmp_path, text, name="map.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


SKY_MAP = '[Ta]\ncolumn = "BT"\n[Tgi]\ncolumn = "ET"\n[Gg]\nidentify = true\n'
ROOM_AIR_MAP = '[Ta]\ncolumn = "BT"\n[Tgi]\nconstant_C = 22.0\n[Gg]\nidentify = true\n'


def test_all_shared_logs_import(real_data, tmp_path):
    cmap = load_map(write_map(tmp_path, SKY_MAP))
    logs = sorted(real_data.glob("*.alog"))
    assert len(logs) == 16
    for path in logs:
        b = import_log(path, cmap)
        assert b.time_s[0] == 0.0 and b.n > 100
        assert 0.1 <= b.Mb_kg <= 0.3
        assert 90 < b.Ta_C.min() and b.Ta_C.max() < 230


@pytest.mark.parametrize("name", SPOT)
def test_charge_and_drop_match_artisan_computed(real_data, name):
    path = real_data / name
    computed = ast.literal_eval(path.read_text())["computed"]
    log = read_alog(path)
    assert log.time_s[0] == 0.0
    assert log.events["DROP"] == pytest.approx(computed["DROP_time"], abs=0.05)
    assert log.time_s[-1] == pytest.approx(computed["DROP_time"], abs=0.05)
    assert log.channels["BT"][0] == pytest.approx(computed["CHARGE_BT"], abs=0.05)
    assert log.channels["ET"][0] == pytest.approx(computed["CHARGE_ET"], abs=0.05)
    assert log.channels["BT"][-1] == pytest.approx(computed["DROP_BT"], abs=0.05)
    assert log.events["FCs"] == pytest.approx(computed["FCs_time"], abs=0.05)
    full = read_alog(path, keep_after_drop=True)
    assert full.time_s[-1] > log.time_s[-1]


def test_probe_fault_is_cut_with_a_note(real_data, tmp_path):
    b = import_log(real_data / "roast_25-10-25_1609.alog", load_map(write_map(tmp_path, SKY_MAP)))
    assert b.Ta_C.max() < 200
    assert any("probe fault" in n for n in b.notes)


def test_probe_spikes_are_dropped_and_a_step_that_stays_is_cut(tmp_path):
    """SYNTHETIC: a reading that leaps and comes back within seconds (a thermocouple's pick-up) is a
    few samples dropped, not a fault that ends the roast at half time; a step that stays is cut."""
    bt = [130.0 - 0.2 * i if i < 30 else 124.0 + 0.5 * (i - 30) for i in range(120)]
    spiky = list(bt)
    spiky[60] += 150.0  # one sample, 90 s into a 180 s log
    spiky[80] -= 80.0
    spiky[81] -= 80.0  # two samples
    cmap = load_map(write_map(tmp_path, ROOM_AIR_MAP))
    (tmp_path / "s.alog").write_text(fake_alog(bt=spiky))
    (tmp_path / "c.alog").write_text(fake_alog(bt=bt))
    b, clean = import_log(tmp_path / "s.alog", cmap), import_log(tmp_path / "c.alog", cmap)
    assert b.n == clean.n - 3 and b.time_s[-1] == clean.time_s[-1]
    kept = np.isin(clean.time_s, b.time_s)  # the clean log's samples at the spiky log's times
    assert np.array_equal(b.Ta_C, clean.Ta_C[kept]) and np.diff(clean.time_s[~kept]).tolist() == [30.0, 1.5]
    assert any("dropped 3 sample(s) of bean-probe spikes at t = " in n for n in b.notes), b.notes
    stays = list(bt)
    stays[90:] = [v - 45.0 for v in stays[90:]]  # 45 degC down for the rest of the roast: a fault
    (tmp_path / "f.alog").write_text(fake_alog(bt=stays))
    f = import_log(tmp_path / "f.alog", cmap)
    assert any("probe fault" in n for n in f.notes) and f.n < clean.n - 15  # cut before the step
    assert np.array_equal(f.Ta_C, clean.Ta_C[: f.n]) and f.time_s[-1] == clean.time_s[f.n - 1]


def test_an_alog_whose_time_stumbles_keeps_its_samples_marks_and_events(tmp_path):
    """SYNTHETIC Artisan log with a time stamp repeated at sample 40, one that goes back at sample 70
    and a null BT reading at sample 90 (as a converter writes one not taken): those samples are
    dropped, not the log (it was refused: "time not strictly increasing"); the marks and events that
    index the samples keep their times."""
    n = 120
    extra = {"timeindex": [5, 0, 60, 0, 0, 0, n - 1, 0], **_burner_at(50, 8.0)}  # DROP on the last sample
    clean = json.loads(fake_alog(n=n, extra=extra, as_json=True))
    glitchy = json.loads(json.dumps(clean))
    glitchy["timex"][40] = glitchy["timex"][39]
    glitchy["timex"][70] = glitchy["timex"][69] - 0.5
    glitchy["temp2"][90] = None
    (tmp_path / "c.alog").write_text(json.dumps(clean))
    (tmp_path / "g.alog").write_text(json.dumps(glitchy))
    a, b = read_alog(tmp_path / "c.alog"), read_alog(tmp_path / "g.alog")
    assert len(b.time_s) == len(a.time_s) - 2 and np.isnan(b.channels["BT"]).sum() == 1
    assert (
        b.events == a.events and b.notes[0] == "dropped 2 sample(s) whose time does not follow the one before (timex)"
    )
    kept = np.isin(a.time_s, b.time_s)
    assert np.array_equal(b.channels["Burner"], a.channels["Burner"][kept], equal_nan=True)
    cmap = load_map(write_map(tmp_path, ROOM_AIR_MAP))
    assert import_log(tmp_path / "g.alog", cmap).n == import_log(tmp_path / "c.alog", cmap).n - 3
    glitchy["timex"] = [0.0] * n
    (tmp_path / "g.alog").write_text(json.dumps(glitchy))
    with pytest.raises(InputError, match="fewer than 2 samples follow one another"):
        read_alog(tmp_path / "g.alog")


def test_a_csv_log_whose_time_stumbles_keeps_its_rows_in_order(tmp_path):
    """SYNTHETIC plain CSV log with a row repeated and one stamped before the row above it: those rows
    are dropped with a note, not the log (it was refused: "time not strictly increasing")."""
    rows = ["time_s,BT,Burner"] + [f"{2.0 * i},{150.0 - i if i < 30 else 90.0 + i},60" for i in range(100)]
    (tmp_path / "c.csv").write_text("\n".join(rows) + "\n")
    rows.insert(41, rows[40])  # row 40 again
    rows[71] = "55.0,150,60"  # before the row above it
    (tmp_path / "g.csv").write_text("\n".join(rows) + "\n")
    cmap = load_map(write_map(tmp_path, 'resample_s = 5.0\n[time]\ncolumn = "time_s"\n' + ROOM_AIR_MAP))
    a, b = import_log(tmp_path / "c.csv", cmap), import_log(tmp_path / "g.csv", cmap)
    assert np.array_equal(a.time_s, b.time_s) and np.array_equal(a.Ta_C, b.Ta_C)
    assert "dropped 2 sample(s) whose time does not follow the one before" in b.notes


def test_an_artisan_csv_export_with_a_row_stamped_back_drops_that_row(tmp_path):
    """SYNTHETIC Artisan CSV export with one row stamped a minute back among the others: that row is
    dropped with a note (the export was refused: time not strictly increasing)."""
    rows = ["Date:01.01.2026\tUnit:C\tCHARGE:00:00\tDROP:03:00", "Time1\tTime2\tET\tBT\tEvent"]
    rows += [f"{s // 60:02d}:{s % 60:02d}\t{s // 60:02d}:{s % 60:02d}\t{200 + s * 0.1:.1f}\t{120 + s * 0.3:.1f}\t"
             for s in range(0, 182, 2)]  # fmt: skip
    rows.insert(40, "00:14\t01:14\t207.4\t142.2\t")
    (tmp_path / "e.csv").write_text("\n".join(rows) + "\n")
    b = import_log(tmp_path / "e.csv", load_map(write_map(tmp_path, SKY_MAP)))
    assert b.n == 91 and np.all(np.diff(b.time_s) > 0) and b.time_s[-1] == 180.0
    assert "dropped 1 sample(s) whose time does not follow the one before" in b.notes


def _burner_at(sample: int, internal: float) -> dict:
    """SYNTHETIC Burner events: 70 % from the start, ``internal`` (Artisan's encoding) from ``sample``."""
    return {"specialevents": [0, sample], "specialeventstype": [3, 3], "specialeventsvalue": [8.0, internal],
            "etypes": ["Air", "Drum", "Damper", "Burner", "--"]}  # fmt: skip


def test_special_events_become_step_signals(real_data):
    log = read_alog(real_data / "roast_25-11-16_1235.alog")
    burner = log.channels["Burner"]
    assert np.nanmax(burner) <= 100 and np.nanmin(burner) >= 0
    assert len(np.unique(burner[np.isfinite(burner)])) > 2  # steps, not a constant
    assert events_internal_to_external(8.0) == 70 and events_internal_to_external(11.0) == 100
    assert events_internal_to_external(0.5) == 0 and events_internal_to_external(1.0) == 0


def fake_alog(mode="C", bt=None, et=None, n=120, extra=None, as_json=False):
    t = [1.5 * i for i in range(n)]
    bt = bt if bt is not None else [130.0 - 0.2 * i if i < 30 else 124.0 + 0.5 * (i - 30) for i in range(n)]
    et = et if et is not None else [150.0 + 0.4 * i for i in range(n)]
    d = {
        "mode": mode,
        "timex": t,
        "temp1": et,
        "temp2": bt,
        "timeindex": [5, 0, 0, 0, 0, 0, n - 10, 0],
        "weight": [200.0, 170.0, "g"],
    }
    d.update(extra or {})
    return json.dumps(d) if as_json else repr(d)


def test_fahrenheit_log_converted_but_not_non_temperature_extras(tmp_path):
    n = 120
    btF = [266.0 + 0.9 * i for i in range(n)]
    etF = [300.0 + 0.9 * i for i in range(n)]
    extra = {
        "extratimex": [[1.5 * i for i in range(n)]],
        "extraname1": ["Inlet"],
        "extratemp1": [[752.0] * n],
        "extraname2": ["Fan"],
        "extratemp2": [[40.0] * n],
        "extraNoneTempHint1": [False],
        "extraNoneTempHint2": [True],
    }
    p = tmp_path / "f.alog"
    p.write_text(fake_alog("F", btF, etF, n, extra))
    log = read_alog(p)
    assert log.channels["BT"][0] == pytest.approx((btF[5] - 32) * 5 / 9)
    assert log.channels["Inlet"][0] == pytest.approx(400.0)  # a temperature: converted
    assert log.channels["Fan"][0] == pytest.approx(40.0)  # flagged non-temperature: untouched
    assert log.weight_in_kg == pytest.approx(0.2)


def test_a_batch_keeps_the_unit_its_log_was_recorded_in(tmp_path):
    """Artisan's profile mode goes with the batch (its values are degC either way): a roaster who logs in
    degF gets degF tables and figures by default (whatif, the page)."""
    for mode in ("C", "F"):
        p = tmp_path / f"{mode}.alog"
        p.write_text(fake_alog(mode))
        b = import_log(p, None)  # Artisan's defaults: BT the probe
        assert b.temp_unit == mode


#: SYNTHETIC extra devices laid out as Artisan's Aillio R1 setup writes them: ``{3}``/``{0}`` are the
#: heater and fan readouts named after the event types, beside a fan speed in rpm.
AILLIO_LIKE_EXTRAS = {
    "etypes": ["Fan", "Drum", "Damper", "Heater", "--"],
    "extraname1": ["{3}", "Voltage"],
    "extraname2": ["{0}", "Fan RPM"],
    "extraNoneTempHint1": [True, True],
    "extraNoneTempHint2": [True, True],
}


def _aillio_like(n: int, events: bool) -> dict:
    extra = dict(AILLIO_LIKE_EXTRAS)
    extra["extratimex"] = [[1.5 * i for i in range(n)]] * 2
    extra["extratemp1"] = [[6.0] * n, [230.0] * n]
    extra["extratemp2"] = [[3.0] * n, [2400.0] * n]
    if events:  # Heater 70 %, Fan 20 % in Artisan's encoding
        extra.update(specialevents=[5, 5], specialeventstype=[3, 0], specialeventsvalue=[8.0, 3.0])
    return extra


@pytest.mark.parametrize("events", [True, False])
def test_extra_device_names_are_filled_from_the_event_types(tmp_path, events):
    """Artisan shows ``{3}`` as the fourth event type's name; a readout whose name is an event type
    with events in the log is kept apart from those events (the events are the setting made)."""
    n = 120
    p = tmp_path / "a.alog"
    p.write_text(fake_alog(n=n, extra=_aillio_like(n, events)))
    log = read_alog(p)
    assert "{3}" not in log.channels and "Voltage" in log.channels and "Fan RPM" in log.channels
    if events:
        assert log.channels["Heater"][0] == 70.0 and log.channels["Fan"][0] == 20.0
        assert log.channels["Heater readout"][0] == 6.0 and log.channels["Fan readout"][0] == 3.0
    else:
        assert log.channels["Heater"][0] == 6.0 and log.channels["Fan"][0] == 3.0
        assert "Heater readout" not in log.channels


def test_a_name_field_outside_the_event_types_is_left_as_written(tmp_path):
    n = 120
    extra = _aillio_like(n, False)
    extra["etypes"] = ["Fan", "Drum"]
    p = tmp_path / "a.alog"
    p.write_text(fake_alog(n=n, extra=extra))
    assert "{3}" in read_alog(p).channels and "Fan" in read_alog(p).channels


def test_a_weight_in_pounds_reads_as_the_grams_it_was(tmp_path):
    p = tmp_path / "lb.alog"
    p.write_text(fake_alog(extra={"weight": [152.0 / 453.59237, 130.0 / 453.59237, "lb"]}))
    assert read_alog(p).weight_in_kg == 0.152  # to a tenth of a gram, so messages print 0.152 kg


def test_json_alog_and_missing_samples(tmp_path):
    n = 120
    bt = [130.0 - 0.2 * i if i < 30 else 124.0 + 0.5 * (i - 30) for i in range(n)]
    bt[50] = -1
    p = tmp_path / "j.alog"
    p.write_text(fake_alog(bt=bt, n=n, as_json=True))
    b = import_log(p, load_map(write_map(tmp_path, SKY_MAP)))
    assert b.n == (n - 10) - 5 + 1 - 1  # CHARGE..DROP, one missing sample dropped
    assert any("incomplete" in note for note in b.notes)


def test_an_artisan_log_without_a_map_reads_bt_and_et(tmp_path):
    """Artisan's own channel names are the default for an Artisan log: BT the probe, ET the inlet."""
    p = tmp_path / "plain.alog"
    p.write_text(fake_alog())
    b = import_log(p, None)
    assert b.Ta_C[0] == pytest.approx(130.0 - 0.2 * 5) and b.Tgi_C[0] == pytest.approx(150.0 + 0.4 * 5)
    assert any("no map" in note and "BT" in note for note in b.notes)


def test_artisan_csv_export(tmp_path):
    rows = [
        "Date:01.01.2026\tUnit:C\tCHARGE:00:06\tTP:\tDRYe:\tFCs:\tFCe:\tSCs:\tSCe:\tDROP:03:00\tCOOL:",
        "Time1\tTime2\tET\tBT\tEvent",
    ]
    for i in range(0, 200, 2):
        t2 = "" if i < 6 else f"{(i - 6) // 60:02d}:{(i - 6) % 60:02d}"
        rows.append(f"{i // 60:02d}:{i % 60:02d}\t{t2}\t{150 + i * 0.2:.1f}\t{120 + i * 0.3:.1f}\t")
    p = tmp_path / "export.csv"
    p.write_text("\n".join(rows) + "\n")
    b = import_log(p, load_map(write_map(tmp_path, SKY_MAP)))
    assert b.time_s[0] == 0 and b.time_s[-1] == pytest.approx(174.0)
    assert b.Ta_C[0] == pytest.approx(121.8)
    # ET's median over the rows before CHARGE (0, 2, 4 s: 150.0, 150.4, 150.8), kept for an ET that reads beans
    assert read_artisan_csv(p).fields == {ET_BEFORE_CHARGE: pytest.approx(150.4)}


def _csv_export_with_extras(path, clock="14:05"):
    """SYNTHETIC Artisan CSV export (the layout of Artisan's exportCSV) with its first line's marks and
    two extra devices: "{3}"/"{0}" (the Burner and Air event types' names, as Artisan's Kaleido setup
    names its extra device) and "Inlet Temp"/"Drum RPM", in degF; CHARGE at 0:06 on the Time1 axis, the
    recording started at ``clock``."""
    head = (
        "Date:01.01.2026\tUnit:F\tCHARGE:00:06\tTP:01:00\tDRYe:04:06\tFCs:07:36\tFCe:\tSCs:\tSCe:\tDROP:09:06"
        f"\tCOOL:\tTime:{clock}"
    )
    rows = [head, "Time1\tTime2\tET\tBT\tEvent\t{3}\t{0}\tInlet Temp\tDrum RPM"]
    for i in range(0, 560, 2):
        t2 = "" if i < 6 else f"{(i - 6) // 60:02d}:{(i - 6) % 60:02d}"
        burner = 70.0 if i < 300 else 55.0
        rows.append(f"{i // 60:02d}:{i % 60:02d}\t{t2}\t{350 + i * 0.2:.1f}\t{250 + i * 0.3:.1f}\t\t"
                    f"{burner}\t{30.0 if i < 200 else -1}\t{572.0:.1f}\t60")  # fmt: skip
    path.write_text("\n".join(rows) + "\n")
    return path


def test_an_artisan_csv_export_keeps_its_marks_and_extra_devices(cli, tmp_path):
    """Artisan's CSV export lists DRY END and first crack on its first line and writes each extra device's
    two channels after the Event column: the reader keeps the marks (seconds after CHARGE) and the
    channels under their names; from degF it converts ET, BT and an extra channel its name calls a
    temperature, and leaves a burner's percent as written (-1: a missing sample)."""
    log = read_artisan_csv(_csv_export_with_extras(tmp_path / "e.csv"))
    assert log.events == {"CHARGE": 0.0, "DRY": 240.0, "FCs": 450.0, "DROP": 540.0}
    assert log.started_epoch_s == 1767276300.0  # Date and Time on its first line: 2026-01-01 14:05
    assert log.channels["Burner"][0] == 70.0 and log.channels["Burner"][-1] == 55.0
    assert log.channels["Air"][0] == 30.0 and np.isnan(log.channels["Air"][-1])
    assert log.channels["Inlet Temp"][0] == pytest.approx(300.0)  # 572 degF
    assert log.channels["BT"][0] == pytest.approx((251.8 - 32.0) / 1.8)
    assert log.temperature_channels == {"ET", "BT", "Inlet Temp"} and log.channels["Drum RPM"][0] == 60.0
    # the reader's marks serve init as an .alog's do: the burner and air are found, first crack is read
    f = _csv_export_with_extras(tmp_path / "f.csv", clock="15:20")  # another roast: recorded later
    code, out, err = cli("init", log.path, f, "--out", tmp_path / "cfg", "--batch-kg", "0.2")
    assert code == 0 and "heater: Burner (percent); fan: Air (percent)" in out, err
    assert "2 of 2 log(s) mark first crack" in out, out


def test_an_artisan_csv_export_marked_wrong_or_without_settings_is_one_line_naming_why(tmp_path):
    """SYNTHETIC exports: DROP marked before CHARGE is refused as an .alog's is (it was an IndexError
    with a map that reads the drum at CHARGE from a channel); a heater column with no finite reading
    names the column that left no complete sample."""
    good = _csv_export_with_extras(tmp_path / "e.csv")
    text = good.read_text()
    early = tmp_path / "early.csv"
    early.write_text(text.replace("DROP:09:06", "DROP:00:02"))
    with pytest.raises(InputError, match=r"DROP \(00:02\) is marked at or before CHARGE \(0:06"):
        read_artisan_csv(early)
    heater_map = load_map(
        write_map(
            tmp_path, 'format = "alog"\n' + ROOM_AIR_MAP + '[heater]\ncolumn = "Burner"\n[initial]\nTm0_C = "ET"\n'
        )
    )
    with pytest.raises(InputError, match="DROP"):
        import_log(early, heater_map)
    lines = text.splitlines()
    blank = tmp_path / "noburner.csv"  # the Burner's cells all infinite: no reading
    blank.write_text("\n".join(lines[:2] + [_with_cell(row, 5, "inf") for row in lines[2:]]) + "\n")
    with pytest.raises(InputError, match=r"no readings in heater \(column Burner\)"):
        import_log(blank, heater_map)


def _with_cell(row: str, k: int, value: str) -> str:
    """A tab-separated ``row`` with its cell ``k`` replaced by ``value``."""
    cells = row.split("\t")
    cells[k] = value
    return "\t".join(cells)


def test_a_log_of_another_program_than_the_maps_is_one_line_naming_both(tmp_path):
    """SYNTHETIC logs: a RoasTime log under a map of Artisan logs (a Skywalker model given a Bullet's log)
    said "key timex: missing key", an .alog under a RoasTime map "not valid JSON"; each now names both
    programs. An Artisan CSV export under an .alog map still reads (one program, two formats)."""
    roastime = tmp_path / "bullet.json"
    roastime.write_text('{"beanTemperature": [20.0, 21.0], "sampleRate": 2}')
    alog = tmp_path / "sky.alog"
    alog.write_text(fake_alog())
    alog_map = load_map(write_map(tmp_path, 'format = "alog"\n' + ROOM_AIR_MAP))
    rt_map = load_map(write_map(tmp_path, 'format = "roastime"\n' + ROOM_AIR_MAP, "rt.toml"))
    with pytest.raises(InputError, match="a RoasTime log, and the column map reads Artisan logs"):
        import_log(roastime, alog_map)
    with pytest.raises(InputError, match="an Artisan log, and the column map reads RoasTime logs"):
        import_log(alog, rt_map)
    assert import_log(_csv_export_with_extras(tmp_path / "e.csv"), alog_map).n > 2


def test_a_map_of_artisan_logs_reads_their_csv_exports_and_one_rule_tells_logs_from_batch_csvs(tmp_path):
    """A map written for .alog files (format "alog", as init writes it) reads Artisan's CSV export of the
    same roaster too, the channels being Artisan's names in both; reads_as_log, the one rule that
    validate, simulate and whatif use, tells such a log, a plain CSV log and a batch CSV apart."""
    from roastlab.io.importers.mapping import reads_as_log

    export = _csv_export_with_extras(tmp_path / "e.csv")
    alog_map = load_map(write_map(tmp_path, 'format = "alog"\n' + ROOM_AIR_MAP + '[heater]\ncolumn = "Burner"\n'))
    b = import_log(export, alog_map)
    assert b.heater[0] == 70.0 and b.heater[-1] == 55.0 and b.events["FCs"] == 450.0
    batch = tmp_path / "batch.csv"
    batch.write_text("time_s,Gg_kg_s,Tgi_C,Ta_C\n0,0.4,200,120\n5,0.4,200,118\n")
    plain = tmp_path / "plain.csv"
    plain.write_text("seconds,bean temp,burner\n0,120,70\n5,118,70\n")
    csv_map = load_map(write_map(tmp_path, 'format = "csv"\n' + SKY_MAP, "csv.toml"))
    assert reads_as_log(export, alog_map) and not reads_as_log(batch, alog_map)
    tsv = tmp_path / "e.tsv"  # the same export saved as .tsv (or .txt): a text table like a .csv
    tsv.write_bytes(export.read_bytes())
    assert reads_as_log(tsv, alog_map) and import_log(tsv, alog_map).events["FCs"] == 450.0
    assert reads_as_log(plain, csv_map) and not reads_as_log(batch, csv_map)
    assert reads_as_log(tmp_path / "r.alog", None) and not reads_as_log(export, None)
    # a model reads each as the rule says (the CLI's read_inputs and the page use it): the export through
    # its map, a batch CSV as it is, and a raw log it has no map for is one line saying so
    from types import SimpleNamespace

    from roastlab.workflows.model import load_log_for

    model = SimpleNamespace(column_map=alog_map)
    assert load_log_for(export, model).events["FCs"] == 450.0
    assert load_log_for(batch, model).Ta_C.tolist() == [120.0, 118.0]
    with pytest.raises(InputError, match="a raw log needs a column map"):
        load_log_for(tmp_path / "r.alog", SimpleNamespace(column_map=None))
    with pytest.raises(InputError, match="choose a model fitted on this roaster's logs"):  # the page, none chosen
        load_log_for(tmp_path / "r.alog", None)


def test_an_artisan_csv_export_with_repeated_whole_seconds_is_averaged(tmp_path):
    """SYNTHETIC export sampled every 0.5 s: the export's whole seconds repeat each time twice; the rows
    sharing a time are averaged (it was refused: time not strictly increasing)."""
    rows = ["Date:01.01.2026\tUnit:C\tCHARGE:00:00\tDROP:02:00", "Time1\tTime2\tET\tBT\tEvent"]
    for k in range(0, 242):
        s = k // 2  # 0.5 s apart, written as whole seconds
        rows.append(f"{s // 60:02d}:{s % 60:02d}\t{s // 60:02d}:{s % 60:02d}\t{200 + k * 0.1:.2f}\t{120 + k:.1f}\t")
    p = tmp_path / "fast.csv"
    p.write_text("\n".join(rows) + "\n")
    log = read_artisan_csv(p)
    assert np.all(np.diff(log.time_s) == 1.0) and log.time_s[-1] == 120.0
    assert log.channels["BT"][:2].tolist() == [120.5, 122.5]  # each second the mean of its two rows
    assert log.notes[0].startswith("121 time stamp(s) repeat")


def test_generic_csv_with_units_and_pitot(tmp_path):
    t = np.arange(0, 601, 10.0)
    lines = ["t_min,bean_F,inlet_K,dp_Pa,pitotT_C"] + [
        f"{v / 60},{(30 + v * 0.3) * 9 / 5 + 32},{450 + 273.15},{120.0},{200.0}" for v in t
    ]
    p = tmp_path / "plant.csv"
    p.write_text("\n".join(lines) + "\n")
    m = write_map(
        tmp_path,
        '[time]\ncolumn = "t_min"\nunit = "min"\n[Ta]\ncolumn = "bean_F"\nunit = "F"\n[Tgi]\ncolumn = "inlet_K"\nunit = "K"\n'
        '[Gg.pitot]\ndp_column = "dp_Pa"\nT_column = "pitotT_C"\nsection_m2 = 0.05\n',
    )
    b = import_log(p, load_map(m))
    assert b.temp_unit == "F"  # the unit the log recorded BT in, what a roaster's tables show by default
    np.testing.assert_allclose(b.time_s, t)
    np.testing.assert_allclose(b.Ta_C, 30 + t * 0.3, atol=1e-9)
    np.testing.assert_allclose(b.Tgi_C, 450.0)
    np.testing.assert_allclose(b.Gg_kg_s, gas_flow_pitot_kg_s(120.0, 200.0, 0.05))


def test_flow_units(tmp_path):
    p = tmp_path / "f.csv"
    p.write_text("time_s,Ta_C,Tgi_C,flow\n0,30,450,1440\n30,40,450,1440\n")
    b = import_log(p, load_map(write_map(tmp_path, '[Gg]\ncolumn = "flow"\nunit = "kg/h"\n')))
    assert b.Gg_kg_s[0] == pytest.approx(0.4)
    b = import_log(p, load_map(write_map(tmp_path, '[Gg]\ncolumn = "flow"\nunit = "m3/h"\ndensity_kg_m3 = 1.0\n')))
    assert b.Gg_kg_s[0] == pytest.approx(0.4)


def test_a_raw_csv_logs_empty_cell_is_a_sample_not_taken(tmp_path):
    """A raw log read through a map: an empty cell drops its row with a note (as an Artisan -1 does);
    a batch CSV stays strict (tests/test_bad_input.py)."""
    p = tmp_path / "gaps.csv"
    p.write_text("time_s,Ta_C,Tgi_C,flow\n0,30,450,1440\n30,,450,1440\n60,50,450,1440\n")
    b = import_log(p, load_map(write_map(tmp_path, '[Gg]\ncolumn = "flow"\nunit = "kg/h"\n')))
    assert b.time_s.tolist() == [0.0, 60.0] and any("dropped 1 incomplete sample" in n for n in b.notes)


def test_pitot_formula_eq16():
    # Gg = S sqrt(2 rho0 dp 273.15 / (T + 273.15)); at T = 0 degC: S sqrt(2 rho0 dp)
    assert gas_flow_pitot_kg_s(100.0, 0.0, 0.05) == pytest.approx(0.05 * np.sqrt(2 * 1.275 * 100.0))
    hot = gas_flow_pitot_kg_s(100.0, 273.15, 0.05)
    assert hot == pytest.approx(0.05 * np.sqrt(1.275 * 100.0))  # twice the absolute temperature


def test_parquet(tmp_path):
    pd = pytest.importorskip("pandas")
    pytest.importorskip("pyarrow")
    frame = pd.DataFrame(
        {"time_s": [0.0, 30.0, 60.0], "Gg_kg_s": [0.4] * 3, "Tgi_C": [450.0] * 3, "Ta_C": [30.0, 50.0, 70.0]}
    )
    p = tmp_path / "b.parquet"
    frame.to_parquet(p)
    b = import_log(p, None)
    assert b.n == 3 and b.Ta_C[-1] == 70.0


def test_a_parquet_with_a_duplicated_column_is_one_line(cli, tmp_path):
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    cols = [
        pa.array([0.0, 30.0, 60.0]),
        pa.array([0.4] * 3),
        pa.array([450.0] * 3),
        pa.array([30.0] * 3),
        pa.array([31.0] * 3),
    ]
    pq.write_table(pa.table(cols, names=["time_s", "Gg_kg_s", "Tgi_C", "Ta_C", "Ta_C"]), tmp_path / "d.parquet")
    code, _, err = cli("import", tmp_path / "d.parquet", "--out", tmp_path / "o.csv")
    assert code == 2 and "more than once" in err and err.count("\n") == 1, err


def test_parquet_columns_are_checked_from_the_footer(cli, tmp_path, monkeypatch):
    """Only the columns the map reads are decoded: a junk list column beside them is ignored,
    a wanted column of lists, strings or integers-with-gaps is judged by its type, and the wanted
    columns' decoded size is bounded from the footer's page sizes."""
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    from roastlab.errors import InputError
    from roastlab.io.importers import mapping

    base = {"time_s": [0.0, 30.0, 60.0], "Gg_kg_s": [0.4] * 3, "Tgi_C": [450, None, 450], "Ta_C": [30.0, 50.0, 70.0]}
    junk = pa.array([[1.0] * 50] * 3)
    pq.write_table(pa.table({**base, "junk": junk}), tmp_path / "ok.parquet")
    b = import_log(tmp_path / "ok.parquet", None)  # an integer column with a gap: that sample is dropped, said
    assert b.n == 2 and b.Ta_C[-1] == 70.0 and "incomplete" in " ".join(b.notes)
    pq.write_table(pa.table({**base, "Ta_C": [["a"], ["b"], ["c"]]}), tmp_path / "lists.parquet")
    code, _, err = cli("import", tmp_path / "lists.parquet", "--out", tmp_path / "o.csv")
    assert code == 2 and "column Ta_C" in err and "not one number per row" in err and err.count("\n") == 1, err
    monkeypatch.setattr(mapping, "MAX_PARQUET_DECODED_BYTES", 100)
    with pytest.raises(InputError, match="would decode to"):
        import_log(tmp_path / "ok.parquet", None)
    assert not (tmp_path / "o.csv").exists()


def test_import_cli_then_simulate(cli, real_data, tmp_path):
    m = write_map(tmp_path, SKY_MAP)
    out = tmp_path / "batch.csv"
    code, stdout, err = cli("import", real_data / SPOT[1], "--map", m, "--out", out)
    assert code == 0, err
    text = out.read_text()
    assert "# Mb_kg = 0.2" in text and "time_s,Gg_kg_s,Tgi_C,Ta_C" in text
    from roastlab.io.batch import read_batch_csv

    assert read_batch_csv(out).Mb_kg == pytest.approx(0.2)
    plant = Path(__file__).parents[1] / "examples" / "skywalker" / "plant.toml"
    code, _, err = cli("simulate", "--plant", plant, "--inputs", out, "--out", tmp_path / "sim.csv")
    assert code == 0, err
    # a 200 g log on the 120 kg plant is a mismatch worth an error, not a silent answer
    code, _, err = cli("simulate", "--plant", "120kg", "--inputs", out, "--out", tmp_path / "sim2.csv")
    assert code == 2 and "wrong plant" in err


def test_inputs_never_modified(cli, real_data, tmp_path):
    src = real_data / SPOT[0]
    before = src.read_bytes()
    cli("import", src, "--map", write_map(tmp_path, SKY_MAP), "--out", tmp_path / "o.csv")
    assert src.read_bytes() == before


def test_an_artisan_logs_et_is_kept_beside_the_model_and_survives_the_batch_csv(tmp_path):
    """ET (Artisan's temp1) is read from every Artisan log as ``Batch.ET_C``: drawn beside the
    model, never an input (the Skywalker map's inlet stays room air), kept by the batch CSV with
    its gaps (an ET that read nothing, Artisan's -1, is a gap, not a sample dropped)."""
    from roastlab.io.batch import read_batch_csv, write_batch_csv

    n = 120
    et = [150.0 + 0.4 * i for i in range(n)]
    et[40] = -1
    p = tmp_path / "et.alog"
    p.write_text(fake_alog(et=et, n=n))
    raw = read_alog(p)
    b = import_log(p, load_map(write_map(tmp_path, ROOM_AIR_MAP)))
    assert b.ET_C is not None and b.ET_C.size == b.n
    assert np.isnan(b.ET_C).sum() == 1  # the -1 sample only
    ok = np.isfinite(b.ET_C)
    assert np.allclose(b.ET_C[ok], raw.channels["ET"][: b.n][ok])
    assert np.all(b.Tgi_C == 22.0)  # not the inlet: the map's inlet is what it says
    write_batch_csv(tmp_path / "b.csv", b)
    back = read_batch_csv(tmp_path / "b.csv")
    assert np.array_equal(np.isnan(back.ET_C), np.isnan(b.ET_C))
    assert np.allclose(back.ET_C[ok], b.ET_C[ok], atol=1e-4)


def test_a_map_names_et_where_the_log_calls_it_something_else(tmp_path):
    p = tmp_path / "et.alog"
    extra = {
        "extratimex": [[1.5 * i for i in range(80)]],
        "extraname1": ["Exhaust"],
        "extratemp1": [[200.0 + i for i in range(80)]],
    }
    p.write_text(fake_alog(n=80, extra=extra))
    b = import_log(p, load_map(write_map(tmp_path, ROOM_AIR_MAP + '[ET]\ncolumn = "Exhaust"\n')))
    assert b.ET_C[0] == pytest.approx(205.0)
    # a name this log does not record: the log is read without ET, and the note names what it has
    b = import_log(p, load_map(write_map(tmp_path, ROOM_AIR_MAP + '[ET]\ncolumn = "Nope"\n')))
    assert b.ET_C is None
    (note,) = [n for n in b.notes if n.startswith("ET: no channel 'Nope' in the log (has: ")]
    assert "Exhaust" in note and note.endswith("so it is neither fitted nor scored")


def test_a_list_of_control_names_is_checked_and_serves_logs_not_csv(tmp_path):
    """A ``[heater]`` column may list the names a roaster's logs give it; a list repeating a name is
    refused, and a CSV map names its one column."""
    from roastlab.errors import InputError
    from roastlab.io.importers.mapping import map_from_mapping

    base = {"Ta": {"column": "BT"}, "Tgi": {"constant_C": 22.0}, "Gg": {"identify": True}}
    cmap = map_from_mapping({**base, "heater": {"column": ["Burner", "Power"]}}, "m.toml")
    assert cmap.heater["column"] == ["Burner", "Power"]
    with pytest.raises(InputError, match="list of names, each once"):
        map_from_mapping({**base, "heater": {"column": ["Burner", "Burner"]}}, "m.toml")
    csv = tmp_path / "r.csv"
    csv.write_text("time_s,BT,Burner\n0,20,50\n1,21,50\n")
    csv_map = map_from_mapping(
        {**base, "time": {"column": "time_s"}, "heater": {"column": ["Burner", "Power"]}}, "m.toml"
    )
    with pytest.raises(InputError, match="a CSV or Parquet map names its one column"):
        import_log(csv, csv_map)


def test_et_below_bt_through_the_roast_is_dropped_when_the_map_asks(tmp_path):
    """[ET] above_BT: a log whose ET reads below BT from 1:00 on loses ET (with a note) and its drum
    at charge falls back to the next source; a log whose ET runs above BT keeps both; without the
    flag nothing changes. Synthetic logs (fake_alog)."""
    from roastlab.errors import InputError
    from roastlab.metrics.profile import et_minus_bt_C

    n = 120
    bt = [130.0 - 0.2 * i if i < 30 else 124.0 + 0.5 * (i - 30) for i in range(n)]
    low, high = tmp_path / "low.alog", tmp_path / "high.alog"
    low.write_text(fake_alog(bt=bt, et=[b - 30.0 for b in bt], n=n))  # an ET 30 degC under the beans
    high.write_text(fake_alog(bt=bt, et=[b + 15.0 for b in bt], n=n))
    flagged = ROOM_AIR_MAP + '[ET]\ncolumn = "ET"\nabove_BT = true\n[initial]\nTm0_C = ["ET", "BT"]\n'
    b = import_log(low, load_map(write_map(tmp_path, flagged)))
    assert b.ET_C is None and any("below BT" in note and "neither fitted nor scored" in note for note in b.notes)
    assert b.initial["Tm0_C"] == pytest.approx(bt[5])  # BT at CHARGE (index 5), not ET's
    b = import_log(high, load_map(write_map(tmp_path, flagged)))
    assert b.ET_C is not None and b.initial["Tm0_C"] == pytest.approx(bt[5] + 15.0)
    plain = ROOM_AIR_MAP + '[ET]\ncolumn = "ET"\n[initial]\nTm0_C = "ET"\n'
    b = import_log(low, load_map(write_map(tmp_path, plain)))
    assert b.ET_C is not None and b.initial["Tm0_C"] == pytest.approx(bt[5] - 30.0)
    only_et = ROOM_AIR_MAP + '[ET]\ncolumn = "ET"\nabove_BT = true\n[initial]\nTm0_C = ["ET"]\n'
    with pytest.raises(InputError, match="initial.Tm0_C: no field or channel"):
        import_log(low, load_map(write_map(tmp_path, only_et)))
    for bad, words in (("above_BT = 1", "true or false"), ("above_BT = true\n[initial]\nTm0_C = []", "list of names")):
        with pytest.raises(InputError, match=words):
            load_map(write_map(tmp_path, ROOM_AIR_MAP + '[ET]\ncolumn = "ET"\n' + bad + "\n"))
    # the rule's window starts past the charge dip and skips Artisan's -1
    t = np.arange(0.0, 300.0, 5.0)
    et = np.where(t < 60, 500.0, 100.0)
    et[20] = -1.0
    assert et_minus_bt_C(t, et, np.full(t.size, 120.0)) == pytest.approx(-20.0)
    assert et_minus_bt_C(t[:5], et[:5], np.full(5, 120.0)) is None


def test_an_et_below_bt_that_drives_the_model_refuses_the_log_naming_it(tmp_path):
    """With no heater logged the map takes ET as the inlet air. Where ET reads below BT through the
    roast (a sensor elsewhere) dropping it as a reading would leave it driving the model, the beans
    heated by a sensor that was not in the drum: the log is refused, naming it and why (fit-roaster
    leaves it out); a log whose ET runs above BT is read. A CSV map the same. Synthetic logs."""
    from roastlab.errors import InputError

    n = 120
    bt = [130.0 - 0.2 * i if i < 30 else 124.0 + 0.5 * (i - 30) for i in range(n)]
    low, high = tmp_path / "low.alog", tmp_path / "high.alog"
    low.write_text(fake_alog(bt=bt, et=[b - 30.0 for b in bt], n=n))
    high.write_text(fake_alog(bt=bt, et=[b + 15.0 for b in bt], n=n))
    et_inlet = (
        '[Ta]\ncolumn = "BT"\n[Tgi]\ncolumn = "ET"\n[Gg]\nidentify = true\n[ET]\ncolumn = "ET"\nabove_BT = true\n'
    )
    cmap = load_map(write_map(tmp_path, et_inlet))
    with pytest.raises(InputError, match="below BT.*drives the model with it as the inlet air") as exc:
        import_log(low, cmap)
    assert str(exc.value).startswith(str(low))
    b = import_log(high, cmap)
    assert b.ET_C is not None and b.Tgi_C[10] == pytest.approx(bt[15] + 15.0)  # CHARGE at index 5
    csv = tmp_path / "low.csv"
    csv.write_text("time_s,BT,ET\n" + "".join(f"{5 * i},{v},{v - 30.0}\n" for i, v in enumerate(bt[5:])))
    csv_map = load_map(write_map(tmp_path, 'batch_kg = 0.2\n[time]\ncolumn = "time_s"\n' + et_inlet))
    with pytest.raises(InputError, match="inlet air"):
        import_log(csv, csv_map)


def test_the_drum_at_charge_of_an_artisan_log_is_bt_else_et(tmp_path):
    """roastlab.io.importers.artisan.DRUM_AT_CHARGE, as init writes it: BT at CHARGE, and ET where a
    log has no BT reading then (Artisan's -1) instead of refusing the log. Synthetic logs (fake_alog)."""
    from roastlab.io.importers.artisan import DRUM_AT_CHARGE

    sources = ", ".join(f'"{c}"' for c in DRUM_AT_CHARGE)
    cmap = load_map(write_map(tmp_path, ROOM_AIR_MAP + f"[initial]\nTm0_C = [{sources}]\n"))
    n = 120
    bt = [130.0 - 0.2 * i if i < 30 else 124.0 + 0.5 * (i - 30) for i in range(n)]
    et = [150.0 + 0.4 * i for i in range(n)]
    whole, gap = tmp_path / "whole.alog", tmp_path / "gap.alog"
    whole.write_text(fake_alog(bt=bt, et=et, n=n))
    gap.write_text(fake_alog(bt=bt[:5] + [-1.0] + bt[6:], et=et, n=n))  # BT missing at CHARGE (index 5)
    assert import_log(whole, cmap).initial["Tm0_C"] == pytest.approx(bt[5])
    assert import_log(gap, cmap).initial["Tm0_C"] == pytest.approx(et[5])


def test_the_skywalker_examples_drop_et_on_the_three_oldest_logs(real_data):
    """On the shared Skywalker logs the example's map drops ET where it reads below BT: the three
    September-October 2025 logs (docs/real-roaster.md), and keeps it on the 13 later ones."""
    cmap = load_map(Path(__file__).resolve().parents[1] / "examples" / "skywalker" / "map.toml")
    dropped = sorted(p.stem for p in real_data.glob("*.alog") if import_log(p, cmap).ET_C is None)
    assert dropped == ["roast_25-09-27_1236_R14", "roast_25-10-04_1155", "roast_25-10-04_1229"]


def test_init_flags_an_et_that_reads_below_bt_unlike_the_machines_other_logs():
    """A sensor that moved shows as logs far below the others (flagged); one sensor's spread about a
    small negative offset does not (numbers: the Skywalker's medians and a synthetic spread)."""
    from roastlab.metrics.profile import et_not_drum_air

    sky = [-32.2, -38.1, -31.3, 8.9, 1.7, 24.8, 21.9, 28.1, 12.7, 16.8, 18.6, 19.8, 23.0, 17.3, 21.9, 16.8]
    assert et_not_drum_air(sky) == [True] * 3 + [False] * 13
    assert not any(et_not_drum_air([8.3, -6.7, -2.9, 0.4, 3.1, -10.3]))
    assert et_not_drum_air([-30.0, None, 20.0]) == [False] * 3  # two known logs say nothing about a spread


def test_an_et_sensor_moved_on_a_third_of_the_logs_is_still_flagged_and_one_sensors_spread_seldom():
    """A third of the logs with the sensor elsewhere widen the spread of all the logs until none
    lies far below it; the split into two groups still finds them (the Skywalker's first ten logs
    by name, three moved). SYNTHETIC draws, seeded: logs of one sensor position (a normal spread
    about 0) are flagged little more often than by the median rule alone, and machines whose
    sensor moved on 3 of 10 or 5 of 12 logs (30-40 degC below BT, the others 0-30 above) are found
    far more often (profile.TWO_SENSORS_SHARE states the larger draw)."""
    from roastlab.metrics.profile import _far_below_C, et_not_drum_air

    sky10 = [-32.2, -38.1, -31.3, 8.9, 1.7, 24.8, 21.9, 28.1, 12.7, 16.8]
    assert not any(np.asarray(sky10) < _far_below_C(sky10))  # the median rule alone misses them
    assert et_not_drum_air(sky10) == [True] * 3 + [False] * 7
    rng = np.random.default_rng(0)
    draws = 300
    for n in (6, 10):
        one = [rng.normal(0.0, 5.0, n) for _ in range(draws)]
        by_median = np.mean([np.any(d < _far_below_C(d)) for d in one])
        by_split = np.mean([any(et_not_drum_air(d)) for d in one])
        assert by_median <= by_split <= by_median + 0.08, (n, by_median, by_split)
    for n, moved in ((10, 3), (12, 5)):
        two = [np.r_[rng.uniform(-40, -30, moved), rng.uniform(0, 30, n - moved)] for _ in range(draws)]
        by_median = np.mean([np.all(d[:moved] < _far_below_C(d)) for d in two])
        by_split = np.mean([all(et_not_drum_air(d)[:moved]) for d in two])
        assert by_median < 0.4 and by_split > 0.9, (n, moved, by_median, by_split)


def test_an_et_that_falls_to_the_green_beans_at_charge_reads_the_beans():
    """SYNTHETIC readings: an infrared bean sensor logged as ET reads the green beans as they land
    (25 degC) while the probe cools only to its turning point (100 degC); a drum-air ET dips to about
    the probe's low, or (roastlab's model of a big batch in a gas drum) 0.4 of the way from the room
    to it. Undecided without both readings in the first minute, or with a probe at the room's."""
    from roastlab.metrics.profile import BEANS_IN_VIEW_S, et_reads_beans

    t = np.arange(0.0, 300.0, 2.0)
    bt = np.where(t < 60, 150.0 - 50.0 * t / 60, 100.0 + 0.4 * (t - 60))
    ir = 25.0 + 0.6 * t
    assert et_reads_beans(t, ir, bt, 22.0) is True
    assert et_reads_beans(t, bt - 10.0, bt, 22.0) is False  # the Skywalker's air: 91 degC against 99 at most
    assert et_reads_beans(t, np.where(t < 40, 40.0, bt), bt, 22.0) is False  # (40-22) > 0.2 (100-22)
    assert et_reads_beans(t, np.where(t < 40, 36.0, bt), bt, 22.0) is True
    late = t > BEANS_IN_VIEW_S
    assert et_reads_beans(t, np.where(late, ir, np.nan), bt, 22.0) is None
    assert et_reads_beans(t, np.zeros(t.size), bt, 22.0) is False  # an unconnected channel reading 0
    assert et_reads_beans(t, np.full(t.size, -52.2), bt, 22.0) is None  # below -1 degC: no reading (Aillio's "Exhaust")
    assert et_reads_beans(t, np.full(t.size, 5.0), bt, 22.0) is False  # below the room and flat: reads nothing
    assert et_reads_beans(t, ir, np.full(t.size, 20.0), 22.0) is None


def test_the_shared_logs_et_reads_the_beans_on_the_bullet_only():
    """The Bullet's IR reading (RoasTime's drumTemperature, what Artisan's IBTS device logs as ET)
    reads the beans on all 28 logs; the Skywalker's ET, the drum's air, on none of its 16."""
    from conftest import REAL_DATA
    from roastlab.io.importers.roastime import read_roastime
    from roastlab.metrics.profile import et_reads_beans

    if not (REAL_DATA / "bullet").is_dir() or not (REAL_DATA / "skywalker").is_dir():
        pytest.skip("../shared/data/real is absent")
    bullet = [read_roastime(p) for p in sorted((REAL_DATA / "bullet").glob("*.json"))]
    sky = [read_alog(p) for p in sorted((REAL_DATA / "skywalker").glob("*.alog"))]
    assert len(bullet) >= 28 and len(sky) >= 16
    assert all(et_reads_beans(g.time_s, g.channels["drumTemperature"], g.channels["BT"], 22.0) for g in bullet)
    assert not any(et_reads_beans(g.time_s, g.channels["ET"], g.channels["BT"], 22.0) for g in sky)


def test_the_room_temperature_a_log_records_sets_the_inlet_air_and_the_beans_at_charge(tmp_path):
    """[Tgi] room = true: the inlet air is the room temperature the log records (Artisan's
    ambientTemp in the profile's mode, RoasTime's typed text with the map's room_unit for a bare
    number), the constant where a log has none or where the entry is no room's (with a note);
    [initial] Tb0_C = "Tgi" starts the beans at that air. Synthetic logs (fake_alog, a RoasTime
    JSON written here)."""
    from roastlab.errors import InputError
    from roastlab.io.importers.artisan import room_from_text

    room_map = ROOM_AIR_MAP.replace("constant_C = 22.0\n", "constant_C = 22.0\nroom = true\n")
    room_map += '[initial]\nTb0_C = "Tgi"\n'
    cmap = load_map(write_map(tmp_path, room_map))
    for mode, value, want in (("C", 8.0, 8.0), ("F", 50.0, 10.0)):
        p = tmp_path / f"room_{mode}.alog"
        p.write_text(
            fake_alog(mode, extra={"ambientTemp": value})
            if mode == "C"
            else fake_alog(
                "F",
                [266.0 + 0.9 * i for i in range(120)],
                [300.0 + 0.9 * i for i in range(120)],
                120,
                {"ambientTemp": value},
            )
        )
        b = import_log(p, cmap)
        assert np.all(b.Tgi_C == pytest.approx(want)) and b.initial["Tb0_C"] == pytest.approx(want)
    unset = tmp_path / "unset.alog"
    unset.write_text(fake_alog(extra={"ambientTemp": 0.0}))  # Artisan's "not entered"
    b = import_log(unset, cmap)
    assert np.all(b.Tgi_C == 22.0) and b.initial["Tb0_C"] == 22.0 and not b.notes
    # without room = true the log's entry is not read
    b = import_log(tmp_path / "room_C.alog", load_map(write_map(tmp_path, ROOM_AIR_MAP)))
    assert np.all(b.Tgi_C == 22.0)

    def roastime(ambient, key="ambientTemp"):
        d = {
            "sampleRate": 1,
            "weightGreen": 500,
            "beanTemperature": [150.0 - 2 * i if i < 30 else 90 + i for i in range(200)],
            "drumTemperature": [200.0] * 200,
            "actions": {"actionTimeList": [{"index": 0, "value": 6, "ctrlType": 0}]},
            key: ambient,
        }
        p = tmp_path / f"rt_{key}_{len(str(ambient))}.json"
        p.write_text(json.dumps(d))
        return p

    rt_map = room_map.replace("[Ta]", 'format = "roastime"\n[Ta]') + ""
    for unit, text, key, want in (
        ("F", "72", "ambientTemp", 22.222),
        ("F", "18 C", "ambient", 18.0),
        ("C", "64 F", "ambient", 17.778),
        ("C", "19.5", "ambientTemp", 19.5),
    ):
        m = load_map(write_map(tmp_path, rt_map.replace("room = true\n", f'room = true\nroom_unit = "{unit}"\n')))
        b = import_log(roastime(text, key), m)
        assert b.Tgi_C[0] == pytest.approx(want, abs=1e-3) and b.initial["Tb0_C"] == pytest.approx(want, abs=1e-3)
    for text, words in (("85", "not a room's (85 degC)"), ("warm", "not a number"), (10**400, "not a number")):
        b = import_log(roastime(text), load_map(write_map(tmp_path, rt_map)))  # a bare 85 read as degC
        assert b.Tgi_C[0] == 22.0 and any(words in note and "constant_C used" in note for note in b.notes)
    assert room_from_text("21,5 °C") == room_from_text("21,5 °C") and room_from_text("21,5 °C").value == 21.5
    for bad, words in (("room = 1", "true or false"), ('room_unit = "K"', "room_unit needs room")):
        with pytest.raises(InputError, match=words):
            load_map(write_map(tmp_path, ROOM_AIR_MAP.replace("constant_C = 22.0\n", f"constant_C = 22.0\n{bad}\n")))
    with pytest.raises(InputError, match="needs constant_C"):
        load_map(write_map(tmp_path, SKY_MAP.replace('column = "ET"\n', 'column = "ET"\nroom = true\n', 1)))
    with pytest.raises(InputError, match="room_unit"):
        load_map(write_map(tmp_path, room_map.replace("room = true\n", 'room = true\nroom_unit = "K"\n')))


@pytest.mark.parametrize("preheat", [230.0, 0, None])
def test_roastime_drum_at_charge_is_the_preheat_else_the_ir_reading_then(tmp_path, preheat):
    """SYNTHETIC RoasTime log: roastime.DRUM_AT_CHARGE (the map init writes) takes the preheat, and
    the IR reading at charge where the log has none (absent, or RoasTime's 0 for "not set")."""
    from roastlab.io.importers.roastime import DRUM_AT_CHARGE

    d = {
        "sampleRate": 1,
        "weightGreen": 500,
        "beanTemperature": [150.0 - 2 * i if i < 30 else 90 + i for i in range(200)],
        "drumTemperature": [200.0] * 200,
        "drumChargeTemperature": 221.5,
        "actions": {"actionTimeList": [{"index": 0, "value": 6, "ctrlType": 0}]},
    }
    if preheat is not None:
        d["preheatTemperature"] = preheat
    p = tmp_path / "rt.json"
    p.write_text(json.dumps(d))
    sources = ", ".join(f'"{c}"' for c in DRUM_AT_CHARGE)
    m = load_map(write_map(tmp_path, f'format = "roastime"\n[Ta]\ncolumn = "beanTemperature"\n[Tgi]\n'
                                     f'constant_C = 22.0\n[Gg]\nconstant_kg_s = 0.01\n[initial]\nTm0_C = [{sources}]\n'))  # fmt: skip
    assert import_log(p, m).initial["Tm0_C"] == (preheat or 221.5)


def test_a_roastime_log_without_a_map_is_read_as_a_bullet(tmp_path):
    """SYNTHETIC RoasTime log imported with no map: the bean probe, the heater and fan levels over the
    room air (the quantity table's room), the IR from SECOND_BEAN_START_S, the drum at the preheat,
    with a note that says so; before, it stopped on a map for CSV columns ('no channel Ta_C')."""
    from roastlab.io.importers.mapping import SECOND_BEAN_START_S
    from roastlab.model.quantities import default

    n = 200
    d = {
        "sampleRate": 1,
        "weightGreen": "480",
        "preheatTemperature": 235,
        "beanTemperature": [150.0 - 2 * i if i < 30 else 90 + i for i in range(n)],
        "drumTemperature": [300.0 - i for i in range(n)],
        "actions": {"actionTimeList": [{"index": 0, "value": 6, "ctrlType": 0}, {"index": 0, "value": 2, "ctrlType": 1},
                                       {"index": 100, "value": 4, "ctrlType": 0}]},
    }  # fmt: skip
    p = tmp_path / "rt.json"
    p.write_text(json.dumps(d))
    b = import_log(p, None)
    assert b.Mb_kg == pytest.approx(0.48) and b.initial["Tm0_C"] == 235.0
    assert np.all(b.Tgi_C == default("T_room_C")) and b.Ta_C[0] == 150.0
    assert b.heater[0] == 6 and b.heater[-1] == 4 and np.all(b.fan == 2)
    ir = b.Tb2_C
    assert np.all(np.isnan(ir[b.time_s < SECOND_BEAN_START_S])) and ir[b.time_s >= SECOND_BEAN_START_S][0] < 300.0
    assert any(note.startswith("no map: read as a Bullet's defaults") for note in b.notes)
    # a log with no fan change, no IR channel and no reading of the drum at charge: read without them
    for key in ("drumTemperature", "preheatTemperature"):
        del d[key]
    d["actions"]["actionTimeList"] = [a for a in d["actions"]["actionTimeList"] if a["ctrlType"] == 0]
    p.write_text(json.dumps(d))
    b = import_log(p, None)
    assert b.fan is None and b.Tb2_C is None and "Tm0_C" not in b.initial and b.heater[-1] == 4
    (note,) = [n for n in b.notes if n.startswith("no map")]
    assert "the heater levels over room air" in note and "the IR" not in note and "drum at charge" not in note


def test_a_log_without_the_maps_second_bean_reading_is_read_without_it(tmp_path):
    """SYNTHETIC RoasTime log with no IR channel, read with the Bullet example's map, whose [Tb2] names
    it: the log is read with its probe alone and a note, as a log whose ET is not the drum's air is,
    rather than refused (a prediction, a what-if and a fit that has other logs with the IR go on)."""
    from conftest import REPO

    n = 200
    d = {
        "sampleRate": 1,
        "weightGreen": 480,
        "preheatTemperature": 235,
        "beanTemperature": [150.0 - 2 * i if i < 30 else 90 + i for i in range(n)],
        "actions": {"actionTimeList": [{"index": 0, "value": 6, "ctrlType": 0}, {"index": 0, "value": 2, "ctrlType": 1}]},
    }  # fmt: skip
    p = tmp_path / "rt.json"
    p.write_text(json.dumps(d))
    cmap = load_map(REPO / "examples" / "bullet" / "map.toml")
    assert cmap.Tb2["column"] == "drumTemperature"
    b = import_log(p, cmap)
    assert b.Tb2_C is None and b.Ta_C[0] == 150.0 and b.initial["Tm0_C"] == 235.0
    (note,) = [n for n in b.notes if n.startswith("Tb2: no channel 'drumTemperature' in the log (has: ")]
    assert "beanTemperature" in note and note.endswith("so it is neither fitted nor scored")
    d["drumTemperature"] = [300.0 - i for i in range(n)]  # with it, it is read as before
    p.write_text(json.dumps(d))
    b = import_log(p, cmap)
    assert np.isfinite(b.Tb2_C).sum() > 0 and not any(note.startswith("Tb2:") for note in b.notes)


def test_a_roastworld_export_steps_its_settings_at_their_seconds(tmp_path):
    """SYNTHETIC roast in RoastWorld's export layout, 2 samples/s over 99.5 s (no sampleRate): Power 6
    from the start and 4 from 50 s, Blower 2, the IR as ``ibtsTemperature``, ``ambient`` 0 (none
    typed); a control it does not model (``Drum``) and one it does not know are passed over."""
    n = 200
    d = {
        "weightGreen": 480,
        "totalRoastTime": 99.5,
        "preheatTemperature": 235,
        "ambient": 0,
        "beanTemperature": [150.0 - i if i < 60 else 30 + i for i in range(n)],
        "ibtsTemperature": [235.0] + [25.0 + i for i in range(n - 1)],
        "actions": [{"type": "Power", "second": 0, "setting": 6}, {"type": "Blower", "second": 0, "setting": 2},
                    {"type": "Drum", "second": 0, "setting": 9}, {"type": "Power", "second": 50, "setting": 4},
                    {"type": "Extra", "second": 10, "setting": 1}],
    }  # fmt: skip
    p = tmp_path / "rw.json"
    p.write_text(json.dumps(d))
    from roastlab.io.importers.roastime import read_roastime

    b = import_log(p, None)
    assert b.time_s[1] == 0.5 and b.n == n and read_roastime(p).room is None  # 0: no room typed
    assert np.all(b.heater[b.time_s < 50] == 6) and np.all(b.heater[b.time_s >= 50] == 4) and np.all(b.fan == 2)
    assert np.nanmax(b.Tb2_C) == 25.0 + n - 2 and b.initial["Tm0_C"] == 235.0
    assert any("no sampleRate: 2 samples/s from totalRoastTime (99.5 s over 200 samples)" in n for n in b.notes)


def as_roastworld(doc: dict) -> dict:
    """A RoasTime log rewritten as RoastWorld's roast export lays it out (its public API's roast
    detail: the IR curve as ``ibtsTemperature``, ``actions`` as ``[{type, second, setting}]``, no
    ``sampleRate`` nor roast bounds, ``ambient`` 0 where no room was typed). Written here from the
    export's field list, not taken from roastlab: the test checks the reader against it."""
    rate, start = doc["sampleRate"], doc.get("roastStartIndex", 0)
    end = doc.get("roastEndIndex") or len(doc["beanTemperature"])
    out = {k: v for k, v in doc.items() if k not in ("sampleRate", "roastStartIndex", "roastEndIndex", "actions")}
    for key in ("beanTemperature", "drumTemperature", "exitTemperature", "beanDerivative", "ibtsDerivative"):
        if key in out:
            out[key] = out[key][start:end]
    out["ibtsTemperature"] = out.pop("drumTemperature")
    out["totalRoastTime"] = (end - 1 - start) / rate
    kinds = {0: "Power", 1: "Blower", 2: "Drum"}
    out["actions"] = [
        {"type": kinds[a["ctrlType"]], "second": max(a["index"] - start, 0) / rate, "setting": a["value"]}
        for a in doc["actions"]["actionTimeList"]
        if a["ctrlType"] in kinds
    ]
    for key in ("indexYellowingStart", "indexFirstCrackStart", "indexFirstCrackEnd"):
        if out.get(key):
            out[key] = out[key] - start
    out["ambient"] = out.pop("ambientTemp", 0) or 0
    return out


@pytest.mark.skipif(not (REAL_DATA / "bullet").is_dir(), reason="needs ../shared/data/real/bullet")
def test_roastworlds_export_of_a_roast_reads_as_roastimes_own_file(tmp_path):
    """Every shared Bullet log rewritten in RoastWorld's export layout (:func:`as_roastworld`) imports
    through the Bullet example's map to the same batch as RoasTime's own file: the same samples, the
    same heater and fan steps, the same IR and drum at charge."""
    cmap = load_map(Path(__file__).parents[1] / "examples" / "bullet" / "map.toml")
    logs = sorted((REAL_DATA / "bullet").glob("bullet_*g.json"))
    assert len(logs) >= 20
    for log in logs:
        doc = json.loads(log.read_text())
        moved = tmp_path / log.name
        moved.write_text(json.dumps(as_roastworld(doc)))
        a, b = import_log(log, cmap), import_log(moved, cmap)
        assert b.n == a.n and np.allclose(b.time_s, a.time_s), log.name
        for key in ("Ta_C", "heater", "fan", "Tb2_C", "Tgi_C"):
            assert np.allclose(getattr(a, key), getattr(b, key), equal_nan=True), (log.name, key)
        assert a.initial == b.initial and a.Mb_kg == b.Mb_kg and a.unit == b.unit
        assert any(n.startswith("no sampleRate: 2 samples/s from totalRoastTime") for n in b.notes)


def test_an_unmarked_charge_and_drop_are_read_from_bt(tmp_path):
    """SYNTHETIC BT: 30 s of preheated drum at 200 degC, the charge (a dip to a turning point near 90 degC),
    a rise to 205 degC at 10:00 after CHARGE, then the discharge; no CHARGE or DROP marked (-1, 0)."""
    t = np.arange(0.0, 720.0, 1.5)
    after = t - 30.0
    roast = (
        90.0 + 110.0 * np.exp(-np.maximum(after, 0) / 25.0) + 115.0 * (1 - np.exp(-np.maximum(after, 0) / 400.0)) * 1.35
    )
    bt = np.where(after < 0, 200.0, roast)
    bt = np.where(after > 600.0, bt[np.searchsorted(after, 600.0)] - 0.8 * (after - 600.0), bt)
    p = tmp_path / "unmarked.alog"
    p.write_text(fake_alog(bt=bt.tolist(), et=[220.0] * len(t), n=len(t),
                           extra={"timex": t.tolist(), "timeindex": [-1, 0, 0, 0, 0, 0, 0, 0]}))  # fmt: skip
    log = read_alog(p)
    assert log.time_s[0] == 0.0 and abs(t[log.charge_index] - 30.0) <= 1.5
    assert abs(log.time_s[-1] - 600.0) <= 3.0 and log.events["DROP"] == log.time_s[-1]
    assert [n.split(":")[0] for n in log.notes] == ["no CHARGE marked", "no DROP marked"]
    # marked logs are read as marked, with no note
    p.write_text(fake_alog(bt=bt.tolist(), et=[220.0] * len(t), n=len(t),
                           extra={"timex": t.tolist(), "timeindex": [10, 0, 0, 0, 0, 0, 400, 0]}))  # fmt: skip
    log = read_alog(p)
    assert log.charge_index == 10 and log.time_s[-1] == t[400] - t[10] and not log.notes
    # marks past the last sample (a template whose marks are seconds, a file cut short): said, read as unmarked
    p.write_text(fake_alog(bt=bt.tolist(), et=[220.0] * len(t), n=len(t),
                           extra={"timex": t.tolist(), "timeindex": [10, 600, 0, 0, 0, 0, 700, 0]}))  # fmt: skip
    log = read_alog(p)
    assert log.notes[0] == f"DRY (sample 600), DROP (sample 700) marked past the log's last sample ({len(t) - 1}): " \
        "read as unmarked"  # fmt: skip
    assert (
        "DRY" not in log.events
        and log.notes[1].startswith("no DROP marked")
        and abs(log.time_s[-1] - (630.0 - t[10])) <= 3.0
    )


@pytest.mark.parametrize("drop_marked", [True, False])
def test_a_recording_begun_after_the_charge_is_read_from_its_first_sample(tmp_path, drop_marked):
    """SYNTHETIC BT as above, the recording begun 45 s after the charge (BT already past its fall):
    the only fall left is the discharge's, which no roast follows, so it is not taken for the
    charge (it was: the log was then cut to one sample and refused as having no BT)."""
    t = np.arange(0.0, 720.0, 1.5)
    roast = 90.0 + 110.0 * np.exp(-t / 25.0) + 115.0 * (1 - np.exp(-t / 400.0)) * 1.35
    bt = np.where(t > 600.0, roast[np.searchsorted(t, 600.0)] - 0.8 * (t - 600.0), roast)
    late = t >= 45.0
    drop = int(np.searchsorted(t[late] - 45.0, 555.0))
    p = tmp_path / "late.alog"
    p.write_text(fake_alog(bt=bt[late].tolist(), et=[220.0] * int(late.sum()), n=int(late.sum()),
                           extra={"timex": (t[late] - 45.0).tolist(),
                                  "timeindex": [-1, 0, 0, 0, 0, 0, drop if drop_marked else 0, 0]}))  # fmt: skip
    log = read_alog(p)
    assert log.charge_index == 0 and log.notes[0].startswith("no CHARGE marked and BT shows no charge")
    assert abs(log.time_s[-1] - 555.0) <= 3.0  # to the DROP, marked or found in BT


def test_a_green_weight_in_the_file_name_is_the_batchs_when_the_log_has_none(tmp_path):
    """SYNTHETIC: init reads a weight from a file name ("..._230g.alog"); the import does too, so the
    fit sees each log's own batch, not the plant's nominal one (the log's own weight wins)."""
    unweighed = tmp_path / "kenya_230g.alog"
    unweighed.write_text(fake_alog(extra={"weight": [0, 0, "g"]}))
    b = import_log(unweighed, load_map(write_map(tmp_path, SKY_MAP)))
    assert b.Mb_kg == 0.23 and any("from the file name's '230g'" in n for n in b.notes)
    weighed = tmp_path / "kenya_230g_weighed.alog"
    weighed.write_text(fake_alog())  # weight [200, 170, "g"]
    assert import_log(weighed, load_map(write_map(tmp_path, SKY_MAP))).Mb_kg == 0.2
    # the map's batch_kg is the weight of a log that records none, nor in its file name
    default = load_map(write_map(tmp_path, "batch_kg = 0.3\n" + SKY_MAP))
    assert import_log(unweighed, default).Mb_kg == 0.23 and import_log(weighed, default).Mb_kg == 0.2
    plain = tmp_path / "kenya.alog"
    plain.write_text(fake_alog(extra={"weight": [0, 0, "g"]}))
    assert import_log(plain, default).Mb_kg == 0.3
