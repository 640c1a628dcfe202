"""Named laws of the bean bed in the drum: how the batch meets the metal, the gas and the probe.

The paper (section 3.1, eqs. 7-11, 17) scales every bean area with the batch mass and keeps the
probe in the beans. These options replace one law each by one that follows from the drum's
geometry and a bed in motion; the default of every option is the paper's (or, for the probe, the
earlier probe-immersion extension whose ``h_probe_m = 0`` is the paper), bit for bit:

``contact``
    ``"paper"``: Abm = Pbm Ab, Agb = (1 - Pbm) Ab (section 3.1: both areas grow with the mass).
    ``"wall"``: the beans touch the metal where the bed wets the drum: Abm = Pbm A_wall with
    A_wall the wetted arc of the bed's circular segment times the drum length plus the two
    end-disc segments (:attr:`roastlab.model.plant.Plant.wall_contact_area_m2`), Pbm then the
    share of that wall area in bean contact; every other bean surface meets the gas,
    Agb = Ab - Abm. A deeper bed wets less wall per kilogram, so the metal's share of the
    heat per kilogram falls with the batch, and a tumbling bed exposes nearly all its beans to
    the air drawn through it.
``probe``
    ``"rest"``: the probe's covered share is the depth of the bed at rest over the covering
    depth, c = min(1, h_bed / h_probe) (the probe-immersion extension of eq. 17).
    ``"tumbling"``: c = 1 - exp(-h_bed / h_probe). In a turning drum the probe is covered by a
    moving bed and by the beans the vanes shower over it, not by a still surface; the share of
    a surface left bare by grains laid at random (a Boolean / Poisson coverage model) is
    exp(-n a), n a the grains' projected area per unit surface, which grows in proportion to
    the bed depth. ``h_probe`` is then the e-folding depth: a shallow bed already covers part
    of the probe, a deep one never quite all of it.
``probe_gas``
    ``"outlet"``: the uncovered probe sees the gas at the outlet temperature Tgo (eq. 15e).
    ``"mean"``: it sees the gas's mean temperature along its path through the bed: the gas
    cools from Tgi towards T* as exp(-NTU s) over the path s in [0, 1] (the exchanger of eq.
    15e), whose mean is T* + (Tgi - T*)(1 - exp(-NTU))/NTU = T* + (Tgi - Tgo)/NTU. It is the
    outlet temperature when the gas meets no beans (NTU large) and the inlet's when it meets
    few (NTU -> 0).

>>> BedLaws.parse("contact=wall, probe=tumbling").name
'contact=wall,probe=tumbling'
>>> BedLaws.parse("paper") == PAPER_BED
True
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from ..errors import ParameterError

#: Each option's allowed laws, the first the default (the paper's model).
LAWS: dict[str, tuple[str, ...]] = {
    "contact": ("paper", "wall"),
    "probe": ("rest", "tumbling"),
    "probe_gas": ("outlet", "mean"),
}


@dataclass(frozen=True)
class BedLaws:
    """One choice per option of :data:`LAWS` (see the module docstring)."""

    contact: str = "paper"
    probe: str = "rest"
    probe_gas: str = "outlet"

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if value not in LAWS[f.name]:
                raise ParameterError(f"unknown {f.name} law {value!r} (allowed: {', '.join(LAWS[f.name])})")

    @property
    def name(self) -> str:
        """``"paper"`` or the options that differ from it, ``"contact=wall,probe=tumbling"``."""
        return ",".join(f"{k}={v}" for k, v in self.changed().items()) or "paper"

    def changed(self) -> dict[str, str]:
        """The options whose law is not the default (the paper's), ``{"probe": "tumbling"}``."""
        return {k: v for k, v in self.as_dict().items() if v != LAWS[k][0]}

    def as_dict(self) -> dict[str, str]:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def codes(self) -> dict[str, float]:
        """The parameter-vector entries of these laws: each law's index in :data:`LAWS` (0 = default)."""
        return {f"{k}_law": float(LAWS[k].index(v)) for k, v in self.as_dict().items()}

    @classmethod
    def parse(cls, value) -> BedLaws:
        """A BedLaws from itself, None (the paper), a mapping or text ``"paper"`` / ``"contact=wall,probe=tumbling"``."""
        if value is None or isinstance(value, BedLaws):
            return value or PAPER_BED
        if isinstance(value, dict):
            unknown = sorted(set(value) - set(LAWS))
            if unknown:
                raise ParameterError(f"unknown bed option(s) {', '.join(unknown)} (allowed: {', '.join(LAWS)})")
            return cls(**{k: str(v) for k, v in value.items()})
        if not isinstance(value, str):
            raise ParameterError(f"bed laws must be text like 'contact=wall,probe=tumbling', got {value!r}")
        text = value.strip()
        if text in ("", "paper"):
            return PAPER_BED
        pairs = {}
        for part in text.split(","):
            key, sep, law = (s.strip() for s in part.partition("="))
            if not sep or not key or not law:
                raise ParameterError(f"bed laws: {part.strip()!r} is not option=law (e.g. 'probe=tumbling')")
            pairs[key] = law
        return cls.parse(pairs)


#: The paper's bed (and the probe-immersion extension's at-rest probe).
PAPER_BED = BedLaws()

#: The laws leave-one-size-out cross-validation chose on the only multi-size real logs we have (the
#: Aillio Bullet's 27 weighed logs, 200-900 g, docs/real-roaster.md): the probe covered by a
#: tumbling bed, its uncovered part in the bed's mean air, the paper's contact. The Skywalker's 16
#: logs, each predicted by a fit on the others, choose them again (83.8 % against 79.3 % with the
#: paper's probe). Both examples (``examples/*/fit.toml``) and ``roastlab init`` for every roaster use
#: them (a test holds the examples to this value). They only act with the probe-immersion term on.
CROSS_VALIDATED = BedLaws(probe="tumbling", probe_gas="mean")

#: The probe's depth scale ``h_probe_m`` over the drum diameter under :data:`CROSS_VALIDATED`: only a
#: change of batch size determines it, and its leave-one-size-out profile on the Bullet rises to a
#: plateau that starts at the drum's diameter (72.9 % at 0.15 D, 73.4 % at 1 D, 73.5 % at 5 D), so it
#: is held there rather than fitted on one batch size (the Bullet example, ``roastlab init`` where a bean
#: reading runs beside the probe or the logs are of one size). The Skywalker example, and ``roastlab init``
#: on logs like its own (several sizes, the probe alone), fit it from there: 0.17 D (0.026 m) on logs of
#: 150-250 g, leave-one-log-out FIT 84.1 % against 83.8 % at 1 D, with the metal-bean coefficient off its
#: ceiling (docs/real-roaster.md, "Skywalker: the probe half in the bed").
PROBE_DEPTH_OVER_DIAMETER = 1.0

#: The variants ``roastlab compare-models`` fits by default, by name: the paper's bed and each law
#: that follows from the drum, alone and together.
VARIANTS: dict[str, BedLaws] = {
    b.name: b
    for b in (
        PAPER_BED,
        BedLaws(probe="tumbling"),
        BedLaws(contact="wall"),
        CROSS_VALIDATED,
        BedLaws(contact="wall", probe="tumbling", probe_gas="mean"),
    )
}

#: The two heat paths that grow with the bed's surface rather than its mass (:mod:`roastlab.model.rhs`,
#: both off by default), as ``compare-models`` variant settings to add to a set of laws: the wall's
#: radiation to the bed (``eps_rad``) and the gas meeting the beans at the bed's surface
#: (``k_flight``), with Pbm held, because the gas's area then no longer depends on it and hbm and Pbm
#: act only as their product. ``make real-roaster`` cross-validates both beside the example.
SURFACE_HEAT: tuple[str, ...] = ("eps_rad=free", "k_flight=free,Pbm=0.5")
