/*
 * mix.c: shape mixes (surrogate.validation.mix_cdf): cumulative weights in the table's shape order, into a block
 * sized by the table (rbs_mix_new_*) or into a 1.0 value (tables of at most RBS_MAX_SHAPES shapes).
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
 * its order, the running sum in the table's order). RBS_OK or RBS_ERR_ARGUMENT with a message. */
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
        if (w > 0.0 && s < 0) {
            rbs_message(message, message_size, "shape '%s' is not in the table %s.", name, t->path);
            return RBS_ERR_ARGUMENT;
        }
        if (s >= 0) cdf[s] = w;
    }
    double total = 0.0;
    for (int i = 0; i < n; i++) total += weights[i];
    if (fabs(total - 1.0) > 1e-9) {
        rbs_message(message, message_size, "The mix weights must sum to 1; got %.17g.", total);
        return RBS_ERR_ARGUMENT;
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

/* a block for the table's mixes, its head's cdf set to 1 (filled by set_block) */
static rbs_mix_block *new_block(const rbs_table *t)
{
    rbs_mix_block *block = malloc(sizeof *block + (size_t)t->n_shapes * sizeof(double));
    if (block) block->head.n_shapes = t->n_shapes;
    return block;
}

/* the head's inline cdf from the block's (a mix of at most RBS_MAX_SHAPES shapes is read from the head) */
static rbs_mix *set_block(rbs_mix_block *block)
{
    for (int i = 0; i < RBS_MAX_SHAPES; i++)
        block->head.cdf[i] = i < block->head.n_shapes ? block->cdf[i] : 1.0;
    return &block->head;
}

rbs_mix *rbs_mix_new_from_weights(const rbs_table *t, int n, const char *const names[], const double weights[],
                                  char *message, size_t message_size)
{
    if (message && message_size > 0) message[0] = '\0';
    if (!t || n < 0 || (n > 0 && (!names || !weights))) {
        rbs_message(message, message_size, "rbs_mix_new_from_weights: NULL table, names or weights, or n < 0");
        return NULL;
    }
    rbs_mix_block *block = new_block(t);
    if (!block) {
        rbs_message(message, message_size, "rbs_mix_new_from_weights: out of memory");
        return NULL;
    }
    if (weights_cdf(t, n, names, weights, block->cdf, message, message_size) != RBS_OK) {
        free(block);
        return NULL;
    }
    return set_block(block);
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
    rbs_mix_block *block = t ? new_block(t) : NULL;
    if (!block) return NULL;
    equal_cdf(t, block->cdf);
    return set_block(block);
}

void rbs_mix_free(rbs_mix *mix)
{
    free(mix ? (rbs_mix_block *)(void *)mix : NULL);
}

/* a 1.0 value mix holds at most RBS_MAX_SHAPES shapes: RBS_OK, or RBS_ERR_ARGUMENT with a message */
static int value_fits(const rbs_table *t, const char *function, char *message, size_t message_size)
{
    if (t->n_shapes <= RBS_MAX_SHAPES) return RBS_OK;
    rbs_message(message, message_size, "%s: the table %s holds %d shapes; an rbs_mix value holds at most %d: use "
                "rbs_mix_new_* (rebound_scatter.h, 'shape mixes')", function, t->path, t->n_shapes, RBS_MAX_SHAPES);
    return RBS_ERR_ARGUMENT;
}

int rbs_mix_from_weights(const rbs_table *t, int n, const char *const names[], const double weights[],
                         rbs_mix *mix, char *message, size_t message_size)
{
    if (message && message_size > 0) message[0] = '\0';
    if (!t || !mix || n < 0 || (n > 0 && (!names || !weights))) {
        rbs_message(message, message_size, "rbs_mix_from_weights: NULL table, mix, names or weights, or n < 0");
        return RBS_ERR_ARGUMENT;
    }
    if (value_fits(t, "rbs_mix_from_weights", message, message_size) != RBS_OK) return RBS_ERR_ARGUMENT;
    double cdf[RBS_MAX_SHAPES];
    if (weights_cdf(t, n, names, weights, cdf, message, message_size) != RBS_OK) return RBS_ERR_ARGUMENT;
    mix->n_shapes = t->n_shapes;
    for (int i = 0; i < RBS_MAX_SHAPES; i++) mix->cdf[i] = i < t->n_shapes ? cdf[i] : 1.0;
    return RBS_OK;
}

int rbs_mix_equal(const rbs_table *t, rbs_mix *mix)
{
    if (!t || !mix || value_fits(t, "rbs_mix_equal", NULL, 0) != RBS_OK) return RBS_ERR_ARGUMENT;
    mix->n_shapes = t->n_shapes;
    for (int i = 0; i < RBS_MAX_SHAPES; i++) mix->cdf[i] = 1.0;
    equal_cdf(t, mix->cdf);
    return RBS_OK;
}

int rbs_mix_from_shape(const rbs_table *t, const char *name, rbs_mix *mix, char *message, size_t message_size)
{
    if (name && strcmp(name, "mix") == 0) {
        if (message && message_size > 0) message[0] = '\0';
        if (t && value_fits(t, "rbs_mix_from_shape", message, message_size) != RBS_OK) return RBS_ERR_ARGUMENT;
        return rbs_mix_equal(t, mix);
    }
    const double one = 1.0;
    const char *names[1] = {name};
    return rbs_mix_from_weights(t, 1, names, &one, mix, message, message_size);
}
