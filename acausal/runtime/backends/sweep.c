/* Staggered forward sensitivities along a finished run (acausal.runtime.staggered).
 *
 * Linked with a model's generated acs_res / acs_jac. Given the accepted steps
 * (t_m, y_m, y'_m) of one run of the base DAE F(t, y, y', p) = 0 and the
 * consistent sensitivities S_0 = dy/dp, S'_0 at t_0 (n x k), the linear
 * sensitivity DAE
 *
 *     F_y S + F_y' S' + F_p = 0
 *
 * is integrated for all k columns at once on the same step sequence by the
 * variable-coefficient BDF of order min(q, m) in Lagrange form on the points
 * t_m, t_{m-1}, ... (S'_m = sum_j a_j S_{m-j}): one LU of the iteration matrix
 * F_y + a_0 F_y' a step (acs_jac), k right-hand sides. This is the staggered
 * direct method of Caracotsios & Stewart (1985, Comput. Chem. Eng. 9) without
 * its corrector iteration: the sensitivity equations are linear, so one solve a
 * step is exact for the BDF formula, and their error is not controlled (the
 * base run's steps are). F_p by central differences of acs_res in each
 * parameter, forward ones for a parameter the residuals are linear in. Output at the times tout by cubic Hermite interpolation of
 * (S, S') between the steps around each; S' there is the interpolant's slope
 * (the algebraic unknowns' S' at t_0, which the equations leave free, is the
 * first step's secant).
 *
 * Returns 0, -1 when the iteration matrix is singular at a step, -2 when the
 * times do not increase strictly (a restart: the caller treats those), -3
 * when memory runs out. pd is restored on return. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

void acs_res(double t, const double* y, const double* yp, const double* pd, double* r);
void acs_jac(double t, const double* y, const double* yp, const double* pd, double cj,
             double* J);

typedef struct {
  int N, n, ns, k, q;         /* steps, unknowns, states, columns, highest BDF order */
  const double *t, *Y, *YP;   /* N times; N x n unknowns and their rates (row-major) */
  double *pd;                 /* the parameters, then the discrete values */
  const int *pidx;            /* k positions in pd */
  const double *step;         /* k difference steps */
  const int *central;         /* k: 1 central differences, 0 forward (a parameter the
                                 residuals are linear in: exact, half the evaluations) */
  const double *S0, *SP0;     /* n x k at t[0] (row-major) */
  int nout;
  const double *tout;         /* sorted output times */
  double *Sout, *SPout;       /* nout x n x k (row-major) */
} acs_sweep_args;

/* Lagrange-derivative coefficients at tt[0] on the points tt[0..qq]. */
static void bdf_coefficients(const double* tt, int qq, double* a) {
  a[0] = 0.0;
  for (int m = 1; m <= qq; m++) a[0] += 1.0 / (tt[0] - tt[m]);
  for (int j = 1; j <= qq; j++) {
    double num = 1.0, den = 1.0;
    for (int m = 1; m <= qq; m++) if (m != j) num *= tt[0] - tt[m];
    for (int m = 0; m <= qq; m++) if (m != j) den *= tt[j] - tt[m];
    a[j] = num / den;
  }
}

/* LU with partial pivoting of the column-major n x n A in place; 0 when singular. */
static int lu(double* A, int n, int* piv) {
  for (int c = 0; c < n; c++) {
    int p = c;
    double best = fabs(A[c + c * n]);
    for (int r = c + 1; r < n; r++)
      if (fabs(A[r + c * n]) > best) { best = fabs(A[r + c * n]); p = r; }
    if (best == 0.0 || !isfinite(best)) return 0;
    piv[c] = p;
    if (p != c)
      for (int j = 0; j < n; j++) { double s = A[c + j * n]; A[c + j * n] = A[p + j * n]; A[p + j * n] = s; }
    for (int r = c + 1; r < n; r++) {
      double f = A[r + c * n] /= A[c + c * n];
      if (f != 0.0)
        for (int j = c + 1; j < n; j++) A[r + j * n] -= f * A[c + j * n];
    }
  }
  return 1;
}

/* Solve LU X = R for the n x k row-major R in place. */
static void lu_solve(const double* A, int n, const int* piv, double* R, int k) {
  for (int c = 0; c < n; c++)
    if (piv[c] != c)
      for (int j = 0; j < k; j++) { double s = R[c * k + j]; R[c * k + j] = R[piv[c] * k + j]; R[piv[c] * k + j] = s; }
  for (int i = 1; i < n; i++)
    for (int l = 0; l < i; l++) {
      double f = A[i + l * n];
      if (f != 0.0) for (int c = 0; c < k; c++) R[i * k + c] -= f * R[l * k + c];
    }
  for (int i = n - 1; i >= 0; i--) {
    for (int l = i + 1; l < n; l++) {
      double f = A[i + l * n];
      if (f != 0.0) for (int c = 0; c < k; c++) R[i * k + c] -= f * R[l * k + c];
    }
    double d = A[i + i * n];
    for (int c = 0; c < k; c++) R[i * k + c] /= d;
  }
}

/* Hermite interpolation of (S, S') on [ta, tb] at tau into out, outp. */
static void hermite(double ta, double tb, const double* Sa, const double* SPa, const double* Sb,
                    const double* SPb, int nk, double tau, double* out, double* outp) {
  double h = tb - ta, u = (tau - ta) / h;
  double h00 = (1 + 2 * u) * (1 - u) * (1 - u), h10 = u * (1 - u) * (1 - u);
  double h01 = u * u * (3 - 2 * u), h11 = u * u * (u - 1);
  double d00 = 6 * u * (u - 1) / h, d10 = (1 - u) * (1 - 3 * u), d01 = -d00, d11 = u * (3 * u - 2);
  for (int i = 0; i < nk; i++) {
    out[i] = h00 * Sa[i] + h10 * h * SPa[i] + h01 * Sb[i] + h11 * h * SPb[i];
    outp[i] = d00 * Sa[i] + d10 * SPa[i] + d01 * Sb[i] + d11 * SPb[i];
  }
}

int acs_sweep(const acs_sweep_args* a) {
  const int n = a->n, k = a->k, q = a->q, nk = n * k, ring = q + 1;
  for (int m = 1; m < a->N; m++) if (!(a->t[m] > a->t[m - 1])) return -2;
  double* mem = (double*)malloc(sizeof(double) * ((size_t)2 * ring * nk + 3 * (size_t)n * n
                                                  + 3 * (size_t)nk + 3 * (size_t)n));
  int* piv = (int*)malloc(sizeof(int) * (n > 0 ? n : 1));
  if (!mem || !piv) { free(mem); free(piv); return -3; }
  double *S = mem, *SP = S + (size_t)ring * nk, *A = SP + (size_t)ring * nk, *J0 = A + n * n;
  double *Jp = J0 + n * n, *H = Jp + n * n, *R = H + nk, *Fp = R + nk, *r1 = Fp + nk;
  double *r2 = r1 + n, *r0 = r2 + n;
  int forward = 0;
  for (int c = 0; c < k; c++) forward |= !a->central[c];
  double al[16], tt[16];
  int status = 0, o = 0;
  memcpy(S, a->S0, sizeof(double) * nk);
  memcpy(SP, a->SP0, sizeof(double) * nk);
  for (; o < a->nout && a->tout[o] <= a->t[0]; o++) {
    memcpy(a->Sout + (size_t)o * nk, a->S0, sizeof(double) * nk);
    memcpy(a->SPout + (size_t)o * nk, a->SP0, sizeof(double) * nk);
  }
  for (int m = 1; m < a->N && status == 0; m++) {
    const double tm = a->t[m], *y = a->Y + (size_t)m * n, *yp = a->YP + (size_t)m * n;
    int qq = m < q ? m : q;
    for (int j = 0; j <= qq; j++) tt[j] = a->t[m - j];
    bdf_coefficients(tt, qq, al);
    acs_jac(tm, y, yp, a->pd, 0.0, J0);
    acs_jac(tm, y, yp, a->pd, al[0], A);
    for (int i = 0; i < n * n; i++) Jp[i] = (A[i] - J0[i]) / al[0];   /* F_y' (column-major) */
    if (forward) acs_res(tm, y, yp, a->pd, r0);
    for (int c = 0; c < k; c++) {
      double* p = a->pd + a->pidx[c];
      const double v = *p, h = a->step[c];
      *p = v + h; acs_res(tm, y, yp, a->pd, r1);
      if (a->central[c]) {
        *p = v - h; acs_res(tm, y, yp, a->pd, r2);
        for (int i = 0; i < n; i++) Fp[i * k + c] = (r1[i] - r2[i]) / (2 * h);
      } else {
        for (int i = 0; i < n; i++) Fp[i * k + c] = (r1[i] - r0[i]) / h;
      }
      *p = v;
    }
    memset(H, 0, sizeof(double) * nk);
    for (int j = 1; j <= qq; j++) {
      const double* Sj = S + (size_t)((m - j) % ring) * nk;
      for (int i = 0; i < nk; i++) H[i] += al[j] * Sj[i];
    }
    for (int i = 0; i < n; i++)
      for (int c = 0; c < k; c++) {
        double s = Fp[i * k + c];
        for (int l = 0; l < n; l++) {
          double f = Jp[i + l * n];
          if (f != 0.0) s += f * H[l * k + c];
        }
        R[i * k + c] = -s;
      }
    if (!lu(A, n, piv)) { status = -1; break; }
    lu_solve(A, n, piv, R, k);
    double *Sm = S + (size_t)(m % ring) * nk, *SPm = SP + (size_t)(m % ring) * nk;
    for (int i = 0; i < nk; i++) { Sm[i] = R[i]; SPm[i] = al[0] * R[i] + H[i]; }
    if (m == 1)
      for (int i = a->ns * k; i < nk; i++) SP[i] = (Sm[i] - S[i]) / (tm - a->t[0]);
    const double* Sa = S + (size_t)((m - 1) % ring) * nk;
    const double* SPa = SP + (size_t)((m - 1) % ring) * nk;
    for (; o < a->nout && a->tout[o] <= tm; o++)
      hermite(a->t[m - 1], tm, Sa, SPa, Sm, SPm, nk, a->tout[o], a->Sout + (size_t)o * nk,
              a->SPout + (size_t)o * nk);
  }
  if (status == 0 && a->N > 0) {     /* output times after the last step: its values */
    const double* Sl = S + (size_t)((a->N - 1) % ring) * nk;
    const double* SPl = SP + (size_t)((a->N - 1) % ring) * nk;
    for (; o < a->nout; o++) {
      memcpy(a->Sout + (size_t)o * nk, Sl, sizeof(double) * nk);
      memcpy(a->SPout + (size_t)o * nk, SPl, sizeof(double) * nk);
    }
  }
  free(mem);
  free(piv);
  return status;
}
