/* The compiled reference of the benchmark: one RLS step, eqs. (4)-(7) of
 * methods/rls.py, with lambda = 1, in plain C (gcc -O2). Same arithmetic, same
 * symmetrised covariance update as methods/kernels.py:rls_update. */
#include <stddef.h>

double rls_step(size_t n, double *theta, double *cov, const double *phi, double y,
                double *c_phi, double *gain) {
    double e = y, denom = 1.0;
    for (size_t i = 0; i < n; i++) e -= phi[i] * theta[i];
    for (size_t i = 0; i < n; i++) {
        double s = 0.0;
        for (size_t j = 0; j < n; j++) s += cov[i * n + j] * phi[j];
        c_phi[i] = s;
        denom += phi[i] * s;
    }
    for (size_t i = 0; i < n; i++) {
        gain[i] = c_phi[i] / denom;
        theta[i] += gain[i] * e;
    }
    for (size_t i = 0; i < n; i++)
        for (size_t j = i; j < n; j++) {
            double a = cov[i * n + j] - gain[i] * c_phi[j];
            double b = cov[j * n + i] - gain[j] * c_phi[i];
            cov[i * n + j] = cov[j * n + i] = 0.5 * (a + b);
        }
    return e;
}

/* n_steps steps of an ARX regression with n_b inputs and n_a outputs (the RLS-ARX
 * pair's arithmetic without its bookkeeping). */
void rls_run(size_t n_steps, size_t na, size_t nb, const double *u, const double *y,
             double *theta, double *cov, double *phi, double *c_phi, double *gain,
             double *e) {
    size_t n = na + nb, start = (na > nb - 1) ? na : nb - 1;
    for (size_t k = start; k < n_steps; k++) {
        for (size_t i = 0; i < na; i++) phi[i] = y[k - 1 - i];
        for (size_t j = 0; j < nb; j++) phi[na + j] = u[k - j];
        e[k] = rls_step(n, theta, cov, phi, y[k], c_phi, gain);
    }
}
