"""Model selection by evidence: fit several model variants on the same logs and cross-validate them
by batch size (issue 25; ``roastlab compare-models``).

For each variant (a set of bed laws, :mod:`roastlab.model.bed`) :func:`compare_models` reports

* on the fit set (every log): the summed weighted SSR, the number of residuals n and of free
  parameters k, AIC and BIC (the one rule of :mod:`roastlab.fit.uncertainty`), the parameters a
  bound holds, and the mean probe FIT;
* **leave-one-size-out** cross-validation: the logs are grouped by green weight (each weight
  rounded to a step, default a tenth of the median batch); for each group, the variant is fitted
  on every other group and predicts that one with nothing refitted. The figure of merit is the
  mean over groups of the group's mean probe FIT (each batch size counts once), with each
  group's figure beside it.

The variant to prefer is the one that predicts the sizes it never saw best (the highest
cross-validated FIT), not the one that fits best: more freedom always fits the fit set better.

``group_by="unit"`` groups the logs by the roaster that recorded them instead (``Batch.unit``,
RoasTime's serial number): **leave-one-roaster-out**, each drum predicted by a model fitted on the
other drums of the make, the cross-machine test of the same claim. ``group_by="log"`` makes each log
its own group: **leave-one-log-out**, each roast predicted by a model fitted on all the others, the
test of how well a new roast of the sizes and drums already seen is predicted.

Every held-out group is also scored against the prediction band of the model fitted without it
(:func:`roastlab.evaluate.bands.band_coverage`, level :data:`~roastlab.evaluate.bands.BAND_LEVEL`):
the share of the held-out measured probe samples inside the band is its **cross-validated
calibration**, about the level when the band is honest for the groups left out (a band measured
on the other logs of one drum and size says nothing of another drum or size, so it is expected to
hold fewer of those).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import InputError, ParameterError
from ..evaluate.bands import BAND_LEVEL, band_coverage, share_inside, stored_spread, why_no_band
from ..evaluate.metrics import size_labels
from ..io.batch import first_of_each_roast
from ..model.bed import LAWS, VARIANTS, BedLaws
from ..model.limits import check_value
from ..model.parameters import FREE_NAMES, N_STARTS, FreeParameter
from ..report.result import Result, aligned


def size_groups(batches, step_kg: float | None = None) -> tuple[list[str], float]:
    """A size-group label per batch and the step used (:func:`roastlab.evaluate.metrics.size_labels`
    of their green weights); a batch without a weight is an :class:`~roastlab.errors.InputError`."""
    masses = []
    for b in batches:
        m = getattr(b, "Mb_kg", None)
        if not m or not math.isfinite(m):
            raise InputError(
                "no green weight: a leave-one-size-out comparison groups logs by their batch mass", b.source or b.name
            )
        masses.append(float(m))
    try:
        return size_labels(masses, step_kg)
    except ValueError as exc:
        raise InputError(str(exc), "command line") from None


#: How compare-models may group the logs: by green weight, by the roaster that recorded them, or each log alone.
GROUPINGS = ("size", "unit", "log")
#: Each grouping's words: the cross-validation's name, what one group is (singular, plural, as the
#: others the fit used), and what it needs at least.
_GROUP_WORDS = {
    "size": {
        "cv": "leave-one-size-out",
        "kind": "batch size",
        "kinds": "sizes",
        "other": "size",
        "need": "two batch sizes",
    },
    "unit": {
        "cv": "leave-one-roaster-out",
        "kind": "roaster",
        "kinds": "roasters",
        "other": "roaster of the make",
        "need": "logs of two roasters",
    },
    "log": {
        "cv": "leave-one-log-out",
        "kind": "log",
        "kinds": "logs",
        "other": "log",
        "need": "two logs",
    },
}


def unit_groups(batches) -> list[str]:
    """A group label per batch, ``"unit 2779"``, from the roaster that recorded it (``Batch.unit``);
    a batch whose log names no roaster is an :class:`~roastlab.errors.InputError`."""
    labels = []
    for b in batches:
        u = str(getattr(b, "unit", "") or "")
        if not u:
            raise InputError(
                "the log names no roaster (RoasTime's serialNumber): leave-one-roaster-out groups logs by it",
                b.source or b.name,
            )
        labels.append(f"unit {u}")
    return labels


def log_groups(batches) -> list[str]:
    """A group label per batch, its own name (``#2``, ``#3``, ... added to repeated names): every
    log a group of one, for leave-one-log-out."""
    seen: dict[str, int] = {}
    labels = []
    for b in batches:
        seen[b.name] = seen.get(b.name, 0) + 1
        labels.append(b.name if seen[b.name] == 1 else f"{b.name} #{seen[b.name]}")
    return labels


#: The summary gives each held-out group a column up to this many groups, else a table of its own.
MAX_GROUP_COLUMNS = 10

#: The value of a variant's parameter override that frees it within its quantity-table bounds.
FREE = "free"


@dataclass(frozen=True)
class Variant:
    """One model variant: bed laws and, optionally, parameters held at a value or freed.

    ``overrides`` are ``(name, value)`` pairs over the fit spec: a number holds the parameter at
    that value (it leaves ``[free]``), ``"free"`` frees it within the fit bounds of the quantity
    table (:mod:`roastlab.model.quantities`), started at their middle. A parameter that only a
    change of batch size can determine (the probe's depth scale ``h_probe_m``) is chosen this way:
    a profile of fixed values, each cross-validated by batch size.
    """

    laws: BedLaws
    overrides: tuple = ()

    @property
    def name(self) -> str:
        parts = [self.laws.name] + [f"{k}={v if v == FREE else format(v, 'g')}" for k, v in self.overrides]
        return ",".join(parts)

    @classmethod
    def parse(cls, value) -> Variant:
        """A Variant from itself, BedLaws or text ``"contact=wall,probe=tumbling,h_probe_m=0.2"``
        (bed options and parameter overrides in one list; ``"paper"`` alone is the paper's bed)."""
        if isinstance(value, Variant):
            return value
        if value is None or isinstance(value, (BedLaws, dict)):
            return cls(BedLaws.parse(value))
        if not isinstance(value, str):
            raise ParameterError(f"a model variant must be text like 'probe=tumbling,h_probe_m=0.2', got {value!r}")
        laws, overrides = [], []
        for part in (p.strip() for p in value.split(",")):
            key, _sep, val = (s.strip() for s in part.partition("="))
            if key in FREE_NAMES:
                if val == FREE:
                    overrides.append((key, FREE))
                    continue
                try:
                    number = float(val)
                except ValueError:
                    number = math.nan
                if not math.isfinite(number):
                    raise ParameterError(f"model variant: {part!r} needs a number or '{FREE}' (e.g. {key}=0.2)")
                overrides.append((key, check_value(key, number)))
            elif key in LAWS or part == "paper":
                laws.append(part)
            else:
                raise ParameterError(
                    f"model variant: {part!r} is neither a bed option ({', '.join(LAWS)}) nor a parameter "
                    f"(e.g. h_probe_m=0.2 or h_probe_m={FREE})"
                )
        return cls(BedLaws.parse(",".join(laws)), tuple(overrides))

    def spec(self, base):
        """The fit spec of this variant: ``base`` (a FitSpec, or None for the default free parameters)
        with the overrides applied; ``base`` itself when there are none."""
        if not self.overrides:
            return base
        from ..fit.identify import build_free_parameters
        from ..io.fitspec import FitSpec
        from ..model.quantities import quantity

        if base is None:
            base = FitSpec(*build_free_parameters())
        free, fixed = list(base.free), dict(base.fixed)
        for name, value in self.overrides:
            free = [f for f in free if f.name != name]
            fixed.pop(name, None)
            if value == FREE:
                lo, hi = quantity(name).bounds
                free.append(FreeParameter(name, lo, hi, 0.5 * (lo + hi)))
            else:
                fixed[name] = float(value)
        if not free:
            raise ParameterError(f"model variant {self.name}: nothing left to fit")
        return replace(base, free=free, fixed=fixed)


@dataclass
class VariantScore:
    """One variant's figures (see the module docstring)."""

    name: str
    laws: BedLaws
    overrides: dict
    ssr: float
    n_residuals: int
    k_free: int
    aic: float
    bic: float
    on_bound: list[str]
    fit_FIT: float
    cv_FIT: float
    cv_by_group: dict[str, float]
    cv_by_batch: dict[str, float] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    #: cross-validated calibration: the share of held-out measured probe samples inside the band of
    #: the model fitted without them (NaN where that model carries no band), overall and per group
    cv_band_inside: float = math.nan
    cv_band_by_group: dict[str, float] = field(default_factory=dict)
    #: the median over the held-out logs of each log's median band width [degC]
    cv_band_width_C: float = math.nan
    #: held-out groups whose fit had one log: no roast-to-roast spread, a band of the parameters alone
    cv_band_parameters_only: list[str] = field(default_factory=list)


@dataclass
class ModelComparison(Result):
    """What :func:`compare_models` returns: one :class:`VariantScore` per variant, best first by
    cross-validated FIT."""

    scores: list[VariantScore]
    groups: dict[str, list[str]]
    step_kg: float | None
    group_by: str = "size"
    left_out: dict = field(default_factory=dict)  # {log: why}: copies of a roast given twice

    @property
    def best(self) -> VariantScore:
        """The variant with the highest cross-validated FIT."""
        return max(self.scores, key=lambda s: s.cv_FIT)

    @property
    def cv_name(self) -> str:
        """``"leave-one-size-out"`` or ``"leave-one-roaster-out"``."""
        return _GROUP_WORDS[self.group_by]["cv"]

    @property
    def cv_short(self) -> str:
        """``"LOSO"`` or ``"LORO"``: the cross-validation's initials, for table columns and JSON keys."""
        return "".join(w[0] for w in self.cv_name.split("-")).upper()

    def cv_difference(self, a: VariantScore, b: VariantScore) -> tuple[float, float]:
        """How much better ``a`` predicts the held-out groups than ``b``: the mean over groups of the
        paired FIT difference [points] and its standard error (sd / sqrt(groups)), the yardstick of
        the one-standard-error rule of cross-validation (Breiman et al. 1984; Hastie, Tibshirani and
        Friedman, *Elements of Statistical Learning*, 7.10): a difference within one standard error
        does not single out either variant."""
        d = np.array([a.cv_by_group[g] - b.cv_by_group[g] for g in self.groups])
        se = float(np.std(d, ddof=1) / np.sqrt(d.size)) if d.size > 1 else float("nan")
        return float(d.mean()), se

    def to_frame(self):
        import pandas as pd

        rows = []
        for s in self.scores:
            rows.append(
                {
                    "variant": s.name,
                    "k": s.k_free,
                    "SSR": s.ssr,
                    "AIC": s.aic,
                    "BIC": s.bic,
                    "on bound": len(s.on_bound),
                    "fit FIT %": s.fit_FIT,
                    f"{self.cv_short} FIT %": s.cv_FIT,
                    f"{self.cv_short} band inside %": 100.0 * s.cv_band_inside,
                    **{f"{g} %": v for g, v in s.cv_by_group.items()},
                }
            )
        return pd.DataFrame(rows).set_index("variant")

    def summary(self) -> str:
        groups = list(self.groups)
        words = _GROUP_WORDS[self.group_by]
        step = f" (step {self.step_kg:.3g} kg)" if self.step_kg is not None else ""
        head = (
            f"{len(self.scores)} variant(s) on {sum(len(v) for v in self.groups.values())} log(s) in "
            f"{len(groups)} {words['kinds']}{step}; probe FIT %"
        )
        wide = len(groups) <= MAX_GROUP_COLUMNS  # few groups: one column each; many: a table of their own
        cols = ["variant", "k", "SSR °C²", "AIC", "BIC", "on bound", "fit FIT", f"{self.cv_short} FIT",
                f"{self.cv_short} band in", *(groups if wide else ())]  # fmt: skip
        table = [cols]
        for s in self.scores:
            table.append(
                [
                    s.name,
                    str(s.k_free),
                    f"{s.ssr:.4g}",
                    f"{s.aic:.1f}",
                    f"{s.bic:.1f}",
                    str(len(s.on_bound)),
                    f"{s.fit_FIT:.1f}",
                    f"{s.cv_FIT:.1f}",
                    _percent(s.cv_band_inside),
                    *(f"{s.cv_by_group[g]:.1f}" for g in (groups if wide else ())),
                ]
            )
        lines = [head, "", *aligned(table)]
        if not wide:
            one = len(self.scores) == 1
            by_group = [[f"held-out {words['kind']}", *(h if one else f"{s.name}: {h}" for s in self.scores
                                                        for h in ("FIT", "band in"))]]  # fmt: skip
            for g in groups:
                by_group.append([g, *(v for s in self.scores for v in (f"{s.cv_by_group[g]:.1f}",
                                                                       _percent(s.cv_band_by_group.get(g, math.nan))))])  # fmt: skip
            lines += ["", *aligned(by_group)]
        lines.append(
            f"{self.cv_short} band in: the share of the held-out logs' measured probe samples inside the "
            f"{_percent(BAND_LEVEL)} band of the model fitted without them (about {_percent(BAND_LEVEL)} when the band is honest)"
        )
        best = self.best
        by_aic = min(self.scores, key=lambda s: s.aic)
        lines += ["", f"best by {self.cv_name} FIT: {best.name} ({best.cv_FIT:.1f} %)"]
        unseen = words["kinds"]
        if by_aic is not best:
            diff, se = self.cv_difference(best, by_aic)
            by = f"{diff:.1f} ± {se:.1f} points over {len(groups)} groups"
            if diff > se:
                lines.append(
                    f"lowest AIC: {by_aic.name} (fits the logs best, predicts unseen {unseen} worse by {by}: "
                    f"prefer {best.name})"
                )
            else:
                lines.append(
                    f"lowest AIC: {by_aic.name} (fits the logs best; on unseen {unseen} within one standard error "
                    f"of {best.name}, {by}: cross-validation does not tell the two apart)"
                )
        for s in self.scores:
            if s.on_bound:
                lines.append(f"{s.name}: on a bound: {', '.join(s.on_bound)}")
            if s.cv_band_parameters_only:
                lines.append(
                    f"{s.name}: without {', '.join(s.cv_band_parameters_only)} the fit had one log, so its band is the "
                    "parameters' alone (no spread between roasts) and holds few of the held-out samples"
                )
        lines += [f"left out: {why}" for why in self.left_out.values()]
        return "\n".join(lines)

    def to_json_dict(self) -> dict:
        key = self.cv_short.lower()  # loso_FIT (by size, as before) or loro_FIT (by roaster)
        return {
            "group_by": self.group_by,
            "step_kg": self.step_kg,
            "groups": self.groups,
            "left_out": self.left_out,
            "best": self.best.name,
            "variants": [
                {
                    "name": s.name,
                    "bed": s.laws.as_dict(),
                    "overrides": dict(s.overrides),
                    "SSR": s.ssr,
                    "n_residuals": s.n_residuals,
                    "k_free": s.k_free,
                    "AIC": s.aic,
                    "BIC": s.bic,
                    "on_bound": s.on_bound,
                    "fit_FIT": s.fit_FIT,
                    f"{key}_FIT": s.cv_FIT,
                    f"{key}_FIT_by_group": s.cv_by_group,
                    f"{key}_FIT_by_batch": s.cv_by_batch,
                    f"{key}_band_inside": s.cv_band_inside,  # NaN (no band) becomes null where written
                    f"{key}_band_inside_by_group": s.cv_band_by_group,
                    f"{key}_band_median_width_C": s.cv_band_width_C,
                    f"{key}_band_parameters_only": s.cv_band_parameters_only,
                    "band_level": BAND_LEVEL,
                    "warnings": s.warnings,
                }
                for s in self.scores
            ],
        }

    def _draw(self, ax, band_ax=None) -> None:
        """Each held-out group's FIT per variant on ``ax``; on ``band_ax`` (if given) the share of its
        samples inside the band, against the band's level."""
        groups = list(self.groups)
        x = np.arange(len(groups))
        width = 0.8 / max(len(self.scores), 1)
        colours = variant_colours(len(self.scores))
        for i, s in enumerate(self.scores):
            at = x + (i - (len(self.scores) - 1) / 2) * width
            # the legend: the variant's mean FIT and (with the band panel) its share of all held-out samples in the band
            in_band = f"; {_percent(s.cv_band_inside)} in the band" if band_ax is not None else ""
            label = f"{s.name} ({s.cv_FIT:.1f} %{in_band})"
            ax.bar(at, [s.cv_by_group[g] for g in groups], width, label=label, color=colours[i])
            if band_ax is not None:
                inside = [100.0 * s.cv_band_by_group.get(g, math.nan) for g in groups]
                band_ax.bar(at, inside, width, color=colours[i])
        words = _GROUP_WORDS[self.group_by]
        ax.set_ylabel("probe FIT [%]")
        ax.set_ylim(max(min(0.0, ax.get_ylim()[0]), -50.0), 100.0)
        ax.axhline(0.0, color="0.5", lw=0.6)
        ax.grid(axis="y", alpha=0.3)
        bottom = ax
        if band_ax is not None:
            band_ax.axhline(100.0 * BAND_LEVEL, color="0.2", lw=1.0, ls="--")
            band_ax.annotate(f"level {_percent(BAND_LEVEL)}", (1.0, 100.0 * BAND_LEVEL), xycoords=("axes fraction", "data"),
                             xytext=(3, 0), textcoords="offset points", va="center", fontsize=8)  # fmt: skip
            band_ax.set_ylim(0.0, 100.0)
            band_ax.set_ylabel(f"inside the {_percent(BAND_LEVEL)} band [%]")
            band_ax.grid(axis="y", alpha=0.3)
            ax.tick_params(labelbottom=False)
            bottom = band_ax
        long = max(map(len, groups)) > 12  # log names: slanted, to stay readable
        bottom.set_xticks(
            x, groups, rotation=35 if long else 0, ha="right" if long else "center", fontsize=7 if long else None
        )
        bottom.set_xlabel(f"held-out {words['kind']} (fitted on every other {words['other']})")
        handles, labels = ax.get_legend_handles_labels()
        legend = {"fontsize": 8, "ncol": 2, "frameon": False, "title": "variant (mean FIT over held-out groups"
                  + ("; share of all held-out samples in the band)" if band_ax is not None else ")"),
                  "title_fontsize": 8}  # fmt: skip
        if ax.figure.get_layout_engine() is not None:  # below everything, however tall the slanted names
            ax.figure.legend(handles, labels, loc="outside lower center", **legend)
        else:
            bottom.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, -0.16), **legend)

    def _figure(self, path, outputs, title=None):
        from ..report.figures import finish_figure, new_figure

        fig = new_figure(figsize=(9, 7.5), layout="constrained")
        ax, band_ax = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 2]})
        self._draw(ax, band_ax)
        kind = _GROUP_WORDS[self.group_by]["kind"]
        title = title or f"{self.cv_name.capitalize()}: each {kind} predicted by a model fitted on the others"
        return finish_figure(fig, path, title, outputs)


def variant_colours(n: int) -> list:
    """One colour per variant, all different: matplotlib's ten-colour cycle up to ten variants (as
    any other figure), its twenty-colour map up to twenty, an even spread of a perceptual map beyond
    (the ten-colour cycle repeats from the eleventh, which made two variants one colour)."""
    from matplotlib import colormaps

    if n <= 10:
        return [colormaps["tab10"](i) for i in range(n)]
    if n <= 20:
        return [colormaps["tab20"](i) for i in range(n)]
    return [colormaps["turbo"](v) for v in np.linspace(0.05, 0.95, n)]


def _percent(share: float) -> str:
    """A share as ``"87 %"`` for the summary table, ``"-"`` when there is none (NaN)."""
    return f"{100.0 * share:.0f} %" if math.isfinite(share) else "-"


def compare_models(
    batches,
    plant,
    spec=None,
    variants=None,
    *,
    column_map=None,
    step_kg: float | None = None,
    group_by: str = "size",
    seed: int = 0,
    starts: int = N_STARTS,
    progress=None,
) -> ModelComparison:
    """Fit each variant on ``batches`` and cross-validate it leaving one batch size (or one roaster) out.

    A log that is a copy of another (the same recording start: :func:`roastlab.io.batch.first_of_each_roast`)
    is left out and said (``ModelComparison.left_out``): fitted in one copy and held out in the other,
    a roast would score the model on itself.

    Parameters
    ----------
    batches : list of Batch (each with its green weight ``Mb_kg``)
    plant, spec, column_map, seed, starts : as :func:`roastlab.workflows.fitting.fit`
    variants : {name: BedLaws, Variant or its text} or a list of them (:class:`Variant`: bed laws
        and parameter overrides such as ``h_probe_m=0.2``); default :data:`roastlab.model.bed.VARIANTS`
    step_kg : the group step (default :data:`roastlab.evaluate.metrics.GROUP_STEP_SHARE` of the median green weight)
    group_by : ``"size"`` (by green weight), ``"unit"`` (by the roaster that recorded each log,
        :func:`unit_groups`: leave-one-roaster-out) or ``"log"`` (each log alone, :func:`log_groups`:
        leave-one-log-out)
    progress : callable ``progress(done, total, text)``
    """
    from ..io.fitspec import FitSpec, load_fit_spec
    from .fitting import fit

    if variants is None:
        variants = VARIANTS
    if isinstance(variants, dict):
        variants = {name: Variant.parse(v) for name, v in variants.items()}
    else:
        variants = {v.name: v for v in map(Variant.parse, variants)}
    base = spec if spec is None or isinstance(spec, FitSpec) else load_fit_spec(spec)
    if not variants:
        raise InputError("no model variants to compare", "command line")
    if group_by not in GROUPINGS:
        raise InputError(f"group logs by one of {', '.join(GROUPINGS)}, got {group_by!r}", "command line")
    # a roast given twice would be fitted in one copy and held out in the other
    batches, left_out = first_of_each_roast(list(batches), lambda b: b.started_epoch_s, lambda b: b.name)
    if group_by == "size":
        labels, step = size_groups(batches, step_kg)
        order = sorted(set(labels), key=lambda g: float(g.split()[0].split("-")[0]))
    elif group_by == "unit":
        labels, step = unit_groups(batches), None
        order = sorted(set(labels))
    else:
        labels, step = log_groups(batches), None
        order = list(labels)
    if len(order) < 2:
        words = _GROUP_WORDS[group_by]
        raise InputError(
            f"every log is in one group ({order[0]}): {words['cv']} needs at least {words['need']}",
            batches[0].source or batches[0].name,
        )
    groups = {g: [b.name for b, lab in zip(batches, labels) if lab == g] for g in order}
    total, done = len(variants) * (1 + len(order)), 0
    scores = []
    for name, variant in variants.items():
        laws, spec = variant.laws, variant.spec(base)
        if progress:
            progress(done, total, f"{name}: all logs")
        full = fit(batches, plant, spec, column_map=column_map, seed=seed, starts=starts, bed=laws)
        done += 1
        ident = full.identification
        u = ident.uncertainty
        on_bound = [n for n, b in zip(u.names, u.on_bound) if b] if u is not None else []
        by_group, by_batch, band_by_group, band_rows, no_spread = {}, {}, {}, [], []
        for g in order:
            if progress:
                progress(done, total, f"{name}: without {g}")
            train = [b for b, lab in zip(batches, labels) if lab != g]
            test = [b for b, lab in zip(batches, labels) if lab == g]
            model = fit(train, plant, spec, column_map=column_map, seed=seed, starts=starts, bed=laws).model
            v = model.validate(test)
            by_group[g] = float(v.average["FIT"])
            by_batch.update({n: float(r["FIT"]) for n, r in zip(v.names, v.rows)})
            if why_no_band(model) is None:
                rows = band_coverage(model, test)
                band_rows += rows
                band_by_group[g] = share_inside(rows)
                if not stored_spread(model):
                    no_spread.append(g)
            else:
                band_by_group[g] = math.nan
            done += 1
        scores.append(
            VariantScore(
                name=name,
                laws=laws,
                overrides=dict(variant.overrides),
                ssr=float(ident.SSR),
                n_residuals=int(ident.n_residuals),
                k_free=int(u.k_free) if u is not None else len(ident.values),
                aic=float(ident.aic),
                bic=float(ident.bic),
                on_bound=on_bound,
                fit_FIT=float(full.validation.average["FIT"]),
                cv_FIT=float(np.mean(list(by_group.values()))),
                cv_by_group=by_group,
                cv_by_batch=by_batch,
                warnings=list(ident.warnings),
                cv_band_inside=share_inside(band_rows) if band_rows else math.nan,
                cv_band_by_group=band_by_group,
                cv_band_width_C=float(np.median([r["median_width_C"] for r in band_rows])) if band_rows else math.nan,
                cv_band_parameters_only=no_spread,
            )
        )
    if progress:
        progress(total, total, "done")
    scores.sort(key=lambda s: -s.cv_FIT)
    return ModelComparison(scores, groups, step, group_by, left_out)


__all__ = [
    "FREE",
    "GROUPINGS",
    "ModelComparison",
    "Variant",
    "VariantScore",
    "compare_models",
    "log_groups",
    "size_groups",
    "unit_groups",
]
