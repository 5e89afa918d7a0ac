"""The Monte Carlo's building blocks against closed forms: the tolerance distributions'
quantile functions (moments, truncation) and the exceedance interval (Clopper-Pearson at k = 0
and k = n, where it has a closed form)."""

import math

import numpy as np
import pytest

from gearrattle.study import designs, spec
from gearrattle.study.distributions import parse_dist
from gearrattle.study.montecarlo import exceedance

U = (np.arange(200_000) + 0.5) / 200_000  # a fine midpoint grid of (0, 1): quadrature of E[X]


@pytest.mark.parametrize("text, mean, sd", [
    ("x=normal:25e-6:2e-6", 25e-6, 2e-6),
    ("x=uniform:0.02:0.03", 0.025, 0.01 / math.sqrt(12)),
    ("x=lognormal:0.32e-3:0.02e-3", 0.32e-3, 0.02e-3),  # the value's mean and SD, not its log's
])
def test_quantile_functions_have_the_requested_moments(text, mean, sd):
    x = parse_dist(text, "test").ppf(U)
    assert abs(x.mean() - mean) < 1e-4 * sd
    assert abs(x.std() - sd) < 1e-3 * sd


def test_truncated_normal_stays_in_its_band():
    d = parse_dist("G=truncnormal:25e-6:5e-6:20e-6:30e-6", "test")
    x = d.ppf(U)
    assert x.min() >= 20e-6 and x.max() <= 30e-6
    assert abs(np.median(x) - 25e-6) < 1e-12
    assert d.support() == (20e-6, 30e-6)


def test_sobol_design_has_saltelli_size_and_the_distributions_range():
    st = spec.Study(kind="mc", fmu="", out="", n=16, sensitivity="sobol")
    st.dists = [parse_dist("G=uniform:20e-6:30e-6", "t"), parse_dist("C=normal:0.025:0.002", "t")]
    pts = designs.points(st)
    assert len(pts) == 16 * (2 + 2)
    g = np.array([p["G"] for p in pts])
    assert g.min() >= 20e-6 and g.max() <= 30e-6


@pytest.mark.parametrize("n", [10, 200])
def test_clopper_pearson_interval_at_the_ends(n):
    alpha = 0.05
    p, lo, hi = exceedance(0, n)
    assert p == 0 and lo == 0
    assert hi == pytest.approx(1 - (alpha / 2) ** (1 / n), rel=1e-9)
    p, lo, hi = exceedance(n, n)
    assert p == 1 and hi == 1
    assert lo == pytest.approx((alpha / 2) ** (1 / n), rel=1e-9)
