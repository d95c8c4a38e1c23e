/*
 * hull_walk.h: walks over a hull's vertex graph (direct_model.hull_walk), the contact search of a hull of more than
 * WALK_ABOVE vertices in time that barely grows with their number, with the bits of a scan of every vertex: each
 * query walks the band of vertices its answer may come from (connected on a convex hull) and applies the scan's
 * comparisons to them in index order. Body frame, lengths in units of a; a vertex of the particle is
 * unit[i] · scale, its height h = y + g·p and rate h' = v + d·p (flight.c).
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_HULL_WALK_H
#define RBS_HULL_WALK_H

#include <math.h>
#include <stdint.h>

#define WALK_ABOVE 64       /* direct_model.hull_walk.WALK_ABOVE: a hull of more vertices is walked */
#define WALK_ROOM 128       /* direct_model.hull_walk.ROOM: vertices one walk may meet; more: the query scans */
#define WALK_SLOTS 256      /* direct_model.hull_walk.SLOTS: the hash slots of the vertices met */
#define WALK_BAND 1e-9      /* direct_model.hull_walk.BAND: the relative widening of a walk's bound */
#define MAP_CELLS 16        /* direct_model.hull_walk.MAP_CELLS: cells along a face's edge of the start map */
#define MAP_SIZE (6 * MAP_CELLS * MAP_CELLS)
#define FAR_MARGIN 1e-12    /* direct_model.hull_walk.FAR_MARGIN */

/* One particle's walked hull (direct_model.shape_arrays.particle_hull): the shape's n unit vertices (row-major
 * n × 3), the particle's scale, the vertex graph (vertex i's neighbours graph[graph_start[i] .. graph_start[i + 1]],
 * indices into unit), the start map (MAP_SIZE vertices) and the n_far farthest candidates. */
typedef struct rbs_hull {
    const double *unit;
    int n;
    double scale[3];
    const int64_t *graph_start;
    const int32_t *graph;
    const int32_t *starts;
    const int32_t *far;
    int n_far;
} rbs_hull;

/* A walk's work space (direct_model.hull_walk: the work array): the hash set of the vertices met (vertex + 1, 0
 * empty; empty between walks), the slots of the vertices met, the band's members, the vertex the next descent to the
 * lowest may start from. */
typedef struct rbs_walk {
    int32_t slots[WALK_SLOTS];
    int32_t where[WALK_ROOM];
    int32_t members[WALK_ROOM];
    int start;
} rbs_walk;

/* vertex i of the particle, unit[i] · scale */
static inline void rbs_hull_vertex(const rbs_hull *hl, int i, double p[3])
{
    for (int k = 0; k < 3; k++) p[k] = hl->unit[3 * i + k] * hl->scale[k];
}

/* vertex i's height y + g·p, and p */
static inline double rbs_hull_height(const rbs_hull *hl, const double g[3], double y, int i, double p[3])
{
    rbs_hull_vertex(hl, i, p);
    return y + (g[0] * p[0] + g[1] * p[1] + g[2] * p[2]);
}

/* vertex i's level h + T·h' (T = 0: its height, bit for bit) */
static inline double rbs_walk_level(const rbs_hull *hl, const double g[3], const double d[3], double y, double v,
                                    double T, int i)
{
    double p[3];
    double h = rbs_hull_height(hl, g, y, i, p);
    if (T == 0.0) return h;
    return h + T * (v + (d[0] * p[0] + d[1] * p[1] + d[2] * p[2]));
}

/* Σ |direction_k · scale_k| · 2: a bound on |direction·p| over the unit body (direct_model.hull_walk.reach) */
static inline double rbs_hull_reach(const double direction[3], const double scale[3])
{
    return 2.0 * (fabs(direction[0] * scale[0]) + fabs(direction[1] * scale[1]) + fabs(direction[2] * scale[2]));
}

/* the k-th vertex a query takes: of the band (count >= 0 of them), or of the whole hull (count −1) */
static inline int rbs_walk_member(const rbs_walk *w, int count, int k)
{
    return count >= 0 ? w->members[k] : k;
}

/* Building a shape's walk from its hull (direct_model: polyhedron.vertex_graph, hull_walk.start_map and
 * farthest_candidates); each returns 0, or −1 out of memory. */

/* The vertex graph of the n vertices from nt triangles (row-major nt × 3): *start (n + 1) and *graph (2 × edges),
 * each list ascending, malloc'ed here. */
int rbs_vertex_graph(const int32_t *triangles, int64_t nt, int n, int64_t **start, int32_t **graph);

/* starts (MAP_SIZE) of the n unit vertices (n × 3) and their graph (start local to them) */
void rbs_start_map(const double *unit, int n, const int64_t *start, const int32_t *graph, int32_t *starts);

/* the farthest candidates of the n unit vertices, ascending, into far (room for n); returns their number or −1 */
int rbs_farthest_candidates(const double *unit, int n, int32_t *far);

/* The queries (direct_model.hull_walk); w's hash set empty on entry and on return (rbs_walk_clear before a rebound's
 * first). */
void rbs_walk_clear(rbs_walk *w);

int rbs_walk_map_start(const rbs_hull *hl, const double direction[3]);
int rbs_walk_nearer(const rbs_hull *hl, const double g[3], double y, const rbs_walk *w);
int rbs_walk_descend(const rbs_hull *hl, const double g[3], const double d[3], double y, double v, double T, int i,
                     double *around);
int rbs_walk_band(const rbs_hull *hl, const double g[3], const double d[3], double y, double v, double T, double limit,
                  int start, rbs_walk *w);
void rbs_walk_lowest(const rbs_hull *hl, const double g[3], double y, int start, rbs_walk *w, double *h_low, int *low);
void rbs_walk_contact_sums(const rbs_hull *hl, const double g[3], const double d[3], double y, double v, double limit,
                           int low, rbs_walk *w, int *count, double sums[3], double *rate, int *best);
double rbs_walk_farthest(const rbs_hull *hl);

#endif /* RBS_HULL_WALK_H */
