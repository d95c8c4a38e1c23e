/*
 * shapes.h: the particle shapes of the direct model. The shapes as plain arrays (direct_model.shape_arrays: the
 * form, one particle's body from it), the four families' unit bodies (direct_model.shapes.body_vertices) and
 * their names. Lengths in units of the particle's half-size a, body frame Oξηζ (principal axes).
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_SHAPES_H
#define RBS_SHAPES_H

#include <stdint.h>

#include "hull_walk.h"
#include "rebound_scatter.h"

#define RBS_N_FAMILIES 4    /* the built-in families, codes RBS_ELLIPSOID .. RBS_TETRAHEDRON (direct_model.shapes.SHAPES) */
/* the short names the library's sources use for the public enumerators of families and kinds (rebound_scatter.h) */
#define RBS_ELLIPSOID RBS_FAMILY_ELLIPSOID
#define RBS_PRISM RBS_FAMILY_PRISM
#define RBS_CUT_PRISM RBS_FAMILY_CUT_PRISM
#define RBS_TETRAHEDRON RBS_FAMILY_TETRAHEDRON
#define RBS_SMOOTH RBS_KIND_SMOOTH
#define RBS_POLYHEDRON RBS_KIND_POLYHEDRON
#define MAX_VERTICES 24             /* direct_model.shapes.MAX_VERTICES: the cut prism's */
#define MAX_HULL_VERTICES 65536     /* direct_model.registry.MAX_HULL_VERTICES: the most a shape has */
/* the most vertices whose work space a call keeps on its stack (a hit's 40 bytes each, 10 KiB; the loader's mass
 * properties 64, 16 KiB: far inside the smallest thread stack in common use, musl's 128 KiB); a larger hull's takes
 * one malloc per call */
#define MAX_STACK_VERTICES 256
#define KIND_ELLIPSOID 0            /* direct_model.shape_arrays.KIND_ELLIPSOID */
#define KIND_POLYHEDRON 1           /* direct_model.shape_arrays.KIND_POLYHEDRON */
#define FAMILY_VERTEX_ROWS 37       /* the families' unit bodies: the ellipsoid's semi-axes, 8, 24 and 4 vertices */

/* Every shape as plain arrays (direct_model.shape_arrays.ShapeArrays; its module doc says what each holds):
 * shape i is row i of each per-shape array, its vertices rows vertex_start[i] .. vertex_start[i + 1] of
 * `vertices` (row-major × 3). The kernels read, never write them. */
typedef struct rbs_shape_arrays {
    int n_shapes;
    const int8_t *kind;             /* KIND_ELLIPSOID or KIND_POLYHEDRON */
    const int64_t *vertex_start;    /* n_shapes + 1 */
    const double *vertices;         /* the unit bodies: hull vertices, or an ellipsoid's semi-axes (one row) */
    const double *second_moments;   /* n_shapes × 3: ∫ξ² dm/m, ∫η² dm/m, ∫ζ² dm/m of the unit body, a² */
    const double *aspect;           /* n_shapes × 4: the b/a, c/b law (mean, sd, low, high); NaN: fixed */
    const double *aspect_cdf;       /* n_shapes × 2: Φ((low − mean)/sd), Φ((high − mean)/sd) */
    const uint8_t *both_hands;      /* 1: half of the particles are the mirror image */
    /* derived (NULL: none); half_extents NULL: computed from the vertices per call (the same values) */
    const double *half_extents;     /* n_shapes × 3: (max − min)/2 of the unit body along ξ, η, ζ */
    /* a hull of more than WALK_ABOVE vertices is walked (hull_walk.h) where graph_start is not NULL: */
    const int64_t *graph_start;     /* vertex_start[n_shapes] + 1: row r's neighbours graph[graph_start[r] ..] */
    const int32_t *graph;           /* the vertex graphs, the shape's own vertex indices */
    const int32_t *starts;          /* n_shapes × MAP_SIZE: the start maps (a walked hull's) */
    const int64_t *far_start;       /* n_shapes + 1: shape i's farthest candidates far[far_start[i] ..] */
    const int32_t *far;
} rbs_shape_arrays;

/* The built-in families' names by code (direct_model.shapes.SHAPES): the registry the loader consults for a
 * table's built-in names and for the records of a table before format 3.4 */
extern const char *const rbs_shape_names[RBS_N_FAMILIES];

/* The code of a built-in family's name, −1 for a name that is none (direct_model.shapes.SHAPES.index) */
int rbs_shape_code(const char *name);

/* out[0..n) = the body-frame vertices (row-major n × 3) of the polyhedron `shape` with half-extents a, b, c,
 * cut fraction kappa (cut prism) and hand ±1 (tetrahedron); returns n, 0 for the ellipsoid
 * (direct_model.shapes.body_vertices). */
int rbs_body_vertices(int shape, double a, double b, double c, double kappa, double hand, double *out);

/* The four families' rows of shape arrays, in code order (direct_model.shape_arrays.family_shape_arrays), into
 * arrays with room for RBS_N_FAMILIES shapes and FAMILY_VERTEX_ROWS vertex rows: from κ, the b/a, c/b law
 * (mean, sd, low, high) and its CDF bounds, and the factor s per shape code. */
void rbs_family_shapes_fill(int8_t *kind, int64_t *vertex_start, double *vertices, double *second_moments,
                            double *aspect, double *aspect_cdf, uint8_t *both_hands, double kappa,
                            const double law[4], const double law_cdf[2], const double kfac[RBS_N_FAMILIES]);

/* One particle's body from shape `shape` of `s` (direct_model.shape_arrays.particle_body): b/a and c/b
 * (ignored for fixed proportions), hand ±1; the vertices into verts unless it is NULL (row-major, room for the
 * shape's vertex_start[shape + 1] − vertex_start[shape] rows: numba copies them only into a scan's room, the bits
 * are the same), the principal J/m into K (a²), the half-extents into semi and the factors that take the unit body
 * to the particle's into scale (vertex i is unit[i] · scale); returns their number, 0 for an ellipsoid. */
int rbs_particle_body(const rbs_shape_arrays *s, int shape, double ratio_ba, double ratio_cb, double hand,
                      double *verts, double K[3], double semi[3], double scale[3]);

/* Whether shape `shape` of `s` is walked over its vertex graph: a hull of more than WALK_ABOVE vertices, with the
 * graphs in `s` */
int rbs_walked(const rbs_shape_arrays *s, int shape);

/* A walked shape's hull for the particle of the scale rbs_particle_body gave (direct_model.shape_arrays.
 * particle_hull) */
void rbs_particle_hull(const rbs_shape_arrays *s, int shape, const double scale[3], rbs_hull *hull);

/* (max − min)/2 of rows lo .. lo + nv of `unit` along each axis into e (direct_model.shape_arrays._half_extents) */
void rbs_half_extents(const double *unit, int64_t lo, int nv, double e[3]);

/* Radius of the smallest centroid-centred sphere holding the body, units of a
 * (direct_model.shape_arrays.bounding_radius). */
double rbs_bounding_radius(int kind, const double semi[3], const double *verts, int nv);

#endif /* RBS_SHAPES_H */
