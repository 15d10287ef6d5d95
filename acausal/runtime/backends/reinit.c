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

/* ---------------------------------------------------------------------------
 * The initialisation's Gauss-Newton (acausal.initialize._newton with
 * _lstsq_scaled) on z = (y, y' of the states), for the system
 *   F(t, y, y') = 0,  observed[fk[a]] - fv[a] = 0 (fixed starts),
 *   z[gk[b]] - z0[gk[b]] = 0 (imposed guesses),
 * its Jacobian from acs_jacs, acs_fixjac (the fixed-start rows) and unit
 * rows. The least-squares step is Householder QR of the column-scaled
 * Jacobian: the same solution as the SVD's (numpy's lstsq) when the scaled
 * Jacobian has full column rank and is well conditioned; otherwise (and on
 * a non-finite matrix) this returns -1 and the caller runs the Python version.
 */
void acs_observe(double t, const double* y, const double* yp, const double* pd, double* o);
void acs_fixjac(double t, const double* y, const double* yp, const double* pd, double* F);
int acs_n_observed(void);

typedef struct {
  int n, ns, m, c, nf, ng, nobs;
  double t;
  const double *pd, *fv, *z0;
  const int *fk, *gk;
  double *y, *yp, *o, *r, *Jy, *Jyp, *F;
} init_sys;

/* The initial system's fields and its workspace, laid out once for
 * acs_init_newton and acs_init_check: y, yp, the observed values, the two
 * Jacobians and the fixed starts' rows (F), then the m x c Jacobian J (at
 * s->F + max(nf, 1) * c) and ``extra`` words the caller lays out after J.
 * Returns the block to free, or NULL when out of memory. */
static double* init_alloc(init_sys* s, int n, int ns, double t, const double* pd, int nf,
                          const int* fk, const double* fv, int ng, const int* gk,
                          size_t extra) {
  int c = n + ns, m = n + nf + ng;
  s->n = n; s->ns = ns; s->m = m; s->c = c; s->nf = nf; s->ng = ng; s->t = t; s->pd = pd;
  s->fv = fv; s->fk = fk; s->gk = gk; s->z0 = NULL; s->nobs = acs_n_observed();
  size_t words = 2 * (size_t)n + (size_t)s->nobs + 1 + 2 * (size_t)n * n
                 + (size_t)(nf ? nf : 1) * c + (size_t)m * c + extra;
  double* w = (double*)calloc(words, sizeof(double));
  if (!w) return NULL;
  s->y = w; s->yp = s->y + n; s->o = s->yp + n; s->Jy = s->o + s->nobs + 1;
  s->Jyp = s->Jy + (size_t)n * n; s->F = s->Jyp + (size_t)n * n;
  return w;
}

static void split(init_sys* s, const double* z) {
  memcpy(s->y, z, sizeof(double) * s->n);
  memset(s->yp, 0, sizeof(double) * s->n);
  memcpy(s->yp, z + s->n, sizeof(double) * s->ns);
}

static void init_residual(init_sys* s, const double* z, double* out) {
  split(s, z);
  acs_res(s->t, s->y, s->yp, s->pd, out);
  if (s->nf) {
    acs_observe(s->t, s->y, s->yp, s->pd, s->o);
    for (int a = 0; a < s->nf; a++) out[s->n + a] = s->o[s->fk[a]] - s->fv[a];
  }
  for (int b = 0; b < s->ng; b++) out[s->n + s->nf + b] = z[s->gk[b]] - s->z0[s->gk[b]];
}

/* J row-major m x c */
static void init_jacobian(init_sys* s, const double* z, double* J) {
  int n = s->n, c = s->c;
  split(s, z);
  acs_jacs(s->t, s->y, s->yp, s->pd, s->Jy, s->Jyp);
  memset(J, 0, sizeof(double) * (size_t)s->m * c);
  for (int i = 0; i < n; i++) {
    memcpy(J + (size_t)i * c, s->Jy + (size_t)i * n, sizeof(double) * n);
    memcpy(J + (size_t)i * c + n, s->Jyp + (size_t)i * n, sizeof(double) * s->ns);
  }
  if (s->nf) {
    acs_fixjac(s->t, s->y, s->yp, s->pd, s->F);
    memcpy(J + (size_t)n * c, s->F, sizeof(double) * (size_t)s->nf * c);
  }
  for (int b = 0; b < s->ng; b++) J[(size_t)(n + s->nf + b) * c + s->gk[b]] = 1.0;
}

static double norm2(const double* a, int m) {
  double s = 0.0;
  for (int i = 0; i < m; i++) s += a[i] * a[i];
  return sqrt(s);
}

/* x (length c) = argmin |J x - b| with J's columns scaled to unit norm
 * first; J (m x c, row-major) and b are overwritten. -1: not of full,
 * well-conditioned column rank, or non-finite. */
static int lstsq_scaled(int m, int c, double* J, double* b, double* x, double* dcol) {
  if (m < c || !all_finite(J, m * c) || !all_finite(b, m)) return -1;
  for (int j = 0; j < c; j++) {
    double s = 0.0;
    for (int i = 0; i < m; i++) s += J[(size_t)i * c + j] * J[(size_t)i * c + j];
    s = sqrt(s);
    if (!(s > 0.0)) return -1;              /* a zero column: rank deficient */
    dcol[j] = 1.0 / s;
    for (int i = 0; i < m; i++) J[(size_t)i * c + j] *= dcol[j];
  }
  double rmax = 0.0, rmin = INFINITY;
  for (int k = 0; k < c; k++) {             /* Householder QR, applied to b */
    double alpha = 0.0;
    for (int i = k; i < m; i++) alpha += J[(size_t)i * c + k] * J[(size_t)i * c + k];
    alpha = sqrt(alpha);
    if (!(alpha > 0.0)) return -1;
    if (J[(size_t)k * c + k] > 0) alpha = -alpha;
    double v0 = J[(size_t)k * c + k] - alpha;
    J[(size_t)k * c + k] = v0;              /* v = (v0, J[k+1.., k]) */
    double vnorm2 = v0 * v0;
    for (int i = k + 1; i < m; i++) vnorm2 += J[(size_t)i * c + k] * J[(size_t)i * c + k];
    if (vnorm2 > 0.0) {
      for (int j = k + 1; j < c; j++) {
        double s = 0.0;
        for (int i = k; i < m; i++) s += J[(size_t)i * c + k] * J[(size_t)i * c + j];
        s = 2.0 * s / vnorm2;
        for (int i = k; i < m; i++) J[(size_t)i * c + j] -= s * J[(size_t)i * c + k];
      }
      double s = 0.0;
      for (int i = k; i < m; i++) s += J[(size_t)i * c + k] * b[i];
      s = 2.0 * s / vnorm2;
      for (int i = k; i < m; i++) b[i] -= s * J[(size_t)i * c + k];
    }
    J[(size_t)k * c + k] = alpha;           /* R's diagonal */
    rmax = fmax(rmax, fabs(alpha));
    rmin = fmin(rmin, fabs(alpha));
  }
  if (!(rmin > 1e-10 * rmax)) return -1;    /* near rank deficiency: the SVD decides */
  for (int k = c - 1; k >= 0; k--) {
    double s = b[k];
    for (int j = k + 1; j < c; j++) s -= J[(size_t)k * c + j] * x[j];
    x[k] = s / J[(size_t)k * c + k];
  }
  for (int j = 0; j < c; j++) x[j] *= dcol[j];
  return all_finite(x, c) ? 0 : -1;
}

/* z (length n + ns): in the start z0, out the last iterate. Returns 0 (z
 * is the iterate _newton returns), 1 (_newton returns None: a non-finite
 * residual) or -1 (run the Python version). */
int acs_init_newton(int n, int ns, double t, double* z, const double* pd, int nf,
                    const int* fk, const double* fv, int ng, const int* gk, int max_iter) {
  init_sys s;
  int c = n + ns, m = n + nf + ng, flag = -1;
  double* w = init_alloc(&s, n, ns, t, pd, nf, fk, fv, ng, gk, 3 * (size_t)m + 4 * (size_t)c);
  if (!w) return -1;
  double *J = s.F + (size_t)(nf ? nf : 1) * c, *r = J + (size_t)m * c, *r2 = r + m,
         *b = r2 + m, *dz = b + m, *z2 = dz + c, *dcol = z2 + c, *z0 = dcol + c;
  memcpy(z0, z, sizeof(double) * c);
  s.z0 = z0;
  init_residual(&s, z, r);
  double nr = norm2(r, m);
  for (int it = 0; it < max_iter; it++) {
    if (!all_finite(r, m)) { flag = 1; goto done; }
    init_jacobian(&s, z, J);
    for (int i = 0; i < m; i++) b[i] = -r[i];
    if (lstsq_scaled(m, c, J, b, dz, dcol) < 0) goto done;     /* flag -1 */
    double step = 1.0, n2 = 0.0;
    int accepted = 0;
    for (int h = 0; h < 30; h++) {
      for (int j = 0; j < c; j++) z2[j] = z[j] + step * dz[j];
      init_residual(&s, z2, r2);
      n2 = norm2(r2, m);
      if ((isfinite(n2) && n2 <= nr * (1 - 1e-4 * step)) || n2 <= 1e-300) { accepted = 1; break; }
      step *= 0.5;
    }
    if (!accepted) { flag = 0; goto done; }   /* no more progress */
    int small = 1;
    for (int j = 0; j < c; j++) {
      z[j] = z2[j];
      small &= fabs(step * dz[j]) <= 1e-13 * (1.0 + fabs(z[j]));
    }
    memcpy(r, r2, sizeof(double) * m);
    nr = n2;
    if (small || nr == 0.0) { flag = 0; goto done; }
  }
  flag = 0;
done:
  if (flag < 0) memcpy(z, z0, sizeof(double) * c);
  free(w);
  return flag;
}

/* The consistency test of acausal.initialize._check at z (length n + ns):
 * every row i of the residuals and the fixed starts (no guess rows) has
 * |r_i| <= 1e-7 (|J_i| . (|z| + 1e-12) + 1e-12) + 1e-10, written as that
 * function writes it (a NaN row passes there and here). Returns 1 when it
 * holds, 0 when not (the Python check then names the violation), -1 when
 * out of memory. */
int acs_init_check(int n, int ns, double t, const double* z, const double* pd, int nf,
                   const int* fk, const double* fv) {
  init_sys s;
  int c = n + ns, m = n + nf, ok = 1;
  double* w = init_alloc(&s, n, ns, t, pd, nf, fk, fv, 0, NULL, (size_t)m);
  if (!w) return -1;
  s.z0 = z;
  double *J = s.F + (size_t)(nf ? nf : 1) * c, *r = J + (size_t)m * c;
  init_residual(&s, z, r);
  init_jacobian(&s, z, J);
  for (int i = 0; i < m && ok; i++) {
    double scale = 0.0;
    for (int j = 0; j < c; j++) scale += fabs(J[(size_t)i * c + j]) * (fabs(z[j]) + 1e-12);
    if (fabs(r[i]) > 1e-7 * (scale + 1e-12) + 1e-10) ok = 0;
  }
  free(w);
  return ok;
}
