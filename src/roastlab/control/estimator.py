"""State estimation: an extended Kalman filter on the compiled model.

The roaster shows one number, the bean probe's reading Ta (eq. 17). The filter estimates the
states behind it -- bean temperature Tb, drum metal temperature Tm (the drum's stored heat,
which no sensor shows), moisture X, released exothermic heat He -- and, for offset-free
control, an unmeasured disturbance d: an offset of the inlet gas temperature [degC] that stands
for every heat deficit or surplus the model does not know (a fouled drum, a weak burner, a
different batch). Its state is z = [Tb, Tm, X, He, Ta, H, d] (H: the heater lag of the actuator
extension).

* Predict: the compiled integrator over the one right-hand side
  (:func:`roastlab.sim.simulate.advance`) carries z over one control interval with the
  input that was applied (zero-order hold) and Tgi + d; its Jacobian is a forward difference
  per state (seven extra one-interval runs, ~15 us together).
* Update: the scalar measurement Ta with noise variance ``measurement_noise_C**2``, Joseph form.
* Physical bounds after each update: X >= 0, 0 <= He <= Het.

Process noise is a random walk per state, scaled with the interval (``process_sd`` per sqrt(s)).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..model.layout import S_HE, S_X
from ..model.rhs import I_HET, N_STATES, STATE_NAMES
from ..sim.kernels import H0_S
from ..sim.simulate import advance
from .base import LoopSetup

#: Names of the filter's states: the model's six and the inlet-temperature disturbance.
NAMES = (*STATE_NAMES, "Tgi_bias_C")
NZ = N_STATES + 1
#: Standard deviation of the initial guess: Tb, Tm (the drum's stored heat is the unknown), X,
#: He, Ta, H, d.
INITIAL_SD = np.array([3.0, 40.0, 0.02, 2.0, 0.5, 0.01, 10.0])
#: Random-walk process noise per sqrt(second) of each state.
PROCESS_SD = np.array([0.02, 0.05, 2e-5, 0.05, 0.02, 1e-3, 0.4])
#: Forward-difference steps of the Jacobian.
STEPS = np.array([0.05, 0.05, 1e-4, 0.05, 0.05, 1e-3, 0.5])


class ExtendedKalmanFilter:
    """EKF of the bean, drum, moisture, exothermic-heat states and an inlet disturbance.

    Parameters
    ----------
    measurement_noise_C : probe noise assumed [degC] (standard deviation)
    initial_sd, process_sd : per state, in the order of :data:`NAMES` (defaults above)
    disturbance : estimate the inlet-temperature disturbance d (else it stays 0)
    """

    def __init__(self, measurement_noise_C: float = 0.5, initial_sd=None, process_sd=None, disturbance: bool = True):
        if not (np.isfinite(measurement_noise_C) and measurement_noise_C > 0):
            raise InputError(f"measurement noise must be > 0 degC, got {measurement_noise_C!r}", "estimator")
        self.r = float(measurement_noise_C) ** 2
        self.initial_sd = np.array(INITIAL_SD if initial_sd is None else initial_sd, dtype=float)
        self.process_sd = np.array(PROCESS_SD if process_sd is None else process_sd, dtype=float)
        if not disturbance:
            self.initial_sd[-1] = 0.0
            self.process_sd[-1] = 0.0
        self.disturbance = disturbance

    def reset(self, setup: LoopSetup, x0=None) -> None:
        """Start from the model's nominal state at CHARGE (or ``x0``, six states) and d = 0."""
        self.setup = setup
        self.p = setup.params
        self.z = np.zeros(NZ)
        self.z[:N_STATES] = setup.x0 if x0 is None else x0
        self.P = np.diag(self.initial_sd**2)
        self._h = H0_S

    def _f(self, z, inputs, dt):
        vec = inputs.copy()
        vec[1] += z[-1]  # the disturbance is an offset of the inlet temperature
        x, _, h = advance(z[:N_STATES], vec, vec, dt, self.p, h_s=self._h)
        out = np.empty(NZ)
        out[:N_STATES] = x
        out[-1] = z[-1]
        return out, h

    def predict(self, inputs, dt: float) -> None:
        """Carry the estimate over ``dt`` seconds with the model's ``inputs`` [Gg, Tgi, heater,
        fan] held (the decided one as applied; see :meth:`LoopSetup.input_vector`)."""
        inputs = np.asarray(inputs, dtype=np.float64)
        z0 = self.z
        z1, h = self._f(z0, inputs, dt)
        F = np.empty((NZ, NZ))
        for j in range(NZ):
            zp = z0.copy()
            zp[j] += STEPS[j]
            F[:, j] = (self._f(zp, inputs, dt)[0] - z1) / STEPS[j]
        self._h = h
        Q = np.diag((self.process_sd**2) * dt)
        self.P = F @ self.P @ F.T + Q
        self.z = z1

    def update(self, measurement_C: float) -> None:
        """Correct with one probe reading [degC]."""
        i = 4  # Ta
        S = self.P[i, i] + self.r
        K = self.P[:, i] / S
        self.z = self.z + K * (measurement_C - self.z[i])
        A = np.eye(NZ)
        A[:, i] -= K
        self.P = A @ self.P @ A.T + self.r * np.outer(K, K)
        self.z[S_X] = max(self.z[S_X], 0.0)
        self.z[S_HE] = min(max(self.z[S_HE], 0.0), self.p[I_HET])

    @property
    def state(self) -> np.ndarray:
        """The model's six states as estimated now."""
        return self.z[:N_STATES].copy()

    @property
    def disturbance_C(self) -> float:
        return float(self.z[-1])

    def as_dict(self) -> dict[str, float]:
        return {f"{n}_est": float(v) for n, v in zip(NAMES, self.z) if n != "H"}
