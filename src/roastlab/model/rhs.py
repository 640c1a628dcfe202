"""The roasting-chamber model: one pure right-hand side (paper eqs. 2-17, MODEL.md).

States ``x = [Tb, Tm, X, He, Ta, H]`` (see :data:`STATE_NAMES`), inputs
``u = [Gg, Tgi, heater, fan]`` (:data:`INPUT_NAMES`), parameters a flat float64 vector ``p`` built by :func:`pack_params`
(:data:`PARAM_NAMES`). The functions here are plain Python when called from Python (the
slow reference path and the benchmark baseline) and are compiled inline into the
integrators of :mod:`roastlab.sim.kernels` through ``numba.extending.register_jitable``: one
source, never copied.

Departures from the printed paper, each a reading fixed by MODEL.md:

* eq. 15e gives the temperature *drop* Tgi - Tgo, with the (1 + F) factor inside NTU;
* eq. 13/15c: Schwartzberg's law dX/dt = -k1 X^2 / Db^2 exp(-k2/T) by default; the printed
  law (no X factor, k1 = 4.32e-9) is the ``"printed"`` variant (exponent 0);
* heat-transfer coefficients are in kW/(m^2 K), not W/(m^2 K).

The actuator extension (not in the paper; off unless a map declares a heater or fan setting)
adds a sixth state and two inputs to the same function: the logged heater setting passes a
first-order actuator lag (state H, in the setting's own units) and becomes heat into the drum
metal, Qe = Qe_offset + Qe_gain H [kW] (eq. 12/15b's Qe, zero in the paper), and/or a rise of
the inlet gas temperature Tgi + Tgi_gain H [degC]; the fan setting moves the gas flow
affinely, Gg Gg_scale + Gg_fan fan [kg/s]. A heat loss of the drum shell to the room,
U_shell Ashell (Tm - T_room) [kW], leaves the metal (eq. 12; the paper's shell is adiabatic).
The probe-immersion extension lets the bean probe see the gas where the bean bed does not cover
it (eq. 17 extended, :func:`probe_coverage`): a small batch in a large drum reads low when the
gas is cooler than the beans. The radiation extension lets the drum wall radiate to the bed's free
surface (:func:`wall_radiation_kW`, eqs. 15a/15b extended), and the gas-area extension lets the gas
meet the beans at that surface rather than over a share of every bean (``k_flight``,
:func:`bed_areas_m2`). With the gains, U_shell, h_probe, eps_rad and k_flight at their default 0
and no heater input the model is the paper's (MODEL.md's check value holds; tests/test_physics.py).
"""

from __future__ import annotations

import math
import types

import numpy as np
from numba.extending import register_jitable

from ..errors import ParameterError
from .constants import CG_ALPHA_J_KG_K, K1_PRINTED, MOISTURE_LAWS

# The vectors' layout lives in one place (layout.py); re-exported here for the existing imports.
from .layout import (  # noqa: E402, F401
    HEATER_STATE,
    I_A,
    I_AB,
    I_AGM,
    I_ASH,
    I_ASURF,
    I_AWALL,
    I_CM,
    I_CONTACT,
    I_CW,
    I_DB,
    I_EPSRAD,
    I_FEXP,
    I_GGF,
    I_GGS,
    I_HAR,
    I_HBED,
    I_HBM,
    I_HET,
    I_HEXP,
    I_HFULL,
    I_HGM,
    I_HLEXP,
    I_HPROBE,
    I_K1,
    I_K2,
    I_KFLIGHT,
    I_KT,
    I_LAM,
    I_MBD,
    I_MM,
    I_PBM,
    I_PROBEGAS,
    I_PROBELAW,
    I_QEG,
    I_QEO,
    I_SWELL,
    I_TAUH,
    I_TGIG,
    I_TROOM,
    I_USH,
    I_XEXP,
    INPUT_NAMES,
    N_PARAMS,
    N_STATES,
    PARAM_NAMES,
    S_H,
    S_HE,
    S_TA,
    S_TB,
    S_TM,
    S_X,
    STATE_NAMES,
    U_FAN,
    U_GG,
    U_HEATER,
    U_TGI,
    P,
)

#: Stefan-Boltzmann constant [kW/(m2 K4)] (5.670374419e-8 W/(m2 K4), CODATA 2018).
STEFAN_BOLTZMANN_KW_M2K4 = 5.670374419e-11

#: Smallest gas flow the fan map may give [kg/s] (a fan map fitted below zero is clipped here).
GG_MIN_KG_S = 1e-6

_A0, _A1, _A2, _A3, _A4, _A5, _A6 = CG_ALPHA_J_KG_K
KELVIN = 273.15

# The elementary operations of the right-hand side, by name, so that :func:`rebind` can evaluate
# the same equations with other number types (CasADi symbols for the control baseline).
exp = math.exp
fmax = max


@register_jitable
def power(x, a):
    """``x ** a``: the moisture law's power of X, an operation of its own so that :func:`rebind`
    can replace it (the vectorised integrator, :mod:`roastlab.sim.lanes`)."""
    return x**a


@register_jitable
def cube_root(v):
    """``v ** (1/3)``: the beans' size (:func:`swell_factor`), an operation of its own so that
    :func:`rebind` can replace it (the vectorised integrator's plain-arithmetic root,
    :func:`roastlab.sim.vecmath.cube_root`)."""
    return v ** (1.0 / 3.0)


@register_jitable
def where(condition, a, b):
    """``a`` where ``condition`` holds, else ``b`` (a branch that symbolic types can also take)."""
    return a if condition else b


@register_jitable
def gas_heat_capacity_kJ_kgK(Tgi_C):
    """Specific heat of the drying air cg [kJ/(kg K)] at inlet temperature [degC] (eq. 2).

    The polynomial of eq. 2 is in J/(kg K) of the absolute temperature; times 1e-3 (a product,
    not a division, on the integrator's hot path).

    >>> round(gas_heat_capacity_kJ_kgK(450.0), 4)
    1.0807
    """
    T = Tgi_C + KELVIN
    return (_A0 + T * (_A1 + T * (_A2 + T * (_A3 + T * (_A4 + T * (_A5 + T * _A6)))))) * 1e-3


@register_jitable
def bean_heat_transfer_coefficient_kW_m2K(X):
    """Gas-to-bean coefficient he [kW/(m^2 K)] at moisture X [kg/kg dry] (eq. 3)."""
    return 0.49 - 0.443 * exp(-0.206 * X)


@register_jitable
def bean_areas_m2(Ab_m2, Pbm):
    """Gas-to-bean and metal-to-bean areas (Agb, Abm) = (Ab (1 - Pbm), Ab Pbm) [m^2] (section 3.1)."""
    return Ab_m2 * (1.0 - Pbm), Ab_m2 * Pbm


@register_jitable
def swell_factor(He, p):
    """The beans' size over their green size, s = (V / V0)^(1/3) [-] (extension; 1 in the paper).

    Roasting swells coffee beans: the water vapour and the carbon dioxide the roast reactions release
    press on cell walls that the heat has made rubbery, and a roasted bean has gained 50-100 % of its
    green volume while losing 12-20 % of its mass (Schenker, "Investigations on the hot air roasting of
    coffee beans", ETH Zurich diss. 13620, 2000; Perren, Geiger, Schenker and Escher, ASIC 2004). The
    volume gain is taken in proportion to the reactions' extent He/Het (eq. 14's exothermic heat over
    its total): V / V0 = 1 + bean_swell He / Het. With the number of beans fixed, each bean's surface
    goes as s^2, and so does the beans' area Ab (section 3.1; :func:`bed_areas_m2`); the bed's volume
    goes as s^3 at a fixed porosity, so a shallow bed's depth goes as s^2 (a circular segment of depth
    h << D holds an area (4/3) sqrt(D) h^(3/2) per unit length) and its wetted arc and free surface as s
    (their widths go as sqrt(h)): :func:`probe_coverage`, :func:`bed_areas_m2`, :func:`wall_radiation_kW`.
    ``bean_swell`` 0 (the default): s = 1 exactly, the paper's beans.
    """
    if p[I_SWELL] == 0.0:  # the lanes compile it in as a constant (roastlab.sim.lanes.LAW_SLOTS)
        return 1.0
    return cube_root(1.0 + p[I_SWELL] * fmax(He, 0.0) * (1.0 / p[I_HET]))


@register_jitable
def bed_areas_m2(p, s):
    """(Agb, Abm) [m^2] under the model's contact law (:mod:`roastlab.model.bed`) and gas area, for
    beans of ``s`` times their green size (:func:`swell_factor`; 1 in the paper).

    ``contact_law`` 0 (the paper, section 3.1): :func:`bean_areas_m2`, both shares of Ab. Swollen beans
    (s > 1) scale Ab by s^2 and A_wall and A_surf below by s (:func:`swell_factor`).
    1 (``"wall"``): Abm = Pbm A_wall, the share Pbm of the drum wall the bed wets
    (:attr:`roastlab.model.plant.Plant.wall_contact_area_m2`), and Agb = Ab - Abm, every other
    bean surface (never below 1 % of Ab).

    With ``k_flight`` > 0 (an extension; 0, the default, keeps the contact law's Agb) the gas meets
    the beans where the bed faces it instead: Agb = k_flight A_surf, the bed's free surface
    (:attr:`roastlab.model.plant.Plant.bed_surface_area_m2`) and, for k_flight above 1, the beans
    the flights lift through the air, taken in proportion to that surface. The air drawn through a
    drum passes over the bed more than through it, so the area it meets grows with the bed's
    surface (as the fill to the power ~1/3 for a shallow bed), not with the number of beans: a small
    batch loses less heat to cool air per kilogram than the paper's Agb gives. Agb then no longer
    depends on Pbm, so hbm and Pbm act only as their product (hold Pbm when fitting).
    """
    Ab = p[I_AB] * (s * s)  # each bean's surface as its size squared
    if p[I_CONTACT] == 0.0:
        Agb, Abm = bean_areas_m2(Ab, p[I_PBM])
    else:
        Abm = p[I_PBM] * p[I_AWALL] * s  # the wetted arc widens as the bed deepens
        Agb = fmax(Ab - Abm, 0.01 * Ab)
    if p[I_KFLIGHT] == 0.0:  # off: the lanes compile the zero in (roastlab.sim.lanes.OFF_SLOTS)
        return Agb, Abm
    return where(p[I_KFLIGHT] > 0.0, p[I_KFLIGHT] * p[I_ASURF] * s, Agb), Abm


@register_jitable
def conductance_ratio_F(hgm, Agm_m2, he, Agb_m2):
    """F = hgm Agm / (he Agb) [-], gas-metal over gas-bean conductance (eq. 6)."""
    return hgm * Agm_m2 / (he * Agb_m2)


@register_jitable
def dry_mass_kg(Mb_kg, X0):
    """Dry batch mass Mbd = Mb / (1 + X(0)) [kg], fixed for the batch (section 3.6)."""
    return Mb_kg / (1.0 + X0)


#: The setting [its unit] added under the power in a setting's drive (:func:`setting_power`), so that
#: its slope stays finite at 0 (the square root's is not): 1e-6 kPa, a millionth of a burner's
#: pressure, changes the heat by less than a millionth wherever the burner is lit.
SETTING_POWER_FLOOR = 1e-6


@register_jitable
def setting_power(u, e):
    """A setting ``u`` to the power ``e`` [unit^e] (extension): u itself at e = 1, else computed as
    u (u + h0)^(e - 1), h0 = :data:`SETTING_POWER_FLOOR`: u^e wherever u >> h0, 0 at u = 0 with a
    finite slope h0^(e - 1) there (the Jacobian, :mod:`roastlab.sim.jacobian`), where the square
    root's is infinite."""
    if e == 1.0:  # the lanes compile the exponents in as constants (roastlab.sim.lanes.LAW_SLOTS)
        return u
    return u * power(fmax(u, 0.0) + SETTING_POWER_FLOOR, e - 1.0)


@register_jitable
def heater_drive(H, p):
    """The heater's lagged setting ``H`` as the heat it releases, D = H^e [setting unit^e] (extension).

    e = ``heater_exp``. 1 (the default) is the heat in proportion to the setting (a percentage of
    an element's power, a level), D = H exactly. A gas burner logged as its pressure releases heat
    in proportion to its gas flow, and the flow through the burner's jet (an orifice) goes as the
    square root of the pressure across it, m = Cd A sqrt(2 rho dp) (Bernoulli for an orifice): e =
    0.5 (:func:`setting_power`).
    """
    return setting_power(H, p[I_HEXP])


#: The share of full power below which a radiant heater's lag stops growing (:func:`heater_lag_factor`):
#: there the element, near the drum's temperature, loses its heat to its surroundings' radiation and
#: the air rather than by its own glow. An element glowing at 1000-1300 K at full power in a drum at
#: 450-550 K has a lag at most (T_full / T_drum)^3 = 8-24 times its full-power lag, a share of
#: 0.015-0.06 at e = 3/4; 0.05 caps it at 9.5 times. The logs fitted so far never set the heater below
#: 30 %, so the cap is a guard, not a fitted value.
HEATER_LAG_FLOOR = 0.05


@register_jitable
def heater_lag_factor(H, p):
    """The heater's lag at full power over its lag at the lagged setting ``H``: (H / full)^e [-]
    (extension; dH/dt = (heater - H) / tau_heater times this).

    e = ``heater_lag_exp``, full = ``heater_full``. e = 0 (the default): one lag at every setting, the
    first-order law, and the factor is exactly 1. A radiant element (a lamp, a quartz or ceramic
    emitter) holds heat C in its body and glows it away, Q = eps sigma A T^4 (its surroundings' share
    left out), so C dT/dt = P - Q. With Q the lagged heat, dQ/dt = (dQ/dT) dT/dt = (4 Q / T)(P - Q) / C:
    a first-order lag whose time constant C T / (4 Q) goes as Q^(-3/4), since T goes as Q^(1/4). So
    the lag at setting H is tau_heater (full / H)^(3/4), tau_heater the lag at full power: e = 3/4. At
    half power it is 1.68 times as long, so a heater turned down keeps glowing, as users of infrared
    drum roasters describe. Below :data:`HEATER_LAG_FLOOR` of full power the lag stops growing.
    """
    e = p[I_HLEXP]
    if e == 0.0:  # the lanes compile the exponent in as a constant (roastlab.sim.lanes.LAW_SLOTS)
        return 1.0
    full = p[I_HFULL]
    return power(fmax(H, HEATER_LAG_FLOOR * full) * (1.0 / full), e)


@register_jitable
def fan_drive(fan, p):
    """The fan setting ``fan`` as the air flow it moves, in proportion to fan^e [setting unit^e] (extension).

    e = ``fan_exp``. 1 (the default): the flow in proportion to the setting (a percentage, a speed in
    rpm or Hz: the fan laws, volume flow ~ speed). A fan logged as the pressure it makes across the
    drum (a draft in Pa) drives the air through a fixed resistance, the drum and its beans, where the
    flow goes as the square root of the pressure drop (Bernoulli, as for an orifice): e = 0.5
    (:func:`setting_power`).
    """
    return setting_power(fan, p[I_FEXP])


@register_jitable
def gas_inputs(Gg, Tgi, D, fan, p):
    """The gas flow [kg/s] and inlet temperature [degC] the chamber sees (actuator extension).

    Gg_eff = Gg Gg_scale + Gg_fan F (at least :data:`GG_MIN_KG_S`): the logged or placeholder
    flow, scaled, plus the fan map, F the fan's drive (:func:`fan_drive`: the setting itself unless
    ``fan_exp`` says); Tgi_eff = Tgi + Tgi_gain D: the logged or ambient inlet
    temperature plus the lagged heater's rise, D its drive (:func:`heater_drive` of the lagged
    setting H; H itself unless ``heater_exp`` says). Both reduce to (Gg, Tgi) in the paper's model.
    """
    g = Gg * p[I_GGS] + p[I_GGF] * fan_drive(fan, p)
    return fmax(g, GG_MIN_KG_S), Tgi + p[I_TGIG] * D


@register_jitable
def heater_power_kW(D, p):
    """Heat into the drum metal Qe = Qe_offset + Qe_gain D [kW], never negative (eq. 12's Qe; D the
    heater's drive, :func:`heater_drive` of the lagged setting H, H itself unless ``heater_exp`` says)."""
    return fmax(p[I_QEO] + p[I_QEG] * D, 0.0)


@register_jitable
def shell_loss_kW(Tm, p):
    """Heat the drum metal loses to the room, Qloss = U_shell Ashell (Tm - T_room) [kW].

    An extension of eq. 12 (the paper's shell is adiabatic: U_shell = 0). ``Tm`` [degC];
    U_shell [kW/(m2 K)] is a combined convection and radiation coefficient of the outer drum
    surface Ashell [m2] (:attr:`roastlab.model.plant.Plant.Ashell_m2`, computed from the
    geometry, so the loss scales with the drum and not with the batch).
    """
    return p[I_USH] * p[I_ASH] * (Tm - p[I_TROOM])


def drum_at_charge_C(reading_C, share, room_C):
    """The drum metal's temperature at CHARGE from the map's drum-start reading [degC].

    Tm(0) = T_room + (reading - T_room) / Tm0_share, with T_room ``room_C`` [degC] the room and
    Tm0_share ``share`` [-] the share of the drum's rise over the room that the reading shows (the
    extension's ``Tm0_share``; 1, the default, is a reading of the drum itself: the Bullet's
    preheat, the paper's Tm0, returned unchanged, bit for bit). A bean probe that soaked in the
    empty preheated drum sits in air the drum heats and sees the wall by radiation: it settles
    between the room and the wall, a share of the way up. Its steady heat balance, h_c (T_probe -
    T_air) + h_r (T_probe - T_wall) = 0 with the air between the room and the wall, puts that
    share below 1; on the Bullet, whose infrared sensor reads the preheated drum while its probe
    soaks beside it, the probe reads 0.48-0.69 of the way (docs/real-roaster.md). An extension
    of section 5.1's initial state, not a term of the right-hand side: read once per batch
    (:func:`roastlab.sim.population.run_arrays`). Numbers or arrays that broadcast together
    (a parameter vector's entries ``p[P["Tm0_share"]]``, ``p[P["T_room"]]``).
    """
    return np.where(share == 1.0, reading_C, room_C + (reading_C - room_C) / share)


def drum_start_reading_C(drum_C, share, room_C):
    """The inverse of :func:`drum_at_charge_C`: the reading a drum at ``drum_C`` [degC] shows."""
    return np.where(share == 1.0, drum_C, room_C + share * (drum_C - room_C))


@register_jitable
def wall_radiation_kW(Tb, Tm, s, p):
    """Heat the drum wall radiates to the bean bed, Qrad = eps sigma A_surf (Tm^4 - Tb^4) [kW]
    (temperatures in kelvin; ``Tb``, ``Tm`` [degC]).

    An extension of eqs. 12 and 15a (the paper's metal reaches the beans by contact alone, eq. 11).
    The bed's free surface ``A_surf`` [m2] (:attr:`roastlab.model.plant.Plant.bed_surface_area_m2`)
    sees nothing but the drum's inner wall (view factor 1), which is far larger than it; for two
    grey surfaces the exchange is sigma A_surf (Tm^4 - Tb^4) / (1/eps_b + A_surf/A_wall (1/eps_w - 1))
    (e.g. Incropera, the two-surface enclosure), lumped here into one effective emissivity
    ``eps_rad`` [-] (about 0.8 for beans at 0.9 in a steel drum at 0.6 whose wall is six times
    the surface, the Bullet at 500 g). The surface grows more slowly than the batch (the chord of
    the bed's segment), so a small batch takes more of this heat per kilogram than a large one;
    swollen beans (``s``, :func:`swell_factor`) widen it as s. eps_rad 0 (the default) is the paper's model.
    """
    if p[I_EPSRAD] == 0.0:  # off: the lanes compile the zero in (roastlab.sim.lanes.OFF_SLOTS)
        return 0.0
    a = Tm + KELVIN
    b = Tb + KELVIN
    a2 = a * a
    b2 = b * b
    return p[I_EPSRAD] * STEFAN_BOLTZMANN_KW_M2K4 * p[I_ASURF] * s * (a2 * a2 - b2 * b2)


@register_jitable
def probe_coverage(p, s):
    """Share c of the bean probe the bean bed covers [-] (eq. 17 extended; :mod:`roastlab.model.bed`).

    The paper's probe is always immersed: c = 1, also whenever h_probe is 0 (the default).
    ``h_bed`` [m] is the depth of the bed at rest, computed from the drum geometry and the
    batch mass (:attr:`roastlab.model.plant.Plant.bed_depth_m`); ``h_probe`` [m], a property of
    where the probe sits, is identified from the logs. ``probe_law`` 0 (a bed at rest):
    c = min(1, h_bed / h_probe), coverage linear in the depth up to the covering depth h_probe;
    1 (a tumbling bed): c = 1 - exp(-h_bed / h_probe), the Boolean-coverage law of beans laid
    over the probe at random, h_probe the e-folding depth. Beans ``s`` times their green size
    (:func:`swell_factor`) deepen the bed to h_bed s^2.
    """
    h_probe = p[I_HPROBE]
    if h_probe == 0.0:  # the paper's probe: the lanes compile the zero in (roastlab.sim.lanes.OFF_SLOTS)
        return 1.0
    h_bed = p[I_HBED] * (s * s)  # swollen beans deepen the bed (:func:`swell_factor`)
    if p[I_PROBELAW] == 0.0:
        return where(h_probe > h_bed, h_bed / fmax(h_probe, 1e-12), 1.0)
    return where(h_probe > 0.0, 1.0 - exp(-h_bed / fmax(h_probe, 1e-12)), 1.0)


@register_jitable
def probe_rate_C_s(Tb, Ta, Tg, s, p):
    """dTa/dt [degC/s]: eq. 17, Kt (Tb - Ta), with the probe-immersion extension
    Kt [c (Tb - Ta) + (1 - c) (Tg - Ta)]: the covered share c of the probe (:func:`probe_coverage`)
    follows the beans, the rest the gas in the drum at ``Tg`` (:func:`probe_gas_C`), ``s`` the
    beans' size (:func:`swell_factor`). With c = 1 it is eq. 17 exactly.
    """
    c = probe_coverage(p, s)
    return p[I_KT] * (c * (Tb - Ta) + (1.0 - c) * (Tg - Ta))


@register_jitable
def exchanger(Tb, Tm, X, s, Gg, Tgi, p):
    """The gas path of eq. 15e: ``(T_star [degC], NTU [-], w [-], Agb, Abm [m^2], he [kW/(m^2 K)], cg [kJ/(kg K)])``.

    T* = (Tb + F Tm)/(1 + F) is the mean sink temperature (eq. 5/15e), NTU = he Agb (1 + F)/(Gg cg)
    (eq. 15e), F = hgm Agm/(he Agb) eq. 6, the areas from :func:`bed_areas_m2` for beans of size ``s``
    (:func:`swell_factor`), he eq. 3, cg eq. 2;
    w = F/(1 + F) is the metal's share of the sink conductance, the factor of eq. 10.

    Evaluated through the conductances G = he Agb (gas-bean) and C = hgm Agm (gas-metal), F = C/G:
    multiplying eq. 5's and eq. 10's fractions by G gives T* = (G Tb + C Tm)/(G + C),
    w = C/(G + C) and NTU = (G + C)/(Gg cg), one reciprocal for all three where F's own quotient
    and the three divisions by (1 + F) took four (the integrator's inner loop; same values to rounding).
    """
    Agb, Abm = bed_areas_m2(p, s)  # section 3.1 (or the bed's contact law), beans of size s
    he = bean_heat_transfer_coefficient_kW_m2K(X)  # eq. 3
    cg = gas_heat_capacity_kJ_kgK(Tgi)  # eq. 2
    G = he * Agb  # gas-bean conductance [kW/K]
    C = p[I_HGM] * p[I_AGM]  # gas-metal conductance [kW/K]; F = C / G, eq. 6
    sink = G + C  # the sink's total conductance, G (1 + F) [kW/K]
    r = 1.0 / sink
    T_star = (G * Tb + C * Tm) * r  # eq. 5/15e: mean sink temperature (Tb + F Tm)/(1 + F)
    NTU = sink / (Gg * cg)  # eq. 15e: he Agb (1 + F)/(Gg cg)
    return T_star, NTU, C * r, Agb, Abm, he, cg


@register_jitable
def probe_gas_C(Tgi, Tgo, T_star, NTU, p):
    """The gas temperature the uncovered probe sees [degC] (``probe_gas_law``, :mod:`roastlab.model.bed`).

    0: the outlet temperature Tgo (eq. 15e, the well-mixed gas). 1: the mean of the gas along its
    path, T* + (Tgi - Tgo)/NTU (the exchanger's exponential profile Tgi -> T* averaged over the path;
    ``T_star`` and ``NTU`` from :func:`exchanger`).
    """
    if p[I_PROBEGAS] == 0.0:
        return Tgo
    return T_star + (Tgi - Tgo) / NTU


@register_jitable
def gas_heat_flows(Tb, Tm, Gg, Tgi, path, p):
    """Outlet gas temperature and heat flows ``(Tgo [degC], Qgb, Qgm, Qbm [kW])`` from the gas
    path ``path`` = :func:`exchanger` of the same instant: Tgi - Tgo from eq. 15e, Qgb eq. 9,
    Qgm eq. 10, Qbm eq. 11."""
    T_star, NTU, w, Agb, Abm, he, cg = path
    drop = (Tgi - T_star) * (1.0 - exp(-NTU))  # eq. 15e: Tgi - Tgo
    Qgb = Gg * cg * drop  # eq. 9
    Qgm = w * (he * Agb * (Tb - Tm) + Qgb)  # eq. 10: F/(1 + F) (he Agb (Tb - Tm) + Qgb)
    Qbm = p[I_HBM] * Abm * (Tm - Tb)  # eq. 11
    return Tgi - drop, Qgb, Qgm, Qbm


@register_jitable
def heat_flows(Tb, Tm, X, He, Gg, Tgi, p):
    """Outlet gas temperature and heat flows at one instant, for the gas the chamber sees.

    ``Gg`` [kg/s] and ``Tgi`` [degC] are the effective gas inputs (:func:`gas_inputs`); ``He``
    [kJ/kg dry] sets the beans' size (:func:`swell_factor`).
    Returns ``(Tgo [degC], Qgb, Qgm, Qbm [kW])`` (:func:`gas_heat_flows` of :func:`exchanger`).
    """
    return gas_heat_flows(Tb, Tm, Gg, Tgi, exchanger(Tb, Tm, X, swell_factor(He, p), Gg, Tgi, p), p)


@register_jitable
def moisture_rate_1_s(Tb, X, p):
    """dX/dt [1/s] (eqs. 13, 15c); zero once X reaches 0 so X never goes negative."""
    Xn = X * X if p[I_XEXP] == 2.0 else power(X, p[I_XEXP])
    # k1/Db^2 depends on the parameters alone: the compiled integrator computes it once per run
    rate = -(p[I_K1] / (p[I_DB] * p[I_DB])) * Xn * exp(-p[I_K2] * (1.0 / (Tb + KELVIN)))
    return where(X > 0.0, rate, 0.0)


@register_jitable
def reaction_heat_rate_kW_kg(Tb, He, p):
    """Exothermic heat production Qr = dHe/dt [kW/kg dry] (eqs. 14, 15d)."""
    Het = p[I_HET]
    # A/Het depends on the parameters alone (once per run compiled); 1/(Tb + 273.15) is the same
    # quotient as the moisture law's, which the compiler may share between the two
    return (p[I_A] / Het) * (Het - He) * exp(-p[I_HAR] * (1.0 / (Tb + KELVIN)))


# inlined into each integrator stage (numba IR), so that with the parameters passed as a tuple
# (roastlab.sim.kernels.integrate_into) their values are not copied into a call per evaluation
@register_jitable(inline="always")
def derivatives(Tb, Tm, X, He, Ta, H, Gg, Tgi, heater, fan, p):
    """Time derivatives of the six states (eqs. 15a-15d, 17, actuator lag) as a tuple.

    ``Gg`` [kg/s], ``Tgi`` [degC] are the logged (or placeholder) gas inputs, ``heater`` and
    ``fan`` the logged settings (0 when not used); :func:`heater_drive`, :func:`gas_inputs` and
    :func:`heater_power_kW` turn them into what the chamber sees.
    """
    D = heater_drive(H, p)  # the heat the lagged setting releases, once per evaluation
    g, T = gas_inputs(Gg, Tgi, D, fan, p)
    s = swell_factor(He, p)  # the beans' size (extension; 1 in the paper)
    path = exchanger(Tb, Tm, X, s, g, T, p)  # eq. 15e's gas path, once per evaluation
    Tgo, Qgb, Qgm, Qbm = gas_heat_flows(Tb, Tm, g, T, path, p)
    dX = moisture_rate_1_s(Tb, X, p)  # eq. 15c
    Qr = reaction_heat_rate_kW_kg(Tb, He, p)  # eq. 15d
    Mbd = p[I_MBD]
    cs = 1.099 + 0.007 * Tb  # partial heat capacity of bean solids, section 3.2
    Qrad = wall_radiation_kW(Tb, Tm, s, p)  # the wall's radiation to the bed (extension; 0 in the paper)
    dTb = (Qgb - Qgm + Qbm + Qrad + Mbd * (Qr + p[I_LAM] * dX)) / (Mbd * (cs + p[I_CW] * X))  # eq. 15a
    # eq. 15b, eq. 12's Qe; 1/(Mm cm) and 1/tau depend on the parameters alone (once per run compiled)
    dTm = (Qgm - Qbm - Qrad + heater_power_kW(D, p) - shell_loss_kW(Tm, p)) * (1.0 / (p[I_MM] * p[I_CM]))
    dTa = probe_rate_C_s(Tb, Ta, probe_gas_C(T, Tgo, path[0], path[1], p), s, p)  # eq. 17 (probe immersion: extension)
    dH = (heater - H) * (1.0 / p[I_TAUH]) * heater_lag_factor(H, p)  # actuator lag (extension)
    return dTb, dTm, dX, Qr, dTa, dH


@register_jitable
def outlet_gas_C(x, Gg, Tgi, fan, p):
    """Outlet gas temperature Tgo [degC] at state ``x`` (eq. 15e, effective gas inputs)."""
    g, T = gas_inputs(Gg, Tgi, heater_drive(x[S_H], p), fan, p)
    return heat_flows(x[S_TB], x[S_TM], x[S_X], x[S_HE], g, T, p)[0]


@register_jitable
def rhs(t, x, u, p):
    """The model's right-hand side f(t, x, u, p) -> dx/dt as a length-5 array.

    Parameters
    ----------
    t : float
        Time [s]; the model is autonomous, so ``t`` is unused but kept for the ODE form.
    x : array of 5 or 6 floats
        ``[Tb degC, Tm degC, X kg/kg dry, He kJ/kg dry, Ta degC[, H setting units]]``
        (H = 0 when omitted).
    u : array of 2 or 4 floats
        ``[Gg kg/s, Tgi degC[, heater, fan]]`` (settings 0 when omitted).
    p : array
        Parameter vector from :func:`pack_params`.

    Returns an array of the same length as ``x``.
    """
    H = x[S_H] if x.shape[0] > S_H else 0.0
    heater = u[U_HEATER] if u.shape[0] > U_HEATER else 0.0
    fan = u[U_FAN] if u.shape[0] > U_FAN else 0.0
    d = derivatives(x[S_TB], x[S_TM], x[S_X], x[S_HE], x[S_TA], H, u[U_GG], u[U_TGI], heater, fan, p)
    out = np.empty(x.shape[0])
    for i in range(x.shape[0]):
        out[i] = d[i]
    return out


def _real_vector(name: str, value, sizes: tuple[int, ...]) -> np.ndarray:
    if np.iscomplexobj(value):
        raise ParameterError(f"{name} must be real numbers, got complex values")
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be an array of numbers, got {type(value).__name__}") from None
    if a.ndim != 1 or a.shape[0] not in sizes:
        raise ParameterError(
            f"{name} must be a 1-D array of {' or '.join(map(str, sizes))} numbers, got shape {a.shape}"
        )
    if not np.all(np.isfinite(a)):
        raise ParameterError(f"{name} must be finite, got {a.tolist()}")
    return a


def checked_rhs(t, x, u, p) -> np.ndarray:
    """:func:`rhs` for Python callers (``roastlab.rhs``): the arguments' types, shapes and
    finiteness are checked first and a wrong one is a ParameterError naming it. The compiled
    :func:`rhs` itself (callable from numba code) checks nothing.

    Parameters
    ----------
    t : float
        Time [s] (unused: the model is autonomous).
    x : array of 5 or 6 floats
        ``[Tb degC, Tm degC, X kg/kg dry, He kJ/kg dry, Ta degC[, H setting units]]``.
    u : array of 2 or 4 floats
        ``[Gg kg/s, Tgi degC[, heater, fan]]``.
    p : array
        Parameter vector from :func:`pack_params`.

    Returns dx/dt, an array of the same length as ``x``.
    """
    if isinstance(t, bool) or not isinstance(t, (int, float, np.integer, np.floating)) or not math.isfinite(t):
        raise ParameterError(f"t must be a finite number of seconds, got {str(t)[:40]!r}")
    x = _real_vector("x (the state)", x, (S_H, S_H + 1))
    u = _real_vector("u (the inputs)", u, (2, U_FAN + 1))
    p = _real_vector("p (the parameter vector from pack_params)", p, (N_PARAMS,))
    return rhs(float(t), x, u, p)


#: The elementary operations :func:`rebind` may replace.
OPERATIONS = ("exp", "fmax", "where", "power", "cube_root")


def rebind(**operations) -> types.SimpleNamespace:
    """This module's equations evaluated with other elementary operations: the one right-hand side
    for other number types, never a copy of it.

    ``operations`` replace ``exp``, ``fmax``, ``where``, ``power`` and ``cube_root`` (e.g. ``casadi.exp``,
    ``casadi.fmax``, ``casadi.if_else``; branch-free arithmetic versions for
    :mod:`roastlab.sim.lanes`). Returns a namespace of every function of this module rebuilt over those
    operations (``derivatives``, ``heat_flows`` ...); the parameter vector stays numeric.

    >>> ns = rebind(exp=lambda v: 1.0)  # a toy "number type": exp is 1 everywhere
    >>> ns.bean_heat_transfer_coefficient_kW_m2K(0.1) == 0.49 - 0.443
    True
    """
    unknown = sorted(set(operations) - set(OPERATIONS))
    if unknown:
        raise ParameterError(f"unknown operation(s) {', '.join(unknown)} (allowed: {', '.join(OPERATIONS)})")
    namespace = dict(globals())
    namespace.update(operations)
    functions = {}
    for name, value in list(namespace.items()):
        if isinstance(value, types.FunctionType) and value.__module__ == __name__ and name not in operations:
            functions[name] = types.FunctionType(value.__code__, namespace, name, value.__defaults__)
    namespace.update(functions)
    return types.SimpleNamespace(**functions)


def pack_params(plant, theta, X0: float = 0.1, moisture: str = "schwartzberg", bed=None) -> np.ndarray:
    """Build the parameter vector ``p`` for a plant, theta and initial moisture.

    Parameters
    ----------
    plant : roastlab.plant.Plant (:func:`roastlab.model.plant.as_plant` for a preset name)
    theta : sequence (hgm [kW/(m2 K)], hbm [kW/(m2 K)], Pbm [-]) or mapping with those keys
    X0 : float
        Initial moisture [kg/kg dry]; fixes the dry batch mass Mbd = Mb / (1 + X0).
    moisture : {"schwartzberg", "printed"}
    bed : :class:`roastlab.model.bed.BedLaws`, its text (``"contact=wall,probe=tumbling"``) or None
        (the paper's bed)
    """
    from .bed import BedLaws
    from .parameters import as_theta
    from .quantities import table

    th = as_theta(theta)
    from .limits import check_value

    if not hasattr(plant, "process") or not hasattr(plant, "Mbd_kg"):
        raise ParameterError(
            f"plant must be a Plant, got {type(plant).__name__} {str(plant)[:40]!r}: "
            "roastlab.model.plant.as_plant('120kg') or roastlab.load_plant('PLANT.toml')"
        )
    X0 = check_value("X0", X0, "pack_params")
    if moisture not in MOISTURE_LAWS:
        raise ParameterError(f"unknown moisture law {moisture!r} (allowed: {', '.join(MOISTURE_LAWS)})")
    pc = plant.process
    k1 = pc.k1 if moisture == "schwartzberg" else K1_PRINTED
    values = {
        "hgm": th.hgm,
        "hbm": th.hbm,
        "Pbm": th.Pbm,
        "Agm": plant.Agm_m2,
        "Ab": plant.Ab_m2,
        "Mbd": plant.Mbd_kg(X0),
        "Mm": plant.Mm_kg,
        "A": pc.A,
        "cm": pc.cm,
        "cw": pc.cw,
        "Db": pc.Db,
        "Ha_R": pc.Ha_R,
        "Het": pc.Het,
        "k1": k1,
        "k2": pc.k2,
        "Kt": pc.Kt,
        "lam": pc.lam,
        "x_exp": MOISTURE_LAWS[moisture],
        "Gg_scale": 1.0,  # the flow input as given
        "Ashell": plant.Ashell_m2,
        "h_bed": plant.bed_depth_m,
        "A_wall": plant.wall_contact_area_m2,
        "A_surf": plant.bed_surface_area_m2,
        **BedLaws.parse(bed).codes(),
    }
    # the extensions' defaults (each the paper's model) from the one quantity table
    values.update({q.slot: q.default for q in table() if q.kind == "extension"})
    return np.array([values[name] for name in PARAM_NAMES], dtype=np.float64)
