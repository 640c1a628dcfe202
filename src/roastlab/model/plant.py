"""Plant geometry and the quantities derived from it (paper eq. 7 and section 3.1).

A plant is a data file: six measured dimensions and, optionally, overrides of the fixed
process constants. Everything else (areas, dry mass, F) is computed here, never stored.
Presets ``120kg`` and ``360kg`` ship as TOML files in ``roastlab/plants/``.
"""

from __future__ import annotations

import functools
import math
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from ..errors import InputError, ParameterError
from .constants import GREEN_BULK_DENSITY_KG_M3, ProcessConstants
from .limits import check_value
from .rhs import bean_areas_m2, bean_heat_transfer_coefficient_kW_m2K, conductance_ratio_F, dry_mass_kg

#: A batch may be this far below or above a plant's nominal batch (factor): outside it, it is
#: another machine's batch (a log read on the wrong plant, or a change with a unit slip).
BATCH_RANGE_FACTOR = (1 / 20, 5.0)

GEOMETRY_KEYS = ("Mb_kg", "Dch_m", "Lch_m", "Hflap_m", "Sflap_m", "Mm_kg")
_GEOMETRY_DOC = {
    "Mb_kg": "green batch mass [kg]",
    "Dch_m": "chamber diameter [m]",
    "Lch_m": "chamber length [m]",
    "Hflap_m": "flap height [m]",
    "Sflap_m": "flap step [m]",
    "Mm_kg": "metal mass [kg]",
}


@functools.cache
def _preset_names() -> tuple[str, ...]:
    folder = resources.files("roastlab.model") / "plants"
    return tuple(sorted(p.name.removesuffix(".toml") for p in folder.iterdir() if p.name.endswith(".toml")))


@functools.cache
def _load_preset(name: str) -> Plant:
    resource = resources.files("roastlab.model") / "plants" / f"{name}.toml"
    return plant_from_mapping(tomllib.loads(resource.read_text(encoding="utf-8")), f"preset {name}", name)


def preset_names() -> list[str]:
    """Names of the plant presets shipped with roastlab."""
    return list(_preset_names())


@dataclass(frozen=True)
class Plant:
    """A drum roaster described by its geometry (Table 5, right).

    Attributes
    ----------
    name : str
    Mb_kg, Dch_m, Lch_m, Hflap_m, Sflap_m, Mm_kg : float
        Green batch mass [kg], chamber diameter [m], chamber length [m], flap height [m],
        flap step [m] and metal mass [kg].
    process : ProcessConstants
        Fixed process constants (Table 5, left), possibly overridden by the plant file.

    Examples
    --------
    >>> p = as_plant("120kg")
    >>> round(p.Agm_m2, 1), round(p.Ab_m2)
    (23.2, 147)
    """

    name: str
    Mb_kg: float
    Dch_m: float
    Lch_m: float
    Hflap_m: float
    Sflap_m: float
    Mm_kg: float
    process: ProcessConstants = field(default_factory=ProcessConstants)

    def __post_init__(self) -> None:
        for key in GEOMETRY_KEYS:
            check_value(key, getattr(self, key))  # the one plausibility table

    # --- derived geometry (eq. 7, section 3.1) ------------------------------------
    @property
    def Agm_m2(self) -> float:
        """Gas-to-metal area: drum wall, flaps and end discs [m^2] (eq. 7)."""
        return math.pi * self.Dch_m * (self.Lch_m + self.Hflap_m * self.Lch_m / self.Sflap_m + self.Dch_m / 2)

    @property
    def Ashell_m2(self) -> float:
        """Outer drum surface exposed to the room: mantle and two end discs, pi D (L + D/2) [m^2].

        Not in the paper (its shell is adiabatic); the area of the shell heat-loss extension
        (:func:`roastlab.model.rhs.shell_loss_kW`).
        """
        return math.pi * self.Dch_m * (self.Lch_m + self.Dch_m / 2)

    @property
    def fill_fraction(self) -> float:
        """Share of the drum volume the green batch fills, Mb / (rho_bulk pi D^2/4 L) [-].

        Not in the paper; the bean-bed geometry of the probe-immersion extension, with the
        free-settled bulk density :data:`~roastlab.model.constants.GREEN_BULK_DENSITY_KG_M3`.
        """
        return self.Mb_kg / self.capacity_kg

    @property
    def capacity_kg(self) -> float:
        """Green beans the drum holds when full, rho_bulk pi D^2/4 L [kg] (fill fraction 1);
        not in the paper, it bounds the batch masses a what-if or transfer may ask for."""
        return GREEN_BULK_DENSITY_KG_M3 * math.pi * self.Dch_m**2 / 4.0 * self.Lch_m

    def batch_fits(self, mass_kg: float) -> bool:
        """True when a green batch of ``mass_kg`` can be roasted here: within
        :data:`BATCH_RANGE_FACTOR` of the nominal batch and no more than the drum holds."""
        lo, hi = BATCH_RANGE_FACTOR
        return lo * self.Mb_kg <= mass_kg <= min(hi * self.Mb_kg, self.capacity_kg)

    def check_batch_mass(self, mass_kg: float) -> None:
        """Refuse a requested green batch of ``mass_kg`` this plant cannot take, naming its range and
        capacity (:meth:`batch_fits`)."""
        if not self.batch_fits(mass_kg):
            lo, hi = BATCH_RANGE_FACTOR
            raise ParameterError(
                f"a {mass_kg:g} kg batch is far outside {self.name}'s range: nominal {self.Mb_kg:g} kg, "
                f"{lo * self.Mb_kg:.3g}-{min(hi * self.Mb_kg, self.capacity_kg):.3g} kg accepted "
                f"(the drum holds {self.capacity_kg:.3g} kg of green beans)"
            )

    @property
    def bed_depth_m(self) -> float:
        """Depth of the bean bed at rest in the drum [m]: the height h of the circular segment of
        the drum's cross-section whose area is the fill fraction (segment angle t with
        (t - sin t) / (2 pi) = fill, h = D/2 (1 - cos(t/2))); the drum diameter if overfilled.

        Not in the paper; it sets how much of the bean probe the beans cover (probe-immersion
        extension of eq. 17, :func:`roastlab.model.rhs.probe_coverage`), so a smaller batch in
        the same drum leaves more of the probe in the gas.

        >>> p = as_plant("120kg")
        >>> round(p.bed_depth_m / p.Dch_m, 3)   # 120 kg in a 1.1 m x 1.5 m drum (fill ~ 12 %)
        0.167
        """
        if self.fill_fraction >= 1.0:
            return self.Dch_m
        return self.Dch_m / 2.0 * (1.0 - math.cos(self.bed_angle_rad / 2.0))

    @functools.cached_property
    def bed_angle_rad(self) -> float:
        """Central angle t [rad] of the circular segment the bed at rest fills in the drum's
        cross-section: (t - sin t) / (2 pi) = fill fraction (the segment's area over the disc's);
        2 pi when overfilled. Not in the paper; the bed geometry of :mod:`roastlab.model.bed`.
        Solved once per plant (the bed depth and the wetted wall both read it at packing)."""
        from scipy.optimize import brentq

        fill = self.fill_fraction
        if fill >= 1.0:
            return 2.0 * math.pi
        # (t - sin t) / (2 pi) rises monotonically from 0 to 1 on [0, 2 pi]: one root
        return brentq(lambda a: (a - math.sin(a)) / (2.0 * math.pi) - fill, 0.0, 2.0 * math.pi, xtol=1e-14, rtol=1e-15)

    @property
    def wall_contact_area_m2(self) -> float:
        """Drum metal the bed at rest wets [m^2]: the segment's arc (D/2) t along the drum length
        plus the segment on each end disc, (D/2) t L + 2 (D^2/8)(t - sin t).

        Not in the paper (its metal-bean area is Pbm Ab, proportional to the mass); the
        ``contact = "wall"`` law of :mod:`roastlab.model.bed`. It grows more slowly than the
        mass (as the fill to the power ~2/3 for a shallow bed) and is the whole drum when full.

        >>> p = Plant("half", 1.0, 1.0, 1.0, 0.1, 0.1, 10.0)   # a 1 m drum
        >>> q = Plant("half", p.capacity_kg / 2, 1.0, 1.0, 0.1, 0.1, 10.0)   # filled half way
        >>> round(q.bed_angle_rad / math.pi, 6), round(q.wall_contact_area_m2 / (math.pi / 2 + math.pi / 4), 6)
        (1.0, 1.0)
        """
        t = self.bed_angle_rad
        return self.Dch_m / 2.0 * t * self.Lch_m + 2.0 * self.Dch_m**2 / 8.0 * (t - math.sin(t))

    @property
    def bed_surface_area_m2(self) -> float:
        """The bed's free surface [m^2]: the chord of its circular segment, D sin(t/2), along the
        drum length (0 when overfilled: the beans then touch the wall all round).

        Not in the paper; the surface the drum wall radiates to (:func:`roastlab.model.rhs.wall_radiation_kW`).
        A tumbling bed tilts it without changing its chord. It grows more slowly than the mass (as the
        fill to the power ~1/3 for a shallow bed) and is the drum's diametral plane when half full.

        >>> q = Plant("half", 1.0, 1.0, 1.0, 0.1, 0.1, 10.0)   # a 1 m drum ...
        >>> q = Plant("half", q.capacity_kg / 2, 1.0, 1.0, 0.1, 0.1, 10.0)   # ... filled half way
        >>> round(q.bed_surface_area_m2, 9)   # its diameter times its length
        1.0
        """
        return self.Dch_m * math.sin(self.bed_angle_rad / 2.0) * self.Lch_m

    @property
    def Ab_m2(self) -> float:
        """Total bean surface, (Mb/mb) * pi * Db^2 [m^2] (section 3.1)."""
        return self.Mb_kg / self.process.mb * math.pi * self.process.Db**2

    def Agb_m2(self, Pbm: float) -> float:
        """Gas-to-bean area Ab (1 - Pbm) [m^2] (section 3.1)."""
        return bean_areas_m2(self.Ab_m2, Pbm)[0]

    def Abm_m2(self, Pbm: float) -> float:
        """Metal-to-bean area Ab Pbm [m^2] (section 3.1)."""
        return bean_areas_m2(self.Ab_m2, Pbm)[1]

    def Mbd_kg(self, X0: float) -> float:
        """Dry batch mass Mb / (1 + X0) [kg] at initial moisture ``X0`` [kg/kg] (section 3.6)."""
        return dry_mass_kg(self.Mb_kg, X0)

    def F(self, hgm: float, Pbm: float, X: float) -> float:
        """F = hgm Agm / (he(X) Agb(Pbm)) [-] (eq. 6) for ``hgm`` [kW/(m2 K)], ``Pbm`` [-], moisture ``X``."""
        he = bean_heat_transfer_coefficient_kW_m2K(X)
        return conductance_ratio_F(hgm, self.Agm_m2, he, self.Agb_m2(Pbm))

    def geometry(self) -> dict[str, float]:
        return {key: float(getattr(self, key)) for key in GEOMETRY_KEYS}

    def describe(self, hgm: float, hbm: float, Pbm: float, X0: float = 0.1) -> list[tuple[str, float, str, str]]:
        """Rows (symbol, value, unit, meaning) of geometry and derived quantities.

        F uses ``hgm``, ``Pbm`` and moisture ``X0``; ``hbm`` is accepted for symmetry with theta.
        """
        rows = []
        for key in GEOMETRY_KEYS:
            symbol, unit = key.rsplit("_", 1)
            rows.append((symbol, float(getattr(self, key)), unit, _GEOMETRY_DOC[key].split(" [")[0]))
        rows += [
            ("Agm", self.Agm_m2, "m2", "gas-metal area, eq. 7"),
            ("Ashell", self.Ashell_m2, "m2", "outer drum surface (shell-loss extension)"),
            ("h_bed", self.bed_depth_m, "m", "bean-bed depth at rest (probe-immersion extension)"),
            ("A_wall", self.wall_contact_area_m2, "m2", "drum wall the bed at rest wets (bed law contact=wall)"),
            ("A_surf", self.bed_surface_area_m2, "m2", "the bed's free surface (wall-radiation extension)"),
            ("Ab", self.Ab_m2, "m2", "total bean area"),
            ("Agb", self.Agb_m2(Pbm), "m2", f"gas-bean area at Pbm={Pbm:g}"),
            ("Abm", self.Abm_m2(Pbm), "m2", f"metal-bean area at Pbm={Pbm:g}"),
            ("Mbd", self.Mbd_kg(X0), "kg", f"dry batch mass at X0={X0:g}"),
            ("F", self.F(hgm, Pbm, X0), "-", f"eq. 6 at hgm={hgm:g}, X={X0:g}"),
            ("Mm*cm", self.Mm_kg * self.process.cm, "kJ/K", "metal heat capacity"),
        ]
        return rows


def plant_from_mapping(data: dict, source: str | Path, default_name: str) -> Plant:
    """Build a :class:`Plant` from a parsed TOML mapping, naming ``source`` in errors."""
    missing = [k for k in GEOMETRY_KEYS if k not in data]
    if missing:
        raise InputError(f"missing key(s) {', '.join(missing)} (a plant needs {', '.join(GEOMETRY_KEYS)})", source)
    allowed = set(GEOMETRY_KEYS) | {"name", "process", "description", "source", "sources", "notes"}
    unknown = sorted(set(data) - allowed)
    if unknown:
        raise InputError(f"unknown key(s) {', '.join(unknown)}", source)
    process_table = data.get("process", {})
    if not isinstance(process_table, dict):
        raise InputError("[process] must be a table", source)
    process = ProcessConstants.from_mapping(process_table, str(source))
    name = data.get("name", default_name)
    if not isinstance(name, str):
        raise InputError(f"name must be a string, got {name!r}", source, "name")
    geometry = {}
    for key in GEOMETRY_KEYS:
        geometry[key] = check_value(key, data[key], source)
    return Plant(name=name, process=process, **geometry)


def as_plant(spec: str | Plant) -> Plant:
    """A :class:`Plant` or a preset name (``"120kg"``, ``"360kg"``) as a Plant.

    Plant files are user input and are read through :func:`roastlab.io.plants.load_plant`.
    """
    if isinstance(spec, Plant):
        return spec
    text = str(spec)
    if text in _preset_names():
        return _load_preset(text)  # presets are immutable data: parse once per process
    raise InputError(f"unknown plant preset (presets: {', '.join(preset_names())}; or give a PLANT.toml path)", text)
