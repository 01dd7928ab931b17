"""jetfit.fit_jet on one neighbourhood: exact on an analytic surface, and
equal bit for bit to estimate's row on the same neighbourhood."""
import numpy as np
import pytest

import jetfit
from conftest import fib_sphere


def test_paraboloid_exact():
    # z = (k1 x^2 + k2 y^2)/2 + (b0 x^3 + 3 b1 x^2 y + 3 b2 x y^2 + b3 y^3)/6
    k1, k2, b = 2.0, -1.0, (0.3, -0.2, 0.1, 0.4)
    g = np.linspace(-0.1, 0.1, 7)
    x, y = [a.ravel() for a in np.meshgrid(g, g)]
    z = (k1 * x**2 + k2 * y**2) / 2 + (b[0] * x**3 + 3 * b[1] * x**2 * y
                                       + 3 * b[2] * x * y**2 + b[3] * y**3) / 6
    nb = np.stack([x, y, z], 1)
    nb = nb[np.argsort(x**2 + y**2, kind="stable")]  # the point (0,0,0) first
    j = jetfit.fit_jet(nb, 3, frame="axis")
    assert j.status == 0 and j.degree == 3 and j.neighbors == 49
    assert j.k1 == pytest.approx(k1, abs=1e-9) and j.k2 == pytest.approx(k2, abs=1e-9)
    assert np.allclose(j.normal, [0, 0, 1], atol=1e-12)
    assert np.allclose(j.b, b, atol=1e-8)
    assert j.c is None
    assert j.residual < 1e-12


def test_equals_estimate_row():
    p = fib_sphere(2000) + np.random.default_rng(3).normal(0, 1e-3, (2000, 3))
    r = jetfit.estimate(p, neighbors="knn:16", degree=3)
    for i in (0, 777, 1999):
        d2 = ((p - p[i]) ** 2).sum(1)
        idx = np.lexsort((np.arange(len(p)), d2))[:16]  # (distance, index) order
        j = jetfit.fit_jet(p[idx], 3, point=p[i])
        assert j.k1 == r.k1[i] and j.k2 == r.k2[i] and j.cond == r.cond[i]
        assert np.array_equal(j.normal, r.normal[i]) and np.array_equal(j.b, r.b[i])


def test_weights_and_errors():
    nb = fib_sphere(30)
    a = jetfit.fit_jet(nb, 2)
    w = jetfit.fit_jet(nb, 2, weights=np.ones(30))
    assert w.k1 == pytest.approx(a.k1, rel=1e-12)
    with pytest.raises(ValueError, match="weights: 29 values for 30 neighbours"):
        jetfit.fit_jet(nb, 2, weights=np.ones(29))
    with pytest.raises(ValueError, match="weights: expected finite values >= 0"):
        jetfit.fit_jet(nb, 2, weights=-np.ones(30))
    with pytest.raises(ValueError, match="^degree=10: expected an integer 1..9$"):
        jetfit.fit_jet(nb, 10)
    few = jetfit.fit_jet(nb[:2], 2)
    assert few.status & jetfit.STATUS["failed"] and np.isnan(few.k1)
