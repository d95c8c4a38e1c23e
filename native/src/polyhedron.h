/*
 * polyhedron.h: a convex hull's mass properties and a family's surface, bit for bit as Python makes them
 * (polyhedron.c: direct_model.polyhedron.mass_properties, direct_model.registry._faces_to_triangles), so that the
 * loader can check a table's stored triangles and inertia as data_schema.shape_records.records_from_arrays does.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_POLYHEDRON_H
#define RBS_POLYHEDRON_H

#include <stddef.h>
#include <stdint.h>

#include "shapes.h"

#define MAX_HULL_TRIANGLES (2 * MAX_HULL_VERTICES - 4)     /* Euler: a triangulated convex hull of n vertices */

/* math.fsum of x[0..n): the correctly rounded sum of finite values (CPython's); `partials` work space, room for n. */
double rbs_fsum(const double *x, size_t n, double *partials);

/* direct_model.polyhedron.MassProperties: volume, centre of mass, J/m about it in the vertices' frame. */
typedef struct rbs_mass_properties {
    double volume;
    double centroid[3];
    double inertia[3][3];
} rbs_mass_properties;

/* direct_model.polyhedron.mass_properties of the body bounded by `n_triangles` triangles (indices into the
 * `n_vertices` rows of `vertices`, row-major × 3; n_vertices <= MAX_HULL_VERTICES, n_triangles <=
 * MAX_HULL_TRIANGLES, indices checked by the caller): the same operations in the same order, so the same
 * bits. 0, or -1 if the triangles enclose no volume (out->volume is then the volume found; Python's ValueError),
 * or -2 if the work space of a hull of more than MAX_STACK_VERTICES vertices cannot be allocated (one malloc). */
int rbs_hull_mass_properties(const double *vertices, int n_vertices, const int32_t *triangles, int n_triangles,
                             rbs_mass_properties *out);

/* direct_model.registry._faces_to_triangles: the triangles (row-major × 3, at most `max_triangles`) of the convex
 * polyhedron of these `n_vertices` vertices whose faces have the `n_normals` outward normals (rows × 3), a fan
 * per face; their number, or -1 if more than max_triangles, -2 if the work space of more than MAX_STACK_VERTICES
 * vertices cannot be allocated (one malloc). */
int rbs_faces_to_triangles(const double *vertices, int n_vertices, const double *normals, int n_normals,
                           int32_t *out, int max_triangles);

#endif /* RBS_POLYHEDRON_H */
