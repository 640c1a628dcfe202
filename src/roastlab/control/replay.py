"""Replay: the reference roast's own recorded inputs, open loop.

What Artisan's maintainers recommend for repeating a roast (replay the background's burner and
air events) and the baseline every feedback controller should beat under disturbance: it ignores
the probe entirely, so on the nominal scenario it reproduces the reference exactly and on every
other it shows the disturbance unopposed.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .base import LoopSetup


class Replay:
    """Returns the reference's recorded decided input at each time (held linearly between its
    samples, as the model holds logged inputs; the actuator then holds it over the interval)."""

    name = "replay"
    estimate = None

    def reset(self, setup: LoopSetup) -> None:
        if setup.reference_u is None:
            raise InputError(f"the reference has no recorded {setup.limits.decide} to replay", "--reference")
        self.setup = setup

    def step(self, time_s: float, measurement_C: float) -> float:
        return float(np.interp(time_s, self.setup.time_s, self.setup.reference_u))
