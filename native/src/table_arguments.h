/*
 * table_arguments.h: the table path's argument checks, shared by its entry points (table_path.c, pipeline.c) and
 * by rbs_rebound (wall_hit.c), which takes the same mix and interpolation.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_TABLE_ARGUMENTS_H
#define RBS_TABLE_ARGUMENTS_H

#include "internal.h"

/* a table, a mix made from it, a known interpolation */
static inline int rbs_table_arguments_ok(const rbs_table *t, const rbs_mix *mix, int interpolation)
{
    return t != NULL && mix != NULL && mix->table == t
           && (interpolation == RBS_INTERPOLATION_SCALED || interpolation == RBS_INTERPOLATION_STOCHASTIC);
}

#endif /* RBS_TABLE_ARGUMENTS_H */
