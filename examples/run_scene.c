/* run_scene SCENE T_END: a scene run to T_END through libswim; prints the number of rows and, on
 * its last line, the final "t x y theta" (%.17g: the digits of swim run's summary.json).
 *
 *   cc run_scene.c $(pkg-config --cflags --libs swim) -o run_scene
 */
#include <stdio.h>
#include <stdlib.h>

#include <swim.h>

static int count_row(void *ctx, double t, const double *values, int ncol)
{
    (void)t; (void)values; (void)ncol;
    ++*(long *)ctx;
    return 0;   /* go on */
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: run_scene SCENE T_END\n");
        return 2;
    }
    char set[64];
    snprintf(set, sizeof set, "run.t_end=%s", argv[2]);
    const char *sets[] = {set};
    swim_model *model;
    swim_sim *sim;
    swim_error err = SWIM_ERROR_INIT;   /* size set: the library fills what this struct holds */
    if (swim_model_from_file(argv[1], sets, 1, &model, &err) != SWIM_OK) {
        fprintf(stderr, "run_scene: %s (file %s, line %d, key %s; %s)\n", err.message, err.file, err.line, err.key,
                swim_strerror(err.status));
        return 2;
    }
    long rows = 0;
    swim_sim_options opts = SWIM_SIM_OPTIONS_INIT;
    opts.rows = count_row;
    opts.rows_ctx = &rows;
    if (swim_sim_create(model, &opts, &sim, &err) != SWIM_OK) {
        fprintf(stderr, "run_scene: %s\n", err.message);
        swim_model_free(model);
        return 2;
    }
    const int rc = swim_sim_run(sim, &err);
    if (rc != SWIM_OK) fprintf(stderr, "run_scene: the run failed: %s\n", err.message);
    swim_result r = SWIM_RESULT_INIT;
    swim_sim_result(sim, &r);
    printf("swim %s: %ld rows\n", swim_version(), rows);
    printf("%.17g %.17g %.17g %.17g\n", r.t_reached, r.x, r.y, r.theta);
    swim_sim_free(sim);
    swim_model_free(model);
    return rc == SWIM_OK ? 0 : 1;
}
