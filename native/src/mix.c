/*
 * mix.c: shape mixes (surrogate.validation.mix_cdf, rbs_mix_new_*): cumulative weights in the table's shape order,
 * in a block sized by the table that remembers the table.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "shapes.h"

static int table_shape(const rbs_table *t, const char *name)
{
    for (int i = 0; i < t->n_shapes; i++)
        if (strcmp(name, t->shape_names[i]) == 0) return i;
    return -1;
}

/* The cumulative weights of named weights into cdf[0 .. t->n_shapes) (surrogate.validation.mix_cdf: the checks in
 * its order, the running sum in the table's order). RBS_OK or RBS_INVALID with a message. */
static int weights_cdf(const rbs_table *t, int n, const char *const names[], const double weights[], double *cdf,
                       char *message, size_t message_size)
{
    for (int i = 0; i < t->n_shapes; i++) cdf[i] = 0.0;
    for (int i = 0; i < n; i++) {
        const char *name = names[i];
        int s = name ? table_shape(t, name) : -1;
        if (!name || (s < 0 && rbs_shape_code(name) < 0)) {
            rbs_message(message, message_size, "The 'shape' parameter must name one of the table's shapes or a "
                        "built-in (ellipsoid, prism, cut_prism, tetrahedron); got '%s'.", name ? name : "(null)");
            return RBS_INVALID;
        }
        for (int j = 0; j < i; j++) {
            if (strcmp(names[j], name) == 0) {
                rbs_message(message, message_size, "The mix names shape '%s' twice.", name);
                return RBS_INVALID;
            }
        }
        double w = weights[i];
        if (!(isfinite(w) && w >= 0.0)) {
            rbs_message(message, message_size, "The mix weight of '%s' must be finite and >= 0; got %.17g.", name, w);
            return RBS_INVALID;
        }
        if (w > 0.0 && s < 0) {
            rbs_message(message, message_size, "shape '%s' is not in the table %s.", name, t->path);
            return RBS_INVALID;
        }
        if (s >= 0) cdf[s] = w;
    }
    double total = 0.0;
    for (int i = 0; i < n; i++) total += weights[i];
    if (fabs(total - 1.0) > 1e-9) {
        rbs_message(message, message_size, "The mix weights must sum to 1; got %.17g.", total);
        return RBS_INVALID;
    }
    double sum = 0.0;
    for (int i = 0; i < t->n_shapes; i++) {
        sum += cdf[i];
        cdf[i] = sum;
    }
    cdf[t->n_shapes - 1] = 1.0;
    return RBS_OK;
}

/* the equal mix's cumulative weights into cdf[0 .. t->n_shapes) */
static void equal_cdf(const rbs_table *t, double *cdf)
{
    double w = 1.0 / (double)t->n_shapes, sum = 0.0;
    for (int i = 0; i < t->n_shapes; i++) {
        sum += w;
        cdf[i] = sum;
    }
    cdf[t->n_shapes - 1] = 1.0;
}

/* a mix of the table, its cdf to be filled */
static rbs_mix *new_mix(const rbs_table *t)
{
    rbs_mix *mix = malloc(sizeof *mix + (size_t)t->n_shapes * sizeof(double));
    if (mix) {
        mix->table = t;
        mix->n_shapes = t->n_shapes;
    }
    return mix;
}

rbs_mix *rbs_mix_new_from_weights(const rbs_table *t, int n, const char *const names[], const double weights[],
                                  char *message, size_t message_size)
{
    if (message && message_size > 0) message[0] = '\0';
    if (!t || n < 0 || (n > 0 && (!names || !weights))) {
        rbs_message(message, message_size, "rbs_mix_new_from_weights: NULL table, names or weights, or n < 0");
        return NULL;
    }
    rbs_mix *mix = new_mix(t);
    if (!mix) {
        rbs_message(message, message_size, "rbs_mix_new_from_weights: out of memory");
        return NULL;
    }
    if (weights_cdf(t, n, names, weights, mix->cdf, message, message_size) != RBS_OK) {
        free(mix);
        return NULL;
    }
    return mix;
}

rbs_mix *rbs_mix_new_from_shape(const rbs_table *t, const char *name, char *message, size_t message_size)
{
    if (name && strcmp(name, "mix") == 0) {
        if (message && message_size > 0) message[0] = '\0';
        rbs_mix *mix = rbs_mix_new_equal(t);
        if (!mix) rbs_message(message, message_size, "rbs_mix_new_from_shape: NULL table or out of memory");
        return mix;
    }
    const double one = 1.0;
    const char *names[1] = {name};
    return rbs_mix_new_from_weights(t, 1, names, &one, message, message_size);
}

rbs_mix *rbs_mix_new_equal(const rbs_table *t)
{
    rbs_mix *mix = t ? new_mix(t) : NULL;
    if (mix) equal_cdf(t, mix->cdf);
    return mix;
}

void rbs_mix_free(rbs_mix *mix)
{
    free(mix);
}
