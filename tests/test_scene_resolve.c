/* Tests for the scene as run (runtime/scene/resolve.h, swim_scene_resolve): overrides written into
 * a scene file's text.
 *   - Hand-written texts with their exact expected results: a value replaced in place with its
 *     comment kept, an integer kept an integer, items of one-line and multi-line arrays (comments,
 *     nested arrays, strings with ',' ']' '#' inside), a coordinate name, a key added at the end of
 *     its table, a new table, words as strings and booleans, "\r\n" files, a file without its
 *     last line end, a byte order mark, dotted keys, numbers that read back bit for bit, the
 *     header's quoting of control characters, and the refusals.
 *   - Every scene of models/ with overrides of each kind (a scalar of an existing table, an item
 *     by index, an item by coordinate name, an absent key, words, a new table): the scene read
 *     from the resolved text without overrides is the scene swim_scene_parse_with reads from the
 *     file with them (every field but line numbers and owned pointers compared byte for byte,
 *     strings and laws separately), it differs from the file's own scene, and every line no
 *     override touches is in the result byte for byte, in order. */
#include <fcntl.h>
#include <glob.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "kernel/coords.h"
#include "scene/resolve.h"
#include "scene/scene.h"
#include "scene/toml.h"

/* ---- helpers ------------------------------------------------------------------------------ */

static int saved_stderr = -1;

/* The scene reader reports on stderr (projections, refusals of candidate overrides): quiet. */
static void quiet(int on)
{
    fflush(stderr);
    if (on && saved_stderr < 0) {
        saved_stderr = dup(2);
        int fd = open("/dev/null", O_WRONLY);
        if (fd >= 0) {
            dup2(fd, 2);
            close(fd);
        }
    } else if (!on && saved_stderr >= 0) {
        dup2(saved_stderr, 2);
        close(saved_stderr);
        saved_stderr = -1;
    }
}

static swim_override ovr(const char *text)
{
    swim_override o;
    char err[256];
    int rc = swim_override_parse(text, &o, err, sizeof err);
    CHECK(rc == 0, "override '%s' parses: %s", text, err);
    return o;
}

/* swim_scene_resolve on a NUL-terminated text; NULL when it refuses (reason in err). */
static char *resolve(const char *text, const char *path, const swim_override *ov, int nov, char *err, size_t errlen)
{
    char *out = NULL;
    size_t outlen = 0;
    err[0] = '\0';
    /* an exact-size copy, not NUL-terminated, so that sanitizers see any over-read */
    const size_t len = strlen(text);
    char *copy = malloc(len ? len : 1);
    memcpy(copy, text, len);
    int rc = swim_scene_resolve(copy, len, path, ov, nov, &out, &outlen, err, errlen);
    free(copy);
    if (rc != 0) {
        CHECK(out == NULL, "refusal leaves no buffer");
        CHECK(err[0] != '\0' && !strchr(err, '\n'), "refusal has a one-line reason: '%s'", err);
        return NULL;
    }
    CHECK(out && strlen(out) == outlen, "result length %zu", outlen);
    return out;
}

/* One hand-written case: the result must be `want` exactly. */
static void case_exact(const char *what, const char *text, const char *const *sets, int nsets, const char *want)
{
    swim_override ov[16];
    for (int i = 0; i < nsets; i++) ov[i] = ovr(sets[i]);
    char err[512];
    char *got = resolve(text, "x.toml", ov, nsets, err, sizeof err);
    CHECK(got != NULL, "%s: refused: %s", what, err);
    if (!got) return;
    CHECK(strcmp(got, want) == 0, "%s:\n--- got:\n%s--- want:\n%s---", what, got, want);
    /* the result is TOML the reader takes, and each override's value is there bit for bit */
    const char *body = got;
    if (!strncmp(body, "\xEF\xBB\xBF", 3)) body += 3;
    char perr[256];
    toml_value *root = toml_parse(body, strlen(body), perr, sizeof perr);
    CHECK(root != NULL, "%s: result parses: %s", what, perr);
    for (int i = 0; root && i < nsets; i++) {
        const toml_value *v = toml_get(toml_get(root, ov[i].table), ov[i].key);
        if (v && ov[i].index >= 0) v = toml_array_at(v, (size_t)ov[i].index);
        CHECK(v != NULL, "%s: %s is in the result", what, ov[i].text);
        if (!v) continue;
        if (!ov[i].word[0]) {
            const double x = toml_number(v);
            CHECK(memcmp(&x, &ov[i].value, sizeof x) == 0, "%s: %s reads back as %.17g", what, ov[i].text, x);
        } else if (!strcmp(ov[i].word, "true") || !strcmp(ov[i].word, "false")) {
            CHECK(toml_kind_of(v) == TOML_BOOL && toml_bool(v) == (ov[i].word[0] == 't'), "%s: %s a boolean", what, ov[i].text);
        } else {
            CHECK(toml_string(v) && !strcmp(toml_string(v), ov[i].word), "%s: %s a string", what, ov[i].text);
        }
    }
    toml_free(root);
    free(got);
}

static void case_refused(const char *what, const char *text, const char *const *sets, int nsets, const char *reason)
{
    swim_override ov[16];
    for (int i = 0; i < nsets; i++) ov[i] = ovr(sets[i]);
    char err[512];
    char *got = resolve(text, "x.toml", ov, nsets, err, sizeof err);
    CHECK(got == NULL, "%s: refused (got:\n%s)", what, got ? got : "");
    CHECK(strstr(err, reason) != NULL, "%s: reason '%s' names '%s'", what, err, reason);
    free(got);
}

#define SETS(...) (const char *const[]){__VA_ARGS__}, (int)(sizeof((const char *const[]){__VA_ARGS__}) / sizeof(const char *))

static void test_exact(void)
{
    const char *H = "# resolved by swim: ";
    char want[2048];

    snprintf(want, sizeof want, "%s--set run.t_end=2 applied to x.toml\n"
             "[run]\nt_end = 2.0 # the end, = [1] \"x\"\nrtol = 1e-10\n", H);
    case_exact("float replaced, comment kept", "[run]\nt_end = 30.0 # the end, = [1] \"x\"\nrtol = 1e-10\n",
               SETS("run.t_end=2"), want);

    snprintf(want, sizeof want, "%s--set model.modes=4, --set model.rho0=2.5 applied to x.toml\n"
             "[model]\nmodes   =   4   \t# N\nrho0 = 2.5\n", H);
    case_exact("integer kept an integer", "[model]\nmodes   =   3   \t# N\nrho0 = 1\n",
               SETS("model.modes=4", "model.rho0=2.5"), want);

    snprintf(want, sizeof want, "%s--set shape.c0[2]=0.5, --set shape.c0.bm1=-1e-300 applied to x.toml\n"
             "[shape]\n#       a1 b1 a-1 b-1\nc0  = [ 1, 0, 0.5,  -1e-300 ]  # c\ndc0 = [ 0, 0, 0.6, 0 ]\n", H);
    case_exact("items of a one-line array, by index and by name",
               "[shape]\n#       a1 b1 a-1 b-1\nc0  = [ 1, 0, 0.4,  0 ]  # c\ndc0 = [ 0, 0, 0.6, 0 ]\n",
               SETS("shape.c0[2]=0.5", "shape.c0.bm1=-1e-300"), want);

    const char *multi = "[t]\nx = [\n  1, # one, ]\n  \"a,]#\", [3, [4, 5]],\n  0x10 , # sixteen\n  6\n  ,7,\n]   # end\ny = 1\n";
    snprintf(want, sizeof want, "%s--set t.x[3]=0.25, --set t.x[5]=8, --set t.x[4]=-3 applied to x.toml\n"
             "[t]\nx = [\n  1, # one, ]\n  \"a,]#\", [3, [4, 5]],\n  0.25 , # sixteen\n  -3\n  ,8,\n]   # end\ny = 1\n", H);
    case_exact("items of a multi-line array (comments, strings, nested arrays)", multi,
               SETS("t.x[3]=0.25", "t.x[5]=8", "t.x[4]=-3"), want);

    snprintf(want, sizeof want, "%s--set run.rtol=1e-9, --set run.jacobian=differences, --set run.projection=false applied to x.toml\n"
             "[run]\nt_end = 1\nrtol = 1e-09\njacobian = \"differences\"\nprojection = false\n\n# the model\n[model]\nmodes = 3\n", H);
    case_exact("absent keys added after the table's last key",
               "[run]\nt_end = 1\n\n# the model\n[model]\nmodes = 3\n",
               SETS("run.rtol=1e-9", "run.jacobian=differences", "run.projection=false"), want);

    snprintf(want, sizeof want, "%s--set barrier.epsilon=0.03, --set run.t_end=5, --set barrier.alpha=1, --set parameters.A=-0 applied to x.toml\n"
             "[run]\nt_end = 5\n\n[barrier]\nepsilon = 0.03\nalpha = 1.0\n\n[parameters]\nA = -0.0\n", H);
    case_exact("absent tables appended", "[run]\nt_end = 1\n",
               SETS("barrier.epsilon=0.03", "run.t_end=5", "barrier.alpha=1", "parameters.A=-0"), want);

    snprintf(want, sizeof want, "%s--set run.integrator=rk45, --set run.project_initial=false applied to x.toml\n"
             "[run]\nintegrator = \"rk45\"   # was abm\nproject_initial = false\n", H);
    case_exact("string and boolean replaced", "[run]\nintegrator = 'abm'   # was abm\nproject_initial = true\n",
               SETS("run.integrator=rk45", "run.project_initial=false"), want);

    snprintf(want, sizeof want, "%s--set forcing.law=cos applied to x.toml\n"
             "[forcing]\nlaw = \"cos\" # \"b # c\"\n", H);
    case_exact("a string with '#' and escapes replaced", "[forcing]\nlaw = \"a \\\" # b\" # \"b # c\"\n",
               SETS("forcing.law=cos"), want);

    snprintf(want, sizeof want, "%s--set run.t_end=3, --set run.rtol=1e-8, --set model.rho0=2 applied to x.toml\r\n"
             "[run]\r\nt_end = 3.0\r\nrtol = 1e-08\r\n[model]\r\nrho0 = 2.0\r\n", H);
    case_exact("\\r\\n line ends", "[run]\r\nt_end = 1.0\r\n[model]\r\nrho0 = 1.0\r\n",
               SETS("run.t_end=3", "run.rtol=1e-8", "model.rho0=2"), want);

    snprintf(want, sizeof want, "%s--set run.rtol=0.001, --set shape.x=1 applied to x.toml\n"
             "[run]\nt_end = 1\nrtol = 0.001\n\n[shape]\nx = 1.0\n", H);
    case_exact("no line end at the end of the file", "[run]\nt_end = 1", SETS("run.rtol=0.001", "shape.x=1"), want);

    snprintf(want, sizeof want, "\xEF\xBB\xBF%s--set run.t_end=0.1 applied to x.toml\n[run]\nt_end = 0.1\n", H);
    case_exact("a byte order mark stays first", "\xEF\xBB\xBF[run]\nt_end = 1\n", SETS("run.t_end=0.1"), want);

    snprintf(want, sizeof want, "%s--set run.t_end=7, --set shape.c0.a1=0.75 applied to x.toml\n"
             "title = \"t\"\nrun.t_end = 7\n\"shape\" . 'c0' = [0.75, 0]\n", H);
    case_exact("dotted and quoted keys", "title = \"t\"\nrun.t_end = 1\n\"shape\" . 'c0' = [1.0, 0]\n",
               SETS("run.t_end=7", "shape.c0.a1=0.75"), want);

    snprintf(want, sizeof want, "%s--set run.t_end=0.30000000000000004, --set run.atol=1e300, --set run.rtol=5e-324, "
             "--set run.output_step=0.1 applied to x.toml\n"
             "[run]\nt_end = 0.30000000000000004\natol = 1e+300\nrtol = 4.94065645841247e-324\noutput_step = 0.1\n", H);
    case_exact("numbers that read back bit for bit",
               "[run]\nt_end = 1\natol = 2\nrtol = 3\noutput_step = 4.0\n",
               SETS("run.t_end=0.30000000000000004", "run.atol=1e300", "run.rtol=5e-324", "run.output_step=0.1"), want);

    snprintf(want, sizeof want, "%s--set model.modes=9007199254740993, --set model.rhof=12 applied to x.toml\n"
             "[model]\nmodes = 9007199254740992.0\nrhof = 12\n", H);
    case_exact("integers as swim_scene_parse_with keeps them", "[model]\nmodes = 1\nrhof = 3\n",
               SETS("model.modes=9007199254740993", "model.rhof=12"), want);

    snprintf(want, sizeof want, "%s--set run.t_end=2, --set run.t_end=2, --set run.rtol=0.5, --set run.rtol=0.5 applied to x.toml\n"
             "[run]\nt_end = 2\nrtol = 0.5\n", H);
    case_exact("one value given twice", "[run]\nt_end = 1\n", SETS("run.t_end=2", "run.t_end=2", "run.rtol=0.5", "run.rtol=0.5"), want);

    snprintf(want, sizeof want, "%s--set run.t_end=2 applied to x.toml\n[run]\nt_end = 2\n[run.sub]\nk = 1\n[[ev]]\nt_end = 9\n", H);
    case_exact("sub-tables and arrays of tables are other tables",
               "[run]\nt_end = 1\n[run.sub]\nk = 1\n[[ev]]\nt_end = 9\n", SETS("run.t_end=2"), want);

    snprintf(want, sizeof want, "%s--set run.rtol=0.5 applied to x.toml\n[run]\nt_end = 1\nsub.k = 2\nrtol = 0.5\n[model]\n", H);
    case_exact("a key added after a dotted key of the table", "[run]\nt_end = 1\nsub.k = 2\n[model]\n",
               SETS("run.rtol=0.5"), want);

    snprintf(want, sizeof want, "%sno --set applied to x.toml\n[run]\nt_end = 1\n", H);
    case_exact("no overrides", "[run]\nt_end = 1\n", NULL, 0, want);

    /* control characters and bad UTF-8 in the path or an override cannot break the comment */
    {
        swim_override o = ovr("run.t_end=\n 3");
        char err[256];
        char *got = resolve("[run]\nt_end = 1\n", "a\nb\x01\xff\xc3\xa9.toml", &o, 1, err, sizeof err);
        CHECK(got && !strcmp(got, "# resolved by swim: --set run.t_end=? 3 applied to a?b??\xc3\xa9.toml\n[run]\nt_end = 3\n"),
              "control characters quoted: %s", got ? got : err);
        free(got);
    }

    case_refused("item of an absent key", "[run]\nt_end = 1\n", SETS("run.x[0]=1"), "no array run.x");
    case_refused("item of an absent table", "[run]\nt_end = 1\n", SETS("shape.c0[0]=1"), "no array shape.c0");
    case_refused("item out of range", "[shape]\nc0 = [1, 2]\n", SETS("shape.c0[2]=1"), "no item 2");
    case_refused("item of a number", "[shape]\nc0 = 1\n", SETS("shape.c0[0]=1"), "no item 0");
    case_refused("conflicting overrides", "[run]\nt_end = 1\n", SETS("run.t_end=1", "run.t_end=2"), "conflicts with --set run.t_end=1");
    case_refused("not TOML", "[run]\nt_end = = 1\n", SETS("run.t_end=1"), "line 2");
    case_refused("a key in an inline table", "shape = {c0 = [1, 2]}\n", SETS("shape.c0[0]=3"), "cannot place");
    case_refused("a key added to a table of dotted keys", "run.t_end = 1\n", SETS("run.rtol=3"), "no [run] header");
    case_refused("a table that is a value", "run = 1\n", SETS("run.t_end=3"), "not a table");
    case_refused("a word for an item", "[shape]\nc0 = [1]\n", SETS("shape.c0[0]=abc"), "takes a number");
}

/* ---- every scene of models/ --------------------------------------------------------------- */

/* Scene s with the fields that may differ between two readings of one scene -- line numbers,
 * the override list, owned pointers -- zeroed, for a byte comparison of all the rest. */
static void neutral(const swim_scene *s, swim_scene *out)
{
    memcpy(out, s, sizeof *s);
    out->path = out->title = out->forcing_text = NULL;
    out->forcing = NULL;
    out->override_text = NULL;
    out->nover = 0;
    memset(out->setting_line, 0, sizeof out->setting_line);
    out->line_c0 = out->line_dc0 = out->line_rho0 = out->line_rhof = 0;
    out->events_line = out->stroke_period_line = out->params_line = 0;
    memset(out->stroke_law, 0, sizeof out->stroke_law);
    memset(out->stroke_expr, 0, sizeof out->stroke_expr);
    memset(out->stroke_line, 0, sizeof out->stroke_line);
    out->energy_text = NULL;   /* an energy law is compared by its text (same_scene) */
    out->energy = NULL;
    out->energy_line = 0;
}

static int same_str(const char *a, const char *b) { return (!a && !b) || (a && b && !strcmp(a, b)); }

static int same_law(const swim_expr *a, const swim_expr *b)
{
    if (!a || !b) return a == b;
    static const double ts[] = {0.0, 0.37, 1.0, 2.5, 11.0};
    for (size_t i = 0; i < sizeof ts / sizeof ts[0]; i++) {
        const double x = swim_expr_eval(a, ts[i]), y = swim_expr_eval(b, ts[i]);
        if (memcmp(&x, &y, sizeof x) != 0) return 0;
    }
    return 1;
}

/* 1 when a and b are the same scene (line numbers aside); with `why`, the first difference. */
static int same_scene(const swim_scene *a, const swim_scene *b, char *why, size_t len)
{
    static swim_scene na, nb;
    neutral(a, &na);
    neutral(b, &nb);
    const unsigned char *p = (const unsigned char *)&na, *q = (const unsigned char *)&nb;
    for (size_t i = 0; i < sizeof na; i++)
        if (p[i] != q[i]) {
            snprintf(why, len, "byte %zu of swim_scene (of %zu) differs", i, sizeof na);
            return 0;
        }
    if (!same_str(a->title, b->title)) return snprintf(why, len, "title"), 0;
    if (!same_str(a->path, b->path)) return snprintf(why, len, "path"), 0;
    if (!same_str(a->forcing_text, b->forcing_text) || !same_law(a->forcing, b->forcing))
        return snprintf(why, len, "forcing law"), 0;
    if (!same_str(a->energy_text, b->energy_text) || !a->energy != !b->energy)
        return snprintf(why, len, "energy law"), 0;
    for (int k = 0; k < a->stroke_count; k++)
        if (!same_str(a->stroke_law[k], b->stroke_law[k]) || !same_law(a->stroke_expr[k], b->stroke_expr[k]))
            return snprintf(why, len, "stroke law %d", k), 0;
    return 1;
}

/* The comparison itself can fail: a scene differs from its copy with one value changed. */
static void test_comparison(const swim_scene *s)
{
    static swim_scene t;
    char why[128];
    memcpy(&t, s, sizeof t);
    CHECK(same_scene(s, &t, why, sizeof why), "a scene is the same as its copy: %s", why);
    t.c0[t.n - 1] = nextafter(t.c0[t.n - 1], INFINITY);
    CHECK(!same_scene(s, &t, why, sizeof why), "one ulp of c0 is a difference");
    memcpy(&t, s, sizeof t);
    t.run.jacobian_exact = !t.run.jacobian_exact;
    CHECK(!same_scene(s, &t, why, sizeof why), "jacobian is a difference");
    memcpy(&t, s, sizeof t);
    t.title = "another title";
    CHECK(!same_scene(s, &t, why, sizeof why), "the title is a difference");
    memcpy(&t, s, sizeof t);
    t.line_c0 += 5;
    t.setting_line[0] = -1;
    CHECK(same_scene(s, &t, why, sizeof why), "line numbers are not a difference: %s", why);
}

typedef struct {
    const char *path, *text;
    size_t len;
    toml_value *root;
    swim_override ov[16];
    int nov;
    int changed_line[16];   /* original line each replacing override changes (0: it inserts) */
    int inserted;           /* lines the result has beyond the file's (header aside) */
} scene_case;

/* parse_with on the case's text and overrides (quiet). 0 or 2. */
static int parse_ov(const scene_case *c, const swim_override *ov, int nov, swim_scene *s)
{
    quiet(1);
    int rc = swim_scene_parse_with(c->text, c->len, c->path, ov, nov, s, NULL);
    quiet(0);
    return rc;
}

/* The number at table.key (item index) of the file, NAN when absent. */
static double file_number(const scene_case *c, const char *table, const char *key, long index)
{
    const toml_value *v = toml_get(toml_get(c->root, table), key);
    if (index >= 0) v = toml_array_at(v, (size_t)index);
    return v && toml_is_number(v) ? toml_number(v) : NAN;
}

/* Adds the override `text` when the scene reader accepts the file with the overrides so far
 * and it; 1 when added. The line it changes is recorded for the byte check. */
static int try_add(scene_case *c, const char *text)
{
    swim_override o = ovr(text);
    static swim_scene s;
    c->ov[c->nov] = o;
    if (parse_ov(c, c->ov, c->nov + 1, &s) != 0) return 0;
    swim_scene_free(&s);
    const toml_value *t = toml_get(c->root, o.table), *v = toml_get(t, o.key);
    int line = 0;
    if (v) line = o.index >= 0 ? toml_line(toml_array_at(v, (size_t)o.index)) : toml_get_key_line(t, o.key);
    else c->inserted++;
    c->changed_line[c->nov++] = line;
    return 1;
}

/* An item override of the first vector (of candidates) the reader accepts a change of. */
static int add_item(scene_case *c, int by_name)
{
    static const char *const vec[][2] = {{"elastic", "stiffness"}, {"damping", "diagonal"}, {"forcing", "direction"},
                                         {"shape", "c0"}};
    const int n = (int)toml_array_size(toml_get(toml_get(c->root, "shape"), "c0"));
    for (size_t k = 0; k < sizeof vec / sizeof vec[0]; k++)
        for (int i = by_name ? n - 1 : 2; i >= 0 && i < n; i += by_name ? -1 : 1) {
            double old = file_number(c, vec[k][0], vec[k][1], i);
            if (isnan(old)) continue;
            /* a shape coordinate moves a little (the shape must stay in D); others by a lot */
            const double val = !strcmp(vec[k][0], "shape") ? old + 1.0 / 1024 + 1e-9 : 1.5 * old + 0.2500000001;
            char text[160], name[16];
            if (by_name) {
                swim_coord_name(i, name, sizeof name);
                snprintf(text, sizeof text, "%s.%s.%s=%.17g", vec[k][0], vec[k][1], name, val);
            } else {
                snprintf(text, sizeof text, "%s.%s[%d]=%.17g", vec[k][0], vec[k][1], i, val);
            }
            int dup = 0;   /* not the item the other kind already set */
            swim_override o = ovr(text);
            for (int j = 0; j < c->nov; j++) dup |= swim_override_same_target(&c->ov[j], &o);
            if (!dup && try_add(c, text)) return 1;
        }
    return 0;
}

/* Splits text into lines (each with its line end); returns the count. */
static int split_lines(const char *text, size_t len, const char **line, size_t *llen, int max)
{
    int k = 0;
    for (size_t i = 0; i < len && k < max;) {
        size_t j = i;
        while (j < len && text[j] != '\n') j++;
        if (j < len) j++;
        line[k] = text + i;
        llen[k++] = j - i;
        i = j;
    }
    return k;
}

/* Where the comment of a line starts (outside strings), or its length. */
static size_t comment_at(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (s[i] == '"' || s[i] == '\'') {
            const char q = s[i];
            for (i++; i < n && s[i] != q; i++)
                if (q == '"' && s[i] == '\\') i++;
        } else if (s[i] == '#') {
            return i;
        }
    }
    return n;
}

static int has_line(const int *lines, int n, int line)
{
    for (int i = 0; i < n; i++)
        if (lines[i] == line) return 1;
    return 0;
}

/* Every line of the file that no override changes is in the result, byte for byte and in order;
 * a changed line keeps its key and its comment; nothing else is added. */
static void check_lines(const scene_case *c, const char *res, size_t reslen, const char *tail)
{
    enum { MAXL = 4096 };
    static const char *ol[MAXL], *rl[MAXL];
    static size_t oll[MAXL], rll[MAXL];
    const int no = split_lines(c->text, c->len, ol, oll, MAXL);
    const int nr = split_lines(res, reslen, rl, rll, MAXL);
    CHECK(nr >= 1 && !strncmp(rl[0], "# resolved by swim: --set ", 26), "%s: the header first", c->path);
    int j = 1, extra = 0, changed = 0;
    for (int i = 0; i < no; i++) {
        if (has_line(c->changed_line, c->nov, i + 1)) {
            CHECK(j < nr && (rll[j] != oll[i] || memcmp(rl[j], ol[i], oll[i]) != 0), "%s:%d: changed", c->path, i + 1);
            if (j >= nr) return;
            const char *eq = memchr(ol[i], '=', oll[i]);
            const size_t keylen = eq ? (size_t)(eq - ol[i]) + 1 : 0;
            CHECK(eq && rll[j] > keylen && !memcmp(rl[j], ol[i], keylen), "%s:%d: the key kept", c->path, i + 1);
            const size_t oc = comment_at(ol[i], oll[i]), rc = comment_at(rl[j], rll[j]);
            CHECK(oll[i] - oc == rll[j] - rc && !memcmp(ol[i] + oc, rl[j] + rc, oll[i] - oc),
                  "%s:%d: the comment and line end kept", c->path, i + 1);
            changed++;
            j++;
            continue;
        }
        while (j < nr && !(rll[j] == oll[i] && !memcmp(rl[j], ol[i], oll[i])) && extra < c->inserted) {
            extra++;
            j++;
        }
        CHECK(j < nr && rll[j] == oll[i] && !memcmp(rl[j], ol[i], oll[i]), "%s:%d: line kept byte for byte: '%.*s'",
              c->path, i + 1, (int)oll[i], ol[i]);
        j++;
    }
    extra += nr - j;
    int tail_lines = 0;   /* blank, [table], its keys */
    for (const char *q = tail ? tail + 1 : ""; *q; q++) tail_lines += *q == '\n';
    CHECK(extra == c->inserted + tail_lines, "%s: %d lines added, %d expected", c->path, extra, c->inserted + tail_lines);
    if (tail) {
        const size_t tl = strlen(tail);
        CHECK(reslen >= tl && !memcmp(res + reslen - tl, tail, tl), "%s: ends with the new table", c->path);
    }
    int expect_changed = 0;
    for (int k = 0; k < c->nov; k++) expect_changed += c->changed_line[k] > 0 && !has_line(c->changed_line, k, c->changed_line[k]);
    CHECK(changed == expect_changed, "%s: %d lines changed, %d expected", c->path, changed, expect_changed);
}

static int scenes_done, tables_done;

static void test_scene(const char *path)
{
    scene_case c;
    memset(&c, 0, sizeof c);
    c.path = path;
    char *text = swim_scene_read(path, &c.len, NULL);
    CHECK(text != NULL, "%s: read", path);
    if (!text) return;
    c.text = text;
    char perr[256];
    c.root = toml_parse(text, c.len, perr, sizeof perr);
    CHECK(c.root != NULL, "%s: parses: %s", path, perr);
    static swim_scene orig, with, back;
    if (!c.root || parse_ov(&c, NULL, 0, &orig) != 0) {
        CHECK(0, "%s: the scene reads", path);
        toml_free(c.root);
        free(text);
        return;
    }
    test_comparison(&orig);

    char t[160];
    /* a scalar of an existing table (two), then items by index and by coordinate name */
    snprintf(t, sizeof t, "run.t_end=%.17g", 0.5 * file_number(&c, "run", "t_end", -1) + 0.1);
    CHECK(try_add(&c, t), "%s: %s accepted", path, t);
    snprintf(t, sizeof t, "run.atol=%.17g", 0.77 * file_number(&c, "run", "atol", -1));
    CHECK(try_add(&c, t), "%s: %s accepted", path, t);
    CHECK(add_item(&c, 0), "%s: an item override accepted", path);
    CHECK(add_item(&c, 1), "%s: a coordinate-name override accepted", path);
    /* an absent key (a number), words: a string (absent or not) and a boolean */
    CHECK(try_add(&c, "run.impact_depth=3e-17"), "%s: run.impact_depth accepted", path);
    CHECK(try_add(&c, "run.jacobian=differences"), "%s: run.jacobian accepted", path);
    CHECK(try_add(&c, "run.projection=false"), "%s: run.projection accepted", path);
    if (toml_get(toml_get(c.root, "run"), "stiff_fallback")) CHECK(try_add(&c, "run.stiff_fallback=none"), "%s: stiff_fallback", path);
    CHECK(c.inserted >= 1, "%s: an absent key among the overrides", path);

    /* the new table: swim_scene_parse_with refuses an absent table, so the reference is the file
     * with the table written at its end by hand, read with the other overrides */
    const char *tail = NULL, *tsets[2] = {NULL, NULL};
    if (!toml_get(c.root, "parameters")) {
        tsets[0] = "parameters.zeta=0.25";
        tail = "\n\n[parameters]\nzeta = 0.25\n";
    } else if (!toml_get(c.root, "barrier") && !toml_get(c.root, "stroke")) {   /* no barrier on a stroke */
        tsets[0] = "barrier.epsilon=0.03";
        tsets[1] = "barrier.alpha=1";
        tail = "\n\n[barrier]\nepsilon = 0.03\nalpha = 1.0\n";
    }
    char *ref_text = malloc(c.len + 64);
    memcpy(ref_text, text, c.len);
    size_t ref_len = c.len;
    if (tail) {
        const char *add = tail + (c.len && text[c.len - 1] == '\n');   /* the file's last line end */
        memcpy(ref_text + ref_len, add, strlen(add));
        ref_len += strlen(add);
    }
    scene_case ref = c;
    ref.text = ref_text;
    ref.len = ref_len;
    int ok = parse_ov(&ref, c.ov, c.nov, &with) == 0;
    CHECK(ok, "%s: the file with its overrides reads", path);
    swim_override all[18];
    memcpy(all, c.ov, sizeof(swim_override) * (size_t)c.nov);
    int nall = c.nov;
    for (int k = 0; k < 2 && tsets[k]; k++) all[nall++] = ovr(tsets[k]);
    tables_done += tail != NULL;
    char err[512];
    char *res = NULL;
    size_t reslen = 0;
    int rrc = swim_scene_resolve(text, c.len, path, all, nall, &res, &reslen, err, sizeof err);
    CHECK(rrc == 0, "%s: resolved: %s", path, err);
    if (ok && rrc == 0) {
        quiet(1);
        int back_ok = swim_scene_parse(res, reslen, path, &back, NULL) == 0;
        quiet(0);
        CHECK(back_ok, "%s: the resolved text reads:\n%s", path, res);
        if (back_ok) {
            char why[128];
            CHECK(same_scene(&with, &back, why, sizeof why), "%s: the resolved scene is the scene as run: %s", path, why);
            CHECK(!same_scene(&orig, &with, why, sizeof why), "%s: the overrides change the scene", path);
            CHECK(back.nover == 0, "%s: read with no overrides", path);
            swim_scene_free(&back);
        }
        check_lines(&c, res, reslen, tail);
        /* the header names every override and the file */
        char head[2048] = "# resolved by swim: ";
        for (int i = 0; i < nall; i++)
            snprintf(head + strlen(head), sizeof head - strlen(head), "%s--set %s", i ? ", " : "", all[i].text);
        snprintf(head + strlen(head), sizeof head - strlen(head), " applied to %s\n", path);
        CHECK(!strncmp(res, head, strlen(head)), "%s: header '%.*s'", path, (int)strlen(head) - 1, head);
        /* resolving the resolved text again with no overrides changes only the header */
        char *again = NULL;
        size_t alen = 0;
        CHECK(swim_scene_resolve(res, reslen, "r.toml", NULL, 0, &again, &alen, err, sizeof err) == 0, "%s: again", path);
        const char *body = strchr(res, '\n') + 1, *abody = again ? strchr(again, '\n') + 1 : NULL;
        CHECK(again && !strcmp(strchr(abody, '\n') + 1, body), "%s: no overrides: the text kept", path);
        free(again);
        scenes_done++;
    }
    if (ok) swim_scene_free(&with);
    free(res);
    free(ref_text);
    swim_scene_free(&orig);
    toml_free(c.root);
    free(text);
}

static void test_models(void)
{
    glob_t g;
    int n = 0;
    if (glob("models/*.toml", 0, NULL, &g) == 0) {
        for (size_t i = 0; i < g.gl_pathc; i++, n++) test_scene(g.gl_pathv[i]);
        globfree(&g);
    }
    if (glob("models/*/*.toml", 0, NULL, &g) == 0) {
        for (size_t i = 0; i < g.gl_pathc; i++, n++) test_scene(g.gl_pathv[i]);
        globfree(&g);
    }
    CHECK(n >= 25, "scenes of models/ found (%d; the test runs from the top folder)", n);
    CHECK(scenes_done == n, "%d of %d scenes resolved and compared", scenes_done, n);
    CHECK(tables_done >= n - 2, "%d scenes got a new table", tables_done);
    printf("%d scenes of models/ resolved and compared (%d with a new table)\n", scenes_done, tables_done);
}

int main(void)
{
    test_exact();
    test_models();
    return check_report("test_scene_resolve");
}
