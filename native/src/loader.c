/*
 * loader.c: opening a table file (HDF5), the checks of data_schema (check_file, read_table), closing it (what a
 * loaded table tells about itself: table_info.c). The wall (group wall: its law family by name, WALL_FAMILIES) and
 * the direct model's parameters (group model) are read here, each one row of a compound type read by field name;
 * the kernel arrays are derived in layout.c; the shapes (group shapes) are read by shape_records.c; both read with
 * the helpers of hdf5_read.c (which calls neither). A table of format 3 (before rebound-scatter 1.0) is refused
 * with how to rebuild it (data_schema.table.check_table_file).
 *
 * Every error names the file and what is wrong with it; HDF5's own error printing is switched off
 * around each HDF5 call that may fail (H5E_BEGIN_TRY), so the library prints nothing.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "hdf5_read.h"
#include "shape_records.h"

#define TABLE_FILE_TYPE "rebound_table"

/* ------------------------------------------------------------------------- HDF5 helpers */

static int attribute_exists(hid_t where, const char *name)
{
    htri_t found = 0;
    H5E_BEGIN_TRY { found = H5Aexists(where, name); } H5E_END_TRY;
    return found > 0;
}

/* A string attribute (variable or fixed length) into out (truncated to size); 0 on success. */
static int read_string_attribute(hid_t where, const char *name, char *out, size_t size)
{
    int status = -1;
    hid_t attr = -1, type = -1, memtype = -1, space = -1;
    out[0] = '\0';
    H5E_BEGIN_TRY {
        attr = H5Aopen(where, name, H5P_DEFAULT);
        if (attr >= 0) type = H5Aget_type(attr);
        if (type >= 0) space = H5Aget_space(attr);
        if (type >= 0 && space >= 0 && H5Tget_class(type) == H5T_STRING && H5Sget_simple_extent_npoints(space) == 1) {
            if (H5Tis_variable_str(type) > 0) {
                char *text = NULL;
                memtype = H5Tcopy(H5T_C_S1);
                H5Tset_size(memtype, H5T_VARIABLE);
                H5Tset_cset(memtype, H5Tget_cset(type));
                if (H5Aread(attr, memtype, &text) >= 0 && text) {
                    snprintf(out, size, "%s", text);
                    H5free_memory(text);
                    status = 0;
                }
            } else {
                size_t length = H5Tget_size(type);
                char *text = calloc(length + 1, 1);
                memtype = H5Tcopy(H5T_C_S1);
                H5Tset_size(memtype, length + 1);
                H5Tset_strpad(memtype, H5T_STR_NULLTERM);
                if (text && H5Aread(attr, memtype, text) >= 0) {
                    snprintf(out, size, "%s", text);
                    status = 0;
                }
                free(text);
            }
        }
    } H5E_END_TRY;
    if (memtype >= 0) H5Tclose(memtype);
    if (space >= 0) H5Sclose(space);
    if (type >= 0) H5Tclose(type);
    if (attr >= 0) H5Aclose(attr);
    return status;
}

/* A numeric attribute of `count` elements (exactly) as `memtype`, of HDF5 class integer (or also float unless
 * `integer`: an integer attribute stored as a float is refused, as data_schema.table._number does); 0 on success. */
static int read_numeric_attribute(hid_t where, const char *name, hid_t memtype, void *out, hssize_t count, int integer)
{
    int status = -1;
    hid_t attr = -1, type = -1, space = -1;
    H5E_BEGIN_TRY {
        attr = H5Aopen(where, name, H5P_DEFAULT);
        if (attr >= 0) type = H5Aget_type(attr);
        if (type >= 0) space = H5Aget_space(attr);
        if (space >= 0 && H5Sget_simple_extent_npoints(space) == count
            && (H5Tget_class(type) == H5T_INTEGER || (!integer && H5Tget_class(type) == H5T_FLOAT))
            && H5Aread(attr, memtype, out) >= 0)
            status = 0;
    } H5E_END_TRY;
    if (space >= 0) H5Sclose(space);
    if (type >= 0) H5Tclose(type);
    if (attr >= 0) H5Aclose(attr);
    return status;
}

static int read_integer_attribute(loader *ld, hid_t where, const char *group, const char *name, long long *out)
{
    if (!attribute_exists(where, name)) return rbs_fail(ld, RBS_ERR_FORMAT, "missing attribute '%s' of group '%s'", name, group);
    if (read_numeric_attribute(where, name, H5T_NATIVE_LLONG, out, 1, 1) != 0)
        return rbs_fail(ld, RBS_ERR_FORMAT, "cannot read the attribute '%s' of group '%s' as one integer", name, group);
    return RBS_OK;
}

/* Open group `name` of the file; -1 (and the error set) if missing. */
static hid_t open_group(loader *ld, hid_t file, const char *name)
{
    hid_t group = -1;
    if (!rbs_link_exists(file, name)) {
        rbs_fail(ld, RBS_ERR_FORMAT, "missing group '%s'", name);
        return -1;
    }
    H5E_BEGIN_TRY { group = H5Gopen2(file, name, H5P_DEFAULT); } H5E_END_TRY;
    if (group < 0) rbs_fail(ld, RBS_ERR_FORMAT, "'%s' is not a readable group (truncated or corrupt?)", name);
    return group;
}

/* The shape names (a 1-D dataset of strings, 1 to RBS_TABLE_MAX_SHAPES of them) into the table. */
static int read_shapes(loader *ld, hid_t grid, rbs_table *t)
{
    int rank = 0;
    hsize_t dims[8];
    if (rbs_dataset_shape(ld, grid, "grid", "shapes", &rank, dims) != RBS_OK) return ld->code;
    if (rank != 1 || dims[0] < 1)
        return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'grid/shapes' must hold at least one shape name");
    if (dims[0] > RBS_TABLE_MAX_SHAPES)
        return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'grid/shapes' holds %llu shapes; a table may hold at most %d",
                        (unsigned long long)dims[0], RBS_TABLE_MAX_SHAPES);
    int n = (int)dims[0], ok = 0;
    t->shape_names = calloc((size_t)n, sizeof *t->shape_names);
    if (!t->shape_names) return rbs_fail(ld, RBS_ERR_MEMORY, "out of memory reading the shape names");
    hid_t ds = -1, type = -1, memtype = -1, space = -1;
    H5E_BEGIN_TRY {
        ds = H5Dopen2(grid, "shapes", H5P_DEFAULT);
        if (ds >= 0) type = H5Dget_type(ds);
        if (type >= 0 && H5Tget_class(type) == H5T_STRING) {
            memtype = H5Tcopy(H5T_C_S1);
            if (H5Tis_variable_str(type) > 0) {
                char **names = calloc((size_t)n, sizeof *names);
                H5Tset_size(memtype, H5T_VARIABLE);
                H5Tset_cset(memtype, H5Tget_cset(type));
                if (names && H5Dread(ds, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, names) >= 0) {
                    ok = 1;
                    for (int i = 0; i < n; i++) {
                        if (!names[i] || strlen(names[i]) >= RBS_SHAPE_NAME_SIZE) ok = 0;
                        else snprintf(t->shape_names[i], RBS_SHAPE_NAME_SIZE, "%s", names[i]);
                    }
                    space = H5Dget_space(ds);
#if H5_VERSION_GE(1, 12, 0)
                    H5Treclaim(memtype, space, H5P_DEFAULT, names);
#else
                    H5Dvlen_reclaim(memtype, space, H5P_DEFAULT, names);
#endif
                }
                free(names);
            } else {
                size_t length = H5Tget_size(type);
                char *text = calloc((size_t)n, length + 1);
                H5Tset_size(memtype, length + 1);
                H5Tset_strpad(memtype, H5T_STR_NULLTERM);
                if (text && length < RBS_SHAPE_NAME_SIZE && H5Dread(ds, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, text) >= 0) {
                    ok = 1;
                    for (int i = 0; i < n; i++)
                        snprintf(t->shape_names[i], RBS_SHAPE_NAME_SIZE, "%s", text + (size_t)i * (length + 1));
                }
                free(text);
            }
        }
    } H5E_END_TRY;
    if (space >= 0) H5Sclose(space);
    if (memtype >= 0) H5Tclose(memtype);
    if (type >= 0) H5Tclose(type);
    if (ds >= 0) H5Dclose(ds);
    if (!ok)
        return rbs_fail(ld, RBS_ERR_FORMAT, "cannot read the shape names of 'grid/shapes' (strings of fewer than %d bytes)",
                        RBS_SHAPE_NAME_SIZE);
    t->n_shapes = n;
    return RBS_OK;
}

/* A 1-D grid dataset: strictly increasing in [lo, hi] (lo excluded if `open_low`), consecutive values at
 * most a factor `ratio` apart (0: no limit). */
static double *read_grid(loader *ld, hid_t grid, const char *name, double lo, int open_low, double hi, double ratio,
                         const char *units, int *n)
{
    int rank = 0;
    hsize_t dims[8];
    if (rbs_dataset_shape(ld, grid, "grid", name, &rank, dims) != RBS_OK) return NULL;
    if (rank != 1 || dims[0] < 1 || dims[0] > 100000) {
        rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'grid/%s' must be a 1-D grid of at least one point", name);
        return NULL;
    }
    double *values = rbs_read_dataset(ld, grid, "grid", name, H5T_NATIVE_DOUBLE, sizeof(double), 1, dims);
    if (!values) return NULL;
    for (hsize_t i = 0; i < dims[0]; i++) {
        double x = values[i];
        if (!(open_low ? x > lo : x >= lo) || !(x <= hi) || (i > 0 && !(x > values[i - 1]))) {
            rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'grid/%s' must be strictly increasing in %c%g, %g] %s (value %g at index "
                 "%llu)", name, open_low ? '(' : '[', lo, hi, units, x, (unsigned long long)i);
            free(values);
            return NULL;
        }
        if (ratio > 0.0 && i > 0 && x > ratio * values[i - 1]) {
            rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'grid/%s' has consecutive speeds more than a factor %g apart (%g and %g "
                 "%s)", name, ratio, values[i - 1], x, units);
            free(values);
            return NULL;
        }
    }
    *n = (int)dims[0];
    return values;
}

/* ------------------------------------------------------------------------- the file */

/* data_schema.check_file: exists, HDF5, file_type, major version. Returns the open file or -1. */
static hid_t check_file(loader *ld, rbs_table *t)
{
    struct stat info;
    if (stat(ld->path, &info) != 0) {
        rbs_fail(ld, RBS_ERR_IO, "no such file");
        return -1;
    }
    if (!S_ISREG(info.st_mode)) {
        rbs_fail(ld, RBS_ERR_IO, "not a regular file");
        return -1;
    }
    FILE *probe = fopen(ld->path, "rb");
    if (!probe) {
        rbs_fail(ld, RBS_ERR_IO, "cannot open the file for reading");
        return -1;
    }
    fclose(probe);
    hid_t file = -1;
    htri_t is_hdf5 = -1;
    H5E_BEGIN_TRY {
        is_hdf5 = H5Fis_hdf5(ld->path);
        if (is_hdf5 > 0) file = H5Fopen(ld->path, H5F_ACC_RDONLY, H5P_DEFAULT);
    } H5E_END_TRY;
    if (file < 0) {
        rbs_fail(ld, RBS_ERR_FORMAT, "not a readable HDF5 file (truncated or corrupt?)");
        return -1;
    }
    char found[128];
    if (!attribute_exists(file, "file_type") || read_string_attribute(file, "file_type", found, sizeof found) != 0) {
        rbs_fail(ld, RBS_ERR_FORMAT, "file_type is missing, expected '%s'", TABLE_FILE_TYPE);
        H5Fclose(file);
        return -1;
    }
    if (strcmp(found, TABLE_FILE_TYPE) != 0) {
        rbs_fail(ld, RBS_ERR_FORMAT, "file_type is '%s', expected '%s'", found, TABLE_FILE_TYPE);
        H5Fclose(file);
        return -1;
    }
    long long version[2] = {0, 0};
    if (!attribute_exists(file, "format_version")
        || read_numeric_attribute(file, "format_version", H5T_NATIVE_LLONG, version, 2, 0) != 0) {
        rbs_fail(ld, RBS_ERR_FORMAT, "missing or malformed 'format_version' attribute");
        H5Fclose(file);
        return -1;
    }
    if (version[0] == 3) {      /* data_schema.table._older_table, word for word */
        rbs_fail(ld, RBS_ERR_VERSION, "table format %lld.%lld was written before rebound-scatter 1.0, which reads format "
                 "%d; rebuild it from the configuration it stores: tablegen info --config %s > TABLE.toml && tablegen "
                 "build --config TABLE.toml -o NEW.h5", version[0], version[1], RBS_TABLE_FORMAT_MAJOR, ld->path);
        H5Fclose(file);
        return -1;
    }
    if (version[0] != RBS_TABLE_FORMAT_MAJOR) {
        rbs_fail(ld, RBS_ERR_VERSION, "format version %lld.%lld is not readable by this version of the library, which "
             "reads major version %d; make the file again with a matching version of tablegen "
             "(docs/format.md, 'Identification and versions')", version[0], version[1], RBS_TABLE_FORMAT_MAJOR);
        H5Fclose(file);
        return -1;
    }
    t->format_major = (int)version[0];
    t->format_minor = (int)version[1];
    return file;
}

/* the cell datasets (data_schema.table.CELL_DATASETS), then those of the work on the wall (WORK_DATASETS, format
 * 4.1: all or none) */
static const char *const CELL_NAMES[] = {
    "cluster_weight", "cluster_loc", "cluster_scale", "cluster_shape", "cluster_slope", "cluster_regime",
    "shape_dictionary", "status_counts", "collision_counts", "mean", "std", "indicatrix_2d", "indicatrix_3d",
    "work_loc", "work_scale", "work_shape", "work_slope", "work_dictionary", "work_mean", "work_std", "trapped_work"};
#define N_CELL_NAMES 13     /* the datasets every table holds */
#define N_ALL_CELL_NAMES (sizeof CELL_NAMES / sizeof CELL_NAMES[0])
#define N_WORK_NAMES (N_ALL_CELL_NAMES - N_CELL_NAMES)

/* trailing shape of cell dataset i (data_schema.table.TableResolution.cell_shapes) */
static int cell_trailing(size_t i, hsize_t C, hsize_t M, hsize_t L, hsize_t *dims)
{
    switch (i) {
    case 0: case 5: dims[0] = C; return 1;
    case 1: case 2: case 3: dims[0] = C; dims[1] = N_CHAIN; return 2;
    case 4: dims[0] = C; dims[1] = N_SLOPES; return 2;
    case 6: dims[0] = N_CHAIN; dims[1] = M; dims[2] = L + 1; return 3;
    case 7: dims[0] = 3; return 1;
    case 8: dims[0] = 11; return 1;
    case 9: case 10: dims[0] = 6; return 1;
    case 11: dims[0] = 72; return 1;
    case 12: dims[0] = 72; dims[1] = 72; return 2;
    case 13: case 14: case 15: dims[0] = C; dims[1] = N_WORK; return 2;
    case 16: dims[0] = C; dims[1] = N_WORK_SLOPES; return 2;
    case 17: dims[0] = N_WORK; dims[1] = M; dims[2] = L + 1; return 3;
    default: dims[0] = N_WORK; return 1;
    }
}

/* two names in strcmp's order, for qsort (Python's sorted on ASCII names) */
static int compare_names(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* `names` sorted, as Python's repr of a sorted list of strings: ['a', 'b'] */
static void name_list(const char **names, size_t n, char *out, size_t size)
{
    qsort(names, n, sizeof *names, compare_names);
    snprintf(out, size, "[");
    for (size_t i = 0; i < n; i++)
        snprintf(out + strlen(out), size - strlen(out), "%s'%s'", i ? ", " : "", names[i]);
    snprintf(out + strlen(out), size - strlen(out), "]");
}

/* Whether the cells hold the work datasets: 1 for all, 0 for none; a subset is refused (RBS_ERR_FORMAT, -1) with
 * data_schema.table.ReboundTable.__post_init__'s words, as the Python reader reports them */
static int work_present(loader *ld, hid_t cells)
{
    const char *have[N_WORK_NAMES], *lack[N_WORK_NAMES];
    size_t n_have = 0, n_lack = 0;
    for (size_t i = N_CELL_NAMES; i < N_ALL_CELL_NAMES; i++) {
        if (rbs_link_exists(cells, CELL_NAMES[i])) have[n_have++] = CELL_NAMES[i];
        else lack[n_lack++] = CELL_NAMES[i];
    }
    if (n_have == 0 || n_lack == 0) return n_lack == 0;
    char have_list[256], lack_list[256];
    name_list(have, n_have, have_list, sizeof have_list);
    name_list(lack, n_lack, lack_list, sizeof lack_list);
    rbs_fail(ld, RBS_ERR_FORMAT, "inconsistent table: ReboundTable has the work datasets %s but not %s: all or none",
             have_list, lack_list);
    return -1;
}

/* The checksummed copy grid/shape_codes equals the names' codes (each family's code, USER_SHAPE_CODE for another
 * shape; data_schema.table.check_contract, shape_codes). */
static int check_shape_codes(loader *ld, hid_t grid, const rbs_table *t)
{
    const hsize_t shapes = (hsize_t)t->n_shapes;
    uint8_t *codes = rbs_read_dataset(ld, grid, "grid", "shape_codes", H5T_NATIVE_UINT8, 1, 1, &shapes);
    if (!codes) return ld->code;
    int same = 1;
    for (int i = 0; same && i < t->n_shapes; i++) {
        int family = rbs_shape_code(t->shape_names[i]);
        same = codes[i] == (family >= 0 ? family : USER_SHAPE_CODE);
    }
    free(codes);
    if (!same)
        return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'grid/shapes' differs from its checksummed copy 'grid/shape_codes'");
    return RBS_OK;
}

/* index of the first element of x[0..n) that fails `ok`, or n */
#define FIRST_BAD(x, n, ok, out)                                \
    do {                                                        \
        (out) = (n);                                            \
        for (size_t i_ = 0; i_ < (n); i_++) {                   \
            double v = (double)(x)[i_];                         \
            if (!(ok)) {                                        \
                (out) = i_;                                     \
                break;                                          \
            }                                                   \
        }                                                       \
    } while (0)

/* Every row of cells/`name` (shape_dictionary, work_dictionary) a standardised quantile function: non-decreasing,
 * knots within ±√L up to float32 round-off (data_schema.table.check_dictionary). */
static int check_dictionary(loader *ld, const char *name, const float *dictionary, size_t rows, long long L)
{
    const float bound = (float)(sqrt((double)L) * (1.0 + DICTIONARY_BOUND_TOLERANCE));
    const size_t knots = (size_t)L + 1;
    for (size_t i = 0; i < rows * knots; i++)
        if (!(fabsf(dictionary[i]) <= bound))
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'cells/%s' holds %g at element %zu; its values must be in "
                        "[-%.9g, %.9g] (sqrt of the levels %lld)", name, (double)dictionary[i], i, (double)bound,
                        (double)bound, L);
    for (size_t row = 0; row < rows; row++)
        for (size_t i = 1; i < knots; i++)
            if (dictionary[row * knots + i] < dictionary[row * knots + i - 1])
                return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'cells/%s' row %zu decreases; each row (a quantile "
                            "function) must be non-decreasing", name, row);
    return RBS_OK;
}

/* The values of the cell datasets (data_schema.table.check_contract, the same rules in the same order). */
static int check_cell_values(loader *ld, const rbs_raw_cells *raw, size_t n_cells, size_t C, long long M, long long L)
{
    size_t bad;
#define RULE(field, n, ok, wanted)                                                                                 \
    do {                                                                                                           \
        FIRST_BAD(raw->field, n, ok, bad);                                                                         \
        if (bad < (n))                                                                                             \
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'cells/%s' holds %g at element %zu; its values must be %s", \
                        #field, (double)raw->field[bad], bad, wanted);                                             \
    } while (0)
    RULE(cluster_weight, n_cells * C, isfinite(v) && v >= 0.0, "finite and >= 0");
    RULE(cluster_loc, n_cells * C * N_CHAIN, fabs(v) <= CELL_VALUE_BOUND, "in [-1e+06, 1e+06]");
    RULE(cluster_scale, n_cells * C * N_CHAIN, v >= 0.0 && v <= CELL_VALUE_BOUND, "in [0, 1e+06]");
    RULE(cluster_slope, n_cells * C * N_SLOPES, fabs(v) <= CELL_VALUE_BOUND, "in [-1e+06, 1e+06]");
    char below_m[64];
    snprintf(below_m, sizeof below_m, "below the dictionary size %lld", M);
    RULE(cluster_shape, n_cells * C * N_CHAIN, v < (double)M, below_m);
    RULE(cluster_regime, n_cells * C, v <= 1.0, "0 or 1");
    RULE(status_counts, n_cells * 3, v >= 0.0, ">= 0");
    RULE(collision_counts, n_cells * 11, v >= 0.0, ">= 0");
    RULE(mean, n_cells * 6, fabs(v) <= CELL_VALUE_BOUND, "in [-1e+06, 1e+06]");
    RULE(std, n_cells * 6, v >= 0.0 && v <= CELL_VALUE_BOUND, "in [0, 1e+06]");
    RULE(indicatrix_2d, n_cells * 72, isfinite(v) && v >= 0.0, "finite and >= 0");
    RULE(indicatrix_3d, n_cells * 72 * 72, isfinite(v) && v >= 0.0, "finite and >= 0");
    if (raw->work_loc) {
        RULE(work_loc, n_cells * C * N_WORK, fabs(v) <= CELL_VALUE_BOUND, "in [-1e+06, 1e+06]");
        RULE(work_scale, n_cells * C * N_WORK, v >= 0.0 && v <= CELL_VALUE_BOUND, "in [0, 1e+06]");
        RULE(work_slope, n_cells * C * N_WORK_SLOPES, fabs(v) <= CELL_VALUE_BOUND, "in [-1e+06, 1e+06]");
        RULE(work_shape, n_cells * C * N_WORK, v < (double)M, below_m);
        RULE(work_mean, n_cells * N_WORK, fabs(v) <= CELL_VALUE_BOUND, "in [-1e+06, 1e+06]");
        RULE(work_std, n_cells * N_WORK, v >= 0.0 && v <= CELL_VALUE_BOUND, "in [0, 1e+06]");
        RULE(trapped_work, n_cells * N_WORK, v >= 0.0 && v <= 1.0, "in [0, 1] (fractions of E⁻)");
    }
#undef RULE
    if (check_dictionary(ld, "shape_dictionary", raw->shape_dictionary, n_cells * N_CHAIN * (size_t)M, L) != RBS_OK)
        return ld->code;
    if (raw->work_loc
        && check_dictionary(ld, "work_dictionary", raw->work_dictionary, n_cells * N_WORK * (size_t)M, L) != RBS_OK)
        return ld->code;
    for (size_t cell = 0; cell < n_cells; cell++) {
        double sum = 0.0;
        for (size_t c = 0; c < C; c++) sum += raw->cluster_weight[cell * C + c];
        if (!(fabs(sum - 1.0) <= WEIGHT_SUM_TOLERANCE))
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'cells/cluster_weight' of cell %zu sums to %.17g; each cell's "
                        "weights must sum to 1 within %g", cell, sum, WEIGHT_SUM_TOLERANCE);
        if (raw->status_counts[3 * cell] + raw->status_counts[3 * cell + 1] <= 0)
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'cells/status_counts' of cell %zu has no rebounded or trapped "
                        "particle", cell);
    }
    return RBS_OK;
}

/* ------------------------------------------------------------------------- the parameter rows: model and wall */

/* how a field of a parameter row is stored and read: a real (an HDF5 integer or float, read as double), an integer
 * (an HDF5 integer, read as long long) or an array of `count` reals (data_schema.table._field) */
enum { FIELD_REAL, FIELD_INTEGER, FIELD_ARRAY };

typedef struct row_field {
    const char *name;
    int kind;
    int count;                  /* the reals of an array field */
    size_t offset;              /* of its value in the struct read */
} row_field;

/* whether HDF5 type `type` is stored as field `f` wants it */
static int field_type_ok(hid_t type, const row_field *f)
{
    H5T_class_t cls = H5Tget_class(type);
    if (f->kind == FIELD_INTEGER) return cls == H5T_INTEGER;
    if (f->kind == FIELD_REAL) return cls == H5T_INTEGER || cls == H5T_FLOAT;
    if (cls != H5T_ARRAY || H5Tget_array_ndims(type) != 1) return 0;
    hsize_t dims[1] = {0};
    hid_t base = H5Tget_super(type);
    H5T_class_t base_cls = base >= 0 ? H5Tget_class(base) : H5T_NO_CLASS;
    if (base >= 0) H5Tclose(base);
    return H5Tget_array_dims2(type, dims) == 1 && dims[0] == (hsize_t)f->count
           && (base_cls == H5T_INTEGER || base_cls == H5T_FLOAT);
}

/* The one row of `group_name`/parameters (a compound type) read by field name into `out` (a struct of `size`
 * bytes laid out as `fields` say): H5Dread converts the file's fields by name into an in-memory compound type of
 * the fields wanted (their order in the file does not matter, others are ignored). Refused, naming the dataset,
 * as data_schema.table._read_row and _field refuse it: missing, not one row of a compound type, a field missing
 * (`names`: the fields read, for the message) or stored as another type, or unreadable. */
static int read_row(loader *ld, hid_t group, const char *group_name, const row_field *fields, int n_fields,
                    const char *names, void *out, size_t size)
{
    hid_t ds = -1, type = -1, space = -1, memtype = -1;
    int rank = -1, ok = 0;
    hsize_t dims[1] = {0};
    if (!rbs_link_exists(group, "parameters"))
        return rbs_fail(ld, RBS_ERR_FORMAT, "missing dataset '%s/parameters'", group_name);
    H5E_BEGIN_TRY {
        ds = H5Dopen2(group, "parameters", H5P_DEFAULT);
        if (ds >= 0) type = H5Dget_type(ds);
        if (ds >= 0) space = H5Dget_space(ds);
        if (space >= 0) rank = H5Sget_simple_extent_ndims(space);
        if (rank == 1) H5Sget_simple_extent_dims(space, dims, NULL);
        if (type >= 0 && H5Tget_class(type) == H5T_COMPOUND && rank == 1 && dims[0] == 1) ok = 1;
    } H5E_END_TRY;
    if (!ok) {
        rbs_fail(ld, RBS_ERR_FORMAT, "dataset '%s/parameters' must hold one row of a compound type, one field per "
                 "parameter", group_name);
        goto done;
    }
    memtype = H5Tcreate(H5T_COMPOUND, size);
    for (int i = 0; i < n_fields && ld->code == RBS_OK; i++) {
        const row_field *f = &fields[i];
        int index = -1, type_ok = 0;
        H5E_BEGIN_TRY {
            index = H5Tget_member_index(type, f->name);
            if (index >= 0) {
                hid_t member = H5Tget_member_type(type, (unsigned)index);
                if (member >= 0) {
                    type_ok = field_type_ok(member, f);
                    H5Tclose(member);
                }
            }
        } H5E_END_TRY;
        if (index < 0) {
            rbs_fail(ld, RBS_ERR_FORMAT, "dataset '%s/parameters' has no field '%s'; the fields read: %s", group_name,
                     f->name, names);
        } else if (!type_ok) {
            if (f->kind == FIELD_ARRAY)
                rbs_fail(ld, RBS_ERR_FORMAT, "field '%s' of dataset '%s/parameters' must be stored as %d numbers",
                         f->name, group_name, f->count);
            else
                rbs_fail(ld, RBS_ERR_FORMAT, "field '%s' of dataset '%s/parameters' must be stored as one %s", f->name,
                         group_name, f->kind == FIELD_INTEGER ? "integer" : "number");
        } else if (f->kind == FIELD_ARRAY) {
            hsize_t count = (hsize_t)f->count;
            hid_t array = H5Tarray_create2(H5T_NATIVE_DOUBLE, 1, &count);
            H5Tinsert(memtype, f->name, f->offset, array);
            H5Tclose(array);
        } else {
            H5Tinsert(memtype, f->name, f->offset, f->kind == FIELD_INTEGER ? H5T_NATIVE_LLONG : H5T_NATIVE_DOUBLE);
        }
    }
    if (ld->code != RBS_OK) goto done;
    herr_t read = -1;
    H5E_BEGIN_TRY { read = H5Dread(ds, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, out); } H5E_END_TRY;
    if (read < 0)
        rbs_fail(ld, RBS_ERR_FORMAT, "cannot read dataset '%s/parameters' (truncated, corrupt or failed checksum?)",
                 group_name);
done:
    if (memtype >= 0) H5Tclose(memtype);
    if (space >= 0) H5Sclose(space);
    if (type >= 0) H5Tclose(type);
    if (ds >= 0) H5Dclose(ds);
    return ld->code;
}

/* the row model/parameters (data_schema.table.MODEL_FIELDS): the direct model's parameters by name */
typedef struct model_row {
    double kappa;
    long long n_max;
    double aspect[4];           /* aspect_ratio_mean, _sd, _low, _high */
    double contact_tol, set_tol;
    long long max_steps;
    double kfac[RBS_N_FAMILIES];    /* second_moment_factors */
} model_row;

static const row_field MODEL_FIELDS[] = {
    {"kappa", FIELD_REAL, 1, offsetof(model_row, kappa)},
    {"n_max", FIELD_INTEGER, 1, offsetof(model_row, n_max)},
    {"aspect_ratio_mean", FIELD_REAL, 1, offsetof(model_row, aspect) + 0 * sizeof(double)},
    {"aspect_ratio_sd", FIELD_REAL, 1, offsetof(model_row, aspect) + 1 * sizeof(double)},
    {"aspect_ratio_low", FIELD_REAL, 1, offsetof(model_row, aspect) + 2 * sizeof(double)},
    {"aspect_ratio_high", FIELD_REAL, 1, offsetof(model_row, aspect) + 3 * sizeof(double)},
    {"contact_tol", FIELD_REAL, 1, offsetof(model_row, contact_tol)},
    {"set_tol", FIELD_REAL, 1, offsetof(model_row, set_tol)},
    {"max_steps", FIELD_INTEGER, 1, offsetof(model_row, max_steps)},
    {"second_moment_factors", FIELD_ARRAY, RBS_N_FAMILIES, offsetof(model_row, kfac)},
};
#define N_MODEL_FIELDS ((int)(sizeof MODEL_FIELDS / sizeof MODEL_FIELDS[0]))

#define TWO_TO_53 9007199254740992LL

/* The direct model's parameters (group model) by name, each in its range (data_schema.table._model_fields: the
 * fields' presence and types in order, then their ranges in order, with the same words). */
static int read_model(loader *ld, hid_t file, model_row *m)
{
    hid_t group = open_group(ld, file, "model");
    if (group < 0) return ld->code;
    char names[512] = "";
    for (int i = 0; i < N_MODEL_FIELDS; i++)
        snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", i ? ", " : "", MODEL_FIELDS[i].name);
    int code = read_row(ld, group, "model", MODEL_FIELDS, N_MODEL_FIELDS, names, m, sizeof *m);
    H5Gclose(group);
    if (code != RBS_OK) return code;
#define MODEL_FAIL(field, allowed, format, value)                                                                  \
    rbs_fail(ld, RBS_ERR_FORMAT, "field '" field "' of dataset 'model/parameters' must be " allowed "; got " format, \
             value)
    if (!(m->kappa >= 0.0 && m->kappa < 1.0)) return MODEL_FAIL("kappa", "in [0, 1)", "%.17g", m->kappa);
    if (!(m->n_max >= 1 && m->n_max < TWO_TO_53))
        return MODEL_FAIL("n_max", "an integer in [1, 2**53)", "%lld", m->n_max);
    if (!isfinite(m->aspect[0])) return MODEL_FAIL("aspect_ratio_mean", "finite", "%.17g", m->aspect[0]);
    if (!(isfinite(m->aspect[1]) && m->aspect[1] > 0.0))
        return MODEL_FAIL("aspect_ratio_sd", "finite and > 0", "%.17g", m->aspect[1]);
    if (!(m->aspect[2] > 0.0 && m->aspect[2] < 1.0))
        return MODEL_FAIL("aspect_ratio_low", "in (0, 1)", "%.17g", m->aspect[2]);
    if (!(m->aspect[2] < m->aspect[3] && m->aspect[3] <= 1.0))
        return MODEL_FAIL("aspect_ratio_high", "in (aspect_ratio_low, 1]", "%.17g", m->aspect[3]);
    if (!(isfinite(m->contact_tol) && m->contact_tol > 0.0))
        return MODEL_FAIL("contact_tol", "finite and > 0", "%.17g", m->contact_tol);
    if (!(isfinite(m->set_tol) && m->set_tol > 0.0))
        return MODEL_FAIL("set_tol", "finite and > 0", "%.17g", m->set_tol);
    if (!(m->max_steps >= 1 && m->max_steps < TWO_TO_53))
        return MODEL_FAIL("max_steps", "an integer in [1, 2**53)", "%lld", m->max_steps);
#undef MODEL_FAIL
    for (int k = 0; k < RBS_N_FAMILIES; k++)
        if (!(m->kfac[k] > 0.0 && m->kfac[k] < 1.0))
            return rbs_fail(ld, RBS_ERR_FORMAT, "field 'second_moment_factors' of dataset 'model/parameters' must be %d "
                            "numbers in (0, 1), one per shape code; got %.17g at index %d", RBS_N_FAMILIES, m->kfac[k], k);
    return RBS_OK;
}

/* The wall law families (direct_model.wall.WALL_FAMILIES, its twin: the same names and codes, scalar parameters in
 * the family's order with their ranges in the same words, and the arrays of each, datasets of group wall). */
typedef struct wall_array {
    const char *name;
    int rank;
    const char *meaning;        /* direct_model.wall.WallArray's meaning up to its colon: a missing dataset's words */
} wall_array;

typedef struct wall_family {
    const char *name;
    int code;                   /* wall.h: EXPONENTIAL_CODE, TABULATED_CODE */
    int n_parameters;
    const char *const *parameters;
    const char *const *allowed;
    int (*const *ok)(double);
    int n_arrays;
    const wall_array *arrays;
} wall_family;

static int finite_and_positive(double x) { return isfinite(x) && x > 0.0; }
static int finite(double x) { return isfinite(x); }

static const char *const EXPONENTIAL_PARAMETERS[] = {"k", "p", "q"};
static const char *const EXPONENTIAL_ALLOWED[] = {"finite and > 0", "finite and > 0", "finite"};
static int (*const EXPONENTIAL_OK[])(double) = {finite_and_positive, finite_and_positive, finite};
static const char *const TABULATED_PARAMETERS[] = {"q"};
static const char *const TABULATED_ALLOWED[] = {"finite"};
static int (*const TABULATED_OK[])(double) = {finite};
static const wall_array TABULATED_ARRAYS[] = {
    {"contact_speed_m_s", 1, "the speed nodes |V_c⁻|"},
    {"contact_sine", 1, "the sine nodes |v_c⁻|/|V_c⁻|"},
    {"restitution", 2, "a_nc at the nodes, one row per speed node, each value in (0, 1]"},
};
static const wall_family WALL_FAMILIES[] = {
    {"exponential", EXPONENTIAL_CODE, 3, EXPONENTIAL_PARAMETERS, EXPONENTIAL_ALLOWED, EXPONENTIAL_OK, 0, NULL},
    {"tabulated", TABULATED_CODE, 1, TABULATED_PARAMETERS, TABULATED_ALLOWED, TABULATED_OK, 3, TABULATED_ARRAYS},
};
#define N_WALL_FAMILIES ((int)(sizeof WALL_FAMILIES / sizeof WALL_FAMILIES[0]))

/* `text` appended to the string `out` of `size` bytes (truncated) */
static void append(char *out, size_t size, const char *text)
{
    size_t used = strlen(out);
    if (used + 1 < size) snprintf(out + used, size - used, "%s", text);
}

/* x as Python's repr(float) writes it (the shortest digits that read back as x, fixed notation for decimal exponents
 * -4 to 15 with at least one decimal), so that a message quoting a value is the Python reader's */
static void python_repr(double x, char *out, size_t size)
{
    if (!isfinite(x)) {
        snprintf(out, size, "%s", isnan(x) ? "nan" : x > 0.0 ? "inf" : "-inf");
        return;
    }
    char scientific[40];
    int digits = 1;
    for (;; digits++) {
        snprintf(scientific, sizeof scientific, "%.*e", digits - 1, x);
        if (digits == 17 || strtod(scientific, NULL) == x) break;
    }
    int exponent = atoi(strchr(scientific, 'e') + 1);
    if (exponent < -4 || exponent >= 16) {
        snprintf(out, size, "%s", scientific);
        return;
    }
    snprintf(out, size, "%.*f", digits - 1 - exponent > 0 ? digits - 1 - exponent : 0, x);
    if (!strchr(out, '.')) append(out, size, ".0");
}

/* The values of a dataset of rank 1 or 2 as Python writes a list of floats (nested for rank 2): [0.0, 0.5, 1.0] */
static void list_text(const double *values, int rank, const hsize_t *dims, char *out, size_t size)
{
    size_t rows = rank == 2 ? (size_t)dims[0] : 1, columns = (size_t)dims[rank - 1];
    out[0] = '\0';
    if (rank == 2) append(out, size, "[");
    for (size_t i = 0; i < rows; i++) {
        append(out, size, i ? ", [" : "[");
        for (size_t j = 0; j < columns; j++) {
            char number[40];
            python_repr(values[i * columns + j], number, sizeof number);
            if (j) append(out, size, ", ");
            append(out, size, number);
        }
        append(out, size, "]");
    }
    if (rank == 2) append(out, size, "]");
}

/* Whether `name` in `where` is a dataset (not a group): h5py's isinstance(group[name], h5py.Dataset) */
static int is_dataset(hid_t where, const char *name)
{
    if (!rbs_link_exists(where, name)) return 0;
    hid_t object = -1;
    H5E_BEGIN_TRY { object = H5Oopen(where, name, H5P_DEFAULT); } H5E_END_TRY;
    if (object < 0) return 0;
    int dataset = H5Iget_type(object) == H5I_DATASET;
    H5Oclose(object);
    return dataset;
}

/* The numpy name of dataset `name`'s element type into `out` (float64, int32, uint8, ...): 1 if it holds numbers
 * (numpy's kinds i, u, f), else 0 with `out` saying what it holds */
static int numeric_type(hid_t where, const char *name, char *out, size_t size)
{
    hid_t ds = -1, type = -1;
    int numeric = 0;
    snprintf(out, size, "no numbers");
    H5E_BEGIN_TRY {
        ds = H5Dopen2(where, name, H5P_DEFAULT);
        if (ds >= 0) type = H5Dget_type(ds);
        if (type >= 0) {
            H5T_class_t cls = H5Tget_class(type);
            size_t bits = 8 * H5Tget_size(type);
            numeric = cls == H5T_FLOAT || cls == H5T_INTEGER;
            if (cls == H5T_FLOAT) snprintf(out, size, "float%zu", bits);
            else if (cls == H5T_INTEGER) snprintf(out, size, "%sint%zu", H5Tget_sign(type) == H5T_SGN_NONE ? "u" : "", bits);
            else if (cls == H5T_STRING) snprintf(out, size, "strings");
        }
    } H5E_END_TRY;
    if (type >= 0) H5Tclose(type);
    if (ds >= 0) H5Dclose(ds);
    return numeric;
}

/* direct_model.wall._nodes: `least` to `most` values, finite, strictly increasing, and > 0 (`unit` 0) or from
 * exactly 0 to exactly 1 */
static int nodes_ok(const double *x, size_t n, size_t least, size_t most, int unit)
{
    if (n < least || n > most) return 0;
    for (size_t i = 0; i < n; i++)
        if (!isfinite(x[i]) || (i > 0 && !(x[i] > x[i - 1])) || (!unit && !(x[i] > 0.0))) return 0;
    return !unit || (x[0] == 0.0 && x[n - 1] == 1.0);
}

/* The family's arrays, datasets of group wall (data_schema.table._wall, then direct_model.wall.TabulatedWall: the
 * same checks in the same order and words): each present and numbers of its rank; the speed nodes 1 to
 * MAX_CONTACT_SPEEDS, finite, strictly increasing and > 0; the sine nodes 2 to MAX_CONTACT_SINES, strictly
 * increasing from 0 to 1; a_nc one row per speed node, one value per sine node, each in (0, 1]. Into t->wall as
 * direct_model.wall.Wall.as_array lays them out (the counts at W_N_SPEEDS, W_N_SINES, the values from W_NODES). */
static int read_wall_arrays(loader *ld, hid_t group, const wall_family *family, rbs_table *t)
{
    double *values[3] = {NULL, NULL, NULL};
    hsize_t dims[3][8] = {{0}};
    int ranks[3] = {0, 0, 0};
    for (int a = 0; a < family->n_arrays && ld->code == RBS_OK; a++) {
        const wall_array *spec = &family->arrays[a];
        char type[32], shape[160] = "(";
        if (!is_dataset(group, spec->name)) {
            rbs_fail(ld, RBS_ERR_FORMAT, "missing dataset 'wall/%s' (an array of the %s wall law: %s)", spec->name,
                     family->name, spec->meaning);
            break;
        }
        if (rbs_dataset_shape(ld, group, "wall", spec->name, &ranks[a], dims[a]) != RBS_OK) break;
        if (!numeric_type(group, spec->name, type, sizeof type) || ranks[a] != spec->rank) {
            for (int k = 0; k < ranks[a]; k++)      /* numpy's shape: (3,), (3, 2) */
                snprintf(shape + strlen(shape), sizeof shape - strlen(shape), "%s%llu%s", k ? " " : "",
                         (unsigned long long)dims[a][k], k + 1 < ranks[a] || ranks[a] == 1 ? "," : "");
            append(shape, sizeof shape, ")");
            rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'wall/%s' must hold %d-dimensional numbers; got %s of shape %s",
                     spec->name, spec->rank, type, shape);
            break;
        }
        values[a] = rbs_read_dataset(ld, group, "wall", spec->name, H5T_NATIVE_DOUBLE, sizeof(double), ranks[a],
                                     dims[a]);
    }
    char got[1024];
    const size_t ns = ld->code == RBS_OK ? (size_t)dims[0][0] : 0, nz = ld->code == RBS_OK ? (size_t)dims[1][0] : 0;
    if (ld->code == RBS_OK && !nodes_ok(values[0], ns, 1, MAX_CONTACT_SPEEDS, 0)) {
        list_text(values[0], 1, dims[0], got, sizeof got);
        rbs_fail(ld, RBS_ERR_FORMAT, "group 'wall': The wall law parameter 'contact_speed_m_s' must be 1 to %d finite, "
                 "strictly increasing numbers > 0; got %s.", MAX_CONTACT_SPEEDS, got);
    } else if (ld->code == RBS_OK && !nodes_ok(values[1], nz, 2, MAX_CONTACT_SINES, 1)) {
        list_text(values[1], 1, dims[1], got, sizeof got);
        rbs_fail(ld, RBS_ERR_FORMAT, "group 'wall': The wall law parameter 'contact_sine' must be 2 to %d finite, "
                 "strictly increasing numbers from 0 to 1; got %s.", MAX_CONTACT_SINES, got);
    } else if (ld->code == RBS_OK && (dims[2][0] != ns || dims[2][1] != nz)) {
        list_text(values[2], 2, dims[2], got, sizeof got);
        rbs_fail(ld, RBS_ERR_FORMAT, "group 'wall': The wall law parameter 'restitution' must be %zu rows (one per speed "
                 "node) of %zu numbers (one per sine node); got %s.", ns, nz, got);
    }
    for (size_t k = 0; ld->code == RBS_OK && k < ns * nz; k++) {
        double v = values[2][k];
        if (!(v > 0.0 && v <= 1.0)) {       /* the first node out of range, row-major as numpy.argwhere finds it */
            python_repr(v, got, sizeof got);
            rbs_fail(ld, RBS_ERR_FORMAT, "group 'wall': The wall law parameter 'restitution' must be in (0, 1] at every "
                     "node; got %s at [%zu][%zu] (|V_c| = %g m/s, sine %g).", got, k / nz, k % nz, values[0][k / nz],
                     values[1][k % nz]);
        }
    }
    if (ld->code == RBS_OK) {
        t->wall[W_N_SPEEDS] = (double)ns;
        t->wall[W_N_SINES] = (double)nz;
        memcpy(t->wall + W_NODES, values[0], ns * sizeof(double));
        memcpy(t->wall + W_NODES + ns, values[1], nz * sizeof(double));
        memcpy(t->wall + W_NODES + ns + nz, values[2], ns * nz * sizeof(double));
    }
    for (int a = 0; a < 3; a++) free(values[a]);
    return ld->code;
}

/* Whether the compound row wall/parameters (read already: one row of a compound type) has the field `name` */
static int wall_row_has_field(hid_t group, const char *name)
{
    hid_t ds = -1, type = -1;
    int index = -1;
    H5E_BEGIN_TRY {
        ds = H5Dopen2(group, "parameters", H5P_DEFAULT);
        if (ds >= 0) type = H5Dget_type(ds);
        if (type >= 0) index = H5Tget_member_index(type, name);
    } H5E_END_TRY;
    if (type >= 0) H5Tclose(type);
    if (ds >= 0) H5Dclose(ds);
    return index >= 0;
}

/* The wall's roughness (data_schema.table._wall): the optional field roughness_deg of wall/parameters, written for a
 * rough wall only (absent: 0, smooth), one number in [0, RBS_MAX_ROUGHNESS_DEG] degrees; `names` the row's fields
 * read, for the messages of read_row */
static int read_wall_roughness(loader *ld, hid_t group, const char *names, rbs_table *t)
{
    t->wall_roughness = 0.0;
    if (!wall_row_has_field(group, "roughness_deg")) return ld->code;
    static const row_field field = {"roughness_deg", FIELD_REAL, 1, 0};
    double roughness = 0.0;
    if (read_row(ld, group, "wall", &field, 1, names, &roughness, sizeof roughness) != RBS_OK) return ld->code;
    if (!(roughness >= 0.0 && roughness <= RBS_MAX_ROUGHNESS_DEG))
        return rbs_fail(ld, RBS_ERR_FORMAT, "field 'roughness_deg' of dataset 'wall/parameters' must be in [0, %g] "
                        "degrees; got %.17g", RBS_MAX_ROUGHNESS_DEG, roughness);
    t->wall_roughness = roughness;
    return RBS_OK;
}

/* The wall (group wall, data_schema.table._wall): its attributes family and name (strings), the family one of
 * WALL_FAMILIES, its parameters by field name within their ranges, then the family's arrays; into t (wall_*, and the
 * kernels' wall array t->wall, direct_model.wall.Wall.as_array: the family's code, q, then k, p or the arrays). */
static int read_wall(loader *ld, hid_t file, rbs_table *t)
{
    hid_t group = open_group(ld, file, "wall");
    if (group < 0) return ld->code;
    char family_name[RBS_WALL_NAME_SIZE];
    const wall_family *family = NULL;
    static const char *const attributes[2] = {"family", "name"};
    char *values[2] = {family_name, t->wall_name};
    for (int i = 0; i < 2 && ld->code == RBS_OK; i++) {
        if (!attribute_exists(group, attributes[i]))
            rbs_fail(ld, RBS_ERR_FORMAT, "missing attribute '%s' of group 'wall'", attributes[i]);
        else if (read_string_attribute(group, attributes[i], values[i], RBS_WALL_NAME_SIZE) != 0)
            rbs_fail(ld, RBS_ERR_FORMAT, "cannot read the attribute '%s' of group 'wall' as a string", attributes[i]);
    }
    for (int i = 0; ld->code == RBS_OK && !family && i < N_WALL_FAMILIES; i++)
        if (strcmp(family_name, WALL_FAMILIES[i].name) == 0) family = &WALL_FAMILIES[i];
    if (ld->code == RBS_OK && !family) {
        char known[256] = "";
        for (int i = 0; i < N_WALL_FAMILIES; i++)
            snprintf(known + strlen(known), sizeof known - strlen(known), "%s%s", i ? ", " : "", WALL_FAMILIES[i].name);
        rbs_fail(ld, RBS_ERR_FORMAT, "the attribute 'family' of group 'wall' names an unknown wall law family '%s' (this "
                 "version knows: %s)", family_name, known);
    }
    double row[RBS_WALL_MAX_PARAMETERS + 2];        /* the family's parameters, then the speed range */
    int n = ld->code == RBS_OK ? family->n_parameters : 0;
    char names_of_row[512] = "";
    if (ld->code == RBS_OK) {
        row_field fields[RBS_WALL_MAX_PARAMETERS + 1];
        char *names = names_of_row;
        const size_t names_size = sizeof names_of_row;
        for (int i = 0; i < n; i++) {
            fields[i] = (row_field){family->parameters[i], FIELD_REAL, 1, (size_t)i * sizeof(double)};
            snprintf(names + strlen(names), names_size - strlen(names), "%s%s", i ? ", " : "", family->parameters[i]);
        }
        fields[n] = (row_field){"speed_range_m_s", FIELD_ARRAY, 2, (size_t)n * sizeof(double)};
        snprintf(names + strlen(names), names_size - strlen(names), " (the %s wall law) and speed_range_m_s",
                 family->name);
        read_row(ld, group, "wall", fields, n + 1, names, row, (size_t)(n + 2) * sizeof(double));
    }
    for (int i = 0; ld->code == RBS_OK && i < n; i++) {
        t->wall_parameters[i] = row[i];
        if (!family->ok[i](row[i]))
            rbs_fail(ld, RBS_ERR_FORMAT, "field '%s' of dataset 'wall/parameters' must be %s; got %.17g",
                     family->parameters[i], family->allowed[i], row[i]);
    }
    if (ld->code == RBS_OK) {
        /* direct_model.wall.check_speed_range: [0, inf] (not stated), or finite with 0 <= low < high */
        double low = row[n], high = row[n + 1];
        if (!((low == 0.0 && isinf(high) && high > 0.0) || (isfinite(low) && isfinite(high) && 0.0 <= low && low < high)))
            rbs_fail(ld, RBS_ERR_FORMAT, "field 'speed_range_m_s' of dataset 'wall/parameters' must be [low, high] m/s "
                     "with 0 <= low < high finite, or [0, inf] (not stated); got [%.17g, %.17g]", low, high);
        t->wall_speed_range[0] = low;
        t->wall_speed_range[1] = high;
    }
    if (ld->code == RBS_OK) read_wall_roughness(ld, group, names_of_row, t);
    if (ld->code == RBS_OK && family->n_arrays > 0) read_wall_arrays(ld, group, family, t);
    H5Gclose(group);
    if (ld->code != RBS_OK) return ld->code;
    t->wall_family = family->name;
    t->wall_parameter_names = family->parameters;
    t->n_wall_parameters = family->n_parameters;
    /* direct_model.wall.Wall.as_array: [code, q, ...], the exponential family's k, p after q */
    t->wall[W_FAMILY] = (double)family->code;
    for (int i = 0; i < n; i++)
        if (strcmp(family->parameters[i], "q") == 0) t->wall[W_Q] = row[i];
    if (family->code == EXPONENTIAL_CODE) {
        t->wall[W_K] = row[0];
        t->wall[W_P] = row[1];
    }
    return RBS_OK;
}

/* The direct model's parameters (surrogate.table.SurrogateTable.direct_parameters): the P_* array of
 * direct_model.runtime.model_parameters from the model's row and the wall's array, in range (read_model,
 * read_wall). */
static void direct_parameters(rbs_table *t, const model_row *m)
{
    double *p = t->direct_parameters;
    double mean = m->aspect[0], sd = m->aspect[1], low = m->aspect[2], high = m->aspect[3];
    p[P_ASPECT_MEAN] = mean;
    p[P_ASPECT_SD] = sd;
    p[P_ASPECT_LOW] = low;
    p[P_ASPECT_HIGH] = high;
    p[P_CDF_LOW] = rbs_normal_cdf((low - mean) / sd);
    p[P_CDF_HIGH] = rbs_normal_cdf((high - mean) / sd);
    p[P_KAPPA] = m->kappa;
    p[P_N_MAX] = (double)m->n_max;
    p[P_CONTACT_TOL] = m->contact_tol;
    p[P_SET_TOL] = m->set_tol;
    p[P_MAX_STEPS] = (double)m->max_steps;
    for (int k = 0; k < RBS_N_FAMILIES; k++) p[P_KFAC + k] = m->kfac[k];
    memcpy(p + P_WALL, t->wall, sizeof t->wall);      /* zero after the wall's own values, as np.zeros leaves them */
    t->n_max = m->n_max;
}

static void free_raw(rbs_raw_cells *raw)
{
    free(raw->cluster_weight);
    free(raw->cluster_loc);
    free(raw->cluster_scale);
    free(raw->cluster_shape);
    free(raw->cluster_slope);
    free(raw->cluster_regime);
    free(raw->shape_dictionary);
    free(raw->status_counts);
    free(raw->mean);
    free(raw->std);
    free(raw->collision_counts);
    free(raw->indicatrix_2d);
    free(raw->indicatrix_3d);
    free(raw->work_loc);
    free(raw->work_scale);
    free(raw->work_shape);
    free(raw->work_slope);
    free(raw->work_dictionary);
    free(raw->work_mean);
    free(raw->work_std);
    free(raw->trapped_work);
}

static int load(loader *ld, rbs_table *t)
{
    hid_t file = check_file(ld, t);
    if (file < 0) return ld->code;
    hid_t grid = -1, resolution = -1, cells = -1;
    rbs_raw_cells raw;
    memset(&raw, 0, sizeof raw);

    grid = open_group(ld, file, "grid");
    if (grid >= 0) resolution = open_group(ld, file, "resolution");
    if (resolution >= 0) cells = open_group(ld, file, "cells");
    if (cells < 0) goto done;

    /* grid: the three datasets, then every cell dataset present (the Python reader's order of checks) */
    for (int i = 0; i < 3; i++) {
        static const char *const names[] = {"alpha1_deg", "speed_m_s", "shapes"};
        if (!rbs_link_exists(grid, names[i])) {
            rbs_fail(ld, RBS_ERR_FORMAT, "missing dataset 'grid/%s'", names[i]);
            goto done;
        }
    }
    {
        char missing[512] = "";
        for (size_t i = 0; i < N_CELL_NAMES; i++)
            if (!rbs_link_exists(cells, CELL_NAMES[i]))
                snprintf(missing + strlen(missing), sizeof missing - strlen(missing), "%scells/%s",
                         missing[0] ? ", " : "", CELL_NAMES[i]);
        if (missing[0]) {
            rbs_fail(ld, RBS_ERR_FORMAT, "missing dataset(s) %s", missing);
            goto done;
        }
    }
    long long C = 0, M = 0, L = 0;
    if (read_integer_attribute(ld, resolution, "resolution", "clusters", &C) != RBS_OK
        || read_integer_attribute(ld, resolution, "resolution", "dictionary_size", &M) != RBS_OK
        || read_integer_attribute(ld, resolution, "resolution", "levels", &L) != RBS_OK)
        goto done;
    if (C < 1 || C > 1000000 || M < 1 || M > 256 || L < 1 || L > 1000000) {
        rbs_fail(ld, RBS_ERR_FORMAT, "inconsistent table: resolution clusters %lld, dictionary_size %lld, levels %lld "
             "(each must be >= 1, dictionary_size <= 256)", C, M, L);
        goto done;
    }
    t->n_clusters = (int)C;
    t->n_dictionary = (int)M;
    t->n_levels = (int)L + 1;

    /* attributes data_schema reads (provenance: present, not used here) */
    for (int i = 0; i < 6; i++) {
        static const char *const names[] = {"created", "package_version", "model_sha256", "config", "config_sha256",
                                            "master_seed"};
        if (!attribute_exists(file, names[i])) {
            rbs_fail(ld, RBS_ERR_FORMAT, "missing root attribute '%s'", names[i]);
            goto done;
        }
    }
    /* the direct model's parameters and the wall, each one row read by field name */
    model_row model;
    if (read_integer_attribute(ld, grid, "grid", "particles_per_cell", &t->particles_per_cell) != RBS_OK
        || read_model(ld, file, &model) != RBS_OK || read_wall(ld, file, t) != RBS_OK)
        goto done;
    direct_parameters(t, &model);
    if (read_shapes(ld, grid, t) != RBS_OK) goto done;
    t->alpha1_deg = read_grid(ld, grid, "alpha1_deg", 0.0, 1, 90.0, 0.0, "deg", &t->n_alpha1);
    if (!t->alpha1_deg) goto done;
    t->speed_m_s = read_grid(ld, grid, "speed_m_s", SPEED_GRID_MIN, 0, SPEED_GRID_MAX, MAX_SPEED_RATIO, "m/s",
                             &t->n_speed);
    if (!t->speed_m_s) goto done;
    if (check_shape_codes(ld, grid, t) != RBS_OK) goto done;

    const hsize_t lead[3] = {(hsize_t)t->n_shapes, (hsize_t)t->n_alpha1, (hsize_t)t->n_speed};
    const size_t n_cells = (size_t)t->n_shapes * (size_t)t->n_alpha1 * (size_t)t->n_speed;
    if ((double)n_cells * (double)C * ROW_SIZE > 4e9 || (double)n_cells * 6.0 * (double)M * (double)(L + 1) > 4e9) {
        rbs_fail(ld, RBS_ERR_FORMAT, "inconsistent table: %zu cells of %lld components are too large", n_cells, C);
        goto done;
    }
    /* the work datasets all or none, then every cell dataset's shape (only metadata: nothing read yet) */
    const int has_work = work_present(ld, cells);
    if (has_work < 0) goto done;
    const size_t n_names = has_work ? N_ALL_CELL_NAMES : N_CELL_NAMES;
    for (size_t i = 0; i < n_names; i++) {
        hsize_t want[8], found[8];
        int rank = 3 + cell_trailing(i, (hsize_t)C, (hsize_t)M, (hsize_t)L, want + 3), found_rank = 0;
        memcpy(want, lead, sizeof lead);
        if (rbs_dataset_shape(ld, cells, "cells", CELL_NAMES[i], &found_rank, found) != RBS_OK) goto done;
        int same = found_rank == rank;
        for (int k = 0; same && k < rank; k++) same = found[k] == want[k];
        if (!same) {
            rbs_read_dataset(ld, cells, "cells", CELL_NAMES[i], H5T_NATIVE_DOUBLE, sizeof(double), rank, want);
            goto done;
        }
    }
    hsize_t dims[8];
    memcpy(dims, lead, sizeof lead);
#define READ_CELLS(field, index, memtype, ctype)                                                              \
    do {                                                                                                      \
        int rank_ = 3 + cell_trailing(index, (hsize_t)C, (hsize_t)M, (hsize_t)L, dims + 3);                   \
        raw.field = rbs_read_dataset(ld, cells, "cells", CELL_NAMES[index], memtype, sizeof(ctype), rank_, dims); \
        if (!raw.field) goto done;                                                                            \
    } while (0)
    READ_CELLS(cluster_weight, 0, H5T_NATIVE_DOUBLE, double);
    READ_CELLS(cluster_loc, 1, H5T_NATIVE_FLOAT, float);
    READ_CELLS(cluster_scale, 2, H5T_NATIVE_FLOAT, float);
    READ_CELLS(cluster_shape, 3, H5T_NATIVE_UINT8, uint8_t);
    READ_CELLS(cluster_slope, 4, H5T_NATIVE_FLOAT, float);
    READ_CELLS(cluster_regime, 5, H5T_NATIVE_UINT8, uint8_t);
    READ_CELLS(shape_dictionary, 6, H5T_NATIVE_FLOAT, float);
    READ_CELLS(status_counts, 7, H5T_NATIVE_INT64, int64_t);
    READ_CELLS(mean, 9, H5T_NATIVE_DOUBLE, double);
    READ_CELLS(std, 10, H5T_NATIVE_DOUBLE, double);
    READ_CELLS(collision_counts, 8, H5T_NATIVE_INT64, int64_t);
    READ_CELLS(indicatrix_2d, 11, H5T_NATIVE_FLOAT, float);
    READ_CELLS(indicatrix_3d, 12, H5T_NATIVE_FLOAT, float);
    if (has_work) {
        READ_CELLS(work_loc, 13, H5T_NATIVE_FLOAT, float);
        READ_CELLS(work_scale, 14, H5T_NATIVE_FLOAT, float);
        READ_CELLS(work_shape, 15, H5T_NATIVE_UINT8, uint8_t);
        READ_CELLS(work_slope, 16, H5T_NATIVE_FLOAT, float);
        READ_CELLS(work_dictionary, 17, H5T_NATIVE_FLOAT, float);
        READ_CELLS(work_mean, 18, H5T_NATIVE_DOUBLE, double);
        READ_CELLS(work_std, 19, H5T_NATIVE_DOUBLE, double);
        READ_CELLS(trapped_work, 20, H5T_NATIVE_DOUBLE, double);
    }
#undef READ_CELLS
    if (check_cell_values(ld, &raw, n_cells, (size_t)C, M, L) != RBS_OK) goto done;
    {
        const char *what = NULL;
        int code = rbs_derive(t, &raw, &what);
        if (code == RBS_ERR_MEMORY) rbs_fail(ld, code, "out of memory deriving the kernel arrays");
        else if (code != RBS_OK) rbs_fail(ld, code, "the derived kernel array %s is not finite (inconsistent table)", what);
    }
    if (ld->code == RBS_OK && rbs_shape_records_load(ld, file, t, model.kappa, model.aspect) == RBS_OK
        && rbs_direct_shapes_build(t) != RBS_OK)
        rbs_fail(ld, RBS_ERR_MEMORY, "out of memory building the direct model's shapes");

done:
    free_raw(&raw);
    if (cells >= 0) H5Gclose(cells);
    if (resolution >= 0) H5Gclose(resolution);
    if (grid >= 0) H5Gclose(grid);
    H5Fclose(file);
    return ld->code;
}

/* ------------------------------------------------------------------------- public */

int rbs_table_open(const char *path, rbs_table **table, char *message, size_t message_size)
{
    loader ld = {path ? path : "(null)", message, message_size, RBS_OK};
    if (message && message_size > 0) message[0] = '\0';
    if (!table) return rbs_fail(&ld, RBS_INVALID, "no place for the table (table is NULL)");
    *table = NULL;
    if (!path) return rbs_fail(&ld, RBS_INVALID, "no path given");
    rbs_table *t = calloc(1, sizeof *t);
    if (!t) return rbs_fail(&ld, RBS_ERR_MEMORY, "out of memory");
    t->path = malloc(strlen(path) + 1);
    if (!t->path) {
        free(t);
        return rbs_fail(&ld, RBS_ERR_MEMORY, "out of memory");
    }
    strcpy(t->path, path);
    if (load(&ld, t) != RBS_OK) {
        rbs_table_close(t);
        return ld.code;
    }
    *table = t;
    return RBS_OK;
}

void rbs_table_close(rbs_table *t)
{
    if (!t) return;
    free(t->path);
    free(t->alpha1_deg);
    free(t->speed_m_s);
    free(t->alpha1_axis);
    free(t->speed_axis);
    free(t->cells);
    free(t->clusters);
    free(t->dictionary);
    free(t->speed_restitution);
    free(t->restitution_pieces);
    free(t->work_rows);
    free(t->work_dictionary);
    free(t->work_cells);
    free(t->shape_names);
    rbs_shape_records_free(&t->shapes);
    rbs_direct_shapes_free(t);
    free(t);
}

const char *rbs_table_path(const rbs_table *t) { return t ? t->path : NULL; }

int rbs_table_n_shapes(const rbs_table *t) { return t ? t->n_shapes : 0; }

const char *rbs_table_shape_name(const rbs_table *t, int i)
{
    return t && i >= 0 && i < t->n_shapes ? t->shape_names[i] : NULL;
}
