"""Physical plausibility: the one table of allowed ranges for every quantity a user can give.

The CLI, the file readers and the Python API check values against :data:`LIMITS`, and the
message names the quantity, its unit and the range. The ranges are wide (any real roaster
fits well inside) but exclude values that break the model or give absurd answers: a gas flow
of 1e17 kg/s saturates every heat transfer and still prints a plausible-looking curve.
"""

from __future__ import annotations

import math

from ..errors import ParameterError

#: name -> (lowest, highest, unit, meaning); bounds inclusive.
LIMITS: dict[str, tuple[float, float, str, str]] = {
    # inputs
    "time_s": (0.0, 86400.0, "s", "time since CHARGE (a day at most)"),
    "Gg_kg_s": (1e-6, 100.0, "kg/s", "inlet gas mass flow"),
    "Tgi_C": (-50.0, 1000.0, "degC", "inlet gas temperature"),
    "Ta_C": (-50.0, 1000.0, "degC", "bean-probe temperature"),
    "dt_s": (1e-6, 3600.0, "s", "time between two samples"),
    # initial states
    "Tb0_C": (-50.0, 400.0, "degC", "bean temperature at CHARGE"),
    "Tm0_C": (-50.0, 700.0, "degC", "drum metal temperature at CHARGE"),
    "X0": (0.0, 1.0, "kg/kg", "green moisture, dry basis"),
    "He0_kJ_kg": (0.0, 1e4, "kJ/kg", "exothermic heat at CHARGE"),
    "Ta0_C": (-50.0, 700.0, "degC", "probe reading at CHARGE"),
    # identified coefficients and constants
    "hgm": (0.0, 100.0, "kW/(m2 K)", "gas-to-metal coefficient"),
    "hbm": (0.0, 100.0, "kW/(m2 K)", "metal-to-bean coefficient"),
    "Pbm": (1e-6, 1.0 - 1e-6, "-", "bean area touching the metal"),
    "Mm": (1e-4, 1e6, "kg", "drum metal mass"),
    "Mb_kg": (1e-4, 1e5, "kg", "green batch mass"),
    "batch_kg": (1e-4, 1e5, "kg", "green batch mass"),
    "Tgi_offset_C": (-500.0, 500.0, "degC", "change of the inlet gas temperature"),
    # actuator extension: logged settings (percent, levels or physical units) and their maps
    "heater": (-1e3, 1e4, "setting", "heater setting"),
    "fan": (-1e3, 1e4, "setting", "fan setting"),
    "Qe_gain_kW": (0.0, 1e4, "kW/unit", "heat into the drum per unit of heater setting"),
    "Qe_offset_kW": (-1e4, 1e4, "kW", "heat into the drum at heater setting 0"),
    "Tgi_gain_C": (-100.0, 1e3, "degC/unit", "inlet gas rise per unit of heater setting"),
    "tau_heater_s": (0.1, 1e4, "s", "heater lag"),
    "Gg_fan_kg_s": (-100.0, 100.0, "kg/s/unit", "gas flow per unit of fan setting"),
    "U_shell_kW_m2K": (0.0, 10.0, "kW/(m2 K)", "drum-shell heat-loss coefficient"),
    "T_room_C": (-50.0, 60.0, "degC", "room temperature"),
    "h_probe_m": (0.0, 10.0, "m", "bean-bed depth that covers the bean probe"),
    # plant geometry (Table 5); from a 50 g sample roaster to a 5 t drum, with room
    "Dch_m": (0.02, 10.0, "m", "chamber diameter"),
    "Lch_m": (0.02, 20.0, "m", "chamber length"),
    "Hflap_m": (1e-4, 2.0, "m", "flap height"),
    "Sflap_m": (1e-3, 20.0, "m", "flap step"),
    "Mm_kg": (1e-3, 1e6, "kg", "drum metal mass"),
    # process constants (Table 4); each within orders of magnitude of the paper's value
    "A": (1e-6, 1e12, "1/s", "reaction pre-exponential factor"),
    "cm": (0.01, 10.0, "kJ/(kg K)", "metal specific heat"),
    "cw": (0.1, 20.0, "kJ/(kg K)", "partial heat capacity of water"),
    "Db": (1e-4, 0.05, "m", "bean diameter"),
    "Ha_R": (1.0, 1e5, "K", "activation energy over R"),
    "Het": (1e-3, 1e4, "kJ/kg", "total reaction heat"),
    "k1": (1e-6, 1e12, "m2/s", "Schwartzberg pre-factor"),
    "k2": (1.0, 1e5, "K", "Schwartzberg activation temperature"),
    "Kt": (1e-5, 10.0, "1/s", "bean-probe inverse time constant"),
    "mb": (1e-6, 1e-2, "kg", "mass of one bean"),
    "lam": (10.0, 1e4, "kJ/kg", "latent heat of vaporisation"),
    # closed-loop scenarios (roastlab.io.scenario)
    "mass_factor": (0.1, 5.0, "-", "batch mass over the reference's"),
    "Gg_factor": (0.1, 5.0, "-", "gas flow the plant gets over the flow set"),
    "theta_factor": (0.1, 10.0, "-", "plant coefficient over the controller model's"),
    "Tb0_offset_C": (-300.0, 300.0, "degC", "bean charge temperature change"),
    "Tm0_offset_C": (-500.0, 500.0, "degC", "drum temperature change at CHARGE"),
    "noise_C": (0.0, 20.0, "degC", "probe noise (standard deviation)"),
    "delay_s": (0.0, 120.0, "s", "probe reading delay"),
    "sample_s": (0.1, 60.0, "s", "control interval"),
    "rate_per_min": (1e-3, 1e5, "unit/min", "actuator rate limit"),
}


def check_value(name: str, value, source: str | None = None) -> float:
    """``value`` as a float if it is a finite number inside ``LIMITS[name]``; else ParameterError.

    >>> check_value("X0", 0.11)
    0.11
    """
    lo, hi, unit, meaning = LIMITS[name]
    if isinstance(value, bool):
        raise ParameterError(f"{name} ({meaning}) must be a number, got {value!r}", source)
    try:
        v = float(value)
    except OverflowError:
        v = math.copysign(math.inf, value)  # an integer beyond float range: reported as out of range below
    except (TypeError, ValueError):
        raise ParameterError(f"{name} ({meaning}) must be a number, got {str(value)[:40]!r}", source) from None
    if not math.isfinite(v) or not lo <= v <= hi:
        raise ParameterError(
            f"{name} ({meaning}) = {v:g} {unit} outside the plausible range {lo:g}..{hi:g} {unit}", source
        )
    return v


def check_array(name: str, values, source: str | None = None, where: str | None = None) -> None:
    """Every element finite and inside ``LIMITS[name]``; else ParameterError naming the first bad row."""
    import numpy as np

    lo, hi, unit, meaning = LIMITS[name]
    a = np.asarray(values, dtype=float)
    bad = np.flatnonzero(~np.isfinite(a) | (a < lo) | (a > hi))
    if bad.size:
        i = int(bad[0])
        raise ParameterError(
            f"{name} ({meaning}) = {a[i]:g} {unit} outside the plausible range {lo:g}..{hi:g} {unit}",
            source,
            where or f"row {i + 1}, column {name}",
        )
