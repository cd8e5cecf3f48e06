/* lyapunov.c -- the exponent, horizon and verdict of Benettin's method from the growth of the
 * tangent vector the run carries (model/lyapunov.h). */
#include "model/lyapunov.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


/* A fixed pseudo-random unit vector on the shape state (the same start at every tolerance). */
static void start_vector(double *w, int n, int from, int count)
{
    unsigned long x = 0x2545F4914F6CDD1DUL;
    double norm = 0.0;
    memset(w, 0, sizeof(double) * n);
    for (int i = from; i < from + count; i++) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        w[i] = (double)(x >> 11) / 9007199254740992.0 - 0.5;
        norm += w[i] * w[i];
    }
    norm = sqrt(norm);
    for (int i = from; i < from + count; i++) w[i] /= norm;
}

/* Least-squares slope of y against x over [from, to) (points with x > 0 only when logx). */
static double slope(const double *x, const double *y, int from, int to, int logx)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int m = 0;
    for (int k = from; k < to; k++) {
        if (logx && !(x[k] > 0)) continue;
        const double u = logx ? log(x[k]) : x[k];
        sx += u;
        sy += y[k];
        sxx += u * u;
        sxy += u * y[k];
        m++;
    }
    const double den = m * sxx - sx * sx;
    return m >= 2 && den > 0 ? (m * sxy - sx * sy) / den : NAN;
}

/* The verdict of lyapunov.h on l's segments; need = ln(separation / rtol). */
static void assess(swim_lyapunov *l, double need)
{
    l->verdict = SWIM_LYAP_NOT_CONVERGED;
    l->rate_first = l->rate_second = l->power = l->horizon_power = l->t_end_needed = NAN;
    const int n = l->n;
    const double T = n > 0 ? l->t[n - 1] : 0.0;
    if (n < 2) {
        l->t_end_needed = SWIM_LYAPUNOV_MIN_SEGMENTS * l->interval;
        return;
    }
    /* the points (0, 0), (t_k, G_k): the first half is [0, h], the second [h, n] */
    double *t = malloc(sizeof(double) * (size_t)(n + 1)), *G = malloc(sizeof(double) * (size_t)(n + 1));
    if (!t || !G) {
        free(t);
        free(G);
        return;
    }
    t[0] = G[0] = 0.0;
    for (int k = 0; k < n; k++) {
        t[k + 1] = l->t[k];
        G[k + 1] = G[k] + l->log_growth[k];
    }
    const int h = (n + 1) / 2;
    l->rate_first = slope(t, G, 0, h + 1, 0);
    l->rate_second = slope(t, G, h, n + 1, 0);
    l->power = slope(t, G, h, n + 1, 1);
    const double a1 = l->rate_first, a2 = l->rate_second, half = T - t[h];
    const int enough = n >= SWIM_LYAPUNOV_MIN_SEGMENTS;
    const int agree = fabs(a1 - a2) <= SWIM_LYAPUNOV_AGREE * fmax(fabs(a1), fabs(a2));
    if (enough && agree && fabs(a2) * half >= SWIM_LYAPUNOV_EFOLDS) {
        l->verdict = SWIM_LYAP_CONVERGED;
    } else if (enough && l->power <= SWIM_LYAPUNOV_POWER) {
        l->verdict = SWIM_LYAP_REGULAR;
        /* G(t) = G_fit(T) + p ln(t / T): the power law's value at T from the fit's centroid */
        double su = 0, sg = 0;
        for (int k = h; k <= n; k++) {
            su += log(t[k]);
            sg += G[k];
        }
        const double gT = sg / (n + 1 - h) + l->power * (log(T) - su / (n + 1 - h));
        l->horizon_power = gT >= need ? NAN : l->power > 0 ? T * exp((need - gT) / l->power) : INFINITY;
    } else {
        /* twice as long, and long enough for the e-folds at the second half's rate */
        double want = 2.0 * T;
        if (a2 > 0) want = fmax(want, 2.0 * SWIM_LYAPUNOV_EFOLDS / a2);
        if (!enough) want = fmax(want, SWIM_LYAPUNOV_MIN_SEGMENTS * l->interval);
        l->t_end_needed = want;
    }
    free(t);
    free(G);
}

const char *swim_lyapunov_verdict_name(swim_lyapunov_verdict v)
{
    return v == SWIM_LYAP_CONVERGED ? "converged" : v == SWIM_LYAP_REGULAR ? "regular" : "not_converged";
}

void swim_lyapunov_start(double *w, int n, int from, int count) { start_vector(w, n, from, count); }

int swim_lyapunov_from_marks(swim_lyapunov *l, double interval, double rtol, const double *t, const double *log_norm,
                             long marks)
{
    l->interval = interval;
    l->rtol = rtol;
    l->n = 0;
    free(l->t);
    free(l->log_growth);
    l->t = malloc(sizeof(double) * (size_t)(marks > 0 ? marks : 1));
    l->log_growth = malloc(sizeof(double) * (size_t)(marks > 0 ? marks : 1));
    if (!l->t || !l->log_growth) return -1;
    /* segment k: the growth between marks k-1 and k (|w| = 1 at t = 0) */
    double sum = 0.0, prev = 0.0;
    for (long k = 0; k < marks; k++) {
        l->t[l->n] = t[k];
        l->log_growth[l->n++] = log_norm[k] - prev;
        prev = log_norm[k];
    }
    sum = prev;
    const double tend = l->n > 0 ? l->t[l->n - 1] : 0.0;
    l->t_end = tend;
    l->exponent = tend > 0 ? sum / tend : NAN;
    if (l->n >= 2) {   /* the second half alone: the running exponent should have settled */
        const int h = l->n / 2;
        double s2 = 0.0;
        for (int k = h; k < l->n; k++) s2 += l->log_growth[k];
        l->exponent_half = s2 / (l->t[l->n - 1] - l->t[h - 1]);
    } else {
        l->exponent_half = l->exponent;
    }
    const double need = log(SWIM_LYAPUNOV_SEPARATION / l->rtol);
    l->horizon_mean = l->exponent > 0 ? need / l->exponent : INFINITY;
    l->horizon = INFINITY;
    double cum = 0.0;
    for (int k = 0; k < l->n; k++) {
        const double before = cum, t_before = k ? l->t[k - 1] : 0.0;
        cum += l->log_growth[k];
        if (cum >= need) {   /* within this segment, as if the growth were uniform over it */
            l->horizon = t_before + (l->t[k] - t_before) * (need - before) / (cum - before);
            break;
        }
    }
    assess(l, need);
    return 0;
}

void swim_lyapunov_free(swim_lyapunov *l)
{
    free(l->t);
    free(l->log_growth);
    l->t = l->log_growth = NULL;
}
