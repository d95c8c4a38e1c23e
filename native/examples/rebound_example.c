/*
 * rebound_example.c: open a table, draw the rebounds of a few particles hitting a wall, spinning or not, print them
 * and the path that answered each (the table or the direct model).
 *
 *   rbs_example_rebound TABLE.h5 [N]
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "rebound_scatter.h"

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s TABLE.h5 [N]\n", argv[0]);
        return 2;
    }
    int count = argc > 2 ? atoi(argv[2]) : 5;
    char message[1024];
    rbs_table *table = NULL;
    int code = rbs_table_open(argv[1], &table, message, sizeof message);
    if (code != RBS_OK) {
        fprintf(stderr, "error %d (%s): %s\n", code, rbs_status_string(code), message);
        return 1;
    }
    rbs_mix *mix = rbs_mix_new_equal(table);    /* the table's shapes, however many, with equal weights */
    if (!mix) {
        fprintf(stderr, "out of memory\n");
        rbs_table_close(table);
        return 1;
    }
    printf("%d shapes, the first %s\n", rbs_table_n_shapes(table), rbs_table_shape_name(table, 0));
    rbs_rng rng;
    rbs_rng_seed(&rng, 1);                      /* == surrogate.seed_state(1) */

    rbs_hit hit = RBS_HIT_INIT;                 /* sets hit.size; no grain key, uniforms from hit.rng */
    const double V[3] = {120.0, -80.0, 10.0};   /* m/s, moving into the wall */
    const double speed = sqrt(V[0] * V[0] + V[1] * V[1] + V[2] * V[2]);
    for (int k = 0; k < 3; k++) hit.V[k] = V[k];
    hit.n[1] = 1.0;                             /* unit wall normal into the gas */
    hit.a = 5e-5;                               /* m, half-size */
    hit.rng = &rng;
    int rebounded = 0;
    for (int i = 0; i < count; i++) {
        /* rad/s: no spin, then |Omega-| a/|V-| = 0.3 about the wall normal (the table's law no longer holds) */
        hit.Omega[1] = i % 2 ? 0.3 * speed / hit.a : 0.0;
        rbs_result result = RBS_RESULT_INIT;
        /* NULL options, RBS_METHOD_AUTO: the table where its law is valid, the direct model for the other hits */
        int status = rbs_rebound(table, mix, &hit, NULL, &result);
        printf("%d Omega- = (%g, %g, %g) rad/s, %s, shape %s: status %2d  V+ = (%9.3f, %9.3f, %9.3f) m/s  "
               "Omega+ = (%11.1f, %11.1f, %11.1f) rad/s\n", i, hit.Omega[0], hit.Omega[1], hit.Omega[2],
               result.path == RBS_PATH_TABLE ? "table" : "direct model",
               result.shape >= 0 ? rbs_table_shape_name(table, result.shape) : "-", status, result.V[0], result.V[1],
               result.V[2], result.Omega[0], result.Omega[1], result.Omega[2]);
        rebounded += status == RBS_OK;
    }
    printf("%d of %d rebounded\n", rebounded, count);
    rbs_mix_free(mix);
    rbs_table_close(table);
    return 0;
}
