r"""Compiled (numba) kernels of the per-sample recursions.

Each kernel advances a recursion over a block of steps, holding its whole state in
arrays that the caller owns, so the same code can serve streaming (a block of one
step) and batch runs (a whole flight). The arithmetic is that of the plain per-sample
implementations it replaces (the detectors' stepwise ``update()``, and the reference
RLS-ARX detector in ``tests/reference_rls_arx.py``); only the order of the sums in
the dot products differs, so results agree to rounding (the tests bound it).

:func:`rls_update` is one RLS step, eqs. (4)-(7) of :mod:`.rls`.
:func:`rls_arx_advance` runs one RLS-ARX z-score pair (:mod:`.rls_arx_zscore`);
:func:`glrt_advance` the windowed GLRT (:mod:`.glrt`); :func:`kalman_innovations` a
steady-state Kalman filter (:mod:`.kalman_okid`); :func:`ffrls_advance` one model of
the forgetting-factor RLS monitor (:mod:`.ffrls_monitor`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["ARX_FLOATS", "ARX_INTS", "ffrls_advance", "glrt_advance", "kalman_innovations",
           "rls_arx_advance", "rls_update"]

# slots of the integer state of an RLS-ARX pair
K, UPDATES, N_U, N_Y, STREAK_FROM, MODEL_STABLE, VAR_FROM, VAR_STABLE, W_N = range(9)
ARX_INTS = 9
# slots of its float state
W_MEAN, W_M2, LAST_VAR = range(3)
ARX_FLOATS = 3


@njit(cache=True)
def rls_update(theta, cov, phi, y, lam, max_trace, c_phi, gain):
    """One RLS step in place on ``theta`` and ``cov``; returns :math:`\\hat e(k)` and
    leaves :math:`L(k)` in ``gain`` (``c_phi`` is workspace)."""
    n = theta.size
    e = y
    for i in range(n):
        e -= phi[i] * theta[i]                         # (4) e = y - phi' theta
    denom = lam
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += cov[i, j] * phi[j]
        c_phi[i] = s
        denom += phi[i] * s
    for i in range(n):
        gain[i] = c_phi[i] / denom                     # (5) L = C phi / (lam + phi' C phi)
        theta[i] += gain[i] * e                        # (6) theta += L e
    trace = 0.0
    for i in range(n):
        for j in range(i, n):                          # (7) C = (C - L phi' C) / lam, symmetric
            a = (cov[i, j] - gain[i] * c_phi[j]) / lam
            b = (cov[j, i] - gain[j] * c_phi[i]) / lam
            cov[i, j] = cov[j, i] = 0.5 * (a + b)
        trace += cov[i, i]
    if trace > max_trace:
        scale = max_trace / trace                      # tr C <= max_trace: no wind-up
        for i in range(n):
            for j in range(n):
                cov[i, j] *= scale
    return e


@njit(cache=True)
def rls_arx_advance(u, y, fresh, ints, floats, theta, cov, ubuf, ybuf, phi, c_phi, gain,
                    na, warmup, eps, stable_steps, var_rtol, var_steps, fresh_only,
                    z, prediction, residual, judged):
    """Advance one RLS-ARX z-score pair over the steps of ``u``, ``y``, ``fresh``.

    Writes per step the z-score (NaN until both stability flags latch), the
    prediction :math:`y - \\hat e` and residual :math:`\\hat e` of an RLS update (NaN
    without one), and ``judged``: :math:`\\hat e` when the model was already stable.
    """
    nb = ubuf.size
    ny_max = ybuf.size
    for i in range(u.size):
        k = ints[K]
        ints[K] += 1
        z[i] = prediction[i] = residual[i] = judged[i] = np.nan
        for j in range(nb - 1, 0, -1):                # phi's inputs: u(k), ..., u(k-nb+1)
            ubuf[j] = ubuf[j - 1]
        ubuf[0] = u[i]
        ints[N_U] = min(ints[N_U] + 1, nb)
        if fresh_only and not fresh[i]:
            continue
        if ints[N_U] < nb or ints[N_Y] < na:
            _push_output(ybuf, ints, y[i], ny_max)
            continue
        for j in range(na):
            phi[j] = ybuf[j]
        for j in range(nb):
            phi[na + j] = ubuf[j]
        was_stable = ints[MODEL_STABLE] == 1
        e = rls_update(theta, cov, phi, y[i], 1.0, np.inf, c_phi, gain)
        prediction[i], residual[i] = y[i] - e, e
        _push_output(ybuf, ints, y[i], ny_max)
        ints[UPDATES] += 1
        if not was_stable:
            big = 0.0
            for j in range(theta.size):
                big = max(big, abs(gain[j] * e))      # ||L e||_inf
            if big < eps:
                if ints[STREAK_FROM] < 0:
                    ints[STREAK_FROM] = k
            else:
                ints[STREAK_FROM] = -1
            if (ints[STREAK_FROM] >= 0 and ints[UPDATES] >= warmup
                    and k - ints[STREAK_FROM] >= stable_steps):
                ints[MODEL_STABLE] = 1
            continue
        judged[i] = e
        n = ints[W_N]
        if ints[VAR_STABLE] == 1:                      # z with the statistics before e
            var = floats[W_M2] / (n - 1) if n > 1 else np.nan
            dev = abs(e - floats[W_MEAN])
            if var > 0:
                z[i] = dev / math.sqrt(var)
            else:
                z[i] = np.inf if dev != 0 else 0.0
        n += 1                                         # Welford, eq. (8)
        ints[W_N] = n
        delta = e - floats[W_MEAN]
        floats[W_MEAN] += delta / n
        floats[W_M2] += delta * (e - floats[W_MEAN])
        var = floats[W_M2] / (n - 1) if n > 1 else np.nan
        if ints[VAR_STABLE] == 0 and n > 2:
            if abs(var - floats[LAST_VAR]) <= var_rtol * floats[LAST_VAR]:
                if ints[VAR_FROM] < 0:
                    ints[VAR_FROM] = k
            else:
                ints[VAR_FROM] = -1
            if ints[VAR_FROM] >= 0 and k - ints[VAR_FROM] >= var_steps:
                ints[VAR_STABLE] = 1
        floats[LAST_VAR] = var


@njit(cache=True)
def _push_output(ybuf, ints, value, ny_max):
    for j in range(ny_max - 1, 0, -1):
        ybuf[j] = ybuf[j - 1]
    ybuf[0] = value
    ints[N_Y] = min(ints[N_Y] + 1, ny_max)


@njit(cache=True)
def glrt_advance(x, buf, count, sigma2, g):
    """The windowed GLRT :math:`g(k)` of eq. (3) of :mod:`.glrt` over the steps of ``x``
    (NaN steps are skipped and give NaN). ``buf`` holds the last :math:`M` values,
    newest first, ``count[0]`` how many are held; sums run newest first, as
    :class:`~.glrt.WindowedGlrt` sums them."""
    m = buf.size
    for i in range(x.size):
        if not math.isfinite(x[i]):
            g[i] = np.nan
            continue
        for j in range(m - 1, 0, -1):
            buf[j] = buf[j - 1]
        buf[0] = x[i]
        count[0] = min(count[0] + 1, m)
        s = 0.0
        best = -np.inf
        for n in range(1, count[0] + 1):
            s += buf[n - 1]                            # sum_{i=j}^{k} x(i), j = k - n + 1
            best = max(best, s * s / (2.0 * sigma2 * n))
        g[i] = best


@njit(cache=True)
def kalman_innovations(a, b, c, d, k, u, y, skip, x, e):
    """Innovations of a steady-state Kalman filter with one output, over the steps of
    ``u`` (shape (n, m)) and ``y`` (n,), from the state ``x`` (updated in place):

    .. math::

        e(k) = y(k) - D u(k) - C \\hat x(k), \\qquad
        \\hat x(k+1) = A\\,(\\hat x(k) + K e(k)) + B u(k).

    The first ``skip`` innovations (the observer's start-up) are NaN."""
    nx = x.size
    post = np.empty(nx)
    for i in range(u.shape[0]):
        ei = y[i]
        for j in range(u.shape[1]):
            ei -= d[0, j] * u[i, j]
        for j in range(nx):
            ei -= c[0, j] * x[j]
        e[i] = ei if i >= skip else np.nan
        for j in range(nx):
            post[j] = x[j] + k[j, 0] * ei             # x(k|k) = x(k|k-1) + K e(k)
        for r in range(nx):
            acc = 0.0
            for j in range(nx):
                acc += a[r, j] * post[j]
            for j in range(u.shape[1]):
                acc += b[r, j] * u[i, j]
            x[r] = acc                                 # x(k+1|k) = A x(k|k) + B u(k)


@njit(cache=True)
def ffrls_advance(u, y, ar, theta, cov, lam, max_trace, c_phi, gain, y_prev, thetas, n_thetas,
                  res_mean, sigma2, glrt_buf, glrt_count, info, gamma_r_joint,
                  gamma_theta_joint, freeze, frozen, eps, dtheta, g, t, joint):
    """Advance one FF-RLS model of :mod:`.ffrls_monitor` over the steps of ``u``
    (normalised deflections, shape (n, m)) and ``y`` (the rate).

    State, updated in place: ``theta``, ``cov``, ``y_prev[0]`` (the last rate),
    ``thetas`` (the last :math:`M + 1` estimates, newest first) and ``n_thetas[0]``,
    the GLRT's ``glrt_buf``/``glrt_count``, and ``frozen[0]``. With ``freeze``,
    adaptation stops while :math:`g > \\gamma_r'`. Per step it writes the prediction
    error ``eps``, and once the window is full ``dtheta`` (:math:`\\hat\\theta(k) -
    \\hat\\theta(k-M)`), the GLRT ``g``, ``t`` (:math:`T`) and ``joint``; NaN before.
    """
    n_par = theta.size
    keep = thetas.shape[0]
    phi = np.empty(n_par)
    one = np.empty(1)
    g_one = np.empty(1)
    for i in range(u.shape[0]):
        eps[i] = g[i] = t[i] = joint[i] = np.nan
        dtheta[i, :] = np.nan
        previous = y_prev[0]
        y_prev[0] = y[i]
        if ar and not math.isfinite(previous):
            continue
        for j in range(u.shape[1]):
            phi[j] = u[i, j]
        if ar:
            phi[u.shape[1]] = previous
        phi[n_par - 1] = 1.0
        if frozen[0]:
            e = y[i]
            for j in range(n_par):
                e -= phi[j] * theta[j]                 # (14) with theta held
        else:
            e = rls_update(theta, cov, phi, y[i], lam, max_trace, c_phi, gain)  # (14)-(16)
        eps[i] = e
        for r in range(keep - 1, 0, -1):
            thetas[r, :] = thetas[r - 1, :]
        thetas[0, :] = theta
        n_thetas[0] = min(n_thetas[0] + 1, keep)
        if n_thetas[0] < keep:
            continue
        for j in range(n_par):
            dtheta[i, j] = thetas[0, j] - thetas[keep - 1, j]  # theta(k) - theta(k - M)
        one[0] = e - res_mean
        glrt_advance(one, glrt_buf, glrt_count, sigma2, g_one)
        g[i] = g_one[0]
        tt = 0.0
        for a in range(n_par):
            for b in range(n_par):
                tt += dtheta[i, a] * info[a, b] * dtheta[i, b]  # T = dtheta' Sigma^-1 dtheta
        t[i] = tt
        if freeze:
            frozen[0] = g[i] > gamma_r_joint           # stop adapting while residual test is up
        joint[i] = min(g[i] / gamma_r_joint, tt / gamma_theta_joint)
