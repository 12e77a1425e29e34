import numpy as np
import pytest
from conftest import central_fd

from flipkit.model.bezier import Bezier
from flipkit.errors import ConfigError, FlipkitError


@pytest.fixture
def alpha():
    return np.random.default_rng(0).normal(size=(6, 7))


def test_endpoints_and_partition_of_unity(alpha):
    b, T = Bezier(), 0.8
    np.testing.assert_allclose(b.evaluate(alpha, [0.0], T)[0], alpha[:, 0])
    np.testing.assert_allclose(b.evaluate(alpha, [T], T)[0], alpha[:, -1])
    np.testing.assert_allclose(b.basis(np.linspace(0, 1, 11)).sum(1), 1.0)
    # binomial coefficients: B_3(1/2) = C(6,3)/2^6
    assert b.basis([0.5])[0, 3] == pytest.approx(20 / 64)


def test_endpoint_derivatives(alpha):
    b, T = Bezier(), 1.3
    np.testing.assert_allclose(b.evaluate(alpha, [0.0], T, 1)[0], 6 * (alpha[:, 1] - alpha[:, 0]) / T)
    np.testing.assert_allclose(b.evaluate(alpha, [T], T, 1)[0], 6 * (alpha[:, 6] - alpha[:, 5]) / T)
    np.testing.assert_allclose(b.evaluate(alpha, [0.0], T, 2)[0],
                               30 * (alpha[:, 2] - 2 * alpha[:, 1] + alpha[:, 0]) / T**2)


@pytest.mark.parametrize("deriv", [0, 1, 2])
def test_time_and_duration_derivatives(alpha, deriv):
    b, T = Bezier(), 0.9
    t = np.linspace(0, T, 7)
    if deriv < 2:
        num = central_fd(lambda x: b.evaluate(alpha, x, T, deriv)[:, 2], t)
        np.testing.assert_allclose(np.diag(num), b.evaluate(alpha, t, T, deriv + 1)[:, 2], atol=1e-6)
    dT = central_fd(lambda x: b.evaluate(alpha, t, x[0], deriv), np.array([T]))[..., 0]
    np.testing.assert_allclose(b.d_dT(alpha, t, T, deriv), dT, atol=1e-5, rtol=1e-6)
    # linear in alpha: basis times alpha reproduces evaluate
    np.testing.assert_allclose(b.basis(t / T, deriv) @ alpha.T / T**deriv,
                               b.evaluate(alpha, t, T, deriv))


def test_invalid_degree_and_order():
    with pytest.raises(FlipkitError, match="degree"):
        Bezier(0)
    with pytest.raises(ConfigError, match="0..6"):
        Bezier().basis([0.1], 7)
