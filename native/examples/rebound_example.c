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
        fprintf(stderr, "error %d (%s): %s\n", code, rbs_error_string(code), message);
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

    const double V[3] = {120.0, -80.0, 10.0};   /* m/s, moving into the wall */
    const double n[3] = {0.0, 1.0, 0.0};        /* unit wall normal into the gas */
    const double a = 5e-5;                      /* m, half-size */
    const double speed = sqrt(V[0] * V[0] + V[1] * V[1] + V[2] * V[2]);
    /* rad/s: no spin, then |Omega-| a/|V-| = 0.3 about the wall normal (the table's law no longer holds) */
    const double Omegas[2][3] = {{0.0, 0.0, 0.0}, {0.0, 0.3 * speed / a, 0.0}};
    int rebounded = 0;
    for (int i = 0; i < count; i++) {
        const double *Omega = Omegas[i % 2];
        double V_out[3], Omega_out[3];
        /* RBS_AUTO: the table where its law is valid, the direct model for the other hits */
        int path = rbs_rebound_path(table, V, Omega, n, a, RBS_AUTO);
        int status = rbs_rebound_rng(table, mix, V, Omega, n, a, &rng, RBS_AUTO, RBS_SCALED, V_out, Omega_out);
        printf("%d Omega- = (%g, %g, %g) rad/s, %s: status %2d  V+ = (%9.3f, %9.3f, %9.3f) m/s  "
               "Omega+ = (%11.1f, %11.1f, %11.1f) rad/s\n", i, Omega[0], Omega[1], Omega[2],
               path == RBS_PATH_TABLE ? "table" : "direct model", status, V_out[0], V_out[1], V_out[2],
               Omega_out[0], Omega_out[1], Omega_out[2]);
        rebounded += status == RBS_REBOUNDED;
    }
    printf("%d of %d rebounded\n", rebounded, count);
    rbs_mix_free(mix);
    rbs_table_close(table);
    return 0;
}
