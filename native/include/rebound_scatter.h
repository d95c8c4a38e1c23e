/*
 * rebound_scatter.h: the native runtime of rebound-scatter, version 1.4.
 *
 * A C library that answers a particle's hit on a wall with its reflected state, for non-spherical particles
 * spinning or not, with the same law and the same bits as the numba kernels of the Python package `surrogate`
 * for the same uniforms. See docs/native.md; why the interface looks as it does: docs/design/c_api.md.
 *
 * Where to start
 * --------------
 * Before the loop: rbs_table_open (a table `tablegen build` wrote), a shape mix (rbs_mix_new_equal,
 * rbs_mix_new_from_shape, rbs_mix_new_from_weights) and one rbs_rng per thread. For every wall hit: fill an
 * rbs_hit and call rbs_rebound, which answers any hit, from the table where the table's law is valid (the table
 * path), from the direct model elsewhere (the direct path): surrogate.kernels.wall_hit.rebound. Many hits of
 * particles that do not spin, from the table alone: rbs_draw_many. The law in the model's own frame:
 * rbs_draw_local.
 *
 *     rbs_hit hit = RBS_HIT_INIT;           (sets hit.size; no grain key, no uniforms: set what you have)
 *     rbs_result result = RBS_RESULT_INIT;
 *     ... hit.V, hit.Omega, hit.n, hit.a = ...; hit.rng = &rng;
 *     if (rbs_rebound(table, mix, &hit, NULL, &result) == RBS_OK) ... result.V, result.Omega
 *
 * Records that grow
 * -----------------
 * Every record the library reads or writes (rbs_hit, rbs_options, rbs_result, rbs_hits, rbs_results,
 * rbs_table_info, rbs_shape_info, rbs_wall_info, rbs_grain) begins with `size_t size`, which the caller sets to
 * sizeof the record as its own header declares it (the RBS_*_INIT initialisers do). A later version of the
 * library adds fields at the end only: it reads an input record's fields only up to `size` (later fields take
 * their defaults) and writes an output record's only up to `size`. So a program built against 1.0 keeps working
 * with 1.x, and a new input or output is a new field, never a new function. A record whose size does not reach
 * the end of its last 1.0 field gives RBS_INVALID (an rbs_result that reaches its `status` gets RBS_INVALID there,
 * nothing else). A NULL rbs_options means the defaults.
 *
 * Status
 * ------
 * One status space, rbs_status: RBS_OK (0) when a call did its job (for a hit: the particle rebounded), the
 * other outcomes of a hit > 0 (RBS_TRAPPED, RBS_FAILED), every refusal < 0 (RBS_INVALID for an argument outside
 * its range, RBS_ERR_* for a file or the memory). The hits' codes equal those of surrogate (STATUS_REBOUNDED 0,
 * STATUS_TRAPPED 1, STATUS_FAILED 2, STATUS_INVALID −1). rbs_status_string names any of them.
 *
 * Frames and units
 * ----------------
 * Global frame: any right-handed Cartesian frame of the caller. V⁻ (incident velocity) and V⁺ (reflected) in m/s,
 * Ω⁻ and Ω⁺ (angular velocities) in rad/s, n the unit wall normal pointing into the gas (| |n| − 1 | <=
 * RBS_NORMAL_TOLERANCE; not normalised), a the particle's half-size (half its largest extent) in m, finite and > 0.
 * Impact frame of a hit: ex the direction of the tangential part of V⁻ (at normal impact, |V⁻_t| <= 1e-12 |V⁻|, a
 * direction in the wall plane drawn from u[12]), n, ez = ex × n. α1 = angle of V⁻ from the wall, degrees in
 * [0, 90]. Local frame (the model's lab frame): wall y = 0, normal +Y, impact plane XY,
 * V⁻ = |V⁻| (cos α1, −sin α1, 0). Local draws give α2 (rad, from the wall in the XY plane), β2 (rad, out of the
 * impact plane), s = |V⁺|/|V⁻| and Ω⁺ a/|V⁻| (dimensionless).
 *
 * Uniforms
 * --------
 * A hit consumes RBS_U_PER_DRAW = 13 uniforms in [0, 1), whatever the path (a hit given one outside, or NaN, gets
 * RBS_INVALID), so a stream stays aligned:
 *   table path:  u[0] shape from the mix   u[1] α1 neighbour   u[2] speed neighbour   u[3] trapped or not
 *                u[4] mixture component    u[5..10] the six chain variables   u[11] mirror sign
 *                u[12] in-wall axis at normal impact (the work on the wall: keyed uniforms of a hash of the 13)
 *   direct path: u[0] shape from the mix (as the table path)   u[1..3] the orientation (Shoemake's uniform
 *                quaternion)   u[4], u[5] b/a and c/b (inverse CDF of the shape's law)   u[6] the hand of a shape
 *                drawn in both hands (+1 below ½)   u[7] in-wall axis at normal impact   u[8..12] unused
 * Give them yourself (rbs_hit.u), or let the hit draw them from an rbs_rng (rbs_hit.rng; xoshiro256+, the
 * generator of surrogate.fill_uniforms).
 *
 * Threads
 * -------
 * No global mutable state. An rbs_table is immutable once opened: any number of threads may draw from one table
 * at once; likewise an rbs_mix. An rbs_rng is mutable: one per thread (or per MPI rank, per stream), e.g.
 * rbs_rng_seed_stream(&rng, seed, thread_or_rank). rbs_table_open and rbs_table_close call HDF5: call them from
 * one thread at a time unless your HDF5 is built thread-safe.
 *
 * Errors
 * ------
 * rbs_table_open and the rbs_mix_new_* functions write, when `message` is not NULL, a NUL-terminated message of at
 * most message_size bytes naming the file or the argument and what is wrong. The hit functions never fail,
 * whatever their arguments: a NULL pointer, a record too small, a uniform outside [0, 1) or NaN, a particle that
 * does not move into the wall (V·n >= 0, zero or non-finite V), a normal that is not a unit vector, a half-size
 * that is not finite and > 0, or a result that is not a finite rebound leaving the wall (V⁺·n > 0) gets status
 * RBS_INVALID and NaN outputs (a NULL output gets nothing).
 *
 * Only the names declared here are exported by the shared library.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef REBOUND_SCATTER_H
#define REBOUND_SCATTER_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__) || defined(__clang__)
#define RBS_API __attribute__((visibility("default")))
#else
#define RBS_API
#endif

#define RBS_VERSION_MAJOR 1
#define RBS_VERSION_MINOR 4
#define RBS_VERSION_PATCH 1
/* MAJOR · 1 000 000 + MINOR · 1 000 + PATCH, as rbs_version_number() returns it for the library linked */
#define RBS_VERSION_NUMBER (RBS_VERSION_MAJOR * 1000000 + RBS_VERSION_MINOR * 1000 + RBS_VERSION_PATCH)

#define RBS_TABLE_FORMAT_MAJOR 4    /* the table format read, any minor (data_schema.table.TABLE_VERSION) */
#define RBS_U_PER_DRAW 13           /* uniforms per hit (surrogate.U_PER_DRAW) */
#define RBS_TABLE_MAX_SHAPES 4096   /* the most shapes a table holds (data_schema.shape_records.MAX_TABLE_SHAPES) */
#define RBS_SHAPE_NAME_SIZE 65      /* bytes of a shape's name with its NUL (direct_model.registry.NAME_PATTERN) */
#define RBS_BLOCK 32                /* rows per block of rbs_draw_many, and its xoshiro256+ lanes */
#define RBS_LOCAL_SIZE 6            /* outputs of rbs_draw_local */
#define RBS_NORMAL_TOLERANCE 1e-6   /* | |n| − 1 | allowed for a wall normal (surrogate.kernels.frame.NORMAL_TOLERANCE) */
/* The largest |Ω⁻| a/|V⁻| the table answers under RBS_METHOD_AUTO (surrogate.SPIN_TOLERANCE): where the table's law
 * and the direct model's with that spin stay within classifier accuracy 0.52 (docs/design/spin_tolerance.md). */
#define RBS_SPIN_TOLERANCE 0.001
#define RBS_NO_KEY (-1)             /* rbs_hit.grain_key of a particle without a grain key */
#define RBS_MAX_ROUGHNESS_DEG 45.0  /* the largest wall roughness Δγ, degrees (direct_model.wall.MAX_ROUGHNESS_DEG) */
#define RBS_ROUGHNESS_OF_TABLE (-1.0)   /* rbs_options.roughness_deg: the table's wall's roughness */
#define RBS_MAX_WALL_HITS 10        /* the most facet hits of a hit (surrogate.kernels.wall_hit.MAX_WALL_HITS) */

/* ---------------------------------------------------------------- status and enumerations */

/* The one status space of every call and every hit (section "Status" above). */
typedef enum rbs_status {
    RBS_OK = 0,             /* the call did its job; a hit: the particle rebounded (V⁺ leaves the wall) */
    RBS_TRAPPED = 1,        /* a hit: still colliding after n_max collisions, or drawn trapped from the table */
    RBS_FAILED = 2,         /* a hit on the direct path: a collision solve or a contact search failed; count it */
    RBS_INVALID = -1,       /* an argument outside its range (a NULL pointer, a record too small, an unknown name
                               or method, bad weights, a hit's input out of range): NaN outputs */
    RBS_ERR_IO = -2,        /* the file does not exist or cannot be opened */
    RBS_ERR_FORMAT = -3,    /* not a readable table: not HDF5, truncated, corrupt (checksum), another file type, a
                               group, dataset or attribute missing or of the wrong shape, a non-finite value */
    RBS_ERR_VERSION = -4,   /* a table of another format major version (the message says how to rebuild it) */
    RBS_ERR_MEMORY = -5     /* out of memory */
} rbs_status;

/* Which path answers a hit (rbs_options.method; surrogate's method "auto", "table", "direct"). */
typedef enum rbs_method {
    RBS_METHOD_AUTO = 0,    /* the table where its law is valid (rbs_rebound_path), the direct model elsewhere */
    RBS_METHOD_TABLE = 1,   /* the table whatever Ω⁻ (outside the grid, the law at the nearest grid edge) */
    RBS_METHOD_DIRECT = 2   /* the direct model for every hit */
} rbs_method;

/* The path that answered a hit (rbs_result.path, rbs_rebound_path). */
typedef enum rbs_path { RBS_PATH_NONE = -1, RBS_PATH_TABLE = 0, RBS_PATH_DIRECT = 1 } rbs_path;

/* Interpolation between the table's grid points (rbs_options.interpolation; surrogate's `interpolation`). */
typedef enum rbs_interpolation {
    RBS_INTERPOLATION_SCALED = 0,       /* a neighbour's cell drawn with its weight, then moved to the incident α1
                                           (interpolated means and sds) and |V⁻| (wall restitution law) */
    RBS_INTERPOLATION_STOCHASTIC = 1    /* the neighbour's law as is */
} rbs_interpolation;

/* The paper's four shape families (rbs_shape_info.family; direct_model.shapes.SHAPES order). */
typedef enum rbs_family {
    RBS_FAMILY_NONE = -1,   /* any other shape: a user's grain */
    RBS_FAMILY_ELLIPSOID = 0, RBS_FAMILY_PRISM = 1, RBS_FAMILY_CUT_PRISM = 2, RBS_FAMILY_TETRAHEDRON = 3
} rbs_family;

/* Kinds of a shape (rbs_shape_info.kind; data_schema.shape_records.KIND_SMOOTH, KIND_POLYHEDRON). */
typedef enum rbs_kind { RBS_KIND_SMOOTH = 0, RBS_KIND_POLYHEDRON = 1 } rbs_kind;

/* Element types of rbs_table_kernel_array. */
typedef enum rbs_dtype { RBS_DTYPE_FLOAT64 = 0, RBS_DTYPE_FLOAT32 = 1 } rbs_dtype;

/* ---------------------------------------------------------------- opaque handles and the generator */

/* A loaded table: opaque, immutable after rbs_table_open, shareable by threads. */
typedef struct rbs_table rbs_table;

/* A shape mix of one table (cumulative weights in its shape order; surrogate.mix_cdf): opaque, made by rbs_mix_new_*,
 * freed by rbs_mix_free, read only by the draws (threads may share it). A mix belongs to the table it was made from. */
typedef struct rbs_mix rbs_mix;

/* One xoshiro256+ state (four 64-bit words, not all zero): one per thread / MPI rank / stream, owned by the caller. */
typedef struct rbs_rng {
    uint64_t s[4];
} rbs_rng;

/* ---------------------------------------------------------------- records of a hit */

/* One hit, global frame. */
typedef struct rbs_hit {
    size_t size;            /* sizeof(rbs_hit) */
    double V[3];            /* incident velocity V⁻, m/s (finite, must move into the wall: V·n < 0) */
    double Omega[3];        /* incident angular velocity Ω⁻, rad/s (finite); exactly zero: the body starts touching
                               the wall (the tables' case), otherwise the flight in from a clear start is simulated */
    double n[3];            /* unit wall normal into the gas (| |n| − 1 | <= RBS_NORMAL_TOLERANCE) */
    double a;               /* half-size (half the largest extent), m (finite, > 0) */
    int64_t grain_key;      /* RBS_NO_KEY, or the particle's grain key >= 0 (rbs_grain_key; section "Grain keys") */
    const double *u;        /* RBS_U_PER_DRAW uniforms in [0, 1), or NULL: drawn from rng */
    rbs_rng *rng;           /* where u is NULL: advanced by RBS_U_PER_DRAW uniforms whatever the path and result; a
                               NULL or all-zero rng gives RBS_INVALID */
} rbs_hit;
#define RBS_HIT_INIT {sizeof(rbs_hit), {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, 0.0, RBS_NO_KEY, NULL, NULL}

/* How hits are answered (NULL: these defaults). */
typedef struct rbs_options {
    size_t size;            /* sizeof(rbs_options) */
    int method;             /* rbs_method; RBS_METHOD_AUTO */
    int interpolation;      /* rbs_interpolation of the table path; RBS_INTERPOLATION_SCALED */
    /* since 1.2: the wall's roughness Δγ, degrees (rbs_rebound, "Rough walls"): < 0 (the default,
       RBS_ROUGHNESS_OF_TABLE; also a record too small to hold it) the table's wall's (rbs_wall_info.roughness_deg),
       0 a smooth wall, (0, RBS_MAX_ROUGHNESS_DEG] a rough one; NaN or above RBS_MAX_ROUGHNESS_DEG: RBS_INVALID */
    double roughness_deg;
} rbs_options;
#define RBS_OPTIONS_INIT {sizeof(rbs_options), RBS_METHOD_AUTO, RBS_INTERPOLATION_SCALED, RBS_ROUGHNESS_OF_TABLE}

/* What a hit did (written up to its size; NaN vectors unless the status is RBS_OK). */
typedef struct rbs_result {
    size_t size;            /* sizeof(rbs_result) */
    int status;             /* rbs_status of the hit, also returned by rbs_rebound */
    int path;               /* rbs_path that answered it; RBS_PATH_NONE for RBS_INVALID */
    int shape;              /* the table's shape index of the particle (drawn from the mix or fixed by its key);
                               −1 for RBS_INVALID */
    int n_collisions;       /* direct path: collisions of the rebound (up to the trap); table path: −1 */
    double V[3];            /* reflected velocity V⁺, m/s, global frame */
    double Omega[3];        /* reflected angular velocity Ω⁺, rad/s, global frame */
    int wall_hits;          /* since 1.2: the hits on the wall this hit took: 1 on a smooth wall, 1 to RBS_MAX_WALL_HITS
                               on a rough one (its facet hits); 0 for RBS_INVALID */
    /* since 1.3: what the hit did to the wall (docs/model.md §4.7), the work of its collisions on the wall per unit
       particle mass, m²/s² (J/kg), each >= 0; their sum is the particle's loss of translational plus rotational
       kinetic energy. The direct path's from its collisions (up to the trap or the failure); since 1.4 the table
       path's too, drawn jointly with the rebound (a trapped draw: its cell's trapped particles' mean); on a rough
       wall summed over the facet hits. NaN from a table of format 4.0, which does not hold them (on a rough wall: if
       such a table answered any facet hit), and for RBS_INVALID */
    double wall_work_normal;        /* W_n: the normal impulses' work (plastic indentation) */
    double wall_work_tangential;    /* W_t: the tangential impulses' work (cutting, the erosion of ductile walls) */
} rbs_result;
#define RBS_RESULT_INIT {sizeof(rbs_result), RBS_INVALID, RBS_PATH_NONE, -1, -1, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, 0, \
                         0.0, 0.0}

/* ---------------------------------------------------------------- every wall hit: call this first */

/* The reflected state of one particle hitting the wall, spinning or not, global frame
 * (surrogate.kernels.wall_hit.rebound): the path rbs_rebound_path gives, then
 *   RBS_PATH_TABLE   the table's law (surrogate.kernels.table_path.table_rebound; Ω⁻ unused);
 *   RBS_PATH_DIRECT  the shape drawn from the mix with u[0] as the table path draws it, then the direct model
 *                    (surrogate.kernels.direct_path.direct_rebound) with u[1..8] as its uniforms, in the impact
 *                    frame, with the parameters the table was built with (its wall, shapes, n_max, tolerances).
 * A hit with a grain key (hit->grain_key >= 0) keeps its grain: u[0] (the shape) is replaced by the key's uniform
 * on either path and, on the direct path, u[4], u[5] (b/a, c/b) and u[6] (the hand) by the key's; the hit still
 * takes RBS_U_PER_DRAW uniforms, all checked. Writes *result up to result->size and returns result->status:
 * RBS_OK, RBS_TRAPPED, RBS_FAILED or RBS_INVALID (a NULL table, mix, hit or result, a mix of another table, a
 * record too small, an unknown method or interpolation, a roughness out of range, a hit's input out of range). The
 * direct path costs microseconds, the table path a fraction of one. Thread-safe.
 *
 * Rough walls (docs/model.md §12; surrogate.kernels.wall_hit.rough_rebound): with a roughness Δγ > 0 (the table's
 * wall's, or options->roughness_deg) the particle lands on a facet, the mean wall (normal n) tilted by Gaussian
 * angles of sd Δγ in the impact frame, drawn as seen along V⁻ (the shadow effect; surrogate.kernels.facet). The
 * facet hit is answered along its own path (as above, with the facet's normal and options->method); if its rebound
 * still moves into the mean wall (V⁺·n <= 0), that rebound hits another facet with its V⁺ and Ω⁺ and the same
 * shape, up to RBS_MAX_WALL_HITS facet hits, after which the hit is RBS_TRAPPED. The first facet hit takes the
 * hit's uniforms; the facets and every later facet hit take keyed uniforms of a hash of them, so a hit never takes
 * more than RBS_U_PER_DRAW uniforms of a stream. result->wall_hits counts the facet hits; path and n_collisions are
 * the last one's, the wall work the sum of theirs; a facet not found (probability below 1e-14) gives RBS_FAILED.
 * Roughness 0 is the smooth wall, bit for bit. */
RBS_API int rbs_rebound(const rbs_table *table, const rbs_mix *mix, const rbs_hit *hit, const rbs_options *options,
                        rbs_result *result);

/* The path that answers `hit` under options->method (surrogate.kernels.wall_hit.rebound_path), without drawing
 * (hit->u, hit->rng and hit->grain_key are not read). Under RBS_METHOD_AUTO, the table iff |Ω⁻| a/|V⁻| <=
 * RBS_SPIN_TOLERANCE (Ω⁻ = 0 included), and α1 and |V⁻| lie in the table's grid ranges, edges included; else the
 * direct model. RBS_PATH_TABLE or RBS_PATH_DIRECT; RBS_PATH_NONE for an argument rbs_rebound refuses. On a rough
 * wall, the path of a hit on the mean wall (each facet hit of rbs_rebound takes its own). */
RBS_API int rbs_rebound_path(const rbs_table *table, const rbs_hit *hit, const rbs_options *options);

/* ---------------------------------------------------------------- many hits from the table */

/* `count` hits of particles that do not spin, each row answered by the table path (Ω⁻ = 0, grain keys not used):
 * arrays row-major, the outputs must not overlap the inputs. */
typedef struct rbs_hits {
    size_t size;            /* sizeof(rbs_hits) */
    size_t count;           /* rows */
    const double *V;        /* (count, 3) V⁻, m/s */
    const double *n;        /* (count, 3) unit wall normals */
    const double *a;        /* (count) half-sizes, m */
    const double *u;        /* (count, RBS_U_PER_DRAW) uniforms, or NULL: drawn from rng as rbs_draw_many_uniforms */
    rbs_rng *rng;           /* where u is NULL */
} rbs_hits;
#define RBS_HITS_INIT {sizeof(rbs_hits), 0, NULL, NULL, NULL, NULL, NULL}

typedef struct rbs_results {
    size_t size;            /* sizeof(rbs_results) */
    double *V;              /* (count, 3) V⁺, m/s */
    double *Omega;          /* (count, 3) Ω⁺, rad/s */
    signed char *status;    /* (count) rbs_status of each row */
} rbs_results;
#define RBS_RESULTS_INIT {sizeof(rbs_results), NULL, NULL, NULL}

/* Every row of `hits` by the table path, one thread (surrogate.kernels.pipeline.table_rebound_many, with u given,
 * table_rebound_many_rng with rng): the same bits as rbs_rebound with RBS_METHOD_TABLE row by row for the same
 * uniforms; faster, because the table reads of RBS_BLOCK rows are in flight together and the arithmetic runs as
 * SIMD loops over them. With rng, it is advanced one step to seed RBS_BLOCK xoshiro256+ lanes (splitmix64), and row
 * b of every block of RBS_BLOCK rows takes its uniforms from lane b. options->method must be RBS_METHOD_AUTO or
 * RBS_METHOD_TABLE. Returns RBS_OK; or RBS_INVALID, every row RBS_INVALID and NaN (in the outputs that are not
 * NULL) and rng not advanced, for a NULL table, mix, hits or results, an array NULL with count > 0, a mix of
 * another table, a record too small, RBS_METHOD_DIRECT or an unknown interpolation, a NULL or all-zero rng, a
 * rough wall (a roughness other than 0, options->roughness_deg or the table's: the smooth wall only; rbs_rebound
 * answers a rough wall's hits). */
RBS_API int rbs_draw_many(const rbs_table *table, const rbs_mix *mix, const rbs_hits *hits, const rbs_options *options,
                          rbs_results *results);

/* The (count, RBS_U_PER_DRAW) uniforms rbs_draw_many draws for count rows from rng, advancing rng as it does
 * (surrogate.kernels.pipeline.table_rebound_uniforms); NaN for a NULL or all-zero state. */
RBS_API void rbs_draw_many_uniforms(rbs_rng *rng, size_t count, double *u);

/* One reflected state at (α1 deg, |V⁻| m/s) in the local frame (surrogate.kernels.table_path.draw_local):
 * out = (α2 rad, β2 rad, s = |V⁺|/|V⁻|, Ω_x, Ω_y, Ω_z in units of |V⁻|/a), NaN unless rebounded. Returns RBS_OK or
 * RBS_TRAPPED; RBS_INVALID for α1 outside (0, 90] or NaN, |V⁻| not finite and > 0, a uniform outside [0, 1), a NULL
 * pointer, a mix of another table, an unknown interpolation. Outside the grid (however far), the law at the nearest
 * grid edge. options->method and options->roughness_deg are not read. */
RBS_API int rbs_draw_local(const rbs_table *table, const rbs_mix *mix, double alpha1_deg, double speed_m_s,
                           const double u[RBS_U_PER_DRAW], const rbs_options *options, double out[RBS_LOCAL_SIZE]);

/* ---------------------------------------------------------------- tables */

/* Open and check a table file, derive the kernel arrays; *table = NULL on error. Checks what
 * data_schema.table.read_table checks (docs/format.md "What makes a table valid"; one verdict with Python on every
 * table). A table of another format (one written before version 1.0) gives RBS_ERR_VERSION with a message naming
 * its format and the commands that rebuild it from the configuration it stores. Returns RBS_OK, RBS_ERR_IO,
 * RBS_ERR_FORMAT, RBS_ERR_VERSION, RBS_ERR_MEMORY or RBS_INVALID (a NULL path or table). */
RBS_API int rbs_table_open(const char *path, rbs_table **table, char *message, size_t message_size);

/* Free everything the table holds (NULL: nothing). No draw may use it, or a mix made from it, afterwards. */
RBS_API void rbs_table_close(rbs_table *table);

/* The path the table was opened from. */
RBS_API const char *rbs_table_path(const rbs_table *table);

/* Sizes, grids' ranges and provenance of a table. */
typedef struct rbs_table_info {
    size_t size;                        /* sizeof(rbs_table_info) */
    int n_shapes, n_alpha1, n_speed;    /* cell (shape, i_α1, i_speed) is number (shape·n_alpha1 + i_α1)·n_speed + i_speed */
    int n_clusters;                     /* mixture components per cell (C) */
    int n_levels;                       /* L + 1 quantile levels of a residual shape */
    int n_dictionary;                   /* M residual shapes per chain variable and cell */
    int n_pieces;                       /* restitution polynomial pieces per speed interval */
    int format_major, format_minor;     /* the file's table format version */
    long long particles_per_cell, n_max;
    double alpha1_min_deg, alpha1_max_deg;  /* the α1 grid's first and last points */
    double speed_min_m_s, speed_max_m_s;    /* the |V⁻| grid's first and last points */
    size_t kernel_bytes;                /* bytes held by the kernel arrays */
} rbs_table_info;
#define RBS_TABLE_INFO_INIT {sizeof(rbs_table_info), 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.0, 0.0, 0.0, 0.0, 0}

/* *info up to info->size. RBS_OK, or RBS_INVALID for a NULL pointer or a record too small. */
RBS_API int rbs_table_info_get(const rbs_table *table, rbs_table_info *info);

/* The grids themselves: *count points, the pointer valid until rbs_table_close. */
RBS_API const double *rbs_table_alpha1_grid(const rbs_table *table, int *count);
RBS_API const double *rbs_table_speed_grid(const rbs_table *table, int *count);

/* Number of shapes and the name of shape i (table order; NULL if i is out of range). */
RBS_API int rbs_table_n_shapes(const rbs_table *table);
RBS_API const char *rbs_table_shape_name(const rbs_table *table, int i);

/* One shape of a table, in the body frame (centre of mass at the origin, principal axes of inertia along ξ, η, ζ)
 * and units of a (the largest half-extent along a principal axis), at b/a = c/b = 1. */
typedef struct rbs_shape_info {
    size_t size;                /* sizeof(rbs_shape_info) */
    const char *name;           /* valid until rbs_table_close */
    int kind;                   /* rbs_kind */
    int family;                 /* rbs_family: the paper's four, RBS_FAMILY_NONE for any other shape */
    int n_vertices;             /* hull vertices, 0 for a smooth body */
    const double *vertices;     /* n_vertices × 3, row-major, valid until rbs_table_close; NULL if none */
    double inertia[3];          /* principal J/m along ξ, η, ζ, units of a² */
    double aspect[4];           /* the law of b/a and c/b: mean, sd, low, high; NaN: fixed proportions */
    int both_hands;             /* 1: half of the particles are the mirror image (ζ → −ζ) */
} rbs_shape_info;
#define RBS_SHAPE_INFO_INIT {sizeof(rbs_shape_info), NULL, 0, 0, 0, NULL, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0, 0.0}, 0}

/* The record of shape i (group /shapes). RBS_OK, or RBS_INVALID for a NULL pointer, a record too small or i out
 * of range. */
RBS_API int rbs_table_shape_info(const rbs_table *table, int i, rbs_shape_info *info);

/* The wall of a table (group /wall; docs/model.md §10, §12): its law family, named parameters and arrays, and its
 * roughness, as the build's [wall] section gave them. The fields after speed_range_m_s came after 1.0: written only
 * where the caller's record reaches them (its size). Every pointer is valid until rbs_table_close. */
typedef struct rbs_wall_info {
    size_t size;                /* sizeof(rbs_wall_info) */
    const char *family;         /* the law family, "exponential" or "tabulated" */
    const char *name;           /* the wall's name (the pair of materials), "" if none */
    int n_parameters;
    const char *const *parameter_names;     /* n_parameters names: "k", "p", "q" (exponential), "q" (tabulated) */
    const double *parameter_values;         /* their values, in the family's units (docs/model.md §10) */
    double speed_range_m_s[2];  /* the incident speeds |V⁻| (m/s) the law was measured or fitted over, low < high;
                                   {0, INFINITY}: not stated. Hits outside it are answered with the law all the
                                   same: count them (the adapters' summaries do) */
    /* the tabulated family's nodes and a_nc (0 and NULL for the exponential family): a_nc bilinear between them */
    int n_contact_speeds;                   /* 1 to 16 */
    const double *contact_speed_m_s;        /* the contact-point speeds |V_c⁻| (m/s), increasing, > 0 */
    int n_contact_sines;                    /* 2 to 16 */
    const double *contact_sine;             /* the sines |v_c⁻|/|V_c⁻| of the impact angle, increasing from 0 to 1 */
    const double *restitution;              /* a_nc at the nodes, in (0, 1], row-major: n_contact_speeds rows of
                                               n_contact_sines values */
    double roughness_deg;                   /* since 1.2: the wall's roughness Δγ, degrees, in
                                               [0, RBS_MAX_ROUGHNESS_DEG]; 0: a smooth wall (a table without it) */
} rbs_wall_info;
#define RBS_WALL_INFO_INIT {sizeof(rbs_wall_info), NULL, NULL, 0, NULL, NULL, {0.0, 0.0}, 0, NULL, 0, NULL, NULL, 0.0}

/* *info up to info->size. RBS_OK, or RBS_INVALID for a NULL pointer or a record too small. */
RBS_API int rbs_table_wall(const rbs_table *table, rbs_wall_info *info);

/* A derived kernel array, equal element for element to the field of surrogate's table.kernel_data of the same
 * name: "alpha1_axis", "speed_axis", "cells", "speed_restitution", "restitution_pieces" (float64), "clusters",
 * "dictionary" (float32); since 1.4 the work on the wall's "work_rows", "work_dictionary" (float32) and
 * "work_cells" (float64), of count 0 for a table of format 4.0; or "direct_parameters" (float64), equal to
 * surrogate's table.direct_parameters.
 * *data points into the table (read-only, valid until rbs_table_close), *count is its number of elements, *dtype
 * an rbs_dtype (any of the three output pointers may be NULL). RBS_OK or RBS_INVALID (unknown name). */
RBS_API int rbs_table_kernel_array(const rbs_table *table, const char *name, const void **data, size_t *count,
                                   int *dtype);

/* ---------------------------------------------------------------- shape mixes */

/* rbs_mix_new_from_weights: named weights (surrogate.mix_cdf with a dict): names of the table's shapes, each at
 * most once; weights finite and >= 0, summing to 1 within 1e-9 (summed in the order given). Shapes not named get
 * weight 0. rbs_mix_new_from_shape: one shape alone (surrogate.mix_cdf(table, name)); "mix" gives the equal mix.
 * rbs_mix_new_equal: equal weights over the table's shapes (surrogate.mix_cdf(table, "mix")). Each returns the
 * mix, or NULL with a message (a bad argument, out of memory). */
RBS_API rbs_mix *rbs_mix_new_from_weights(const rbs_table *table, int n, const char *const names[],
                                          const double weights[], char *message, size_t message_size);
RBS_API rbs_mix *rbs_mix_new_from_shape(const rbs_table *table, const char *name, char *message,
                                        size_t message_size);
RBS_API rbs_mix *rbs_mix_new_equal(const rbs_table *table);

/* Free a mix (NULL: nothing). */
RBS_API void rbs_mix_free(rbs_mix *mix);

/* ---------------------------------------------------------------- grain keys */

/* A grain key: an int64 >= 0 per particle, its own for life (rbs_grain_key derives one from a seed and the
 * particle's ids), so that the particle hits every wall as the same grain (surrogate.kernels.grain). The random
 * properties of the grain are pure functions of (key, the shape mix): the shape from the mix, and, for a shape of
 * random proportions, b/a and c/b, and for a shape drawn in both hands, its hand; each is drawn from a uniform of
 * the key (splitmix64 of the key and the property's slot) instead of from u. Everything else (the orientation at
 * impact, the table's law, the impact frame) stays random per hit. Under the table path a key fixes the shape
 * only (the table holds each shape's law over its proportions and hands); under the direct path it fixes the
 * shape, the proportions and the hand. */

/* One grain of a table's mix (rbs_grain_info). */
typedef struct rbs_grain {
    size_t size;            /* sizeof(rbs_grain) */
    int shape;              /* the table's shape index (rbs_table_shape_name gives its name) */
    double ratio_ba;        /* b/a and c/b the direct path gives this grain on every hit; NaN for a shape of */
    double ratio_cb;        /*   fixed proportions (the table path: the shape's law) */
    double hand;            /* +1 or −1 (the mirror image) on the direct path; NaN for a shape of one hand */
} rbs_grain;
#define RBS_GRAIN_INIT {sizeof(rbs_grain), -1, 0.0, 0.0, 0.0}

/* The grain of key `key` in the mix of `table` (surrogate.grain_of): RBS_OK, or RBS_INVALID (nothing written) for
 * a NULL pointer, a mix of another table, a record too small or key < 0. */
RBS_API int rbs_grain_info(const rbs_table *table, const rbs_mix *mix, int64_t key, rbs_grain *grain);

/* A grain key from a seed and two ids, e.g. (the run's seed, the rank a particle was born on, its number there):
 * splitmix64 chained, the top bit cleared, so a key >= 0 (surrogate.grain_key with the same numbers). The same
 * numbers give the same key on every machine, rank count and run. */
RBS_API int64_t rbs_grain_key(uint64_t seed, uint64_t id1, uint64_t id2);

/* ---------------------------------------------------------------- random numbers */

/* The state surrogate.seed_state(seed) gives (numpy's SeedSequence(seed).spawn(1)[0], 4 uint64 words, never all
 * zero). A NULL rng: nothing. */
RBS_API void rbs_rng_seed(rbs_rng *rng, uint64_t seed);

/* The state surrogate.seed_state(seed, n_streams=n)[k] gives, for any n > k: stream k of a seed (SeedSequence(seed)
 * child k). Use k = thread number or MPI rank. */
RBS_API void rbs_rng_seed_stream(rbs_rng *rng, uint64_t seed, uint64_t k);

/* The next uniform in [0, 1) (53 bits; surrogate.kernels.rng.next_uniform); NaN for a NULL or all-zero state (not a
 * xoshiro256+ state: it would give 0 forever), which every hit refuses. */
RBS_API double rbs_rng_uniform(rbs_rng *rng);

/* u[0..count) = the next count uniforms (surrogate.fill_uniforms); NaN for a NULL or all-zero state. */
RBS_API void rbs_rng_fill(rbs_rng *rng, double *u, size_t count);

/* ---------------------------------------------------------------- the library */

/* A static description of a status (any rbs_status; "unknown status" otherwise). */
RBS_API const char *rbs_status_string(int status);

/* The library's version, "MAJOR.MINOR.PATCH", and as a number (RBS_VERSION_NUMBER of the library linked, which a
 * program compares with the RBS_VERSION_NUMBER of the header it was built with). */
RBS_API const char *rbs_version(void);
RBS_API int rbs_version_number(void);

#ifdef __cplusplus
}
#endif

#endif /* REBOUND_SCATTER_H */
