/*
 * hdf5_read.c: the error state of one rbs_table_open and the HDF5 reading helpers that loader.c and
 * shape_records.c share (hdf5_read.h). HDF5's own error printing is switched off around each call that may fail
 * (H5E_BEGIN_TRY), so the library prints nothing.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hdf5_read.h"

int rbs_fail(loader *ld, int code, const char *format, ...)
{
    if (ld->code != RBS_OK) return ld->code;
    ld->code = code;
    if (ld->message && ld->message_size > 0) {
        char detail[2048];         /* room for a message quoting a wall law's nodes (loader.c) */
        va_list args;
        va_start(args, format);
        vsnprintf(detail, sizeof detail, format, args);
        va_end(args);
        snprintf(ld->message, ld->message_size, "%s: %s", ld->path, detail);
    }
    return code;
}

int rbs_link_exists(hid_t where, const char *name)
{
    htri_t found = 0;
    H5E_BEGIN_TRY { found = H5Lexists(where, name, H5P_DEFAULT); } H5E_END_TRY;
    return found > 0;
}

/* The shape of dataset `name` in `group`: its rank into *rank and dims (up to 8); 0 on success. */
int rbs_dataset_shape(loader *ld, hid_t group, const char *group_name, const char *name, int *rank,
                      hsize_t dims[8])
{
    hid_t ds = -1, space = -1;
    int r = -1;
    if (!rbs_link_exists(group, name)) return rbs_fail(ld, RBS_ERR_FORMAT, "missing dataset '%s/%s'", group_name, name);
    H5E_BEGIN_TRY {
        ds = H5Dopen2(group, name, H5P_DEFAULT);
        if (ds >= 0) space = H5Dget_space(ds);
        if (space >= 0) r = H5Sget_simple_extent_ndims(space);
        if (r >= 0 && r <= 8) H5Sget_simple_extent_dims(space, dims, NULL);
    } H5E_END_TRY;
    if (space >= 0) H5Sclose(space);
    if (ds >= 0) H5Dclose(ds);
    if (r < 0 || r > 8) return rbs_fail(ld, RBS_ERR_FORMAT, "cannot read dataset '%s/%s' (truncated or corrupt?)", group_name, name);
    *rank = r;
    return RBS_OK;
}

/* Read dataset `name` whole as `memtype` into a new buffer of `count` elements of `size` bytes, after
 * checking its shape is `rank` × `dims`. */
void *rbs_read_dataset(loader *ld, hid_t group, const char *group_name, const char *name, hid_t memtype,
                       size_t size, int rank, const hsize_t *dims)
{
    int found_rank = 0;
    hsize_t found[8];
    if (rbs_dataset_shape(ld, group, group_name, name, &found_rank, found) != RBS_OK) return NULL;
    int same = found_rank == rank;
    size_t count = 1;
    for (int i = 0; same && i < rank; i++) {
        same = found[i] == dims[i];
        count *= (size_t)dims[i];
    }
    if (!same) {
        char want[160] = "(", got[160] = "(";
        for (int i = 0; i < rank; i++)
            snprintf(want + strlen(want), sizeof want - strlen(want), "%s%llu", i ? ", " : "", (unsigned long long)dims[i]);
        for (int i = 0; i < found_rank; i++)
            snprintf(got + strlen(got), sizeof got - strlen(got), "%s%llu", i ? ", " : "", (unsigned long long)found[i]);
        strcat(want, ")");
        strcat(got, ")");
        rbs_fail(ld, RBS_ERR_FORMAT, "dataset '%s/%s' has shape %s, expected %s", group_name, name, got, want);
        return NULL;
    }
    void *buffer = malloc(count ? count * size : 1);
    if (!buffer) {
        rbs_fail(ld, RBS_ERR_MEMORY, "out of memory reading dataset '%s/%s' (%zu elements)", group_name, name, count);
        return NULL;
    }
    herr_t status = -1;
    hid_t ds = -1;
    H5E_BEGIN_TRY {
        ds = H5Dopen2(group, name, H5P_DEFAULT);
        if (ds >= 0) status = H5Dread(ds, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer);
    } H5E_END_TRY;
    if (ds >= 0) H5Dclose(ds);
    if (status < 0) {
        free(buffer);
        rbs_fail(ld, RBS_ERR_FORMAT, "cannot read dataset '%s/%s' (truncated, corrupt or failed checksum?)", group_name, name);
        return NULL;
    }
    return buffer;
}
