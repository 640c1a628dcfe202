"""Metrics against values computed by hand on a tiny example."""

import math

import numpy as np
import pytest

from roastlab.evaluate.metrics import absolute_error_moments, average_metrics, batch_metrics

# Y = [100, 200, 300], Yhat = [110, 190, 300]: e = [-10, 10, 0]
Y = [100.0, 200.0, 300.0]
YHAT = [110.0, 190.0, 300.0]


def test_hand_computed_values():
    m = batch_metrics(Y, YHAT)
    assert m["n"] == 3
    assert m["SSR"] == pytest.approx(200.0)  # 100 + 100 + 0
    assert m["norm"] == pytest.approx(math.sqrt(200.0))
    assert m["MAE"] == pytest.approx(20.0 / 3.0)
    assert m["MPE"] == pytest.approx(100.0 / 3.0 * (-10 / 100 + 10 / 200 + 0))  # -1.6667 %
    assert m["MAPE"] == pytest.approx(100.0 / 3.0 * (10 / 100 + 10 / 200))  # 5 %
    # ||Y - mean|| = sqrt(100^2 + 0 + 100^2) = 141.42; FIT = 100 (1 - 14.142 / 141.42) = 90 %
    assert m["FIT"] == pytest.approx(90.0)
    # rho: Yhat - mean = [-90, -10, 100]; Y - mean = [-100, 0, 100]
    num = 9000 + 0 + 10000
    den = math.sqrt(20000) * math.sqrt(8100 + 100 + 10000)
    assert m["rho"] == pytest.approx(num / den)


def test_perfect_fit_and_average():
    perfect = batch_metrics(Y, Y)
    assert perfect["SSR"] == 0 and perfect["FIT"] == 100 and perfect["rho"] == pytest.approx(1.0)
    avg = average_metrics([perfect, batch_metrics(Y, YHAT)])
    assert avg["n"] == 6 and avg["FIT"] == pytest.approx(95.0) and avg["SSR"] == pytest.approx(100.0)


def test_absolute_error_moments():
    em = absolute_error_moments([np.array([-1.0, 1.0]), np.array([3.0])])
    assert em["mean_abs_error"] == pytest.approx(5 / 3)
    assert em["var_abs_error"] == pytest.approx(np.var([1, 1, 3], ddof=1))


def test_mean_gap_is_welchs_interval_by_hand():
    """The gap's interval against Welch's formula written out: means 3 and 4, variances 2.5 and 4,
    se = sqrt(2.5/5 + 4/3), Satterthwaite dof = se^4 / ((2.5/5)^2/4 + (4/3)^2/2) = 3.533."""
    from scipy.stats import t

    from roastlab.evaluate.metrics import mean_gap

    g = mean_gap([1, 2, 3, 4, 5], [2, 4, 6], level=0.9)
    se = np.sqrt(2.5 / 5 + 4 / 3)
    dof = se**4 / ((2.5 / 5) ** 2 / 4 + (4 / 3) ** 2 / 2)
    assert dof == pytest.approx(3.533, abs=1e-3)
    half = t.ppf(0.95, dof) * se
    assert g["gap"] == -1.0 and (g["n"], g["n_reference"]) == (5, 3)
    assert (g["se"], g["dof"]) == pytest.approx((se, dof))
    assert (g["low"], g["high"]) == pytest.approx((-1.0 - half, -1.0 + half))
    # a wider level, a wider interval; one log alone has no spread to say how far it pins the gap
    assert mean_gap([1, 2, 3, 4, 5], [2, 4, 6], level=0.99)["low"] < g["low"]
    one = mean_gap([70.0], [80.0, 82.0])
    assert one["gap"] == -11.0 and np.isnan(one["low"]) and np.isnan(one["high"])
    with pytest.raises(ValueError):
        mean_gap([], [1.0])
