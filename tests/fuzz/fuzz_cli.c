/* libFuzzer target: command-line arguments of `swim inspect` (option forms, number lists,
 * shapes in and out of D). The input is split at newlines into at most 12 arguments; output is silenced by
 * -close_fd_mask (tests/fuzz/run_fuzz.sh). */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cli/args.h"
#include "cli/commands.h"

/* Mode counts not linked in would be generated and compiled at run time (seconds each): point
 * the generator lookup nowhere, so that they fail fast with their one line (exit status 1). */
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    setenv("SWIM_SHARE", "/nonexistent-swim-share", 1);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4096) return 0;
    char *buf = malloc(size + 1), *argv[16];
    if (!buf) return 0;
    memcpy(buf, data, size);
    buf[size] = '\0';
    int argc = 0;
    argv[argc++] = "swim";
    argv[argc++] = "inspect";
    for (char *p = buf; argc < 14;) {
        argv[argc++] = p;
        char *nl = memchr(p, '\n', (size_t)(buf + size - p));
        if (!nl) break;
        *nl = '\0';
        p = nl + 1;
    }
    argv[argc] = NULL;
    int rc = swim_cmd_inspect(argc, argv);
    free(buf);
    /* 0, 1 (a run-time failure), 2 (bad input) or SWIM_ARGS_HELP (the options were printed for
     * -h/--help, which main turns into 0): anything else is a status no caller expects */
    if (rc != 0 && rc != 1 && rc != 2 && rc != SWIM_ARGS_HELP) abort();
    return 0;
}
