"""The one table of every quantity roastlab knows: unit, default, plausible range, fit bounds.

Every reader (plant files, fit specs, model files, scenarios, logs), every CLI option, the
plausibility checks (:mod:`roastlab.model.limits`) and the identification registry
(:data:`roastlab.model.parameters.REGISTRY`) look a quantity up here; no other module holds a
numeric range or a default of a registered quantity (``tests/test_quantities.py`` walks the
source to keep it so).

Each :class:`Quantity` has

* ``unit`` in MODEL.md's units (kJ, kW, kg, m, s, degC);
* ``kind``: ``"input"`` (a logged or given input series), ``"initial"`` (an initial state,
  paper section 5.1), ``"theta"`` (the identified coefficients, Table 1), ``"process"``
  (fixed process constants, Table 5 left), ``"plant"`` (plant geometry, Table 5 right),
  ``"extension"`` (the named extensions that are not in the paper: actuator maps, shell
  loss, probe immersion; each 0 or off by default) or ``"scenario"`` (closed-loop scenario
  settings, :mod:`roastlab.io.scenario`);
* ``default``: the value used when nothing else is given (the paper's value where it has one);
  ``None`` only for measured inputs and the actuator rate limit, which have no sensible
  default, and for plant geometry, which a plant file always gives (the presets in
  ``model/plants``);
* ``plausible``: the inclusive range any user-given value must lie in. Wide (any real roaster
  fits well inside) but it excludes values that break the model or give absurd answers;
* ``bounds``: the default fit bounds, inside ``plausible``, for the quantities an
  identification may free (``None`` for the others);
* ``carries_over``: True if geometry-independent, so a value fitted on one plant applies to
  another (the paper's 120 -> 360 kg validation); False for what belongs to the fitted plant
  or batch;
* ``slot``: the parameter-vector entry (:data:`roastlab.model.layout.PARAM_NAMES`) or initial
  state (:data:`roastlab.model.layout.STATE0`) the quantity sets, if any.

A quantity known by two names (``Mm`` in fit specs and model files, ``Mm_kg`` in plant files; ``batch_kg``
on the command line and ``Mb_kg`` in batch files) is one entry with an alias, so both names
always share one range.

Units: hgm and hbm are in kW/(m^2 K) (Table 1 prints W/(m^2 K)); Pbm is a fraction (Table 1
prints %); A is a rate, kJ/(kg s) (Table 5 prints kJ/kg); MODEL.md explains each slip.

>>> QUANTITIES["hbm"].default, QUANTITIES["hbm"].unit
(0.0254, 'kW/(m2 K)')
>>> QUANTITIES["Mm"] is QUANTITIES["Mm_kg"]
True
"""

from __future__ import annotations

from dataclasses import dataclass

KINDS = ("input", "initial", "theta", "process", "plant", "extension", "scenario")


@dataclass(frozen=True)
class Quantity:
    """One quantity: see the module docstring for each field."""

    name: str
    unit: str
    kind: str
    default: float | None
    plausible: tuple[float, float]
    meaning: str
    bounds: tuple[float, float] | None = None
    carries_over: bool = False
    slot: str | None = None
    aliases: tuple[str, ...] = ()

    @property
    def identifiable(self) -> bool:
        """True if an identification may free it (it has fit bounds and a slot)."""
        return self.bounds is not None and self.slot is not None


def _process(name, unit, default, plausible, meaning, slot=True, factor=5.0, bounds=None):
    """A Table 5 constant: freed without bounds it may move ``factor`` either way from the
    paper's value, within its plausible range (or within ``bounds`` where given)."""
    lo, hi = plausible
    if bounds is None and slot:
        bounds = (max(default / factor, lo), min(default * factor, hi))
    return Quantity(name, unit, "process", default, plausible, meaning, bounds, True, name if slot else None)


#: Fit bounds of the beans' exothermic rate law (eq. 14's A and Ha/R): they hold the paper's law
#: (Schwartzberg's A = 116200 kJ/(kg s), Ha/R = 5500 K) and the steeper, later law the Bullet's logs
#: pin (Ha/R about 9100 K with A about 6e8: the same rate near 150 degC, 2.4 times it at 200 degC),
#: A over five decades because A and Ha/R move together along one mid-roast rate (correlation
#: +0.998); they stop short of exotherms so fast the integrator crawls (ten times wider ended at the
#: same values, 45 s against 17 s; docs/real-roaster.md, "The beans' exotherm, fitted").
_EXOTHERM_BOUNDS = {"A": (1e5, 1e10), "Ha_R": (5000.0, 13000.0)}


_TABLE: tuple[Quantity, ...] = (
    # --- inputs (measured or given series) -------------------------------------------------------
    Quantity("time_s", "s", "input", None, (0.0, 86400.0), "time since CHARGE (a day at most)"),
    Quantity("dt_s", "s", "input", None, (1e-6, 3600.0), "time between two samples"),
    Quantity("Gg_kg_s", "kg/s", "input", 1.0, (1e-6, 100.0), "inlet gas mass flow",
             # a log without a flow gets a 1 kg/s placeholder scaled by the identified Gg_scale
             (1e-4, 10.0), False, "Gg_scale"),
    Quantity("Tgi_C", "degC", "input", None, (-50.0, 1000.0), "inlet gas temperature"),
    Quantity("Ta_C", "degC", "input", None, (-50.0, 1000.0), "bean-probe temperature"),
    Quantity("heater", "setting", "input", 0.0, (-1e3, 1e4), "heater setting"),
    Quantity("fan", "setting", "input", 0.0, (-1e3, 1e4), "fan setting"),
    Quantity("Tgi_offset_C", "degC", "input", 0.0, (-500.0, 500.0), "change of the inlet gas temperature"),
    # --- initial states (paper section 5.1: [30, 121, 0.1, 0, Ta(0)]) --------------------------
    Quantity("Tb0_C", "degC", "initial", 30.0, (-50.0, 400.0), "bean temperature at CHARGE",
             (0.0, 60.0), True, "Tb0_C"),
    Quantity("Tm0_C", "degC", "initial", 121.0, (-50.0, 700.0), "drum metal temperature at CHARGE",
             (20.0, 300.0), False, "Tm0_C"),
    Quantity("X0", "kg/kg", "initial", 0.1, (0.0, 1.0), "green moisture, dry basis",
             (0.02, 0.2), True, "X0"),
    Quantity("He0_kJ_kg", "kJ/kg", "initial", 0.0, (0.0, 1e4), "exothermic heat at CHARGE",
             (0.0, 232.0), True, "He0_kJ_kg"),
    # default: the log's first probe reading (None here: it comes from the log, else Tb0)
    Quantity("Ta0_C", "degC", "initial", 30.0, (-50.0, 700.0), "probe reading at CHARGE (default: the log's first reading, else Tb0)",
             (0.0, 300.0), False, "Ta0_C"),
    # --- identified coefficients (Table 1; default theta*, bounds as printed) --------------------
    Quantity("hgm", "kW/(m2 K)", "theta", 0.0100, (0.0, 100.0), "gas-to-metal coefficient, eq. 6",
             (0.01, 0.35), True, "hgm"),
    Quantity("hbm", "kW/(m2 K)", "theta", 0.0254, (0.0, 100.0), "metal-to-bean coefficient, eq. 11",
             (0.01, 0.35), True, "hbm"),
    Quantity("Pbm", "-", "theta", 0.5793, (1e-6, 1.0 - 1e-6), "bean area touching the metal, section 3.1",
             (0.5, 0.8), True, "Pbm"),
    # --- process constants (Table 5 left; MODEL.md's readings) ----------------------------------
    _process("A", "kJ/(kg s)", 116200.0, (1e-6, 1e12), "reaction pre-exponential factor, eq. 14",
             bounds=_EXOTHERM_BOUNDS["A"]),
    _process("cm", "kJ/(kg K)", 0.418, (0.01, 10.0), "metal specific heat, eq. 12"),
    _process("cw", "kJ/(kg K)", 5.0, (0.1, 20.0), "partial heat capacity of water, eq. 8"),
    _process("Db", "m", 7.65e-3, (1e-4, 0.05), "bean diameter, eq. 13", slot=False),
    _process("Ha_R", "K", 5500.0, (1.0, 1e5), "activation energy over R, eq. 14",
             bounds=_EXOTHERM_BOUNDS["Ha_R"]),
    _process("Het", "kJ/kg", 232.0, (1e-3, 1e4), "total reaction heat, eq. 14"),
    _process("k1", "m2/s", 4320.0, (1e-6, 1e12), "Schwartzberg pre-factor, eq. 13"),
    _process("k2", "K", 9889.0, (1.0, 1e5), "Schwartzberg activation temperature, eq. 13"),
    _process("Kt", "1/s", 0.01, (1e-5, 10.0), "bean-probe inverse time constant, eq. 17"),
    _process("mb", "kg", 1.5e-4, (1e-6, 1e-2), "mass of one bean, section 3.1", slot=False),
    _process("lam", "kJ/kg", 2790.0, (10.0, 1e4), "latent heat of vaporisation, eq. 8"),
    # --- plant geometry (Table 5 right): no default, a plant file gives it (presets: model/plants) --
    Quantity("Mb_kg", "kg", "plant", None, (1e-4, 1e5), "green batch mass", aliases=("batch_kg",)),
    Quantity("Dch_m", "m", "plant", None, (0.02, 10.0), "chamber diameter"),
    Quantity("Lch_m", "m", "plant", None, (0.02, 20.0), "chamber length"),
    Quantity("Hflap_m", "m", "plant", None, (1e-4, 2.0), "flap height"),
    Quantity("Sflap_m", "m", "plant", None, (1e-3, 20.0), "flap step"),
    # "Mm" in fit specs and model files, "Mm_kg" in plant files: one quantity
    Quantity("Mm", "kg", "plant", None, (1e-3, 1e6), "drum metal mass in thermal contact, eq. 12",
             (1e-3, 1e5), False, "Mm", aliases=("Mm_kg",)),
    # --- extensions (not in the paper; each default is the paper's model) ------------------------
    Quantity("Qe_gain_kW", "kW/unit", "extension", 0.0, (0.0, 1e4),
             "heat into the drum metal per unit of heater setting (eq. 12's Qe)", (0.0, 10.0), False, "Qe_gain"),
    Quantity("Qe_offset_kW", "kW", "extension", 0.0, (-1e4, 1e4),
             "heat into the drum metal at heater setting 0 (eq. 12's Qe)", (-5.0, 5.0), False, "Qe_offset"),
    Quantity("Tgi_gain_C", "degC/unit", "extension", 0.0, (-100.0, 1e3),
             "rise of the inlet gas temperature per unit of heater setting", (0.0, 100.0), False, "Tgi_gain"),
    Quantity("tau_heater_s", "s", "extension", 1.0, (0.1, 1e4), "first-order lag of the heater's effect",
             (1.0, 600.0), False, "tau_heater"),
    Quantity("Gg_fan_kg_s", "kg/s/unit", "extension", 0.0, (-100.0, 100.0),
             "gas flow per unit of fan setting (affine with Gg_kg_s)", (0.0, 1.0), False, "Gg_fan"),
    Quantity("U_shell_kW_m2K", "kW/(m2 K)", "extension", 0.0, (0.0, 10.0),
             "heat loss of the drum's outer surface to the room per m2 and K (eq. 12 extension)",
             (0.0, 0.1), False, "U_shell"),
    Quantity("T_room_C", "degC", "extension", 22.0, (-50.0, 60.0), "room temperature (shell loss, room air)",
             (0.0, 40.0), False, "T_room"),
    Quantity("h_probe_m", "m", "extension", 0.0, (0.0, 10.0),
             "bean-bed depth that covers the bean probe; shallower beds leave part of it in the gas (eq. 17 extension)",
             (0.0, 0.5), False, "h_probe"),
    Quantity("eps_rad", "-", "extension", 0.0, (0.0, 1.0),
             "effective emissivity of the drum wall's radiation to the bed's free surface (eq. 12/15a extension)",
             (0.0, 1.0), True, "eps_rad"),
    Quantity("k_flight", "-", "extension", 0.0, (0.0, 1000.0),
             "gas-bean area over the bed's free surface, beans in flight included (0: the contact law's Agb)",
             (1.0, 100.0), False, "k_flight"),
    Quantity("Tm0_share", "-", "extension", 1.0, (0.05, 1.0),
             "share of the drum's rise over the room at CHARGE that the map's drum-start reading shows "
             "(1: the reading is the drum's; a probe soaked in the empty drum reads less)",
             (0.3, 1.0), False, "Tm0_share"),
    Quantity("heater_exp", "-", "extension", 1.0, (0.1, 2.0),
             "exponent of the heater's lagged setting in the heat it releases (1: in proportion; 0.5: a gas "
             "burner logged as its pressure, whose gas flow through the jet goes as the pressure's square root)",
             (0.3, 1.5), False, "heater_exp"),
    Quantity("fan_exp", "-", "extension", 1.0, (0.1, 2.0),
             "exponent of the fan setting in the air flow it moves (1: in proportion; 0.5: a fan logged as "
             "the pressure it makes across the drum, whose flow goes as the pressure's square root)",
             (0.3, 1.5), False, "fan_exp"),
    Quantity("heater_lag_exp", "-", "extension", 0.0, (0.0, 1.0),
             "exponent of the heater's lag in full power over its lagged setting, tau_heater (full / H)^e (0: one "
             "lag at every setting; 0.75: a radiant element, whose output goes as its temperature to the fourth)",
             (0.0, 1.0), False, "heater_lag_exp"),
    Quantity("heater_full", "unit", "extension", 100.0, (1e-6, 1e6),
             "the heater setting at full power, at which the lag is tau_heater_s (100 for a percentage; a "
             "fit spec fixes it for another scale, 9 for levels P1-P9)",
             (1e-3, 1e4), False, "heater_full"),
    Quantity("bean_swell", "-", "extension", 0.0, (0.0, 3.0),
             "the beans' volume gain when the roast reactions are complete, V/V0 - 1, growing with their extent "
             "He/Het (0: beans of a fixed size; roasted coffee has gained 50-100 % of its green volume)",
             (0.0, 1.0), True, "bean_swell"),
    # --- closed-loop scenarios (roastlab.io.scenario) --------------------------------------------
    Quantity("mass_factor", "-", "scenario", 1.0, (0.1, 5.0), "batch mass over the reference's"),
    Quantity("Gg_factor", "-", "scenario", 1.0, (0.1, 5.0), "gas flow the plant gets over the flow set"),
    Quantity("theta_factor", "-", "scenario", 1.0, (0.1, 10.0), "plant coefficient over the controller model's"),
    Quantity("Tb0_offset_C", "degC", "scenario", 0.0, (-300.0, 300.0), "bean charge temperature change"),
    Quantity("Tm0_offset_C", "degC", "scenario", 0.0, (-500.0, 500.0), "drum temperature change at CHARGE"),
    Quantity("noise_C", "degC", "scenario", 0.0, (0.0, 20.0), "probe noise (standard deviation)"),
    Quantity("delay_s", "s", "scenario", 0.0, (0.0, 120.0), "probe reading delay"),
    Quantity("sample_s", "s", "scenario", 5.0, (0.1, 60.0), "control interval"),
    Quantity("rate_per_min", "unit/min", "scenario", None, (1e-3, 1e5), "actuator rate limit"),
)  # fmt: skip


def _index(table) -> dict[str, Quantity]:
    out: dict[str, Quantity] = {}
    for q in table:
        for name in (q.name, *q.aliases):
            if name in out:
                raise RuntimeError(f"quantity {name!r} listed twice")  # a programming error, caught by the tests
            out[name] = q
    return out


#: Every quantity by name and by alias (an alias maps to the same :class:`Quantity`).
QUANTITIES: dict[str, Quantity] = _index(_TABLE)


def quantity(name: str) -> Quantity:
    """The :class:`Quantity` called ``name`` (or one of its aliases); KeyError if unknown."""
    return QUANTITIES[name]


def default(name: str) -> float:
    """The default value of ``name`` (see :class:`Quantity`).

    >>> default("T_room_C")
    22.0
    """
    v = QUANTITIES[name].default
    if v is None:
        raise KeyError(f"{name} has no default (a measured input)")
    return v


def defaults(kind: str) -> dict[str, float]:
    """``{name: default}`` of every quantity of ``kind``, in table order (aliases left out)."""
    return {q.name: q.default for q in _TABLE if q.kind == kind and q.default is not None}


def table() -> tuple[Quantity, ...]:
    """Every quantity once (no aliases), in table order."""
    return _TABLE
