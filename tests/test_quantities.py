"""The one quantity table: every quantity complete and consistent, and no second copy of a range.

The table (roastlab.model.quantities) is the only home of a registered quantity's unit, default,
plausible range and fit bounds; the plausibility view (LIMITS), the identification registry
(REGISTRY, THETA_BOUNDS), the process constants' and initial state's defaults and pack_params
read it. These tests fail when a quantity is incomplete, when a view disagrees with the table,
or when a module outside the table writes a numeric range for a registered quantity.
"""

import ast
import dataclasses
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import roastlab
from roastlab.model import layout
from roastlab.model.constants import ProcessConstants
from roastlab.model.limits import LIMITS, check_value
from roastlab.model.parameters import REGISTRY, THETA_BOUNDS, THETA_NAMES, THETA_PAPER
from roastlab.model.quantities import KINDS, QUANTITIES, table
from roastlab.model.rhs import pack_params
from roastlab.sim.simulate import InitialState

SRC = Path(roastlab.__file__).parent
#: Kinds whose quantities may have no default: measured inputs (and the rate limit) and plant
#: geometry, which a plant file always gives.
NO_DEFAULT_KINDS = {"input", "plant", "scenario"}


@pytest.mark.parametrize("q", table(), ids=lambda q: q.name)
def test_every_quantity_is_complete(q):
    assert q.kind in KINDS
    assert q.unit and q.meaning
    lo, hi = q.plausible
    assert math.isfinite(lo) and math.isfinite(hi) and lo < hi
    if q.default is None:
        assert q.kind in NO_DEFAULT_KINDS, f"{q.name} ({q.kind}) needs a default"
    else:
        assert lo <= q.default <= hi, f"default of {q.name} outside its plausible range"
    if q.bounds is not None:
        blo, bhi = q.bounds
        assert lo <= blo < bhi <= hi, f"fit bounds of {q.name} {q.bounds} not inside plausible {q.plausible}"
    if q.kind in ("theta", "initial") or q.bounds is not None:
        assert q.slot is not None
    if q.slot is not None and q.kind != "initial":
        assert q.slot in layout.P, f"{q.name} sets {q.slot!r}, not a parameter-vector entry"
    if q.kind == "initial":
        assert q.slot in layout.STATE0


def test_the_views_are_the_table():
    for name, (lo, hi, unit, meaning) in LIMITS.items():
        q = QUANTITIES[name]
        assert (lo, hi, unit, meaning) == (*q.plausible, q.unit, q.meaning)
    assert set(LIMITS) == set(QUANTITIES)
    for name, q in REGISTRY.items():
        assert q is QUANTITIES[name] and q.identifiable
    assert {q.name for q in table() if q.identifiable} == set(REGISTRY)
    assert THETA_BOUNDS == {k: QUANTITIES[k].bounds for k in THETA_NAMES}
    assert THETA_PAPER.as_dict() == {k: QUANTITIES[k].default for k in THETA_NAMES}
    # aliases are one quantity: one range for both names
    assert QUANTITIES["Mm"] is QUANTITIES["Mm_kg"] and LIMITS["Mm"] == LIMITS["Mm_kg"]
    assert QUANTITIES["batch_kg"] is QUANTITIES["Mb_kg"]


def test_defaults_come_from_the_table():
    pc = ProcessConstants()
    for f in dataclasses.fields(pc):
        assert getattr(pc, f.name) == QUANTITIES[f.name].default
    x = InitialState().vector()
    for name, i in layout.STATE0.items():
        if name != "Ta0_C":  # Ta0 follows the log's first reading, else Tb0
            assert x[i] == QUANTITIES[name].default
    p = pack_params(roastlab.load_plant("120kg"), THETA_PAPER)
    for q in table():
        if q.kind == "extension":
            assert p[layout.P[q.slot]] == q.default, q.name


def test_the_paper_check_value_still_holds():
    """MODEL.md's check value with every default from the table (the table did not move the model)."""
    t = np.arange(0, 901, 30.0)
    r = roastlab.simulate("120kg", t, np.full_like(t, 0.4), np.full_like(t, 450.0))
    assert abs(r.Tb_C[-1] - 218.31) < 0.01


@pytest.mark.parametrize("name", ["cm", "A", "hgm", "Mm", "Kt", "X0", "T_room_C"])
def test_values_outside_the_plausible_range_are_refused(name):
    lo, hi = QUANTITIES[name].plausible
    for bad in (lo - abs(lo) - 1.0, hi * 10 + 1.0, math.nan, math.inf):
        with pytest.raises(roastlab.ParameterError, match=name):
            check_value(name, bad)


def _numeric_pair(node) -> bool:
    def num(n):
        if isinstance(n, ast.UnaryOp) and isinstance(n.op, ast.USub):
            n = n.operand
        return isinstance(n, ast.Constant) and isinstance(n.value, (int, float)) and not isinstance(n.value, bool)

    return isinstance(node, ast.Tuple) and len(node.elts) in (2, 4) and num(node.elts[0]) and num(node.elts[1])


def stray_ranges() -> list[str]:
    """Places outside quantities.py that write a numeric (lo, hi) range keyed by a registered name:
    a dict entry ``"name": (lo, hi, ...)`` or a call ``Quantity("name", ..., (lo, hi), ...)``."""
    out = []
    for path in sorted(SRC.rglob("*.py")):
        if path.name == "quantities.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Dict):
                for k, v in zip(node.keys, node.values):
                    if isinstance(k, ast.Constant) and k.value in QUANTITIES and _numeric_pair(v):
                        out.append(f"{path.relative_to(SRC)}:{node.lineno}: {k.value}")
            elif isinstance(node, ast.Call) and node.args:
                first = node.args[0]
                if isinstance(first, ast.Constant) and first.value in QUANTITIES:
                    if any(_numeric_pair(a) for a in node.args[1:]):
                        out.append(f"{path.relative_to(SRC)}:{node.lineno}: {first.value}")
    return out


def test_no_other_module_holds_a_range_of_a_registered_quantity():
    assert stray_ranges() == []


def test_the_walker_finds_a_stray_range(tmp_path, monkeypatch):
    """The walker above can fail: a module with a copied range is found."""
    fake = tmp_path / "roastlab"
    fake.mkdir()
    (fake / "copy.py").write_text('LIMITS = {"hgm": (0.0, 100.0, "kW/(m2 K)", "x")}\n')
    monkeypatch.setattr(sys.modules[__name__], "SRC", fake)
    assert stray_ranges() == ["copy.py:1: hgm"]


def test_fix_out_of_range_is_one_line_exit_2(tmp_path):
    """`identify --fix cm=0` (and any fixed value outside its range) is refused before any simulation."""
    data = roastlab.default_dataset_root() / "dataset-I"
    for fix in ("cm=0", "Kt=-1", "hgm=1e9", "X0=2"):
        proc = subprocess.run(
            [sys.executable, "-m", "roastlab", "identify", str(data), "--fix", fix, "--out", str(tmp_path / "m.json")],
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert proc.returncode == 2, (fix, proc.stderr)
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and fix.split("=")[0] in lines[0] and "plausible range" in lines[0], proc.stderr
        assert not (tmp_path / "m.json").exists()
