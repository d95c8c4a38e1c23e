/*============================================================================
 * rebound-scatter for code_saturne 6.0's Lagrangian module: every particle
 * that hits a boundary zone of type CS_LAGR_BC_USER gets its rebound from
 * the rebound-scatter C runtime (rebound_scatter.h): the table's law where
 * it holds, the direct model elsewhere.
 *
 * Copyright (C) 2026 the rebound-scatter authors
 *
 * This program is free software; you can redistribute it and/or modify it
 * under the terms of the GNU General Public License as published by the Free
 * Software Foundation; either version 2 of the License, or (at your option)
 * any later version.
 *
 * This program is distributed in the hope that it will be useful, but WITHOUT
 * ANY WARRANTY; without even the implied warranty of MERCHANTABILITY or
 * FITNESS FOR A PARTICULAR PURPOSE.  See the GNU General Public License for
 * more details.
 *
 * You should have received a copy of the GNU General Public License along with
 * this program (integrations/code_saturne/LICENSE); if not, write to the Free
 * Software Foundation, Inc., 51 Franklin Street, Fifth Floor, Boston, MA
 * 02110-1301, USA.
 *============================================================================*/

#include "cs_defs.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "bft_error.h"
#include "bft_printf.h"

#include "cs_ale.h"
#include "cs_boundary_zone.h"
#include "cs_math.h"
#include "cs_mesh_quantities.h"
#include "cs_parall.h"
#include "cs_time_step.h"
#include "cs_timer.h"
#include "cs_turbomachinery.h"

#include "cs_lagr.h"
#include "cs_lagr_event.h"
#include "cs_lagr_particle.h"
#include "cs_lagr_prototypes.h"
#include "cs_lagr_tracking.h"

#include "rebound_scatter.h"
#include "rbs_cs_rebound.h"

/*----------------------------------------------------------------------------
 * Settings, state and counters of this rank
 *----------------------------------------------------------------------------*/

#define RBS_CS_DEFAULT_SETUP "rebound_scatter.conf"
#define RBS_CS_MAX_WEIGHTS 256     /* shape:weight items of the weights setting */
#define RBS_CS_LINE 4096

/* The solver's own rebound restarts the next segment this fraction of the
 * way from the hit point to the cell centre (bc_epsilon of 6.0's
 * cs_lagr_tracking.c): so does ours */
#define RBS_CS_BC_EPSILON 1.e-2

typedef struct {
  char        setup_path[RBS_CS_LINE];
  char        table_path[RBS_CS_LINE];
  char        mix_name[RBS_CS_LINE];        /* "prism", "mix", "weights (...)" */
  char        hits_dir[RBS_CS_LINE];        /* "" if no hit records */
  double      half_size_factor;             /* a = factor * d / 2 */
  uint64_t    seed;
  int         method;                       /* RBS_METHOD_AUTO, _TABLE, _DIRECT */
  int         interpolation;                /* RBS_INTERPOLATION_SCALED,
                                               RBS_INTERPOLATION_STOCHASTIC */
  int         remove_trapped;               /* 0: deposited, 1: removed */
  int         keep_grain;                   /* 1: kept, 0: a new grain per hit */
  uint64_t    grain_seed;                   /* the keys' seed */
  long long   max_hit_records;
} rbs_cs_settings_t;

typedef struct {
  cs_gnum_t   hits, table_path, direct_path, rebounded, trapped, failed,
              invalid, outside_grid;
  double      trapped_weight, failed_weight, direct_seconds, cpu_seconds;
} rbs_cs_counters_t;

static int                 _initialized = 0;
static rbs_cs_settings_t   _set;
static rbs_table          *_table = NULL;
static rbs_mix            *_mix = NULL;   /* sized by the table (rbs_mix_new_*) */
static rbs_rng             _rng;
static FILE               *_hits = NULL;
static long long           _n_recorded = 0;
static rbs_cs_counters_t   _count;
static double              _alpha1_lo, _alpha1_hi, _speed_lo, _speed_hi;

/* CPU seconds of the calling thread: what the hits cost whatever else runs on
   the machine */
static double
_thread_cpu_seconds(void)
{
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9*(double)t.tv_nsec;
}

/*----------------------------------------------------------------------------
 * Reading the settings
 *----------------------------------------------------------------------------*/

static const char *_keys[] = {"table", "shape", "weights", "seed", "method",
                              "interpolation", "trapped", "half_size_factor",
                              "hits", "max_hit_records", "grain",
                              "grain_seed"};
#define RBS_CS_N_KEYS (sizeof(_keys)/sizeof(_keys[0]))

/* A copy of `src` into `dst` (size RBS_CS_LINE): it fits, lines being shorter */
static void
_copy(char dst[RBS_CS_LINE], const char *src)
{
  size_t n = strlen(src);
  if (n >= RBS_CS_LINE)
    n = RBS_CS_LINE - 1;
  memcpy(dst, src, n);
  dst[n] = '\0';
}

/* `path` as given if absolute, else relative to the settings file's folder */
static void
_resolve(char dst[RBS_CS_LINE], const char *path)
{
  const char *slash = strrchr(_set.setup_path, '/');
  if (path[0] == '/' || slash == NULL)
    _copy(dst, path);
  else
    snprintf(dst, RBS_CS_LINE, "%.*s/%s", (int)(slash - _set.setup_path),
             _set.setup_path, path);
}

static char *
_trim(char *s)
{
  while (isspace((unsigned char)*s))
    s++;
  char *e = s + strlen(s);
  while (e > s && isspace((unsigned char)e[-1]))
    *(--e) = '\0';
  return s;
}

/* A value the settings file gave, or NULL; values[i] belongs to _keys[i] */
static const char *
_value(char values[][RBS_CS_LINE], const int given[], const char *key)
{
  for (size_t i = 0; i < RBS_CS_N_KEYS; i++)
    if (strcmp(_keys[i], key) == 0)
      return given[i] ? values[i] : NULL;
  return NULL;
}

static void
_read_settings_file(const char *path, char values[][RBS_CS_LINE], int given[])
{
  FILE *f = fopen(path, "r");
  if (f == NULL)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter: cannot read the settings file %s (%s); "
              "write one there or name it with RBS_CS_SETUP",
              path, strerror(errno));

  char line[RBS_CS_LINE];
  int line_no = 0;
  while (fgets(line, sizeof(line), f) != NULL) {
    line_no++;
    if (strchr(line, '\n') == NULL && !feof(f))
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s, line %d: longer than %d "
                "characters", path, line_no, RBS_CS_LINE - 2);
    char *hash = strchr(line, '#');
    if (hash != NULL)
      *hash = '\0';
    char *s = _trim(line);
    if (*s == '\0')
      continue;
    char *eq = strchr(s, '=');
    if (eq == NULL)
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s, line %d: \"%s\" is not "
                "key = value", path, line_no, s);
    *eq = '\0';
    const char *key = _trim(s), *val = _trim(eq + 1);
    size_t i = 0;
    while (i < RBS_CS_N_KEYS && strcmp(_keys[i], key) != 0)
      i++;
    if (i == RBS_CS_N_KEYS)
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s, line %d: unknown key \"%s\"; "
                "the keys are table, shape, weights, seed, method, "
                "interpolation, trapped, half_size_factor, hits, "
                "max_hit_records, grain, grain_seed", path, line_no, key);
    if (given[i])
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s, line %d: \"%s\" is given twice",
                path, line_no, key);
    given[i] = 1;
    _copy(values[i], val);
  }
  fclose(f);
}

static long long
_parse_integer(const char *key, const char *text, long long lo, long long hi)
{
  char *end = NULL;
  errno = 0;
  long long v = strtoll(text, &end, 10);
  if (*text == '\0' || *end != '\0' || errno != 0 || v < lo || v > hi)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter settings %s: %s must be an integer in "
              "[%lld, %lld], not \"%s\"", _set.setup_path, key, lo, hi, text);
  return v;
}

static int
_parse_choice(const char *key, const char *text, const char *const names[],
              const int codes[], int n, const char *allowed)
{
  for (int i = 0; i < n; i++)
    if (strcmp(text, names[i]) == 0)
      return codes[i];
  bft_error(__FILE__, __LINE__, 0,
            "rebound-scatter settings %s: %s must be %s, not \"%s\"",
            _set.setup_path, key, allowed, text);
  return -1;
}

/* "prism:0.7, tetrahedron:0.3" into the table's mix */
static void
_parse_weights(const char *text)
{
  char buf[RBS_CS_LINE], msg[512];
  const char *names[RBS_CS_MAX_WEIGHTS];
  double weights[RBS_CS_MAX_WEIGHTS];
  int n = 0;
  snprintf(buf, sizeof(buf), "%s", text);
  for (char *item = strtok(buf, ","); item != NULL; item = strtok(NULL, ",")) {
    char *colon = strchr(item, ':');
    char *end = NULL;
    if (colon == NULL || n == RBS_CS_MAX_WEIGHTS)
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s: weights must be up to %d "
                "shape:weight items separated by commas, not \"%s\"",
                _set.setup_path, RBS_CS_MAX_WEIGHTS, text);
    *colon = '\0';
    names[n] = _trim(item);
    weights[n] = strtod(_trim(colon + 1), &end);
    if (end == _trim(colon + 1) || *end != '\0')
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s: the weight of %s must be a "
                "number, not \"%s\"", _set.setup_path, names[n],
                _trim(colon + 1));
    n++;
  }
  _mix = rbs_mix_new_from_weights(_table, n, names, weights, msg, sizeof(msg));
  if (_mix == NULL)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter settings %s: bad weights \"%s\": %s",
              _set.setup_path, text, msg);
  snprintf(_set.mix_name, sizeof(_set.mix_name), "weights (%s)", text);
}

static void
_read_settings(void)
{
  static char values[RBS_CS_N_KEYS][RBS_CS_LINE];
  int given[RBS_CS_N_KEYS] = {0};
  char msg[512];

  const char *env = getenv("RBS_CS_SETUP");
  snprintf(_set.setup_path, sizeof(_set.setup_path), "%s",
           (env != NULL && env[0] != '\0') ? env : RBS_CS_DEFAULT_SETUP);
  _read_settings_file(_set.setup_path, values, given);

  const char *table = _value(values, given, "table");
  if (table == NULL || table[0] == '\0')
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter settings %s: no table (table = path of a "
              "table written by tablegen build)", _set.setup_path);
  _resolve(_set.table_path, table);
  int err = rbs_table_open(_set.table_path, &_table, msg, sizeof(msg));
  if (err != RBS_OK)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter settings %s: cannot open the table %s: "
              "%s: %s", _set.setup_path, _set.table_path,
              rbs_status_string(err), msg);
  rbs_table_info info = RBS_TABLE_INFO_INIT;
  err = rbs_table_info_get(_table, &info);
  if (err != RBS_OK)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter settings %s: cannot read the grids of the "
              "table %s: %s", _set.setup_path, _set.table_path,
              rbs_status_string(err));
  _alpha1_lo = info.alpha1_min_deg;
  _alpha1_hi = info.alpha1_max_deg;
  _speed_lo = info.speed_min_m_s;
  _speed_hi = info.speed_max_m_s;

  const char *shape = _value(values, given, "shape");
  const char *weights = _value(values, given, "weights");
  if (shape != NULL && weights != NULL)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter settings %s: shape and weights are both "
              "given: give one of them", _set.setup_path);
  if (weights != NULL)
    _parse_weights(weights);
  else {
    if (shape == NULL)
      shape = "mix";
    _mix = rbs_mix_new_from_shape(_table, shape, msg, sizeof(msg));
    if (_mix == NULL)
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s: bad shape \"%s\": %s",
                _set.setup_path, shape, msg);
    _copy(_set.mix_name, shape);
  }

  /* the seed: 0 to 2^63 - 1 (a text of digits, no sign) */
  const char *seed = _value(values, given, "seed");
  _set.seed = (seed == NULL) ? 1
    : (uint64_t)_parse_integer("seed", seed, 0, 9223372036854775807LL);

  static const char *const method_names[] = {"auto", "table", "direct"};
  static const int method_codes[] = {RBS_METHOD_AUTO, RBS_METHOD_TABLE,
                                     RBS_METHOD_DIRECT};
  const char *method = _value(values, given, "method");
  _set.method = _parse_choice("method", method ? method : "auto", method_names,
                              method_codes, 3, "auto, table or direct");

  static const char *const interp_names[] = {"scaled", "stochastic"};
  static const int interp_codes[] = {RBS_INTERPOLATION_SCALED,
                                     RBS_INTERPOLATION_STOCHASTIC};
  const char *interp = _value(values, given, "interpolation");
  _set.interpolation = _parse_choice("interpolation",
                                     interp ? interp : "scaled", interp_names,
                                     interp_codes, 2, "scaled or stochastic");

  static const char *const trapped_names[] = {"deposit", "remove"};
  static const int trapped_codes[] = {0, 1};
  const char *trapped = _value(values, given, "trapped");
  _set.remove_trapped = _parse_choice("trapped",
                                      trapped ? trapped : "deposit",
                                      trapped_names, trapped_codes, 2,
                                      "deposit or remove");

  /* grain kept: a particle's key from its random value (module doc of
     docs/code_saturne.md); perHit: a new grain from the mix at every hit */
  static const char *const grain_names[] = {"kept", "perHit"};
  static const int grain_codes[] = {1, 0};
  const char *grain = _value(values, given, "grain");
  _set.keep_grain = _parse_choice("grain", grain ? grain : "kept",
                                  grain_names, grain_codes, 2,
                                  "kept or perHit");
  const char *grain_seed = _value(values, given, "grain_seed");
  _set.grain_seed = (grain_seed == NULL) ? _set.seed
    : (uint64_t)_parse_integer("grain_seed", grain_seed, 0,
                               9223372036854775807LL);

  const char *factor = _value(values, given, "half_size_factor");
  _set.half_size_factor = 1.0;
  if (factor != NULL) {
    char *end = NULL;
    _set.half_size_factor = strtod(factor, &end);
    if (end == factor || *end != '\0' || !(_set.half_size_factor > 0)
        || !isfinite(_set.half_size_factor))
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s: half_size_factor must be a "
                "finite number > 0, not \"%s\"", _set.setup_path, factor);
  }

  const char *hits = _value(values, given, "hits");
  if (hits != NULL && hits[0] != '\0')
    _resolve(_set.hits_dir, hits);
  else
    _set.hits_dir[0] = '\0';

  const char *max_rec = _value(values, given, "max_hit_records");
  _set.max_hit_records = (max_rec == NULL) ? 1000000
    : _parse_integer("max_hit_records", max_rec, 0, 9223372036854775807LL);
}

/*----------------------------------------------------------------------------
 * The hits file of this rank: the layout of the OpenFOAM adapter's
 *----------------------------------------------------------------------------*/

static const char *
_name(int code, const char *const names[], const int codes[], int n)
{
  for (int i = 0; i < n; i++)
    if (codes[i] == code)
      return names[i];
  return "?";
}

static void
_open_hits(int rank)
{
  if (_set.hits_dir[0] == '\0')
    return;
  if (mkdir(_set.hits_dir, 0777) != 0 && errno != EEXIST)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter settings %s: cannot create the hits folder "
              "%s (%s)", _set.setup_path, _set.hits_dir, strerror(errno));
  char path[RBS_CS_LINE + 32];
  snprintf(path, sizeof(path), "%s/hits_%d.csv", _set.hits_dir, rank);
  /* a new run starts our records again, and never overwrites another file */
  static const char ours[] = "# code_saturne rebound-scatter hits:";
  FILE *old = fopen(path, "r");
  if (old != NULL) {
    char first[sizeof(ours)] = "";
    const int is_ours = fgets(first, sizeof(first), old) != NULL
                        && strcmp(first, ours) == 0;
    fclose(old);
    if (!is_ours)
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s: %s exists and is not a "
                "rebound-scatter hits file; choose another hits folder",
                _set.setup_path, path);
  }
  _hits = fopen(path, "w");
  if (_hits == NULL)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter: cannot write the hits file %s (%s)", path,
              strerror(errno));
  /* the table's absolute path: the records are read from other folders */
  char table[2*RBS_CS_LINE + 2], cwd[RBS_CS_LINE];
  if (_set.table_path[0] != '/' && getcwd(cwd, sizeof(cwd)) != NULL)
    snprintf(table, sizeof(table), "%s/%s", cwd, _set.table_path);
  else
    _copy(table, _set.table_path);
  static const char *const m[] = {"auto", "table", "direct"};
  static const int mc[] = {RBS_METHOD_AUTO, RBS_METHOD_TABLE,
                           RBS_METHOD_DIRECT};
  static const char *const im[] = {"scaled", "stochastic"};
  static const int ic[] = {RBS_INTERPOLATION_SCALED,
                           RBS_INTERPOLATION_STOCHASTIC};
  fprintf(_hits,
          "%s seed %llu, stream %d, "
          "table %s, mix %s, halfSizeFactor %.17g, interpolation %s, "
          "method %s, spin tolerance %g, grain ",
          ours, (unsigned long long)_set.seed, rank, table, _set.mix_name,
          _set.half_size_factor, _name(_set.interpolation, im, ic, 2),
          _name(_set.method, m, mc, 3), RBS_SPIN_TOLERANCE);
  if (_set.keep_grain)
    fprintf(_hits, "kept (key seed %llu)\n",
            (unsigned long long)_set.grain_seed);
  else
    fprintf(_hits, "perHit\n");
  fprintf(_hits,
          "# V: incident velocity relative to the wall (at rest), Win: "
          "incident angular velocity (0: code_saturne 6.0's particles carry "
          "none), n: unit normal into the gas, Uw: wall velocity, patch: "
          "boundary zone, origProc/origId: -1 (6.0's particles carry no "
          "persistent id), path: 0 table, 1 direct model, -1 invalid, "
          "Vout/Wout: rebound velocity and angular velocity, spin_ratio: "
          "|Win| a/|V|, u0: first uniform of the draw, key: the particle's "
          "grain key (from its random value; -1: a new grain per hit), "
          "shape: its shape (empty: drawn per hit), ratio_ba/ratio_cb/hand: "
          "its b/a, c/b and hand on the direct path (nan: the table path or "
          "not random)\n");
  fprintf(_hits,
          "time,rank,patch,origProc,origId,d,a,Vx,Vy,Vz,Winx,Winy,Winz,"
          "nx,ny,nz,Uwx,Uwy,Uwz,status,path,Voutx,Vouty,Voutz,Wx,Wy,Wz,"
          "spin_ratio,u0,key,shape,ratio_ba,ratio_cb,hand\n");
}

static void
_record_hit(int b_zone_id, double d, const rbs_hit *hit,
            const rbs_result *result, int path, double u0)
{
  if (_hits == NULL || _n_recorded >= _set.max_hit_records)
    return;
  _n_recorded++;
  const cs_zone_t *z = cs_boundary_zone_by_id(b_zone_id);

  /* The grain: its shape under grain kept (empty for a new grain per hit;
     the result's, else, for a hit refused, the key's), and b/a, c/b and the
     hand where the direct path fixed them (NaN on the table path, which
     draws them from the shape's law) */
  const int64_t key = hit->grain_key;
  const char *shape = "";
  double ratio_ba = NAN, ratio_cb = NAN, hand = NAN;
  if (key >= 0) {
    int grain_shape = result->shape;
    rbs_grain grain = RBS_GRAIN_INIT;
    if ((grain_shape < 0 || path == RBS_PATH_DIRECT)
        && rbs_grain_info(_table, _mix, key, &grain) == RBS_OK) {
      grain_shape = grain.shape;
      if (path == RBS_PATH_DIRECT) {
        ratio_ba = grain.ratio_ba;
        ratio_cb = grain.ratio_cb;
        hand = grain.hand;
      }
    }
    if (grain_shape >= 0)
      shape = rbs_table_shape_name(_table, grain_shape);
  }
  const double *V = hit->V, *n = hit->n;
  const double *Vout = result->V, *Wout = result->Omega;
  fprintf(_hits,
          "%.9g,%d,%s,-1,-1,%.9g,%.9g,%.17g,%.17g,%.17g,0,0,0,"
          "%.17g,%.17g,%.17g,0,0,0,%d,%d,"
          "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,0,%.17g,"
          "%lld,%s,%.17g,%.17g,%g\n",
          cs_glob_time_step->t_cur, cs_glob_rank_id < 0 ? 0 : cs_glob_rank_id,
          z->name, d, hit->a, V[0], V[1], V[2], n[0], n[1], n[2],
          result->status, path,
          Vout[0], Vout[1], Vout[2], Wout[0], Wout[1], Wout[2], u0,
          (long long)key, shape, ratio_ba, ratio_cb, hand);
}

/*----------------------------------------------------------------------------
 * Public functions
 *----------------------------------------------------------------------------*/

void
rbs_cs_initialize(void)
{
  if (_initialized)
    return;

  /* A moving wall would need its velocity taken out of V⁻: 6.0 gives the
     user function none, so the walls must be at rest */
  if (cs_glob_ale != 0)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter: ALE (moving mesh) is on; the rebound is "
              "drawn relative to walls at rest, so it needs a fixed mesh");
  if (cs_turbomachinery_get_model() != CS_TURBOMACHINERY_NONE)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter: a turbomachinery model is on; the rebound is "
              "drawn relative to walls at rest, so it needs fixed walls");

  memset(&_count, 0, sizeof(_count));
  _read_settings();

  /* Rank r draws stream r of the seed: no two ranks share draws, and rank 0
     of a parallel run draws the serial run's stream */
  const int rank = cs_glob_rank_id < 0 ? 0 : cs_glob_rank_id;
  rbs_rng_seed_stream(&_rng, _set.seed, (uint64_t)rank);
  _open_hits(rank);
  _initialized = 1;

  static const char *const m[] = {"auto", "table", "direct"};
  static const int mc[] = {RBS_METHOD_AUTO, RBS_METHOD_TABLE,
                           RBS_METHOD_DIRECT};
  bft_printf("\n  rebound-scatter: table %s (%d shapes, alpha1 %g-%g deg, "
             "|V| %g-%g m/s)\n"
             "    mix %s, a = %g*d/2, trapped particles %s, method %s "
             "(spin tolerance %g), seed %llu (rank r draws stream r), "
             "grain %s%s%s\n",
             _set.table_path, rbs_table_n_shapes(_table), _alpha1_lo,
             _alpha1_hi, _speed_lo, _speed_hi, _set.mix_name,
             _set.half_size_factor,
             _set.remove_trapped ? "removed" : "deposited",
             _name(_set.method, m, mc, 3), RBS_SPIN_TOLERANCE,
             (unsigned long long)_set.seed,
             _set.keep_grain ? "kept (a particle's key from grain_seed and "
                               "its random value)"
                             : "perHit (a new grain from the mix at every hit)",
             _hits != NULL ? ", hits in " : "", _set.hits_dir);
}

void
rbs_cs_finalize(void)
{
  if (!_initialized)
    return;
  cs_gnum_t c[8] = {_count.hits, _count.table_path, _count.direct_path,
                    _count.rebounded, _count.trapped, _count.failed,
                    _count.invalid, _count.outside_grid};
  double w[4] = {_count.trapped_weight, _count.failed_weight,
                 _count.direct_seconds, _count.cpu_seconds};
  cs_parall_counter(c, 8);
  cs_parall_sum(4, CS_DOUBLE, w);
  const char *policy = _set.remove_trapped ? "removed" : "deposited";
  bft_printf("\n  rebound-scatter (%s), all ranks\n"
             "    - wall hits                    = %llu\n"
             "    - answered by the table        = %llu\n"
             "    - answered by the direct model = %llu (mean cost %g us per "
             "hit)\n"
             "    - rebounded                    = %llu\n"
             "    - trapped, %s (number, weight) = %llu, %g\n"
             "    - failed (direct model), %s (number, weight) = %llu, %g\n"
             "    - invalid (solver's rebound)   = %llu\n"
             "    - outside the table's grid     = %llu\n"
             "    - CPU time in the hits         = %g s (%g us per hit)\n",
             _set.mix_name, (unsigned long long)c[0], (unsigned long long)c[1],
             (unsigned long long)c[2], c[2] > 0 ? 1e6*w[2]/c[2] : 0.,
             (unsigned long long)c[3], policy, (unsigned long long)c[4], w[0],
             policy, (unsigned long long)c[5], w[1], (unsigned long long)c[6],
             (unsigned long long)c[7], w[3], c[0] > 0 ? 1e6*w[3]/c[0] : 0.);
  if (_hits != NULL)
    fclose(_hits);
  _hits = NULL;
  rbs_mix_free(_mix);
  _mix = NULL;
  rbs_table_close(_table);
  _table = NULL;
  _initialized = 0;
}

/*----------------------------------------------------------------------------
 * The hit (declared in cs_lagr_prototypes.h, called by 6.0's tracking for
 * every boundary face of a CS_LAGR_BC_USER zone a particle crosses)
 *----------------------------------------------------------------------------*/

void
cs_lagr_user_boundary_interaction(cs_lagr_particle_set_t    *particles,
                                  cs_lnum_t                  p_id,
                                  cs_lnum_t                  face_id,
                                  const cs_real_t            face_norm[3],
                                  const cs_real_t            c_intersect[3],
                                  cs_real_t                  t_intersect,
                                  int                        b_zone_id,
                                  int                       *event_flag,
                                  cs_lagr_tracking_state_t  *tracking_state)
{
  CS_UNUSED(face_id);
  rbs_cs_initialize();
  const double cpu0 = _thread_cpu_seconds();

  const cs_lagr_attribute_map_t *p_am = particles->p_am;
  unsigned char *particle = particles->p_buffer + p_am->extents * p_id;
  cs_real_t *coords = cs_lagr_particle_attr(particle, p_am, CS_LAGR_COORDS);
  cs_real_t *vel = cs_lagr_particle_attr(particle, p_am, CS_LAGR_VELOCITY);
  cs_real_t *vel_seen = cs_lagr_particle_attr(particle, p_am,
                                              CS_LAGR_VELOCITY_SEEN);
  const double d = cs_lagr_particle_get_real(particle, p_am, CS_LAGR_DIAMETER);
  const double weight = cs_lagr_particle_get_real(particle, p_am,
                                                  CS_LAGR_STAT_WEIGHT);
  const cs_lnum_t cell_id = cs_lagr_particle_get_lnum(particle, p_am,
                                                      CS_LAGR_CELL_ID);
  const cs_real_t *cell_cen = cs_glob_mesh_quantities->cell_cen + 3*cell_id;

  /* The start of the particle's next trajectory segment: 6.0 keeps it in the
     tracking work area before the particle's attributes (its first member,
     p_am->lb bytes reserved) and has no function to set it; the solver's own
     rebound moves it next to the hit point. The hit point it passes is
     start + t (end - start): check that we read the start we think we do */
  if (p_am->lb < 3*sizeof(cs_real_t))
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter: this code_saturne reserves no tracking work "
              "area before a particle's attributes; rbs_cs_rebound.c is "
              "written for code_saturne 6.0");
  cs_real_t *start = (cs_real_t *)particle;
  double mismatch = 0, scale = 0;
  for (int k = 0; k < 3; k++) {
    const double x = (coords[k] - start[k])*t_intersect + start[k];
    mismatch = fmax(mismatch, fabs(x - c_intersect[k]));
    scale = fmax(scale, fabs(coords[k]) + fabs(start[k]));
  }
  /* the same arithmetic as the solver's: equal but for rounding */
  if (!(mismatch <= 1e-12*scale))
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter: this code_saturne does not keep the start of "
              "a trajectory segment where 6.0 does (hit point mismatch %g m); "
              "rbs_cs_rebound.c is written for code_saturne 6.0", mismatch);

  /* Ours is the unit normal into the gas. 6.0.2 passes the crossed
     sub-triangle's unit normal, which its cs_geom_segment_intersect_face
     points into the domain; the segment leaves the domain through the face,
     so the normal that opposes it is the one into the gas whatever the
     convention. The walls are at rest (rbs_cs_initialize) */
  const double seg_n = (coords[0] - start[0])*face_norm[0]
                     + (coords[1] - start[1])*face_norm[1]
                     + (coords[2] - start[2])*face_norm[2];
  const double nn = sqrt(face_norm[0]*face_norm[0] + face_norm[1]*face_norm[1]
                         + face_norm[2]*face_norm[2]);
  /* The hit: V⁻, Ω⁻ (6.0's particles carry no spin), n into the gas, a,
     the particle's grain key and this rank's stream */
  rbs_hit hit = RBS_HIT_INIT;
  if (nn > 0)
    for (int k = 0; k < 3; k++)
      hit.n[k] = (seg_n > 0 ? -face_norm[k] : face_norm[k])/nn;
  for (int k = 0; k < 3; k++)
    hit.V[k] = vel[k];
  hit.a = _set.half_size_factor*0.5*d;
  /* grain kept: the key of the particle's random value (drawn at its
     injection, carried from rank to rank and through a restart file: 6.0's
     one persistent mark of a particle); perHit: RBS_NO_KEY, a new grain per
     hit */
  if (_set.keep_grain) {
    const double random = cs_lagr_particle_get_real(particle, p_am,
                                                    CS_LAGR_RANDOM_VALUE);
    uint64_t bits;
    memcpy(&bits, &random, sizeof(bits));
    hit.grain_key = rbs_grain_key(_set.grain_seed, bits, 0);
  }
  hit.rng = &_rng;   /* 13 uniforms whatever the path and the result */

  rbs_options options = RBS_OPTIONS_INIT;
  options.method = _set.method;
  options.interpolation = _set.interpolation;

  /* the first of the hit's 13 uniforms, for the record */
  rbs_rng peek = _rng;
  const double u0 = rbs_rng_uniform(&peek);

  /* the path is a pure function of the state: learnt before the draw, so
     the clock runs around the direct model's calls only */
  const int path = rbs_rebound_path(_table, &hit, &options);
  double t0 = 0;
  if (path == RBS_PATH_DIRECT)
    t0 = cs_timer_wtime();
  rbs_result result = RBS_RESULT_INIT;
  const int status = rbs_rebound(_table, _mix, &hit, &options, &result);
  const double *V = hit.V, *n = hit.n, *Vout = result.V;
  if (path == RBS_PATH_DIRECT) {
    _count.direct_seconds += cs_timer_wtime() - t0;
    _count.direct_path++;
  }
  else if (path == RBS_PATH_TABLE)
    _count.table_path++;
  _count.hits++;

  if (status != RBS_INVALID) {
    /* outside the grid: the direct model answers under auto and direct, the
       law at the nearest grid edge under table */
    const double speed = sqrt(V[0]*V[0] + V[1]*V[1] + V[2]*V[2]);
    const double sin_a = -(V[0]*n[0] + V[1]*n[1] + V[2]*n[2])/speed;
    const double alpha1 = asin(fmin(fmax(sin_a, -1.), 1.))*180./acos(-1.);
    if (speed < _speed_lo || speed > _speed_hi
        || alpha1 < _alpha1_lo || alpha1 > _alpha1_hi)
      _count.outside_grid++;
  }

  if (status == RBS_OK) {
    /* The rest of the step: the solver's rebound mirrors it; ours goes
       along V⁺ for the time the particle had left at |V⁻|, so the end
       point lies on the gas side of the wall whatever V⁺ is */
    const double rest = sqrt(cs_math_3_square_distance(coords, c_intersect));
    const double speed = sqrt(V[0]*V[0] + V[1]*V[1] + V[2]*V[2]);
    const double vs_n = vel_seen[0]*face_norm[0] + vel_seen[1]*face_norm[1]
                      + vel_seen[2]*face_norm[2];
    for (int k = 0; k < 3; k++) {
      start[k] = c_intersect[k] + RBS_CS_BC_EPSILON*(cell_cen[k] - c_intersect[k]);
      coords[k] = c_intersect[k] + Vout[k]*(rest/speed);
      vel[k] = Vout[k];
      /* the fluid velocity seen is mirrored, as the solver's rebound does */
      vel_seen[k] -= 2*vs_n*face_norm[k];
    }
    _count.rebounded++;
    *event_flag = *event_flag | CS_EVENT_REBOUND;
    *tracking_state = CS_LAGR_PART_TO_SYNC;
  }
  else if (status == RBS_TRAPPED || status == RBS_FAILED) {
    /* A failed direct rebound has no answer: the trapped policy applies,
       counted apart */
    if (status == RBS_TRAPPED) {
      _count.trapped++;
      _count.trapped_weight += weight;
    }
    else {
      _count.failed++;
      _count.failed_weight += weight;
    }
    particles->n_part_dep += 1;
    particles->weight_dep += weight;
    cs_lagr_particles_set_flag(particles, p_id, CS_LAGR_PART_DEPOSITED);
    *event_flag = *event_flag | CS_EVENT_DEPOSITION;
    if (_set.remove_trapped) {
      /* as the solver's CS_LAGR_DEPO1: deposited and removed */
      for (int k = 0; k < 3; k++)
        coords[k] = c_intersect[k];
      *event_flag = *event_flag | CS_EVENT_OUTFLOW;
      *tracking_state = CS_LAGR_PART_OUT;
    }
    else {
      /* as the solver's CS_LAGR_DEPO2 without resuspension: kept, at rest
         next to the hit point */
      for (int k = 0; k < 3; k++) {
        coords[k] = c_intersect[k] + RBS_CS_BC_EPSILON*(cell_cen[k] - c_intersect[k]);
        vel[k] = 0;
        vel_seen[k] = 0;
      }
      cs_lagr_particles_set_flag(particles, p_id, CS_LAGR_PART_FIXED);
      *tracking_state = CS_LAGR_PART_STUCK;
    }
  }
  else {
    /* Not moving into the wall (or a degenerate face): the solver's own
       rebound, mirror image, counted */
    _count.invalid++;
    double disp[3], dn = 0, vn = 0, vs_n = 0;
    for (int k = 0; k < 3; k++) {
      disp[k] = coords[k] - c_intersect[k];
      dn += disp[k]*face_norm[k];
      vn += vel[k]*face_norm[k];
      vs_n += vel_seen[k]*face_norm[k];
    }
    for (int k = 0; k < 3; k++) {
      start[k] = c_intersect[k] + RBS_CS_BC_EPSILON*(cell_cen[k] - c_intersect[k]);
      coords[k] -= 2*dn*face_norm[k];
      vel[k] -= 2*vn*face_norm[k];
      vel_seen[k] -= 2*vs_n*face_norm[k];
    }
    *event_flag = *event_flag | CS_EVENT_REBOUND;
    *tracking_state = CS_LAGR_PART_TO_SYNC;
  }

  _record_hit(b_zone_id, d, &hit, &result, path, u0);
  _count.cpu_seconds += _thread_cpu_seconds() - cpu0;
}
