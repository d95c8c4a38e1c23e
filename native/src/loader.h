/*
 * loader.h: what the table loader's parts share (loader.c opens the file and reads the grids, the law and the
 * cells; shape_records.c the shapes): the error state of one rbs_table_open and the HDF5 reading helpers.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_LOADER_H
#define RBS_LOADER_H

#include <hdf5.h>

#include "internal.h"

/* what a failed step leaves: code and message (the first error wins) */
typedef struct loader {
    const char *path;
    char *message;
    size_t message_size;
    int code;
} loader;

/* Set the error (unless one is set): `code` and the message "path: ..."; returns the code in force. */
int rbs_fail(loader *ld, int code, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Whether link `name` exists in `where` (HDF5's error printing off). */
int rbs_link_exists(hid_t where, const char *name);

/* The shape of dataset `name` in `group`: its rank into *rank and dims (up to 8); 0 on success. */
int rbs_dataset_shape(loader *ld, hid_t group, const char *group_name, const char *name, int *rank, hsize_t dims[8]);

/* Read dataset `name` whole as `memtype` into a new buffer of `count` elements of `size` bytes, after checking its
 * shape is `rank` × `dims`; NULL (and the error set) on failure. */
void *rbs_read_dataset(loader *ld, hid_t group, const char *group_name, const char *name, hid_t memtype, size_t size,
                       int rank, const hsize_t *dims);

/* shape_records.c: group /shapes of a table of format 3.4 into t->shapes, checked as
 * data_schema.shape_records.check_shape_datasets and records_from_arrays check them (a built-in family's row against
 * the family's record at κ and the aspect-ratio law `aspect`); before 3.4, the families' records synthesised
 * from κ, `aspect` and the second-moment factors `kfac` (NaN if not recorded). RBS_OK or the error's code. */
int rbs_shape_records_load(loader *ld, hid_t file, rbs_table *t, double kappa, const double aspect[4],
                           const double kfac[RBS_N_FAMILIES]);

#endif /* RBS_LOADER_H */
