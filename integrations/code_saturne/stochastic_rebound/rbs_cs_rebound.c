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
#include "bft_mem.h"
#include "bft_printf.h"

#include "cs_ale.h"
#include "cs_boundary_zone.h"
#include "cs_math.h"
#include "cs_mesh.h"
#include "cs_mesh_quantities.h"
#include "cs_parall.h"
#include "cs_time_step.h"
#include "cs_timer.h"
#include "cs_turbomachinery.h"

#include "cs_lagr.h"
#include "cs_lagr_event.h"
#include "cs_lagr_particle.h"
#include "cs_lagr_prototypes.h"
#include "cs_lagr_stat.h"
#include "cs_lagr_tracking.h"

#include "rebound_scatter.h"
#include "rbs_cs_rebound.h"

/* rbs_result's work on the wall of the table path (1.3 gives it on the
   direct path only) */
#if RBS_VERSION_NUMBER < 1004000
#error "rbs_cs_rebound.c needs rebound_scatter.h 1.4 or later"
#endif

/*----------------------------------------------------------------------------
 * Settings, state and counters of this rank
 *----------------------------------------------------------------------------*/

#define RBS_CS_DEFAULT_SETUP "rebound_scatter.conf"
#define RBS_CS_MAX_WEIGHTS 256     /* shape:weight items of the weights setting */
#define RBS_CS_LINE 4096
#define RBS_CS_TEXT (5*RBS_CS_LINE)   /* a rule in words (_describe) */
#define RBS_CS_WHERE (3*RBS_CS_LINE)  /* the file and section of a message */

/* The solver's own rebound restarts the next segment this fraction of the
 * way from the hit point to the cell centre (bc_epsilon of 6.0's
 * cs_lagr_tracking.c): so does ours */
#define RBS_CS_BC_EPSILON 1.e-2

/* The hits files' title, and the interaction column of the hits a table or
   the direct model answered: hit_records.py reads files without that column
   as the title's */
#define RBS_CS_TITLE "code_saturne rebound-scatter"

/* What a zone does with the particles that hit it (the type of its section) */
typedef enum {
  RBS_CS_DRAWN,      /* rebound-scatter: the table or the direct model */
  RBS_CS_REBOUND,    /* as CS_LAGR_REBOUND: elastic, specular */
  RBS_CS_DEPOSIT,    /* as CS_LAGR_DEPO2 without resuspension */
  RBS_CS_OUTLET      /* as CS_LAGR_OUTLET */
} rbs_cs_type_t;

static const char *const _type_names[] = {"rebound-scatter", "rebound",
                                          "deposit", "outlet"};
static const int _type_codes[] = {RBS_CS_DRAWN, RBS_CS_REBOUND,
                                  RBS_CS_DEPOSIT, RBS_CS_OUTLET};

static const char *const _method_names[] = {"auto", "table", "direct"};
static const int _method_codes[] = {RBS_METHOD_AUTO, RBS_METHOD_TABLE,
                                    RBS_METHOD_DIRECT};
static const char *const _interp_names[] = {"scaled", "stochastic"};
static const int _interp_codes[] = {RBS_INTERPOLATION_SCALED,
                                    RBS_INTERPOLATION_STOCHASTIC};
static const char *const _trapped_names[] = {"deposit", "remove"};
static const int _trapped_codes[] = {0, 1};

/* A table, opened once however many zones draw from it */
typedef struct {
  char        path[RBS_CS_LINE];       /* as the settings resolve it */
  dev_t       dev;                     /* the file, whatever the spelling of */
  ino_t       ino;                     /*   its path */
  rbs_table  *table;
  char        wall[RBS_CS_LINE];       /* its wall's name, else its law family */
  double      alpha1_lo, alpha1_hi, speed_lo, speed_hi;
  double      law_lo, law_hi;           /* the |V| its wall law holds over */
  double      roughness;                /* its wall's (deg; 0: smooth), the
                                           default of its zones */
} rbs_cs_table_t;

/* What a zone does; rule 0 holds the global settings, the rule of the
   CS_LAGR_BC_USER zones no section names */
typedef struct {
  int         type;                    /* rbs_cs_type_t */
  int         table;                   /* in _tables; -1: a stock type, or no
                                          global table */
  rbs_mix    *mix;                     /* sized by the table (rbs_mix_new_*) */
  char        mix_name[RBS_CS_LINE];   /* "prism", "mix", "weights (...)" */
  int         method;                  /* rbs_method */
  int         interpolation;           /* rbs_interpolation */
  int         remove_trapped;          /* 0: deposited, 1: removed */
  double      roughness_given;         /* roughness_deg as given (deg), or
                                          RBS_ROUGHNESS_OF_TABLE */
  double      roughness;               /* the one its hits are drawn with:
                                          the given one, else its table's
                                          wall's */
} rbs_cs_rule_t;

typedef struct {
  char        setup_path[RBS_CS_LINE];
  char        hits_dir[RBS_CS_LINE];        /* "" if no hit records */
  double      half_size_factor;             /* a = factor * d / 2 */
  uint64_t    seed;
  int         keep_grain;                   /* 1: kept, 0: a new grain per hit */
  uint64_t    grain_seed;                   /* the keys' seed */
  long long   max_hit_records;
  long long   hits_every;                   /* k: the 1st, (k+1)-th, ... hit */
} rbs_cs_settings_t;

/* The drawn hits (a table or the direct model answered) of all zones; the
   CPU time of every hit */
typedef struct {
  cs_gnum_t   hits, table_path, direct_path, rebounded, trapped, failed,
              invalid, outside_grid;
  double      trapped_weight, failed_weight, direct_seconds, cpu_seconds;
} rbs_cs_counters_t;

/* The counts per zone: the hits, each one of rebounded, stuck, removed,
   escaped or invalid; why a drawn hit did not rebound; its path; the drawn
   hits outside the grid of the zone's table, by cause; those outside the
   speeds its wall law holds over; the drawn hits that hit the wall again
   (rbs_result.wall_hits > 1) and those that reached RBS_MAX_WALL_HITS; the
   drawn hits without work on the wall (NaN: a table of format 4.0) */
enum {ZC_HITS, ZC_REBOUNDED, ZC_STUCK, ZC_REMOVED, ZC_ESCAPED, ZC_INVALID,
      ZC_TRAPPED, ZC_FAILED, ZC_TABLE, ZC_DIRECT, ZC_SPEED_BELOW,
      ZC_SPEED_ABOVE, ZC_ALPHA1_OUT, ZC_OUTSIDE_LAW, ZC_HIT_AGAIN, ZC_AT_CAP,
      ZC_NO_WORK, ZC_N};
static const char *const _zc_names[ZC_N] = {
  "hits", "rebounded", "stuck", "removed", "escaped", "invalid", "trapped",
  "failed", "table", "direct", "|V|<grid", "|V|>grid", "alpha1-out",
  "out-of-law", "hit-again", "at-cap", "no-work"};

/* The work on the wall per zone, summed over the drawn hits with work:
   statistical weight x mass x W_n, x W_t (J), and weight x mass (kg) */
enum {ZW_NORMAL, ZW_TANGENTIAL, ZW_MASS, ZW_N};

/* The boundary statistics (rbs_cs_define_statistics), per boundary face of
   the rank, over the drawn hits with work: weight x mass x W_n, x W_t (J),
   weight x mass (kg) and weight (the hits) */
enum {ST_WORK_NORMAL, ST_WORK_TANGENTIAL, ST_MASS, ST_HITS, ST_N};
static const char *const _stat_names[ST_N] = {
  "rbs_wall_work_normal", "rbs_wall_work_tangential", "rbs_wall_hit_mass",
  "rbs_wall_hits"};
static int _stat_ids[ST_N] = {ST_WORK_NORMAL, ST_WORK_TANGENTIAL, ST_MASS,
                              ST_HITS};   /* the data function's inputs */
static int        _stats_defined = 0;
static cs_lnum_t  _stat_n_faces = 0;
static cs_real_t *_stat_new[ST_N];  /* the hits since the solver's last
                                       update of its statistics */
static cs_real_t *_stat_sum[ST_N];  /* over the statistics' period */
static int        _stat_nt[ST_N] = {-1, -1, -1, -1};  /* the step of each
                                                         one's last update */

static int                 _initialized = 0;
static rbs_cs_settings_t   _set;
static rbs_cs_table_t     *_tables = NULL;
static int                 _n_tables = 0;
static rbs_cs_rule_t      *_rules = NULL;
static int                 _n_rules = 0;
static int                 _n_zones = 0;
static int                *_zone_rule = NULL;     /* per boundary zone; -1 none */
static int                *_zone_listed = NULL;   /* CS_LAGR_BC_USER or named
                                                     when initialized */
static cs_gnum_t          *_zone_count = NULL;    /* ZC_N per zone */
static double             *_zone_work = NULL;     /* ZW_N per zone */
static rbs_rng             _rng;
static FILE               *_hits = NULL;
static long long           _n_recorded = 0;
static unsigned long long  _n_recordable = 0;   /* hits_every counts these */
static rbs_cs_counters_t   _count;

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
 * Reading the settings: global keys, then [zone NAME] sections
 *----------------------------------------------------------------------------*/

/* A section's keys first: the others are global only */
static const char *_keys[] = {"type", "table", "shape", "weights", "method",
                              "interpolation", "trapped", "roughness_deg",
                              "seed", "half_size_factor", "hits",
                              "max_hit_records", "hits_every", "grain",
                              "grain_seed"};
#define RBS_CS_N_KEYS (sizeof(_keys)/sizeof(_keys[0]))
#define RBS_CS_N_SECTION_KEYS 8

/* The global keys (before the first section) or one [zone NAME] section */
typedef struct {
  char  zone[RBS_CS_LINE];             /* "" for the global keys */
  int   line;                          /* of the section's header */
  char  values[RBS_CS_N_KEYS][RBS_CS_LINE];
  int   given[RBS_CS_N_KEYS];
} rbs_cs_block_t;

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

/* `path` made absolute: the records are read from other folders */
static void
_absolute(char dst[2*RBS_CS_LINE + 2], const char *path)
{
  char cwd[RBS_CS_LINE];
  if (path[0] != '/' && getcwd(cwd, sizeof(cwd)) != NULL)
    snprintf(dst, 2*RBS_CS_LINE + 2, "%s/%s", cwd, path);
  else
    snprintf(dst, 2*RBS_CS_LINE + 2, "%s", path);
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

static int
_key_index(const char *key)
{
  for (size_t i = 0; i < RBS_CS_N_KEYS; i++)
    if (strcmp(_keys[i], key) == 0)
      return (int)i;
  return -1;
}

/* A value the block gave, or NULL */
static const char *
_value(const rbs_cs_block_t *b, const char *key)
{
  const int i = _key_index(key);
  return b->given[i] ? b->values[i] : NULL;
}

/* Where a message points: the file, and the section if any */
static void
_where(const rbs_cs_block_t *b, char where[RBS_CS_WHERE])
{
  if (b->zone[0] == '\0')
    snprintf(where, RBS_CS_WHERE, "rebound-scatter settings %s",
             _set.setup_path);
  else
    snprintf(where, RBS_CS_WHERE, "rebound-scatter settings %s, [zone %s]",
             _set.setup_path, b->zone);
}

/* The file's blocks: the global keys, then one per section */
static rbs_cs_block_t *
_read_settings_file(const char *path, int *n_blocks)
{
  FILE *f = fopen(path, "r");
  if (f == NULL)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter: cannot read the settings file %s (%s); "
              "write one there or name it with RBS_CS_SETUP",
              path, strerror(errno));

  rbs_cs_block_t *blocks = NULL;
  int n = 1;
  BFT_MALLOC(blocks, 1, rbs_cs_block_t);
  memset(blocks, 0, sizeof(rbs_cs_block_t));
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

    if (s[0] == '[') {
      char header[RBS_CS_LINE];
      _copy(header, s);
      const size_t len = strlen(s);
      char *zone = NULL;
      if (s[len-1] == ']') {
        s[len-1] = '\0';
        char *inner = _trim(s + 1);
        if (strncmp(inner, "zone", 4) == 0 && isspace((unsigned char)inner[4]))
          zone = _trim(inner + 4);
      }
      if (zone == NULL || *zone == '\0')
        bft_error(__FILE__, __LINE__, 0,
                  "rebound-scatter settings %s, line %d: \"%s\" is not a "
                  "section header; a section is [zone NAME], NAME a boundary "
                  "zone", path, line_no, header);
      for (int k = 1; k < n; k++)
        if (strcmp(blocks[k].zone, zone) == 0)
          bft_error(__FILE__, __LINE__, 0,
                    "rebound-scatter settings %s, line %d: [zone %s] is "
                    "given twice (first at line %d)", path, line_no, zone,
                    blocks[k].line);
      BFT_REALLOC(blocks, n + 1, rbs_cs_block_t);
      memset(blocks + n, 0, sizeof(rbs_cs_block_t));
      _copy(blocks[n].zone, zone);
      blocks[n].line = line_no;
      n++;
      continue;
    }

    char *eq = strchr(s, '=');
    if (eq == NULL)
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s, line %d: \"%s\" is not "
                "key = value", path, line_no, s);
    *eq = '\0';
    const char *key = _trim(s), *val = _trim(eq + 1);
    rbs_cs_block_t *b = blocks + (n - 1);
    const int i = _key_index(key);
    if (b->zone[0] == '\0' && i < 0)
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s, line %d: unknown key \"%s\"; "
                "the keys are table, shape, weights, seed, method, "
                "interpolation, trapped, roughness_deg, half_size_factor, "
                "hits, max_hit_records, hits_every, grain, grain_seed, then "
                "[zone NAME] sections", path, line_no, key);
    if (b->zone[0] == '\0' && i == 0)
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s, line %d: type is a key of a "
                "[zone NAME] section, not a global one", path, line_no);
    if (b->zone[0] != '\0' && (i < 0 || i >= RBS_CS_N_SECTION_KEYS))
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s, line %d: %s \"%s\" in [zone %s]"
                "; the keys of a section are type, table, shape, weights, "
                "method, interpolation, trapped, roughness_deg", path, line_no,
                i < 0 ? "unknown key" : "global key", key, b->zone);
    if (b->given[i])
      bft_error(__FILE__, __LINE__, 0,
                "rebound-scatter settings %s, line %d: \"%s\" is given twice",
                path, line_no, key);
    b->given[i] = 1;
    _copy(b->values[i], val);
  }
  fclose(f);
  *n_blocks = n;
  return blocks;
}

static long long
_parse_integer(const char *where, const char *key, const char *text,
               long long lo, long long hi)
{
  char *end = NULL;
  errno = 0;
  long long v = strtoll(text, &end, 10);
  if (*text == '\0' || *end != '\0' || errno != 0 || v < lo || v > hi)
    bft_error(__FILE__, __LINE__, 0,
              "%s: %s must be an integer in [%lld, %lld], not \"%s\"",
              where, key, lo, hi, text);
  return v;
}

static int
_parse_choice(const char *where, const char *key, const char *text,
              const char *const names[], const int codes[], int n,
              const char *allowed)
{
  for (int i = 0; i < n; i++)
    if (strcmp(text, names[i]) == 0)
      return codes[i];
  bft_error(__FILE__, __LINE__, 0, "%s: %s must be %s, not \"%s\"",
            where, key, allowed, text);
  return -1;
}

/* roughness_deg: a number of degrees in [0, RBS_MAX_ROUGHNESS_DEG] (the
   library refuses every hit of a roughness out of range: refused here,
   before any hit) */
static double
_parse_roughness(const char *where, const char *text)
{
  char *end = NULL;
  const double v = strtod(text, &end);
  if (end == text || *end != '\0' || !(v >= 0 && v <= RBS_MAX_ROUGHNESS_DEG))
    bft_error(__FILE__, __LINE__, 0,
              "%s: roughness_deg must be in [0, %g] (degrees), not \"%s\"",
              where, RBS_MAX_ROUGHNESS_DEG, text);
  return v;
}

/* The roughness of a rule on its table: the given one, else the table's
   wall's */
static void
_resolve_roughness(rbs_cs_rule_t *rule)
{
  rule->roughness = rule->roughness_given >= 0 ? rule->roughness_given
                                               : _tables[rule->table].roughness;
}

static const char *
_name(int code, const char *const names[], const int codes[], int n)
{
  for (int i = 0; i < n; i++)
    if (codes[i] == code)
      return names[i];
  return "?";
}

/* The table of `text` (a path), opened on first use */
static int
_open_table(const char *where, const char *text)
{
  char path[RBS_CS_LINE], msg[512];
  _resolve(path, text);
  struct stat st;
  memset(&st, 0, sizeof(st));
  if (stat(path, &st) == 0)
    for (int i = 0; i < _n_tables; i++)
      if (_tables[i].dev == st.st_dev && _tables[i].ino == st.st_ino)
        return i;

  rbs_table *table = NULL;
  int err = rbs_table_open(path, &table, msg, sizeof(msg));
  if (err != RBS_OK)
    bft_error(__FILE__, __LINE__, 0,
              "%s: cannot open the table %s: %s: %s", where, path,
              rbs_status_string(err), msg);
  rbs_table_info info = RBS_TABLE_INFO_INIT;
  rbs_wall_info wall = RBS_WALL_INFO_INIT;
  err = rbs_table_info_get(table, &info);
  if (err == RBS_OK)
    err = rbs_table_wall(table, &wall);
  if (err != RBS_OK)
    bft_error(__FILE__, __LINE__, 0,
              "%s: cannot read the grids and the wall of the table %s: %s",
              where, path, rbs_status_string(err));

  BFT_REALLOC(_tables, _n_tables + 1, rbs_cs_table_t);
  rbs_cs_table_t *t = _tables + _n_tables;
  _copy(t->path, path);
  t->dev = st.st_dev;
  t->ino = st.st_ino;
  t->table = table;
  _copy(t->wall, (wall.name != NULL && wall.name[0] != '\0') ? wall.name
                 : (wall.family != NULL ? wall.family : ""));
  t->alpha1_lo = info.alpha1_min_deg;
  t->alpha1_hi = info.alpha1_max_deg;
  t->speed_lo = info.speed_min_m_s;
  t->speed_hi = info.speed_max_m_s;
  t->law_lo = wall.speed_range_m_s[0];
  t->law_hi = wall.speed_range_m_s[1];
  t->roughness = wall.roughness_deg;
  bft_printf("\n  rebound-scatter: opened the table %s (wall %s, its law "
             "holding for |V| %g-%g m/s, roughness %g deg; %d shapes, alpha1 "
             "%g-%g deg, |V| %g-%g m/s)\n", t->path, t->wall, t->law_lo,
             t->law_hi, t->roughness, rbs_table_n_shapes(table),
             t->alpha1_lo, t->alpha1_hi, t->speed_lo, t->speed_hi);
  return _n_tables++;
}

/* The rule's mix of its table: `weights` "prism:0.7, tetrahedron:0.3", else
   `shape`, else the equal mix */
static void
_make_mix(const char *where, rbs_cs_rule_t *rule, const char *shape,
          const char *weights)
{
  char msg[512];
  const rbs_table *table = _tables[rule->table].table;
  if (weights != NULL) {
    char buf[RBS_CS_LINE];
    const char *names[RBS_CS_MAX_WEIGHTS];
    double w[RBS_CS_MAX_WEIGHTS];
    int n = 0;
    snprintf(buf, sizeof(buf), "%s", weights);
    for (char *item = strtok(buf, ","); item != NULL;
         item = strtok(NULL, ",")) {
      char *colon = strchr(item, ':');
      char *end = NULL;
      if (colon == NULL || n == RBS_CS_MAX_WEIGHTS)
        bft_error(__FILE__, __LINE__, 0,
                  "%s: weights must be up to %d shape:weight items separated "
                  "by commas, not \"%s\"", where, RBS_CS_MAX_WEIGHTS, weights);
      *colon = '\0';
      names[n] = _trim(item);
      w[n] = strtod(_trim(colon + 1), &end);
      if (end == _trim(colon + 1) || *end != '\0')
        bft_error(__FILE__, __LINE__, 0,
                  "%s: the weight of %s must be a number, not \"%s\"",
                  where, names[n], _trim(colon + 1));
      n++;
    }
    rule->mix = rbs_mix_new_from_weights(table, n, names, w, msg,
                                         sizeof(msg));
    if (rule->mix == NULL)
      bft_error(__FILE__, __LINE__, 0, "%s: bad weights \"%s\": %s",
                where, weights, msg);
    snprintf(rule->mix_name, sizeof(rule->mix_name), "weights (%s)",
             weights);
  }
  else {
    if (shape == NULL)
      shape = "mix";
    rule->mix = rbs_mix_new_from_shape(table, shape, msg, sizeof(msg));
    if (rule->mix == NULL)
      bft_error(__FILE__, __LINE__, 0, "%s: bad shape \"%s\": %s",
                where, shape, msg);
    _copy(rule->mix_name, shape);
  }
}

/* The name of a Lagrangian zone type (cs_lagr_bc_type_t), for a message */
static const char *
_lagr_type_name(int type)
{
  static const char *const names[] = {
    "CS_LAGR_BC_UNDEFINED", "CS_LAGR_SYM", "CS_LAGR_INLET", "CS_LAGR_OUTLET",
    "CS_LAGR_REBOUND", "CS_LAGR_DEPO1", "CS_LAGR_DEPO2", "CS_LAGR_DEPO_DLVO",
    "CS_LAGR_FOULING", "CS_LAGR_BC_USER"};
  if (type >= 0 && type <= CS_LAGR_BC_USER)
    return names[type];
  return "none yet";
}

/* One [zone NAME] section: its zone, which must be CS_LAGR_BC_USER, and
   what it does, each key defaulting to the global one */
static void
_read_section(const rbs_cs_block_t *b, const rbs_cs_block_t *global,
              const int zone_type[], int n_lagr_zones)
{
  char where[RBS_CS_WHERE];
  _where(b, where);

  const cs_zone_t *z = cs_boundary_zone_by_name_try(b->zone);
  if (z == NULL) {
    char names[RBS_CS_LINE] = "";
    for (int i = 1; i < _n_zones; i++) {
      const size_t used = strlen(names);
      snprintf(names + used, sizeof(names) - used, "%s%s", i > 1 ? ", " : "",
               cs_boundary_zone_by_id(i)->name);
    }
    bft_error(__FILE__, __LINE__, 0,
              "%s: no boundary zone is named %s; the zones are %s",
              where, b->zone, names);
  }
  const int type_now = z->id < n_lagr_zones ? zone_type[z->id] : -1;
  if (type_now != CS_LAGR_BC_USER)
    bft_error(__FILE__, __LINE__, 0,
              "%s: the zone's Lagrangian type is %s, not CS_LAGR_BC_USER: "
              "give it CS_LAGR_BC_USER in cs_user_lagr_boundary_conditions "
              "before calling rbs_cs_initialize()", where,
              _lagr_type_name(type_now));

  BFT_REALLOC(_rules, _n_rules + 1, rbs_cs_rule_t);
  rbs_cs_rule_t *rule = _rules + _n_rules;
  *rule = _rules[0];
  rule->table = -1;
  rule->mix = NULL;
  _copy(rule->mix_name, "");
  const char *type = _value(b, "type");
  rule->type = _parse_choice(where, "type", type ? type : "rebound-scatter",
                             _type_names, _type_codes, 4,
                             "rebound-scatter, rebound, deposit or outlet");
  if (rule->type != RBS_CS_DRAWN) {
    for (int i = 1; i < RBS_CS_N_SECTION_KEYS; i++)
      if (b->given[i])
        bft_error(__FILE__, __LINE__, 0,
                  "%s: a zone of type %s takes no key but type, not \"%s\"",
                  where, type, _keys[i]);
  }
  else {
    const char *table = _value(b, "table");
    if (table == NULL)
      table = _value(global, "table");
    if (table == NULL || table[0] == '\0')
      bft_error(__FILE__, __LINE__, 0,
                "%s: no table (table = path of a table written by tablegen "
                "build), in the section or before the first one", where);
    const char *shape = _value(b, "shape"), *weights = _value(b, "weights");
    if (shape != NULL && weights != NULL)
      bft_error(__FILE__, __LINE__, 0,
                "%s: shape and weights are both given: give one of them",
                where);
    if (shape == NULL && weights == NULL) {
      shape = _value(global, "shape");
      weights = _value(global, "weights");
    }
    rule->table = _open_table(where, table);
    _make_mix(where, rule, shape, weights);
    const char *method = _value(b, "method");
    if (method != NULL)
      rule->method = _parse_choice(where, "method", method, _method_names,
                                   _method_codes, 3, "auto, table or direct");
    const char *interp = _value(b, "interpolation");
    if (interp != NULL)
      rule->interpolation = _parse_choice(where, "interpolation", interp,
                                          _interp_names, _interp_codes, 2,
                                          "scaled or stochastic");
    const char *trapped = _value(b, "trapped");
    if (trapped != NULL)
      rule->remove_trapped = _parse_choice(where, "trapped", trapped,
                                           _trapped_names, _trapped_codes, 2,
                                           "deposit or remove");
    const char *roughness = _value(b, "roughness_deg");
    if (roughness != NULL)
      rule->roughness_given = _parse_roughness(where, roughness);
    _resolve_roughness(rule);
  }
  _zone_rule[z->id] = _n_rules;
  _zone_listed[z->id] = 1;
  _n_rules++;
}

static void
_read_settings(void)
{
  const char *env = getenv("RBS_CS_SETUP");
  snprintf(_set.setup_path, sizeof(_set.setup_path), "%s",
           (env != NULL && env[0] != '\0') ? env : RBS_CS_DEFAULT_SETUP);
  int n_blocks = 0;
  rbs_cs_block_t *blocks = _read_settings_file(_set.setup_path, &n_blocks);
  const rbs_cs_block_t *g = blocks;
  char where[RBS_CS_WHERE];
  _where(g, where);

  /* the seed: 0 to 2^63 - 1 (a text of digits, no sign) */
  const char *seed = _value(g, "seed");
  _set.seed = (seed == NULL) ? 1
    : (uint64_t)_parse_integer(where, "seed", seed, 0, 9223372036854775807LL);

  /* grain kept: a particle's key from its random value (module doc of
     docs/code_saturne.md); perHit: a new grain from the mix at every hit */
  static const char *const grain_names[] = {"kept", "perHit"};
  static const int grain_codes[] = {1, 0};
  const char *grain = _value(g, "grain");
  _set.keep_grain = _parse_choice(where, "grain", grain ? grain : "kept",
                                  grain_names, grain_codes, 2,
                                  "kept or perHit");
  const char *grain_seed = _value(g, "grain_seed");
  _set.grain_seed = (grain_seed == NULL) ? _set.seed
    : (uint64_t)_parse_integer(where, "grain_seed", grain_seed, 0,
                               9223372036854775807LL);

  const char *factor = _value(g, "half_size_factor");
  _set.half_size_factor = 1.0;
  if (factor != NULL) {
    char *end = NULL;
    _set.half_size_factor = strtod(factor, &end);
    if (end == factor || *end != '\0' || !(_set.half_size_factor > 0)
        || !isfinite(_set.half_size_factor))
      bft_error(__FILE__, __LINE__, 0,
                "%s: half_size_factor must be a finite number > 0, not "
                "\"%s\"", where, factor);
  }

  const char *hits = _value(g, "hits");
  if (hits != NULL && hits[0] != '\0')
    _resolve(_set.hits_dir, hits);
  else
    _set.hits_dir[0] = '\0';

  const char *max_rec = _value(g, "max_hit_records");
  _set.max_hit_records = (max_rec == NULL) ? 1000000
    : _parse_integer(where, "max_hit_records", max_rec, 0,
                     9223372036854775807LL);

  const char *every = _value(g, "hits_every");
  _set.hits_every = (every == NULL) ? 1
    : _parse_integer(where, "hits_every", every, 1, 9223372036854775807LL);

  /* Rule 0, the global settings: the defaults of every section */
  BFT_MALLOC(_rules, 1, rbs_cs_rule_t);
  _n_rules = 1;
  rbs_cs_rule_t *rule = _rules;
  memset(rule, 0, sizeof(*rule));
  rule->type = RBS_CS_DRAWN;
  rule->table = -1;
  const char *method = _value(g, "method");
  rule->method = _parse_choice(where, "method", method ? method : "auto",
                               _method_names, _method_codes, 3,
                               "auto, table or direct");
  const char *interp = _value(g, "interpolation");
  rule->interpolation = _parse_choice(where, "interpolation",
                                      interp ? interp : "scaled",
                                      _interp_names, _interp_codes, 2,
                                      "scaled or stochastic");
  const char *trapped = _value(g, "trapped");
  rule->remove_trapped = _parse_choice(where, "trapped",
                                       trapped ? trapped : "deposit",
                                       _trapped_names, _trapped_codes, 2,
                                       "deposit or remove");
  const char *roughness = _value(g, "roughness_deg");
  rule->roughness_given = (roughness == NULL) ? RBS_ROUGHNESS_OF_TABLE
    : _parse_roughness(where, roughness);
  const char *shape = _value(g, "shape"), *weights = _value(g, "weights");
  if (shape != NULL && weights != NULL)
    bft_error(__FILE__, __LINE__, 0,
              "%s: shape and weights are both given: give one of them",
              where);
  const char *table = _value(g, "table");
  if (table != NULL && table[0] != '\0') {
    rule->table = _open_table(where, table);
    _make_mix(where, rule, shape, weights);
    _resolve_roughness(rule);
  }

  /* The zones: a section's own rule, else the global one for a
     CS_LAGR_BC_USER zone (which needs the global table) */
  const cs_lagr_zone_data_t *bcs = cs_lagr_get_boundary_conditions();
  _n_zones = cs_boundary_zone_n_zones();
  BFT_MALLOC(_zone_rule, _n_zones, int);
  BFT_MALLOC(_zone_listed, _n_zones, int);
  BFT_MALLOC(_zone_count, (size_t)_n_zones*ZC_N, cs_gnum_t);
  memset(_zone_count, 0, (size_t)_n_zones*ZC_N*sizeof(cs_gnum_t));
  BFT_MALLOC(_zone_work, (size_t)_n_zones*ZW_N, double);
  memset(_zone_work, 0, (size_t)_n_zones*ZW_N*sizeof(double));
  for (int i = 0; i < _n_zones; i++) {
    _zone_rule[i] = -1;
    _zone_listed[i] = 0;
  }
  for (int k = 1; k < n_blocks; k++)
    _read_section(blocks + k, g, bcs->zone_type, bcs->n_zones);
  for (int i = 0; i < _n_zones; i++) {
    if (_zone_rule[i] >= 0)
      continue;
    const int user = i < bcs->n_zones && bcs->zone_type[i] == CS_LAGR_BC_USER;
    if (user && _rules[0].table < 0) {
      const char *zone = cs_boundary_zone_by_id(i)->name;
      bft_error(__FILE__, __LINE__, 0,
                "%s: no table (table = path of a table written by tablegen "
                "build) for the zone %s, of Lagrangian type CS_LAGR_BC_USER "
                "and named by no [zone %s] section", where, zone, zone);
    }
    _zone_rule[i] = _rules[0].table >= 0 ? 0 : -1;
    _zone_listed[i] = user;
  }
  BFT_FREE(blocks);
}

/* What a rule does, in words: `full` for the log and the hits files (the
   table's absolute path), else for the summary */
static void
_describe(const rbs_cs_rule_t *rule, int full, char *out, size_t size)
{
  if (rule->type != RBS_CS_DRAWN) {
    snprintf(out, size, "%s", _name(rule->type, _type_names, _type_codes, 4));
    return;
  }
  const rbs_cs_table_t *t = _tables + rule->table;
  if (!full) {
    snprintf(out, size, "rebound-scatter, wall %s", t->wall);
    return;
  }
  char table[2*RBS_CS_LINE + 2];
  _absolute(table, t->path);
  snprintf(out, size,
           "rebound-scatter, table %s, mix %s, method %s, interpolation %s, "
           "trapped %s, roughness %g deg%s, wall %s", table, rule->mix_name,
           _name(rule->method, _method_names, _method_codes, 3),
           _name(rule->interpolation, _interp_names, _interp_codes, 2),
           _trapped_names[rule->remove_trapped], rule->roughness,
           rule->roughness_given < 0 ? " (the table's)" : "", t->wall);
}

/*----------------------------------------------------------------------------
 * The hits file of this rank: the layout of the OpenFOAM adapter's
 *----------------------------------------------------------------------------*/

/* n as an English ordinal (1st, 2nd, 3rd, 4th, 11th, 21st) in `out` (32
   characters), for the hits file's words on hits_every */
static const char *
_ordinal(unsigned long long n, char out[32])
{
  const unsigned long long tens = n % 100;
  const char *suffix = (tens >= 11 && tens <= 13) ? "th"
                       : n % 10 == 1 ? "st"
                       : n % 10 == 2 ? "nd"
                       : n % 10 == 3 ? "rd" : "th";
  snprintf(out, 32, "%llu%s", n, suffix);
  return out;
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
  static const char ours[] = "# " RBS_CS_TITLE " hits:";
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
  /* the global settings: the global table ("none" if every zone names its
     own), its mix, the global method and interpolation */
  const rbs_cs_rule_t *g = _rules;
  char table[2*RBS_CS_LINE + 2] = "none";
  if (g->table >= 0)
    _absolute(table, _tables[g->table].path);
  fprintf(_hits,
          "%s seed %llu, stream %d, "
          "table %s, mix %s, halfSizeFactor %.17g, interpolation %s, "
          "method %s, spin tolerance %g, grain ",
          ours, (unsigned long long)_set.seed, rank, table,
          g->table >= 0 ? g->mix_name : "none", _set.half_size_factor,
          _name(g->interpolation, _interp_names, _interp_codes, 2),
          _name(g->method, _method_names, _method_codes, 3),
          RBS_SPIN_TOLERANCE);
  if (_set.keep_grain)
    fprintf(_hits, "kept (key seed %llu)\n",
            (unsigned long long)_set.grain_seed);
  else
    fprintf(_hits, "perHit\n");
  fprintf(_hits, "# ");
  if (_set.hits_every > 1) {
    /* a reader of the file must know it holds a sample */
    const unsigned long long k = (unsigned long long)_set.hits_every;
    char kth[32], second[32], third[32];
    fprintf(_hits,
            "Every %s hit (hits_every %llu): the 1st, %s, %s, ... of the hits "
            "this rank would record. ", _ordinal(k, kth), k,
            _ordinal(k + 1, second), _ordinal(2*k + 1, third));
  }
  fprintf(_hits,
          "V: incident velocity relative to the wall (at rest), Win: "
          "incident angular velocity (0: code_saturne 6.0's particles carry "
          "none), n: unit normal into the gas, Uw: wall velocity, patch: "
          "boundary zone, origProc/origId: -1 (6.0's particles carry no "
          "persistent id), path: 0 table, 1 direct model, -1 invalid or "
          "stock (on a rough wall, the last of its wall hits), Vout/Wout: "
          "rebound velocity and angular velocity, "
          "spin_ratio: |Win| a/|V|, u0: first uniform of the draw, key: the "
          "particle's grain key (from its random value; -1: a new grain per "
          "hit), shape: its shape (empty: drawn per hit), "
          "ratio_ba/ratio_cb/hand: its b/a, c/b and hand on the direct path "
          "(nan: the table path or not random), interaction: "
          RBS_CS_TITLE " or rebound (the zone's stock rebound; deposit and "
          "outlet hits are counted, not recorded), wall: the wall of the "
          "zone's table (a comma written ;). Zones:");
  char text[RBS_CS_TEXT];
  const char *separator = " ";
  for (int i = 0; i < _n_zones; i++)
    if (_zone_listed[i]) {
      _describe(_rules + _zone_rule[i], 1, text, sizeof(text));
      fprintf(_hits, "%s%s = %s", separator, cs_boundary_zone_by_id(i)->name,
              text);
      separator = "; ";
    }
  fprintf(_hits,
          "\ntime,rank,patch,origProc,origId,d,a,Vx,Vy,Vz,Winx,Winy,Winz,"
          "nx,ny,nz,Uwx,Uwy,Uwz,status,path,Voutx,Vouty,Voutz,Wx,Wy,Wz,"
          "spin_ratio,u0,key,shape,ratio_ba,ratio_cb,hand,interaction,wall\n");
}

static void
_record_hit(int b_zone_id, const rbs_cs_rule_t *rule, double d,
            const rbs_hit *hit, const rbs_result *result, int path, double u0)
{
  if (_hits == NULL || _n_recorded >= _set.max_hit_records)
    return;
  /* hits_every k keeps the 1st, (k+1)-th, ... hit of those this rank records */
  if (_n_recordable++ % (unsigned long long)_set.hits_every != 0)
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
  const char *interaction = "rebound";
  char wall[RBS_CS_LINE] = "";
  if (rule->type == RBS_CS_DRAWN) {
    const rbs_table *table = _tables[rule->table].table;
    interaction = RBS_CS_TITLE;
    /* the reader splits rows at commas: a wall named with one keeps it as a
       semicolon */
    _copy(wall, _tables[rule->table].wall);
    for (char *c = wall; *c != '\0'; c++)
      if (*c == ',')
        *c = ';';
    if (key >= 0) {
      int grain_shape = result->shape;
      rbs_grain grain = RBS_GRAIN_INIT;
      if ((grain_shape < 0 || path == RBS_PATH_DIRECT)
          && rbs_grain_info(table, rule->mix, key, &grain) == RBS_OK) {
        grain_shape = grain.shape;
        if (path == RBS_PATH_DIRECT) {
          ratio_ba = grain.ratio_ba;
          ratio_cb = grain.ratio_cb;
          hand = grain.hand;
        }
      }
      if (grain_shape >= 0)
        shape = rbs_table_shape_name(table, grain_shape);
    }
  }
  const double *V = hit->V, *n = hit->n;
  const double *Vout = result->V, *Wout = result->Omega;
  fprintf(_hits,
          "%.9g,%d,%s,-1,-1,%.9g,%.9g,%.17g,%.17g,%.17g,0,0,0,"
          "%.17g,%.17g,%.17g,0,0,0,%d,%d,"
          "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,0,%.17g,"
          "%lld,%s,%.17g,%.17g,%g,%s,%s\n",
          cs_glob_time_step->t_cur, cs_glob_rank_id < 0 ? 0 : cs_glob_rank_id,
          z->name, d, hit->a, V[0], V[1], V[2], n[0], n[1], n[2],
          result->status, path,
          Vout[0], Vout[1], Vout[2], Wout[0], Wout[1], Wout[2], u0,
          (long long)key, shape, ratio_ba, ratio_cb, hand, interaction, wall);
}

/*----------------------------------------------------------------------------
 * The boundary statistics: 6.0's Lagrangian mesh-based statistics of the
 * tracking events (cs_lagr_stat_mesh_define, as its boundary mass flux)
 *----------------------------------------------------------------------------*/

/* The arrays of this rank's boundary faces, zero on first use (the mesh is
   read after cs_user_lagr_model, where the statistics are defined) */
static void
_stat_allocate(void)
{
  if (_stat_n_faces > 0 || cs_glob_mesh->n_b_faces == 0)
    return;
  _stat_n_faces = cs_glob_mesh->n_b_faces;
  for (int s = 0; s < ST_N; s++) {
    BFT_MALLOC(_stat_new[s], _stat_n_faces, cs_real_t);
    BFT_MALLOC(_stat_sum[s], _stat_n_faces, cs_real_t);
    memset(_stat_new[s], 0, _stat_n_faces*sizeof(cs_real_t));
    memset(_stat_sum[s], 0, _stat_n_faces*sizeof(cs_real_t));
  }
}

/* The solver's update of the statistic *input (cs_lagr_moment_m_data_t),
   at each flush of its boundary events, at least once per time step after
   the particles moved: the hits since the last update are added to the
   statistic, which restarts with each step while the statistics are
   unsteady (isttio = 0, or up to the step nstist), as the solver's own */
static void
_stat_update(const void                 *input,
             const cs_lagr_event_set_t  *events,
             int                         location_id,
             int                         class_id,
             cs_real_t                   vals[])
{
  CS_UNUSED(events);
  CS_UNUSED(location_id);
  CS_UNUSED(class_id);
  const int s = *(const int *)input;
  const int nt = cs_glob_time_step->nt_cur;
  _stat_allocate();
  if (_stat_nt[s] != nt
      && (cs_glob_lagr_time_scheme->isttio == 0
          || nt <= cs_glob_lagr_stat_options->nstist))
    memset(_stat_sum[s], 0, _stat_n_faces*sizeof(cs_real_t));
  _stat_nt[s] = nt;
  for (cs_lnum_t f = 0; f < _stat_n_faces; f++) {
    _stat_sum[s][f] += _stat_new[s][f];
    _stat_new[s][f] = 0;
    vals[f] = _stat_sum[s][f];
  }
}

/* A drawn hit's work on the face, once the statistics have started (the
   step idstnt, when the solver starts updating them) */
static void
_stat_add(cs_lnum_t face_id, double weight, double mass, double wn,
          double wt)
{
  if (!_stats_defined
      || cs_glob_time_step->nt_cur < cs_glob_lagr_stat_options->idstnt)
    return;
  _stat_allocate();
  _stat_new[ST_WORK_NORMAL][face_id] += weight*mass*wn;
  _stat_new[ST_WORK_TANGENTIAL][face_id] += weight*mass*wt;
  _stat_new[ST_MASS][face_id] += weight*mass;
  _stat_new[ST_HITS][face_id] += weight;
}

/*----------------------------------------------------------------------------
 * Public functions
 *----------------------------------------------------------------------------*/

void
rbs_cs_define_statistics(void)
{
  if (_stats_defined)
    return;
  /* defined later, a statistic would miss the preparation of its values
     for the first step */
  if (cs_glob_time_step->nt_cur > cs_glob_time_step->nt_prev)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter: call rbs_cs_define_statistics() from "
              "cs_user_lagr_model, before the time steps");
  for (int s = 0; s < ST_N; s++)
    cs_lagr_stat_mesh_define(_stat_names[s], CS_MESH_LOCATION_BOUNDARY_FACES,
                             CS_LAGR_STAT_GROUP_TRACKING_EVENT, 0, 1,
                             _stat_update, _stat_ids + s, 0, -1);
  _stats_defined = 1;
}

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

  /* the library the solver loads may be older than the header it was
     compiled with */
  if (rbs_version_number() < 1004000)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter: the C runtime loaded is %s; rbs_cs_rebound.c "
              "needs 1.4 or later (the table path's work on the wall): "
              "rebuild it (integrations/code_saturne/build.sh)",
              rbs_version());

  memset(&_count, 0, sizeof(_count));
  _read_settings();

  /* Rank r draws stream r of the seed: no two ranks share draws, and rank 0
     of a parallel run draws the serial run's stream */
  const int rank = cs_glob_rank_id < 0 ? 0 : cs_glob_rank_id;
  rbs_rng_seed_stream(&_rng, _set.seed, (uint64_t)rank);
  _open_hits(rank);
  _initialized = 1;

  char text[RBS_CS_TEXT];
  for (int i = 0; i < _n_zones; i++)
    if (_zone_listed[i]) {
      _describe(_rules + _zone_rule[i], 1, text, sizeof(text));
      bft_printf("  rebound-scatter: zone %s = %s\n",
                 cs_boundary_zone_by_id(i)->name, text);
    }
  bft_printf("  rebound-scatter: a = %g*d/2, spin tolerance %g (method "
             "auto), seed %llu (rank r draws stream r), grain %s%s%s\n",
             _set.half_size_factor, RBS_SPIN_TOLERANCE,
             (unsigned long long)_set.seed,
             _set.keep_grain ? "kept (a particle's key from grain_seed and "
                               "its random value)"
                             : "perHit (a new grain from the mix at every hit)",
             _hits != NULL ? ", hits in " : "", _set.hits_dir);
}

void
rbs_cs_finalize(void)
{
  /* the statistics' arrays: the solver's updates allocate them whether or
     not a zone draws */
  for (int k = 0; k < ST_N; k++) {
    BFT_FREE(_stat_new[k]);
    BFT_FREE(_stat_sum[k]);
  }
  _stat_n_faces = 0;
  if (!_initialized)
    return;
  cs_gnum_t c[8] = {_count.hits, _count.table_path, _count.direct_path,
                    _count.rebounded, _count.trapped, _count.failed,
                    _count.invalid, _count.outside_grid};
  double w[4] = {_count.trapped_weight, _count.failed_weight,
                 _count.direct_seconds, _count.cpu_seconds};
  cs_parall_counter(c, 8);
  cs_parall_sum(4, CS_DOUBLE, w);
  cs_parall_counter(_zone_count, _n_zones*ZC_N);
  cs_parall_sum(_n_zones*ZW_N, CS_DOUBLE, _zone_work);

  /* the trapped policy of the zones that draw, if they share one; the work
     on their walls */
  cs_gnum_t all_hits = 0, no_work = 0;
  double work[ZW_N] = {0, 0, 0};
  int policy = -1;
  size_t width = 4;
  for (int i = 0; i < _n_zones; i++) {
    const cs_gnum_t *zc = _zone_count + (size_t)i*ZC_N;
    all_hits += zc[ZC_HITS];
    no_work += zc[ZC_NO_WORK];
    for (int k = 0; k < ZW_N; k++)
      work[k] += _zone_work[(size_t)i*ZW_N + k];
    if (!_zone_listed[i] && zc[ZC_HITS] == 0)
      continue;
    width = CS_MAX(width, strlen(cs_boundary_zone_by_id(i)->name));
    const rbs_cs_rule_t *rule = _rules + _zone_rule[i];
    if (rule->type == RBS_CS_DRAWN)
      policy = (policy == -1 || policy == rule->remove_trapped)
               ? rule->remove_trapped : 2;
  }
  static const char *const policies[] = {
    "deposited", "removed", "deposited or removed (per zone)"};
  const char *trapped = policies[policy < 0 ? _rules[0].remove_trapped
                                            : policy];
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
             "    - CPU time in the hits         = %g s (%g us per hit, "
             "every zone's)\n"
             "    - work on the walls, normal and tangential = %g J, %g J "
             "(%llu hits without work: a table of format 4.0)\n",
             _rules[0].table >= 0 ? _rules[0].mix_name : "tables per zone",
             (unsigned long long)c[0], (unsigned long long)c[1],
             (unsigned long long)c[2], c[2] > 0 ? 1e6*w[2]/c[2] : 0.,
             (unsigned long long)c[3], trapped, (unsigned long long)c[4], w[0],
             trapped, (unsigned long long)c[5], w[1], (unsigned long long)c[6],
             (unsigned long long)c[7], w[3],
             all_hits > 0 ? 1e6*w[3]/all_hits : 0., work[ZW_NORMAL],
             work[ZW_TANGENTIAL], (unsigned long long)no_work);

  /* Per zone: the zones the adapter handles, a line each */
  char line[RBS_CS_TEXT], text[RBS_CS_TEXT];
  int used = snprintf(line, sizeof(line), "      %-*s", (int)width, "zone");
  for (int k = 0; k < ZC_N; k++)
    used += snprintf(line + used, sizeof(line) - used, " %10s", _zc_names[k]);
  used += snprintf(line + used, sizeof(line) - used, " %10s %12s %12s",
                   "roughness", "Wn(J/kg)", "Wt(J/kg)");
  bft_printf("    Per zone (hits; their fate; the path; hits outside the "
             "table's grid: |V| below, |V| above, alpha1 outside; outside "
             "the wall law's speeds; hits that hit the wall again, and those "
             "that reached %d wall hits; hits without work on the wall; the "
             "wall's roughness, deg; the mean work on the wall per unit "
             "particle mass, normal and tangential, weighted by the mass "
             "that hit, J/kg)\n"
             "%s  interaction\n", RBS_MAX_WALL_HITS, line);
  for (int i = 0; i < _n_zones; i++) {
    const cs_gnum_t *zc = _zone_count + (size_t)i*ZC_N;
    if (!_zone_listed[i] && zc[ZC_HITS] == 0)
      continue;
    used = snprintf(line, sizeof(line), "      %-*s", (int)width,
                    cs_boundary_zone_by_id(i)->name);
    for (int k = 0; k < ZC_N; k++)
      used += snprintf(line + used, sizeof(line) - used, " %10llu",
                       (unsigned long long)zc[k]);
    const rbs_cs_rule_t *rule = _rules + _zone_rule[i];
    const double *zw = _zone_work + (size_t)i*ZW_N;
    if (rule->type == RBS_CS_DRAWN)
      used += snprintf(line + used, sizeof(line) - used, " %10g",
                       rule->roughness);
    else
      used += snprintf(line + used, sizeof(line) - used, " %10s", "-");
    if (zw[ZW_MASS] > 0)
      used += snprintf(line + used, sizeof(line) - used, " %12.6g %12.6g",
                       zw[ZW_NORMAL]/zw[ZW_MASS],
                       zw[ZW_TANGENTIAL]/zw[ZW_MASS]);
    else
      used += snprintf(line + used, sizeof(line) - used, " %12s %12s", "-",
                       "-");
    _describe(rule, 0, text, sizeof(text));
    bft_printf("%s  %s\n", line, text);
  }

  if (_hits != NULL)
    fclose(_hits);
  _hits = NULL;
  for (int r = 0; r < _n_rules; r++)
    rbs_mix_free(_rules[r].mix);
  for (int t = 0; t < _n_tables; t++)
    rbs_table_close(_tables[t].table);
  BFT_FREE(_rules);
  BFT_FREE(_tables);
  BFT_FREE(_zone_rule);
  BFT_FREE(_zone_listed);
  BFT_FREE(_zone_count);
  BFT_FREE(_zone_work);
  _n_rules = _n_tables = _n_zones = 0;
  _initialized = 0;
}

/*----------------------------------------------------------------------------
 * What the solver's own zone types do (cs_lagr_tracking.c of 6.0), operation
 * for operation
 *----------------------------------------------------------------------------*/

/* CS_LAGR_REBOUND: the next segment starts next to the hit point, and the
   rest of the step, the velocity and the fluid velocity seen are mirrored in
   the face */
static void
_mirror(cs_real_t start[3], cs_real_t coords[3], cs_real_t vel[3],
        cs_real_t vel_seen[3], const cs_real_t face_norm[3],
        const cs_real_t c_intersect[3], const cs_real_t cell_cen[3])
{
  cs_real_t disp[3];
  for (int k = 0; k < 3; k++) {
    start[k] = c_intersect[k] + RBS_CS_BC_EPSILON*(cell_cen[k] - c_intersect[k]);
    disp[k] = coords[k] - c_intersect[k];
  }
  const cs_real_t dn = 2.*cs_math_3_dot_product(disp, face_norm);
  const cs_real_t vn = 2.*cs_math_3_dot_product(vel, face_norm);
  const cs_real_t sn = 2.*cs_math_3_dot_product(vel_seen, face_norm);
  for (int k = 0; k < 3; k++) {
    coords[k] -= dn*face_norm[k];
    vel[k] -= vn*face_norm[k];
    vel_seen[k] -= sn*face_norm[k];
  }
}

/* CS_LAGR_DEPO2 without resuspension: deposited and fixed, at rest next to
   the hit point */
static void
_deposit(cs_lagr_particle_set_t *particles, cs_lnum_t p_id, double weight,
         cs_real_t coords[3], cs_real_t vel[3], cs_real_t vel_seen[3],
         const cs_real_t c_intersect[3], const cs_real_t cell_cen[3],
         int *event_flag, cs_lagr_tracking_state_t *tracking_state)
{
  for (int k = 0; k < 3; k++) {
    coords[k] = c_intersect[k] + RBS_CS_BC_EPSILON*(cell_cen[k] - c_intersect[k]);
    vel[k] = 0;
    vel_seen[k] = 0;
  }
  particles->n_part_dep += 1;
  particles->weight_dep += weight;
  cs_lagr_particles_set_flag(particles, p_id,
                             CS_LAGR_PART_DEPOSITED | CS_LAGR_PART_FIXED);
  *event_flag = *event_flag | CS_EVENT_DEPOSITION;
  *tracking_state = CS_LAGR_PART_STUCK;
}

/* CS_LAGR_DEPO1: deposited and removed at the hit point */
static void
_remove(cs_lagr_particle_set_t *particles, cs_lnum_t p_id, double weight,
        cs_real_t coords[3], const cs_real_t c_intersect[3], int *event_flag,
        cs_lagr_tracking_state_t *tracking_state)
{
  for (int k = 0; k < 3; k++)
    coords[k] = c_intersect[k];
  particles->n_part_dep += 1;
  particles->weight_dep += weight;
  cs_lagr_particles_set_flag(particles, p_id, CS_LAGR_PART_DEPOSITED);
  *event_flag = *event_flag | CS_EVENT_DEPOSITION | CS_EVENT_OUTFLOW;
  *tracking_state = CS_LAGR_PART_OUT;
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
  rbs_cs_initialize();
  const double cpu0 = _thread_cpu_seconds();

  /* A zone made CS_LAGR_BC_USER after rbs_cs_initialize() gets the global
     settings, which need the global table */
  const int rule_id = _zone_rule[b_zone_id];
  if (rule_id < 0)
    bft_error(__FILE__, __LINE__, 0,
              "rebound-scatter settings %s: no table (table = path of a "
              "table written by tablegen build) for the zone %s, made "
              "CS_LAGR_BC_USER after rbs_cs_initialize() and named by no "
              "[zone] section", _set.setup_path,
              cs_boundary_zone_by_id(b_zone_id)->name);
  const rbs_cs_rule_t *rule = _rules + rule_id;
  cs_gnum_t *zc = _zone_count + (size_t)b_zone_id*ZC_N;
  zc[ZC_HITS]++;

  const cs_lagr_attribute_map_t *p_am = particles->p_am;
  unsigned char *particle = particles->p_buffer + p_am->extents * p_id;
  cs_real_t *coords = cs_lagr_particle_attr(particle, p_am, CS_LAGR_COORDS);
  cs_real_t *vel = cs_lagr_particle_attr(particle, p_am, CS_LAGR_VELOCITY);
  cs_real_t *vel_seen = cs_lagr_particle_attr(particle, p_am,
                                              CS_LAGR_VELOCITY_SEEN);
  const double d = cs_lagr_particle_get_real(particle, p_am, CS_LAGR_DIAMETER);
  const double weight = cs_lagr_particle_get_real(particle, p_am,
                                                  CS_LAGR_STAT_WEIGHT);
  const double mass = cs_lagr_particle_get_real(particle, p_am, CS_LAGR_MASS);
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

  if (rule->type == RBS_CS_DEPOSIT) {
    _deposit(particles, p_id, weight, coords, vel, vel_seen, c_intersect,
             cell_cen, event_flag, tracking_state);
    zc[ZC_STUCK]++;
    _count.cpu_seconds += _thread_cpu_seconds() - cpu0;
    return;
  }
  if (rule->type == RBS_CS_OUTLET) {
    /* as CS_LAGR_OUTLET: the particle leaves at the hit point */
    for (int k = 0; k < 3; k++)
      coords[k] = c_intersect[k];
    *event_flag = *event_flag | CS_EVENT_OUTFLOW;
    *tracking_state = CS_LAGR_PART_OUT;
    zc[ZC_ESCAPED]++;
    _count.cpu_seconds += _thread_cpu_seconds() - cpu0;
    return;
  }

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
  rbs_result result = RBS_RESULT_INIT;

  if (rule->type == RBS_CS_REBOUND) {
    /* the solver's rebound, recorded: no draw, no grain */
    _mirror(start, coords, vel, vel_seen, face_norm, c_intersect, cell_cen);
    result.status = RBS_OK;
    for (int k = 0; k < 3; k++)
      result.V[k] = vel[k];
    *event_flag = *event_flag | CS_EVENT_REBOUND;
    *tracking_state = CS_LAGR_PART_TO_SYNC;
    zc[ZC_REBOUNDED]++;
    _record_hit(b_zone_id, rule, d, &hit, &result, RBS_PATH_NONE, NAN);
    _count.cpu_seconds += _thread_cpu_seconds() - cpu0;
    return;
  }

  const rbs_cs_table_t *table = _tables + rule->table;
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
  options.method = rule->method;
  options.interpolation = rule->interpolation;
  options.roughness_deg = rule->roughness;

  /* the first of the hit's 13 uniforms, for the record */
  rbs_rng peek = _rng;
  const double u0 = rbs_rng_uniform(&peek);

  /* the path is a pure function of the state: learnt before the draw, so
     the clock runs around the direct model's calls only. On a rough wall
     each wall hit takes its own path: the last one's is counted (a hit that
     hits again ends on the direct model under auto), and the clock runs
     around every hit */
  const int rough = rule->roughness > 0;
  const int mean_path = rbs_rebound_path(table->table, &hit, &options);
  double t0 = 0;
  if (rough || mean_path == RBS_PATH_DIRECT)
    t0 = cs_timer_wtime();
  const int status = rbs_rebound(table->table, rule->mix, &hit, &options,
                                 &result);
  const int path = (rough && result.path != RBS_PATH_NONE) ? result.path
                                                           : mean_path;
  const double *V = hit.V, *n = hit.n, *Vout = result.V;
  if (path == RBS_PATH_DIRECT) {
    _count.direct_seconds += cs_timer_wtime() - t0;
    _count.direct_path++;
    zc[ZC_DIRECT]++;
  }
  else if (path == RBS_PATH_TABLE) {
    _count.table_path++;
    zc[ZC_TABLE]++;
  }
  _count.hits++;
  zc[ZC_HIT_AGAIN] += result.wall_hits > 1;
  zc[ZC_AT_CAP] += result.wall_hits >= RBS_MAX_WALL_HITS;

  if (status != RBS_INVALID) {
    /* outside the grid, by cause: the direct model answers under auto and
       direct, the law at the nearest grid edge under table */
    const double speed = sqrt(V[0]*V[0] + V[1]*V[1] + V[2]*V[2]);
    const double sin_a = -(V[0]*n[0] + V[1]*n[1] + V[2]*n[2])/speed;
    const double alpha1 = asin(fmin(fmax(sin_a, -1.), 1.))*180./acos(-1.);
    const int below = speed < table->speed_lo;
    const int above = speed > table->speed_hi;
    const int alpha1_out = alpha1 < table->alpha1_lo
                           || alpha1 > table->alpha1_hi;
    zc[ZC_SPEED_BELOW] += below;
    zc[ZC_SPEED_ABOVE] += above;
    zc[ZC_ALPHA1_OUT] += alpha1_out;
    zc[ZC_OUTSIDE_LAW] += speed < table->law_lo || speed > table->law_hi;
    if (below || above || alpha1_out)
      _count.outside_grid++;

    /* The work on the wall (docs/model.md §4.7), J/kg; a table of format 4.0
       holds none (NaN): such a hit is counted, and left out of the sums */
    const double wn = result.wall_work_normal;
    const double wt = result.wall_work_tangential;
    if (isfinite(wn) && isfinite(wt)) {
      double *zw = _zone_work + (size_t)b_zone_id*ZW_N;
      zw[ZW_NORMAL] += weight*mass*wn;
      zw[ZW_TANGENTIAL] += weight*mass*wt;
      zw[ZW_MASS] += weight*mass;
      _stat_add(face_id, weight, mass, wn, wt);
    }
    else
      zc[ZC_NO_WORK]++;
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
    zc[ZC_REBOUNDED]++;
    *event_flag = *event_flag | CS_EVENT_REBOUND;
    *tracking_state = CS_LAGR_PART_TO_SYNC;
  }
  else if (status == RBS_TRAPPED || status == RBS_FAILED) {
    /* A failed direct rebound has no answer: the trapped policy applies,
       counted apart */
    if (status == RBS_TRAPPED) {
      _count.trapped++;
      _count.trapped_weight += weight;
      zc[ZC_TRAPPED]++;
    }
    else {
      _count.failed++;
      _count.failed_weight += weight;
      zc[ZC_FAILED]++;
    }
    if (rule->remove_trapped) {
      _remove(particles, p_id, weight, coords, c_intersect, event_flag,
              tracking_state);
      zc[ZC_REMOVED]++;
    }
    else {
      _deposit(particles, p_id, weight, coords, vel, vel_seen, c_intersect,
               cell_cen, event_flag, tracking_state);
      zc[ZC_STUCK]++;
    }
  }
  else {
    /* Not moving into the wall (or a degenerate face): the solver's own
       rebound, mirror image, counted */
    _count.invalid++;
    zc[ZC_INVALID]++;
    _mirror(start, coords, vel, vel_seen, face_norm, c_intersect, cell_cen);
    *event_flag = *event_flag | CS_EVENT_REBOUND;
    *tracking_state = CS_LAGR_PART_TO_SYNC;
  }

  _record_hit(b_zone_id, rule, d, &hit, &result, path, u0);
  _count.cpu_seconds += _thread_cpu_seconds() - cpu0;
}
