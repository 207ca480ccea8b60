"""The RLS core and Welford's variance against independent references."""

import numpy as np
import pytest
from reference_rls_arx import Welford

from alfa_bench.methods.rls import RecursiveLeastSquares


def regression(n=400, p=5, seed=0):
    rng = np.random.default_rng(seed)
    phi = rng.normal(size=(n, p))
    theta = rng.normal(size=p)
    return phi, phi @ theta + rng.normal(0, 0.1, n), theta


def run(phi, y, **kw):
    rls = RecursiveLeastSquares(phi.shape[1], **kw).reset()
    errors = np.array([rls.update(ph, yy) for ph, yy in zip(phi, y, strict=True)])
    return rls, errors


@pytest.mark.parametrize("p0", [1.0, 1e3, 1e6])
def test_rls_equals_ridge_solution_at_every_step(p0):
    """With lambda = 1, theta(k) = (Phi'Phi + I/p0)^-1 Phi'y over the first k rows."""
    phi, y, _ = regression()
    rls = RecursiveLeastSquares(phi.shape[1], p0=p0).reset()
    for k in range(phi.shape[0]):
        rls.update(phi[k], y[k])
        if k in (0, 4, 50, 399):
            a = phi[:k + 1].T @ phi[:k + 1] + np.eye(phi.shape[1]) / p0
            ref = np.linalg.solve(a, phi[:k + 1].T @ y[:k + 1])
            np.testing.assert_allclose(rls.theta_, ref, rtol=1e-8, atol=1e-10)
            np.testing.assert_allclose(rls.P_, np.linalg.inv(a), rtol=1e-6, atol=1e-12)


def test_rls_matches_statsmodels_recursive_ls():
    sm = pytest.importorskip("statsmodels.api")
    phi, y, _ = regression()
    rls, errors = run(phi, y, p0=1e8)
    res = sm.RecursiveLS(y, phi).fit()
    filtered = res.recursive_coefficients.filtered.T
    # after the diffuse start both are the least-squares estimate of the rows so far
    np.testing.assert_allclose(rls.theta_, filtered[-1], rtol=1e-6)
    np.testing.assert_allclose(errors[50:], (y - np.einsum("ij,ij->i", phi,
                               np.vstack([filtered[:1], filtered[:-1]])))[50:], atol=1e-6)


def test_a_priori_error_and_gain_are_kept():
    phi, y, _ = regression(n=3)
    rls = RecursiveLeastSquares(phi.shape[1], p0=10.0).reset()
    e = rls.update(phi[0], y[0])
    assert e == rls.error_ == pytest.approx(y[0])  # theta(0) = 0
    np.testing.assert_allclose(rls.step_, rls.K_ * e)
    np.testing.assert_allclose(rls.K_, 10 * phi[0] / (1 + 10 * phi[0] @ phi[0]))


def test_forgetting_validated():
    with pytest.raises(ValueError, match="forgetting"):
        RecursiveLeastSquares(2, forgetting=1.5).reset()


def test_welford_matches_numpy():
    x = np.random.default_rng(3).normal(5.0, 2.0, 1000)
    w = Welford()
    for v in x:
        w.update(v)
    assert w.n_ == 1000
    assert w.mean_ == pytest.approx(x.mean(), rel=1e-12)
    assert w.variance == pytest.approx(x.var(ddof=1), rel=1e-10)
    assert np.isnan(Welford().variance)
