/*
 * rebound_internal.h: argument checks shared by the draw entry points.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_REBOUND_INTERNAL_H
#define RBS_REBOUND_INTERNAL_H

#include "internal.h"

/* a table, a mix of its shape count, a known interpolation */
static inline int rbs_arguments_ok(const rbs_table *t, const rbs_mix *mix, int interpolation)
{
    return t != NULL && mix != NULL && mix->n_shapes == t->n_shapes
           && (interpolation == RBS_SCALED || interpolation == RBS_STOCHASTIC);
}

#endif /* RBS_REBOUND_INTERNAL_H */
