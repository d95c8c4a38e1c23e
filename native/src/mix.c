/*
 * mix.c: shape mixes (surrogate.validation.mix_cdf): cumulative weights in the table's shape order.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "shapes.h"

static int table_shape(const rbs_table *t, const char *name)
{
    for (int i = 0; i < t->n_shapes; i++)
        if (strcmp(name, t->shape_names[i]) == 0) return i;
    return -1;
}

int rbs_mix_from_weights(const rbs_table *t, int n, const char *const names[], const double weights[],
                         rbs_mix *mix, char *message, size_t message_size)
{
    if (message && message_size > 0) message[0] = '\0';
    if (!t || !mix || n < 0 || (n > 0 && (!names || !weights))) {
        rbs_message(message, message_size, "rbs_mix_from_weights: NULL table, mix, names or weights, or n < 0");
        return RBS_ERR_ARGUMENT;
    }
    double by_shape[RBS_MAX_SHAPES] = {0.0};
    double total = 0.0;
    for (int i = 0; i < n; i++) {
        const char *name = names[i];
        if (!name || rbs_shape_code(name) < 0) {
            rbs_message(message, message_size, "The 'shape' parameter must name one of ellipsoid, prism, cut_prism, "
                        "tetrahedron; got '%s'.", name ? name : "(null)");
            return RBS_ERR_ARGUMENT;
        }
        for (int j = 0; j < i; j++) {
            if (strcmp(names[j], name) == 0) {
                rbs_message(message, message_size, "The mix names shape '%s' twice.", name);
                return RBS_ERR_ARGUMENT;
            }
        }
        double w = weights[i];
        if (!(isfinite(w) && w >= 0.0)) {
            rbs_message(message, message_size, "The mix weight of '%s' must be finite and >= 0; got %.17g.", name, w);
            return RBS_ERR_ARGUMENT;
        }
        int s = table_shape(t, name);
        if (w > 0.0 && s < 0) {
            rbs_message(message, message_size, "shape '%s' is not in the table %s.", name, t->path);
            return RBS_ERR_ARGUMENT;
        }
        if (s >= 0) by_shape[s] = w;
    }
    for (int i = 0; i < n; i++) total += weights[i];
    if (fabs(total - 1.0) > 1e-9) {
        rbs_message(message, message_size, "The mix weights must sum to 1; got %.17g.", total);
        return RBS_ERR_ARGUMENT;
    }
    double sum = 0.0;
    mix->n_shapes = t->n_shapes;
    for (int i = 0; i < RBS_MAX_SHAPES; i++) mix->cdf[i] = 1.0;
    for (int i = 0; i < t->n_shapes; i++) {
        sum += by_shape[i];
        mix->cdf[i] = sum;
    }
    mix->cdf[t->n_shapes - 1] = 1.0;
    return RBS_OK;
}

int rbs_mix_equal(const rbs_table *t, rbs_mix *mix)
{
    if (!t || !mix) return RBS_ERR_ARGUMENT;
    double w = 1.0 / (double)t->n_shapes, sum = 0.0;
    mix->n_shapes = t->n_shapes;
    for (int i = 0; i < RBS_MAX_SHAPES; i++) mix->cdf[i] = 1.0;
    for (int i = 0; i < t->n_shapes; i++) {
        sum += w;
        mix->cdf[i] = sum;
    }
    mix->cdf[t->n_shapes - 1] = 1.0;
    return RBS_OK;
}

int rbs_mix_from_shape(const rbs_table *t, const char *name, rbs_mix *mix, char *message, size_t message_size)
{
    if (name && strcmp(name, "mix") == 0) {
        if (message && message_size > 0) message[0] = '\0';
        return rbs_mix_equal(t, mix);
    }
    const double one = 1.0;
    const char *names[1] = {name};
    return rbs_mix_from_weights(t, 1, names, &one, mix, message, message_size);
}
