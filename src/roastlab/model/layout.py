"""The one layout of the model's vectors: state, input and parameter names and their indices.

Every module that reads or writes a state, input or parameter vector takes its index from
here by name (``S["Tm_C"]``, ``P["Mbd"]``) or through the integer constants below, which the
compiled kernels use as compile-time constants. No bare index into one of these vectors
stands outside the kernels and the right-hand side.

States ``x = [Tb, Tm, X, He, Ta, H]``: the paper's five (bean, metal, moisture, exothermic
heat, probe; eqs. 15a-15d, 17) and the lagged heater setting of the actuator extension.
Inputs ``u = [Gg, Tgi, heater, fan]``: the paper's two gas inputs and the two logged settings
of the actuator extension.

>>> STATE_NAMES[S_TM], PARAM_NAMES[P["Mbd"]]
('Tm_C', 'Mbd')
>>> len(STATE_NAMES) == N_STATES
True
"""

from __future__ import annotations

#: The paper's five states (eqs. 15a-15d, 17) [degC, degC, kg/kg dry, kJ/kg dry, degC].
PAPER_STATE_NAMES = ("Tb_C", "Tm_C", "X_kg_kg", "He_kJ_kg", "Ta_C")
#: The actuator extension's state: the heater setting after its first-order lag [setting units].
HEATER_STATE = "heater_lagged"
#: Every state the integrator carries, in the order of the state vector.
STATE_NAMES = (*PAPER_STATE_NAMES, HEATER_STATE)
N_STATES = len(STATE_NAMES)
#: State index by name.
S = {name: i for i, name in enumerate(STATE_NAMES)}
S_TB, S_TM, S_X, S_HE, S_TA, S_H = (S[k] for k in STATE_NAMES)

#: Initial-state quantity (:mod:`roastlab.model.quantities`) -> its index in the state vector.
STATE0 = {"Tb0_C": S_TB, "Tm0_C": S_TM, "X0": S_X, "He0_kJ_kg": S_HE, "Ta0_C": S_TA}

#: Inputs of one instant [kg/s, degC, setting, setting].
INPUT_NAMES = ("Gg_kg_s", "Tgi_C", "heater", "fan")
N_INPUTS = len(INPUT_NAMES)
U = {name: i for i, name in enumerate(INPUT_NAMES)}
U_GG, U_TGI, U_HEATER, U_FAN = (U[k] for k in INPUT_NAMES)

#: Layout of the parameter vector ``p`` (:func:`roastlab.model.rhs.pack_params`).
PARAM_NAMES = (
    "hgm",
    "hbm",
    "Pbm",  # identified theta [kW/(m2 K)], [kW/(m2 K)], [-]
    "Agm",
    "Ab",
    "Mbd",
    "Mm",  # plant-derived [m2], [m2], [kg], [kg]
    "A",
    "cm",
    "cw",
    "Db",
    "Ha_R",
    "Het",
    "k1",
    "k2",
    "Kt",
    "lam",  # process constants
    "x_exp",  # exponent of X in the moisture law: 2 (Schwartzberg) or 0 (printed)
    "Gg_scale",  # factor on the gas-flow input [-], 1 = as given (identifies an unlogged constant Gg)
    # actuator extension (0 = the paper's model)
    "Qe_gain",  # heat into the drum metal per unit of heater setting [kW/unit]
    "Qe_offset",  # heat into the drum metal at heater setting 0 [kW]
    "Tgi_gain",  # rise of the inlet gas temperature per unit of heater setting [degC/unit]
    "tau_heater",  # first-order lag of the heater's effect [s]
    "Gg_fan",  # gas flow per unit of fan setting [kg/s per unit]
    # drum-shell heat loss to the room (extension; 0 = the paper's adiabatic shell)
    "U_shell",  # heat-loss coefficient of the drum's outer surface [kW/(m2 K)]
    "Ashell",  # outer drum surface exposed to the room [m2] (plant-derived)
    "T_room",  # room temperature the shell loses heat to [degC]
    # probe immersion (extension; h_probe 0 = the paper's fully immersed probe)
    "h_bed",  # depth of the bean bed at rest [m] (plant- and batch-derived)
    "h_probe",  # bed depth that covers the bean probe fully [m]
    # bed laws (roastlab.model.bed; 0 = the paper's law of each option)
    "A_wall",  # drum wall the bed at rest wets [m2] (plant- and batch-derived)
    "contact_law",  # 0: Abm = Pbm Ab (section 3.1); 1: Abm = Pbm A_wall, Agb = Ab - Abm
    "probe_law",  # 0: covered share min(1, h_bed/h_probe) (bed at rest); 1: 1 - exp(-h_bed/h_probe) (tumbling)
    "probe_gas_law",  # 0: the uncovered probe sees Tgo (eq. 15e); 1: the gas's mean along its path
    # wall-to-bed radiation (extension; eps_rad 0 = the paper, whose metal reaches the beans by contact alone)
    "eps_rad",  # effective emissivity of the drum wall's exchange with the bed's free surface [-]
    "A_surf",  # the bed's free surface, its chord along the drum [m2] (plant- and batch-derived)
    # the gas meets the beans at the bed's surface (extension; k_flight 0 = the contact law's Agb)
    "k_flight",  # gas-bean area over the bed's free surface [-] (>= 1: the beans in flight add to it)
    # the drum at CHARGE from a reading that shows a share of its rise over the room (extension; 1 = the drum's own)
    "Tm0_share",  # read once per batch at CHARGE (roastlab.model.rhs.drum_at_charge_C), never by the right-hand side
    # the heater's setting in the heat it releases (extension; 1 = in proportion, the linear law)
    "heater_exp",  # exponent of the lagged setting: 0.5 for a gas burner logged as its pressure (orifice law)
    # the fan's setting in the air flow it moves (extension; 1 = in proportion, the linear law)
    "fan_exp",  # exponent of the fan setting: 0.5 for a fan logged as the pressure it makes (orifice law)
    # the heater's lag with its setting (extension; 0 = one lag at every setting, the first-order law)
    "heater_lag_exp",  # 3/4 for a radiant element: its lag goes as (full / H)^(3/4) (roastlab.model.rhs.heater_lag_factor)
    "heater_full",  # the heater setting at full power [setting unit] (100 for a percentage)
    # the beans swell as they roast (extension; 0 = the paper's beans, whose size never changes)
    "bean_swell",  # the beans' volume gain at the roast reactions' end, V/V0 - 1 [-] (roastlab.model.rhs.swell_factor)
)
P = {name: i for i, name in enumerate(PARAM_NAMES)}
N_PARAMS = len(PARAM_NAMES)
# indices derived from the names (compile-time constants for the kernels)
I_HGM, I_HBM, I_PBM, I_AGM, I_AB, I_MBD, I_MM = (P[k] for k in ("hgm", "hbm", "Pbm", "Agm", "Ab", "Mbd", "Mm"))
I_A, I_CM, I_CW, I_DB, I_HAR, I_HET = (P[k] for k in ("A", "cm", "cw", "Db", "Ha_R", "Het"))
I_K1, I_K2, I_KT, I_LAM, I_XEXP, I_GGS = (P[k] for k in ("k1", "k2", "Kt", "lam", "x_exp", "Gg_scale"))
I_QEG, I_QEO, I_TGIG, I_TAUH, I_GGF = (P[k] for k in ("Qe_gain", "Qe_offset", "Tgi_gain", "tau_heater", "Gg_fan"))
I_USH, I_ASH, I_TROOM = (P[k] for k in ("U_shell", "Ashell", "T_room"))
I_HBED, I_HPROBE = P["h_bed"], P["h_probe"]
I_AWALL, I_CONTACT, I_PROBELAW, I_PROBEGAS = (P[k] for k in ("A_wall", "contact_law", "probe_law", "probe_gas_law"))
I_EPSRAD, I_ASURF, I_KFLIGHT = P["eps_rad"], P["A_surf"], P["k_flight"]
I_HEXP, I_FEXP = P["heater_exp"], P["fan_exp"]
I_HLEXP, I_HFULL = P["heater_lag_exp"], P["heater_full"]
I_SWELL = P["bean_swell"]
