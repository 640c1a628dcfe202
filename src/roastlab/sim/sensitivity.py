"""Sensitivity of the probe reading to an input program, by finite differences on the compiled
integrator (for input-program optimisation: profile transfer, model predictive control).

The program is the inlet gas temperature Tgi (or the heater setting) at every sample of a time grid (held linearly or
zero-order between samples, as in :func:`roastlab.sim.kernels.integrate_into`). Changing Tgi at
sample k cannot change anything before sample k - 1 (linear hold) or k (zero-order hold), so
each column of the Jacobian restarts the integration from the stored state there and runs to
the end: about n/2 full simulations for n samples instead of n, in parallel over the columns.
The restart takes fresh adaptive steps, so a column carries the integrator's local error
(~1e-4 degC) divided by the perturbation; with a 1 degC perturbation that is negligible.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from ..model.layout import S_TA
from .cache import compiled
from .kernels import H0_S, N_OUT, NS, integrate_into


@compiled
def _column(k, t, Gg, Tgi, Q, F, which, states, ta_base, p, zoh, h_max, delta, jac):
    n = t.shape[0]
    start = k
    if not zoh and k > 0:
        start = k - 1  # a linear hold reaches back one interval
    m = n - start
    tgi = Tgi[start:].copy()
    q = Q[start:].copy()
    if which == 0:
        tgi[k - start] += delta
    else:
        q[k - start] += delta
    out = np.empty((m, N_OUT))
    x0 = np.empty(NS)
    for i in range(NS):
        x0[i] = states[start, i]
    integrate_into(t[start:], Gg[start:], tgi, q, F[start:], m, x0, p, zoh, h_max, out, H0_S, False)
    for i in range(start):
        jac[i, k] = 0.0
    for i in range(m):
        jac[start + i, k] = (out[i, S_TA] - ta_base[start + i]) / delta


@compiled(parallel=True)
def ta_input_jacobian(t, Gg, Tgi, Q, F, which, states, ta_base, p, zoh, h_max, delta, jac):
    """jac[i, k] = d Ta(t_i) / d u_k for the run whose states are ``states`` (n x NS).

    ``u`` is the inlet temperature Tgi [degC] (``which`` = 0) or the heater setting Q
    (``which`` = 1); ``ta_base`` is the run's probe reading, ``delta`` the forward-difference
    step in u's units. Rows before the first sample a change at k can reach are zero.
    """
    for k in prange(t.shape[0]):
        _column(np.int64(k), t, Gg, Tgi, Q, F, which, states, ta_base, p, zoh, h_max, delta, jac)
