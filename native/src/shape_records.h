/*
 * shape_records.h: the shapes a table holds (shape_records.c), as the loader (loader.c) reads them.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_SHAPE_RECORDS_H
#define RBS_SHAPE_RECORDS_H

#include "hdf5_read.h"
#include "shapes.h"

/* Group /shapes of a table into t->shapes, checked as data_schema.shape_records.check_shape_datasets and
 * records_from_arrays check them (a built-in family's row against the family's record at κ and the aspect-ratio
 * law `aspect` of the table's model/parameters, a user polyhedron's inertia against the mass properties of its
 * hull). RBS_OK or the error's code. */
int rbs_shape_records_load(loader *ld, hid_t file, rbs_table *t, double kappa, const double aspect[4]);

#endif /* RBS_SHAPE_RECORDS_H */
