/* expr.h -- scalar expressions in t for forcing laws F(t) (section 5.1), e.g.
 * "2*(4*atan(t)^2/pi^2)*cos(t/3)" or, with a scene's [parameters] A and w, "A*sin(w*t)".
 * Grammar: numbers, t, pi, e, parameter names; + - * / ^ (right-assoc.),
 * unary minus, parentheses; functions sin cos tan asin acos atan exp log sqrt abs sinh cosh
 * tanh, and step (Heaviside: 1 for x >= 0, else 0). Compiled once to a small stack program; evaluation allocates nothing.
 * Stroke laws c(t) use the same grammar. A generated kernel computes the same operations in the
 * same order on the same doubles (generator/swimgen/law.py), so its value of a law is this one's. */
#ifndef SWIM_EXPR_H
#define SWIM_EXPR_H

#include <stddef.h>

typedef struct swim_expr swim_expr;

/* NULL on error, with a one-line message ("at column C: ...") in err. */
swim_expr *swim_expr_compile(const char *text, char *err, size_t errlen);
double swim_expr_eval(const swim_expr *e, double t);
/* 1 when the law is defined at t: every operation in it has a finite real result there. A law
 * may have a finite value without being defined (step(sqrt(-1)) is 0, 0*log(0)... is NaN only
 * by luck of the order): such a law has no meaning, and the generator, which computes its
 * constant parts ahead of time, refuses it. 0 otherwise, with the first operation that is not
 * finite in why (e.g. "sqrt(-1) is not a finite real number"); why may be NULL. */
int swim_expr_defined(const swim_expr *e, double t, char *why, size_t len);
/* The same grammar with named parameters: names[0..count) may appear in the text, and each
 * evaluation reads their current values from values[0..count) (borrowed: the caller keeps the
 * array alive as long as the expression and may change the values between evaluations, which
 * is how a sweep or an optimizer varies a law without recompiling it). A name that is neither
 * t, pi, e, a function nor one of names is an error naming it. */
swim_expr *swim_expr_compile_params(const char *text, const char *const *names, int count,
                                    const double *values, char *err, size_t errlen);
/* 1 when `name` is taken by the grammar (t, pi, e or a function name): it cannot name a parameter. */
int swim_expr_reserved(const char *name);
void swim_expr_free(swim_expr *e);

#endif
