"""OKID/ERA on a known system, and the filterpy Kalman filter against control.dlqe."""

import control
import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

from alfa_bench.data import Sampled
from alfa_bench.methods.kalman_okid import KalmanOkid
from alfa_bench.methods.okid import okid

A = np.array([[0.9, 0.2], [-0.2, 0.8]])
B = np.array([[1.0], [0.5]])
C = np.array([[1.0, 0.0]])
D = np.array([[0.1]])
Q = np.eye(2) * 0.01
R = np.array([[0.04]])


def simulate(n, seed):
    rng = np.random.default_rng(seed)
    u = rng.normal(size=(n, 1))
    x, y = np.zeros(2), np.zeros((n, 1))
    for k in range(n):
        y[k] = C @ x + D @ u[k] + rng.normal(0, np.sqrt(R[0, 0]))
        x = A @ x + B @ u[k] + rng.multivariate_normal([0, 0], Q)
    return u, y


def markov(a, b, c, k):
    return (c @ np.linalg.matrix_power(a, k) @ b).ravel()


def test_filterpy_steady_state_gain_is_dlqe_predictor_gain():
    L, _, _ = control.dlqe(A, np.eye(2), C, Q, R)
    kf = KalmanFilter(dim_x=2, dim_z=1)
    kf.F, kf.H, kf.Q, kf.R = A, C, Q, R
    for _ in range(500):
        kf.predict()
        kf.update(np.zeros(1))
    np.testing.assert_allclose(A @ kf.K, L, rtol=1e-6)   # python-control's L = A K


def test_okid_reproduces_the_system_and_kalman_gain_markov_parameters():
    L, _, _ = control.dlqe(A, np.eye(2), C, Q, R)
    m = okid([simulate(20_000, 0)], lags=20, order=2)
    np.testing.assert_allclose(m.D, D, atol=0.01)
    for k in range(5):
        np.testing.assert_allclose(markov(m.A, m.B, m.C, k), markov(A, B, C, k), atol=0.02)
        np.testing.assert_allclose(markov(m.A, m.L, m.C, k), markov(A, L, C, k), atol=0.02)
    assert m.hankel_sv[1] > 10 * m.hankel_sv[2]                # the order shows in the SVD


def sampled(u, y):
    x = np.c_[u, y]
    return Sampled(t=np.arange(len(x)) / 25.0, x=x, fresh=np.ones_like(x, dtype=bool),
                   names=("roll_cmd", "roll"))


def test_kalman_okid_innovations_are_white_and_calibrated_under_no_fault():
    det = KalmanOkid(inputs=("roll_cmd",), outputs=("roll",), lags_s=0.8, order=2)
    det.fit([sampled(*simulate(10_000, seed)) for seed in (1, 2)])
    s = sampled(*simulate(20_000, 3))
    e = []
    det.reset()
    for x, f in zip(s.x, s.fresh, strict=True):
        det.update(x, f)
        e.append(det.filters_[0].y[0, 0])
    e = np.array(e[det._lags():])
    e = (e - e.mean()) / e.std()
    acf = [np.mean(e[:-k] * e[k:]) for k in range(1, 11)]
    assert np.max(np.abs(acf)) < 4 / np.sqrt(e.size)
    # innovation variance = C P C' + R of the true steady-state filter
    _, P, _ = control.dlqe(A, np.eye(2), C, Q, R)
    assert det.innovation_var_[0] == pytest.approx((C @ P @ C.T + R)[0, 0], rel=0.1)


def test_kalman_okid_alarms_on_a_stuck_sensor():
    det = KalmanOkid(inputs=("roll_cmd",), outputs=("roll",), lags_s=0.8, order=2)
    det.fit([sampled(*simulate(10_000, seed)) for seed in (4, 5)])
    u, y = simulate(2000, 6)
    y[1000:] = y[1000]                                         # stuck at its last value
    s = sampled(u, y)
    det.reset()
    alarms = np.array([det.alarms(det.update(x, f))[0] for x, f in zip(s.x, s.fresh, strict=True)])
    assert not alarms[100:1000].mean() > 0.01
    assert alarms[1000:1100].any()
