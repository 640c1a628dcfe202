"""Fixed process constants of the roasting model (paper Table 5, left; MODEL.md).

Units follow MODEL.md: kJ, kW (= kJ/s), kg, m, s, degC; kelvin only inside the Arrhenius
terms and the gas heat-capacity polynomial.

Departures from the printed paper (see MODEL.md):

* ``A`` is a rate, kJ/(kg s); Table 5 prints kJ/kg.
* ``k1`` = 4320 m^2/s with an X^2 factor (Schwartzberg's law, which the paper cites); the
  printed eq. 13 with k1 = 4.32e-9 and no X factor barely moves moisture in a whole roast.
  It stays available as the ``"printed"`` moisture law (:data:`K1_PRINTED`).

References
----------
.. [1] "A scalable model of a coffee roasting chamber", Procedia Computer Science (2021),
   doi:10.1016/j.procs.2021.01.362
.. [2] Schwartzberg, H. G. "Modeling bean heating during batch roasting of coffee beans",
   in Engineering and Food for the 21st Century (2002).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ..errors import ParameterError
from .limits import check_value
from .quantities import defaults

#: Table 5's values, from the one quantity table.
_D = defaults("process")

#: eq. 2 coefficients alpha_0..alpha_6 of cg(T) in J/(kg K), T in kelvin.
CG_ALPHA_J_KG_K = (
    1.0839e3,
    -7.2075e-1,
    2.1034e-3,
    -2.3267e-6,
    1.3621e-9,
    -4.1550e-13,
    5.3091e-17,
)

#: eq. 13 as printed: k1 = 4.32e-9 with no X factor (the ``"printed"`` moisture law).
K1_PRINTED = 4.32e-9

#: Moisture laws (eq. 13 / 15c): name -> exponent of X in dX/dt.
MOISTURE_LAWS = {"schwartzberg": 2.0, "printed": 0.0}

#: Input hold between samples: first-order (linear) or zero-order.
INPUT_HOLDS = ("linear", "zoh")

#: Air density of the Pitot formula, eq. 16 [kg/m^3].
RHO0_KG_M3 = 1.275


#: Free-settled bulk density of green coffee [kg/m^3] (0.65-0.75 g/mL as measured in a graduated
#: cylinder by green-coffee traders; ISO recommends that method). Sets the volume, and so the depth,
#: of the bean bed in the drum for the probe-immersion extension
#: (:attr:`roastlab.model.plant.Plant.bed_depth_m`).
GREEN_BULK_DENSITY_KG_M3 = 680.0

#: Bean temperature at first crack [degC]. Coffee cracks when its beans reach a temperature, not
#: when a probe reads one: roasting guides put it at about 196-205 degC, and on the 27 weighed
#: RoasTime logs in ../shared/data/real/bullet (five Aillio Bullets, 200-900 g) the infrared bean
#: reading at the roaster's FCs mark reads a median 199.7 degC (standard deviation 3.4 degC,
#: 191-207 degC), while the bean probe reads 162-190 degC there (tests/test_real_roaster.py
#: recomputes it). So a log that marks first crack gives the beans' temperature at one instant even
#: where it logs no bean reading (a column map's ``[Tb2] first_crack``), and a model whose beans are
#: far from it at the mark has placed the beans wrong (:func:`roastlab.metrics.profile.implausible_states`).
FIRST_CRACK_BEAN_C = 200.0


@dataclass(frozen=True)
class ProcessConstants:
    """Fixed process constants (Table 5, left), overridable per plant file; the defaults are the
    quantity table's (:mod:`roastlab.model.quantities`).

    Attributes
    ----------
    A : float
        Arrhenius pre-factor of the exothermic reaction [kJ/(kg s)] (eq. 14).
    cm : float
        Specific heat capacity of the drum metal [kJ/(kg K)] (eq. 12).
    cw : float
        Partial heat capacity of water in the bean [kJ/(kg K)] (eq. 8).
    Db : float
        Bean diameter [m] (eq. 13, area of beans).
    Ha_R : float
        Activation energy over the gas constant [K] (eq. 14).
    Het : float
        Total reaction heat [kJ/kg dry] (eq. 14).
    k1 : float
        Schwartzberg pre-factor [m^2/s] (eq. 13).
    k2 : float
        Schwartzberg activation temperature [K] (eq. 13).
    Kt : float
        Inverse time constant of the bean probe [1/s] (eq. 17).
    mb : float
        Mass of one bean [kg] (area of beans, section 3.1).
    lam : float
        Latent heat of vaporisation of bean moisture [kJ/kg] (eq. 8).
    """

    A: float = _D["A"]
    cm: float = _D["cm"]
    cw: float = _D["cw"]
    Db: float = _D["Db"]
    Ha_R: float = _D["Ha_R"]
    Het: float = _D["Het"]
    k1: float = _D["k1"]
    k2: float = _D["k2"]
    Kt: float = _D["Kt"]
    mb: float = _D["mb"]
    lam: float = _D["lam"]

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            check_value(f.name, getattr(self, f.name))  # the one plausibility table

    #: Names accepted in a plant file's ``[process]`` table, mapped to field names.
    ALIASES = {"Ha/R": "Ha_R", "lambda": "lam"}

    @classmethod
    def from_mapping(cls, values: dict, source: str | None = None) -> ProcessConstants:
        """Build from a ``{name: value}`` mapping of overrides (MODEL.md names)."""
        known = {f.name for f in dataclasses.fields(cls)}
        kwargs = {}
        for key, value in values.items():
            name = cls.ALIASES.get(key, key)
            if name not in known:
                allowed = ", ".join(sorted(known))
                raise ParameterError(f"unknown process constant {key!r} (allowed: {allowed})", source, "[process]")
            kwargs[name] = check_value(name, value, source)
        try:
            return cls(**kwargs)
        except ParameterError as exc:
            raise ParameterError(exc.problem, source, "[process]") from None

    def as_dict(self) -> dict[str, float]:
        return dataclasses.asdict(self)
