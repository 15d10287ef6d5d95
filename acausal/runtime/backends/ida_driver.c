/* A segment driver around SUNDIALS IDA for acausal's compiled backend.
 *
 * Linked with the generated acs_res / acs_jac / acs_roots (acausal/codegen_c.py)
 * against the SUNDIALS 7 libraries that the scikit-sundae wheel ships. IDA is
 * set up as scikit-sundae sets it up (dense direct linear solver, user
 * Jacobian, IDASetId, root directions, stop time at the end of a segment), so
 * the two backends run the same algorithm; only the callbacks differ.
 *
 * The prototypes below are those of SUNDIALS 7 (sunrealtype double,
 * sunindextype int64, SUNComm int without MPI); the wheel ships no headers.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef double sunrealtype;
typedef int64_t sunindextype;
typedef int SUNComm;
typedef struct _generic_N_Vector* N_Vector;
typedef struct _generic_SUNMatrix* SUNMatrix;
typedef struct _generic_SUNLinearSolver* SUNLinearSolver;
typedef struct SUNContext_* SUNContext;
typedef int (*IDAResFn)(sunrealtype, N_Vector, N_Vector, N_Vector, void*);
typedef int (*IDARootFn)(sunrealtype, N_Vector, N_Vector, sunrealtype*, void*);
typedef int (*IDALsJacFn)(sunrealtype, sunrealtype, N_Vector, N_Vector, N_Vector, SUNMatrix,
                          void*, N_Vector, N_Vector, N_Vector);

extern int SUNContext_Create(SUNComm comm, SUNContext* ctx);
extern int SUNContext_Free(SUNContext* ctx);
extern int SUNContext_ClearErrHandlers(SUNContext ctx);
extern N_Vector N_VNew_Serial(sunindextype n, SUNContext ctx);
extern void N_VDestroy(N_Vector v);
extern sunrealtype* N_VGetArrayPointer(N_Vector v);
extern SUNMatrix SUNDenseMatrix(sunindextype m, sunindextype n, SUNContext ctx);
extern sunrealtype* SUNDenseMatrix_Data(SUNMatrix A);
extern void SUNMatDestroy(SUNMatrix A);
extern SUNLinearSolver SUNLinSol_Dense(N_Vector y, SUNMatrix A, SUNContext ctx);
extern int SUNLinSolFree(SUNLinearSolver S);
extern void* IDACreate(SUNContext ctx);
extern int IDAInit(void* mem, IDAResFn res, sunrealtype t0, N_Vector yy0, N_Vector yp0);
extern int IDAReInit(void* mem, sunrealtype t0, N_Vector yy0, N_Vector yp0);
extern int IDASVtolerances(void* mem, sunrealtype rtol, N_Vector atol);
extern int IDASetLinearSolver(void* mem, SUNLinearSolver LS, SUNMatrix A);
extern int IDASetJacFn(void* mem, IDALsJacFn jac);
extern int IDASetUserData(void* mem, void* data);
extern int IDARootInit(void* mem, int nrtfn, IDARootFn g);
extern int IDASetRootDirection(void* mem, int* dir);
extern int IDASetId(void* mem, N_Vector id);
extern int IDASetMaxStep(void* mem, sunrealtype hmax);
extern int IDASetMaxNumSteps(void* mem, long int mxsteps);
extern int IDASetStopTime(void* mem, sunrealtype tstop);
extern int IDAClearStopTime(void* mem);
extern int IDASolve(void* mem, sunrealtype tout, sunrealtype* tret, N_Vector yret,
                    N_Vector ypret, int itask);
extern int IDAGetRootInfo(void* mem, int* rootsfound);
extern int IDAGetNumSteps(void* mem, long int* nsteps);
extern int IDAGetNumResEvals(void* mem, long int* nrevals);
extern int IDAGetNumJacEvals(void* mem, long int* njevals);
extern void IDAFree(void** mem);
extern char* IDAGetReturnFlagName(long int flag);

#define IDA_NORMAL 1
#define IDA_ONE_STEP 2
#define IDA_TSTOP_RETURN 1
#define IDA_ROOT_RETURN 2
#define ACS_FULL 99

void acs_res(double t, const double* y, const double* yp, const double* pd, double* r);
void acs_jac(double t, const double* y, const double* yp, const double* pd, double cj,
             double* J);
void acs_roots(double t, const double* y, const double* yp, const double* pd, double* g);

typedef struct {
  void* mem;
  SUNContext ctx;
  N_Vector yy, yp, id, atol;
  SUNMatrix A;
  SUNLinearSolver LS;
  int n, nr, npd;
  double* pd;
} acs_handle;

static int res_cb(sunrealtype t, N_Vector yy, N_Vector yp, N_Vector rr, void* ud) {
  acs_handle* h = (acs_handle*)ud;
  acs_res(t, N_VGetArrayPointer(yy), N_VGetArrayPointer(yp), h->pd, N_VGetArrayPointer(rr));
  return 0;
}

static int jac_cb(sunrealtype t, sunrealtype cj, N_Vector yy, N_Vector yp, N_Vector rr,
                  SUNMatrix J, void* ud, N_Vector t1, N_Vector t2, N_Vector t3) {
  acs_handle* h = (acs_handle*)ud;
  (void)rr; (void)t1; (void)t2; (void)t3;
  acs_jac(t, N_VGetArrayPointer(yy), N_VGetArrayPointer(yp), h->pd, cj, SUNDenseMatrix_Data(J));
  return 0;
}

static int root_cb(sunrealtype t, N_Vector yy, N_Vector yp, sunrealtype* g, void* ud) {
  acs_handle* h = (acs_handle*)ud;
  acs_roots(t, N_VGetArrayPointer(yy), N_VGetArrayPointer(yp), h->pd, g);
  return 0;
}

void acs_free(void* vh) {
  acs_handle* h = (acs_handle*)vh;
  if (!h) return;
  if (h->mem) IDAFree(&h->mem);
  if (h->LS) SUNLinSolFree(h->LS);
  if (h->A) SUNMatDestroy(h->A);
  if (h->yy) N_VDestroy(h->yy);
  if (h->yp) N_VDestroy(h->yp);
  if (h->id) N_VDestroy(h->id);
  if (h->atol) N_VDestroy(h->atol);
  free(h->pd);
  if (h->ctx) SUNContext_Free(&h->ctx);
  free(h);
}

/* A handle, or NULL when SUNDIALS refuses a setting. id[i] = 1 for a
 * differential unknown, 0 for an algebraic one; dirs: root directions. */
void* acs_new(int n, int nr, int npd, double rtol, const double* atol, const double* id,
              int* dirs, double max_step, long max_steps) {
  acs_handle* h = (acs_handle*)calloc(1, sizeof(acs_handle));
  if (!h) return NULL;
  h->n = n; h->nr = nr; h->npd = npd;
  h->pd = (double*)calloc(npd > 0 ? npd : 1, sizeof(double));
  if (SUNContext_Create(0, &h->ctx) != 0) { acs_free(h); return NULL; }
  SUNContext_ClearErrHandlers(h->ctx);   /* messages go back to Python by flag */
  h->yy = N_VNew_Serial(n, h->ctx);
  h->yp = N_VNew_Serial(n, h->ctx);
  h->id = N_VNew_Serial(n, h->ctx);
  h->atol = N_VNew_Serial(n, h->ctx);
  memset(N_VGetArrayPointer(h->yy), 0, sizeof(double) * n);
  memset(N_VGetArrayPointer(h->yp), 0, sizeof(double) * n);
  memcpy(N_VGetArrayPointer(h->id), id, sizeof(double) * n);
  memcpy(N_VGetArrayPointer(h->atol), atol, sizeof(double) * n);
  h->mem = IDACreate(h->ctx);
  int bad = h->mem == NULL;
  bad = bad || IDAInit(h->mem, res_cb, 0.0, h->yy, h->yp) < 0;
  bad = bad || IDASetUserData(h->mem, h) < 0;
  bad = bad || IDASVtolerances(h->mem, rtol, h->atol) < 0;
  if (!bad) {
    h->A = SUNDenseMatrix(n, n, h->ctx);
    h->LS = SUNLinSol_Dense(h->yy, h->A, h->ctx);
    bad = IDASetLinearSolver(h->mem, h->LS, h->A) < 0 || IDASetJacFn(h->mem, jac_cb) < 0;
  }
  if (!bad && nr > 0)
    bad = IDARootInit(h->mem, nr, root_cb) < 0 || IDASetRootDirection(h->mem, dirs) < 0;
  bad = bad || IDASetId(h->mem, h->id) < 0;
  bad = bad || IDASetMaxStep(h->mem, max_step) < 0;
  bad = bad || IDASetMaxNumSteps(h->mem, max_steps) < 0;
  if (bad) { acs_free(h); return NULL; }
  return h;
}

/* Start a segment at the consistent point (t, y, yp) with parameters and
 * discrete values pd, ending at tend. */
int acs_start(void* vh, double t, const double* y, const double* yp, const double* pd,
              double tend) {
  acs_handle* h = (acs_handle*)vh;
  memcpy(N_VGetArrayPointer(h->yy), y, sizeof(double) * h->n);
  memcpy(N_VGetArrayPointer(h->yp), yp, sizeof(double) * h->n);
  memcpy(h->pd, pd, sizeof(double) * h->npd);
  int flag = IDAReInit(h->mem, t, h->yy, h->yp);
  if (flag < 0) return flag;
  return IDASetStopTime(h->mem, tend);
}

static void put_row(acs_handle* h, double tt, double* T, double* Y, double* YP, int k) {
  T[k] = tt;
  memcpy(Y + (size_t)k * h->n, N_VGetArrayPointer(h->yy), sizeof(double) * h->n);
  memcpy(YP + (size_t)k * h->n, N_VGetArrayPointer(h->yp), sizeof(double) * h->n);
}

/* Advance the segment as scikit-sundae's solve() does: to each output time
 * tout[*iout..] (or by internal steps to tout[nout-1] when every_step),
 * writing rows into T, Y, YP (at most cap). Returns 0 at the end of the
 * segment, IDA_ROOT_RETURN at a root (its point in troot[0], yroot, yproot,
 * the root functions that crossed in rootinfo; not written as a row: the
 * caller decides whether it ends the segment), ACS_FULL when the row buffer
 * is full, or IDA's negative flag (the failure point written as a row). */
int acs_advance(void* vh, const double* tout, int nout, int* iout, int every_step,
                double* T, double* Y, double* YP, int cap, int* nrows,
                double* troot, double* yroot, double* yproot, int* rootinfo) {
  acs_handle* h = (acs_handle*)vh;
  double tt = 0.0;
  *nrows = 0;
  while (*nrows < cap) {
    int last = every_step || *iout == nout - 1;
    double target = every_step ? tout[nout - 1] : tout[*iout];
    int flag = IDASolve(h->mem, target, &tt, h->yy, h->yp, every_step ? IDA_ONE_STEP : IDA_NORMAL);
    if (flag == IDA_ROOT_RETURN) {
      IDAGetRootInfo(h->mem, rootinfo);
      troot[0] = tt;
      memcpy(yroot, N_VGetArrayPointer(h->yy), sizeof(double) * h->n);
      memcpy(yproot, N_VGetArrayPointer(h->yp), sizeof(double) * h->n);
      return IDA_ROOT_RETURN;
    }
    put_row(h, tt, T, Y, YP, (*nrows)++);
    if (flag < 0) return flag;
    if (!every_step) (*iout)++;
    if (flag == IDA_TSTOP_RETURN || (!every_step && last)) return 0;
  }
  return ACS_FULL;
}

void acs_counters(void* vh, long* out) {
  acs_handle* h = (acs_handle*)vh;
  IDAGetNumSteps(h->mem, &out[0]);
  IDAGetNumResEvals(h->mem, &out[1]);
  IDAGetNumJacEvals(h->mem, &out[2]);
}

const char* acs_flag_name(long flag) { return IDAGetReturnFlagName(flag); }

/* The generated functions, exported for tests of the generated code. */
void acs_eval(int which, double t, const double* y, const double* yp, const double* pd,
              double cj, double* out) {
  if (which == 0) acs_res(t, y, yp, pd, out);
  else if (which == 1) acs_jac(t, y, yp, pd, cj, out);
  else acs_roots(t, y, yp, pd, out);
}
