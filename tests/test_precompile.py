"""``roastlab compile``: the kernels compiled ahead are the ones the commands then call."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from roastlab.cli.main import main
from roastlab.model.bed import BedLaws
from roastlab.workflows import precompile

REPO = Path(__file__).resolve().parents[1]

#: In a fresh interpreter: run every job in-process, note each kernel's compiled signatures, then fit,
#: validate and simulate a population as the commands do, and print the signatures any kernel gained.
AFTER_THE_JOBS = """
import json, importlib, pkgutil
import numpy as np
from numba.core.registry import CPUDispatcher
import roastlab
from roastlab.sim.population import pack_batches, simulate_population
from roastlab.workflows import precompile

def dispatchers():
    found = {}
    for pkg in ("roastlab.sim", "roastlab.fit"):
        for info in pkgutil.iter_modules(importlib.import_module(pkg).__path__):
            m = importlib.import_module(f"{pkg}.{info.name}")
            for name, obj in vars(m).items():
                if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == m.__name__:
                    found[f"{m.__name__}.{name}"] = obj
    return found

# the paper's laws, and the Skywalker example's (its bed laws and its held swelling, a lanes constant)
held = precompile.law_set_of("examples/skywalker/fit.toml")
for job, args in precompile.jobs([precompile.LawSet(), held]):
    job(*args)
before = {k: set(d.overloads) for k, d in dispatchers().items()}
batches = roastlab.read_dataset(roastlab.default_dataset_root() / "dataset-I").batches[:1]
res = roastlab.fit(batches, "120kg", starts=1)
res.model.validate(batches)
roastlab.fit(batches, "120kg", starts=1, bed=held.bed, fix={**dict(held.held), **{k: 0.1 for k in held.on}})
simulate_population(pack_batches(batches, "120kg", roastlab.THETA_PAPER), ["hbm"], np.full((16, 1, 1), 0.03))
roastlab.simulate("120kg", batches[0].time_s, batches[0].Gg_kg_s, batches[0].Tgi_C)
gained = {k: [str(s) for s in set(d.overloads) - before.get(k, set())] for k, d in dispatchers().items()}
print(json.dumps({k: v for k, v in gained.items() if v}))
"""


def test_lanes_once_per_set_of_laws_and_first():
    """The lanes (the longest jobs) come first, once per distinct set of laws, the paper's by default;
    a fit spec's laws are its [bed] section's."""
    bullet = precompile.law_set_of(REPO / "examples" / "bullet" / "fit.toml")
    assert bullet.bed == BedLaws(probe="tumbling", probe_gas="mean")
    todo = precompile.jobs([precompile.LawSet(), bullet, precompile.LawSet(), bullet])
    names = [job.__name__ for job, _ in todo]
    assert names == [
        "job_lanes",
        "job_lanes",
        "job_population",
        "job_sensitivities",
        "job_sensitivities",
        "job_stepper",
    ]
    assert [args for _, args in todo[:2]] == [
        ("paper", "schwartzberg", (), ()),
        ("probe=tumbling,probe_gas=mean", "schwartzberg", (), ("h_probe_m",)),  # its probe's depth held at 0.2 m
    ]
    # the sensitivities once per bed and moisture law (their codes are compiled in), the program's once
    assert [args for _, args in todo[3:5]] == [
        ("paper", "schwartzberg", True),
        ("probe=tumbling,probe_gas=mean", "schwartzberg", False),
    ]
    assert [job.__name__ for job, _ in precompile.jobs()][0] == "job_lanes"
    assert precompile.process_count(5, None) >= 1
    assert precompile.process_count(5, 64) == 5 and precompile.process_count(5, 2) == 2


def test_a_model_files_laws_are_its_bed_and_moisture_law(tmp_path):
    """A model file fitted with the tumbling probe (laws whose lanes ``make test`` compiles first): its
    lanes job is for those laws, after the paper's."""
    import roastlab

    batches = roastlab.read_dataset(roastlab.default_dataset_root() / "dataset-I").batches[:1]
    model = roastlab.fit(batches, "120kg", starts=1, bed="probe=tumbling,probe_gas=mean").model
    laws = precompile.law_set_of(model.save(tmp_path / "model.json"))
    assert laws == precompile.LawSet(BedLaws(probe="tumbling", probe_gas="mean"), "schwartzberg")
    todo = precompile.jobs([precompile.LawSet(), laws])
    assert todo[1] == (precompile.job_lanes, ("probe=tumbling,probe_gas=mean", "schwartzberg", (), ()))


def test_a_held_value_the_lanes_compile_in_is_part_of_the_set_of_laws(tmp_path):
    """A spec's or a model file's held value of a lanes constant (the beans' swelling) that differs from
    the quantity table's default is part of its set of laws, so ``compile`` builds the lanes a fit with
    it calls; a held value equal to the default, or of a parameter the lanes do not compile in, is not."""
    from roastlab.workflows.model import FittedModel

    spec = tmp_path / "fit.toml"
    spec.write_text(
        "[free]\nhbm = [0.001, 0.1, 0.02]\n[fixed]\nbean_swell = 1.0\nheater_exp = 1.0\nhgm = 0.02\n"
        '[bed]\nprobe = "tumbling"\n'
    )
    laws = precompile.law_set_of(spec)
    assert laws == precompile.LawSet(BedLaws(probe="tumbling"), "schwartzberg", (("bean_swell", 1.0),))
    assert laws.name.endswith("bean_swell 1")
    todo = precompile.jobs([precompile.LawSet(), laws, precompile.LawSet(BedLaws(probe="tumbling"))])
    assert [args for _, args in todo[:3]] == [
        ("paper", "schwartzberg", (), ()),
        ("probe=tumbling", "schwartzberg", (("bean_swell", 1.0),), ()),
        ("probe=tumbling", "schwartzberg", (), ()),
    ]
    gas = precompile.LawSet(held=(("heater_exp", 0.5),))  # a gas burner's square root: the scalar integrator
    assert [job.__name__ for job, _ in precompile.jobs([gas])] == ["job_population", "job_sensitivities", "job_stepper"]
    model = FittedModel.paper().with_values(bean_swell=1.0, heater_exp=1.0)
    assert precompile.law_set_of(model.save(tmp_path / "model.json")).held == (("bean_swell", 1.0),)


def test_a_term_a_zero_turns_off_is_on_where_a_spec_frees_or_holds_it_or_a_model_has_it(tmp_path):
    """The lanes compile a 0 in for a term off in every run (roastlab.sim.lanes.OFF_SLOTS), so a set of
    laws says which such terms are on: freed by the spec, held at another value, or not 0 in a model
    file; a term held at its 0 is off. The job runs each one on at the middle of its fit bounds."""
    from roastlab.workflows.model import FittedModel

    spec = tmp_path / "fit.toml"
    spec.write_text(
        "[free]\nhbm = [0.001, 0.1, 0.02]\nh_probe_m = [0.0, 0.5, 0.1]\n[fixed]\neps_rad = 0.8\nk_flight = 0.0\n"
    )
    laws = precompile.law_set_of(spec)
    assert laws == precompile.LawSet(on=("eps_rad", "h_probe_m")) and laws.name.endswith("eps_rad on, h_probe_m on")
    assert precompile.jobs([laws])[0] == (precompile.job_lanes, ("paper", "schwartzberg", (), ("eps_rad", "h_probe_m")))
    model = FittedModel.paper().with_values(k_flight=4.0)
    assert precompile.law_set_of(model.save(tmp_path / "model.json")).on == ("k_flight",)
    assert precompile.law_set_of(FittedModel.paper().save(tmp_path / "paper.json")) == precompile.LawSet()


def test_each_family_of_jobs_keeps_its_processes():
    """Every job runs once whatever the processes; on 2 the lanes of both sets of laws run in one process
    and the scalar kernels in the other, so neither compiles the other family's shared callees."""
    todo = precompile.jobs([precompile.LawSet(), precompile.LawSet(BedLaws(probe="tumbling"))])
    for n in range(1, 9):
        groups = precompile.chains(todo, n)
        assert 1 <= len(groups) <= n
        assert sorted(map(repr, sum(groups, []))) == sorted(map(repr, todo))
    lanes, rest = precompile.chains(todo, 2)
    assert [job.__name__ for job, _ in lanes] == ["job_lanes", "job_lanes"]
    assert [job.__name__ for job, _ in rest] == [
        "job_population",
        "job_sensitivities",
        "job_sensitivities",
        "job_stepper",
    ]
    assert precompile.chains(todo, 1) == [todo]


def test_compile_names_a_missing_file(tmp_path, capsys):
    assert main(["compile", str(tmp_path / "nosuch.toml")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nosuch.toml" in err[0], err


def test_compile_bed_adds_its_laws_and_a_bad_one_is_one_line(monkeypatch, capsys):
    """--bed adds a set of laws (the paper's moisture law) to the paper's and the specs'; a law the bed
    does not know is argparse's one line and exit 2, before anything compiles."""
    asked = []
    monkeypatch.setattr(precompile, "compile_kernels", lambda law_sets, n, progress=None: asked.append(law_sets))
    assert main(["compile", "--bed", "contact=wall", "--bed", "probe=tumbling", "--processes", "1"]) == 0
    assert asked == [
        [precompile.LawSet(), precompile.LawSet(BedLaws(contact="wall")), precompile.LawSet(BedLaws(probe="tumbling"))]
    ]
    with pytest.raises(SystemExit) as exc:
        main(["compile", "--bed", "contact=nosuch"])
    assert exc.value.code == 2 and "contact" in capsys.readouterr().err and len(asked) == 1


@pytest.mark.slow
def test_a_fit_after_compile_calls_nothing_compile_left_out():
    """After the jobs, a fit, a validation, a population of lanes and a single run add no compiled
    signature to any kernel: the jobs built exactly what the commands call (a job left out, the
    sensitivities say, shows here as the fit's sensitivity kernel gaining its signature)."""
    proc = subprocess.run([sys.executable, "-c", AFTER_THE_JOBS], capture_output=True, text=True, timeout=900, cwd=REPO)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert json.loads(proc.stdout.strip().splitlines()[-1]) == {}
