"""roastlab init and fit-roaster: a roaster from its logs with no hand-written files."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

import roastlab
from conftest import REAL_DATA, REPO, printed_percent
from roastlab.errors import InputError
from roastlab.workflows import roaster, survey
from test_importers import fake_alog


def test_init_detects_an_artisan_layout_and_writes_commented_files(cli, tmp_path):
    """SYNTHETIC Artisan logs (test_importers.fake_alog) with Burner and Air events and a weight."""
    extra = {
        "specialevents": [10, 40],
        "specialeventstype": [3, 0],
        "specialeventsvalue": [8.0, 4.0],  # Burner 70 %, Air 30 % in Artisan's encoding
        "etypes": ["Air", "Drum", "Damper", "Burner", "--"],
        "roastertype": "Hottop KN-8828B-2K+",
    }
    logs = []
    for k in range(2):
        p = tmp_path / f"r{k}.alog"
        p.write_text(fake_alog(extra=extra))
        logs.append(p)
    before = [p.read_bytes() for p in logs]
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    text = {n: (tmp_path / "cfg" / f"{n}.toml").read_text() for n in ("map", "plant", "fit")}
    assert 'column = "Burner"' in text["map"] and 'column = "Air"' in text["map"] and 'unit = "percent"' in text["map"]
    assert "catalogue: Hottop" in text["plant"] and "Mm_kg = 0.75" in text["plant"]  # 3 kg per kg of 0.25 kg
    assert "Qe_gain_kW" in text["fit"] and "Tgi_gain_C" in text["fit"] and "\n[fixed]\nh_probe_m = " in text["fit"]
    assert 'Tm0_C = ["BT", "ET"]' in text["map"]  # the drum at CHARGE: the probe soaked in the empty drum
    assert "Hottop" in out and [p.read_bytes() for p in logs] == before  # logs never modified
    # Air at 30 % throughout both logs: its share of the flow cannot be told from the base flow
    assert "\nGg_fan_kg_s" not in text["fit"] and "# the fan sits at 30 in every log" in text["fit"]
    assert "the Air sits at 30 in every log" in out


@pytest.mark.parametrize("events", [True, False])
def test_init_takes_the_event_types_before_a_device_named_like_them(cli, tmp_path, events):
    """SYNTHETIC logs with Artisan's Aillio R1 extra devices: the Fan events (or, without events,
    the ``{0}`` readout) are the fan, not the "Fan RPM" speed; likewise the heater."""
    from test_importers import _aillio_like

    n = 120
    logs = []
    for k in range(2):
        logs.append(tmp_path / f"r{k}.alog")
        logs[-1].write_text(fake_alog(n=n, extra=_aillio_like(n, events) | {"roastertype": "Aillio Bullet R1 IBTS"}))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    assert "heater: Heater (" in out and "fan: Fan (" in out and "RPM" not in out
    unit = "tens" if events else "level"  # the events in tens (70: P7, as Artisan's Aillio setup shows it)
    heater = (tmp_path / "cfg" / "map.toml").read_text().split("[heater]")[1].split("[")[0]
    assert 'column = "Heater"' in heater and f'unit = "{unit}"' in heater


def _ir_as_et(n: int = 120, charge: int = 5) -> dict:
    """SYNTHETIC: an ET that reads the beans, as Artisan's Aillio Bullet R1 IBTS device logs its
    infrared sensor: the empty preheated drum (240 degC) before CHARGE, the green beans (25 degC)
    as they land, then above the probe (fake_alog's BT: 130 degC falling to 124, then rising)."""
    et = [240.0] * charge + [25.0 + 2.0 * i for i in range(n - charge)]
    return {"temp1": et, "specialevents": [charge, charge], "specialeventstype": [3, 0],
            "specialeventsvalue": [8.0, 4.0], "etypes": ["Fan", "Drum", "Damper", "Heater", "--"],
            "roastertype": "Aillio Bullet R1 IBTS"}  # fmt: skip


def test_init_takes_an_et_that_never_reads_above_the_room_for_no_et(cli, tmp_path):
    """SYNTHETIC logs whose ET channel is unconnected (0 throughout, as some devices write it): no
    ET for init (nothing to weigh against the outlet gas, nor a bean reading), the heater drives."""
    logs = [tmp_path / f"r{k}.alog" for k in range(2)]
    for p in logs:
        p.write_text(fake_alog(et=[0.0] * 120, extra=_ir_as_et() | {"temp1": [0.0] * 120}))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0 and "second bean reading: none; ET: no" in out, err
    assert "\nET = " not in (tmp_path / "cfg" / "fit.toml").read_text()


def test_init_reads_an_et_that_falls_to_the_green_beans_as_a_second_bean_reading(cli, tmp_path):
    """SYNTHETIC logs whose ET falls to the green beans at CHARGE (:func:`_ir_as_et`): init maps it as
    the second bean reading ([Tb2]), not the drum's air, starts the drum at ET's reading before
    CHARGE, and weighs it against the model's beans; the import does not draw it as ET. A drum-air
    ET (fake_alog's) stays ET."""
    from roastlab.io.importers.mapping import import_log, load_map

    logs = [tmp_path / f"r{k}.alog" for k in range(2)]
    for p in logs:
        p.write_text(fake_alog(extra=_ir_as_et()))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    assert "ET: a bean reading, not the drum's air" in out and "ET falls to the green beans' temperature" in out
    text = {n: (tmp_path / "cfg" / f"{n}.toml").read_text() for n in ("map", "fit")}
    assert '[Tb2]\ncolumn = "ET"' in text["map"] and "[ET]" not in text["map"]
    assert 'Tm0_C = ["ET before CHARGE", "BT"]' in text["map"]
    assert "Tb2 = 1.0" in text["fit"] and "\nET = " not in text["fit"]
    # an Aillio named in the logs: Artisan's setup shows its levels in tens, so 70 and 30 are P7 and F3
    assert "heater: Heater (tens); fan: Fan (tens)" in out
    assert load_map(tmp_path / "cfg" / "map.toml").actuator("heater").describe() == "heater P0-P7 in steps of 1"
    batch = import_log(logs[0], load_map(tmp_path / "cfg" / "map.toml"))
    assert batch.initial["Tm0_C"] == 240.0  # the drum, not BT (130) nor the beans (25)
    assert batch.Tb2_C is not None and batch.ET_C is None
    from roastlab.workflows.transfer import et_source  # a background's ET then lies over the roaster's ET: beans

    assert et_source(load_map(tmp_path / "cfg" / "map.toml")) == "Tb"
    air = tmp_path / "air.alog"
    air.write_text(fake_alog(extra=_ir_as_et() | {"temp1": [150.0 + 0.4 * i for i in range(120)]}))
    code, out, err = cli("init", logs[0], air, "--out", tmp_path / "cfg2")
    assert code == 0 and "ET: yes" in out, err
    assert "ET falls to the green beans' temperature at CHARGE on 1 log(s) (r0.alog), unlike the others" in out
    assert "[Tb2]" not in (tmp_path / "cfg2" / "map.toml").read_text()
    assert et_source(load_map(tmp_path / "cfg2" / "map.toml")) == "Tm"  # the drum, as for the Skywalker


@pytest.mark.parametrize("mode", ["C", "F"])
def test_an_et_below_bt_through_every_roast_is_not_used_and_a_swap_is_suggested(cli, tmp_path, mode):
    """SYNTHETIC logs whose ET reads 15 degC below BT through every roast (ET and BT swapped in the
    device setup, or a probe outside the drum): not the drum's air on any log, which runs above the
    beans it heats. init does not weigh it against the model's air (before, only logs far below the
    others' median were dropped, so a machine whose every log read so kept it), and says a swap is
    likely; the heater then heats the drum alone, as without ET. Logs recorded in degF hear it in degF."""
    bt = [130.0 - 0.2 * i if i < 30 else 124.0 + 0.5 * (i - 30) for i in range(120)]
    logs = [tmp_path / f"r{k}.alog" for k in range(3)]
    f = (lambda c: 9 / 5 * c + 32) if mode == "F" else (lambda c: c)
    for k, p in enumerate(logs):
        p.write_text(fake_alog(mode, bt=[f(b) for b in bt], et=[f(b - 15.0 + k) for b in bt],
                               extra={**_BURNER_AIR, "roastepoch": 1e9 + k}))  # fmt: skip
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    assert "ET: below BT on every log, not used" in out
    by = "by 13 to 15 °C" if mode == "C" else "by 23 to 27 °F"
    assert f"ET reads below BT through the roast on every log ({by})" in out and "swap them back" in out
    spec = (tmp_path / "cfg" / "fit.toml").read_text()
    assert "\nET = " not in spec and "Tgi_gain_C" not in spec.split("[free]")[1].split("[")[0], spec


def test_init_takes_the_damper_as_the_fan_when_no_fan_is_logged(cli, tmp_path):
    """SYNTHETIC logs with Burner and Damper events and no Air: on a drum with one fixed-speed
    exhaust fan the damper sets the air flow, so it stands for the fan, and init says so; with an
    Air channel too, the damper stays unused."""
    damper = {"specialevents": [10, 40, 60], "specialeventstype": [3, 2, 2], "specialeventsvalue": [8.0, 4.0, 6.0],
              "etypes": ["Air", "Drum", "Damper", "Burner", "--"]}  # fmt: skip
    logs = [tmp_path / f"r{k}.alog" for k in range(2)]
    for p in logs:
        p.write_text(fake_alog(extra=damper))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    assert "fan: Damper (percent)" in out and "no fan channel: the Damper sets the air flow" in out
    fan = (tmp_path / "cfg" / "map.toml").read_text().split("[fan]")[1].split("[")[0]
    assert 'column = "Damper"' in fan
    # "the model's flow rises with it": the fit spec frees the flow per % of the setting (it did not,
    # so a percent fan or damper moved nothing in the model, a what-if on it changed nothing)
    gg_hi = (tmp_path / "cfg" / "fit.toml").read_text().split("Gg_kg_s = [")[1].split("]")[0].split(", ")[1]
    assert (
        f"Gg_fan_kg_s = [0, {float(gg_hi) / 100:g}, {float(gg_hi) / 1000:g}]"
        in (tmp_path / "cfg" / "fit.toml").read_text()
    )
    both = dict(damper, specialevents=[10, 40, 50], specialeventstype=[3, 2, 0], specialeventsvalue=[8.0, 4.0, 3.0])
    for p in logs:
        p.write_text(fake_alog(extra=both))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg2")
    assert code == 0, err
    assert "fan: Air (" in out and "no fan channel" not in out
    assert "logged but not used by the model: damper ('Damper')" in (tmp_path / "cfg2" / "map.toml").read_text()


#: SYNTHETIC Burner (type 3) and Air (type 0) events in Artisan's encoding.
_BURNER_AIR = {"specialevents": [10, 40], "specialeventstype": [3, 0], "specialeventsvalue": [8.0, 4.0],
               "etypes": ["Air", "Drum", "Damper", "Burner", "--"]}  # fmt: skip


def test_init_without_et_lets_the_heater_heat_the_drum_alone(cli, tmp_path):
    """SYNTHETIC logs with a burner but no ET: BT alone cannot tell the heater's two paths apart, so
    the fit spec sends the heater into the drum metal only (no Tgi_gain_C) and says why; with ET the
    fit may use both (the test above)."""
    logs = []
    for k in range(2):
        logs.append(tmp_path / f"r{k}.alog")
        logs[-1].write_text(fake_alog(et=[-1.0] * 120, extra=_BURNER_AIR))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0 and "ET: no" in out and "no heater setting" not in out, err
    fit = (tmp_path / "cfg" / "fit.toml").read_text()
    assert "Qe_gain_kW" in fit and "Tgi_gain_C" not in fit and "heater heats the drum metal alone" in fit
    assert "[weights]" not in fit
    # the drum at CHARGE is BT then, the probe soaked in the empty drum: the share of the drum's rise it
    # shows is fitted, within the quantity table's bounds (roastlab.model.rhs.drum_at_charge_C)
    from roastlab.model.quantities import quantity
    from roastlab.workflows.survey import TM0_SHARE_START

    lo, hi = quantity("Tm0_share").bounds
    assert f"Tm0_share = [{lo:g}, {hi:g}, {TM0_SHARE_START:g}]" in fit


def test_init_leaves_the_drum_start_as_read_where_et_drives_the_model(cli, tmp_path):
    """SYNTHETIC logs with BT and ET and no heater setting: ET drives the model as the inlet air, and a
    free share of the drum's rise at CHARGE would stand in for the heater the logs lack (on six
    Skywalker logs without their events it ran to its floor, a drum at 389 degC), so init does not
    free it; with a heater it does (the test above)."""
    logs = [tmp_path / f"r{k}.alog" for k in range(2)]
    for p in logs:
        p.write_text(fake_alog())
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    assert 'column = "ET"' in (tmp_path / "cfg" / "map.toml").read_text()
    assert "Tm0_share" not in (tmp_path / "cfg" / "fit.toml").read_text()
    # and init says, before any fit, that such logs make a weak model and what to log instead
    assert "no heater setting in the logs" in out and '"No heater in the logs"' in out, out
    assert "### No heater in the logs" in (REPO / "docs" / "your-roaster.md").read_text()  # where it points


def _heater_readout_logs(tmp_path, name: str, readings: list, stem: str, k: int = 2) -> list:
    """SYNTHETIC: ``k`` fake Artisan logs whose heater is an extra device ``name`` reading ``readings``
    (one per sample, or one list per log) beside a Fan device at 40."""
    n = len(readings[0]) if isinstance(readings[0], list) else len(readings)
    logs = []
    for i in range(k):
        values = readings[i] if isinstance(readings[0], list) else readings
        extra = {"extratimex": [[1.5 * j for j in range(n)]], "extraname1": [name], "extraname2": ["Fan"],
                 "extratemp1": [values], "extratemp2": [[40.0] * n], "extraNoneTempHint1": [True],
                 "extraNoneTempHint2": [True]}  # fmt: skip
        logs.append(tmp_path / f"{stem}{i}.alog")
        logs[-1].write_text(fake_alog(n=n, extra=extra))
    return logs


def test_a_heater_logged_in_watts_is_read_as_a_power(cli, tmp_path):
    """SYNTHETIC logs whose heater is an extra device reading 450-900 (a power readout, not a
    percent): the map says W with the logs' top, the fit spec bounds the drum's share of it at all of
    it (roastlab.workflows.survey.KW_PER_W), and a program labels it in W."""
    from roastlab.io.importers.mapping import load_map
    from roastlab.workflows.survey import KW_PER_W

    logs = _heater_readout_logs(tmp_path, "Heater W", [450.0 if i < 60 else 900.0 for i in range(120)], "w")
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0 and "heater: Heater W (W)" in out, err
    heater = load_map(tmp_path / "cfg" / "map.toml").actuator("heater")
    assert (heater.unit, heater.high, heater.step, heater.label(900)) == ("W", 900.0, None, "900 W")
    assert f"Qe_gain_kW = [0, {KW_PER_W:g}," in (tmp_path / "cfg" / "fit.toml").read_text()


def test_a_fan_logged_only_as_its_speed_in_rpm_sets_the_flow(cli, tmp_path):
    """SYNTHETIC logs whose only fan channel is an extra device "Fan RPM" reading 1200-2400 (no fan
    events): the fan's speed, the flow in proportion to it (the fan laws), not dropped as it was; the map
    says rpm with the logs' top, the fit frees the flow per rpm (at the top, at most the largest base
    flow), a what-if changes it in rpm; a fan speed that never moves is named and not fitted."""
    from roastlab.io.importers.mapping import load_map

    n = 120
    logs = [tmp_path / f"rpm{k}.alog" for k in range(2)]
    for k, p in enumerate(logs):
        rpm = [1200.0 if i < 60 else 1800.0 + 600.0 * k for i in range(n)]
        extra = {"extratimex": [[1.5 * i for i in range(n)]], "extraname1": ["Fan RPM"], "extraname2": ["Voltage"],
                 "extratemp1": [rpm], "extratemp2": [[230.0] * n], "extraNoneTempHint1": [True],
                 "extraNoneTempHint2": [True], "specialevents": [10, 40], "specialeventstype": [3, 3],
                 "specialeventsvalue": [8.0, 6.0], "etypes": ["Air", "Drum", "Damper", "Burner", "--"]}  # fmt: skip
        p.write_text(fake_alog(extra=extra))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0 and "fan: Fan RPM (rpm)" in out and "taken as the fan's speed in rpm" in out, (out, err)
    fan = load_map(tmp_path / "cfg" / "map.toml").actuator("fan")
    assert (fan.unit, fan.high, fan.step, fan.label(1800)) == ("rpm", 2400.0, None, "1800 rpm")
    fit = (tmp_path / "cfg" / "fit.toml").read_text()
    gg_hi = float(fit.split("Gg_kg_s = [")[1].split("]")[0].split(", ")[1])
    assert f"Gg_fan_kg_s = [0, {float(f'{gg_hi / 2400:.3g}'):g}," in fit and "per rpm of the fan" in fit
    for p in logs:  # the same speed throughout every log: its share cannot be told from the base flow
        p.write_text(p.read_text().replace("1800.0", "1200.0").replace("2400.0", "1200.0"))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg2")
    assert code == 0 and "the Fan RPM sits at 1200 in every log" in out, (out, err)
    assert "\nGg_fan_kg_s" not in (tmp_path / "cfg2" / "fit.toml").read_text()


def _fan_readout_logs(tmp_path, name: str, low: float, high: float) -> list:
    """SYNTHETIC: two fake Artisan logs whose fan is an extra device ``name`` reading ``low``, then
    ``high`` in the second (decimals), beside Burner events."""
    n = 120
    logs = [tmp_path / f"fan{k}.alog" for k in range(2)]
    for k, p in enumerate(logs):
        values = [low if i < 60 else low + (high - low) * (0.5 + 0.5 * k) for i in range(n)]
        extra = {"extratimex": [[1.5 * i for i in range(n)]], "extraname1": [name], "extraname2": ["Voltage"],
                 "extratemp1": [values], "extratemp2": [[230.0] * n], "extraNoneTempHint1": [True],
                 "extraNoneTempHint2": [True], "specialevents": [10, 40], "specialeventstype": [3, 3],
                 "specialeventsvalue": [8.0, 6.0], "etypes": ["Air", "Drum", "Damper", "Burner", "--"]}  # fmt: skip
        p.write_text(fake_alog(extra=extra))
    return logs


@pytest.mark.parametrize(
    "name, unit, exp", [("Fan Hz", "Hz", 1.0), ("Draft Pa", "Pa", 0.5), ("Air (mmH2O)", "mmWC", 0.5)]
)
def test_a_fan_named_in_a_unit_is_read_in_it_with_its_flow_law(cli, tmp_path, name, unit, exp):
    """SYNTHETIC logs whose fan is an extra device reading 32.5-48.3 with decimals: "Fan Hz" (a
    variable-frequency drive's readout) is read in Hz, not as a percent by its values, the flow in
    proportion to it (the fan laws); "Draft Pa" (the pressure the fan makes across the drum) in Pa, the
    flow as its square root (the flow through a fixed resistance: fan_exp 0.5 fixed, the gain per
    Pa^0.5). The map's top is the logs' highest and a program labels the setting in its unit."""
    from roastlab.io.importers.mapping import load_map

    code, out, err = cli("init", *_fan_readout_logs(tmp_path, name, 32.5, 48.3), "--out", tmp_path / "cfg")
    assert code == 0 and f"fan: {name} ({unit})" in out, (out, err)
    fan = load_map(tmp_path / "cfg" / "map.toml").actuator("fan")
    assert (fan.unit, fan.high, fan.step) == (unit, 48.3, None) and fan.label(45).endswith(f"45 {unit}")
    fit = (tmp_path / "cfg" / "fit.toml").read_text()
    gg_hi = float(fit.split("Gg_kg_s = [")[1].split("]")[0].split(", ")[1])
    per = unit if exp == 1.0 else f"{unit}^{exp:g}"
    assert f"Gg_fan_kg_s = [0, {float(f'{gg_hi / 48.3**exp:.3g}'):g}," in fit and f"per {per} of the fan" in fit
    assert ("\nfan_exp = 0.5 " in fit) == (exp == 0.5)
    from roastlab.io.fitspec import load_fit_spec

    assert load_fit_spec(tmp_path / "cfg" / "fit.toml").fixed.get("fan_exp", 1.0) == exp


def test_a_fan_logged_in_tens_above_100_is_the_machines_levels(cli, tmp_path):
    """SYNTHETIC logs whose Fan events run 10-120 in tens, as Artisan's Aillio setup shows the
    Bullet's F1-F12 (a log that never passes F2 beside one that reaches F12): one unit for the
    channel from every log's values, "tens", not a power to drop; a program labels it F1-F12 and
    the fit's flow per logged unit is bounded a tenth of a step's. A heater in W stays W; a
    percent setting every log moves in whole tens gets 10 % steps (Artisan's slider: 5)."""
    from roastlab.io.importers.mapping import load_map
    from roastlab.workflows.survey import _unit_of

    assert _unit_of(np.array([10.0, 20.0, 70.0, 120.0])) == "tens"
    assert _unit_of(np.array([0.0, 70.0, 140.0])) == "tens"  # Artisan's Bullet R2 setup: power P0-P14 as 0-140
    assert _unit_of(np.array([10.0, 20.0, 70.0])) == "percent"  # within Artisan's 0-100: a percent
    assert _unit_of(np.array([900.0, 1350.0])) == "W" and _unit_of(np.array([15.0, 125.0])) == "W"
    assert _unit_of(np.array([0.0, 5.0, 9.0])) == "level" and _unit_of(np.array([np.nan])) == "percent"
    logs = []
    for k, top in enumerate((20.0, 120.0)):  # Artisan's internal values: 1 + shown / 10
        extra = {"specialevents": [5, 40], "specialeventstype": [3, 0], "specialeventsvalue": [8.0, 1.0 + top / 10],
                 "etypes": ["Fan", "Drum", "Damper", "Heater", "--"]}  # fmt: skip
        logs.append(tmp_path / f"r{k}.alog")
        logs[-1].write_text(fake_alog(extra=extra))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0 and "fan: Fan (tens)" in out, err
    fan = load_map(tmp_path / "cfg" / "map.toml").actuator("fan")
    assert (fan.unit, fan.high, fan.step, fan.label(120), fan.label(70)) == ("tens", 120.0, 10.0, "F12", "F7")
    assert fan.describe() == "fan F0-F12 in steps of 1"
    from roastlab.fit.program import ProgramLimits, limit_spans
    from roastlab.model.actuators import Actuator

    power = Actuator("heater", "tens", 0.0, 90.0, 10.0, 120.0)  # Artisan's Bullet setup: P0-P9 as 0-90
    t, u = np.arange(0.0, 60.0, 5.0), np.array([50.0, 60.0, 70.0, 80.0, 90.0] + [90.0] * 7)
    said = [s["limit"] for s in limit_spans(t, u, ProgramLimits(0.0, 90.0, 120.0, decide="heater", actuator=power))]
    assert "heater at its P9 ceiling" in said and "heater rising at its 12 levels/min rate limit" in said
    heater = load_map(tmp_path / "cfg" / "map.toml").actuator("heater")  # 70 % on both logs: moved in 10 % steps
    assert (heater.unit, heater.high, heater.step) == ("percent", 70.0, 10.0)
    assert "Gg_fan_kg_s = [0, 0.001, 0.0001]" in (tmp_path / "cfg" / "fit.toml").read_text()


def test_init_reads_a_plain_csv_by_its_column_names(cli, tmp_path):
    """SYNTHETIC plain CSV logs (a header row, numbers, the first row the charge; degF by the names):
    init finds time, BT, ET, the burner and the fan by name, writes them with their units, reads the
    drum at charge from BT's first row and the batch from the file name; the import reads it so."""
    from roastlab.io.importers.mapping import import_log, load_map

    logs = []
    for k, grams in enumerate((230, 250)):
        rows = ["time (s),Bean Temp (F),ET (F),Burner %,Fan %,Inlet temp (F),BT RoR,Event"]
        for i in range(120):
            bt_f = 300.0 - 2.0 * i if i < 30 else 240.0 + 1.2 * (i - 30)
            event = "Charge" if i == 0 else ""  # words: not a reading, left unread
            et_f = "" if i == 50 else f"{bt_f + 40:.1f}"  # a reading not taken: a gap in ET, not an error
            rows.append(f"{2.0 * i},{bt_f:.1f},{et_f},{60 + 10 * (i > 60)},{30 + k},572.0,0,{event}")
        logs.append(tmp_path / f"roast{k}_{grams}g.csv")
        logs[-1].write_text("\n".join(rows) + "\n")
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    assert "format csv" in out and "heater: Burner % (percent); fan: Fan % (percent)" in out
    assert "CSV: time 'time (s)' [s], BT 'Bean Temp (F)', ET 'ET (F)' [degF]" in out
    assert "not read (not numbers): Event" in out
    cmap = load_map(tmp_path / "cfg" / "map.toml")
    assert (cmap.Ta["column"], cmap.Ta["unit"], cmap.ET["unit"]) == ("Bean Temp (F)", "F", "F")
    b = import_log(logs[1], cmap)
    assert b.initial["Tm0_C"] == pytest.approx((300.0 - 32) * 5 / 9) and b.Mb_kg == 0.25
    assert b.Ta_C[0] == pytest.approx((300.0 - 32) * 5 / 9) and b.heater[-1] == 70.0
    assert b.ET_C is not None and 0.9 < np.isfinite(b.ET_C).mean() < 1.0
    # a CSV map names one column: a burner named otherwise in one log is refused in one line
    logs[1].write_text(logs[1].read_text().replace("Burner %", "Power %", 1))
    code, _, err = cli("init", *logs, "--out", tmp_path / "cfg2")
    assert code == 2 and "the CSV logs name the heater column differently (Burner %, Power %)" in err, err


def test_init_reads_a_plain_csv_whose_time_is_a_clock(cli, tmp_path):
    """SYNTHETIC plain CSV logs with the time written m:ss (and h:mm:ss past an hour, as a clock
    does) and "nan" where a setting was not logged yet: the map says unit "m:ss", the import reads
    seconds, and a bad clock cell is one line naming the file, the line and the column."""
    from roastlab.io.importers.mapping import import_log, load_map

    logs = []
    for k, grams in enumerate((230, 250)):
        rows = ["Time,BT,ET,Burner,Fan"]
        for i in range(120):
            t = 30.0 * i  # to 59:30; the last rows past an hour
            clock = f"{int(t // 60):02d}:{t % 60:04.1f}" if t < 3600 else f"1:{int(t // 60) - 60:02d}:{t % 60:02.0f}"
            bt = 150.0 - 1.0 * i if i < 30 else 120.0 + 0.6 * (i - 30)
            burner = "nan" if i < 3 else f"{60 + 10 * (i > 60)}"
            rows.append(f"{clock},{bt:.1f},{bt + 30:.1f},{burner},{40 + k}")
        logs.append(tmp_path / f"roast{k}_{grams}g.csv")
        logs[-1].write_text("\n".join(rows + ["1:00:00,160,190,70,40", "1:00:30,161,191,70,40"]) + "\n")
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    assert "CSV: time 'Time' [m:ss]" in out and "heater: Burner (percent)" in out and "not read" not in out
    cmap = load_map(tmp_path / "cfg" / "map.toml")
    assert cmap.time == {"column": "Time", "unit": "m:ss"}
    b = import_log(logs[0], cmap)
    assert b.time_s[-1] == pytest.approx(3630.0)  # 1:00:30 after the first row
    assert b.time_s[0] == pytest.approx(90.0) and any("incomplete" in n for n in b.notes)  # "nan": not logged yet
    assert np.interp(600.0, b.time_s, b.Ta_C) == pytest.approx(130.0)  # 10:00.0 is the 21st row
    bad = tmp_path / "bad_230g.csv"
    bad.write_text(logs[0].read_text().replace("00:30.0,", "00:75.0,", 1))
    code, out, err = cli("init", bad, logs[1], "--out", tmp_path / "cfg2")
    assert code == 2 and "bad_230g.csv" in err and "line 3, column Time" in err and "'00:75.0'" in err
    assert len(err.strip().splitlines()) == 1
    seconds_map = (tmp_path / "cfg" / "map.toml").read_text().replace('unit = "m:ss"', 'unit = "s"')
    (tmp_path / "seconds.toml").write_text(seconds_map)
    with pytest.raises(InputError, match=r"line 2, column Time: not a number: '00:00.0' \(a time written as a clock"):
        import_log(logs[0], load_map(tmp_path / "seconds.toml"))


def test_fit_roaster_with_a_log_where_the_folder_goes_says_what_the_first_argument_is(cli, tmp_path):
    """SYNTHETIC: the folder forgotten (``roastlab fit-roaster a.alog b.alog``): one line naming the
    log and what the first argument is, exit 2, rather than a missing map.toml inside a file."""
    logs = [tmp_path / f"r{i}.alog" for i in range(2)]
    for log in logs:
        log.write_text(fake_alog(extra=_BURNER_AIR))
    code, _, err = cli("fit-roaster", *logs)
    assert code == 2 and err.count("\n") == 1
    assert str(logs[0]) in err and "a file, not a folder" in err and "--out DIR" in err


def test_fit_roaster_on_one_log_says_how_to_fit_it_without_a_check(cli, tmp_path):
    """SYNTHETIC: one log leaves nothing to hold out; the refusal gives the identify command that
    fits it anyway from init's files, and that command runs."""
    log = tmp_path / "r0.alog"
    log.write_text(fake_alog(extra=_BURNER_AIR))
    assert cli("init", log, "--out", tmp_path / "cfg")[0] == 0
    code, _, err = cli("fit-roaster", tmp_path / "cfg", log)
    assert code == 2 and err.count("\n") == 1 and "roastlab identify --plant" in err
    command, d = err.split("fitted, unchecked, by ")[1].rsplit(" (D = ", 1)
    command = command.replace("D/", d.strip().rstrip(")") + "/").split()
    assert command[:2] == ["roastlab", "identify"] and command[-1] == "LOG"
    code, _, err = cli(*command[1:-1], "--starts", "1", log)
    assert code == 0, err
    assert (tmp_path / "cfg" / "model.json").is_file()


def test_a_log_with_no_green_weight_is_named_and_left_out(cli, tmp_path):
    """SYNTHETIC: one log of three records no green weight (as one shared Bullet log): init sets up
    the others and names it (it refused all three), fit-roaster leaves it out and says so."""
    logs = [tmp_path / f"r{k}.alog" for k in range(3)]
    for k, p in enumerate(logs):
        p.write_text(fake_alog(extra=dict(_BURNER_AIR, **({"weight": [0, 0, "g"]} if k == 1 else {}))))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    assert "1 log(s) record no green weight, nor one in the file name (r1.alog): fit-roaster leaves them out" in out
    assert out.startswith("2 log(s) (and 1 without a green weight, below)")
    code, out, err = cli("fit-roaster", tmp_path / "cfg", *logs)
    assert code == 0, err
    assert "left out: r1.alog records no green weight" in out
    # --batch-kg is the weight of a log that records none (the others keep theirs), kept in the map
    # for every command's import: nothing is left out then
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg2", "--batch-kg", "0.3")
    assert code == 0 and "green batches: 200 g, 300 g" in out, (out, err)
    assert "\nbatch_kg = 0.3 " in (tmp_path / "cfg2" / "map.toml").read_text()
    code, out, err = cli("fit-roaster", tmp_path / "cfg2", *logs)
    assert code == 0 and "left out" not in out, err


def test_a_log_whose_et_drives_the_model_from_outside_the_drum_is_left_out(cli, tmp_path):
    """SYNTHETIC logs with no heater logged, so ET drives the model as the inlet air; on one of four
    ET reads 30 degC below BT through the roast (a sensor elsewhere). init says fit-roaster will
    leave it out and fit-roaster does, naming it and why: it was fitted with that ET heating its
    beans."""
    n = 120
    bt = [130.0 - 0.2 * i if i < 30 else 124.0 + 0.5 * (i - 30) for i in range(n)]
    logs = [tmp_path / f"r{k}.alog" for k in range(4)]
    for k, p in enumerate(logs):
        p.write_text(fake_alog(bt=bt, et=[b + (-30.0 if k == 2 else 20.0 + k) for b in bt], n=n))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    assert "ET reads below BT through the roast on 1 log(s) (r2.alog)" in out
    assert "with no heater logged ET is the inlet air that drives the model, so fit-roaster leaves them out" in out
    code, out, err = cli("fit-roaster", tmp_path / "cfg", *logs)
    assert code in (0, 1), err  # the fit may fail on its states (no heater): the files say so either way
    assert out.count("left out: ") == 1, out
    assert "left out: r2.alog cannot be fitted with the map (ET reads 30 °C below BT" in out
    assert "drives the model with it as the inlet air" in out


def test_a_folder_of_logs_is_read_and_a_recording_that_is_no_roast_is_named_and_left_out(cli, tmp_path):
    """SYNTHETIC: a roaster's folder as Artisan users keep it: three roasts beside an empty
    recording (no samples), an aborted one (no BT reading), one whose probe read 0 degC throughout,
    a CSV export, a licence and a hidden file. Given the folder, init reads its .alog logs, names the two recordings with why and sets up the three roasts
    (it refused the whole set on the first bad log); fit-roaster likewise."""
    folder = tmp_path / "roasts"
    folder.mkdir()
    for k in range(3):
        (folder / f"r{k}.alog").write_text(fake_alog(extra=_BURNER_AIR))
    (folder / "empty.alog").write_text(fake_alog(extra={"timex": [], "temp1": [], "temp2": []}))
    (folder / "aborted.alog").write_text(fake_alog(bt=[-1.0] * 8, et=[-1.0] * 8, n=8))
    (folder / "dead_probe.alog").write_text(fake_alog(bt=[0.0] * 120, extra=_BURNER_AIR))  # BT reads 0 degC
    # stopped 30 s after CHARGE (Artisan's own roast templates mark CHARGE 30 s before their end, too)
    (folder / "stopped.alog").write_text(fake_alog(extra={**_BURNER_AIR, "timeindex": [100, 0, 0, 0, 0, 0, 0, 0]}))
    (folder / "LICENSE").write_text("MIT License\n")
    (folder / ".r9.alog").write_text("not read: a hidden file")
    (folder / "r0.csv").write_text("not read: Artisan's CSV export of r0.alog, the same roast\n")
    code, out, err = cli("init", folder, "--out", tmp_path / "cfg")
    assert code == 0, err
    assert out.startswith("3 log(s)"), out
    assert "left out: aborted.alog cannot be read as a roast (no bean temperature (BT) in this log" in out
    assert "left out: empty.alog cannot be read as a roast (key timex: needs at least 2 samples" in out
    assert "left out: dead_probe.alog cannot be read as a roast (BT never reads above the room (22 °C; highest 0" in out
    assert (
        "left out: stopped.alog cannot be read as a roast (the log ends 0:28 after CHARGE, shorter than any roast "
        "(1:00): an aborted recording, or CHARGE marked where the beans did not go in?)" in out
    )
    assert "LICENSE" not in out and ".r9" not in out and "r0.csv" not in out
    # the files of another format are not read, and counted: here an export, in another folder another
    # roaster's logs, which a roaster would otherwise not know were passed over
    csv_passed_over = f"left out: 1 .csv file(s) in {folder}, not read: a folder stands for its logs of one format"
    assert csv_passed_over in out and out.count("left out: ") == 5, out
    code, out, err = cli("fit-roaster", tmp_path / "cfg", folder)
    assert code == 0, err
    assert out.count("left out: ") == 5 and "left out: empty.alog cannot be read as a roast" in out
    assert csv_passed_over in out
    assert "held out: FIT" in out
    # the logs named one by one read the same; a folder with no log, or only recordings that are no
    # roast, is one line naming it (the latter: the first log's own problem)
    named = [folder / f"{name}.alog" for name in ("r0", "empty", "r1", "aborted", "r2", "dead_probe")]
    code, out, err = cli("init", *named, "--out", tmp_path / "cfg2")
    assert code == 0 and out.startswith("3 log(s)") and out.count("left out: ") == 3, (out, err)
    (tmp_path / "none").mkdir()
    code, out, err = cli("init", tmp_path / "none", "--out", tmp_path / "cfg3")
    assert code == 2 and "none: no roast logs in this folder" in err and len(err.strip().splitlines()) == 1
    code, out, err = cli("init", folder / "aborted.alog", folder / "empty.alog", "--out", tmp_path / "cfg4")
    assert code == 2 and "aborted.alog: no bean temperature (BT)" in err, err


def test_a_copy_of_a_roast_is_named_and_left_out(cli, tmp_path):
    """SYNTHETIC: a roast saved twice (renamed with its batch number, annotated), as the Skywalker's
    public repository holds several, sits once in the fit set and once in the held-out set, scoring
    the model on a roast it was fitted to (on the Skywalker's 16 logs with two such copies the
    held-out FIT read 85.8 % against 79.7 %). A copy keeps the second its recording started: the
    later in the order given is named and left out, by init and fit-roaster alike."""
    logs, bts = [], []
    for k in range(4):
        bts.append([130.0 - 0.2 * i if i < 30 else 124.0 + (0.5 + 0.01 * k) * (i - 30) for i in range(120)])
        logs.append(tmp_path / f"roast_{k}.alog")
        logs[-1].write_text(fake_alog(bt=bts[k], extra={**_BURNER_AIR, "roastepoch": 1_760_000_000 + 3600 * k}))
    copy = tmp_path / "roast_1_R15_annotated.alog"  # the same recording, a note and FCs marked since
    notes = {"roastingnotes": "crash at FC", "timeindex": [5, 0, 80, 0, 0, 0, 110, 0]}
    copy.write_text(fake_alog(bt=bts[1], extra={**_BURNER_AIR, "roastepoch": 1_760_003_600, **notes}))
    code, out, err = cli("init", *logs, copy, "--out", tmp_path / "cfg")
    assert code == 0 and out.startswith("4 log(s)"), (out, err)
    assert "left out: roast_1_R15_annotated.alog is a copy of roast_1.alog (recorded from the same second" in out
    code, out, err = cli("fit-roaster", tmp_path / "cfg", *logs, copy)
    assert code == 0 and out.count("left out: ") == 1 and "is a copy of roast_1.alog" in out, (out, err)
    # validate is given what the user gives it, and says which of it the model was fitted on (by name,
    # or a copy of one by its start) and which roast is given twice; the held-out average leaves them out
    cfg = tmp_path / "cfg"
    fitted = json.loads((cfg / "model.json").read_text())["fit"]["batches"]
    assert fitted == ["roast_0", "roast_2"]  # sorted by date, alternately
    twice = tmp_path / "roast_3_again.alog"
    twice.write_text(logs[3].read_text())
    files = ("--plant", cfg / "plant.toml", "--map", cfg / "map.toml", "--model", cfg / "model.json")
    code, out, err = cli("validate", *files, logs[0], logs[3], twice, copy, "--json", tmp_path / "v.json")
    assert code == 0, err
    assert "note: roast_0 is a log the model was fitted on: its figures are the fit set's, not held out" in err
    assert "note: roast_3_again is a copy of roast_3 (recorded from the same second: one roast), so it counts" in err
    assert "note: roast_1_R15_annotated" not in err  # a copy of roast_1, which was held out
    doc = json.loads((tmp_path / "v.json").read_text())
    assert sorted(doc["not_held_out"]) == ["roast_0", "roast_3_again"]
    held = [r for r in doc["batches"] if r["name"] in ("roast_3", "roast_1_R15_annotated")]
    assert doc["average_held_out"]["n"] == sum(r["n"] for r in held)
    assert f"held out only (2 of 4 logs; the others are named above): FIT {doc['average_held_out']['FIT']:.1f} %" in out
    renamed = tmp_path / "renamed" / "R2_final.alog"  # a fitted roast under another name
    renamed.parent.mkdir()
    renamed.write_text(logs[2].read_text())
    code, out, err = cli("validate", *files, renamed, logs[1])
    assert (
        code == 0
        and "note: R2_final is a copy of roast_2, which the model was fitted on (recorded from the same" in err
    )
    from roastlab.io.batch import first_of_each_roast

    kept, copies = first_of_each_roast(
        [("a", 1e9), ("b", None), ("c", 1e9 + 0.4), ("d", None)], lambda x: x[1], lambda x: x[0]
    )
    assert [x[0] for x in kept] == ["a", "b", "d"] and list(copies) == ["c"]  # no start: a roast of its own


def test_a_log_without_a_suffix_is_read_by_its_content(tmp_path):
    """RoasTime keeps its logs without a suffix: such a file is a RoasTime log by its series, an
    Artisan log by its Python-literal dict with 'timex'; anything else is refused, naming it."""
    from roastlab.io.importers.mapping import detect_format

    rt, al, other = tmp_path / "zl9ZdStWgBkMIm5TrsOR", tmp_path / "roast", tmp_path / "LICENSE"
    rt.write_text(json.dumps({"beanTemperature": [20.0, 21.0], "sampleRate": 2}))
    al.write_text(fake_alog())
    other.write_text("MIT License {'timex'}\n")
    assert detect_format(rt) == "roastime" and detect_format(al) == "alog"
    with pytest.raises(
        InputError, match="LICENSE: no suffix, and the content is neither a RoasTime nor an Artisan log"
    ):
        detect_format(other)


def test_a_log_of_another_program_is_told_the_way_in_through_artisan(tmp_path, capsys):
    """A Cropster export (.xlsx) or another program's log given to init: exit 2 with one line that says
    what roastlab reads and that Artisan imports the others and saves them as .alog (not "set format in
    the map", which init has none of)."""
    from roastlab.cli.main import main

    xlsx = tmp_path / "roast.xlsx"
    xlsx.write_bytes(b"PK\x03\x04 a spreadsheet")
    assert main(["init", str(xlsx), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "roast.xlsx: cannot tell the log format from suffix '.xlsx'" in err
    assert "Artisan (File > Import)" in err and ".alog" in err
    assert not (tmp_path / "out").exists()


def test_a_csv_of_a_european_spreadsheet_reads_as_any_other():
    from roastlab.io.batch import as_comma_separated

    assert as_comma_separated("time,BT\n0,131.7\n") == "time,BT\n0,131.7\n"  # comma-separated: as it is
    eu = "# Röster 1\nZeit;BT (°C);Ereignis\n00:00,0;131,7;Charge, 200 g\n00:01,5;-1,5;\n"
    assert as_comma_separated(eu) == '# Röster 1\nZeit,BT (°C),Ereignis\n00:00.0,131.7,"Charge, 200 g"\n00:01.5,-1.5,\n'
    assert as_comma_separated("t\tBT\n1,5\t131,7\n") == "t,BT\n1.5,131.7\n"  # tab-separated too


def test_init_reads_a_semicolon_csv_with_decimal_commas(cli, tmp_path):
    """SYNTHETIC: a log as a German spreadsheet exports it (Zeit;BT;ET;Brenner;Luft, decimal commas):
    set up and imported as the comma-separated log with decimal points is."""
    from roastlab.io.importers.mapping import import_log, load_map

    logs = {}
    for sep, dec in ((";", ","), (",", ".")):
        folder = tmp_path / ("eu" if sep == ";" else "us")
        folder.mkdir()
        for k, grams in enumerate((230, 250)):
            rows = [sep.join(["Zeit", "BT", "ET", "Brenner", "Luft"])]
            for i in range(120):
                bt = 150.0 - 1.0 * i if i < 30 else 120.0 + 0.6 * (i - 30)
                cells = [f"{2.5 * i:.1f}", f"{bt:.1f}", f"{bt + 30:.1f}", f"{60 + 10 * (i > 60)}", f"{40 + k}"]
                rows.append(sep.join(c.replace(".", dec) for c in cells))
            (folder / f"roast{k}_{grams}g.csv").write_text("\n".join(rows) + "\n")
        logs[sep] = sorted(folder.glob("*.csv"))
        code, out, err = cli("init", *logs[sep], "--out", folder / "cfg")
        assert code == 0 and "heater: Brenner (percent); fan: Luft (percent)" in out, err
    a = import_log(logs[";"][0], load_map(tmp_path / "eu" / "cfg" / "map.toml"))
    b = import_log(logs[","][0], load_map(tmp_path / "us" / "cfg" / "map.toml"))
    assert np.array_equal(a.time_s, b.time_s) and np.array_equal(a.Ta_C, b.Ta_C) and a.Ta_C[10] != a.Ta_C[0]


def test_a_log_that_records_no_burner_is_named_and_the_others_set_up(cli, tmp_path):
    """SYNTHETIC: Artisan logs a setting only when it moves; a roast whose burner never moved has no
    Burner events. init keeps the other logs' layout and names that log (fit-roaster leaves it out)."""
    logs = [tmp_path / f"r{k}.alog" for k in range(3)]
    for k, p in enumerate(logs):
        p.write_text(fake_alog(extra=_BURNER_AIR if k < 2 else {}))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    assert (
        "1 log(s) record no Burner (r2.alog)" in out
        and 'column = "Burner"' in (tmp_path / "cfg" / "map.toml").read_text()
    )


def test_a_control_the_logs_name_differently_is_one_control_read_by_each_logs_name(cli, tmp_path):
    """SYNTHETIC: a roaster's event types renamed between roasts (Artisan's Burner and Air, later
    Power and Fan, as after a change of machine setup) are one heater and one fan: the map lists the
    names, the most used first, and each log reads by the name it has. A heater in percent under one
    name and in watts under the other is two layouts, refused as before."""
    from roastlab.io.importers.mapping import import_log, load_map

    renamed = {**_BURNER_AIR, "etypes": ["Fan", "Drum", "Damper", 'Power "2"', "--"]}  # a quote: TOML escapes it
    logs = [tmp_path / f"r{k}.alog" for k in range(3)]
    for k, p in enumerate(logs):
        p.write_text(fake_alog(extra=_BURNER_AIR if k < 2 else renamed))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    assert 'heater: Burner/Power "2" (percent); fan: Air/Fan (percent)' in out
    assert 'the logs name the heater differently (Burner: 2 log(s), Power "2": 1 log(s))' in out
    text = (tmp_path / "cfg" / "map.toml").read_text()
    assert 'column = ["Burner", "Power \\"2\\""]' in text and 'column = ["Air", "Fan"]' in text
    cmap = load_map(tmp_path / "cfg" / "map.toml")
    a, b = import_log(logs[0], cmap), import_log(logs[2], cmap)
    for what in ("heater", "fan"):  # the same events under either name: the same setting
        assert np.array_equal(getattr(a, what), getattr(b, what)) and np.nanmax(getattr(a, what)) > 0
    # the only log of one name unweighed (left out): its name is still one of the heater's, no traceback
    unweighed = tmp_path / "u.alog"
    unweighed.write_text(
        fake_alog(extra={**renamed, "etypes": ["Fan", "Drum", "Damper", "Heat", "--"], "weight": [0, 0, "g"]})
    )
    code, out, err = cli("init", *logs[:2], unweighed, "--out", tmp_path / "cfg3")
    assert code == 0 and "Heat: 1 log(s)" in out and "1 log(s) record no green weight" in out, err
    watts = {"extratimex": [[1.5 * i for i in range(120)]], "extraname1": ["Power"], "extratemp1": [[900.0] * 120],
             "extraNoneTempHint1": [True]}  # fmt: skip
    logs[2].write_text(fake_alog(extra=watts))
    code, _, err = cli("init", *logs, "--out", tmp_path / "cfg2")
    assert code == 2 and "disagree on heater channels (Burner in percent, Power in W)" in err, err
    assert err.count("\n") == 1 and not (tmp_path / "cfg2").exists()


def test_a_model_below_the_baseline_is_called_not_usable_with_what_the_logs_lack():
    from roastlab.io.importers.mapping import ColumnMap

    et_driven = ColumnMap(source="map.toml", Tgi={"column": "ET"})
    heated = ColumnMap(source="map.toml", Tgi={"constant_C": 22.0}, heater={"column": "Burner"})
    assert roaster.below_baseline(80.0, 33.0, et_driven) is None
    text = roaster.below_baseline(13.8, 33.0, et_driven)
    assert "13.8 % against 33.0 %" in text and "no heater setting is logged" in text and "logged ET" in text
    text = roaster.below_baseline(20.0, 33.0, heated)
    assert "worse than a first-order lag" in text and "heater" not in text
    inlet = ColumnMap(source="map.toml", Tgi={"column": "Zuluft"})  # a logged inlet drives it: nothing to add
    assert "no heater setting" not in roaster.below_baseline(20.0, 33.0, inlet)


@pytest.mark.parametrize(
    "case, words",
    [
        ("no weight", "--batch-kg"),
        ("mixed machines", "different roasters"),
        ("no BT", "bean temperature"),
        ("nothing drives the model", "neither a heater setting nor ET"),
        ("one log records the heater", "only one log records the Burner setting"),
        ("degF declared as degC", "°F data declared as °C?"),
    ],
)
def test_init_bad_input_is_one_line_saying_what_to_pass(cli, tmp_path, case, words):
    a = tmp_path / "a.alog"
    b = tmp_path / "b.alog"
    if case == "no weight":
        a.write_text(fake_alog(extra={"weight": [0, 0, "g"]}))
        b.write_text(fake_alog())
    elif case == "mixed machines":
        a.write_text(fake_alog(extra={"roastertype": "Hottop"}))
        b.write_text(fake_alog(extra={"roastertype": "Behmor"}))
    elif case == "no BT":
        a.write_text(fake_alog(extra={"temp2": [-1] * 120}))
        b.write_text(fake_alog())
    elif case == "one log records the heater":
        a.write_text(fake_alog(extra=_BURNER_AIR))
        b.write_text(fake_alog())
    elif case == "degF declared as degC":  # BT 400 degF at DROP in a log whose mode says C
        a.write_text(fake_alog(bt=[266.0 + 1.2 * i for i in range(120)]))
        b.write_text(fake_alog())
    else:  # no heater events and no ET
        a.write_text(fake_alog(et=[-1.0] * 120))
        b.write_text(fake_alog(et=[-1.0] * 120))
    code, _, err = cli("init", a, b, "--out", tmp_path / "cfg")
    assert code == 2 and words in err and err.count("\n") == 1, err
    assert not (tmp_path / "cfg").exists()


def test_init_takes_a_probe_fault_before_drop_for_what_it_is(cli, tmp_path):
    """SYNTHETIC: a probe that jumps to 349 degC before DROP (as one Skywalker log's does) is a fault
    the import cuts, not a log in degF: init sets it up."""
    bt = [130.0 - 0.2 * i if i < 30 else 124.0 + 0.5 * (i - 30) for i in range(120)]
    bt[100:] = [349.0] * 20
    logs = [tmp_path / "a.alog", tmp_path / "b.alog"]
    logs[0].write_text(fake_alog(bt=bt, extra=_BURNER_AIR))
    logs[1].write_text(fake_alog(extra=_BURNER_AIR))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err


@pytest.mark.slow
@pytest.mark.parametrize("machine, pattern", [("skywalker", "*.alog"), ("bullet", "*_49[0]g.json *_500g.json")])
def test_init_and_fit_roaster_reach_the_hand_written_examples_on_the_shared_logs(cli, tmp_path, machine, pattern):
    """No hand edits: the held-out FIT is within 2 points of the hand-written example's files
    (examples/<machine>/) fitted and held out on the same split, and beats the first-order baseline."""
    folder = REAL_DATA / machine
    if not folder.is_dir():
        pytest.skip("../shared/data/real is absent")
    logs = sorted({p for pat in pattern.split() for p in folder.glob(pat)})
    assert cli("init", *logs, "--out", tmp_path / "cfg")[0] == 0
    example = tmp_path / "example"
    example.mkdir()
    for name in ("map.toml", "plant.toml", "fit.toml"):
        shutil.copy(Path(__file__).resolve().parents[1] / "examples" / machine / name, example / name)
    held, inside, width = {}, {}, {}
    for cfg in ("cfg", "example"):
        code, out, err = cli("fit-roaster", tmp_path / cfg, *logs)
        assert code == 0, err
        held[cfg] = printed_percent(out, "held out: FIT ")
        base = printed_percent(out, "baseline: ")
        inside[cfg] = printed_percent(out, "band:")
        width[cfg] = float(out.split("median width ")[1].split(" °C")[0])
        assert out.splitlines()[-1].endswith(f"{tmp_path / cfg / 'heldout.png'}")  # the figure is said with the files
    assert abs(held["cfg"] - held["example"]) <= 2.0 and held["cfg"] > base + 20, held
    # the 90 % band on the held-out logs: about its level and not uselessly wide (measured
    # 2026-11-25: Skywalker 96 %, 34.5 °C, since 2026-11-26 92 %, 14.5 °C; Bullet 94 %, 19.0 °C;
    # 100 % and 70 °C on the Skywalker while the band drew parameter sets instead of propagating
    # the covariance)
    # (2026-11-27, the Skywalker with its first-crack marks read as the beans: 83 %, 15.1 °C)
    assert 80.0 <= inside["cfg"] <= 98.0 and width["cfg"] < 40.0, (inside, width)
    doc = json.loads((tmp_path / "cfg" / "model.json").read_text())
    assert doc["format"] == "roastlab-model/1"
    report = (tmp_path / "cfg" / "report.md").read_text()
    assert "sorted by date" in report and "held out" in report
    assert "| inside the 90 % band |" in report and "lie inside the 90 % prediction band" in report
    assert "measured and predicted BT, the 90 % prediction band shaded" in report
    assert (tmp_path / "cfg" / "heldout.png").stat().st_size > 20_000


@pytest.mark.slow
def test_a_band_fitted_on_three_logs_stays_usable_with_the_drum_start_share_free(cli, tmp_path):
    """Six Skywalker logs, three fitted: with the drum-start share free, two logs barely determine
    it, and the band's spread between roasts, each fitted log's error had it been left out, took a
    linearised step of 354 in the share and a band 329 degC wide (2026-11-27, session 21); each log
    is now refitted without it (fit.uncertainty.held_out_residuals): 26.5 degC measured."""
    folder = REAL_DATA / "skywalker"
    if not folder.is_dir():
        pytest.skip("../shared/data/real is absent")
    logs = sorted(folder.glob("*.alog"))[:6]
    assert cli("init", *logs, "--out", tmp_path / "cfg")[0] == 0
    assert "Tm0_share" in (tmp_path / "cfg" / "fit.toml").read_text()
    code, out, err = cli("fit-roaster", tmp_path / "cfg", *logs)
    assert code == 0, err
    width = float(out.split("median width ")[1].split(" °C")[0])
    assert width < 45.0 and printed_percent(out, "band:") >= 80.0, out


def _truth_of_init(cfg: Path, **values):
    """The model ``roastlab init``'s files describe (its plant, map, bed laws and probe depth: held, or
    where the logs span batch sizes the start of its fit), with chosen heater and flow values: the truth
    the SYNTHETIC logs below are drawn from, so that the fit they test can reach it. The drum at CHARGE
    comes from the log, as the map reads it."""
    import roastlab
    from roastlab.io.fitspec import load_fit_spec
    from roastlab.io.importers import load_map
    from roastlab.workflows.model import FittedModel

    spec = load_fit_spec(cfg / "fit.toml")
    depth = {f.name: f.start for f in spec.free if f.name == "h_probe_m"}
    truth = FittedModel.paper(roastlab.load_plant(cfg / "plant.toml")).with_values(**spec.fixed, **depth, **values)
    truth.bed = spec.bed
    truth.doc["map"] = load_map(cfg / "map.toml").to_mapping()
    return FittedModel(truth.doc)


def _synthetic_hottop_logs(folder: Path, n_logs: int = 6, seed: int = 7) -> list[Path]:
    """SYNTHETIC Artisan logs of a machine no example describes: a Fahrenheit Hottop whose heater
    and fan are extra-device curves (%), 0.25 kg batches. The layout comes from
    test_importers.fake_alog; BT and ET (the outlet gas) are roastlab's own model of the catalogue's Hottop
    (``roastlab init`` on the layout) with chosen heater/actuator values, plus seeded noise."""
    import numpy as np

    import roastlab
    from roastlab.io.importers import load_map

    rng = np.random.default_rng(seed)
    n, dt = 145, 5.0  # 12 minutes, a sample every 5 s
    t = [dt * i for i in range(n)]
    layouts = []
    for _ in range(n_logs):
        heater = np.full(n, 80.0)
        for start in sorted(rng.choice(np.arange(12, n - 10), size=3, replace=False)):
            heater[start:] = np.clip(heater[start] + rng.choice([-15.0, -10.0, 10.0]), 40.0, 100.0)
        fan = np.where(np.arange(n) < rng.integers(60, 100), 20.0, 40.0)
        layouts.append((heater, fan))
    extra = {"roastertype": "Hottop KN-8828B-2K+", "extratimex": [t], "extraname1": ["Heater"], "extraname2": ["Fan"],
             "extraNoneTempHint1": [True], "extraNoneTempHint2": [True], "weight": [250.0, 210.0, "g"],
             "timeindex": [0, 0, 0, 0, 0, 0, n - 1, 0]}  # fmt: skip
    f = lambda c: [float(v) * 9.0 / 5.0 + 32.0 for v in c]  # noqa: E731 - degC -> degF
    paths = []
    for k, (heater, fan) in enumerate(layouts):  # first the layout alone, BT at CHARGE the drum's
        p = folder / f"hottop_2026-0{1 + k // 3}-1{k % 3}.alog"
        p.write_text(fake_alog("F", f([210.0] * n), f([220.0] * n), n, {**extra, "timex": t,
                     "extratemp1": [heater.tolist()], "extratemp2": [fan.tolist()]}))  # fmt: skip
        paths.append(p)
    cfg = folder / "truth"
    from roastlab.cli.main import main

    assert main(["init", *map(str, paths), "--out", str(cfg)]) == 0
    cmap = load_map(cfg / "map.toml")
    truth = _truth_of_init(cfg, Qe_gain_kW=0.003, Tgi_gain_C=1.5, tau_heater_s=40.0, Gg_kg_s=0.004, Kt=0.03)
    for p, (heater, fan) in zip(paths, layouts):
        sim = truth.predict(roastlab.load_log(p, cmap))
        bt = sim.Ta_C + rng.normal(0.0, 0.3, n)
        bt[0] = sim.Ta_C[0]  # at CHARGE the probe soaked in the empty drum: the drum's temperature, as the map reads it
        et = sim.Tgo_C + rng.normal(0.0, 0.3, n)  # ET: the drum's air (the outlet gas, as a fit weighs it)
        p.write_text(fake_alog("F", f(bt), f(et), n, {**extra, "timex": t,
                     "extratemp1": [heater.tolist()], "extratemp2": [fan.tolist()]}))  # fmt: skip
    shutil.rmtree(cfg)
    return paths


@pytest.mark.slow
def test_an_unseen_fahrenheit_hottop_is_fitted_with_no_hand_edits(cli, tmp_path):
    """init + fit-roaster on SYNTHETIC logs of a machine no example describes (Fahrenheit,
    heater and fan as extra-device curves): no hand edits, and the held-out FIT beats the
    first-order baseline fed the same inputs."""
    logs = _synthetic_hottop_logs(tmp_path)
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    text = (tmp_path / "cfg" / "map.toml").read_text()
    assert 'column = "Heater"' in text and 'column = "Fan"' in text
    code, out, err = cli("fit-roaster", tmp_path / "cfg", *logs)
    assert code == 0, err
    held = printed_percent(out, "held out: FIT ")
    base = printed_percent(out, "baseline: ")
    assert held > 80.0 and held > base + 10.0, out


@pytest.mark.slow
def test_fit_roaster_every_log_holds_each_log_out_once(cli, tmp_path):
    """--every-log: each SYNTHETIC log predicted by a fit on the others, with the fit spec's own
    bed laws; the report gets a row per log and the overall figures, the terminal one line."""
    logs = _synthetic_hottop_logs(tmp_path, n_logs=4)  # four: each held out once is five fits
    assert cli("init", *logs, "--out", tmp_path / "cfg")[0] == 0
    code, out, err = cli("fit-roaster", tmp_path / "cfg", *logs, "--every-log")
    assert code == 0, err
    line = out.split("each log held out once: FIT ")[1]
    cv = float(line.split(" %")[0])
    held = printed_percent(out, "held out: FIT ")
    assert 80.0 < cv <= 100.0 and abs(cv - held) < 10.0, out
    assert "inside the band of the fit without their log" in line
    report = (tmp_path / "cfg" / "report.md").read_text()
    section = report.split("## Every log held out once")[1]
    rows = [r for r in section.splitlines() if r.startswith("| hottop_")]
    assert len(rows) == len(logs) and f"FIT {cv:.1f} % on average" in section
    # without the flag: no section, no line
    code, out, err = cli("fit-roaster", tmp_path / "cfg", *logs)
    assert code == 0 and "each log held out once" not in out
    assert "## Every log held out once" not in (tmp_path / "cfg" / "report.md").read_text()


def _synthetic_gas_drum_logs(
    folder: Path, n_logs: int = 6, seed: int = 11, inlet: bool = False, batches_g=None, simulated_g=None
) -> list[Path]:
    """SYNTHETIC Artisan logs of a gas drum no catalogue entry names: the burner is logged as
    special events only (Artisan's slider, German event names: Luft, Trommel, Klappe, Brenner),
    no extra devices, 3 kg batches on a 5 kg machine, a sample every 3 s. BT and ET come from
    roastlab's own model of the plant ``roastlab init`` estimates from the capacity (with chosen
    gains), plus seeded noise: a check of the pipeline on this layout, not of the physics.
    ``inlet``: a shop roaster that logs temperatures only, the burner heating the air alone: no
    burner events, an extra device "Zuluft" (inlet air) with the model's inlet gas instead.
    ``batches_g``: each log's green weight (default 3 kg each; ``n_logs`` is then their number);
    ``simulated_g``: the batch the model roasts for each log, when it differs from the weight the
    log records (a log whose weight is wrong)."""
    import numpy as np

    import roastlab
    from roastlab.io.importers import load_map

    rng = np.random.default_rng(seed)
    batches_g = list(batches_g or [3000.0] * n_logs)
    simulated_g = list(simulated_g or batches_g)
    n_logs = len(batches_g)
    n, dt = 241, 3.0  # 12 minutes
    t = [dt * i for i in range(n)]
    layouts = []
    for _ in range(n_logs):
        changes = sorted(rng.choice(np.arange(20, n - 20), size=4, replace=False).tolist())
        levels = [int(v) for v in rng.choice([40, 50, 60, 70, 80], size=5)]
        idx = [0, *changes]
        # Artisan's internal encoding of a slider value v %: 1 + v / 10
        events = {"specialevents": idx, "specialeventstype": [3] * len(idx),
                  "specialeventsvalue": [1.0 + v / 10.0 for v in levels[: len(idx)]]}  # fmt: skip
        layouts.append(events)
    extra = {"roastertype": "Werkstatt-Trommelröster 5 kg", "etypes": ["Luft", "Trommel", "Klappe", "Brenner", "--"],
             "weight": [3000.0, 2580.0, "g"], "timeindex": [0, 0, 0, 0, 0, 0, n - 1, 0]}  # fmt: skip
    paths = []
    for k, events in enumerate(layouts):
        p = folder / f"gasdrum_2026-{1 + k // 3:02d}-2{k % 3}.alog"
        weight = {"weight": [simulated_g[k], 0.86 * simulated_g[k], "g"]}  # the truth roasts this batch
        p.write_text(fake_alog("C", [230.0] * n, [200.0] * n, n, {**extra, **events, **weight, "timex": t}))
        paths.append(p)
    cfg = folder / "truth"
    from roastlab.cli.main import main

    assert main(["init", *map(str, paths), "--out", str(cfg), "--batch-capacity-kg", "5"]) == 0
    cmap = load_map(cfg / "map.toml")
    truth = _truth_of_init(
        cfg, Qe_gain_kW=0.0 if inlet else 0.05, Tgi_gain_C=3.0, tau_heater_s=25.0, Gg_kg_s=0.06, Kt=0.04
    )
    for k, (p, events) in enumerate(zip(paths, layouts)):
        sim = truth.predict(roastlab.load_log(p, cmap))  # on the map's resampled grid
        bt = np.interp(t, sim.time_s, sim.Ta_C) + rng.normal(0.0, 0.3, n)
        bt[0] = sim.Ta_C[0]  # at CHARGE the probe soaked in the empty drum: the drum's temperature, as the map reads it
        et = np.interp(t, sim.time_s, sim.Tgo_C) + rng.normal(0.0, 0.3, n)  # ET: the drum's air (outlet gas)
        if inlet:
            tgi = np.interp(t, sim.time_s, sim.gas_seen()[1]) + rng.normal(0.0, 0.3, n)  # the air the burner heats
            events = {"extradevices": [25], "extraname1": ["Zuluft"], "extraname2": ["Abluft"], "extratimex": [t],
                      "extratemp1": [tgi.tolist()], "extratemp2": [(et - 20.0).tolist()],
                      "extraNoneTempHint1": [False], "extraNoneTempHint2": [False]}  # fmt: skip
        weight = {"weight": [batches_g[k], 0.86 * batches_g[k], "g"]}  # what the log records
        p.write_text(fake_alog("C", bt.tolist(), et.tolist(), n, {**extra, **events, **weight, "timex": t}))
    shutil.rmtree(cfg)
    return paths


@pytest.mark.slow
def test_an_unseen_gas_drum_with_burner_events_is_fitted_with_no_hand_edits(cli, tmp_path, monkeypatch):
    """init + fit-roaster on SYNTHETIC logs of a gas drum whose burner is logged as special
    events (German names), given only its capacity: the burner is found by name, and the
    held-out FIT beats the first-order baseline fed the same inputs."""
    from roastlab.report import figures

    logs = _synthetic_gas_drum_logs(tmp_path)
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg", "--batch-capacity-kg", "5")
    assert code == 0, err
    text = (tmp_path / "cfg" / "map.toml").read_text()
    # its outlet gas falls far at CHARGE (0.4 of the way from the room to the probe), not to the beans
    assert 'column = "Brenner"' in text and "ET: yes" in out, text
    drawn = []  # the held-out figure's bands, as fit-roaster hands them to the figure
    plot_fit = figures.plot_fit
    monkeypatch.setattr(figures, "plot_fit", lambda result, **kw: drawn.append(kw["bands"]) or plot_fit(result, **kw))
    code, out, err = cli("fit-roaster", tmp_path / "cfg", *logs)
    assert code == 0, err
    # the figure shades each held-out log's band, the one the report scores
    (bands,) = drawn
    report = (tmp_path / "cfg" / "report.md").read_text()
    assert "the 90 % prediction band shaded" in report
    widths = [
        float(r.split("|")[5]) for r in report.split("its median width °C |")[1].splitlines()[2:] if r.count("|") == 6
    ]
    assert [round(b.median_width_C, 1) for b in bands] == widths and len(widths) >= 2, report
    held = printed_percent(out, "held out: FIT ")
    base = printed_percent(out, "baseline: ")
    assert held > 80.0 and held > base + 10.0, out
    # the report also as one page a browser opens: its tables as tables, its figure inside it
    page = (tmp_path / "cfg" / "report.html").read_text(encoding="utf-8")
    assert page.startswith("<!doctype html>") and "report.html" in out.splitlines()[-1]
    assert page.count("<table>") == (tmp_path / "cfg" / "report.md").read_text().count("\n|---") > 1
    assert page.count('<img src="data:image/png;base64,') == 1 and 'src="heldout.png"' not in page
    # and as a fleet, with init's fleet spec under fit-roaster's model: still no hand-written file
    pytest.importorskip("duckdb")
    cfg = tmp_path / "cfg"
    rows = ["path,machine,plant,started_at,map"]
    rows += [f"{p},drum,{cfg / 'plant.toml'},2026-01-0{i + 1}T10:00:00,{cfg / 'map.toml'}" for i, p in enumerate(logs)]
    (tmp_path / "m.csv").write_text("\n".join(rows) + "\n")
    assert cli("fleet", "ingest", "--db", tmp_path / "f.duckdb", "--manifest", tmp_path / "m.csv")[0] == 0
    free = survey.fleet_spec_text((cfg / "fit.toml").read_text())
    assert (cfg / "fleet.toml").read_text() == free and "\nQe_gain_kW = [" in free and "\nKt = [" in free
    code, out, err = cli(
        "fleet",
        "fit",
        "--db",
        tmp_path / "f.duckdb",
        "--spec",
        f"drum={cfg / 'fleet.toml'}",
        "--model",
        f"drum={cfg / 'model.json'}",
    )
    assert code == 0, err
    code, out, err = cli("fleet", "report", "--db", tmp_path / "f.duckdb")
    assert code == 0 and "Qe_gain_kW" in out and "Kt" in out, err
    assert float(out.splitlines()[1].split()[2]) > held, out  # each batch's own fit reads closer than held out


#: Green weights [g] of the SYNTHETIC gas drum's logs in the batch-size tests: five at 3 kg (the fit size),
#: two each at 2 and 4 kg.
_SIZES_G = [3000.0, 2000.0, 3000.0, 4000.0, 3000.0, 2000.0, 3000.0, 4000.0, 3000.0]


def _across_sizes(cli, folder: Path, logs) -> tuple[dict, str]:
    """init + fit-roaster --by-size on ``logs``: the across-sizes figures (the report's rows) and the terminal."""
    assert cli("init", *logs, "--out", folder / "cfg", "--batch-capacity-kg", "5")[0] == 0
    code, out, err = cli("fit-roaster", folder / "cfg", *logs, "--by-size")
    assert code == 0, err
    report = (folder / "cfg" / "report.md").read_text()
    section = report.split("## Across batch sizes")[1]
    rows = {r.split("|")[1].strip(): r for r in section.splitlines() if r.startswith("| ")}
    return {"out": out, "section": section, "rows": rows}, report


@pytest.mark.slow
def test_fit_roaster_by_size_carries_a_synthetic_drum_over_to_other_batches(cli, tmp_path):
    """--by-size on SYNTHETIC logs the model itself made at 2, 3 and 4 kg (the paper's claim true by
    construction): fitted on three of the five 3 kg logs (the 1st, 3rd, 5th), the model predicts the 2 and 4 kg
    logs about as well as the held-out 3 kg ones. Where the 2 and 4 kg logs record a weight the truth did not
    roast (it roasted 3 kg), the same command finds a gap: the figure follows the batch's mass."""
    (tmp_path / "right").mkdir()
    logs = _synthetic_gas_drum_logs(tmp_path / "right", batches_g=_SIZES_G)
    right, report = _across_sizes(cli, tmp_path / "right", logs)
    assert "fitted on 3 kg (3 logs)" in right["out"], right["out"]
    assert (tmp_path / "right" / "cfg" / "sizes.png").stat().st_size > 10_000
    assert right["out"].splitlines()[-1].endswith("sizes.png"), right["out"]
    held = float(right["rows"]["3 kg, held out"].split("|")[3])
    other = float(right["rows"]["**every other size**"].split("|")[3])
    assert held > 90.0 and abs(other - held) < 3.0, right["section"]
    assert set(right["rows"]) >= {"2 kg", "4 kg"}
    assert sum("(held out, fit size)" in r for r in right["rows"]) == 2  # the 2nd and 4th 3 kg logs
    assert "second reading" not in right["section"]  # these logs have no second bean reading
    assert "other roasters" not in right["section"]  # nor name their roaster
    # the truth roasted 3 kg where the 2 and 4 kg logs say otherwise: the model, told 2 and 4 kg, misses them
    (tmp_path / "wrong").mkdir()
    wrong_logs = _synthetic_gas_drum_logs(tmp_path / "wrong", batches_g=_SIZES_G, simulated_g=[3000.0] * 9)
    wrong, _ = _across_sizes(cli, tmp_path / "wrong", wrong_logs)
    other_wrong = float(wrong["rows"]["**every other size**"].split("|")[3])
    assert other_wrong < other - 10.0, wrong["section"]
    # without the flag: no section, no line, no figure
    code, out, err = cli("fit-roaster", tmp_path / "right" / "cfg", *logs)
    assert code == 0 and "across sizes" not in out
    assert "## Across batch sizes" not in (tmp_path / "right" / "cfg" / "report.md").read_text()


@pytest.mark.slow
def test_fit_roaster_by_size_on_the_bullet_reads_the_scaling_gap_from_inits_files(cli, tmp_path):
    """The issue-25 check with no hand-written files: init's files on every weighed Bullet log, fitted on
    the size with the most logs (470-500 g on the shared logs, unit 2779), every other size predicted.
    The held-out logs of the fit size read well; the other sizes (other drums among them) read worse,
    and the report names each log's roaster. Counts come from the logs themselves, so more logs of the
    machine keep the test meaningful."""
    bullet = REAL_DATA / "bullet"
    if not bullet.is_dir():
        pytest.skip("../shared/data/real is absent")
    weighed = {}
    for p in bullet.glob("*.json"):
        doc = json.loads(p.read_text())
        if float(doc.get("weightGreen") or 0) > 0:
            weighed[p.stem] = str(doc.get("serialNumber", ""))
    assert cli("init", bullet, "--out", tmp_path / "cfg")[0] == 0
    # the drum at CHARGE is the preheat RoasTime held it at (a reading of the drum): no share of it to fit
    assert "Tm0_share" not in (tmp_path / "cfg" / "fit.toml").read_text()
    code, out, err = cli("fit-roaster", tmp_path / "cfg", bullet, "--by-size")
    assert code == 0, err
    line = out.split("across sizes: ")[1].splitlines()[0]
    n_fit = int(line.split(" logs), every other size")[0].split("(")[-1])
    held = float(line.split("against the fit size's held-out logs (")[1].split(" %")[0])
    n_held = int(line.split("against the fit size's held-out logs (")[1].split(" over ")[1].split(")")[0])
    other = float(line.split("every other size (FIT ")[1].split(" %")[0])
    n_other = int(line.split("every other size (FIT ")[1].split(" over ")[1].split(" logs")[0])
    assert n_fit + n_held + n_other == len(weighed), (line, len(weighed))
    assert held > 80.0 and other < held, line
    section = (tmp_path / "cfg" / "report.md").read_text().split("## Across batch sizes")[1]
    log_rows = [r for r in section.splitlines() if r.startswith("| bullet_")]
    assert len(log_rows) == n_held + n_other and sum("(held out, fit size)" in r for r in log_rows) == n_held
    for r in log_rows:  # each log's roaster, as its file records it
        assert r.split("|")[3].strip() == weighed[r.split("|")[1].split()[0]], r
    units = sorted(set(weighed.values()))
    assert f"from {len(units)} roasters ({', '.join(units)})" in section
    # the fit's own drum's other sizes apart from the other drums' (the issue's two figures), each a gap
    own = next(r for r in section.splitlines() if r.startswith("| other sizes, the fit's own roaster"))
    foreign = next(r for r in section.splitlines() if r.startswith("| other sizes, other roasters |"))
    assert int(own.split("|")[2]) + int(foreign.split("|")[2]) == n_other
    assert "; the fit's own roaster's other sizes " in line and "other roasters' " in line
    # the IR reading judges the beans apart from the probe: the held-out fit size's beans read well
    ref_row = next(r for r in section.splitlines() if ", held out |" in r)
    assert "beans vs the second reading" in section and float(ref_row.split("|")[7]) > 85.0, ref_row


def test_size_split_takes_the_size_with_the_most_logs_and_says_what_it_cannot_do():
    """Which logs fit, which are the fit size's held-out reference, which are other sizes; a tie
    goes to the heavier size; one line for each case it cannot serve."""
    from types import SimpleNamespace

    from roastlab.workflows.sizes import size_split

    def logs(*kg):
        return [SimpleNamespace(Mb_kg=m, name=f"log{k}", source=f"log{k}") for k, m in enumerate(kg)]

    split = size_split(logs(0.5, 0.2, 0.49, 0.5, 0.9, 0.5))
    assert split.fit_size == "0.49-0.5 kg" and split.fit == [0, 3] and split.reference == [2, 5]
    assert split.others == [1, 4] and split.labels[1] == "0.2 kg"
    assert size_split(logs(0.2, 0.5, 0.2, 0.5)).fit_size == "0.5 kg"  # a tie: the heavier
    named = size_split(logs(0.2, 0.5, 0.2, 0.5, 0.5), fit_size_kg=0.2)
    assert named.fit_size == "0.2 kg" and named.fit == [0] and named.reference == [2] and named.others == [1, 3, 4]
    for batches, kw, words in [
        (logs(0.5, 0.5, 0.49), {}, "all one batch size (0.49-0.5 kg)"),
        (logs(0.5, 0.5, 0.2), {"fit_size_kg": 0.9}, "no log of 0.9 kg (the logs' batch sizes: 0.2 kg, 0.5 kg)"),
        (logs(0.5, 0.2), {}, "only one log of 0.5 kg"),
    ]:
        with pytest.raises(InputError, match=re.escape(words)):
            size_split(batches, **kw)


def test_an_inlet_air_logged_beside_a_burner_is_offered_and_is_not_the_fan(cli, tmp_path):
    """SYNTHETIC logs with Burner and Air events and an extra device "Inlet Air" (a temperature): the
    Air events are the fan, not the inlet's reading; the heater stays the input and the map offers
    the inlet, commented, with what else to change."""
    n = 120
    extra = {"specialevents": [5, 40], "specialeventstype": [3, 0], "specialeventsvalue": [8.0, 4.0],
             "etypes": ["Air", "Drum", "Damper", "Burner", "--"], "extratimex": [[1.5 * i for i in range(n)]],
             "extraname1": ["Inlet Air"], "extraname2": ["Exhaust"], "extratemp1": [[300.0] * n],
             "extratemp2": [[150.0] * n], "extraNoneTempHint1": [False], "extraNoneTempHint2": [False]}  # fmt: skip
    logs = [tmp_path / f"r{k}.alog" for k in range(2)]
    for p in logs:
        p.write_text(fake_alog(extra=extra))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0 and "fan: Air (percent)" in out and "inlet air: Inlet Air (offered in the map)" in out, err
    text = (tmp_path / "cfg" / "map.toml").read_text()
    assert "constant_C = 22.0" in text and '# column = "Inlet Air"' in text and "remove Tgi_gain_C" in text


@pytest.mark.slow
def test_an_unseen_gas_drum_that_logs_its_inlet_air_and_no_burner_is_driven_by_the_inlet(cli, tmp_path):
    """init + fit-roaster on SYNTHETIC logs of a shop roaster that logs temperatures only: BT, ET and
    an extra device "Zuluft" (the inlet air, German), no burner. init takes the inlet as the
    model's input (the paper's Tgi) and ET as a reading against the outlet gas; before, ET itself
    drove the model as the inlet."""
    logs = _synthetic_gas_drum_logs(tmp_path, inlet=True)
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg", "--batch-capacity-kg", "5")
    assert code == 0 and "heater: none" in out and "inlet air: Zuluft (the model's input)" in out, err
    # its exhaust air "Abluft" (a temperature, named like the air: "Luft") is no fan in rpm
    assert "fan: none (-)" in out, out
    text = {n: (tmp_path / "cfg" / f"{n}.toml").read_text() for n in ("map", "fit")}
    assert '[Tgi]\ncolumn = "Zuluft"' in text["map"] and 'ET = "residual"' in text["fit"], text
    code, out, err = cli("fit-roaster", tmp_path / "cfg", *logs)
    assert code == 0, err
    held = printed_percent(out, "held out: FIT ")
    assert held > 90.0, out
    assert "\nWeight of ET from the residuals: " in (tmp_path / "cfg" / "report.md").read_text()


@pytest.mark.parametrize(
    "machine, capacity_kg, heat",
    [
        ("Hottop KN-8828B-2K+", 0.25, "both"),  # a fixed entry: the model's digits are not a capacity
        ("Aillio Bullet R1", 1.0, "drum"),
        ("Giesen W6A", 6.0, "both"),
        ("Loring S15 Falcon", 15.0, "air"),
        ("Probatone II 12Kg", 12.0, "both"),
        ("Diedrich IR-2.5", 2.5, "both"),
        ("Coffeetool R500", 0.5, "both"),  # grams: the fixed entry before the family's kg rule
        ("Coffeetool R15", 15.0, "both"),
        ("San Franciscan SF25", 25 * 0.45359237, "both"),  # pounds
        ("Skywalker", None, None),
        ("Giesen", None, None),  # the family without a model number: no capacity to read
    ],
)
def test_catalogue_reads_the_capacity_from_the_model_number(machine, capacity_kg, heat):
    entry = survey.catalogue_entry(machine)
    if capacity_kg is None:
        assert entry is None
    else:
        assert entry[0] == pytest.approx(capacity_kg) and entry[1] == heat and "(" in entry[2]  # a source


def test_init_states_a_capacity_read_from_the_catalogue(cli, tmp_path):
    extra = {"roastertype": "Giesen W6A", "weight": [3000.0, 0.0, "g"]}
    logs = []
    for k in range(2):
        p = tmp_path / f"g{k}.alog"
        p.write_text(fake_alog(extra=extra))
        logs.append(p)
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    plant = (tmp_path / "cfg" / "plant.toml").read_text()
    assert "batch capacity 6 kg: the catalogue: Giesen" in plant and "Mm_kg = 18" in plant  # 3 kg per kg
    assert 'name = "giesen-w6a"' in plant  # the make the logs record names the roaster


def test_init_names_the_roaster_as_asked_else_by_its_make_else_by_its_folder(cli, tmp_path):
    """SYNTHETIC .alog files that record no make: the plant (and so the model and report) takes --name,
    else the output folder's name; the page passes the name the roaster typed."""
    logs = []
    for k in range(2):
        p = tmp_path / f"r{k}.alog"
        p.write_text(fake_alog(extra={"weight": [200.0, 0.0, "g"]}))
        logs.append(p)
    assert cli("init", *logs, "--out", tmp_path / "garage-drum")[0] == 0
    assert 'name = "garage-drum"' in (tmp_path / "garage-drum" / "plant.toml").read_text()
    assert cli("init", *logs, "--out", tmp_path / "cfg", "--name", "Probat L12 (shop)")[0] == 0
    assert 'name = "probat-l12-shop"' in (tmp_path / "cfg" / "plant.toml").read_text()


@pytest.mark.parametrize(
    ("roastersize", "words"),
    [
        (12.0, "batch capacity 12 kg: the capacity 2 of 2 log(s) state"),  # before the catalogue's 6 kg
        (0.0, "batch capacity 6 kg: the catalogue: Giesen"),  # Artisan's "not set"
        (2.0, "batch capacity 6 kg: the catalogue: Giesen"),  # below the 3 kg logged: not a capacity
        ("12", "batch capacity 6 kg: the catalogue: Giesen"),  # not a number
    ],
)
def test_init_takes_the_capacity_the_logs_state(cli, tmp_path, roastersize, words):
    """SYNTHETIC logs whose Roast Properties state the machine's capacity (Artisan's roastersize, kg)."""
    extra = {"roastertype": "Giesen W6A", "weight": [3000.0, 0.0, "g"], "roastersize": roastersize}
    logs = []
    for k in range(2):
        logs.append(tmp_path / f"g{k}.alog")
        logs[-1].write_text(fake_alog(extra=extra))
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, err
    assert words in (tmp_path / "cfg" / "plant.toml").read_text()


@pytest.mark.parametrize(
    "header, want",
    [
        (["time", "BT_F", "ET_F"], ("time", "s", "BT_F", "ET_F", "F")),
        (["Time (min)", "bean temp °F", "exhaust"], ("Time (min)", "min", "bean temp °F", "exhaust", "F")),
        (["t", "BT RoR", "BT", "ET"], ("t", "s", "BT", "ET", "C")),  # a rate is not the reading
        (["seconds", "Bean", "Env (C)", "Burner"], ("seconds", "s", "Bean", "Env (C)", "C")),
        (["elapsed ms", "bt"], ("elapsed ms", "ms", "bt", None, "C")),
    ],
)
def test_a_plain_csvs_columns_are_found_by_name(header, want):
    c = survey.plain_csv_columns(header)
    assert (c["time"], c["time_unit"], c["BT"], c["ET"], c["temp_unit"]) == want


def test_notes_said_alike_on_many_logs_are_one_line_with_the_range():
    notes = {
        "a.alog": ["dropped 4 incomplete sample(s) (missing values)", "ET reads 32 °C below BT (median from 60 s)"],
        "b.alog": ["dropped 1 incomplete sample(s) (missing values)"],
        "c.alog": ["dropped 6 incomplete sample(s) (missing values)", "bean temperature jumps 176 -> 349 °C"],
        "d.alog": ["dropped 1 incomplete sample(s) (missing values)"],
        "e.alog": ["dropped 2 incomplete sample(s) (missing values)", "ET reads -3.5 °C below BT (median from 60 s)"],
    }
    lines = roaster.grouped_notes(notes)
    assert lines[0] == "5 logs: dropped 1-6 incomplete sample(s) (missing values)"  # more than NAMED_UP_TO: counted
    assert "a.alog: ET reads 32 °C below BT (median from 60 s)" in lines  # said on two logs: each as said
    assert "c.alog: bean temperature jumps 176 -> 349 °C" in lines and len(lines) == 4
    clock = {
        f"{k}.alog": [f"no DROP marked: taken at {t} after CHARGE"] for k, t in enumerate(("10:01", "9:58", "11:48"))
    }
    assert roaster.grouped_notes(clock) == [
        "3 logs (0.alog, 1.alog, 2.alog): no DROP marked: taken at 9:58-11:48 after CHARGE"
    ]
    notes["f.alog"] = ["ET reads 40 °C below BT (median from 60 s)"]
    assert (
        "3 logs (a.alog, e.alog, f.alog): ET reads -3.5 to 40 °C below BT (median from 60 s)"
        in roaster.grouped_notes(notes)
    )


def test_the_examples_fit_specs_bound_the_gas_flow_as_init_does():
    """The examples' hand-written fit specs and init's share one gas-flow range (GAS_FLOW_MIN_KG_S to
    GAS_FLOW_MAX_FLOOR_KG_S for roasters of their size): a change to one is a change to both."""
    from roastlab.io.fitspec import load_fit_spec
    from roastlab.workflows.survey import GAS_FLOW_MAX_FLOOR_KG_S, GAS_FLOW_MIN_KG_S

    for machine in ("skywalker", "bullet"):
        spec = load_fit_spec(Path(__file__).resolve().parents[1] / "examples" / machine / "fit.toml")
        gg = next(p for p in spec.free if p.name == "Gg_kg_s")
        assert (gg.lower, gg.upper) == (GAS_FLOW_MIN_KG_S, GAS_FLOW_MAX_FLOOR_KG_S), machine


def test_init_fits_the_probe_depth_where_the_logs_span_batch_sizes_without_a_bean_reading(cli, tmp_path):
    """SYNTHETIC logs of 200 and 300 g with the probe alone: init frees the probe's depth scale (the
    quantity table's bounds, started at the drum's diameter), which only a change of batch size determines
    and which alone tells the probe from the beans. With a bean reading beside the probe it holds it at
    the diameter and writes the line that frees it; logs of one size: held, no such line."""
    import re

    from roastlab.io.fitspec import load_fit_spec
    from roastlab.io.plants import load_plant
    from roastlab.model.bed import PROBE_DEPTH_OVER_DIAMETER
    from roastlab.model.quantities import quantity

    def spec_of(name, extra):
        logs = [tmp_path / f"{name}{k}.alog" for k in range(3)]
        for k, p in enumerate(logs):
            p.write_text(fake_alog(extra=dict(extra, **({"weight": [300, 0, "g"]} if k == 1 else {}))))
        assert cli("init", *logs, "--out", tmp_path / name)[0] == 0
        return logs, (tmp_path / name / "fit.toml").read_text(), load_fit_spec(tmp_path / name / "fit.toml")

    logs, text, spec = spec_of("probe", _BURNER_AIR)
    (h,) = [f for f in spec.free if f.name == "h_probe_m"]
    assert (h.lower, h.upper) == quantity("h_probe_m").bounds and "h_probe_m" not in spec.fixed
    assert "these logs span 200-300 g and no bean reading runs beside the probe" in text
    plant = load_plant(tmp_path / "probe" / "plant.toml")
    assert h.start == pytest.approx(PROBE_DEPTH_OVER_DIAMETER * plant.Dch_m, rel=1e-3)  # started at the diameter
    _, text, spec = spec_of("ir", dict(_BURNER_AIR, **_ir_as_et()))  # a bean reading beside the probe
    held = float(re.search(r"\n\[fixed\]\nh_probe_m = ([0-9.]+)", text).group(1))
    assert spec.fixed["h_probe_m"] == held
    hint = re.search(r"# these logs span 200-300 g, .* as (h_probe_m = \[[^\]]*\])", text)
    assert hint, text
    freed = text.replace("[free]\n", f"[free]\n{hint.group(1)}\n").replace(f"h_probe_m = {held:g} ", "# ")
    (tmp_path / "freed.toml").write_text(freed)
    (f,) = [f for f in load_fit_spec(tmp_path / "freed.toml").free if f.name == "h_probe_m"]
    assert (f.lower, f.upper) == quantity("h_probe_m").bounds and f.start == held
    assert cli("init", *logs[::2], "--out", tmp_path / "one")[0] == 0
    one = (tmp_path / "one" / "fit.toml").read_text()
    assert "these logs span" not in one and "\n[fixed]\nh_probe_m = " in one


def test_logs_of_unit_keeps_one_drums_logs_and_says_the_others_in_one_line():
    """``fit-roaster --unit``: the logs of one roaster unit (RoasTime's serial number), the others left
    out in one line with their units; no log of the unit, or only one, is bad input naming what there is."""
    from types import SimpleNamespace

    def info(name, unit):
        return SimpleNamespace(path=Path(name), unit=unit)

    infos = [info("a.json", "2779"), info("b.json", "2054"), info("c.json", "2779"), info("d.json", "2054")]
    infos += [info("e.json", "2779"), info("f.alog", "")]
    mine, why = roaster.logs_of_unit(infos, "2779")
    assert [i.path.name for i in mine] == ["a.json", "c.json", "e.json"]
    assert why == {"--unit": "3 log(s) of other units (2054: 2, (none named): 1), by --unit 2779"}
    assert roaster.logs_of_unit([infos[0], infos[2]], "2779")[1] == {}  # none left out, nothing said
    for unit, given, words in [
        ("9999", infos, "no log was recorded by unit 9999: the logs name units 2779: 3, 2054: 2 (serial number: logs)"),
        ("9999", [infos[5], info("g.alog", "")], "the logs name no unit"),
        ("2054", infos[:3], "unit 2054 recorded only b.json: fit-roaster needs two of its logs"),
    ]:
        with pytest.raises(InputError, match=re.escape(words)):
            roaster.logs_of_unit(given, unit)


@pytest.mark.slow
def test_fit_roaster_unit_fits_one_drums_logs_and_leaves_the_others_out(cli, tmp_path):
    """Five Bullet logs of one drum, written to tmp_path as two units (the copies' serial numbers set to
    111 and 222; the shared logs are read, never changed): init names both units and the option, and
    ``fit-roaster --unit 222`` fits and holds out 222's two logs alone, the other three said in one line."""
    bullet = REAL_DATA / "bullet"
    if not bullet.is_dir():
        pytest.skip("../shared/data/real is absent")
    logs = sorted(bullet.glob("bullet_*_49?g.json"))[:5]
    folder = tmp_path / "logs"
    folder.mkdir()
    for k, p in enumerate(logs):
        doc = json.loads(p.read_text())
        doc["serialNumber"] = 222 if k in (1, 2) else 111
        (folder / p.name).write_text(json.dumps(doc))
    code, out, _ = cli("init", folder, "--out", tmp_path / "cfg")
    assert code == 0 and "(serial number: logs; 111: 3, 222: 2)" in out and "fit-roaster --unit 111" in out, out
    # without --unit: one fit of both, its held-out logs (the 2nd and 4th by date, one of each unit) by unit
    code, out, err = cli("fit-roaster", tmp_path / "cfg", folder)
    assert code == 0, err
    line = next(x for x in out.splitlines() if x.startswith("held out by unit: "))
    assert line.count(" % (1 log)") == 2 and "222 " in line and "111 " in line, line
    table = (tmp_path / "cfg" / "report.md").read_text().split("Held out by roaster unit")[1]
    assert sum(r.startswith(("| 111 | 1 |", "| 222 | 1 |")) for r in table.splitlines()) == 2, table
    code, out, err = cli("fit-roaster", tmp_path / "cfg", folder, "--unit", "222")
    assert code == 0, err
    assert "held out by unit" not in out  # one unit: nothing to tell apart
    assert "left out: 3 log(s) of other units (111: 3), by --unit 222" in out, out
    report = (tmp_path / "cfg" / "report.md").read_text()
    assert "2 logs sorted by date, split alternately: 1 fit, 1 held out" in report
    assert "Left out: 3 log(s) of other units (111: 3), by --unit 222." in report
    code, out, err = cli("fit-roaster", tmp_path / "cfg", folder, "--unit", "333")  # bad input: one line, exit 2
    assert code == 2 and len(err.strip().splitlines()) == 1 and "the logs name units 111: 3, 222: 2" in err, err


def test_held_out_by_unit_says_which_drum_a_shared_fit_serves():
    """Per unit the held-out logs' paper Average FIT and MAE and the sample-weighted share inside the
    band; nothing where the logs name one unit (or none)."""
    from types import SimpleNamespace

    batches = [SimpleNamespace(unit=u) for u in ("2779", "2054", "2779", "")]
    from roastlab.evaluate.metrics import METRIC_NAMES

    rows = [
        {**dict.fromkeys(METRIC_NAMES, 0.0), "FIT": fit, "MAE": mae}
        for fit, mae in ((90.0, 2.0), (30.0, 20.0), (80.0, 4.0), (70.0, 5.0))
    ]
    band = [{"n": 100, "inside": 1.0}, {"n": 50, "inside": 0.1}, {"n": 300, "inside": 0.8}, {"n": 10, "inside": 0.5}]
    got = roaster.held_out_by_unit(batches, rows, band)
    assert [(g["unit"], g["logs"]) for g in got] == [("2779", 2), ("2054", 1), ("(none named)", 1)]
    assert got[0]["FIT"] == pytest.approx(85.0) and got[0]["MAE"] == pytest.approx(3.0)
    assert got[0]["inside"] == pytest.approx((100 * 1.0 + 300 * 0.8) / 400)
    assert roaster.held_out_by_unit(batches, rows)[1]["inside"] is None  # no band: no share
    assert roaster.held_out_by_unit(batches[:1] + batches[2:], rows[:1] + rows[2:]) == []  # one unit named


def _as_fahrenheit(src: Path, dst: Path) -> Path:
    """A copy of the Artisan log ``src`` as Artisan writes it in Fahrenheit mode (``mode`` "F"):
    BT, ET, the room and the phase limits in degF, -1 (no sample) and 0 (no room entered) kept.
    Read with ``ast.literal_eval`` (data only)."""
    import ast

    def f(v):  # written here, not taken from roastlab: the test checks the importer's inverse
        return v if v == -1 else round(v * 9.0 / 5.0 + 32.0, 4)

    d = ast.literal_eval(src.read_text(encoding="utf-8"))
    d["mode"] = "F"
    d["temp1"], d["temp2"] = [f(v) for v in d["temp1"]], [f(v) for v in d["temp2"]]
    if d.get("ambientTemp"):
        d["ambientTemp"] = f(d["ambientTemp"])
    d["phases"] = [f(v) for v in d.get("phases", [])]
    out = dst / src.name
    out.write_text(repr(d), encoding="utf-8")
    return out


@pytest.mark.slow
def test_a_roaster_logging_in_fahrenheit_gets_the_fit_it_gets_in_celsius(cli, tmp_path):
    """The same six Skywalker roasts as Artisan writes them in Fahrenheit mode: init writes the
    same map, plant and fit spec, and fit-roaster (the inlet air taken from the room each log
    records) the same held-out figures: the importer reads every temperature, the room among
    them, in the profile's unit (the copies round to 1e-4 degF). The roaster who logs in degF
    reads the errors in degF, on the terminal and in the report, and validate's table, band and notes
    likewise (``--units C`` asks for degC); the model file is the same."""
    folder = REAL_DATA / "skywalker"
    if not folder.is_dir():
        pytest.skip("../shared/data/real is absent")
    logs = sorted(folder.glob("*.alog"))[:6]
    (tmp_path / "F").mkdir()
    logs_F = [_as_fahrenheit(p, tmp_path / "F") for p in logs]
    held, mae = {}, {}
    for unit, paths in (("C", logs), ("F", logs_F)):
        # one name for both (by default each would take its folder's: the logs name no make)
        assert cli("init", *paths, "--out", tmp_path / f"cfg{unit}", "--name", "Skywalker")[0] == 0
        map_toml = tmp_path / f"cfg{unit}" / "map.toml"  # the inlet air from the room each log records
        assert "# room = true" in map_toml.read_text()
        map_toml.write_text(map_toml.read_text().replace("# room = true", "room = true"))
        code, out, err = cli("fit-roaster", tmp_path / f"cfg{unit}", *paths)
        assert code == 0, err
        held[unit] = printed_percent(out, "held out: FIT ")
        mae[unit] = float(out.split("held out: FIT")[1].split("MAE ")[1].split(f" °{unit}")[0])
        report = (tmp_path / f"cfg{unit}" / "report.md").read_text()
        assert (f"| model MAE °{unit} |" in report) and (("Temperatures in °F" in report) == (unit == "F"))
        # the first fit's misses that set ET's weight, and the baseline's offset, in the same unit
        baseline = next(line for line in report.splitlines() if line.startswith("Baseline:"))
        assert f" °{unit} RMS and ET by " in report and re.search(rf"offset [-+]\d+\.\d\d deg{unit},", baseline)
        if unit == "F":  # degC only where the report says: the header naming it and the parameters' table
            celsius = [ln for ln in report.splitlines() if "°C" in ln or "degC" in ln]
            assert celsius[0].startswith("Temperatures in °F") and all(ln.startswith("| ") for ln in celsius[1:])
            assert "Refitted: " in report  # these six logs' first fit fails: its sentence's drum and beans in degF
    for name in ("plant.toml", "fit.toml"):
        assert (tmp_path / "cfgC" / name).read_text() == (tmp_path / "cfgF" / name).read_text(), name
    assert 'name = "skywalker"' in (tmp_path / "cfgC" / "plant.toml").read_text()
    # the map names the files it was written from, the same names in both folders
    assert (tmp_path / "cfgC" / "map.toml").read_text() == (tmp_path / "cfgF" / "map.toml").read_text()
    assert abs(held["C"] - held["F"]) < 0.2 and abs(9 / 5 * mae["C"] - mae["F"]) < 0.09, (held, mae)
    # the model the same, in degC, whatever the report shows
    theta = {u: roastlab.load_model(tmp_path / f"cfg{u}" / "model.json").theta for u in "CF"}
    assert theta["F"].hbm == pytest.approx(theta["C"].hbm, rel=1e-3)
    # validate speaks the logs' unit too: its table, the held-out line, the band's widths, the import's notes;
    # --units C reads the degF logs' own fit in degC (the two fits' bands are not compared: a three-log fit's
    # spread between roasts comes from refits on two logs, which need not agree)
    printed = []
    for cfg, paths, asked in (("C", logs, ()), ("F", logs_F, ()), ("F", logs_F, ("--units", "C"))):
        cfg = tmp_path / f"cfg{cfg}"
        code, out, err = cli(
            "validate", "--model", cfg / "model.json", "--map", cfg / "map.toml", *paths, "--band", *asked
        )
        assert code == 0, err
        unit = "F" if "°F" in out else "C"
        mae = float(out.split("held out only")[1].split("MAE ")[1].split(f" °{unit}")[0])
        band = float(out.split("median width\n")[1].split("\n")[0].split()[-2])
        average = next(line for line in out.splitlines() if line.startswith("average"))  # the probe's
        printed.append(
            (unit, mae, band, [float(v) for v in average.split()[1:]], err)
        )  # n SSR norm MAE MPE MAPE FIT rho
    (
        (_, mae_C, _, avg_C, err_C),
        (unit_F, mae_F, band_F, avg_F, err_F),
        (unit_asked, mae_asked, band_asked, avg_asked, _),
    ) = printed
    assert (unit_F, unit_asked) == ("F", "C") and mae_F == pytest.approx(9 / 5 * mae_C, abs=0.09)
    assert avg_F[3] == pytest.approx(9 / 5 * avg_C[3], rel=0.02) and avg_F[1] == pytest.approx(
        81 / 25 * avg_C[1], rel=0.04
    )
    assert avg_F[4:] == pytest.approx(avg_C[4:], abs=0.15)  # MPE, MAPE in % of the degC reading, FIT, rho: no unit
    assert mae_asked == pytest.approx(5 / 9 * mae_F, abs=0.01) and band_asked == pytest.approx(5 / 9 * band_F, abs=0.06)
    assert avg_asked[3] == pytest.approx(5 / 9 * avg_F[3], abs=2e-3) and avg_asked[4:] == avg_F[4:]
    assert "°F" not in err_C and ("°C" in err_C) == ("°F" in err_F)  # a note with a temperature, in the log's unit


def test_a_fit_on_one_batch_size_holds_the_probe_depth_the_spec_frees():
    """fit-roaster --by-size fits on one size: the probe's depth scale, which only a change of batch size
    determines, is held at its start there (and said); a fit on several sizes keeps it free."""
    from types import SimpleNamespace

    from roastlab.io.fitspec import FitSpec, FreeParameter

    spec = FitSpec([FreeParameter("hbm", 0.001, 1.0, 0.02), FreeParameter("h_probe_m", 0.0, 0.5, 0.155)], {"Kt": 0.02})
    one = [SimpleNamespace(Mb_kg=m) for m in (0.15, 0.152, 0.15)]
    held, said = roaster.depth_held_on_one_size(spec, one)
    assert [f.name for f in held.free] == ["hbm"] and held.fixed == {"Kt": 0.02, "h_probe_m": 0.155}
    assert said == "holds the probe's depth scale at 0.155 m: logs of one batch size cannot determine it"
    several = one + [SimpleNamespace(Mb_kg=0.25)]
    assert roaster.depth_held_on_one_size(spec, several) == (spec, None)
    no_depth = FitSpec([FreeParameter("hbm", 0.001, 1.0, 0.02)], {"h_probe_m": 0.155})
    assert roaster.depth_held_on_one_size(no_depth, one) == (no_depth, None)


@pytest.mark.parametrize(
    "name, unit",
    [("Gas kPa", "kPa"), ("Gas (mbar)", "mbar"), ("Burner hPa", "hPa"), ('Gas "WC', "inWC"), ("Gas in. WC", "inWC"),
     ("Gas inH2O", "inWC"), ("Gas mmH2O", "mmWC"), ("Gas psi", "psi"), ("Gas Pa", "Pa"), ("Gas", None),
     ("Burner", None), ("Pan", None), ("Gas pressure", None), (None, None), ("Fan Hz", "Hz"),
     ("Exhaust (Hz)", "Hz"), ("Fan", None), ("Fan Hzx", None), ("Gas %", "percent"), ("Fan (pct)", "percent")],
)  # fmt: skip
def test_a_control_named_in_a_unit_is_read_in_it(name, unit):
    assert survey.named_unit(name) == unit


def test_a_gas_burner_logged_as_its_pressure_in_kpa_is_read_in_kpa(cli, tmp_path):
    """SYNTHETIC logs whose burner is an extra device "Gas kPa" reading 0.5-3.2 (a manometer's
    reading, decimals): a gas pressure in kPa, as the name says, not a percent (which put its gain's
    bound at 0.35 kW at the top setting and quantised programs to 0 or 5 kPa); the fit spec fixes the
    square-root law and its gains are per kPa^0.5 over the logged range, programs continuous and
    labelled in kPa."""
    from roastlab.io.importers.mapping import import_log, load_map

    gas = [0.55 if i < 30 else 3.2 if i < 80 else 1.85 for i in range(120)]  # kPa
    logs = _heater_readout_logs(tmp_path, "Gas kPa", gas, "g")
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0 and "heater: Gas kPa (kPa)" in out, (out, err)
    cmap = load_map(tmp_path / "cfg" / "map.toml")
    heater = cmap.actuator("heater")
    top = max(gas)
    assert (heater.unit, heater.high, heater.step, heater.label(2.347)) == ("kPa", top, None, "2.35 kPa")
    assert heater.describe() == f"heater 0 kPa-{top:g} kPa (continuous)"
    fit = (tmp_path / "cfg" / "fit.toml").read_text()
    qe_hi = float(fit.split("Qe_gain_kW = [")[1].split("]")[0].split(", ")[1])
    capacity_kg = 2 * 0.2  # fake_alog's batch, the capacity twice the largest logged
    # its heat goes as the pressure's square root (the orifice law): the gains per kPa^0.5, ~10 kW per
    # kg of capacity at the top logged pressure
    assert "[kW per kPa^0.5]" in fit and "\nheater_exp = 0.5 " in fit.split("[fixed]")[1]
    assert qe_hi * top**0.5 == pytest.approx(10.0 * capacity_kg, rel=1e-3)
    batch = import_log(logs[0], cmap)
    assert batch.heater is not None and np.nanmax(batch.heater) == top  # read as logged, in kPa


def test_a_decimal_readout_whose_name_gives_no_unit_is_read_over_its_range_and_a_unit_can_be_given(cli, tmp_path):
    """SYNTHETIC logs whose burner is an extra device "Gas" reading 0.55-3.2 (decimals; the name gives
    no unit): no percent a roaster roasts with, so a "reading" over its logged range (as a percent its
    gains' bounds gave the burner a thirtieth of its heat and programs stepped it 0 or 5), linear, with
    a note naming init --heater-unit; given as kPa, it is the gas pressure the name would have said."""
    from roastlab.io.importers.mapping import load_map
    from roastlab.workflows.survey import PERCENT_TOP_ABOVE

    gas = [0.55 if i < 30 else 3.2 if i < 80 else 1.85 for i in range(120)]
    top = max(gas)
    assert top <= PERCENT_TOP_ABOVE
    logs = _heater_readout_logs(tmp_path, "Gas", gas, "g")
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0 and "heater: Gas (reading)" in out and "init --heater-unit UNIT" in out, (out, err)
    heater = load_map(tmp_path / "cfg" / "map.toml").actuator("heater")
    assert (heater.unit, heater.high, heater.step, heater.label(2.347)) == ("reading", top, None, "2.35")
    fit = (tmp_path / "cfg" / "fit.toml").read_text()
    qe_hi = float(fit.split("Qe_gain_kW = [")[1].split("]")[0].split(", ")[1])
    assert qe_hi * top == pytest.approx(10.0 * 2 * 0.2, rel=1e-3)  # ~10 kW per kg of capacity at the top reading
    assert "[kW per logged unit]" in fit and "heater_exp" not in fit
    code, out, err = cli("init", *logs, "--out", tmp_path / "kpa", "--heater-unit", "kPa")
    assert code == 0 and "heater: Gas (kPa)" in out and "read in kPa, as given" in out, (out, err)
    assert load_map(tmp_path / "kpa" / "map.toml").actuator("heater").label(2.347) == "2.35 kPa"
    assert "\nheater_exp = 0.5 " in (tmp_path / "kpa" / "fit.toml").read_text()
    # a percent stays a percent: the same readout in 0-100 % with decimals
    pct = _heater_readout_logs(tmp_path, "Gas", [v * 25.0 + 0.3 for v in gas], "p")
    code, out, err = cli("init", *pct, "--out", tmp_path / "pct")
    assert code == 0 and "heater: Gas (percent)" in out, (out, err)
    # a unit roastlab does not know is refused in one line
    code, out, err = cli("init", *logs, "--out", tmp_path / "x", "--heater-unit", "furlong")
    assert code == 2 and "invalid choice" in err


def test_a_readouts_offset_about_its_zero_is_off_and_a_step_below_zero_a_wrong_unit(cli, tmp_path):
    """SYNTHETIC logs whose "Gas kPa" readout reads -0.02 kPa with the burner off (a gauge's offset
    about its zero): read as 0 with a note, where it refused the log (outside 0..); -0.8 kPa (a quarter of
    the top) is not an offset and stays refused in one line, as does a percent below 0."""
    from roastlab.io.importers.mapping import import_log, load_map, readout_zero_offset

    logs = _heater_readout_logs(tmp_path, "Gas kPa", [3.0 if 10 < i < 60 else -0.02 for i in range(120)], "g")
    code, out, err = cli("init", *logs, "--out", tmp_path / "cfg")
    assert code == 0, (out, err)
    cmap = load_map(tmp_path / "cfg" / "map.toml")
    batch = import_log(logs[0], cmap)
    assert np.nanmin(batch.heater) == 0.0 and any("a sensor's offset about its zero" in n for n in batch.notes)
    (far,) = _heater_readout_logs(tmp_path, "Gas kPa", [3.0 if 10 < i < 60 else -0.8 for i in range(120)], "far", 1)
    with pytest.raises(InputError, match="outside 0"):
        import_log(far, cmap)
    assert not readout_zero_offset("percent", np.array([-0.02, 50.0]))  # a stepped setting: a wrong unit
    assert readout_zero_offset("W", np.array([-20.0, 900.0])) and not readout_zero_offset(
        "W", np.array([-100.0, 900.0])
    )


def test_fit_roaster_leaves_out_an_output_that_no_log_of_its_fit_records(cli, tmp_path):
    """init's files for all 16 Skywalker logs weigh ET; the first four by name, whose fit half are two
    logs with an ET the map leaves out (it reads 31-38 °C below BT), are fitted without it and the
    report says so, where identify with the same files refuses (the spec is the user's there)."""
    sky = REAL_DATA / "skywalker"
    if not sky.is_dir():
        pytest.skip("../shared/data/real is absent")
    logs = sorted(sky.glob("*.alog"))
    assert cli("init", *logs, "--out", tmp_path / "cfg")[0] == 0
    cfg = tmp_path / "cfg"
    assert 'ET = "residual"' in (cfg / "fit.toml").read_text()  # the premise: init weighs ET
    code, out, err = cli("fit-roaster", cfg, *logs[:4])
    assert code == 0, err
    said = "the fit leaves out ET, which fit.toml weighs: none of the 2 logs it fits records it"
    assert f"note: {said}" in out and "reads below BT" in out
    assert f"The {said[4:]}" in (cfg / "report.md").read_text()
    assert printed_percent(out, "held out: FIT ") > 75.0
    C = ["--plant", cfg / "plant.toml", "--map", cfg / "map.toml", "--spec", cfg / "fit.toml"]
    code, _, err = cli("identify", *C, logs[0], logs[2], "--out", tmp_path / "m.json")
    assert code == 2 and "set ET = 0 under [weights]" in err
    # a fit half that records ET keeps its weight (the next logs' fit half, the rule fit-roaster applies)
    from roastlab.io.fitspec import load_fit_spec
    from roastlab.io.importers.mapping import load_map
    from roastlab.workflows.model import load_log

    spec = load_fit_spec(cfg / "fit.toml")
    cmap = load_map(cfg / "map.toml")
    assert roaster.outputs_the_logs_lack(spec, [load_log(p, cmap) for p in logs[4:8:2]]) == (spec, None)
