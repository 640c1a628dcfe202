"""Does the model's error on one roast foretell its error on the next? (docs/profile-transfer.md)

A transfer makes the model's probe follow the reference's measured BT. Where the model misses the
reference as it was run (measured minus predicted, e(t)), a program could instead aim at the target
less that error, on the bet that the next roast will show the same miss: run-to-run control and
iterative learning control correct each run by the last one's error. That pays only if the errors of
two roasts are alike. This script measures it on logs a model was not fitted on.

For every ordered pair (A, B) of held-out logs, on their common time from 1:00 after CHARGE (past
the charge dip) to the earlier DROP, on a 5 s grid: the mean square of B's error as it is, e_B, and
after B is corrected by a share k of A's error, e_B - k e_A. It prints the root mean square over the
pairs for k = 0 (the transfer as it is), 0.5 and 1 (the whole error carried), how many pairs the
correction helps, and the least-squares share k* = sum e_A e_B / sum e_A^2 over all pairs, the share
that would help most on these logs; with the logs' units (RoasTime's serial numbers), pairs of one
unit apart as well.

    python docs/error_persistence.py MODEL.json LOG...

MODEL.json from ``roastlab fit-roaster`` (its ``fit.batches`` say which logs it was fitted on; those
are left out). Reads the logs with the model's map. Prints only; writes nothing.
"""

from __future__ import annotations

import sys
from itertools import permutations

import numpy as np

import roastlab
from roastlab.errors import RoastlabError
from roastlab.workflows.model import load_log_for

#: Where the comparison starts [s after CHARGE]: past the charge dip, which the charge sets.
FROM_S = 60.0
#: The comparison's grid [s].
STEP_S = 5.0
#: The shares of A's error carried over to B that the table shows.
SHARES = (0.0, 0.5, 1.0)


def held_out_errors(model, paths) -> dict:
    """``{name: (time_s, error_C, unit)}``: each log's probe error (measured minus the model's) on the
    logs the model was not fitted on, with a green weight, read with the model's map."""
    batches = []
    for path in paths:
        try:
            b = load_log_for(path, model)
        except RoastlabError as exc:
            print(f"left out: {exc}", file=sys.stderr)
            continue
        if b.Mb_kg:
            batches.append(b)
    fitted = model.fitted_roasts(batches)
    out = {}
    for b in batches:
        if b.name in fitted:
            continue
        r = model.predict(b)
        out[b.name] = (np.asarray(b.time_s, float), np.asarray(b.Ta_C, float) - np.asarray(r.Ta_C, float), b.unit)
    return out


def pair_table(errors: dict, same_unit: bool = False) -> tuple[dict, float, int] | None:
    """``({k: (rms_C, pairs_helped)}, k*, pairs)`` over the ordered pairs of ``errors``
    (:func:`held_out_errors`), of one unit only with ``same_unit``; None without two logs."""
    sq = {k: [] for k in SHARES}
    num = den = 0.0
    for a, b in permutations(errors, 2):
        (ta, ea, ua), (tb, eb, ub) = errors[a], errors[b]
        if same_unit and (not ua or ua != ub):
            continue
        grid = np.arange(FROM_S, min(ta[-1], tb[-1]), STEP_S)
        if grid.size < 2:
            continue
        da, db = np.interp(grid, ta, ea), np.interp(grid, tb, eb)
        for k in SHARES:
            sq[k].append(float(np.mean((db - k * da) ** 2)))
        num += float(np.sum(da * db))
        den += float(np.sum(da * da))
    pairs = len(sq[0.0])
    if not pairs:
        return None
    as_is = np.asarray(sq[0.0])
    table = {k: (float(np.sqrt(np.mean(v))), int(np.sum(np.asarray(v) < as_is))) for k, v in sq.items()}
    return table, num / den, pairs


def main(argv) -> int:
    if len(argv) < 3:
        print(__doc__.split("\n\n")[-2], file=sys.stderr)
        return 2
    model = roastlab.load_model(argv[1])
    errors = held_out_errors(model, argv[2:])
    print(f"{len(errors)} held-out logs (the model's own fit logs left out), from {FROM_S / 60:g}:00 after CHARGE")
    rows = [("every pair", False)]
    if len({u for *_, u in errors.values() if u}) > 1:
        rows.append(("pairs of one unit", True))
    head = "".join(f"{f'k = {k:g}: RMS' + (', helped' if k else ''):>24}" for k in SHARES)
    print(f"{'pairs':<20}{'n':>5}{head}{'k*':>8}")
    for label, same in rows:
        got = pair_table(errors, same)
        if got is None:
            continue
        table, best, n = got
        cells = "".join(
            f"{f'{rms:.2f} °C' + (f', {helped}/{n}' if k else ''):>24}" for k, (rms, helped) in table.items()
        )
        print(f"{label:<20}{n:>5}{cells}{best:>8.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
