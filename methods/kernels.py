r"""Compiled (numba) kernels of the per-sample recursions.

Each kernel advances a recursion over a block of steps, holding its whole state in
arrays that the caller owns, so the same code can serve streaming (a block of one
step) and batch runs (a whole flight). The arithmetic is that of the plain per-sample
implementations it replaces (the detectors' stepwise ``update()``, and the reference
RLS-ARX detector in ``tests/reference_rls_arx.py``); only the order of the sums in
the dot products differs, so results agree to rounding (the tests bound it).

Names are filterpy's: ``x`` a filter's state, ``P`` a covariance, ``K`` a gain,
``y`` an innovation (residual), ``S`` its variance; the RLS estimate is ``theta`` and
its regressor ``phi``, as in the papers. A kernel's state is a few arrays, not one
argument per variable: ``config`` (hyper-parameters), ``counts`` (integers) and
``state`` (floats), with named slots below; :func:`arx_views` and
:func:`ffrls_views` cut ``state`` into its named parts, in the kernel and for the
detector that owns it alike. Outputs are one row per quantity of ``out``.

:func:`rls_update` is one RLS step, eqs. (4)-(7) of :mod:`.rls`.
:func:`rls_arx_advance` runs one RLS-ARX z-score pair (:mod:`.rls_arx_zscore`);
:func:`glrt_advance` the windowed GLRT (:mod:`.glrt`); :func:`kalman_innovations` a
steady-state Kalman filter (:mod:`.kalman_okid`); :func:`ffrls_advance` one model of
the forgetting-factor RLS monitor (:mod:`.ffrls_monitor`).
"""

from __future__ import annotations

import math
from enum import IntEnum

import numpy as np
from numba import njit

__all__ = ["ArxConfig", "ArxCount", "ArxOut", "ArxStat", "FfrlsConfig", "FfrlsCount",
           "FfrlsOut", "arx_state_size", "arx_views", "ffrls_advance",
           "ffrls_state_size", "ffrls_views", "glrt_advance", "kalman_innovations",
           "rls_arx_advance", "rls_update"]


class ArxConfig(IntEnum):
    """Slots of an RLS-ARX pair's ``config`` (integers stored as floats)."""
    NA, NB, WARMUP, EPS, STABLE_STEPS, VAR_RTOL, VAR_STEPS, FRESH_ONLY = range(8)


class ArxCount(IntEnum):
    """Slots of an RLS-ARX pair's ``counts``."""
    STEP, UPDATES, N_U, N_Y, STREAK_FROM, MODEL_STABLE, VAR_FROM, VAR_STABLE, W_N = range(9)


class ArxStat(IntEnum):
    """Slots of Welford's statistics, the ``stats`` part of an RLS-ARX pair's state."""
    MEAN, M2, LAST_VAR = range(3)


class ArxOut(IntEnum):
    """Rows of :func:`rls_arx_advance`'s ``out``."""
    Z, PREDICTION, RESIDUAL, JUDGED = range(4)


class FfrlsConfig(IntEnum):
    """Slots of an FF-RLS model's ``config``: hyper-parameters and fitted statistics."""
    AR, LAM, MAX_TRACE, RES_MEAN, SIGMA2, GAMMA_R_JOINT, GAMMA_THETA_JOINT, FREEZE, M = range(9)


class FfrlsCount(IntEnum):
    """Slots of an FF-RLS model's ``counts``."""
    N_THETAS, GLRT_COUNT, FROZEN = range(3)


class FfrlsOut(IntEnum):
    """Rows of :func:`ffrls_advance`'s ``out``."""
    EPS, G, T, JOINT = range(4)


_N_STATS = len(ArxStat)


def arx_state_size(na, nb):
    """Length of an RLS-ARX pair's ``state`` for :math:`n_a`, :math:`n_b`."""
    n = na + nb
    return n + n * n + nb + max(na, 1) + 3 * n + _N_STATS


@njit(cache=True)
def arx_views(state, na, nb):
    """``state`` cut into ``theta, P, u_hist, y_hist, phi, P_phi, K, stats``:
    :math:`\\hat\\theta`, its covariance, the last :math:`n_b` inputs and :math:`n_a`
    outputs (newest first), the regressor, :math:`P\\phi`, the gain, Welford's
    statistics."""
    n = na + nb
    ny = max(na, 1)
    o = 0
    theta = state[o:o + n]
    o += n
    P = state[o:o + n * n].reshape((n, n))
    o += n * n
    u_hist = state[o:o + nb]
    o += nb
    y_hist = state[o:o + ny]
    o += ny
    phi = state[o:o + n]
    P_phi = state[o + n:o + 2 * n]
    K = state[o + 2 * n:o + 3 * n]
    stats = state[o + 3 * n:o + 3 * n + _N_STATS]
    return theta, P, u_hist, y_hist, phi, P_phi, K, stats


@njit(cache=True)
def rls_update(theta, P, phi, y, lam, max_trace, P_phi, K):
    """One RLS step in place on ``theta`` and ``P``; returns :math:`\\hat e(k)` and
    leaves :math:`K(k)` in ``K`` (``P_phi`` is workspace)."""
    n = theta.size
    e = y
    for i in range(n):
        e -= phi[i] * theta[i]                         # (4) e = y - phi' theta
    S = lam
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += P[i, j] * phi[j]
        P_phi[i] = s
        S += phi[i] * s                                # S = lam + phi' P phi
    for i in range(n):
        K[i] = P_phi[i] / S                            # (5) K = P phi / S
        theta[i] += K[i] * e                           # (6) theta += K e
    trace = 0.0
    for i in range(n):
        for j in range(i, n):                          # (7) P = (P - K phi' P) / lam, symmetric
            a = (P[i, j] - K[i] * P_phi[j]) / lam
            b = (P[j, i] - K[j] * P_phi[i]) / lam
            P[i, j] = P[j, i] = 0.5 * (a + b)
        trace += P[i, i]
    if trace > max_trace:
        scale = max_trace / trace                      # tr P <= max_trace: no wind-up
        for i in range(n):
            for j in range(n):
                P[i, j] *= scale
    return e


@njit(cache=True)
def rls_arx_advance(u, y, fresh, config, counts, state, out):
    """Advance one RLS-ARX z-score pair over the steps of ``u``, ``y``, ``fresh``.

    ``config`` holds the :class:`ArxConfig` hyper-parameters, ``counts`` and ``state`` the
    pair's state (:func:`arx_views`). Writes per step, in the rows of ``out``: the
    z-score (NaN until both stability flags latch), the prediction :math:`y - \\hat e`
    and residual :math:`\\hat e` of an RLS update (NaN without one), and ``judged``:
    :math:`\\hat e` when the model was already stable.
    """
    na, nb = int(config[ArxConfig.NA]), int(config[ArxConfig.NB])
    warmup, eps = int(config[ArxConfig.WARMUP]), config[ArxConfig.EPS]
    stable_steps, var_steps = int(config[ArxConfig.STABLE_STEPS]), int(config[ArxConfig.VAR_STEPS])
    var_rtol, fresh_only = config[ArxConfig.VAR_RTOL], config[ArxConfig.FRESH_ONLY] != 0.0
    theta, P, u_hist, y_hist, phi, P_phi, K, stats = arx_views(state, na, nb)
    ny_max = y_hist.size
    z, prediction, residual = out[ArxOut.Z], out[ArxOut.PREDICTION], out[ArxOut.RESIDUAL]
    judged = out[ArxOut.JUDGED]
    for i in range(u.size):
        k = counts[ArxCount.STEP]
        counts[ArxCount.STEP] += 1
        z[i] = prediction[i] = residual[i] = judged[i] = np.nan
        for j in range(nb - 1, 0, -1):                # phi's inputs: u(k), ..., u(k-nb+1)
            u_hist[j] = u_hist[j - 1]
        u_hist[0] = u[i]
        counts[ArxCount.N_U] = min(counts[ArxCount.N_U] + 1, nb)
        if fresh_only and not fresh[i]:
            continue
        if counts[ArxCount.N_U] < nb or counts[ArxCount.N_Y] < na:
            _push_output(y_hist, counts, y[i], ny_max)
            continue
        for j in range(na):
            phi[j] = y_hist[j]
        for j in range(nb):
            phi[na + j] = u_hist[j]
        was_stable = counts[ArxCount.MODEL_STABLE] == 1
        e = rls_update(theta, P, phi, y[i], 1.0, np.inf, P_phi, K)
        prediction[i], residual[i] = y[i] - e, e
        _push_output(y_hist, counts, y[i], ny_max)
        counts[ArxCount.UPDATES] += 1
        if not was_stable:
            big = 0.0
            for j in range(theta.size):
                big = max(big, abs(K[j] * e))         # ||K e||_inf
            if big < eps:
                if counts[ArxCount.STREAK_FROM] < 0:
                    counts[ArxCount.STREAK_FROM] = k
            else:
                counts[ArxCount.STREAK_FROM] = -1
            if (counts[ArxCount.STREAK_FROM] >= 0 and counts[ArxCount.UPDATES] >= warmup
                    and k - counts[ArxCount.STREAK_FROM] >= stable_steps):
                counts[ArxCount.MODEL_STABLE] = 1
            continue
        judged[i] = e
        n = counts[ArxCount.W_N]
        if counts[ArxCount.VAR_STABLE] == 1:                # z with the statistics before e
            var = stats[ArxStat.M2] / (n - 1) if n > 1 else np.nan
            dev = abs(e - stats[ArxStat.MEAN])
            if var > 0:
                z[i] = dev / math.sqrt(var)
            else:
                z[i] = np.inf if dev != 0 else 0.0
        n += 1                                         # Welford, eq. (8)
        counts[ArxCount.W_N] = n
        delta = e - stats[ArxStat.MEAN]
        stats[ArxStat.MEAN] += delta / n
        stats[ArxStat.M2] += delta * (e - stats[ArxStat.MEAN])
        var = stats[ArxStat.M2] / (n - 1) if n > 1 else np.nan
        if counts[ArxCount.VAR_STABLE] == 0 and n > 2:
            if abs(var - stats[ArxStat.LAST_VAR]) <= var_rtol * stats[ArxStat.LAST_VAR]:
                if counts[ArxCount.VAR_FROM] < 0:
                    counts[ArxCount.VAR_FROM] = k
            else:
                counts[ArxCount.VAR_FROM] = -1
            if counts[ArxCount.VAR_FROM] >= 0 and k - counts[ArxCount.VAR_FROM] >= var_steps:
                counts[ArxCount.VAR_STABLE] = 1
        stats[ArxStat.LAST_VAR] = var


@njit(cache=True)
def _push_output(y_hist, counts, value, ny_max):
    for j in range(ny_max - 1, 0, -1):
        y_hist[j] = y_hist[j - 1]
    y_hist[0] = value
    counts[ArxCount.N_Y] = min(counts[ArxCount.N_Y] + 1, ny_max)


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
def kalman_innovations(F, B, H, D, K, u, z, skip, x, y):
    """Innovations ``y`` of a steady-state Kalman filter with one output, over the
    steps of ``u`` (shape (n, m)) and the measurements ``z`` (n,), from the state ``x``
    (updated in place). ``F, B, H`` are OKID's :math:`A, B, C` of :mod:`.kalman_okid`:

    .. math::

        y(k) = z(k) - D u(k) - H \\hat x(k), \\qquad
        \\hat x(k+1) = F\\,(\\hat x(k) + K y(k)) + B u(k).

    The first ``skip`` innovations (the observer's start-up) are NaN."""
    nx = x.size
    post = np.empty(nx)
    for i in range(u.shape[0]):
        yi = z[i]
        for j in range(u.shape[1]):
            yi -= D[0, j] * u[i, j]
        for j in range(nx):
            yi -= H[0, j] * x[j]
        y[i] = yi if i >= skip else np.nan
        for j in range(nx):
            post[j] = x[j] + K[j, 0] * yi             # x(k|k) = x(k|k-1) + K y(k)
        for r in range(nx):
            acc = 0.0
            for j in range(nx):
                acc += F[r, j] * post[j]
            for j in range(u.shape[1]):
                acc += B[r, j] * u[i, j]
            x[r] = acc                                 # x(k+1|k) = F x(k|k) + B u(k)


def ffrls_state_size(n_par, m):
    """Length of an FF-RLS model's ``state`` for ``n_par`` parameters, window ``m``."""
    return n_par + n_par * n_par + 2 * n_par + 1 + (m + 1) * n_par + m


@njit(cache=True)
def ffrls_views(state, n_par, m):
    """``state`` cut into ``theta, P, P_phi, K, y_prev, thetas, glrt_buf``: the estimate,
    its covariance, workspace, the gain, the last rate (one value), the last
    :math:`M + 1` estimates (newest first) and the GLRT's window."""
    o = 0
    theta = state[o:o + n_par]
    o += n_par
    P = state[o:o + n_par * n_par].reshape((n_par, n_par))
    o += n_par * n_par
    P_phi = state[o:o + n_par]
    K = state[o + n_par:o + 2 * n_par]
    o += 2 * n_par
    y_prev = state[o:o + 1]
    o += 1
    thetas = state[o:o + (m + 1) * n_par].reshape((m + 1, n_par))
    o += (m + 1) * n_par
    glrt_buf = state[o:o + m]
    return theta, P, P_phi, K, y_prev, thetas, glrt_buf


@njit(cache=True)
def ffrls_advance(u, y, config, counts, state, info, out, dtheta):
    """Advance one FF-RLS model of :mod:`.ffrls_monitor` over the steps of ``u``
    (normalised deflections, shape (n, m)) and ``y`` (the rate).

    ``config`` holds the :class:`FfrlsConfig` hyper-parameters and fitted statistics,
    ``info`` the fitted :math:`\\Sigma_{\\Delta\\theta}^{-1}`; ``counts`` and ``state``
    (:func:`ffrls_views`) the model's state, updated in place. With ``FREEZE``,
    adaptation stops while :math:`g > \\gamma_r'`. Per step it writes the prediction
    error (row ``EPS`` of ``out``), and once the window is full ``dtheta``
    (:math:`\\hat\\theta(k) - \\hat\\theta(k-M)`), the GLRT ``G``, ``T`` and ``JOINT``;
    NaN before.
    """
    n_par = dtheta.shape[1]
    ar, lam = config[FfrlsConfig.AR] != 0.0, config[FfrlsConfig.LAM]
    max_trace, res_mean = config[FfrlsConfig.MAX_TRACE], config[FfrlsConfig.RES_MEAN]
    sigma2, freeze = config[FfrlsConfig.SIGMA2], config[FfrlsConfig.FREEZE] != 0.0
    gamma_r_joint = config[FfrlsConfig.GAMMA_R_JOINT]
    gamma_theta_joint = config[FfrlsConfig.GAMMA_THETA_JOINT]
    theta, P, P_phi, K, y_prev, thetas, glrt_buf = ffrls_views(
        state, n_par, int(config[FfrlsConfig.M]))
    glrt_count = counts[FfrlsCount.GLRT_COUNT:FfrlsCount.GLRT_COUNT + 1]
    eps, g, t, joint = out[FfrlsOut.EPS], out[FfrlsOut.G], out[FfrlsOut.T], out[FfrlsOut.JOINT]
    keep = thetas.shape[0]
    frozen, n_thetas = counts[FfrlsCount.FROZEN] != 0, counts[FfrlsCount.N_THETAS]
    previous = y_prev[0]
    phi = np.empty(n_par)
    one = np.empty(1)
    g_one = np.empty(1)
    for i in range(u.shape[0]):
        eps[i] = g[i] = t[i] = joint[i] = np.nan
        dtheta[i, :] = np.nan
        last, previous = previous, y[i]
        if ar and not math.isfinite(last):
            continue
        for j in range(u.shape[1]):
            phi[j] = u[i, j]
        if ar:
            phi[u.shape[1]] = last
        phi[n_par - 1] = 1.0
        if frozen:
            e = y[i]
            for j in range(n_par):
                e -= phi[j] * theta[j]                 # (14) with theta held
        else:
            e = rls_update(theta, P, phi, y[i], lam, max_trace, P_phi, K)  # (14)-(16)
        eps[i] = e
        for r in range(keep - 1, 0, -1):
            thetas[r, :] = thetas[r - 1, :]
        thetas[0, :] = theta
        n_thetas = min(n_thetas + 1, keep)
        if n_thetas < keep:
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
            frozen = g[i] > gamma_r_joint              # stop adapting while residual test is up
        joint[i] = min(g[i] / gamma_r_joint, tt / gamma_theta_joint)
    counts[FfrlsCount.FROZEN], counts[FfrlsCount.N_THETAS] = frozen, n_thetas
    y_prev[0] = previous
