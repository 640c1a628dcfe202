"""A plain, slow, independent reference of the model, for tests only.

Written from MODEL.md without using roastlab.model, integrated by SciPy's DOP853 at tight
tolerance interval by interval (so input kinks at samples are respected). If the compiled
simulator and this disagree, one of them has a bug.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

ALPHA = [1.0839e3, -7.2075e-1, 2.1034e-3, -2.3267e-6, 1.3621e-9, -4.1550e-13, 5.3091e-17]
PROCESS = dict(
    A=116200.0,
    cm=0.418,
    cw=5.0,
    Db=7.65e-3,
    HaR=5500.0,
    Het=232.0,
    k1=4320.0,
    k2=9889.0,
    Kt=0.01,
    mb=1.5e-4,
    lam=2790.0,
)
PLANTS = {
    "120kg": dict(Mb=120.0, Dch=1.24, Lch=1.335, Hflap=0.3, Sflap=0.1, Mm=2000.0),
    "360kg": dict(Mb=360.0, Dch=1.90, Lch=2.04, Hflap=0.3, Sflap=0.1, Mm=7000.0),
}


def bed_segment(Mb, Dch, Lch, rho=680.0):
    """(angle t [rad], depth h [m], wetted wall area [m2]) of a bed at rest: the circular segment
    holding Mb / rho of beans, found by bisection on its area R^2/2 (t - sin t)."""
    R = Dch / 2
    area = Mb / rho / Lch
    lo, hi = 0.0, 2 * math.pi
    for _ in range(200):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if R * R / 2 * (mid - math.sin(mid)) < area else (lo, mid)
    t = (lo + hi) / 2
    return t, R * (1 - math.cos(t / 2)), R * t * Lch + 2 * R * R / 2 * (t - math.sin(t))


def make_rhs(plant: str, theta, X0: float, moisture: str = "schwartzberg", act=None, bed=None, process=None):
    """The slow reference right-hand side. ``act`` holds the actuator extension's values
    (Qe_gain, Qe_offset, Tgi_gain, tau, Gg_fan, U_shell, T_room, heater_exp, fan_exp, heater_lag_exp,
    heater_full); None = the paper's model.
    ``bed`` the bed laws and the probe's depth: {"contact": "paper"|"wall", "probe": "rest"|"tumbling",
    "probe_gas": "outlet"|"mean", "h_probe": m, "eps_rad": the wall's radiation to the bed's free
    surface, 0-1, "k_flight": the gas-bean area over that surface, 0 = the contact law's, "swell": the
    beans' volume gain when the roast reactions are complete, V/V0 - 1}; None = the paper's. ``process`` overrides values of PROCESS (and the plant's metal mass Mm)."""
    process = dict(process or {})
    g = {**PLANTS[plant], **({"Mm": process.pop("Mm")} if "Mm" in process else {})}
    c = {**PROCESS, **process}
    hgm, hbm, Pbm = theta
    Agm = math.pi * g["Dch"] * (g["Lch"] + g["Hflap"] * g["Lch"] / g["Sflap"] + g["Dch"] / 2)
    Ab = g["Mb"] / c["mb"] * math.pi * c["Db"] ** 2
    bed = {
        "contact": "paper",
        "probe": "rest",
        "probe_gas": "outlet",
        "h_probe": 0.0,
        "eps_rad": 0.0,
        "k_flight": 0.0,
        "swell": 0.0,
        **(bed or {}),
    }
    angle, h_bed0, A_wall0 = bed_segment(g["Mb"], g["Dch"], g["Lch"])
    A_surf0 = 2 * (g["Dch"] / 2) * math.sin(angle / 2) * g["Lch"]  # the segment's chord along the drum

    def geometry(He):
        """The bed's areas, the probe's cover and the free surface for beans swollen by the reactions'
        extent He / Het: volume 1 + swell He/Het times the green, so lengths z = its cube root, each
        bean's area z^2, a shallow bed's depth z^2 (segment area ~ h^1.5), its arc and chord z (~ h^0.5)."""
        z = (1 + bed["swell"] * max(He, 0.0) / c["Het"]) ** (1 / 3)
        ab, h_bed, A_surf = Ab * z * z, h_bed0 * z * z, A_surf0 * z
        if bed["contact"] == "wall":  # beans touch the wetted wall; the rest of their surface meets the gas
            Abm = Pbm * A_wall0 * z
            Agb = ab - Abm
        else:
            Agb, Abm = ab * (1 - Pbm), ab * Pbm
        if bed["k_flight"] > 0:  # the gas meets the beans at the bed's surface (and the beans in flight)
            Agb = bed["k_flight"] * A_surf
        hp = bed["h_probe"]
        if hp == 0:
            cover = 1.0
        elif bed["probe"] == "tumbling":
            cover = 1 - math.exp(-h_bed / hp)
        else:
            cover = min(1.0, h_bed / hp)
        return Agb, Abm, cover, A_surf

    Mbd = g["Mb"] / (1 + X0)
    k1, xexp = (c["k1"], 2) if moisture == "schwartzberg" else (4.32e-9, 0)

    a = act or {}

    def f(x, Gg, Tgi, heater=0.0, fan=0.0):
        Tb, Tm, X, He, Ta, H = x
        # actuator extension: fan -> flow, lagged heater -> inlet gas rise and heat into the metal
        # the fan's drive: fan^e (a fan logged as the pressure it makes across the drum: e = 0.5, the flow
        # through a fixed resistance), with the heater's millionth under the power
        ef = a.get("fan_exp", 1.0)
        Gg = max(Gg + a.get("Gg_fan", 0.0) * (fan if ef == 1.0 else fan * (max(fan, 0.0) + 1e-6) ** (ef - 1.0)), 1e-6)
        # the heat the lagged setting releases: H^e (a gas burner's pressure: e = 0.5, the orifice law),
        # a millionth of a unit added under the power so that its slope is finite at 0
        e = a.get("heater_exp", 1.0)
        D = H if e == 1.0 else H * (max(H, 0.0) + 1e-6) ** (e - 1.0)
        Tgi = Tgi + a.get("Tgi_gain", 0.0) * D
        Qe = max(a.get("Qe_offset", 0.0) + a.get("Qe_gain", 0.0) * D, 0.0)
        # the lag: tau at full power, (full / H)^e at setting H (a radiant element: e = 3/4), H at least
        # a twentieth of full power there
        full, elag = a.get("heater_full", 100.0), a.get("heater_lag_exp", 0.0)
        dH = (heater - H) / (a.get("tau", 1.0) * (full / max(H, 0.05 * full)) ** elag)
        Agb, Abm, cover, A_surf = geometry(He)
        cg = sum(a * (Tgi + 273.15) ** i for i, a in enumerate(ALPHA)) / 1000
        he = 0.49 - 0.443 * math.exp(-0.206 * X)
        F = hgm * Agm / (he * Agb)
        Tstar = (Tb + F * Tm) / (1 + F)
        ntu = he * Agb * (1 + F) / (Gg * cg)
        drop = (Tgi - Tstar) * (1 - math.exp(-ntu))
        Qgb = Gg * cg * drop
        Qgm = F * (he * Agb * (Tb - Tm) + Qgb) / (1 + F)
        Qbm = hbm * Abm * (Tm - Tb)
        dX = -k1 * max(X, 0.0) ** xexp / c["Db"] ** 2 * math.exp(-c["k2"] / (Tb + 273.15)) if X > 0 else 0.0
        Qr = c["A"] * (c["Het"] - He) / c["Het"] * math.exp(-c["HaR"] / (Tb + 273.15))
        cs = 1.099 + 0.007 * Tb
        # grey-body radiation of the wall (kelvin) to the bed's free surface, Stefan-Boltzmann in kW
        Qrad = bed["eps_rad"] * 5.670374419e-11 * A_surf * ((Tm + 273.15) ** 4 - (Tb + 273.15) ** 4)
        dTb = (Qgb - Qgm + Qbm + Qrad + Mbd * (Qr + c["lam"] * dX)) / (Mbd * (cs + c["cw"] * X))
        # shell loss to the room from the outer drum surface (mantle and two end discs)
        Qloss = a.get("U_shell", 0.0) * math.pi * g["Dch"] * (g["Lch"] + g["Dch"] / 2) * (Tm - a.get("T_room", 22.0))
        dTm = (Qgm - Qbm - Qrad + Qe - Qloss) / (g["Mm"] * c["cm"])
        # the uncovered probe sees the outlet gas, or the mean of the exponential profile along the path
        Tg = Tgi - drop if bed["probe_gas"] == "outlet" else Tstar + (Tgi - Tstar) * (1 - math.exp(-ntu)) / ntu
        dTa = c["Kt"] * (cover * (Tb - Ta) + (1 - cover) * (Tg - Ta))
        return [dTb, dTm, dX, Qr, dTa, dH], Tgi - drop

    return f


def reference_simulate(
    plant,
    theta,
    t,
    Gg,
    Tgi,
    x0,
    moisture="schwartzberg",
    hold="linear",
    rtol=1e-10,
    atol=1e-10,
    heater=None,
    fan=None,
    act=None,
    bed=None,
    process=None,
    method="DOP853",
):
    """Return (states (n, 6), Tgo (n,)) at the sample times (x0 of 5 states gets H = heater[0]);
    ``method`` a SciPy solver (``"Radau"`` for stiff values)."""
    f = make_rhs(plant, theta, x0[2], moisture, act, bed, process)
    n = len(t)
    heater = np.zeros(n) if heater is None else np.asarray(heater, dtype=float)
    fan = np.zeros(n) if fan is None else np.asarray(fan, dtype=float)
    x0 = list(x0[:5]) + [heater[0]]
    out = np.empty((n, 6))
    tgo = np.empty(n)
    x = np.array(x0, dtype=float)
    out[0] = x
    tgo[0] = f(x, Gg[0], Tgi[0], heater[0], fan[0])[1]
    for k in range(n - 1):
        t0, t1 = t[k], t[k + 1]

        def u(s, k=k, t0=t0, t1=t1):
            series = (Gg, Tgi, heater, fan)
            if hold == "zoh":
                return tuple(v[k] for v in series)
            w = (s - t0) / (t1 - t0)
            return tuple(v[k] + w * (v[k + 1] - v[k]) for v in series)

        sol = solve_ivp(lambda s, y: f(y, *u(s))[0], (t0, t1), x, method=method, rtol=rtol, atol=atol)
        x = sol.y[:, -1]
        out[k + 1] = x
        j = k if hold == "zoh" else k + 1
        uk = (Gg[j], Tgi[j], heater[j], fan[j])
        tgo[k + 1] = f(x, *uk)[1]
    return out, tgo
