/*
 * shapes.h: the particle shapes of the direct model (direct_model.shapes): body-frame vertices and bounding
 * radius, lengths in units of the half-size a.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_SHAPES_H
#define RBS_SHAPES_H

#include "rebound_scatter.h"

#define MAX_VERTICES 24     /* direct_model.shapes.MAX_VERTICES: the cut prism's */
#define RBS_N_FAMILIES 4    /* the built-in families, codes RBS_ELLIPSOID .. RBS_TETRAHEDRON (direct_model.shapes.SHAPES) */

/* The built-in families' names by code (direct_model.shapes.SHAPES): the registry the loader consults for a
 * table's built-in names and for the records of a table before format 3.4 */
extern const char *const rbs_shape_names[RBS_N_FAMILIES];

/* The code of a built-in family's name, −1 for a name that is none (direct_model.shapes.SHAPES.index) */
int rbs_shape_code(const char *name);

/* out[0..n) = the body-frame vertices (row-major n × 3) of the polyhedron `shape` with half-extents a, b, c,
 * cut fraction kappa (cut prism) and hand ±1 (tetrahedron); returns n, 0 for the ellipsoid
 * (direct_model.shapes.body_vertices). */
int rbs_body_vertices(int shape, double a, double b, double c, double kappa, double hand, double *out);

/* Radius of the smallest centroid-centred sphere holding the body, units of a
 * (direct_model.shapes.bounding_radius). */
double rbs_bounding_radius(int shape, double a, double b, double c, const double *verts, int nv);

#endif /* RBS_SHAPES_H */
