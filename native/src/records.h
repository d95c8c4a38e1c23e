/*
 * records.h: the size rule of the public records (rebound_scatter.h, "Records that grow"), in one place.
 *
 * Every record begins with `size_t size`, the caller's sizeof of it. A record is accepted when it reaches the end of
 * its last field of version 1.0 (RBS_RECORD_OK); a field added later is read or written only where the caller's
 * record reaches its end (RBS_HAS_FIELD), else it takes its default (an input) or is left alone (an output).
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_RECORDS_H
#define RBS_RECORDS_H

#include <stddef.h>

#include "rebound_scatter.h"

/* the bytes of `type` up to the end of `field` */
#define RBS_END_OF(type, field) (offsetof(type, field) + sizeof(((type *)0)->field))

/* the 1.0 size of each record: the end of its last field of version 1.0 (never changes) */
#define RBS_SIZE_1_0_rbs_hit RBS_END_OF(rbs_hit, rng)
#define RBS_SIZE_1_0_rbs_options RBS_END_OF(rbs_options, interpolation)
#define RBS_SIZE_1_0_rbs_result RBS_END_OF(rbs_result, Omega)
#define RBS_SIZE_1_0_rbs_hits RBS_END_OF(rbs_hits, rng)
#define RBS_SIZE_1_0_rbs_results RBS_END_OF(rbs_results, status)
#define RBS_SIZE_1_0_rbs_table_info RBS_END_OF(rbs_table_info, kernel_bytes)
#define RBS_SIZE_1_0_rbs_shape_info RBS_END_OF(rbs_shape_info, both_hands)
#define RBS_SIZE_1_0_rbs_wall_info RBS_END_OF(rbs_wall_info, speed_range_m_s)
#define RBS_SIZE_1_0_rbs_grain RBS_END_OF(rbs_grain, hand)

/* a record the caller gave: not NULL, and at least its 1.0 size */
#define RBS_RECORD_OK(record, type) ((record) != NULL && (record)->size >= RBS_SIZE_1_0_##type)

/* a field of a later version inside the caller's record (record checked by RBS_RECORD_OK) */
#define RBS_HAS_FIELD(record, type, field) ((record)->size >= RBS_END_OF(type, field))

/* The options of a hit (NULL: the defaults) into *method and *interpolation: 1, or 0 for a record too small or an
 * unknown interpolation. The method is not checked here (rbs_draw_local does not read it; the hits refuse an
 * unknown one where they choose their path). */
static inline int rbs_options_read(const rbs_options *options, int *method, int *interpolation)
{
    *method = RBS_METHOD_AUTO;
    *interpolation = RBS_INTERPOLATION_SCALED;
    if (!options) return 1;
    if (!RBS_RECORD_OK(options, rbs_options)) return 0;
    *method = options->method;
    *interpolation = options->interpolation;
    return *interpolation == RBS_INTERPOLATION_SCALED || *interpolation == RBS_INTERPOLATION_STOCHASTIC;
}

/* The roughness Δγ (degrees) options ask for, the table's wall's `table_roughness` for a negative one, a NULL
 * options or a record too small to hold the field (1.0, 1.1), into *roughness: 1, or 0 for NaN or a roughness
 * above RBS_MAX_ROUGHNESS_DEG (options checked by rbs_options_read). */
static inline int rbs_options_roughness(const rbs_options *options, double table_roughness, double *roughness)
{
    double asked = RBS_ROUGHNESS_OF_TABLE;
    if (options && RBS_HAS_FIELD(options, rbs_options, roughness_deg))
        asked = options->roughness_deg;
    *roughness = asked < 0.0 ? table_roughness : asked;
    return *roughness <= RBS_MAX_ROUGHNESS_DEG;     /* false for NaN */
}

#endif /* RBS_RECORDS_H */
