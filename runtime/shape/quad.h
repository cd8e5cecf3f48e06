/* Quad precision (__float128) for the shape code, under gcc and clang.
 * gcc: <quadmath.h>. clang does not search gcc's private include folder, so the few libquadmath
 * functions used here are declared directly (same ABI; link with -lquadmath either way).
 * Also provides CMPLX where the C library lacks it (clang 14 in C11 mode). */
#ifndef SWIM_SHAPE_QUAD_H
#define SWIM_SHAPE_QUAD_H
#include <complex.h>

#if defined(__GNUC__) && !defined(__clang__)
#include <quadmath.h>
#else
typedef _Complex float __attribute__((mode(TC))) __complex128;
#define M_PIq 3.141592653589793238462643383279502884Q
extern __float128 cosq(__float128);
extern __float128 sinq(__float128);
extern __float128 fabsq(__float128);
extern __float128 fmodq(__float128, __float128);
extern __float128 powq(__float128, __float128);
extern __float128 sqrtq(__float128);
extern __float128 cabsq(__complex128);
extern __float128 crealq(__complex128);
extern __float128 cimagq(__complex128);
extern __complex128 cexpq(__complex128);
extern __complex128 conjq(__complex128);
#endif

#ifndef CMPLX
#define CMPLX(x, y) __builtin_complex((double)(x), (double)(y))
#endif
#endif
