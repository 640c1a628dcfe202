"""The exact Jacobian of the one right-hand side, generated from it by symbolic differentiation.

:func:`roastlab.model.rhs.derivatives` is evaluated once on SymPy symbols (through
:func:`roastlab.model.rhs.rebind`, the same route that gives the CasADi baseline its symbolic
model), differentiated with respect to the six states, the four inputs and every continuous
entry of the parameter vector, reduced to common subexpressions and printed as plain Python that
numba compiles into the sensitivity integrator (:mod:`roastlab.sim.kernels`). Nothing here is
written by hand: an edit to ``rhs.py`` changes the generated code with it.

The right-hand side branches in Python on the discrete model options (the bed laws'
``contact_law``, ``probe_law``, ``probe_gas_law`` and the moisture law's exponent ``x_exp``), so
the code is generated once per combination of their values (:data:`CODE_VALUES`) and the
generated function picks the block of the combination in ``p`` at run time. :func:`load` also
gives it with one combination's codes written in as constants (``key``, :func:`code_key`), so that
the compiler decides those branches once instead of at every call: the sensitivity integrator is
compiled per combination a fit uses (:func:`roastlab.sim.sensitivity.population_sensitivities`).

The generated source is cached beside the compiled kernels (:func:`roastlab.sim.cache.cache_dir`,
keyed on the hash of the sources it derives from), so SymPy runs once per source version
(a few seconds) and later processes read the file.

Generated function ``rhs_jacobian(Tb, Tm, X, He, Ta, H, Gg, Tgi, heater, fan, p, want, f, Jx, Ju, Jp)``
writes ``f[i]`` = dx_i/dt (as :func:`~roastlab.model.rhs.derivatives`), ``Jx[i, j]`` =
d f_i / d x_j, ``Ju[i, k]`` = d f_i / d u_k (u = [Gg, Tgi, heater, fan], the logged inputs before
:func:`~roastlab.model.rhs.gas_inputs`) and, for each q with ``want[q]`` true, ``Jp[i, q]`` =
d f_i / d p_q (the other columns are neither written nor computed). Entries that are zero
for every input are not written: pass arrays that start at zero. Where the right-hand side has
a kink (``fmax``, ``where``), the derivative is that of the branch taken.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import itertools
import os
import sys
import tempfile
import types
from pathlib import Path

from ..model import bed as _bed
from ..model.constants import MOISTURE_LAWS
from ..model.layout import INPUT_NAMES, N_STATES, PARAM_NAMES, STATE_NAMES, P

#: The parameter-vector entries that select a law (compared with ``==`` in the right-hand side),
#: and the values each can take: the generated code has one block per combination.
CODE_VALUES: dict[str, tuple[float, ...]] = {
    **{f"{k}_law": tuple(float(i) for i in range(len(v))) for k, v in _bed.LAWS.items()},
    "x_exp": tuple(float(v) for v in MOISTURE_LAWS.values()),
}
#: Every combination of the codes' values, in :data:`CODE_VALUES`' order: a combination's index is
#: its ``key`` (:func:`code_key`, :func:`load`).
COMBINATIONS: tuple[tuple[float, ...], ...] = tuple(itertools.product(*CODE_VALUES.values()))
#: Parameter-vector entries the Jacobian differentiates with respect to (every one but the codes).
CONTINUOUS = tuple(name for name in PARAM_NAMES if name not in CODE_VALUES)


_CODE_SLOTS = [P[name] for name in CODE_VALUES]
_KEYS = {combo: key for key, combo in enumerate(COMBINATIONS)}


def code_key(PP) -> int:
    """The index in :data:`COMBINATIONS` of the codes every row of ``PP`` (runs x N_PARAMS) holds, or
    -1 when the rows differ or a code is none of its values (:func:`load` then gives the function that
    reads the codes at run time)."""
    codes = PP[:, _CODE_SLOTS]
    if codes.shape[0] == 0 or not (codes == codes[0]).all():
        return -1
    return _KEYS.get(tuple(codes[0].tolist()), -1)


def with_codes(text: str, key: int) -> str:
    """The generated source ``text`` with the codes of combination ``key`` written in where the
    functions read them from ``p`` (the blocks of the other combinations are left for the compiler to
    drop: every test of a code is then a test of a constant)."""
    import re

    for name, value in zip(CODE_VALUES, COMBINATIONS[key]):
        text = re.sub(rf"^(\s+)p_{name} = p\[{P[name]}\]$", rf"\g<1>p_{name} = {value!r}", text, flags=re.M)
    return text


FUNCTION_NAME = "rhs_jacobian"
OUTLET_FUNCTION_NAME = "outlet_jacobian"


def _symbolic_ops():
    import sympy as sp

    def where(condition, a, b):
        if isinstance(condition, bool) or condition in (sp.true, sp.false):
            return a if bool(condition) else b
        return sp.Piecewise((a, condition), (b, True))

    def fmax(a, b):
        cond = sp.sympify(a) >= sp.sympify(b)
        return where(cond, a, b)

    return {"exp": sp.exp, "fmax": fmax, "where": where}


def _entries(codes: dict[str, float], xs, us, psym, target: str) -> dict:
    """{(array, i, j): expression} of one combination of the codes, zero entries left out.

    ``target`` "rhs": ``derivatives`` (arrays f, Jx, Ju, Jp); "outlet": ``outlet_gas_C`` (arrays
    g, Gx, Gu, Gp; one row)."""
    import sympy as sp

    from ..model.rhs import rebind

    ns = rebind(**_symbolic_ops())
    p = [codes[name] if name in codes else psym[name] for name in PARAM_NAMES]
    if target == "rhs":
        rows, names = ns.derivatives(*xs, *us, p), ("f", "Jx", "Ju", "Jp")
    else:
        rows, names = (ns.outlet_gas_C(list(xs), us[0], us[1], us[3], p),), ("g", "Gx", "Gu", "Gp")
    out = {}
    for i, fi in enumerate(rows):
        fi = sp.sympify(fi)
        out[(names[0], i, None)] = fi
        for j, xj in enumerate(xs):
            out[(names[1], i, j)] = sp.diff(fi, xj)
        for k, uk in enumerate(us):
            out[(names[2], i, k)] = sp.diff(fi, uk)
        for name in CONTINUOUS:
            out[(names[3], i, P[name])] = sp.diff(fi, psym[name])
    return {key: e for key, e in out.items() if e.is_zero is not True}


def _merged(xs, us, psym, csym, target: str):
    """{(array, i, j): expression} over every combination of the codes: an entry that differs
    between combinations is a Piecewise over the codes it depends on (``csym``, compared with
    ``==`` at run time), so blocks shared between laws are generated and computed once."""
    import sympy as sp

    names = list(CODE_VALUES)
    combos = list(itertools.product(*CODE_VALUES.values()))
    per_combo = {combo: _entries(dict(zip(names, combo)), xs, us, psym, target) for combo in combos}
    keys = sorted({k for e in per_combo.values() for k in e}, key=lambda k: (k[0], k[1], -1 if k[2] is None else k[2]))
    merged = {}
    for key in keys:
        expr = {combo: per_combo[combo].get(key, sp.Integer(0)) for combo in combos}
        # the codes this entry depends on: varying one (the others fixed) changes the expression
        depends = [
            c
            for c, name in enumerate(names)
            if any(
                expr[a] != expr[b]
                for a in combos
                for b in combos
                if all(a[d] == b[d] for d in range(len(names)) if d != c) and a[c] != b[c]
            )
        ]
        if not depends:
            merged[key] = expr[combos[0]]
            continue
        pieces = []
        for values in itertools.product(*(CODE_VALUES[names[c]] for c in depends)):
            combo = next(cb for cb in combos if all(cb[c] == v for c, v in zip(depends, values)))
            cond = sp.And(*(sp.Eq(csym[names[c]], v) for c, v in zip(depends, values)))
            pieces.append((expr[combo], cond))
        pieces[-1] = (pieces[-1][0], True)
        merged[key] = sp.Piecewise(*pieces)
    return merged


#: The generated functions: name, what they differentiate, their arguments after ``p`` and the
#: array whose columns are computed only where asked for (or None). The right-hand side's takes
#: ``want`` (a flag per parameter-vector entry) and writes the column ``Jp[:, q]``, and computes the
#: subexpressions only it needs, where ``want[q]`` alone: a fit frees a few of the 36 continuous
#: entries, and the others' derivatives (the options' powers and logarithms above all) cost a quarter
#: of an evaluation (docs/performance.md).
GENERATED = {
    FUNCTION_NAME: ("rhs", "want, f, Jx, Ju, Jp", "Jp"),
    OUTLET_FUNCTION_NAME: ("outlet", "g, Gx, Gu, Gp", None),
}


def _statements(printer, replacements, subexpressions, rows, indent: str) -> list[str]:
    """The assignments of ``subexpressions`` (in ``replacements``' order, each after those it uses)
    and then of ``rows`` ({(array, i, j): expression} items), as lines at ``indent``."""
    lines = [f"{indent}{sym.name} = {printer.doprint(expr)}" for sym, expr in replacements if sym in subexpressions]
    for (array, i, j), expr in rows:
        target = f"{array}[{i}]" if j is None else f"{array}[{i}, {j}]"
        lines.append(f"{indent}{target} = {printer.doprint(expr)}")
    return lines


def _needed(replacements, symbols) -> set:
    """The common subexpressions ``symbols`` need, directly or through one another."""
    deps = {sym: expr.free_symbols for sym, expr in replacements}
    out, stack = set(), [s for s in symbols if s in deps]
    while stack:
        sym = stack.pop()
        if sym not in out:
            out.add(sym)
            stack.extend(s for s in deps[sym] if s in deps)
    return out


def _printer():
    """SymPy's Python printer, with a power whose exponent is not a whole number (or a half) printed
    behind the exact shortcuts of IEEE 754's pow (C99 Annex F): x**0 = 1 for every x, x**1 = x and
    1**y = 1 for every y. They change no bit of a result and skip the library call where a model
    option is off: beans that do not swell (``bean_swell`` 0) give a base of exactly 1 to their size's
    1/3 and 2/3 powers and those of its derivatives, and drives in proportion to their settings
    (``heater_exp``, ``fan_exp`` 1) an exponent of 0 or 1. The differentiated powers are evaluated at
    every stage of a fit's sensitivity integration, whether the option is on or not (one evaluation of
    dataset-I's Jacobian 214 ns against 267 ns; docs/performance.md)."""
    import sympy as sp
    from sympy.printing.pycode import PythonCodePrinter

    class Printer(PythonCodePrinter):
        def _print_Pow(self, expr, rational=False):
            text = super()._print_Pow(expr, rational=rational)
            base, exponent = expr.as_base_exp()
            if exponent.is_Integer or exponent in (sp.S.Half, -sp.S.Half):
                return text  # a product or a square root: no call to shortcut
            b = self.parenthesize(base, 100)
            if not base.is_Number:
                text = f"(1.0 if {b} == 1.0 else {text})"
            if exponent.is_Number:
                return text
            e = self.parenthesize(exponent, 100)
            return f"(1.0 if {e} == 0.0 else ({b} if {e} == 1.0 else {text}))"

    return Printer({"fully_qualified_modules": True, "standard": "python3"})


def generate_source() -> str:
    """The Python source of ``rhs_jacobian`` and ``outlet_jacobian`` (needs SymPy; seconds)."""
    import sympy as sp

    printer = _printer()
    xs = sp.symbols(f"x0:{N_STATES}", real=True)
    us = sp.symbols(f"u0:{len(INPUT_NAMES)}", real=True)
    psym = {name: sp.Symbol(f"p_{name}", real=True) for name in CONTINUOUS}
    csym = {name: sp.Symbol(f"p_{name}", real=True) for name in CODE_VALUES}
    lines = [
        '"""GENERATED by roastlab.sim.jacobian from roastlab.model.rhs: do not edit (see that module)."""',
        "import math",
    ]
    for function, (target, arrays, guarded) in GENERATED.items():
        merged = _merged(xs, us, psym, csym, target)
        replacements, reduced = sp.cse(list(merged.values()), symbols=sp.numbered_symbols("c"))
        lines += [
            "",
            "",
            f"def {function}(x0, x1, x2, x3, x4, x5, u0, u1, u2, u3, p, {arrays}):",
            "    # " + ", ".join(f"x{i} = {n}" for i, n in enumerate(STATE_NAMES)),
            "    # " + ", ".join(f"u{i} = {n}" for i, n in enumerate(INPUT_NAMES)),
        ]
        used = set()
        for expr in list(reduced) + [e for _, e in replacements]:
            used |= expr.free_symbols
        for name, sym in {**psym, **csym}.items():
            if sym in used:
                lines.append(f"    {sym.name} = p[{P[name]}]")
        entries = list(zip(merged, reduced))
        columns = sorted({j for (array, _, j), _ in entries if array == guarded})
        always = [(key, e) for key, e in entries if key[0] != guarded]
        base = _needed(replacements, set().union(*(e.free_symbols for _, e in always)))
        lines += _statements(printer, replacements, base, always, "    ")
        for q in columns:  # a subexpression two columns share is written in both: each block stands alone
            rows = [(key, e) for key, e in entries if key[0] == guarded and key[2] == q]
            needed = _needed(replacements, set().union(*(e.free_symbols for _, e in rows))) - base
            lines += [f"    if want[{q}]:", *_statements(printer, replacements, needed, rows, "        ")]
    return "\n".join(lines) + "\n"


def _sources_hash() -> str:
    from .cache import source_hash

    return hashlib.sha256((source_hash() + FUNCTION_NAME).encode()).hexdigest()[:16]


def _write_atomically(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".jacobian-", suffix=".tmp")
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def source_path(key: int = -1) -> Path | None:
    """Where this source version's generated module is cached (None when no cache folder); ``key``
    (:func:`code_key`): the module with that combination's codes written in."""
    from .cache import cache_dir

    folder = cache_dir()
    suffix = "" if key < 0 else f"_k{key}"
    return None if folder is None else folder / f"rhs_jacobian_{_sources_hash()}{suffix}.py"


def load(function: str = FUNCTION_NAME, key: int = -1):
    """A generated function (``rhs_jacobian`` or ``outlet_jacobian``) as plain Python (generated
    and cached on first use; one module per process holds both). ``key`` >= 0: the function with
    the codes of :data:`COMBINATIONS`' entry ``key`` written in (:func:`with_codes`), which gives
    the same numbers as the one that reads them from ``p`` for parameter vectors holding those codes."""
    # a module in sys.modules under a name of its own: numba's disk cache of the kernels that
    # compile this function in finds its globals by that name in a later process
    name = f"roastlab_rhs_jacobian_{_sources_hash()}" + ("" if key < 0 else f"_k{key}")
    if name in sys.modules:
        return getattr(sys.modules[name], function)
    path = source_path(key)
    text = None
    if path is None or not path.is_file():
        text = generate_source() if key < 0 else with_codes(_source_text(), key)
        if path is not None:
            try:
                _write_atomically(path, text)
            except OSError:
                path = None
    if path is not None:
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    else:
        module = types.ModuleType(name)
        sys.modules[name] = module
        exec(compile(text, f"<{name}>", "exec"), module.__dict__)  # our own generated code, never user input
    return getattr(module, function)


@functools.cache
def _source_text() -> str:
    """The generated source of the functions that read the codes at run time (from the cache folder,
    else generated)."""
    load(FUNCTION_NAME)
    path = source_path()
    return path.read_text() if path is not None and path.is_file() else generate_source()
