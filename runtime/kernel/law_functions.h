/* law_functions.h -- the functions of a compiled law (generator/swimgen/law.py), for generated
 * kernels.
 *
 * A law is validated by the runtime's interpreter (runtime/scene/expr.c), which calls the C
 * library's sin, pow, ... through pointers. The compiled law must compute the same function, to
 * the last bit. Called directly, the compiler may rewrite these calls (pow(x, 2.0) -> x*x) or
 * fold them with its own correctly rounded arithmetic, and the C library's results differ from
 * those in the last place for some arguments. So the compiled law calls them through pointers
 * the compiler cannot look through (volatile): the C library is then the one evaluator of both.
 * sqrt, fabs, + - * / and comparisons are exact or correctly rounded everywhere and are written
 * directly. Written by hand.
 */
#ifndef SWIM_LAW_FUNCTIONS_H
#define SWIM_LAW_FUNCTIONS_H

#include <math.h>

#define SWIM_LAW_FN1(name) \
    static double (*const volatile swim_law_##name)(double) __attribute__((unused)) = name;
SWIM_LAW_FN1(sin)
SWIM_LAW_FN1(cos)
SWIM_LAW_FN1(tan)
SWIM_LAW_FN1(asin)
SWIM_LAW_FN1(acos)
SWIM_LAW_FN1(atan)
SWIM_LAW_FN1(exp)
SWIM_LAW_FN1(log)
SWIM_LAW_FN1(sinh)
SWIM_LAW_FN1(cosh)
SWIM_LAW_FN1(tanh)
#undef SWIM_LAW_FN1
static double (*const volatile swim_law_pow)(double, double) __attribute__((unused)) = pow;

#endif
