"""The control baseline: the same receding-horizon problem as :class:`~roastlab.control.MPC`,
solved by CasADi + IPOPT with multiple shooting (``pip install 'roastlab[control]'``).

The dynamics are the project's one right-hand side evaluated on CasADi symbols
(:func:`roastlab.model.rhs.rebind` with ``casadi.exp``, ``casadi.fmax``, ``casadi.if_else``),
never a second copy of the equations. Per control interval the states are carried by
``substeps`` classical Runge-Kutta steps (the shooting map). The problem, as the project's MPC
poses it:

    minimise   sum_{k=1..N} (Ta_k - ref_k)^2 + lam^2 sum_{k=1..N-1} (u_k - u_{k-1})^2
    subject to x_{k+1} = F(x_k, u_k + d),  x_0 = the estimate,
               low <= u_k <= high,  |u_k - u_{k-1}| <= rate dt,  |u_0 - u_applied| <= rate dt

with the same extended Kalman filter and the same inlet disturbance d. IPOPT is warm-started
with the previous solution (primal and dual). Used by ``roastlab bench --only control`` as the
baseline the project's MPC is timed against.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..fit.program import SMOOTHNESS
from ..model.rhs import I_HET, N_STATES, rebind
from .base import LoopSetup
from .estimator import ExtendedKalmanFilter
from .mpc import MPC


def _casadi():
    try:
        import casadi
    except ImportError:
        raise InputError("the CasADi baseline needs casadi: pip install 'roastlab[control]'", "casadi") from None
    return casadi


def symbolic_rhs(p: np.ndarray):
    """A CasADi Function f(x[6], u[4]) -> dx/dt[6] of the one right-hand side with parameters ``p``."""
    ca = _casadi()
    ns = rebind(exp=ca.exp, fmax=ca.fmax, where=ca.if_else)
    x = ca.SX.sym("x", N_STATES)
    u = ca.SX.sym("u", 4)
    d = ns.derivatives(x[0], x[1], x[2], x[3], x[4], x[5], u[0], u[1], u[2], u[3], p)
    return ca.Function("rhs", [x, u], [ca.vertcat(*d)])


#: Scale of each state in the NLP's decision variables: Tb, Tm [degC], X [kg/kg], He [kJ/kg], Ta, H.
STATE_SCALE = np.array([100.0, 100.0, 0.1, 100.0, 100.0, 1.0])


class CasadiMPC(MPC):
    """Receding-horizon tracking with CasADi + IPOPT (see the module docstring). The filter, the
    horizon and the loop are :class:`~roastlab.control.MPC`'s; only the solve differs. Parameters
    as MPC's, plus ``substeps`` RK4 steps per interval and IPOPT's ``tol``."""

    name = "casadi-mpc"

    def __init__(
        self,
        horizon_s: float = 300.0,
        smoothness: float = SMOOTHNESS,
        substeps: int = 2,
        tol: float = 1e-6,
        estimator: ExtendedKalmanFilter | None = None,
    ):
        super().__init__(horizon_s=horizon_s, smoothness=smoothness, estimator=estimator)
        self.substeps = int(substeps)
        self.tol = float(tol)
        self._built_for = None

    def _build(self, setup: LoopSetup, n: int):
        ca = _casadi()
        f = symbolic_rhs(setup.params)
        dt = setup.sample_s
        h = dt / self.substeps
        x = ca.SX.sym("x", N_STATES)
        u = ca.SX.sym("u", 4)
        xk = x
        for _ in range(self.substeps):
            k1 = f(xk, u)
            k2 = f(xk + h / 2 * k1, u)
            k3 = f(xk + h / 2 * k2, u)
            k4 = f(xk + h * k3, u)
            xk = xk + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        F = ca.Function("F", [x, u], [xk])
        decide = 1 if setup.limits.decide == "Tgi" else 2
        # decision states scaled to order one (IPOPT's iterates and tolerances behave)
        scale = ca.DM(STATE_SCALE)
        Xs = ca.SX.sym("X", N_STATES, n + 1)
        X = ca.diag(scale) @ Xs
        U = ca.SX.sym("U", n)
        P = ca.SX.sym("P", N_STATES + (n + 1) + 1 + 1 + 4 * n)  # x0, ref, u_prev, bias, inputs
        x0 = P[:N_STATES]
        ref = P[N_STATES : N_STATES + n + 1]
        u_prev = P[N_STATES + n + 1]
        bias = P[N_STATES + n + 2]
        base = ca.reshape(P[N_STATES + n + 3 :], 4, n)
        J = 0
        g = [X[:, 0] - x0]
        for k in range(n):
            uk = ca.vertcat(*[U[k] if j == decide else base[j, k] for j in range(4)])
            uk[1] = uk[1] + bias
            g.append(X[:, k + 1] - F(X[:, k], uk))
            J += (X[4, k + 1] - ref[k + 1]) ** 2
        for k in range(1, n):
            J += self.smoothness**2 * (U[k] - U[k - 1]) ** 2
        rate = [U[0] - u_prev] + [U[k] - U[k - 1] for k in range(1, n)]
        g = [g[0] / scale] + [gk / scale for gk in g[1:]]
        g_all = ca.vertcat(*g, *rate)
        z = ca.vertcat(ca.reshape(Xs, -1, 1), U)
        nlp = {"x": z, "p": P, "f": J, "g": g_all}
        opts = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.tol": self.tol}
        opts["ipopt.warm_start_init_point"] = "yes"
        opts["ipopt.max_iter"] = 200
        self._solver = ca.nlpsol("mpc", "ipopt", nlp, opts)
        cap = setup.limits.rate_per_min / 60.0 * dt
        nx = N_STATES * (n + 1)
        # states inside their physical ranges (IPOPT's iterates otherwise wander into overflow)
        lo_x = np.array([-50.0, -50.0, 0.0, 0.0, -50.0, -1e3])
        hi_x = np.array([1000.0, 1000.0, 1.0, float(setup.params[I_HET]), 1000.0, 1e4])
        lbx = np.concatenate([np.tile(lo_x / STATE_SCALE, n + 1), np.zeros(n)])
        ubx = np.concatenate([np.tile(hi_x / STATE_SCALE, n + 1), np.zeros(n)])
        lbx[nx:] = setup.limits.low
        ubx[nx:] = setup.limits.high
        ng = N_STATES * (n + 1)
        self._bounds = {
            "lbx": lbx,
            "ubx": ubx,
            "lbg": np.concatenate([np.zeros(ng), np.full(n, -cap)]),
            "ubg": np.concatenate([np.zeros(ng), np.full(n, cap)]),
        }
        self._n, self._nx = n, nx
        self._F = F
        self._built_for = (id(setup), n)

    def reset(self, setup: LoopSetup) -> None:
        super().reset(setup)
        self._warm = None
        self.failures = 0

    def _solve(self, time_s: float, knots: np.ndarray) -> float:
        s, est = self.setup, self.estimator
        n = knots.size - 1
        if self._built_for != (id(s), n):
            self._build(s, n)
            self._warm = None
        gg, tgi, q, fan = s.model_inputs(knots[:-1], np.zeros(n))
        u_prev = self.u_last if self.u_last is not None else s.u_initial
        params = np.concatenate(
            [est.state, s.reference_at(knots), [u_prev, est.disturbance_C], np.stack([gg, tgi, q, fan]).T.ravel()]
        )
        args = dict(self._bounds, p=params)
        if self._warm is None:  # cold start: the input held, the states simulated along it
            u_guess = np.full(n, u_prev)
            xs = [est.state]
            for k in range(n):
                uk = np.array([gg[k], tgi[k], q[k], fan[k]])
                uk[1 if s.limits.decide == "Tgi" else 2] = u_prev
                uk[1] += est.disturbance_C
                xs.append(np.array(self._F(xs[-1], uk)).ravel())
            args["x0"] = np.concatenate([(np.array(xs) / STATE_SCALE).ravel(), u_guess])
        else:
            z, lam_x, lam_g = self._warm
            xs = z[: self._nx].reshape(n + 1, N_STATES)
            us = z[self._nx :]
            xs = np.vstack([xs[1:], xs[-1:]])
            xs[0] = est.state / STATE_SCALE
            args["x0"] = np.concatenate([xs.ravel(), np.append(us[1:], us[-1])])
            args["lam_x0"], args["lam_g0"] = lam_x, lam_g
        sol = self._solver(**args)
        z = np.array(sol["x"]).ravel()
        ok = self._solver.stats()["success"]
        self.failures += not ok
        # warm-start the next solve from a solution, never from a failed solve's iterates
        self._warm = (z, np.array(sol["lam_x"]).ravel(), np.array(sol["lam_g"]).ravel()) if ok else None
        return float(np.clip(z[self._nx], s.limits.low, s.limits.high))
