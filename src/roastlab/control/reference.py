"""The standard synthetic reference roast of the control testbench (SYNTHETIC: a model run, not a
measured roast).

The paper's model (theta*, Table 1) on its 120 kg plant, run with the inlet program of the
shipped synthetic dataset-I batch 1 (itself synthetic), made into something a controller can
follow exactly: resampled every ``sample_s`` seconds over a stretched roast
(:data:`DURATION_S`), smoothed over a minute (the synthetic log's inlet noise removed), lowered
towards 150 degC by :data:`INTENSITY` so that the actuator keeps headroom under the default
550 degC ceiling for disturbances, and run with a zero-order hold as the testbench applies
inputs. On the nominal scenario, replaying its inputs reproduces its BT to the integrator's
accuracy. Deterministic (no random numbers).
"""

from __future__ import annotations

import numpy as np

from ..io.batch import Batch, read_batch_csv
from ..sim.simulate import simulate
from ..workflows.reproduce import default_dataset_root

#: Length of the standard roast, CHARGE to DROP [s].
DURATION_S = 1020.0
#: Fraction of batch 1's inlet program above 150 degC that the reference uses [-].
INTENSITY = 0.8
#: Moving-average window over the inlet program [s].
SMOOTHING_S = 60.0
LABEL = "SYNTHETIC standard reference: paper model (theta*, 120 kg) on dataset-I batch 1's inlet program, smoothed"


def standard_reference(sample_s: float = 5.0) -> Batch:
    """The standard synthetic reference (see module docstring) as a Batch with Ta_C, on
    ``sample_s``-second samples from CHARGE to DROP."""
    src = read_batch_csv(default_dataset_root() / "dataset-I" / "batch1.csv")
    t = np.arange(0.0, DURATION_S + 1e-9, sample_s)
    tgi = np.interp(t * (src.time_s[-1] / DURATION_S), src.time_s, src.Tgi_C)
    w = max(1, int(round(SMOOTHING_S / sample_s)))
    padded = np.pad(tgi, (w // 2, w - w // 2 - 1), mode="edge")
    tgi = np.convolve(padded, np.ones(w) / w, mode="valid")
    tgi = 150.0 + INTENSITY * (tgi - 150.0)
    gg = np.full(t.shape, float(np.mean(src.Gg_kg_s)))
    run = simulate("120kg", t, gg, tgi, hold="zoh", name="standard-reference")
    batch = Batch("standard-reference (synthetic)", t, gg, tgi, run.Ta_C.copy(), source="standard reference")
    batch.notes.append(LABEL)
    return batch
