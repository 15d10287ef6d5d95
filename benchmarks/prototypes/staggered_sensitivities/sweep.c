/* The sensitivity sweep in C (prototype for a driver-side implementation):
   per accepted step m: A = Jy + a0 Jyp (n x n), LU with partial pivoting,
   H = sum_{j>=1} a_j S_{m-j} (n x k), R = -(Fp + Jyp H), S_m = A^{-1} R, S'_m = a0 S_m + H.
   Arrays row-major: Jy, Jyp: N x n x n; Fp, S, SP: N x n x k; al: N x (q+1). */
#include <string.h>
#include <math.h>
void sweep(int N, int n, int k, int q, const double* al, const double* Jy, const double* Jyp,
           const double* Fp, double* S, double* SP, double* work) {
  double *A = work, *H = A + n * n, *R = H + n * k; int piv[64];
  for (int m = 1; m < N; m++) {
    const double* a = al + (size_t)m * (q + 1);
    const double *jy = Jy + (size_t)m * n * n, *jp = Jyp + (size_t)m * n * n;
    for (int i = 0; i < n * n; i++) A[i] = jy[i] + a[0] * jp[i];
    /* LU, partial pivoting */
    for (int c = 0; c < n; c++) {
      int p = c; double best = fabs(A[c * n + c]);
      for (int r = c + 1; r < n; r++) if (fabs(A[r * n + c]) > best) { best = fabs(A[r * n + c]); p = r; }
      piv[c] = p;
      if (p != c) for (int j = 0; j < n; j++) { double t = A[c * n + j]; A[c * n + j] = A[p * n + j]; A[p * n + j] = t; }
      for (int r = c + 1; r < n; r++) {
        double f = A[r * n + c] /= A[c * n + c];
        for (int j = c + 1; j < n; j++) A[r * n + j] -= f * A[c * n + j];
      }
    }
    int qq = m < q ? m : q;
    memset(H, 0, sizeof(double) * n * k);
    for (int j = 1; j <= qq; j++) {
      const double* Sj = S + (size_t)(m - j) * n * k; double aj = a[j];
      for (int i = 0; i < n * k; i++) H[i] += aj * Sj[i];
    }
    const double* fp = Fp + (size_t)m * n * k;
    for (int i = 0; i < n; i++)
      for (int c = 0; c < k; c++) {
        double s = fp[i * k + c];
        for (int l = 0; l < n; l++) s += jp[i * n + l] * H[l * k + c];
        R[i * k + c] = -s;
      }
    /* apply pivots and solve */
    for (int c = 0; c < n; c++) if (piv[c] != c)
      for (int j = 0; j < k; j++) { double t = R[c * k + j]; R[c * k + j] = R[piv[c] * k + j]; R[piv[c] * k + j] = t; }
    for (int i = 1; i < n; i++) for (int l = 0; l < i; l++) { double f = A[i * n + l]; for (int c = 0; c < k; c++) R[i * k + c] -= f * R[l * k + c]; }
    for (int i = n - 1; i >= 0; i--) {
      for (int l = i + 1; l < n; l++) { double f = A[i * n + l]; for (int c = 0; c < k; c++) R[i * k + c] -= f * R[l * k + c]; }
      double d = A[i * n + i]; for (int c = 0; c < k; c++) R[i * k + c] /= d;
    }
    double* Sm = S + (size_t)m * n * k; double* SPm = SP + (size_t)m * n * k;
    for (int i = 0; i < n * k; i++) { Sm[i] = R[i]; SPm[i] = a[0] * R[i] + H[i]; }
  }
}
