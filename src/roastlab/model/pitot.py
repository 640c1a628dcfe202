"""Gas mass flow from a Pitot tube and a thermocouple (paper eq. 16)."""

from __future__ import annotations

import numpy as np

from .constants import RHO0_KG_M3


def gas_flow_pitot_kg_s(dp_Pa, T_C, section_m2: float, rho0_kg_m3: float = RHO0_KG_M3):
    """Gg = S sqrt(2 rho0 dp 273.15 / (T + 273.15)) [kg/s] (eq. 16).

    Parameters
    ----------
    dp_Pa : Pitot pressure difference [Pa] (>= 0)
    T_C : gas temperature at the Pitot tube [degC]
    section_m2 : pipe cross-section S [m^2]
    rho0_kg_m3 : air density at 0 degC the formula refers to (1.275 kg/m^3 in the paper)

    >>> round(float(gas_flow_pitot_kg_s(100.0, 0.0, 0.05)), 4)
    0.7984
    """
    dp = np.asarray(dp_Pa, dtype=float)
    T = np.asarray(T_C, dtype=float)
    return section_m2 * np.sqrt(2.0 * rho0_kg_m3 * dp * 273.15 / (T + 273.15))
