/* swim export SCENE --out DIR [--set KEY=VALUE ...] [--quiet]: one scene's self-contained source
 * tree, `make -C DIR` builds DIR/simulate (export/export.h, docs/export.md). The command is its
 * command line and its report. */
#include <stdio.h>
#include <stdlib.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "export/export.h"
#include "io/clock.h"
#include "io/message.h"
#include "output/job.h"
#include "cli/report.h"

int swim_cmd_export(int argc, char **argv)
{
    swim_override sets[SWIM_JOB_MAX_SETS];
    const int nsets = swim_args_take_sets("export", &argc, argv, 2, sets, SWIM_JOB_MAX_SETS);
    if (nsets < 0) return 2;
    swim_opt opts[] = {
        {"out", 1, NULL, "DIR", "the tree's folder (required): made, or an earlier export's (its files replaced); any "
                                "other folder that is not empty is refused"},
        {"set", 2, NULL, "KEY=VALUE", "a scene value overridden before the scene is validated, written into DIR/scene.toml "
                                      "(as for swim run)"},
        {"quiet", 0, NULL, NULL, "no report on stdout, no progress of a kernel generation on stderr"}};
    const int nopts = (int)(sizeof opts / sizeof opts[0]);
    const char *pos[1];
    int npos = 0;
    const int prc = swim_args_parse("export", argc, argv, 2, opts, nopts, pos, 1, &npos);
    if (prc) return prc;
    const char *out = swim_args_get(opts, nopts, "out");
    if (npos != 1 || !out || !*out) {
        swim_message(stderr, "swim export: expected one scene file and --out DIR, e.g. swim export models/example3.toml "
                     "--out out/example3-src");
        return 2;
    }
    const int quiet = swim_args_get(opts, nopts, "quiet") != NULL;
    const double t0 = swim_clock_seconds();
    const swim_export_request req = {"export", pos[0], out, sets, nsets, quiet ? 0 : 1};
    swim_export_result res;
    swim_status st = SWIM_STATUS_STDERR;
    const int rc = swim_export(&req, &res, &st);
    swim_status_print(&st, stderr);
    if (rc) return rc;
    if (!quiet) {
        swim_message(stdout, "%s: exported into %s: %d files, %.0f kB, in %.2f s (kernel of N = %d from %s, %s%s)", pos[0],
                     out, res.files, res.bytes / 1024.0, swim_clock_seconds() - t0, res.modes, res.kernel_source,
                     res.stroke ? "stroke laws" : "scene kernel", res.cvode ? "; links SUNDIALS" : "");
        swim_message(stdout, "  build: make -C %s; run: %s/simulate --out OUT [--t-end T] [--output-step H] [--rtol R] [--atol A] [--event COL:KIND] [--set KEY=VALUE]",
                     out, out);
    }
    return 0;
}
