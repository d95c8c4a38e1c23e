/*
 * hdf5_read.h: what the table loader's parts share: the error state of one rbs_table_open and the HDF5 reading
 * helpers (hdf5_read.c). loader.c opens the file and reads the grids, the law and the cells, and calls
 * shape_records.c for the shapes; both read through these helpers, which call neither, so the dependencies go
 * one way: loader.c -> shape_records.c -> hdf5_read.c.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_HDF5_READ_H
#define RBS_HDF5_READ_H

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

#endif /* RBS_HDF5_READ_H */
