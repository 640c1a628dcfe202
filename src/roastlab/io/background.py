"""Artisan background profiles: a predicted roast written as Artisan writes ``.alog`` files.

One writer for every prediction a roaster may roast against (``roastlab transfer --alog``, ``roastlab
whatif --alog``): a Python literal (Artisan's own format, read back by
:func:`roastlab.io.importers.artisan.read_alog`) with BT the predicted probe, ET the model's curve for
what the machine's ET measures, the roast's marks in ``timeindex`` and the settings as Artisan special
events of its default types (``Burner`` for the heater, ``Air`` for the fan), in Artisan's value
encoding (:func:`~roastlab.io.importers.artisan.events_external_to_internal`).
"""

from __future__ import annotations

import datetime as _dt
import json

import numpy as np

from ..metrics.profile import mmss
from ..model.actuators import MIN_HOLD_S
from .importers.artisan import DEFAULT_ETYPES, EVENT_NAMES, events_external_to_internal

#: The event type each setting is written as.
SETTING_ETYPES = {"heater": "Burner", "fan": "Air"}
#: A change of a continuous control (a readout: a gas pressure, W, rpm) smaller than this share of its
#: range is the readout's noise, not a roaster's move (:func:`setting_events`): 2 %, 0.06 kPa on a
#: burner logged to 3 kPa, 20 W on a 1 kW element.
READOUT_DEADBAND_SHARE = 0.02

#: Artisan's alarm table (Config > Alarms; an ``.alrm`` file is its export): "From" CHARGE is alarm time 0;
#: an empty "Source" (no temperature condition) is source -3; the action "Slider <event type k>" is 3 + k
#: for Artisan's four event types (:data:`~roastlab.io.importers.artisan.DEFAULT_ETYPES`: Air, Drum,
#: Damper, Burner); no "If Alarm" / "But Not" guard is -1.
ALARM_FROM_CHARGE = 0
ALARM_NO_SOURCE = -3
ALARM_NO_GUARD = -1


def alarm_slider_action(etype: str) -> int:
    """Artisan's alarm action that moves the slider of event type ``etype`` (Air 3 ... Burner 6)."""
    return 3 + DEFAULT_ETYPES.index(etype)


def setting_events(time_s, series) -> list[tuple[int, str, float, str]]:
    """Step series as Artisan special events ``(sample index, type, value, label)``, one per real
    change. ``series``: ``(setting, values, actuator, thin)`` with ``setting`` "heater" or "fan" and
    the values in the actuator's units; ``thin``: the values are an optimiser's, quantised to the
    actuator's steps and held at least :data:`~roastlab.model.actuators.MIN_HOLD_S` (a logged
    setting keeps its own changes; a logged continuous one, a readout, those beyond its noise,
    :data:`READOUT_DEADBAND_SHARE` of its range). The label is the machine's (``P7``, ``F3``) for
    levels, else the type and the value (in its unit where it is continuous: ``Burner 2.45 kPa``)."""
    t = np.asarray(time_s, dtype=float)
    out = []
    for setting, values, act, thin in series:
        etype = SETTING_ETYPES[setting]
        noise = 0.0 if act.stepped or thin else READOUT_DEADBAND_SHARE * (act.high - act.low)  # a logged readout
        last_v, last_t = None, -np.inf
        for i, v in enumerate(np.asarray(values, dtype=float)):
            if thin:
                v = float(act.quantise(v))
            if last_v is not None and (abs(v - last_v) <= noise or (thin and t[i] - last_t < MIN_HOLD_S)):
                continue
            if act.unit in ("level", "tens"):
                label = act.label(v)
            else:
                label = f"{etype} {v:g}" if act.stepped else f"{etype} {act.label(v)}"
            out.append((i, etype, float(v), label))
            last_v, last_t = v, t[i]
    return sorted(out, key=lambda e: e[0])


def background_alog_text(
    time_s,
    bt_C,
    et_C,
    marks_s: dict,
    events: list,
    *,
    title: str,
    notes: str,
    roaster: str,
    batch_kg: float,
    mode: str = "C",
) -> str:
    """The ``.alog`` text of a predicted roast from CHARGE (``time_s[0]``) to DROP (its last sample).

    ``bt_C``, ``et_C``: the curves Artisan draws as BT and ET [degC]; ``marks_s``: event name
    (:data:`~roastlab.io.importers.artisan.EVENT_NAMES`: DRY, FCs, ...) -> time [s] on ``time_s``,
    each written at its nearest sample (CHARGE is the first sample, DROP the last); ``events``: from
    :func:`setting_events`; ``title``, ``notes`` (Artisan's roasting notes), ``roaster`` (its
    machine name) and ``batch_kg`` (the green weight) describe the prediction. ``mode``: "C" or "F",
    Artisan's profile mode, the unit BT and ET are written in (the roaster's own, so the background
    needs no conversion in an Artisan set to it).
    """
    from ..metrics.profile import display_temp

    t = np.asarray(time_s, dtype=float)
    n = len(t)
    timeindex = [0] * 8
    for k, name in enumerate(EVENT_NAMES):
        at = marks_s.get(name)
        if at is not None and name != "CHARGE" and t[0] <= at <= t[-1]:
            timeindex[k] = int(np.argmin(np.abs(t - at)))
    timeindex[EVENT_NAMES.index("DROP")] = n - 1
    now = _dt.datetime.now(_dt.UTC)
    profile = {
        "recording_version": "roastlab",
        "version": "2.8.4",
        "revision": "",
        "build": "",
        "artisan_os": "roastlab",
        "mode": mode,
        "title": title,
        "roastertype": roaster,
        "operator": "",
        "beans": "",
        "roastingnotes": notes,
        "roastdate": now.strftime("%a %b %d %Y"),
        "roastisodate": now.strftime("%Y-%m-%d"),
        "roasttime": now.strftime("%H:%M:%S"),
        "roastepoch": int(now.timestamp()),
        "samplinginterval": float(t[1] - t[0]),
        "timex": [round(float(v), 3) for v in t],
        "temp1": [round(float(display_temp(v, mode)), 2) for v in et_C],
        "temp2": [round(float(display_temp(v, mode)), 2) for v in bt_C],
        "timeindex": timeindex,
        "specialevents": [int(e[0]) for e in events],
        "specialeventstype": [DEFAULT_ETYPES.index(e[1]) for e in events],
        "specialeventsvalue": [events_external_to_internal(float(e[2])) for e in events],
        "specialeventsStrings": [e[3] for e in events],
        "etypes": list(DEFAULT_ETYPES),
        "weight": [round(batch_kg, 6), 0.0, "Kg"],
        "extradevices": [],
        "extratimex": [],
        "extratemp1": [],
        "extratemp2": [],
        "extraname1": [],
        "extraname2": [],
    }
    return repr(profile) + "\n"


def alarms_text(time_s, series, *, note: str) -> str:
    """An Artisan alarm set (``.alrm``, Config > Alarms > Load) that runs a program: for each change of
    :func:`setting_events` on ``series``, an alarm at its time after CHARGE that moves the setting's
    slider (Burner, Air) to the value Artisan's slider takes for it
    (:meth:`~roastlab.model.actuators.Actuator.artisan_slider`); its description is that value, then
    a comment (after ``#``, which Artisan ignores) with the setting as the roaster reads it and ``note``.

    An alarm whose time is 0:00 has no time condition in Artisan, so a setting at CHARGE is moved at
    0:01 (set it before charging). Each alarm fires once per roast, as Artisan's alarms do."""
    t = np.asarray(time_s, dtype=float)
    units = {SETTING_ETYPES[setting]: act for setting, _, act, _ in series}
    rows = []
    for i, etype, value, label in setting_events(t, series):
        at_s = max(1, int(round(t[i] - t[0])))
        slider = units[etype].artisan_slider(value)
        rows.append((at_s, alarm_slider_action(etype), f"{slider:g} # {label} at {mmss(at_s)}, {note}"))
    n = len(rows)
    alarms = {
        "alarmflags": [1] * n,
        "alarmguards": [ALARM_NO_GUARD] * n,
        "alarmnegguards": [ALARM_NO_GUARD] * n,
        "alarmtimes": [ALARM_FROM_CHARGE] * n,
        "alarmoffsets": [r[0] for r in rows],
        "alarmconds": [1] * n,
        "alarmsources": [ALARM_NO_SOURCE] * n,
        "alarmtemperatures": [500.0] * n,  # Artisan's default; no source, so never compared
        "alarmactions": [r[1] for r in rows],
        "alarmbeep": [0] * n,
        "alarmstrings": [r[2] for r in rows],
    }
    return json.dumps(alarms, ensure_ascii=True) + "\n"
