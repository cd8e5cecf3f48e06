#include "scene/expr.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { OP_NUM, OP_T, OP_PAR, OP_ADD, OP_SUB, OP_MUL, OP_DIV, OP_POW, OP_NEG, OP_FUN };

typedef double (*fun1)(double);
static double heaviside(double x) { return x >= 0.0 ? 1.0 : 0.0; }
static const struct { const char *name; fun1 f; } funcs[] = {
    {"sin", sin},   {"cos", cos},   {"tan", tan},   {"asin", asin}, {"acos", acos},
    {"atan", atan}, {"exp", exp},   {"log", log},   {"sqrt", sqrt}, {"abs", fabs},
    {"sinh", sinh}, {"cosh", cosh}, {"tanh", tanh}, {"step", heaviside},
};
#define FUN_ABS 9
#define FUN_STEP 13
#define NFUNCS (int)(sizeof funcs / sizeof funcs[0])
#define MAX_DEPTH 64
/* The program has no length limit (a law of any length is compiled whole); its evaluation stack
 * grows only with nesting, by at most a few entries per level, so MAX_DEPTH bounds it. */
#define MAX_STACK (4 * MAX_DEPTH + 8)

typedef struct { int op; int fn; double v; } instr;

struct swim_expr {
    instr *code;
    int len, cap, stack;
    const double *values;   /* parameter values read by OP_PAR (borrowed) */
};

typedef struct {
    const char *s, *p;
    swim_expr *e;
    char *err;
    size_t errlen;
    int failed, depth;
    const char *const *names;   /* parameter names, count of them */
    int count;
} parser;

static void fail(parser *ps, const char *msg)
{
    if (!ps->failed && ps->err)
        snprintf(ps->err, ps->errlen, "at column %d: %s", (int)(ps->p - ps->s) + 1, msg);
    ps->failed = 1;
}

static void emit(parser *ps, int op, int fn, double v)
{
    swim_expr *e = ps->e;
    if (e->len == e->cap) {
        int cap = e->cap ? 2 * e->cap : 64;
        instr *code = realloc(e->code, (size_t)cap * sizeof *code);
        if (!code) { fail(ps, "out of memory"); return; }
        e->code = code;
        e->cap = cap;
    }
    e->code[e->len++] = (instr){op, fn, v};
}

static void skip(parser *ps) { while (*ps->p == ' ' || *ps->p == '\t') ps->p++; }

static void expr_sum(parser *ps);

static void expr_atom(parser *ps)
{
    skip(ps);
    if (++ps->depth > MAX_DEPTH) { fail(ps, "expression nested too deeply"); return; }
    const char *p = ps->p;
    if (*p == '(') {
        ps->p++;
        expr_sum(ps);
        skip(ps);
        if (*ps->p != ')') fail(ps, "expected ')'");
        else ps->p++;
    } else if (isdigit((unsigned char)*p) || (*p == '.' && isdigit((unsigned char)p[1]))) {
        char *end;
        double v = strtod(p, &end);
        if (!isfinite(v)) { fail(ps, "number out of range"); return; }
        ps->p = end;
        emit(ps, OP_NUM, 0, v);
    } else if (isalpha((unsigned char)*p)) {
        const char *q = p;
        while (isalnum((unsigned char)*q) || *q == '_') q++;
        size_t n = (size_t)(q - p);
        ps->p = q;
        if (n == 1 && *p == 't') emit(ps, OP_T, 0, 0);
        else if (n == 2 && strncmp(p, "pi", 2) == 0) emit(ps, OP_NUM, 0, 3.14159265358979323846);
        else if (n == 1 && *p == 'e') emit(ps, OP_NUM, 0, 2.71828182845904523536);
        else {
            int fn = -1, par = -1;
            for (int i = 0; i < NFUNCS; i++)
                if (strlen(funcs[i].name) == n && strncmp(funcs[i].name, p, n) == 0) fn = i;
            for (int i = 0; fn < 0 && i < ps->count; i++)
                if (strlen(ps->names[i]) == n && strncmp(ps->names[i], p, n) == 0) par = i;
            if (par >= 0) { emit(ps, OP_PAR, par, 0); ps->depth--; return; }
            if (fn < 0) {
                char msg[128];
                ps->p = p;
                snprintf(msg, sizeof msg, "unknown name '%.*s' (use t, pi, e, %sa function such as sin)",
                         (int)(n < 40 ? n : 40), p, ps->count ? "a name of [parameters], " : "");
                fail(ps, msg);
                return;
            }
            skip(ps);
            if (*ps->p != '(') { fail(ps, "expected '(' after function name"); return; }
            ps->p++;
            expr_sum(ps);
            skip(ps);
            if (*ps->p != ')') { fail(ps, "expected ')'"); return; }
            ps->p++;
            emit(ps, OP_FUN, fn, 0);
        }
    } else {
        fail(ps, *p ? "unexpected character" : "unexpected end of expression");
    }
    ps->depth--;
}

static void expr_unary(parser *ps);

static void expr_power(parser *ps)
{
    expr_atom(ps);
    skip(ps);
    if (!ps->failed && *ps->p == '^') {
        ps->p++;
        expr_unary(ps);   /* right-associative: 2^-1 and a^b^c = a^(b^c) */
        emit(ps, OP_POW, 0, 0);
    }
}

static void expr_unary(parser *ps)
{
    skip(ps);
    if (*ps->p == '-' || *ps->p == '+') {
        int neg = *ps->p == '-';
        ps->p++;
        if (++ps->depth > MAX_DEPTH) { fail(ps, "expression nested too deeply"); return; }
        expr_unary(ps);
        ps->depth--;
        if (neg) emit(ps, OP_NEG, 0, 0);
    } else {
        expr_power(ps);
    }
}

static void expr_product(parser *ps)
{
    expr_unary(ps);
    for (;;) {
        skip(ps);
        if (ps->failed || (*ps->p != '*' && *ps->p != '/')) return;
        int op = *ps->p == '*' ? OP_MUL : OP_DIV;
        ps->p++;
        expr_unary(ps);
        emit(ps, op, 0, 0);
    }
}

static void expr_sum(parser *ps)
{
    expr_product(ps);
    for (;;) {
        skip(ps);
        if (ps->failed || (*ps->p != '+' && *ps->p != '-')) return;
        int op = *ps->p == '+' ? OP_ADD : OP_SUB;
        ps->p++;
        expr_product(ps);
        emit(ps, op, 0, 0);
    }
}

swim_expr *swim_expr_compile(const char *text, char *err, size_t errlen)
{
    return swim_expr_compile_params(text, NULL, 0, NULL, err, errlen);
}

int swim_expr_reserved(const char *name)
{
    if (strcmp(name, "t") == 0 || strcmp(name, "pi") == 0 || strcmp(name, "e") == 0) return 1;
    for (int i = 0; i < NFUNCS; i++)
        if (strcmp(funcs[i].name, name) == 0) return 1;
    return 0;
}

swim_expr *swim_expr_compile_params(const char *text, const char *const *names, int count,
                                    const double *values, char *err, size_t errlen)
{
    swim_expr *e = calloc(1, sizeof *e);
    if (!e) { if (err) snprintf(err, errlen, "out of memory"); return NULL; }
    e->values = values;
    parser ps = {text, text, e, err, errlen, 0, 0, names, count};
    expr_sum(&ps);
    skip(&ps);
    if (!ps.failed && *ps.p) fail(&ps, "unexpected text after the expression");
    if (ps.failed) { swim_expr_free(e); return NULL; }
    int depth = 0;
    for (int i = 0; i < e->len; i++) {
        int op = e->code[i].op;
        depth += (op == OP_NUM || op == OP_T || op == OP_PAR) ? 1 : (op == OP_NEG || op == OP_FUN) ? 0 : -1;
        if (depth > e->stack) e->stack = depth;
    }
    if (e->stack > MAX_STACK) {
        if (err) snprintf(err, errlen, "expression nested too deeply");
        swim_expr_free(e);
        return NULL;
    }
    return e;
}

/* Executes one instruction on the stack st (top st[*sp - 1]); its operands are left in a and b
 * (for messages). Returns the result, now on top. */
static inline double exec(const swim_expr *e, const instr *in, double t, double *st, int *sp, double *a,
                          double *b)
{
    switch (in->op) {
    case OP_NUM: st[(*sp)++] = in->v; break;
    case OP_T: st[(*sp)++] = *a = t; break;
    case OP_PAR: st[(*sp)++] = *a = e->values[in->fn]; break;
    case OP_NEG: *a = st[*sp - 1]; st[*sp - 1] = -*a; break;
    case OP_FUN: *a = st[*sp - 1]; st[*sp - 1] = funcs[in->fn].f(*a); break;
    default:
        *b = st[--*sp];
        *a = st[*sp - 1];
        st[*sp - 1] = in->op == OP_ADD ? *a + *b : in->op == OP_SUB ? *a - *b
                    : in->op == OP_MUL ? *a * *b : in->op == OP_DIV ? *a / *b : pow(*a, *b);
    }
    return st[*sp - 1];
}

double swim_expr_eval(const swim_expr *e, double t)
{
    double st[MAX_STACK], a, b;
    int sp = 0;
    for (int i = 0; i < e->len; i++) exec(e, &e->code[i], t, st, &sp, &a, &b);
    return st[0];
}

/* The operation at `in` with operands a (and b) and its result, as "sqrt(-1)" or "10 ^ 400". */
static void describe(const instr *in, double a, double b, char *why, size_t len)
{
    static const char ops[] = "+-*/^";
    switch (in->op) {
    case OP_T: snprintf(why, len, "t = %g is not finite", a); break;
    case OP_PAR: snprintf(why, len, "parameter %d = %g is not finite", in->fn + 1, a); break;
    case OP_NEG: snprintf(why, len, "-(%g) is not finite", a); break;
    case OP_FUN: snprintf(why, len, "%s(%g) is not a finite real number", funcs[in->fn].name, a); break;
    default: snprintf(why, len, "%g %c %g is not a finite real number", a, ops[in->op - OP_ADD], b);
    }
}

int swim_expr_defined(const swim_expr *e, double t, char *why, size_t len)
{
    double st[MAX_STACK];
    int sp = 0;
    for (int i = 0; i < e->len; i++) {
        double a = 0.0, b = 0.0;
        if (!isfinite(exec(e, &e->code[i], t, st, &sp, &a, &b))) {
            if (why && len) describe(&e->code[i], a, b, why, len);
            return 0;
        }
    }
    return 1;
}

void swim_expr_free(swim_expr *e)
{
    if (e) free(e->code);
    free(e);
}
