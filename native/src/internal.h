/*
 * internal.h: the in-memory table and the layouts of its kernel arrays (surrogate.kernels.layout.KernelData).
 *
 * The arrays are those of surrogate's table.kernel_data, element for element:
 *   alpha1_axis, speed_axis  float64 axis records (AXIS_* layout, layout.c)
 *   cells        float64 (n_cells · CELL_SIZE): P(trapped), 6 means, 6 sds, 6 inverse sds per cell
 *   clusters     float32 (n_cells · C · ROW_SIZE): one row per mixture component (ROW_* layout)
 *   dictionary   float32 (n_cells · 6 · n_levels · n_dictionary): residual shapes, level-major
 *   speed_restitution   float64 (n_speed): the wall's restitution factor f(V) (exp(−k V^p) for the exponential
 *                       law) at the grid speeds
 *   restitution_pieces  float64: polynomial pieces of f(V) between them (layout.c)
 *   work_rows    float32 (n_cells · C · WORK_ROW_SIZE): each component's two work variables (WORK_ROW_* layout)
 *   work_dictionary     float32 (n_cells · N_WORK · n_levels · n_dictionary): their residual shapes, level-major
 *   work_cells   float64 (n_cells · WORK_CELL_SIZE): their moments and the trapped particles' mean work
 * The three work arrays are empty (has_work 0) for a table without the work on the wall (format 4.0).
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_INTERNAL_H
#define RBS_INTERNAL_H

#include <stddef.h>
#include <math.h>
#include <stdint.h>

#include "rebound_scatter.h"
#include "runtime.h"

/* The entry points of the hot path are compiled twice on x86-64 with GCC (function multi-versioning,
 * chosen once at load time): for x86-64-v3 (AVX2 and FMA, so fma() is one instruction, as in numba's code
 * on such CPUs) and for the baseline (fma() is then the C library's, correctly rounded: the same bits).
 * Define RBS_NO_CLONES to build the baseline only. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__ELF__) && !defined(RBS_NO_CLONES)
#define RBS_HOT __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define RBS_HOT
#endif
#if defined(__GNUC__)
#define RBS_INLINE static inline __attribute__((always_inline))
#else
#define RBS_INLINE static inline
#endif

/* A component row of `clusters` (144 bytes: three cache lines when 16-byte aligned in a 64-byte block) */
#define ROW_ALIAS_PROB 0    /* Walker alias table: keep the component if the fractional part < this */
#define ROW_ALIAS 1         /* ... else use this component */
#define ROW_LOC 2           /* 6 locations (chain order) */
#define ROW_SCALE 8         /* 6 scales */
#define ROW_SHAPE 14        /* 6 residual shape indices m */
#define ROW_SLOPE 20        /* 15 slopes, x_k on x_j at k(k−1)/2 + j */
#define ROW_REGIME 35       /* collision regime: 0 = at most two collisions, 1 = more */
#define ROW_SIZE 36

/* A component's work row of `work_rows` (80 bytes): the chain's two work variables r and φ */
#define WORK_ROW_LOC 0      /* 2 locations */
#define WORK_ROW_SCALE 2    /* 2 scales */
#define WORK_ROW_SHAPE 4    /* 2 residual shape indices into work_dictionary */
#define WORK_ROW_SLOPE 6    /* 13 slopes: r on the six chain variables, φ on them and r */
#define WORK_ROW_SIZE 20    /* 19 used; 20 keeps rows 16-byte aligned */

/* A cell's work record of `work_cells` */
#define WORK_CELL_MEAN 0    /* means of r and φ */
#define WORK_CELL_SD 2      /* their standard deviations */
#define WORK_CELL_INV_SD 4  /* 1/sd (0 where sd = 0) */
#define WORK_CELL_TRAPPED 6 /* the trapped particles' mean W_n/E⁻ and W_t/E⁻ */
#define WORK_CELL_SIZE 8

/* A cell record of `cells` */
#define CELL_P_TRAPPED 0
#define CELL_MEAN 1         /* 6 means of (α2, β2, s, Ω_x, Ω_y, Ω_z) */
#define CELL_SD 7           /* 6 standard deviations */
#define CELL_INV_SD 13      /* 1/sd (0 where sd = 0) */
#define CELL_SIZE 19

/* An axis record: origin and inverse step of the auxiliary uniform grid, then the n grid points, then
 * max(n − 1, 1) inverse spacings, then the look-up indices (as float64) */
#define AXIS_ORIGIN 0
#define AXIS_INV_STEP 1
#define AXIS_GRID 2

#define N_CHAIN 6
#define N_SLOPES 15
#define N_WORK 2            /* work variables of a component (data_schema.table.WORK_NAMES) */
#define N_WORK_SLOPES 13    /* data_schema.table.N_WORK_SLOPES */
#define RESTITUTION_DEGREE 9   /* surrogate.kernels.fastmath.DEGREE */
#define RESTITUTION_PIECE_RATIO 1.25   /* surrogate.kernels.fastmath.PIECE_RATIO */

/* what makes a table valid (docs/format.md; data_schema.table.SPEED_GRID_RANGE, MAX_SPEED_RATIO,
 * WEIGHT_SUM_TOLERANCE) */
#define SPEED_GRID_MIN 1e-3         /* m/s */
#define SPEED_GRID_MAX 1e4          /* m/s */
#define MAX_SPEED_RATIO 16.0        /* between consecutive grid speeds */
#define WEIGHT_SUM_TOLERANCE 1e-9   /* |Σ cluster_weight − 1| per cell */
#define CELL_VALUE_BOUND 1e6        /* |value| of cluster_loc, cluster_scale, cluster_slope, mean, std and the work's */
#define DICTIONARY_BOUND_TOLERANCE 1e-6     /* relative, on the bound √L of a shape_dictionary knot */
#define USER_SHAPE_CODE 255         /* grid/shape_codes of a shape that is no family (data_schema.shape_records) */
#define RBS_WALL_NAME_SIZE 256      /* bytes kept of the wall's name (attribute name of group wall), with its NUL */
#define RBS_WALL_MAX_PARAMETERS 8   /* the most parameters of a wall law family (loader.c: WALL_FAMILIES) */

/* The shapes of a table as data (data_schema.shape_records: group /shapes), table order; shape_records.c reads,
 * checks and frees them. The triangles give a walked hull its vertex graph, then are freed (rbs_direct_shapes_build):
 * the runtime needs no surface. */
typedef struct rbs_shape_records {
    int8_t *kind;               /* (n) RBS_SMOOTH or RBS_POLYHEDRON */
    int *family;                /* (n) RBS_ELLIPSOID .. RBS_TETRAHEDRON, or −1 for any other shape */
    int64_t *vertex_start;      /* (n + 1) shape i's vertices are rows vertex_start[i] .. vertex_start[i+1] − 1 */
    double *vertices;           /* (vertex_start[n], 3) body frame, units of a, at b/a = c/b = 1 */
    int64_t *triangle_start;    /* (n + 1) shape i's triangles are rows triangle_start[i] .. triangle_start[i+1] − 1 */
    int32_t *triangles;         /* (triangle_start[n], 3) indices into the shape's own vertices; NULL after the load */
    double *inertia;            /* (n, 3) principal J/m, units of a² */
    double *aspect;             /* (n, 4) mean, sd, low, high of b/a and c/b; NaN row: fixed proportions */
    uint8_t *both_hands;        /* (n) 0 or 1 */
} rbs_shape_records;

struct rbs_table {
    char *path;
    int n_shapes, n_alpha1, n_speed, n_clusters, n_levels, n_dictionary, n_pieces;
    int format_major, format_minor;
    long long particles_per_cell, n_max;
    /* the wall (group wall, read by loader.c; rbs_table_wall): its family's name and parameter names (static, of
     * WALL_FAMILIES), its name, its parameters' values in the family's order, and the kernels' wall array
     * (direct_model.wall.Wall.as_array, layout W_*; zero after its own values), which holds a tabulated law's nodes */
    const char *wall_family;
    const char *const *wall_parameter_names;
    int n_wall_parameters;
    char wall_name[RBS_WALL_NAME_SIZE];
    double wall_parameters[RBS_WALL_MAX_PARAMETERS];
    double wall_speed_range[2];                     /* m/s; {0, inf}: not stated (direct_model.wall) */
    double wall_roughness;                          /* Δγ, degrees, in [0, RBS_MAX_ROUGHNESS_DEG]; 0: smooth */
    double wall[WALL_ARRAY_SIZE];
    char (*shape_names)[RBS_SHAPE_NAME_SIZE];       /* (n_shapes) names, grid/shapes */
    rbs_shape_records shapes;
    double *alpha1_deg, *speed_m_s;                 /* the grids */
    double *alpha1_axis, *speed_axis;
    size_t alpha1_axis_len, speed_axis_len;
    double *cells;
    size_t cells_len;
    float *clusters;                                /* 64-byte aligned */
    size_t clusters_len;
    float *dictionary;                              /* 64-byte aligned */
    size_t dictionary_len;
    double *speed_restitution;
    double *restitution_pieces;
    size_t restitution_pieces_len;
    int has_work;                                   /* the cells hold the work on the wall (format 4.1) */
    float *work_rows;                               /* 64-byte aligned; NULL without the work */
    size_t work_rows_len;
    float *work_dictionary;                         /* 64-byte aligned; NULL without the work */
    size_t work_dictionary_len;
    double *work_cells;                             /* NULL without the work */
    size_t work_cells_len;
    double direct_parameters[N_PARAMS];             /* surrogate.table.SurrogateTable.direct_parameters (P_*) */
    /* the direct model's shapes (surrogate.table.SurrogateTable.shape_arrays): the four families in code order,
     * from the parameters, then the table's other polyhedra in table order; model_shape[i] is the index there of the
     * table's shape i (shape_records.c: rbs_direct_shapes_build) */
    rbs_shape_arrays direct_shapes;
    int *model_shape;
};

/* The raw cell datasets a loader reads (layout.c turns them into the kernel arrays). */
typedef struct rbs_raw_cells {
    double *cluster_weight;     /* (cells, C) */
    float *cluster_loc;         /* (cells, C, 6) */
    float *cluster_scale;       /* (cells, C, 6) */
    uint8_t *cluster_shape;     /* (cells, C, 6) */
    float *cluster_slope;       /* (cells, C, 15) */
    uint8_t *cluster_regime;    /* (cells, C) */
    float *shape_dictionary;    /* (cells, 6, M, L + 1) */
    int64_t *status_counts;     /* (cells, 3) */
    double *mean;               /* (cells, 6) */
    double *std;                /* (cells, 6) */
    int64_t *collision_counts;  /* (cells, 11): read to check them and their checksums, then freed */
    float *indicatrix_2d;       /* (cells, 72): likewise */
    float *indicatrix_3d;       /* (cells, 72, 72): likewise */
    /* the work on the wall (format 4.1): all NULL for a table without it */
    float *work_loc;            /* (cells, C, 2) */
    float *work_scale;          /* (cells, C, 2) */
    uint8_t *work_shape;        /* (cells, C, 2) */
    float *work_slope;          /* (cells, C, 13) */
    float *work_dictionary;     /* (cells, 2, M, L + 1) */
    double *work_mean;          /* (cells, 2) */
    double *work_std;           /* (cells, 2) */
    double *trapped_work;       /* (cells, 2) */
} rbs_raw_cells;

/* A shape mix (rbs_mix_new_*, mix.c): the table it was made from (a mix of another table is refused), its shape
 * count and cumulative weights in the table's shape order (surrogate.mix_cdf). */
struct rbs_mix {
    const rbs_table *table;
    int n_shapes;
    double cdf[];
};

/* the cumulative weights of a mix (n_shapes of them) */
static inline const double *rbs_mix_cdf(const rbs_mix *mix)
{
    return mix->cdf;
}

/* shape_records.c: free what a table's shape records hold (rbs_shape_records_load reads them) */
void rbs_shape_records_free(rbs_shape_records *records);

/* shape_records.c: t->direct_shapes and t->model_shape from the direct parameters and the shape records
 * (surrogate.table.SurrogateTable.shape_arrays, model_shapes): RBS_OK or RBS_ERR_MEMORY; freed by
 * rbs_direct_shapes_free (which takes a table without them too). */
int rbs_direct_shapes_build(rbs_table *t);
void rbs_direct_shapes_free(rbs_table *t);

/* Φ(x), the standard normal CDF (direct_model.shapes.normal_cdf: libm's erfc, as CPython's math.erfc) */
static inline double rbs_normal_cdf(double x)
{
    return 0.5 * erfc(-x / sqrt(2.0));
}

/* layout.c: the kernel arrays of `table` (grids, sizes and direct parameters set) from the raw cells.
 * RBS_OK, RBS_ERR_MEMORY, or RBS_ERR_FORMAT with `what` set to the array that is not finite. */
int rbs_derive(rbs_table *table, const rbs_raw_cells *raw, const char **what);

/* layout.c, exposed for tests of the pieces alone; `wall` the kernels' wall array (wall.h, layout W_*) */
double *rbs_restitution_pieces(const double *grid, int n, const double *wall, int *n_pieces, size_t *len);
double rbs_restitution_factor(double V, const double *wall);

/* error.c: printf into a caller's message buffer (NULL or size 0: nothing). */
void rbs_message(char *message, size_t message_size, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* aligned allocation of `bytes` (rounded up to 64) on a 64-byte boundary; free with free() */
void *rbs_aligned_alloc(size_t bytes);

#endif /* RBS_INTERNAL_H */
