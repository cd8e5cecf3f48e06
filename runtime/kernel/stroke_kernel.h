/* stroke_kernel.h -- contract between a generated stroke kernel and the runtime.
 *
 * A prescribed stroke (scene table [stroke], section 3.3) gives some shape coordinates as laws
 * in t. The generator (generator/swimgen/stroke.py) differentiates them exactly and emits one
 * function, eval, with c, c' and c'' of every prescribed coordinate; runtime/stroke/ completes
 * the rest of the shape and integrates (3.21). Written by hand; the caller owns every array.
 */
#ifndef SWIM_STROKE_KERNEL_H
#define SWIM_STROKE_KERNEL_H

#define SWIM_STROKE_ABI 1

typedef struct swim_stroke_kernel {
    int abi;                    /* SWIM_STROKE_ABI */
    int modes;                  /* N of the scene */
    int count;                  /* prescribed coordinates */
    const int *index;           /* count indices into the shape vector (a1, b1, a-1, b-1, ...) */
    int nparams;                /* named parameters the laws use (par[0..nparams)) */
    const char *structure;      /* the structure key it was generated for */
    /* c[k], dc[k], ddc[k]: the law of coordinate index[k] and its first two time derivatives */
    void (*eval)(double t, const double *par, double *c, double *dc, double *ddc);
} swim_stroke_kernel;

/* Exported name: "swim_stroke_kernel_entry". */

#endif
