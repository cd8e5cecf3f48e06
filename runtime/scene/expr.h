/* expr.h -- scalar expressions in t for forcing laws F(t) (section 5.1), e.g.
 * "2*(4*atan(t)^2/pi^2)*cos(t/3)". Grammar: numbers, t, pi, e; + - * / ^ (right-assoc.),
 * unary minus, parentheses; functions sin cos tan asin acos atan exp log sqrt abs sinh cosh
 * tanh, and step (Heaviside: 1 for x >= 0, else 0). Compiled once to a small stack program; evaluation allocates nothing. */
#ifndef SWIM_EXPR_H
#define SWIM_EXPR_H

#include <stddef.h>

typedef struct swim_expr swim_expr;

/* NULL on error, with a one-line message ("at column C: ...") in err. */
swim_expr *swim_expr_compile(const char *text, char *err, size_t errlen);
double swim_expr_eval(const swim_expr *e, double t);
/* The expression as a C99 expression in a double variable `t` (for generated kernels).
 * Returns the length written (like snprintf). */
int swim_expr_to_c(const swim_expr *e, char *buf, size_t len);
void swim_expr_free(swim_expr *e);

#endif
