/* toml.h -- a small, defensive TOML reader for swim scene files.
 *
 * Supported subset (a strict subset of TOML 1.0; anything else is an error):
 *   - comments:  '#' to end of line (control characters other than tab are rejected)
 *   - line ends: "\n" or "\r\n" (a lone "\r" is an error)
 *   - keys:      bare (A-Z a-z 0-9 _ -), basic-quoted "..." (with escapes), literal-quoted '...',
 *                dotted  a.b."c d" = 1  (creates/extends sub-tables, as in TOML)
 *   - tables:    [a]  [a.b]  and arrays of tables  [[a]]  [[a.b]]  (a header may descend into
 *                the last element of an array of tables, e.g. [[f]] then [f.sub])
 *   - values:    basic strings "..." with escapes \" \\ \b \t \n \f \r \uXXXX \UXXXXXXXX
 *                  (encoded as UTF-8; surrogates and \u0000 are rejected)
 *                literal strings '...' (no escapes)
 *                integers: decimal with optional sign and '_' between digits (no leading
 *                  zeros), 0x.. 0o.. 0b.. (unsigned); out-of-range values are an error
 *                floats: 1.0  -2.5e-3  1e6  1_000.5  inf +inf -inf nan +nan -nan
 *                  (a float that overflows a double is an error)
 *                booleans: true false
 *                arrays: [1, 2, 3], nested, spread over lines, trailing comma, comments inside;
 *                  element types may be mixed
 *                inline tables: {a = 1, b.c = "x"}  (single line, no trailing comma, frozen
 *                  after the closing brace, as in TOML)
 *   - NOT supported (rejected with a clear error): dates and times, multi-line strings
 *     ("""...""" and '''...''').
 *   - Duplicate keys, redefined tables, [a] after a.x = .. defined a, extending an inline
 *     table, etc. are errors, following the TOML 1.0 rules.
 *
 * Robustness: the input need not be NUL-terminated (only `len` bytes are read); NUL bytes
 * and invalid UTF-8 are errors; nesting (tables, arrays, inline tables together) is limited
 * to TOML_MAX_DEPTH levels below the root; there is no unbounded recursion; all memory is
 * released on every error path.
 *
 * Floats are converted with strtod, so LC_NUMERIC must be "C" (the default unless the program
 * calls setlocale).
 *
 * Every node remembers the 1-based line where it appears (a table created by a header: the
 * header's line; a table created implicitly by [a.b] or a.b = ..: the line that first named
 * it), and every table key remembers the line of the key itself.
 *
 * Errors: toml_parse returns NULL and writes a single line "line L: message" into err,
 * e.g. "line 7: expected '=' after key 'rho0', found '1'", "line 3: duplicate key 'N' (first
 * defined on line 2)", "line 9: unterminated string".
 *
 * Accessors are total: called on a NULL or a node of the wrong kind, or with an index out of
 * range, they return NULL / 0 / NaN (documented per function) instead of crashing.
 */
#ifndef SWIM_SCENE_TOML_H
#define SWIM_SCENE_TOML_H

#include <stddef.h>

#define TOML_MAX_DEPTH 64

typedef enum { TOML_TABLE, TOML_ARRAY, TOML_STRING, TOML_INT, TOML_FLOAT, TOML_BOOL } toml_kind;
typedef struct toml_value toml_value; /* a node of the parsed tree; owned by the root */

/* Parse `len` bytes of `text`. Returns the root table, or NULL on error with a one-line
 * message "line L: ..." in err (err may be NULL; the message is truncated to errlen-1). */
toml_value *toml_parse(const char *text, size_t len, char *err, size_t errlen);
/* Free a tree returned by toml_parse (NULL is fine). Only call it on a root. */
void toml_free(toml_value *root);

toml_kind toml_kind_of(const toml_value *v);   /* v must not be NULL */
const char *toml_kind_name(toml_kind k);        /* "table" "array" "string" "integer" "float" "boolean" */
int toml_line(const toml_value *v);             /* 1-based line (or toml_set_origin's); 0 for NULL */

/* tables (wrong kind / out of range: 0 or NULL) */
size_t toml_table_size(const toml_value *t);
const char *toml_table_key(const toml_value *t, size_t i);       /* in file order */
const toml_value *toml_table_value(const toml_value *t, size_t i);
int toml_table_key_line(const toml_value *t, size_t i);          /* line of the key itself */
const toml_value *toml_get(const toml_value *t, const char *key); /* NULL if absent */
int toml_get_key_line(const toml_value *t, const char *key);      /* 0 if absent */

/* arrays (wrong kind / out of range: 0 or NULL) */
size_t toml_array_size(const toml_value *a);
const toml_value *toml_array_at(const toml_value *a, size_t i);

/* scalars */
const char *toml_string(const toml_value *v); /* NUL-terminated UTF-8; NULL if not a string */
size_t toml_string_len(const toml_value *v);  /* bytes, without the NUL; 0 if not a string */
long long toml_int(const toml_value *v);      /* 0 if not an integer */
double toml_number(const toml_value *v);      /* integer or float as double; NaN otherwise */
int toml_bool(const toml_value *v);           /* 1/0; 0 if not a boolean */
int toml_is_number(const toml_value *v);      /* 1 if integer or float */

/* Overrides (`--set table.key=value`): put the number `value` at root[table][key] (index < 0)
 * or at item `index` (0-based) of the array root[table][key]. An integer stays an integer when
 * `value` is integral, otherwise the node becomes a float; an absent key of an existing table
 * is added (the scene reader then judges whether it is allowed). The replaced node must be a
 * number. Returns 0, or -1 with a one-line reason in err (no table, not a number, index out of
 * range, out of memory); the tree is unchanged on error. */
int toml_set_number(toml_value *root, const char *table, const char *key, long index, double value,
                    char *err, size_t errlen);
/* The same for a string value at root[table][key] (no index): the replaced node must be a
 * string; an absent key of an existing table is added. */
int toml_set_string(toml_value *root, const char *table, const char *key, const char *text,
                    char *err, size_t errlen);
/* The same for a boolean (`--set run.projection=false`): the replaced node must be a boolean. */
int toml_set_bool(toml_value *root, const char *table, const char *key, int value, char *err, size_t errlen);
/* Where an override's value came from: sets the line of root[table][key] (the key and its
 * value, or with index >= 0 the key and item `index`) to `line`, which the caller chooses to
 * tell overrides from lines of the file (swim's scene reader uses -1, -2, ... for its
 * overrides). 0, or -1 when there is no such node. */
int toml_set_origin(toml_value *root, const char *table, const char *key, long index, int line);

#endif
