/*
 * table_info.c: what a loaded table tells about itself (rebound_scatter.h, "tables"): its sizes and grids'
 * ranges, its shapes' records, its wall, its derived kernel arrays. Each output record written as the size rule
 * says (records.h).
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <string.h>

#include "internal.h"
#include "records.h"

int rbs_table_info_get(const rbs_table *t, rbs_table_info *info)
{
    if (!t || !RBS_RECORD_OK(info, rbs_table_info))
        return RBS_INVALID;
    info->n_shapes = t->n_shapes;
    info->n_alpha1 = t->n_alpha1;
    info->n_speed = t->n_speed;
    info->n_clusters = t->n_clusters;
    info->n_levels = t->n_levels;
    info->n_dictionary = t->n_dictionary;
    info->n_pieces = t->n_pieces;
    info->format_major = t->format_major;
    info->format_minor = t->format_minor;
    info->particles_per_cell = t->particles_per_cell;
    info->n_max = t->n_max;
    info->alpha1_min_deg = t->alpha1_deg[0];
    info->alpha1_max_deg = t->alpha1_deg[t->n_alpha1 - 1];
    info->speed_min_m_s = t->speed_m_s[0];
    info->speed_max_m_s = t->speed_m_s[t->n_speed - 1];
    info->kernel_bytes = (t->alpha1_axis_len + t->speed_axis_len + t->cells_len + (size_t)t->n_speed
                          + t->restitution_pieces_len + t->work_cells_len) * sizeof(double)
                         + (t->clusters_len + t->dictionary_len + t->work_rows_len + t->work_dictionary_len)
                               * sizeof(float);
    return RBS_OK;
}

const double *rbs_table_alpha1_grid(const rbs_table *t, int *count)
{
    if (count) *count = t ? t->n_alpha1 : 0;
    return t ? t->alpha1_deg : NULL;
}

const double *rbs_table_speed_grid(const rbs_table *t, int *count)
{
    if (count) *count = t ? t->n_speed : 0;
    return t ? t->speed_m_s : NULL;
}

int rbs_table_shape_info(const rbs_table *t, int i, rbs_shape_info *info)
{
    if (!t || !RBS_RECORD_OK(info, rbs_shape_info) || i < 0 || i >= t->n_shapes)
        return RBS_INVALID;
    const rbs_shape_records *r = &t->shapes;
    info->name = t->shape_names[i];
    info->kind = r->kind[i];
    info->family = r->family[i];
    info->n_vertices = (int)(r->vertex_start[i + 1] - r->vertex_start[i]);
    info->vertices = info->n_vertices ? r->vertices + 3 * r->vertex_start[i] : NULL;
    memcpy(info->inertia, r->inertia + 3 * i, sizeof info->inertia);
    memcpy(info->aspect, r->aspect + 4 * i, sizeof info->aspect);
    info->both_hands = r->both_hands[i];
    return RBS_OK;
}

/* the wall as the loader read it from group wall (loader.c, read_wall): its family, name, parameters by name, the
 * speeds it holds over and a tabulated law's arrays (pointers into its wall array, layout W_*) */
int rbs_table_wall(const rbs_table *t, rbs_wall_info *info)
{
    if (!t || !RBS_RECORD_OK(info, rbs_wall_info))
        return RBS_INVALID;
    info->family = t->wall_family;
    info->name = t->wall_name;
    info->n_parameters = t->n_wall_parameters;
    info->parameter_names = t->wall_parameter_names;
    info->parameter_values = t->wall_parameters;
    memcpy(info->speed_range_m_s, t->wall_speed_range, sizeof info->speed_range_m_s);
    int tabulated = t->wall[W_FAMILY] == TABULATED_CODE;
    int ns = tabulated ? (int)t->wall[W_N_SPEEDS] : 0, nz = tabulated ? (int)t->wall[W_N_SINES] : 0;
    /* the fields after 1.0, each where the caller's record reaches it (records.h) */
    if (RBS_HAS_FIELD(info, rbs_wall_info, n_contact_speeds)) info->n_contact_speeds = ns;
    if (RBS_HAS_FIELD(info, rbs_wall_info, contact_speed_m_s))
        info->contact_speed_m_s = tabulated ? t->wall + W_NODES : NULL;
    if (RBS_HAS_FIELD(info, rbs_wall_info, n_contact_sines)) info->n_contact_sines = nz;
    if (RBS_HAS_FIELD(info, rbs_wall_info, contact_sine)) info->contact_sine = tabulated ? t->wall + W_NODES + ns : NULL;
    if (RBS_HAS_FIELD(info, rbs_wall_info, restitution))
        info->restitution = tabulated ? t->wall + W_NODES + ns + nz : NULL;
    if (RBS_HAS_FIELD(info, rbs_wall_info, roughness_deg)) info->roughness_deg = t->wall_roughness;
    return RBS_OK;
}

int rbs_table_kernel_array(const rbs_table *t, const char *name, const void **data, size_t *count, int *dtype)
{
    const void *p = NULL;
    size_t n = 0;
    int type = RBS_DTYPE_FLOAT64;
    if (!t || !name) return RBS_INVALID;
    if (strcmp(name, "alpha1_axis") == 0) { p = t->alpha1_axis; n = t->alpha1_axis_len; }
    else if (strcmp(name, "speed_axis") == 0) { p = t->speed_axis; n = t->speed_axis_len; }
    else if (strcmp(name, "cells") == 0) { p = t->cells; n = t->cells_len; }
    else if (strcmp(name, "clusters") == 0) { p = t->clusters; n = t->clusters_len; type = RBS_DTYPE_FLOAT32; }
    else if (strcmp(name, "dictionary") == 0) { p = t->dictionary; n = t->dictionary_len; type = RBS_DTYPE_FLOAT32; }
    else if (strcmp(name, "speed_restitution") == 0) { p = t->speed_restitution; n = (size_t)t->n_speed; }
    else if (strcmp(name, "restitution_pieces") == 0) { p = t->restitution_pieces; n = t->restitution_pieces_len; }
    else if (strcmp(name, "work_rows") == 0) { p = t->work_rows; n = t->work_rows_len; type = RBS_DTYPE_FLOAT32; }
    else if (strcmp(name, "work_dictionary") == 0) {
        p = t->work_dictionary;
        n = t->work_dictionary_len;
        type = RBS_DTYPE_FLOAT32;
    }
    else if (strcmp(name, "work_cells") == 0) { p = t->work_cells; n = t->work_cells_len; }
    else if (strcmp(name, "direct_parameters") == 0) { p = t->direct_parameters; n = N_PARAMS; }
    else return RBS_INVALID;
    if (data) *data = p;
    if (count) *count = n;
    if (dtype) *dtype = type;
    return RBS_OK;
}
