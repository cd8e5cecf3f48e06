/* resolve.h -- the scene as run: a scene file's text with the overrides of the command line
 * (`--set KEY=VALUE`, swim_override) written into it, so that an output folder's scene.toml
 * reproduces the run without its command line.
 *
 * The text is edited, never re-printed: every byte of the file that no override touches is kept
 * (comments, spacing, the order of keys, "\r\n" line ends, a byte order mark), and
 *   - the value of an existing key is replaced where it stands on its line (`key = value  # c`
 *     keeps `  # c`); an item override (`table.key[I]`, `table.key.NAME`) replaces item I alone,
 *     in an array on one line or spread over several;
 *   - a key absent from an existing [table] is added on a new line after the last key of that
 *     table (before the comments and blank lines that precede the next table);
 *   - a table absent from the file is appended at the end as a new [table] with its keys;
 *   - a number is written as the shortest %.15g/%.16g/%.17g that reads back as the same double,
 *     as a TOML integer where swim_scene_parse_with would keep an integer (an integral value
 *     over an integer) and as a float otherwise ("2.0"); a word (run.jacobian=differences) as a
 *     TOML string, true/false as a boolean, as swim_scene_parse_with sets them;
 *   - a first line "# resolved by swim: --set A=1, --set B=2 applied to PATH" says so (control
 *     characters and invalid UTF-8 of PATH and of the overrides shown as '?').
 * So swim_scene_parse(result) gives the scene swim_scene_parse_with(text, ov) gives, line
 * numbers aside (tests/test_scene_resolve.c checks it on every scene of models/).
 *
 * The overrides are expected to have been validated by swim_scene_parse_with first; those it
 * would refuse need not be (and mostly are not) handled: an item of an absent key, overrides that
 * conflict (swim_override_conflict), text that is not TOML. Layouts the text editor cannot place
 * an override in (a key inside an inline table, a table made only by dotted keys or sub-tables
 * that would need a new key) are refused too, with the reason.
 */
#ifndef SWIM_SCENE_RESOLVE_H
#define SWIM_SCENE_RESOLVE_H

#include <stddef.h>

#include "scene/scene.h"

/* The TOML text (len bytes, not necessarily NUL-terminated) of the scene file `path` with the
 * overrides ov[0..nov) applied (see above). 0 with *out a new NUL-terminated buffer of *outlen
 * bytes (the caller frees it); -1 with *out NULL and a one-line reason in err (errlen bytes; err
 * may be NULL). Prints nothing, keeps no state. */
int swim_scene_resolve(const char *text, size_t len, const char *path, const swim_override *ov, int nov,
                       char **out, size_t *outlen, char *err, size_t errlen);

#endif
