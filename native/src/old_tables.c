/*
 * old_tables.c: reading what tables written before format 3.3 leave out (data_schema.table._direct_model_attributes):
 * the aspect-ratio law from the stored build configuration (TOML text, as tablegen's to_toml writes it) when the
 * grid attributes aspect_ratio_* are absent, and the values every build used for the direct model's tolerances
 * and, at κ = 0.3, its second-moment factors when those attributes are absent. Since 3.3 a table records all of
 * them and loader.c reads nothing here.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

/* the direct model's tolerances every build used before tables recorded them, and s per shape code at
 * κ = 0.3 (data_schema.table.BUILT_WITH_TOLERANCES, BUILT_WITH_KAPPA, BUILT_WITH_SECOND_MOMENT_FACTORS) */
#define BUILT_WITH_CONTACT_TOL 1e-10
#define BUILT_WITH_SET_TOL 1e-9
#define BUILT_WITH_MAX_STEPS 100000
#define BUILT_WITH_KAPPA 0.3
static const double BUILT_WITH_SECOND_MOMENT_FACTORS[RBS_N_FAMILIES] = {
    0.2, 0.33333333333333337, 0.3309571404654277, 0.20000000000000004};
static const char *const ASPECT_KEYS[4] = {"mean", "sd", "low", "high"};

void rbs_built_with_tolerances(double *contact_tol, double *set_tol, long long *max_steps)
{
    *contact_tol = BUILT_WITH_CONTACT_TOL;
    *set_tol = BUILT_WITH_SET_TOL;
    *max_steps = BUILT_WITH_MAX_STEPS;
}

void rbs_built_with_second_moment_factors(double kappa, double kfac[RBS_N_FAMILIES])
{
    for (int k = 0; k < RBS_N_FAMILIES; k++) kfac[k] = kappa == BUILT_WITH_KAPPA ? BUILT_WITH_SECOND_MOMENT_FACTORS[k] : NAN;
}

/* p past spaces and tabs */
static const char *skip_blanks(const char *p)
{
    while (*p == ' ' || *p == '\t') p++;
    return p;
}

/* `key = number` pairs of the aspect-ratio law from p up to `end` (an inline table's '}' or a line's end) */
static void parse_aspect_pairs(const char *p, const char *end, double aspect[4])
{
    while (p < end) {
        p = skip_blanks(p);
        for (int k = 0; k < 4; k++) {
            size_t len = strlen(ASPECT_KEYS[k]);
            const char *q = skip_blanks(p + len);
            if (strncmp(p, ASPECT_KEYS[k], len) == 0 && *q == '=') {
                char *after;
                double x = strtod(q + 1, &after);
                if (after != q + 1) aspect[k] = x;
            }
        }
        while (p < end && *p != ',' && *p != '\n') p++;
        p++;
    }
}

/* The inline table `aspect_ratio = {mean = ..., sd = ..., low = ..., high = ...}` of [simulation], or a
 * [simulation.aspect_ratio] table; what it does not give is left as it was. */
void rbs_config_aspect(const char *text, double aspect[4])
{
    int in_simulation = 0, in_law = 0;
    for (const char *line = text; line && *line; line = strchr(line, '\n') ? strchr(line, '\n') + 1 : NULL) {
        const char *p = skip_blanks(line), *eol = strchr(p, '\n');
        if (!eol) eol = p + strlen(p);
        if (*p == '[') {
            in_simulation = strncmp(p, "[simulation]", 12) == 0;
            in_law = strncmp(p, "[simulation.aspect_ratio]", 25) == 0;
        } else if (in_law) {
            parse_aspect_pairs(p, eol, aspect);
        } else if (in_simulation && strncmp(p, "aspect_ratio", 12) == 0) {
            const char *q = skip_blanks(p + 12);
            const char *close = strchr(q, '}');
            if (*q == '=' && *(q = skip_blanks(q + 1)) == '{' && close && close < eol) parse_aspect_pairs(q + 1, close, aspect);
        }
    }
}
