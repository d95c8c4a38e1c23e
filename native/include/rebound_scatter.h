/*
 * rebound_scatter.h: the native runtime of rebound-scatter.
 *
 * A C library that answers a particle's hit on a wall with its reflected state, for non-spherical
 * particles spinning or not, with the same law and the same bits as the numba kernels of the Python
 * package `surrogate` for the same uniforms. See docs/native.md.
 *
 * Where to start
 * --------------
 * A solver calls rbs_rebound (uniforms given) or rbs_rebound_rng (uniforms from an rbs_rng) for every
 * wall hit: it answers any hit, from the table where the table's law is valid (the table path), from the
 * direct model elsewhere (the direct path), per particle (surrogate.kernels.wall_hit.rebound). Before
 * the loop: rbs_table_open (a table `tablegen build` wrote, format 3.x, docs/format.md), a shape mix
 * (rbs_mix_new_equal, rbs_mix_new_from_shape, rbs_mix_new_from_weights; "Shape mixes" below) and one rbs_rng per
 * thread.
 * Each path can also be called alone: the table path rbs_table_rebound
 * (surrogate.kernels.table_path.table_rebound), its many-particle forms rbs_table_rebound_many and
 * rbs_table_rebound_many_rng (surrogate.kernels.pipeline), rbs_draw_local; the direct path
 * rbs_direct_rebound (surrogate.kernels.direct_path.direct_rebound).
 *
 * One naming rule: no suffix, the uniforms are given; _rng, they are drawn from an rbs_rng. One argument
 * order: table, the mix or the shape, V, Omega, n, a, the uniforms or the rng, then options and outputs.
 * Version 1.0 renamed the draws of 0.x; rbs_rebound_spin and rbs_rebound_path keep working with their 0.x
 * arguments (end of this header). Version 1.1 reads tables of any number of shapes (format 3.4: the families and
 * the user's own grains, each stored as data; rbs_table_shape_info) and adds the mixes sized by the table
 * (rbs_mix_new_*); every 1.0 program compiles and runs unchanged on tables of at most 4 shapes. Version 1.2 adds
 * grain keys (rbs_rebound_grain, "Grain keys" below): a particle that keeps its grain from one hit to the next;
 * every 1.0 and 1.1 call keeps its arguments and its bits.
 *
 * Frames and units
 * ----------------
 * Global frame: any right-handed Cartesian frame of the caller. V⁻ (incident
 * velocity) and V⁺ (reflected) in m/s, Ω⁺ (reflected angular velocity) in
 * rad/s, n the unit wall normal pointing into the gas (| |n| − 1 | <=
 * RBS_NORMAL_TOLERANCE; not normalised), a the particle's half-size (half its
 * largest extent) in m, finite and > 0.
 * Impact frame of a hit: ex the direction of the tangential part of V⁻ (at
 * normal impact, |V⁻_t| <= 1e-12 |V⁻|, a direction in the wall plane drawn
 * from u[12]), n, ez = ex × n. α1 = angle of V⁻ from the wall, degrees in
 * [0, 90].
 * Local frame (the model's lab frame): wall y = 0, normal +Y, impact plane XY,
 * V⁻ = |V⁻| (cos α1, −sin α1, 0). Local draws give α2 (rad, from the wall
 * in the XY plane), β2 (rad, out of the impact plane), s = |V⁺|/|V⁻| and
 * Ω⁺ a/|V⁻| (dimensionless).
 *
 * Uniforms
 * --------
 * A draw consumes RBS_U_PER_DRAW = 13 uniforms in [0, 1) (a draw given one
 * outside, or NaN, returns RBS_INVALID):
 *   u[0] shape from the mix       u[1] α1 neighbour        u[2] speed neighbour
 *   u[3] trapped or not           u[4] mixture component   u[5..10] the six chain variables
 *   u[11] mirror sign             u[12] in-wall axis at normal impact
 * Give them yourself, or draw them with rbs_rng_fill from an rbs_rng
 * (xoshiro256+, the generator of surrogate.fill_uniforms).
 *
 * Threads
 * -------
 * No global mutable state. An rbs_table is immutable once opened: any number
 * of threads may draw from one table at once. An rbs_mix is read only by the draws: threads may share one.
 * An rbs_rng is mutable: one per thread (or per MPI rank, per stream), e.g.
 * rbs_rng_seed_stream(&rng, seed, thread_or_rank). rbs_table_open and
 * rbs_table_close call HDF5: call them from one thread at a time unless your
 * HDF5 is built thread-safe.
 *
 * Errors
 * ------
 * Functions that can fail return an RBS_ERR_* code (RBS_OK = 0) and, when
 * `message` is not NULL, write a NUL-terminated message of at most
 * message_size bytes naming the file and what is wrong. The draw functions
 * never fail, whatever their arguments: a NULL pointer, a uniform outside
 * [0, 1) or NaN, a particle that does not move into the wall (V·n >= 0, zero
 * or non-finite V), a normal that is not a unit vector, a half-size that is
 * not finite and > 0, or a result that is not a finite rebound leaving the
 * wall (V⁺·n > 0; what overflows or underflows at extreme |V⁻| or a) gets
 * status RBS_INVALID and NaN outputs (a NULL output gets nothing). An α1 or
 * |V⁻| outside the table's grid, however far, uses the law at the nearest grid
 * edge (check rbs_table_alpha1_range / rbs_table_speed_range beforehand if that
 * matters).
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

#define RBS_VERSION_MAJOR 1
#define RBS_VERSION_MINOR 2
#define RBS_VERSION_PATCH 0

#define RBS_U_PER_DRAW 13       /* uniforms per draw (surrogate.U_PER_DRAW) */
#define RBS_MAX_SHAPES 4        /* the shapes an rbs_mix value holds (1.0's mix); a table may hold more ("Shape mixes") */
#define RBS_TABLE_MAX_SHAPES 4096   /* the most shapes a table holds (data_schema.shape_records.MAX_TABLE_SHAPES) */
#define RBS_SHAPE_NAME_SIZE 65  /* bytes of a shape's name with its NUL (direct_model.registry.NAME_PATTERN, 64 at most) */
#define RBS_TABLE_MAJOR 3       /* the table format major version read (any minor) */
#define RBS_BLOCK 32            /* rows per block of rbs_table_rebound_many*, lanes of rbs_table_rebound_many_rng */
#define RBS_LOCAL_SIZE 6        /* outputs of rbs_draw_local */
#define RBS_NORMAL_TOLERANCE 1e-6   /* | |n| − 1 | allowed for a wall normal (surrogate.kernels.frame.NORMAL_TOLERANCE) */
#define RBS_U_PER_REBOUND 7     /* uniforms of one direct-model rebound (direct_model.runtime.U_PER_REBOUND) */

/* Status of a draw: the codes of surrogate (STATUS_REBOUNDED, STATUS_TRAPPED, STATUS_FAILED, STATUS_INVALID).
 * RBS_FAILED comes from the direct model only (rbs_direct_rebound): a collision solve or a contact search
 * failed; count and report it, never drop it. */
enum { RBS_REBOUNDED = 0, RBS_TRAPPED = 1, RBS_FAILED = 2, RBS_INVALID = -1 };

/* Shape codes of the direct model, its four built-in families (direct_model.shapes.SHAPES order; a table's own
 * shape order may differ). */
enum { RBS_ELLIPSOID = 0, RBS_PRISM = 1, RBS_CUT_PRISM = 2, RBS_TETRAHEDRON = 3 };

/* Kinds of a shape (rbs_shape_info.kind; data_schema.shape_records.KIND_SMOOTH, KIND_POLYHEDRON). */
enum { RBS_SMOOTH = 0, RBS_POLYHEDRON = 1 };

/* Error codes. */
enum {
    RBS_OK = 0,
    RBS_ERR_IO = 1,         /* the file does not exist or cannot be opened */
    RBS_ERR_FORMAT = 2,     /* not a readable table: not HDF5, truncated, corrupt (checksum), another file
                               type, a group, dataset or attribute missing or of the wrong shape, a
                               non-finite value */
    RBS_ERR_VERSION = 3,    /* a table of another major format version */
    RBS_ERR_ARGUMENT = 4,   /* a bad argument (NULL pointer, unknown shape name, bad weights, ...) */
    RBS_ERR_MEMORY = 5      /* out of memory */
};

/* Interpolation between grid points (surrogate's `interpolation` / the kernels' `scaled`). */
enum {
    RBS_SCALED = 0,         /* a neighbour's cell drawn with its weight, then moved to the incident α1
                               (interpolated means and sds) and |V⁻| (wall restitution law): the default */
    RBS_STOCHASTIC = 1      /* the neighbour's law as is */
};

/* Element types of rbs_table_kernel_array. */
enum { RBS_FLOAT64 = 0, RBS_FLOAT32 = 1 };

/* A loaded table: opaque, immutable after rbs_table_open, shareable by threads. */
typedef struct rbs_table rbs_table;

/* Cumulative shape weights in the table's shape order (cdf[n_shapes - 1] = 1): surrogate.mix_cdf.
 * Two ways to hold one (section "Shape mixes"): a value of this type that the caller owns (1.0's way; tables of at
 * most RBS_MAX_SHAPES shapes), or a pointer from rbs_mix_new_* (any table; free it with rbs_mix_free). The draws
 * take either as `const rbs_mix *`. A mix of more than RBS_MAX_SHAPES shapes is longer than this struct: use it
 * through its pointer only, never copy *mix (the copy would lose the weights past the fourth). */
typedef struct rbs_mix {
    int n_shapes;
    double cdf[RBS_MAX_SHAPES];
} rbs_mix;

/* One shape of a table (rbs_table_shape_info), in the body frame (centre of mass at the origin, principal axes of
 * inertia along ξ, η, ζ) and units of a (the largest half-extent along a principal axis), at b/a = c/b = 1. */
typedef struct rbs_shape_info {
    const char *name;           /* valid until rbs_table_close */
    int kind;                   /* RBS_SMOOTH (the ellipsoid) or RBS_POLYHEDRON */
    int family;                 /* RBS_ELLIPSOID .. RBS_TETRAHEDRON for the paper's four families, −1 for any other
                                 * shape (a user's grain, a family added to the registry after them) */
    int n_vertices;             /* hull vertices (4 to 256), 0 for a smooth body */
    const double *vertices;     /* n_vertices × 3, row-major, valid until rbs_table_close; NULL if none */
    double inertia[3];          /* principal J/m along ξ, η, ζ, units of a² */
    double aspect[4];           /* the law of b/a and c/b: mean, sd, low, high; NaN: fixed proportions */
    int both_hands;             /* 1: half of the particles are the mirror image (ζ → −ζ) */
    int direct_shape;           /* its `shape` for rbs_direct_rebound: the family's code, 4 + k for the table's
                                 * k-th other polyhedron; −1 for a table without the direct model's parameters */
} rbs_shape_info;

/* One xoshiro256+ state (four 64-bit words, not all zero): one per thread / MPI rank / stream. */
typedef struct rbs_rng {
    uint64_t s[4];
} rbs_rng;

/* Sizes and provenance of a table (rbs_table_info). */
typedef struct rbs_table_info {
    int n_shapes, n_alpha1, n_speed;    /* cell (shape, i_α1, i_speed) is number (shape·n_alpha1 + i_α1)·n_speed + i_speed */
    int n_clusters;                     /* mixture components per cell (C) */
    int n_levels;                       /* L + 1 quantile levels of a residual shape */
    int n_dictionary;                   /* M residual shapes per chain variable and cell */
    int n_pieces;                       /* restitution polynomial pieces per speed interval */
    int format_major, format_minor;     /* the file's table format version */
    long long particles_per_cell, n_max;
    double restitution_k;               /* the wall law exp(−k V^p) of the table, (m/s)^(−p) */
    double restitution_p;
    size_t kernel_bytes;                /* bytes held by the kernel arrays */
} rbs_table_info;

/* ---------------------------------------------------------------- tables */

/* Open and check a table file, derive the kernel arrays; *table = NULL on error.
 * Checks what data_schema.table.read_table checks, the whole of docs/format.md "What makes a table
 * valid": the file is a regular HDF5 file, file_type "rebound_table", format_version (3, any minor), the
 * groups, datasets (every one read, so every checksum verified) and attributes with their shapes, the
 * grids and shape names, the wall law (and its checksummed copy since 3.2), the cell values; then the
 * derived arrays are checked finite, and the direct model's parameters in range (those of
 * surrogate.table.SurrogateTable.direct_parameters, RBS_ERR_FORMAT "the direct model's parameters are out of
 * range").
 * Returns RBS_OK, RBS_ERR_IO, RBS_ERR_FORMAT, RBS_ERR_VERSION, RBS_ERR_MEMORY or RBS_ERR_ARGUMENT. */
int rbs_table_open(const char *path, rbs_table **table, char *message, size_t message_size);

/* Free everything the table holds (NULL: nothing). No draw may use it afterwards. */
void rbs_table_close(rbs_table *table);

/* The path the table was opened from. */
const char *rbs_table_path(const rbs_table *table);

/* Number of shapes and the name of shape i (table order; NULL if i is out of range). */
int rbs_table_n_shapes(const rbs_table *table);
const char *rbs_table_shape_name(const rbs_table *table, int i);

/* The record of shape i as the table stores it (format 3.4, group /shapes; for an older table, the families' at
 * its κ and aspect-ratio law, their inertia J/m = s (b² + c², ...) from its second-moment factors, NaN if it does
 * not record them). RBS_OK, or RBS_ERR_ARGUMENT for a NULL table or info or i out of range. */
int rbs_table_shape_info(const rbs_table *table, int i, rbs_shape_info *info);

/* The α1 grid's first and last points, degrees; the |V⁻| grid's, m/s. */
void rbs_table_alpha1_range(const rbs_table *table, double *lo_deg, double *hi_deg);
void rbs_table_speed_range(const rbs_table *table, double *lo_m_s, double *hi_m_s);

/* The grids themselves: *count points, returned pointer valid until rbs_table_close. */
const double *rbs_table_alpha1_grid(const rbs_table *table, int *count);
const double *rbs_table_speed_grid(const rbs_table *table, int *count);

/* Sizes and provenance. */
void rbs_table_info_get(const rbs_table *table, rbs_table_info *info);

/* A derived kernel array, equal element for element to the field of surrogate's table.kernel_data of
 * the same name: "alpha1_axis", "speed_axis", "cells", "speed_restitution", "restitution_pieces"
 * (float64), "clusters", "dictionary" (float32); or "direct_parameters" (float64), the direct model's
 * parameters, equal to surrogate's table.direct_parameters (direct_model.runtime.model_parameters
 * layout). *data points into the table (read-only, valid until rbs_table_close), *count is its number of
 * elements, *dtype RBS_FLOAT64 or RBS_FLOAT32 (any of the three output pointers may be NULL). Returns
 * RBS_OK or RBS_ERR_ARGUMENT (unknown name, or "direct_parameters" of a table that does not record them:
 * built at κ ≠ 0.3 before tables recorded the second-moment factors). */
int rbs_table_kernel_array(const rbs_table *table, const char *name, const void **data, size_t *count,
                           int *dtype);

/* ---------------------------------------------------------------- shape mixes */

/* A mix sized by the table, for a table of any number of shapes: allocated here, freed by rbs_mix_free, read only
 * by the draws (threads may share it). Why a pointer: a table holds as many shapes as its build gave it (the
 * families and the user's grains, up to RBS_TABLE_MAX_SHAPES), so a mix held by value would either fix a largest
 * size in the binary interface again or change the size of the 1.0 rbs_mix that programs put on their stacks; a
 * pointer to a block the library sizes does neither, and the draws keep taking `const rbs_mix *`, so a 1.0
 * program's value mixes still work (tables of at most 4 shapes) and the two kinds never need two sets of draws.
 * Migration from 1.0: `rbs_mix mix; rbs_mix_equal(table, &mix); ... &mix` becomes
 * `rbs_mix *mix = rbs_mix_new_equal(table); ... mix; rbs_mix_free(mix);`.
 *
 * rbs_mix_new_from_weights: named weights (surrogate.mix_cdf with a dict): names of the table's shapes or
 * built-in families (ellipsoid, prism, cut_prism, tetrahedron), each at most once; weights finite and >= 0,
 * summing to 1 within 1e-9 (summed in the order given); a shape with a positive weight must be in the table.
 * Shapes not named get weight 0. rbs_mix_new_from_shape: one shape alone (surrogate.mix_cdf(table, name)); "mix"
 * gives the equal mix. rbs_mix_new_equal: equal weights over the table's shapes (surrogate.mix_cdf(table, "mix")).
 * Each returns the mix, or NULL with a message (a bad argument, out of memory). */
rbs_mix *rbs_mix_new_from_weights(const rbs_table *table, int n, const char *const names[], const double weights[],
                                  char *message, size_t message_size);
rbs_mix *rbs_mix_new_from_shape(const rbs_table *table, const char *name, char *message, size_t message_size);
rbs_mix *rbs_mix_new_equal(const rbs_table *table);

/* Free a mix of rbs_mix_new_* (NULL: nothing). Never pass it a value mix. */
void rbs_mix_free(rbs_mix *mix);

/* The same mixes into a value the caller owns (1.0): a table of at most RBS_MAX_SHAPES shapes, else
 * RBS_ERR_ARGUMENT with a message saying to use rbs_mix_new_*. Returns RBS_OK or RBS_ERR_ARGUMENT. */
int rbs_mix_from_weights(const rbs_table *table, int n, const char *const names[], const double weights[],
                         rbs_mix *mix, char *message, size_t message_size);
int rbs_mix_from_shape(const rbs_table *table, const char *name, rbs_mix *mix, char *message,
                       size_t message_size);
int rbs_mix_equal(const rbs_table *table, rbs_mix *mix);

/* ---------------------------------------------------------------- every wall hit: call this first */

/* Methods of rbs_rebound (surrogate's method "auto", "table", "direct"). */
enum {
    RBS_AUTO = 0,           /* the table where its law is valid (below), the direct model for every other hit */
    RBS_TABLE = 1,          /* the table whatever Ω⁻ (rbs_table_rebound: the law at the nearest grid edge outside) */
    RBS_DIRECT = 2          /* the direct model for every hit */
};

/* The path that answers a hit (rbs_rebound_path). */
enum { RBS_PATH_TABLE = 0, RBS_PATH_DIRECT = 1 };

/* The largest |Ω⁻| a/|V⁻| the table answers under RBS_AUTO (surrogate.SPIN_TOLERANCE): where the table's law
 * and the direct model's with that spin stay within classifier accuracy 0.52 (docs/design/spin_tolerance.md). */
#define RBS_SPIN_TOLERANCE 0.001

/* The reflected state of one particle hitting the wall, spinning or not, global frame
 * (surrogate.kernels.wall_hit.rebound): the path rbs_rebound_path gives, then
 *   RBS_PATH_TABLE   rbs_table_rebound with the same u (Ω⁻ unused);
 *   RBS_PATH_DIRECT  the shape drawn from the mix with u[0] as rbs_table_rebound draws it, then
 *                    rbs_direct_rebound with that shape's code and u[1..RBS_U_PER_REBOUND] as its uniforms.
 * A hit consumes RBS_U_PER_DRAW uniforms whatever the path, so streams stay aligned.
 *   mix      the shape mix (rbs_mix_new_equal, rbs_mix_new_from_shape, rbs_mix_new_from_weights, or a value mix)
 *   V        incident velocity V⁻, m/s (finite, must move into the wall: V·n < 0)
 *   Omega    incident angular velocity Ω⁻, rad/s (finite)
 *   n        unit wall normal into the gas (| |n| − 1 | <= RBS_NORMAL_TOLERANCE)
 *   a        half-size (half the largest extent), m (finite, > 0)
 *   u        RBS_U_PER_DRAW uniforms in [0, 1)
 *   method   RBS_AUTO (the default of surrogate), RBS_TABLE or RBS_DIRECT
 *   interpolation  the table path's, RBS_SCALED or RBS_STOCHASTIC
 *   V_out    V⁺, m/s;  Omega_out  Ω⁺, rad/s  (NaN unless rebounded)
 * Returns RBS_REBOUNDED, RBS_TRAPPED, RBS_FAILED (direct path: a collision solve or a contact search
 * failed; count it) or RBS_INVALID (what rbs_rebound_path refuses, a NULL pointer, a mix of another
 * table's shape count, an unknown interpolation, a uniform outside [0, 1) or NaN); NaN outputs unless
 * rebounded. The direct path costs microseconds, the table path a fraction of one. Thread-safe. */
int rbs_rebound(const rbs_table *table, const rbs_mix *mix, const double V[3], const double Omega[3],
                const double n[3], double a, const double u[RBS_U_PER_DRAW], int method, int interpolation,
                double V_out[3], double Omega_out[3]);

/* rbs_rebound with its RBS_U_PER_DRAW uniforms drawn from `rng` (rbs_rng_fill), which advances by them
 * whatever the path and whatever the result; a NULL or all-zero rng gives RBS_INVALID. */
int rbs_rebound_rng(const rbs_table *table, const rbs_mix *mix, const double V[3], const double Omega[3],
                    const double n[3], double a, rbs_rng *rng, int method, int interpolation, double V_out[3],
                    double Omega_out[3]);

/* The path that answers a hit under `method` (surrogate.kernels.wall_hit.rebound_path): a pure function of
 * the state, so a caller learns it without another draw. Under RBS_AUTO, the table iff |Ω⁻| a/|V⁻| <=
 * RBS_SPIN_TOLERANCE (Ω⁻ = 0 included), and α1 and |V⁻| (as rbs_table_rebound computes them) lie in the
 * table's grid ranges, edges included (rbs_table_alpha1_range, rbs_table_speed_range); else the direct model.
 *   V, Omega, n, a  as rbs_rebound
 * Returns RBS_PATH_TABLE or RBS_PATH_DIRECT; RBS_INVALID for a NULL pointer, an unknown method, or a
 * state rbs_table_rebound or rbs_direct_rebound refuses (V not moving into the wall, n not a unit vector, a
 * not finite and > 0, Ω⁻ not finite). */
int rbs_rebound_path(const rbs_table *table, const double V[3], const double Omega[3], const double n[3],
                     double a, int method);

/* ---------------------------------------------------------------- grain keys */

/* A grain key: an int64 >= 0 per particle, its own for life (rbs_grain_key derives one from a seed and the
 * particle's ids), so that the particle hits every wall as the same grain (surrogate.kernels.grain). The random
 * properties of the grain are pure functions of (key, the shape mix): the shape from the mix, and, for a shape of
 * random proportions, b/a and c/b, and for a shape drawn in both hands, its hand; each is drawn from a uniform of
 * the key (splitmix64 of the key and the property's slot) instead of from u. Everything else (the orientation
 * at impact, the table's law, the impact frame) stays random per hit from u. Which path honours what: the table
 * holds each shape's law over its random proportions and hands, so under the table path a key fixes the shape
 * only; under the direct path it fixes the shape, the proportions and the hand (rbs_grain_info gives them). */

/* One grain of a table's mix (rbs_grain_info). */
typedef struct rbs_grain {
    int shape;              /* the table's shape index (rbs_table_shape_name gives its name) */
    int direct_shape;       /* its shape for rbs_direct_rebound (rbs_shape_info.direct_shape); −1 for none */
    double ratio_ba;        /* b/a and c/b the direct path gives this grain on every hit; NaN for a shape of */
    double ratio_cb;        /*   fixed proportions or without direct shape (the table path: the shape's law) */
    double hand;            /* +1 or −1 (the mirror image) on the direct path; NaN for a shape of one hand */
} rbs_grain;

/* rbs_rebound for a particle of grain key `key` (surrogate.kernels.wall_hit.rebound with its `key`): the same
 * path, with u[0] (the shape) replaced by the key's uniform on either path and, on the direct path, u[4], u[5]
 * (b/a, c/b) and u[6] (the hand; u[1 + k] is the direct model's u[k]) by the key's. The hit still takes
 * RBS_U_PER_DRAW uniforms, all checked in [0, 1), so streams stay aligned keyed or not. A key < 0 (or what
 * rbs_rebound refuses) gives RBS_INVALID and NaN outputs. Thread-safe. */
int rbs_rebound_grain(const rbs_table *table, const rbs_mix *mix, int64_t key, const double V[3],
                      const double Omega[3], const double n[3], double a, const double u[RBS_U_PER_DRAW], int method,
                      int interpolation, double V_out[3], double Omega_out[3]);

/* rbs_rebound_grain with its RBS_U_PER_DRAW uniforms drawn from `rng` (rbs_rng_fill), which advances by them
 * whatever the path, the key and the result; a NULL or all-zero rng gives RBS_INVALID. */
int rbs_rebound_grain_rng(const rbs_table *table, const rbs_mix *mix, int64_t key, const double V[3],
                          const double Omega[3], const double n[3], double a, rbs_rng *rng, int method,
                          int interpolation, double V_out[3], double Omega_out[3]);

/* The grain of key `key` in the mix `mix` of `table` (surrogate.kernels.grain: grain_shape, grain_properties;
 * surrogate.grain_of from Python): its shape, and the proportions and hand the direct path gives it. Returns RBS_OK,
 * or RBS_ERR_ARGUMENT (nothing written) for a NULL pointer, a mix of another table's shape count or key < 0. */
int rbs_grain_info(const rbs_table *table, const rbs_mix *mix, int64_t key, rbs_grain *grain);

/* A grain key from a seed and two ids, e.g. (the run's seed, the rank a particle was born on, its number there):
 * splitmix64 chained, the top bit cleared, so a key >= 0 (surrogate.kernels.grain.grain_key; surrogate.grain_key
 * from Python with the same numbers). The same numbers give the same key on every machine, rank count and run. */
int64_t rbs_grain_key(uint64_t seed, uint64_t id1, uint64_t id2);

/* ---------------------------------------------------------------- the table path */

/* The reflected state of one particle from the table's law, global frame
 * (surrogate.kernels.table_path.table_rebound); Ω⁻ = 0 is assumed.
 *   V        incident velocity V⁻, m/s (finite, must move into the wall: V·n < 0)
 *   n        unit wall normal into the gas (| |n| − 1 | <= RBS_NORMAL_TOLERANCE)
 *   a        half-size, m (finite, > 0)
 *   u        RBS_U_PER_DRAW uniforms in [0, 1)
 *   interpolation  RBS_SCALED or RBS_STOCHASTIC
 *   V_out    V⁺, m/s;  Omega_out  Ω⁺, rad/s  (NaN unless rebounded)
 * Returns RBS_REBOUNDED, RBS_TRAPPED (rolling along or deposited; drawn with the cell's tabulated
 * probability) or RBS_INVALID (V does not move into the wall, n is not a unit vector, a is not finite
 * and > 0, a uniform is outside [0, 1), the result would not be finite or would not leave the wall; a
 * NULL pointer, a mix of another table's shape count, an unknown interpolation). A rebound's V⁺ and Ω⁺
 * are finite and V⁺·n > 0. */
int rbs_table_rebound(const rbs_table *table, const rbs_mix *mix, const double V[3], const double n[3], double a,
                      const double u[RBS_U_PER_DRAW], int interpolation, double V_out[3], double Omega_out[3]);

/* rbs_table_rebound for `count` particles, one thread: V, n, V_out, Omega_out row-major (count, 3), a (count,),
 * u (count, RBS_U_PER_DRAW), status (count,). The same bits as rbs_table_rebound row by row (and as
 * surrogate.kernels.pipeline.table_rebound_many); faster, because the table reads of RBS_BLOCK rows are in
 * flight together and the arithmetic runs as SIMD loops over them. The outputs must not overlap the inputs.
 * A NULL table, mix or array (count > 0), a mix of another table's shape count or an unknown interpolation
 * gives every row RBS_INVALID and NaN (in the outputs that are not NULL). */
void rbs_table_rebound_many(const rbs_table *table, const rbs_mix *mix, size_t count, const double *V,
                            const double *n, const double *a, const double *u, int interpolation, double *V_out,
                            double *Omega_out, signed char *status);

/* rbs_table_rebound_many drawing the uniforms from `rng`, as surrogate.kernels.pipeline.table_rebound_many_rng
 * does, bit for bit: rng is advanced one step to seed RBS_BLOCK xoshiro256+ lanes (splitmix64), and row b of
 * every block of RBS_BLOCK rows takes its 13 uniforms from lane b. rbs_table_rebound_uniforms gives those
 * uniforms. A NULL or all-zero rng (or the cases of rbs_table_rebound_many) gives every row RBS_INVALID, and
 * rng is not advanced. */
void rbs_table_rebound_many_rng(const rbs_table *table, const rbs_mix *mix, size_t count, const double *V,
                                const double *n, const double *a, rbs_rng *rng, int interpolation, double *V_out,
                                double *Omega_out, signed char *status);

/* One reflected state at (α1 deg, |V⁻| m/s) in the local frame (surrogate.kernels.table_path.draw_local):
 * out = (α2 rad, β2 rad, s = |V⁺|/|V⁻|, Ω_x, Ω_y, Ω_z in units of |V⁻|/a): RBS_LOCAL_SIZE = 6 numbers
 * (Ω⁺a/|V⁻| is a vector), NaN unless rebounded.
 * Returns RBS_REBOUNDED or RBS_TRAPPED; RBS_INVALID for α1 outside (0, 90] or NaN, |V⁻| not finite and
 * > 0, a uniform outside [0, 1), a NULL pointer, a mix of another table's shape count, an unknown
 * interpolation. Outside the grid (however far), the law at the nearest grid edge. */
int rbs_draw_local(const rbs_table *table, const rbs_mix *mix, double alpha1_deg, double speed_m_s,
                   const double u[RBS_U_PER_DRAW], int interpolation, double out[RBS_LOCAL_SIZE]);

/* ---------------------------------------------------------------- the direct path */

/* One particle's rebound by the direct model, caller's frame (surrogate.kernels.direct_path.direct_rebound):
 * the impulse model itself (docs/model.md), flights and collisions simulated, where the table's law does not
 * apply (a spinning particle, say). The same bits as the numba kernel for the same uniforms.
 *   shape    RBS_ELLIPSOID, RBS_PRISM, RBS_CUT_PRISM or RBS_TETRAHEDRON (any of the four, whatever
 *            shapes the table holds), or 4 + k for the table's k-th other polyhedron (a user grain, a later
 *            family) in table order
 *            (rbs_shape_info.direct_shape gives it for each of the table's shapes)
 *   V        incident velocity V⁻, m/s (finite, must move into the wall: V·n < 0)
 *   Omega    incident angular velocity Ω⁻, rad/s (finite); exactly zero: the body starts touching the
 *            wall (the tables' case), otherwise the flight in from a clear start is simulated
 *   n        unit wall normal into the gas (| |n| − 1 | <= RBS_NORMAL_TOLERANCE)
 *   a        half-size (half the largest extent), m (finite, > 0)
 *   u        RBS_U_PER_REBOUND uniforms in [0, 1) (−0 allowed): u[0..2] the orientation (Shoemake's
 *            uniform quaternion), u[3], u[4] the aspect ratios b/a and c/b (inverse CDF of the table's
 *            truncated normal law), u[5] the tetrahedron's hand (+1 below ½), u[6] the direction ex of
 *            the impact frame at normal impact (as u[12] of a draw)
 *   V_out    V⁺, m/s;  Omega_out  Ω⁺, rad/s  (NaN unless rebounded)
 * The model runs in the impact frame (ex, n, ez) of rbs_table_rebound, with Ω⁻ in units of (m/s)/a; its
 * parameters (aspect-ratio law, κ, n_max, wall law, tolerances, second-moment factors) are the table's
 * "direct_parameters" (rbs_table_kernel_array), so a table and its direct model never disagree.
 * Returns RBS_REBOUNDED; RBS_TRAPPED (still colliding after n_max collisions) or RBS_FAILED (a collision
 * solve or a contact search failed) with NaN outputs; RBS_INVALID with NaN outputs for an input outside
 * the ranges above, a NULL pointer, a shape outside those, or a table without direct parameters (a NULL
 * output gets nothing). Thread-safe: scratch on the stack, the table read only. */
int rbs_direct_rebound(const rbs_table *table, int shape, const double V[3], const double Omega[3],
                       const double n[3], double a, const double u[RBS_U_PER_REBOUND],
                       double V_out[3], double Omega_out[3]);

/* ---------------------------------------------------------------- random numbers */

/* The state surrogate.seed_state(seed) gives (numpy's SeedSequence(seed).spawn(1)[0], 4 uint64 words, never
 * all zero). A NULL rng: nothing. */
void rbs_rng_seed(rbs_rng *rng, uint64_t seed);

/* The state surrogate.seed_state(seed, n_streams=n)[k] gives, for any n > k: stream k of a seed
 * (SeedSequence(seed) child k). Use k = thread number or MPI rank. */
void rbs_rng_seed_stream(rbs_rng *rng, uint64_t seed, uint64_t k);

/* The next uniform in [0, 1) (53 bits; surrogate.kernels.rng.next_uniform); NaN for a NULL or all-zero
 * state (not a xoshiro256+ state: it would give 0 forever), which every draw refuses. */
double rbs_rng_uniform(rbs_rng *rng);

/* u[0..count) = the next count uniforms (surrogate.fill_uniforms); NaN for a NULL or all-zero state. */
void rbs_rng_fill(rbs_rng *rng, double *u, size_t count);

/* The (count, RBS_U_PER_DRAW) uniforms rbs_table_rebound_many_rng draws for count rows from rng, advancing
 * rng as it does (surrogate.kernels.pipeline.table_rebound_uniforms); NaN for a NULL or all-zero state. */
void rbs_table_rebound_uniforms(rbs_rng *rng, size_t count, double *u);

/* ---------------------------------------------------------------- kept from 0.x */

/* rbs_rebound_rng under its 0.x name, kept for programs written against 0.x: the same arguments, the same
 * bits. rbs_rebound_path too keeps its 0.x name and arguments. The other draws of 0.x were renamed in 1.0
 * (a program calling one of them no longer compiles): rbs_rebound → rbs_table_rebound (the table path; the
 * name rbs_rebound now answers any hit), rbs_rebound_many → rbs_table_rebound_many, rbs_rebound_many_rng →
 * rbs_table_rebound_many_rng, rbs_rebound_uniforms → rbs_table_rebound_uniforms, rbs_rebound_direct →
 * rbs_direct_rebound (same arguments), rbs_rebound_spin_u → rbs_rebound (same arguments). */
int rbs_rebound_spin(const rbs_table *table, const rbs_mix *mix, const double V[3], const double Omega[3],
                     const double n[3], double a, rbs_rng *rng, int method, int interpolation, double V_out[3],
                     double Omega_out[3]);

/* ---------------------------------------------------------------- misc */

/* A static description of an error code. */
const char *rbs_error_string(int code);

/* The library version, "MAJOR.MINOR.PATCH". */
const char *rbs_version(void);

#ifdef __cplusplus
}
#endif

#endif /* REBOUND_SCATTER_H */
