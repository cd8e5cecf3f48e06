/* The structure text of a scene's kernels (structure.h), moved out of codegen.c unchanged. */
#include "codegen/structure.h"

#include <stdio.h>
#include <stdlib.h>

#include "io/json.h"

/* Indices i of the shape vector for which pick(s, i) holds, as a JSON array. */
static void index_list(FILE *f, const swim_scene *s, int generic, int which)
{
    int first = 1;
    fputc('[', f);
    for (int i = 0; i < s->n; i++) {
        int take = 0;
        const int fr = generic || s->free_mask[i];
        switch (which) {
        case 0: take = fr; break;                                              /* carried */
        case 1: take = !fr && s->c0[i] == 0.0; break;                         /* locked at 0 */
        case 2: take = generic || (fr && s->elastic && s->stiffness[i] != 0); break;
        case 3: take = generic || (fr && s->damped && s->damping[i] != 0); break;
        case 4: take = s->forced && (generic || (fr && s->direction[i] != 0)); break;
        }
        if (take) {
            fprintf(f, "%s%d", first ? "" : ", ", i);
            first = 0;
        }
    }
    fputc(']', f);
}

/* The structure as JSON for the generator; with key == NULL, the key itself (no "key" field). */
char *swim_codegen_structure_text(const swim_scene *s, int generic, const char *key)
{
    char *text = NULL;
    size_t len;
    FILE *f = open_memstream(&text, &len);
    if (!f) return NULL;
    fprintf(f, "{\"format\": 2, ");
    if (key) {
        fprintf(f, "\"key\": ");
        swim_json_string(f, key);
        fprintf(f, ", ");
    }
    static const char *const names[] = {"free", "zero", "elastic", "damping"};
    fprintf(f, "\"modes\": %d, \"multipliers\": %s", s->modes, generic ? "true" : "false");
    for (int w = 0; w < 4; w++) {
        fprintf(f, ", \"%s\": ", names[w]);
        index_list(f, s, generic, w);
    }
    fprintf(f, ", \"barrier\": %s, \"forcing\": ", generic || s->barrier ? "true" : "false");
    if (s->forced) {
        fprintf(f, "{\"law\": ");
        swim_json_string(f, s->forcing_text);
        fprintf(f, ", \"direction\": ");
        index_list(f, s, generic, 4);
        if (s->nparams > 0) {   /* the names only: values are run-time (law_params) */
            fprintf(f, ", \"parameters\": [");
            for (int i = 0; i < s->nparams; i++) {
                if (i) fprintf(f, ", ");
                swim_json_string(f, s->param_names[i]);
            }
            fprintf(f, "]");
        }
        fprintf(f, "}");
    } else {
        fprintf(f, "null");
    }
    if (s->energy_text) {   /* [elastic] energy: the law, and the names it may read (values run-time) */
        fprintf(f, ", \"energy\": {\"law\": ");
        swim_json_string(f, s->energy_text);
        fprintf(f, ", \"parameters\": [");
        for (int i = 0; i < s->nparams; i++) {
            if (i) fprintf(f, ", ");
            swim_json_string(f, s->param_names[i]);
        }
        fprintf(f, "]}");
    }
    fprintf(f, "}\n");
    fclose(f);
    return text;
}


/* The stroke structure as JSON (generator/swimgen/stroke.py); with key == NULL the key itself. */
char *swim_codegen_stroke_text(const swim_scene *s, const char *key)
{
    char *text = NULL;
    size_t len;
    FILE *f = open_memstream(&text, &len);
    if (!f) return NULL;
    fprintf(f, "{\"format\": 1, ");
    if (key) {
        fprintf(f, "\"key\": ");
        swim_json_string(f, key);
        fprintf(f, ", ");
    }
    fprintf(f, "\"modes\": %d, \"laws\": [", s->modes);
    for (int k = 0; k < s->stroke_count; k++) {
        fprintf(f, "%s[%d, ", k ? ", " : "", s->stroke_index[k]);
        swim_json_string(f, s->stroke_law[k]);
        fputc(']', f);
    }
    fprintf(f, "], \"parameters\": [");   /* the names only: values are run-time (par[i]) */
    for (int i = 0; i < s->nparams; i++) {
        if (i) fprintf(f, ", ");
        swim_json_string(f, s->param_names[i]);
    }
    fprintf(f, "]}\n");
    fclose(f);
    return text;
}

