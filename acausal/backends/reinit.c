/* Consistent re-initialisation in C for acausal's compiled backend.
 *
 * The algorithm of acausal.initialize.reinitialize followed by
 * acausal.initialize._algebraic_rates, step for step, on the generated
 * acs_res and acs_jacs: keep the states, solve F(t, y, y') = 0 for the
 * algebraic unknowns and the states' y' by Newton (LU with partial
 * pivoting, as LAPACK's gesv behind scipy.linalg.solve), refined while the
 * corrections still shrink; then the algebraic unknowns' true rates from
 * [F_y(alg) F_y'(states)] [y'_alg; y''_states] = -(F_t + F_y(states) y'_states),
 * F_t by a central difference.
 *
 * Where the Python version would take another path (a singular or
 * non-finite matrix: its least-squares fallback) this returns -1 and the
 * caller runs the Python version from the same point instead, so the
 * result is always one of the two implementations of the same algorithm.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

void acs_res(double t, const double* y, const double* yp, const double* pd, double* r);
void acs_jacs(double t, const double* y, const double* yp, const double* pd, double* Jy,
              double* Jyp);

static int all_finite(const double* a, int m) {
  for (int i = 0; i < m; i++)
    if (!isfinite(a[i])) return 0;
  return 1;
}

/* Solve A x = b (A row-major m x m, overwritten; b overwritten by x) by LU
 * with partial pivoting; -1 on a non-finite input or an exactly zero pivot
 * (where gesv reports a singular matrix). */
static int lu_solve(int m, double* A, double* b) {
  if (!all_finite(A, m * m) || !all_finite(b, m)) return -1;
  for (int k = 0; k < m; k++) {
    int p = k;
    double best = fabs(A[k * m + k]);
    for (int i = k + 1; i < m; i++) {
      double v = fabs(A[i * m + k]);
      if (v > best) { best = v; p = i; }
    }
    if (!(best > 0.0)) return -1;
    if (p != k) {
      for (int j = 0; j < m; j++) {
        double s = A[k * m + j]; A[k * m + j] = A[p * m + j]; A[p * m + j] = s;
      }
      double s = b[k]; b[k] = b[p]; b[p] = s;
    }
    for (int i = k + 1; i < m; i++) {
      double f = A[i * m + k] / A[k * m + k];
      if (f == 0.0) continue;
      for (int j = k + 1; j < m; j++) A[i * m + j] -= f * A[k * m + j];
      b[i] -= f * b[k];
    }
  }
  for (int k = m - 1; k >= 0; k--) {
    double s = b[k];
    for (int j = k + 1; j < m; j++) s -= A[k * m + j] * b[j];
    b[k] = s / A[k * m + k];
  }
  return 0;
}

/* J = [Jy[:, ns:], Jyp[:, :ns]] (row-major n x n) at (t, y, yp). */
static void iteration_matrix(int n, int ns, double t, const double* y, const double* yp,
                             const double* pd, double* Jy, double* Jyp, double* J) {
  acs_jacs(t, y, yp, pd, Jy, Jyp);
  int na = n - ns;
  for (int i = 0; i < n; i++) {
    for (int c = 0; c < na; c++) J[i * n + c] = Jy[i * n + ns + c];
    for (int c = 0; c < ns; c++) J[i * n + na + c] = Jyp[i * n + c];
  }
}

static int newton(int n, int ns, double t, double* y, double* yp, const double* pd,
                  double* w) {
  double *r = w, *Jy = r + n, *Jyp = Jy + n * n, *J = Jyp + n * n, *z = J + n * n;
  int na = n - ns, converged = 0;
  double last = INFINITY;
  for (int c = 0; c < na; c++) z[c] = y[ns + c];
  for (int c = 0; c < ns; c++) z[na + c] = yp[c];
  for (int it = 0; it < 50; it++) {
    acs_res(t, y, yp, pd, r);
    int any = 0;
    for (int i = 0; i < n; i++) any |= r[i] != 0.0;   /* NaN counts, as in numpy's any() */
    if (!any) break;
    iteration_matrix(n, ns, t, y, yp, pd, Jy, Jyp, J);
    for (int i = 0; i < n; i++) r[i] = -r[i];
    if (lu_solve(n, J, r) < 0) return -1;
    double size = 0.0;
    for (int i = 0; i < n; i++) size = fmax(size, fabs(r[i]));
    if (converged && !(size < last)) break;
    int small = 1;
    for (int i = 0; i < n; i++) {
      z[i] = z[i] + r[i];
      small &= fabs(r[i]) <= 1e-12 * (1.0 + fabs(z[i]));
    }
    for (int c = 0; c < na; c++) y[ns + c] = z[c];
    for (int c = 0; c < ns; c++) yp[c] = z[na + c];
    converged = converged || small;
    last = size;
  }
  return 0;
}

static int rates(int n, int ns, double t, const double* y, double* yp, const double* pd,
                 double* w) {
  double *rp = w, *Jy = rp + n, *Jyp = Jy + n * n, *J = Jyp + n * n, *rm = J + n * n;
  if (n == ns) return 0;
  iteration_matrix(n, ns, t, y, yp, pd, Jy, Jyp, J);
  double dt = 1e-6 * fmax(1.0, fabs(t));
  acs_res(t + dt, y, yp, pd, rp);
  acs_res(t - dt, y, yp, pd, rm);
  for (int i = 0; i < n; i++) {
    double s = 0.0;
    for (int j = 0; j < ns; j++) s += Jy[i * n + j] * yp[j];
    rp[i] = -((rp[i] - rm[i]) / (2 * dt) + s);
  }
  if (lu_solve(n, J, rp) < 0) return -1;
  if (all_finite(rp, n))
    for (int c = 0; c < n - ns; c++) yp[ns + c] = rp[c];
  return 0;
}

/* Re-initialise (y, yp) in place at time t with parameters and discrete
 * values pd; 0 done, -1 the caller must run the Python version from the
 * original point instead. */
int acs_reinit(int n, int ns, double t, double* y, double* yp, const double* pd) {
  double* w = (double*)malloc(sizeof(double) * (3 * (size_t)n * n + 2 * (size_t)n + 1));
  if (!w) return -1;
  int flag = newton(n, ns, t, y, yp, pd, w);
  if (flag == 0) flag = rates(n, ns, t, y, yp, pd, w);
  free(w);
  return flag;
}
