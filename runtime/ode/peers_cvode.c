/* SUNDIALS CVODE peers: "cvode-adams" (Adams-Moulton, fixed-point iteration)
 * and "cvode-bdf" (BDF, dense Newton with CVODE's difference-quotient
 * Jacobian).  Output at tout comes from CVODE's own interpolant (CV_NORMAL).
 *
 * Projection (cvode-bdf): swim's projection maps y to a point of the manifold
 * in place; CVODE (>= 5.3, BDF only) wants the correction, projected minus
 * corrected y, which it adds to the solution and its Nordsieck history.  The
 * error estimate is not projected (CVodeSetProjErrEst off): the projection
 * function has no use for it.
 *
 * Right-hand-side failures: CVODE's convention is swim's.  A positive value is
 * recoverable: CVODE counts a nonlinear-solver failure, cuts the step (by
 * eta_cf = 1/4) and retries; a positive value inside the difference-quotient
 * Jacobian makes the linear-solver setup fail recoverably, with the same
 * effect.  After maxncf (10) such failures on one step, or at hmin, CVODE
 * returns CV_REPTD_RHSFUNC_ERR (or CV_CONV_FAILURE when the failing call was
 * in the Jacobian).  A positive value at (t0, y0) gives CV_FIRST_RHSFUNC_ERR.
 * A negative value is unrecoverable (CV_RHSFUNC_FAIL / CV_LSETUP_FAIL); the
 * wrapper then also fails every later call without calling the user's f.
 *
 * CVODE has no relative minimum step: when f fails beyond some time t* for
 * good, it creeps towards t* with ever smaller accepted steps, down to steps
 * that no longer change t (it only warns about those), without end.  So the
 * wrapper counts positive returns and makes the next one fatal after
 * CV_MAXDOMFAIL of them without an accepted step in between whose size is
 * above the minimum step of ABM, 4 u |t| (so the count restarts whenever the
 * integration makes real progress). */
#include "ode/ode_internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <cvode/cvode_proj.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#define CV_MAXDOMFAIL 20

typedef struct {
    swim_ode_system sys;
    SUNContext ctx;
    void *mem;
    N_Vector y, atolv;
    N_Vector ky;       /* work vector for CVodeGetDky */
    SUNMatrix A;
    SUNLinearSolver LS;
    SUNNonlinearSolver NLS;
    int bdf;
    int (*project)(double t, double *y, void *params);   /* swim's projection, or NULL */
    double *yproj;     /* work vector for the projection (n) */
    double *jwork;     /* the caller's row-major Jacobian (n x n), or NULL */
    double t;
    long nfe_user;
    int rhs_status;    /* last nonzero value returned by the RHS */
    int fatal;         /* the RHS returned a negative value */
    int last_failed;   /* the most recent call of the RHS returned nonzero */
    int domfail;       /* positive returns without a real accepted step in between */
    long domfail_nst;  /* CVODE's step count at the latest positive return */
} cv_peer;

static int cv_rhs(realtype t, N_Vector y, N_Vector ydot, void *p)
{
    cv_peer *c = p;
    if (c->fatal)
        return -1;   /* after a fatal failure every later call fails too, so CVODE gives up at once */
    c->nfe_user++;
    int rc = c->sys.function(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot), c->sys.params);
    c->last_failed = rc != 0;
    if (rc == 0)
        return 0;
    c->rhs_status = rc;
    if (rc > 0) {
        long nst = 0;
        realtype hu = 0;
        CVodeGetNumSteps(c->mem, &nst);
        if (nst != c->domfail_nst) {
            /* steps were accepted since the last failure: the last one real progress? */
            CVodeGetLastStep(c->mem, &hu);
            if (fabs(hu) > 4.0 * DBL_EPSILON * fabs(t))
                c->domfail = 0;
            c->domfail_nst = nst;
        }
        if (++c->domfail <= CV_MAXDOMFAIL)
            return 1;   /* recoverable: CVODE retries with a smaller step */
    }
    c->fatal = 1;
    return -1;          /* unrecoverable */
}

/* CVLsJacFn: the caller's row-major J into CVODE's dense (column-major) matrix.  Return
 * values as for the RHS: positive makes the linear-solver setup fail recoverably (CVODE
 * retries with a smaller step), negative is fatal. */
static int cv_jac(realtype t, N_Vector y, N_Vector fy, SUNMatrix J, void *p, N_Vector t1, N_Vector t2, N_Vector t3)
{
    (void)fy; (void)t1; (void)t2; (void)t3;
    cv_peer *c = p;
    const size_t n = c->sys.dimension;
    int rc = c->sys.jacobian(t, N_VGetArrayPointer(y), c->jwork, c->sys.params);
    if (rc) {
        c->rhs_status = rc;
        c->last_failed = 1;
        if (rc < 0)
            c->fatal = 1;
        return rc < 0 ? -1 : 1;
    }
    for (size_t j = 0; j < n; j++) {
        realtype *col = SM_COLUMN_D(J, (sunindextype)j);
        for (size_t i = 0; i < n; i++)
            col[i] = c->jwork[i * n + j];
    }
    return 0;
}

/* CVProjFn: corr = P(ycur) - ycur with swim's in-place projection P. */
static int cv_project(realtype t, N_Vector ycur, N_Vector corr, realtype eps, N_Vector err, void *p)
{
    (void)eps; (void)err;
    cv_peer *c = p;
    const size_t n = c->sys.dimension;
    const double *y = N_VGetArrayPointer(ycur);
    double *d = N_VGetArrayPointer(corr);
    memcpy(c->yproj, y, n * sizeof(double));
    int rc = c->project(t, c->yproj, c->sys.params);
    if (rc) {
        c->rhs_status = rc;
        c->fatal = 1;
        return -1;      /* unrecoverable: the run stops with SWIM_ODE_ERHS */
    }
    for (size_t i = 0; i < n; i++)
        d[i] = c->yproj[i] - y[i];
    return 0;
}

static void cv_silent(int code, const char *module, const char *function, char *msg, void *data)
{
    (void)code; (void)module; (void)function; (void)msg; (void)data;
}

static void cv_destroy(void *p)
{
    cv_peer *c = p;
    if (!c)
        return;
    if (c->mem)
        CVodeFree(&c->mem);
    if (c->NLS)
        SUNNonlinSolFree(c->NLS);
    if (c->LS)
        SUNLinSolFree(c->LS);
    if (c->A)
        SUNMatDestroy(c->A);
    if (c->y)
        N_VDestroy(c->y);
    if (c->atolv)
        N_VDestroy(c->atolv);
    if (c->ky)
        N_VDestroy(c->ky);
    if (c->ctx)
        SUNContext_Free(&c->ctx);
    free(c->yproj);
    free(c->jwork);
    free(c);
}

/* CVODE's return value as a SWIM_ODE_* status. */
static int cv_status(const cv_peer *c, int rc)
{
    if (rc >= 0)
        return SWIM_ODE_OK;
    if (c->fatal)
        return SWIM_ODE_ERHS;
    switch (rc) {
    case CV_TOO_MUCH_WORK: return SWIM_ODE_EMAXSTEPS;
    case CV_TOO_MUCH_ACC: return SWIM_ODE_ETOLTOOSMALL;
    case CV_ILL_INPUT: return SWIM_ODE_EBADARG;
    case CV_RHSFUNC_FAIL:
    case CV_FIRST_RHSFUNC_ERR:
    case CV_REPTD_RHSFUNC_ERR:
    case CV_UNREC_RHSFUNC_ERR:
        return c->rhs_status ? SWIM_ODE_ERHS : SWIM_ODE_EFAIL;
    case CV_MEM_FAIL: return SWIM_ODE_ENOMEM;
    case CV_ERR_FAILURE:
    case CV_CONV_FAILURE:
        /* a convergence failure whose last attempt ended in a positive RHS
         * value (in the DQ Jacobian) is a repeated domain failure */
        return c->last_failed ? SWIM_ODE_ERHS : SWIM_ODE_EHMIN;
    default: return c->last_failed ? SWIM_ODE_ERHS : SWIM_ODE_EFAIL;
    }
}

static int cv_advance(void *p, double tout, double *yout)
{
    cv_peer *c = p;
    realtype t = c->t;
    int rc = CVode(c->mem, tout, c->y, &t, CV_NORMAL);
    memcpy(yout, N_VGetArrayPointer(c->y), c->sys.dimension * sizeof(double));
    CVodeGetCurrentTime(c->mem, &t);
    c->t = t;
    return cv_status(c, rc);
}

/* For events: one internal step (CV_ONE_STEP) unless tout is covered already. */
static int cv_step(void *p, double tout, int *done)
{
    cv_peer *c = p;
    *done = c->t >= tout;
    if (*done)
        return SWIM_ODE_OK;
    realtype t = c->t;
    int rc = CVode(c->mem, tout, c->y, &t, CV_ONE_STEP);
    CVodeGetCurrentTime(c->mem, &t);
    c->t = t;
    return cv_status(c, rc);
}

/* CVODE's interpolant on its last step (CVodeGetDky, derivatives 0 and 1). */
static int cv_dense(void *p, double t, double *y, double *yp)
{
    cv_peer *c = p;
    const size_t n = c->sys.dimension;
    if (CVodeGetDky(c->mem, t, 0, c->ky) != CV_SUCCESS)
        return -1;
    memcpy(y, N_VGetArrayPointer(c->ky), n * sizeof(double));
    if (yp) {
        if (CVodeGetDky(c->mem, t, 1, c->ky) != CV_SUCCESS)
            return -1;
        memcpy(yp, N_VGetArrayPointer(c->ky), n * sizeof(double));
    }
    return 0;
}

static void cv_stats(const void *p, swim_ode_stats *st)
{
    const cv_peer *c = p;
    memset(st, 0, sizeof *st);
    long nst = 0, netf = 0, ncf = 0, nje = 0;
    realtype h = 0;
    int q = 0;
    CVodeGetNumSteps(c->mem, &nst);
    CVodeGetNumErrTestFails(c->mem, &netf);
    CVodeGetNumNonlinSolvConvFails(c->mem, &ncf);
    if (c->bdf)
        CVodeGetNumJacEvals(c->mem, &nje);
    CVodeGetLastStep(c->mem, &h);
    CVodeGetLastOrder(c->mem, &q);
    st->steps = nst;
    st->rhs_evals = c->nfe_user;   /* counted in the wrapper: includes DQ Jacobian calls */
    st->rejected = netf + ncf;
    st->jac_evals = nje;
    st->last_h = h;
    st->last_order = q;
}

static double cv_time(const void *p) { return ((const cv_peer *)p)->t; }
static int cv_rhs_status(const void *p) { return ((const cv_peer *)p)->rhs_status; }

static const ode_backend cv_backend = { cv_destroy, cv_advance, cv_stats, cv_time, cv_rhs_status,
                                        cv_step, cv_dense };

int swim_ode_cvode_create(const ode_method *m, const swim_ode_system *sys, const swim_ode_options *opt,
                          double t0, const double *y0, void **impl, const ode_backend **be)
{
    int bdf;
    switch (m->variant) {
    case ODE_CVODE_ADAMS: bdf = 0; break;
    case ODE_CVODE_BDF: bdf = 1; break;
    default: return SWIM_ODE_EBADARG;
    }
    size_t n = sys->dimension;
    cv_peer *c = calloc(1, sizeof *c);
    if (!c)
        return SWIM_ODE_ENOMEM;
    c->sys = *sys;
    c->bdf = bdf;
    c->t = t0;
    int ok = SUNContext_Create(NULL, &c->ctx) == 0;
    if (ok) ok = (c->y = N_VNew_Serial((sunindextype)n, c->ctx)) != NULL;
    if (ok) ok = (c->ky = N_VNew_Serial((sunindextype)n, c->ctx)) != NULL;
    if (ok) {
        memcpy(N_VGetArrayPointer(c->y), y0, n * sizeof(double));
        ok = (c->mem = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, c->ctx)) != NULL;
    }
    if (ok) ok = CVodeSetErrHandlerFn(c->mem, cv_silent, NULL) == CV_SUCCESS;
    if (ok) ok = CVodeInit(c->mem, cv_rhs, t0, c->y) == CV_SUCCESS;
    if (ok) ok = CVodeSetUserData(c->mem, c) == CV_SUCCESS;
    if (ok && opt->atol_vec) {
        ok = (c->atolv = N_VNew_Serial((sunindextype)n, c->ctx)) != NULL;
        if (ok) {
            memcpy(N_VGetArrayPointer(c->atolv), opt->atol_vec, n * sizeof(double));
            ok = CVodeSVtolerances(c->mem, opt->rtol, c->atolv) == CV_SUCCESS;
        }
    } else if (ok) {
        ok = CVodeSStolerances(c->mem, opt->rtol, opt->atol) == CV_SUCCESS;
    }
    if (ok) {
        if (bdf) {
            ok = (c->A = SUNDenseMatrix((sunindextype)n, (sunindextype)n, c->ctx)) != NULL;
            if (ok) ok = (c->LS = SUNLinSol_Dense(c->y, c->A, c->ctx)) != NULL;
            if (ok) ok = CVodeSetLinearSolver(c->mem, c->LS, c->A) == CV_SUCCESS;
            if (ok && sys->jacobian) {
                ok = (c->jwork = malloc(n * n * sizeof(double))) != NULL;
                if (ok) ok = CVodeSetJacFn(c->mem, cv_jac) == CV_SUCCESS;
            }
        } else {
            ok = (c->NLS = SUNNonlinSol_FixedPoint(c->y, 0, c->ctx)) != NULL;
            if (ok) ok = CVodeSetNonlinearSolver(c->mem, c->NLS) == CV_SUCCESS;
        }
    }
    if (ok) ok = CVodeSetMaxNumSteps(c->mem, opt->max_steps > 0 ? opt->max_steps : 10000000L) == CV_SUCCESS;
    if (ok && opt->hmax > 0) ok = CVodeSetMaxStep(c->mem, opt->hmax) == CV_SUCCESS;
    if (ok && opt->h0 > 0) ok = CVodeSetInitStep(c->mem, opt->h0) == CV_SUCCESS;
    if (ok && isfinite(opt->tstop)) ok = CVodeSetStopTime(c->mem, opt->tstop) == CV_SUCCESS;
    if (ok && opt->project) {
        c->project = opt->project;
        ok = (c->yproj = malloc(n * sizeof(double))) != NULL;
        if (ok) ok = CVodeSetProjFn(c->mem, cv_project) == CV_SUCCESS;
        if (ok) ok = CVodeSetProjErrEst(c->mem, SUNFALSE) == CV_SUCCESS;
    }
    if (!ok) {
        cv_destroy(c);
        return SWIM_ODE_EFAIL;
    }
    *impl = c;
    *be = &cv_backend;
    return SWIM_ODE_OK;
}
