/* libFuzzer entry point for the TOML reader (runtime/scene/toml.c).
 * Build and run with tests/fuzz/run_fuzz.sh. Besides memory errors (ASan/UBSan), it aborts
 * when an invariant of the API is broken: error messages are one line "line L: ...",
 * every table key is found again by toml_get, node lines are within the input, etc. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/toml.h"

#define REQUIRE(c)                                                                                     \
    do {                                                                                               \
        if (!(c)) {                                                                                    \
            fprintf(stderr, "invariant failed: %s (%s:%d)\n", #c, __FILE__, __LINE__);                 \
            abort();                                                                                   \
        }                                                                                              \
    } while (0)

static int max_line;

static void walk(const toml_value *v, int depth)
{
    REQUIRE(v != NULL);
    REQUIRE(depth <= TOML_MAX_DEPTH);
    REQUIRE(toml_line(v) >= 1 && toml_line(v) <= max_line);
    toml_kind k = toml_kind_of(v);
    REQUIRE(toml_kind_name(k) != NULL);
    switch (k) {
    case TOML_TABLE: {
        size_t n = toml_table_size(v);
        for (size_t i = 0; i < n; i++) {
            const char *key = toml_table_key(v, i);
            REQUIRE(key != NULL);
            REQUIRE(toml_get(v, key) == toml_table_value(v, i));
            REQUIRE(toml_table_key_line(v, i) >= 1 && toml_table_key_line(v, i) <= max_line);
            walk(toml_table_value(v, i), depth + 1);
        }
        REQUIRE(toml_table_key(v, n) == NULL && toml_table_value(v, n) == NULL);
        REQUIRE(toml_array_size(v) == 0);
        break;
    }
    case TOML_ARRAY: {
        size_t n = toml_array_size(v);
        for (size_t i = 0; i < n; i++)
            walk(toml_array_at(v, i), depth + 1);
        REQUIRE(toml_array_at(v, n) == NULL);
        REQUIRE(toml_table_size(v) == 0);
        break;
    }
    case TOML_STRING: {
        const char *s = toml_string(v);
        REQUIRE(s != NULL && strlen(s) == toml_string_len(v));
        break;
    }
    case TOML_INT: (void)toml_int(v); REQUIRE(toml_is_number(v)); break;
    case TOML_FLOAT: (void)toml_number(v); REQUIRE(toml_is_number(v)); break;
    case TOML_BOOL: REQUIRE(toml_bool(v) == 0 || toml_bool(v) == 1); break;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* copy into an exact-size heap buffer so ASan catches any read past `size` */
    char *buf = malloc(size ? size : 1);
    if (!buf)
        return 0;
    if (size)
        memcpy(buf, data, size);
    max_line = 1;
    for (size_t i = 0; i < size; i++)
        if (buf[i] == '\n')
            max_line++;

    char err[200];
    toml_value *root = toml_parse(buf, size, err, sizeof err);
    if (root) {
        REQUIRE(toml_kind_of(root) == TOML_TABLE);
        walk(root, 0);
        toml_free(root);
    } else {
        int line = 0;
        REQUIRE(strncmp(err, "line ", 5) == 0);
        REQUIRE(sscanf(err, "line %d: ", &line) == 1);
        REQUIRE(line >= 1 && line <= max_line);
        REQUIRE(strchr(err, '\n') == NULL && strchr(err, '\r') == NULL);
        REQUIRE(strlen(err) > 9);
    }
    /* a tiny error buffer must be safe too */
    char small[4];
    root = toml_parse(buf, size, small, sizeof small);
    toml_free(root);
    free(buf);
    return 0;
}
