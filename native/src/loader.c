/*
 * loader.c: opening a table file (HDF5), the checks of data_schema (check_file, read_table), and the
 * accessors of a loaded table. The kernel arrays are derived in layout.c; the shapes (group shapes, format 3.4)
 * are read by shape_records.c, with the helpers loader.h declares; what tables before format 3.3 leave out is
 * read by old_tables.c.
 *
 * Every error names the file and what is wrong with it; HDF5's own error printing is switched off
 * around each HDF5 call that may fail (H5E_BEGIN_TRY), so the library prints nothing.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "loader.h"

#define TABLE_FILE_TYPE "rebound_table"

int rbs_fail(loader *ld, int code, const char *format, ...)
{
    if (ld->code != RBS_OK) return ld->code;
    ld->code = code;
    if (ld->message && ld->message_size > 0) {
        char detail[512];
        va_list args;
        va_start(args, format);
        vsnprintf(detail, sizeof detail, format, args);
        va_end(args);
        snprintf(ld->message, ld->message_size, "%s: %s", ld->path, detail);
    }
    return code;
}

/* ------------------------------------------------------------------------- HDF5 helpers */

int rbs_link_exists(hid_t where, const char *name)
{
    htri_t found = 0;
    H5E_BEGIN_TRY { found = H5Lexists(where, name, H5P_DEFAULT); } H5E_END_TRY;
    return found > 0;
}

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

static int read_double_attribute(loader *ld, hid_t where, const char *group, const char *name, double *out)
{
    if (!attribute_exists(where, name)) return rbs_fail(ld, RBS_ERR_FORMAT, "missing attribute '%s' of group '%s'", name, group);
    if (read_numeric_attribute(where, name, H5T_NATIVE_DOUBLE, out, 1, 0) != 0)
        return rbs_fail(ld, RBS_ERR_FORMAT, "cannot read the attribute '%s' of group '%s' as one number", name, group);
    return RBS_OK;
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

/* The shape of dataset `name` in `group`: its rank into *rank and dims (up to 8); 0 on success. */
int rbs_dataset_shape(loader *ld, hid_t group, const char *group_name, const char *name, int *rank,
                      hsize_t dims[8])
{
    hid_t ds = -1, space = -1;
    int r = -1;
    if (!rbs_link_exists(group, name)) return rbs_fail(ld, RBS_ERR_FORMAT, "missing dataset '%s/%s'", group_name, name);
    H5E_BEGIN_TRY {
        ds = H5Dopen2(group, name, H5P_DEFAULT);
        if (ds >= 0) space = H5Dget_space(ds);
        if (space >= 0) r = H5Sget_simple_extent_ndims(space);
        if (r >= 0 && r <= 8) H5Sget_simple_extent_dims(space, dims, NULL);
    } H5E_END_TRY;
    if (space >= 0) H5Sclose(space);
    if (ds >= 0) H5Dclose(ds);
    if (r < 0 || r > 8) return rbs_fail(ld, RBS_ERR_FORMAT, "cannot read dataset '%s/%s' (truncated or corrupt?)", group_name, name);
    *rank = r;
    return RBS_OK;
}

/* Read dataset `name` whole as `memtype` into a new buffer of `count` elements of `size` bytes, after
 * checking its shape is `rank` × `dims`. */
void *rbs_read_dataset(loader *ld, hid_t group, const char *group_name, const char *name, hid_t memtype,
                       size_t size, int rank, const hsize_t *dims)
{
    int found_rank = 0;
    hsize_t found[8];
    if (rbs_dataset_shape(ld, group, group_name, name, &found_rank, found) != RBS_OK) return NULL;
    int same = found_rank == rank;
    size_t count = 1;
    for (int i = 0; same && i < rank; i++) {
        same = found[i] == dims[i];
        count *= (size_t)dims[i];
    }
    if (!same) {
        char want[160] = "(", got[160] = "(";
        for (int i = 0; i < rank; i++)
            snprintf(want + strlen(want), sizeof want - strlen(want), "%s%llu", i ? ", " : "", (unsigned long long)dims[i]);
        for (int i = 0; i < found_rank; i++)
            snprintf(got + strlen(got), sizeof got - strlen(got), "%s%llu", i ? ", " : "", (unsigned long long)found[i]);
        strcat(want, ")");
        strcat(got, ")");
        rbs_fail(ld, RBS_ERR_FORMAT, "dataset '%s/%s' has shape %s, expected %s", group_name, name, got, want);
        return NULL;
    }
    void *buffer = malloc(count ? count * size : 1);
    if (!buffer) {
        rbs_fail(ld, RBS_ERR_MEMORY, "out of memory reading dataset '%s/%s' (%zu elements)", group_name, name, count);
        return NULL;
    }
    herr_t status = -1;
    hid_t ds = -1;
    H5E_BEGIN_TRY {
        ds = H5Dopen2(group, name, H5P_DEFAULT);
        if (ds >= 0) status = H5Dread(ds, memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer);
    } H5E_END_TRY;
    if (ds >= 0) H5Dclose(ds);
    if (status < 0) {
        free(buffer);
        rbs_fail(ld, RBS_ERR_FORMAT, "cannot read dataset '%s/%s' (truncated, corrupt or failed checksum?)", group_name, name);
        return NULL;
    }
    return buffer;
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
    if (version[0] != RBS_TABLE_MAJOR) {
        rbs_fail(ld, RBS_ERR_VERSION, "format version %lld.%lld is not readable by this version of the library, which "
             "reads major version %d; make the file again with a matching version of tablegen "
             "(docs/format.md, 'Identification and versions')", version[0], version[1], RBS_TABLE_MAJOR);
        H5Fclose(file);
        return -1;
    }
    t->format_major = (int)version[0];
    t->format_minor = (int)version[1];
    return file;
}

static const char *const CELL_NAMES[] = {
    "cluster_weight", "cluster_loc", "cluster_scale", "cluster_shape", "cluster_slope", "cluster_regime",
    "shape_dictionary", "status_counts", "collision_counts", "mean", "std", "indicatrix_2d", "indicatrix_3d"};
#define N_CELL_NAMES (sizeof CELL_NAMES / sizeof CELL_NAMES[0])

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
    default: dims[0] = 72; dims[1] = 72; return 2;
    }
}

/* A table before format 3.4 holds the built-in families only: its names distinct, each a family's
 * (data_schema.table.check_contract; since 3.4 shape_records.c checks the names). */
static int check_family_names(loader *ld, const rbs_table *t)
{
    if (t->format_minor >= SHAPES_SINCE) return RBS_OK;
    for (int i = 0; i < t->n_shapes; i++) {
        int found = rbs_shape_code(t->shape_names[i]) >= 0;
        for (int j = 0; j < i; j++) found &= strcmp(t->shape_names[i], t->shape_names[j]) != 0;
        if (!found)
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'grid/shapes' must name distinct shapes among ellipsoid, prism, "
                            "cut_prism, tetrahedron (a table before format 3.%d); got '%s' at index %d", SHAPES_SINCE,
                            t->shape_names[i], i);
    }
    return RBS_OK;
}

/* The second-moment factors attribute of group grid: 1 to 8 numbers into kfac, their count into *n_kfac. */
static int read_second_moment_factors(loader *ld, hid_t grid, double kfac[8], int *n_kfac)
{
    hid_t attr = -1, space = -1;
    hssize_t count = -1;
    if (!attribute_exists(grid, "second_moment_factors"))
        return rbs_fail(ld, RBS_ERR_FORMAT, "missing attribute 'second_moment_factors' of group 'grid'");
    H5E_BEGIN_TRY {
        attr = H5Aopen(grid, "second_moment_factors", H5P_DEFAULT);
        if (attr >= 0) space = H5Aget_space(attr);
        if (space >= 0) count = H5Sget_simple_extent_npoints(space);
    } H5E_END_TRY;
    if (space >= 0) H5Sclose(space);
    if (attr >= 0) H5Aclose(attr);
    if (count < 1 || count > 8
        || read_numeric_attribute(grid, "second_moment_factors", H5T_NATIVE_DOUBLE, kfac, count, 0) != 0)
        return rbs_fail(ld, RBS_ERR_FORMAT, "cannot read the attribute 'second_moment_factors' of group 'grid' as 1 to 8 "
                    "numbers");
    *n_kfac = (int)count;
    return RBS_OK;
}

/* the attributes grid/law copies, in its order (data_schema.table.LAW_ATTRIBUTES; the last holds 4 numbers) */
static const char *const LAW_ATTRIBUTES[] = {
    "restitution_k", "restitution_p", "friction_q", "kappa", "n_max", "aspect_ratio_mean", "aspect_ratio_sd",
    "aspect_ratio_low", "aspect_ratio_high", "contact_tol", "set_tol", "max_steps", "second_moment_factors"};
#define N_LAW_ATTRIBUTES (sizeof LAW_ATTRIBUTES / sizeof LAW_ATTRIBUTES[0])

/* The attributes of LAW_ATTRIBUTES as grid/law holds them (data_schema.table.ReboundTable.law_values): every
 * one required, integers (n_max, max_steps) converted to double. */
static int law_values(loader *ld, hid_t grid, double values[LAW_SIZE])
{
    int n = 0;
    for (size_t i = 0; i + 1 < N_LAW_ATTRIBUTES; i++) {
        const char *name = LAW_ATTRIBUTES[i];
        if (strcmp(name, "n_max") == 0 || strcmp(name, "max_steps") == 0) {
            long long integer = 0;
            if (read_integer_attribute(ld, grid, "grid", name, &integer) != RBS_OK) return ld->code;
            values[n++] = (double)integer;
        } else if (read_double_attribute(ld, grid, "grid", name, &values[n++]) != RBS_OK) {
            return ld->code;
        }
    }
    double kfac[8];
    int n_kfac = 0;
    if (read_second_moment_factors(ld, grid, kfac, &n_kfac) != RBS_OK) return ld->code;
    if (n + n_kfac != LAW_SIZE)
        return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'grid/law' has shape (%d,), expected (%d,) (the attribute "
                    "'second_moment_factors' of group 'grid' holds %d numbers, not %d)", LAW_SIZE, n + n_kfac, n_kfac,
                    LAW_SIZE - n);
    memcpy(values + n, kfac, (size_t)n_kfac * sizeof(double));
    return RBS_OK;
}

/* Since 3.2: the checksummed copies grid/law and grid/shape_codes equal the attributes (restitution_k,
 * restitution_p in 3.2; every one of LAW_ATTRIBUTES since 3.3) and the names (each family's code, USER_SHAPE_CODE
 * for another shape), bit for bit (data_schema.table.check_contract, shape_codes). */
static int check_law_copies(loader *ld, hid_t grid, const rbs_table *t)
{
    if (t->format_minor < 2) return RBS_OK;
    double attributes[LAW_SIZE] = {t->restitution_k, t->restitution_p};
    const int size = t->format_minor >= 3 ? LAW_SIZE : 2;
    if (size == LAW_SIZE && law_values(ld, grid, attributes) != RBS_OK) return ld->code;
    int rank = 0;
    hsize_t dims[8];
    if (rbs_dataset_shape(ld, grid, "grid", "law", &rank, dims) != RBS_OK) return ld->code;
    if (rank != 1 || dims[0] != (hsize_t)size)
        return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'grid/law' has shape (%llu%s), expected (%d,)",
                    rank ? (unsigned long long)dims[0] : 0ULL, rank == 1 ? "," : ", ...", size);
    const hsize_t n_law = (hsize_t)size, shapes = (hsize_t)t->n_shapes;
    double *law = rbs_read_dataset(ld, grid, "grid", "law", H5T_NATIVE_DOUBLE, sizeof(double), 1, &n_law);
    if (!law) return ld->code;
    int differ = -1;
    for (int i = 0; differ < 0 && i < size; i++)
        if (memcmp(&law[i], &attributes[i], sizeof(double)) != 0) differ = i;
    if (differ >= 0) {
        char name[64];
        if (differ < (int)N_LAW_ATTRIBUTES - 1) snprintf(name, sizeof name, "%s", LAW_ATTRIBUTES[differ]);
        else snprintf(name, sizeof name, "second_moment_factors[%d]", differ - ((int)N_LAW_ATTRIBUTES - 1));
        rbs_fail(ld, RBS_ERR_FORMAT, "the attribute %s of group 'grid' (%.17g) differs from its checksummed copy in "
             "'grid/law' (%.17g)", name, attributes[differ], law[differ]);
    }
    free(law);
    if (differ >= 0) return ld->code;
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

/* Every row of shape_dictionary a standardised quantile function: non-decreasing, knots within ±√L up to
 * float32 round-off (data_schema.table.check_dictionary). */
static int check_dictionary(loader *ld, const float *dictionary, size_t rows, long long L)
{
    const float bound = (float)(sqrt((double)L) * (1.0 + DICTIONARY_BOUND_TOLERANCE));
    const size_t knots = (size_t)L + 1;
    for (size_t i = 0; i < rows * knots; i++)
        if (!(fabsf(dictionary[i]) <= bound))
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'cells/shape_dictionary' holds %g at element %zu; its values must "
                        "be in [-%.9g, %.9g] (sqrt of the levels %lld)", (double)dictionary[i], i, (double)bound,
                        (double)bound, L);
    for (size_t row = 0; row < rows; row++)
        for (size_t i = 1; i < knots; i++)
            if (dictionary[row * knots + i] < dictionary[row * knots + i - 1])
                return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'cells/shape_dictionary' row %zu decreases; each row (a "
                            "quantile function) must be non-decreasing", row);
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
    RULE(cluster_shape, n_cells * C * N_CHAIN, v < (double)M, "below the dictionary size");
    RULE(cluster_regime, n_cells * C, v <= 1.0, "0 or 1");
    RULE(status_counts, n_cells * 3, v >= 0.0, ">= 0");
    RULE(collision_counts, n_cells * 11, v >= 0.0, ">= 0");
    RULE(mean, n_cells * 6, fabs(v) <= CELL_VALUE_BOUND, "in [-1e+06, 1e+06]");
    RULE(std, n_cells * 6, v >= 0.0 && v <= CELL_VALUE_BOUND, "in [0, 1e+06]");
    RULE(indicatrix_2d, n_cells * 72, isfinite(v) && v >= 0.0, "finite and >= 0");
    RULE(indicatrix_3d, n_cells * 72 * 72, isfinite(v) && v >= 0.0, "finite and >= 0");
#undef RULE
    if (check_dictionary(ld, raw->shape_dictionary, n_cells * N_CHAIN * (size_t)M, L) != RBS_OK) return ld->code;
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

/* ------------------------------------------------------------------------- the direct model's parameters */

/* The attributes of the direct model (data_schema.table._direct_model_attributes: every one required since
 * 3.3, the fallbacks of old_tables.c before) into aspect, kfac (*n_kfac of them), the tolerances and q. */
static int direct_attributes(loader *ld, hid_t file, hid_t grid, const rbs_table *t, double kappa, double aspect[4],
                             double kfac[8], int *n_kfac, double *contact_tol, double *set_tol, long long *max_steps,
                             double *q)
{
    static const char *const aspect_names[4] = {"aspect_ratio_mean", "aspect_ratio_sd", "aspect_ratio_low",
                                                "aspect_ratio_high"};
    const int required = t->format_minor >= 3;
    int recorded = 1;
    for (int k = 0; k < 4; k++) {
        aspect[k] = NAN;
        recorded &= attribute_exists(grid, aspect_names[k]);
    }
    if (recorded || required) {
        for (int k = 0; k < 4; k++)
            if (read_double_attribute(ld, grid, "grid", aspect_names[k], &aspect[k]) != RBS_OK) return ld->code;
    } else {
        const size_t size = 1 << 20;
        char *config = malloc(size);
        if (!config) return rbs_fail(ld, RBS_ERR_MEMORY, "out of memory reading the root attribute 'config'");
        if (read_string_attribute(file, "config", config, size) == 0) rbs_config_aspect(config, aspect);
        free(config);
    }
    *n_kfac = RBS_N_FAMILIES;
    if (required || attribute_exists(grid, "second_moment_factors")) {
        if (read_second_moment_factors(ld, grid, kfac, n_kfac) != RBS_OK) return ld->code;
    } else {
        rbs_built_with_second_moment_factors(kappa, kfac);
    }
    rbs_built_with_tolerances(contact_tol, set_tol, max_steps);
    *q = NAN;
    if (((required || attribute_exists(grid, "contact_tol")) && read_double_attribute(ld, grid, "grid", "contact_tol", contact_tol))
        || ((required || attribute_exists(grid, "set_tol")) && read_double_attribute(ld, grid, "grid", "set_tol", set_tol))
        || ((required || attribute_exists(grid, "max_steps")) && read_integer_attribute(ld, grid, "grid", "max_steps", max_steps))
        || ((required || attribute_exists(grid, "friction_q")) && read_double_attribute(ld, grid, "grid", "friction_q", q)))
        return ld->code;
    return RBS_OK;
}

#define OUT_OF_RANGE "the direct model's parameters are out of range: "

/* The direct model's parameters (surrogate.table.SurrogateTable.direct_parameters): none (has_direct = 0) if the table does
 * not record its second-moment factors, else the P_* array of direct_model.runtime.model_parameters after
 * the same range checks in the same order (RBS_ERR_FORMAT naming the value). The aspect-ratio law and the
 * second-moment factors read (NaN where unknown) into aspect and family_kfac, for the shapes' records. */
static int read_direct_parameters(loader *ld, hid_t file, hid_t grid, rbs_table *t, double kappa,
                                  double aspect[4], double family_kfac[RBS_N_FAMILIES])
{
    double kfac[8], contact_tol, set_tol, q;
    long long max_steps = 0;
    int n_kfac = 0;
    if (direct_attributes(ld, file, grid, t, kappa, aspect, kfac, &n_kfac, &contact_tol, &set_tol, &max_steps, &q) != RBS_OK)
        return ld->code;
    for (int k = 0; k < RBS_N_FAMILIES; k++) family_kfac[k] = n_kfac == RBS_N_FAMILIES ? kfac[k] : NAN;
    for (int k = 0; k < n_kfac; k++)
        if (!isfinite(kfac[k])) return RBS_OK;
    /* tables without friction_q (before 3.1) were built before the wall law was configurable: q = 1 */
    if (!isfinite(q)) q = 1.0;
    double mean = aspect[0], sd = aspect[1], low = aspect[2], high = aspect[3];
    if (!(0.0 < low && low < high && high <= 1.0))
        return rbs_fail(ld, RBS_ERR_FORMAT, OUT_OF_RANGE "The aspect-ratio bounds must satisfy 0 < low < high <= 1; got "
                    "low=%.17g, high=%.17g.", low, high);
    if (!(sd > 0.0 && isfinite(sd)))
        return rbs_fail(ld, RBS_ERR_FORMAT, OUT_OF_RANGE "The aspect-ratio 'sd' must be finite and > 0; got %.17g.", sd);
    if (!isfinite(mean))
        return rbs_fail(ld, RBS_ERR_FORMAT, OUT_OF_RANGE "The aspect-ratio 'mean' must be finite; got %.17g.", mean);
    if (!(0.0 <= kappa && kappa < 1.0))
        return rbs_fail(ld, RBS_ERR_FORMAT, OUT_OF_RANGE "The 'kappa' parameter must be in [0, 1); got %.17g.", kappa);
    const long long two53 = 9007199254740992LL;
    if (!(t->n_max >= 1 && t->n_max < two53))
        return rbs_fail(ld, RBS_ERR_FORMAT, OUT_OF_RANGE "The 'n_max' parameter must be an integer in [1, 2**53); got %lld.",
                    t->n_max);
    if (!(max_steps >= 1 && max_steps < two53))
        return rbs_fail(ld, RBS_ERR_FORMAT, OUT_OF_RANGE "The 'max_steps' parameter must be an integer in [1, 2**53); got "
                    "%lld.", max_steps);
    if (!(isfinite(contact_tol) && contact_tol > 0.0))
        return rbs_fail(ld, RBS_ERR_FORMAT, OUT_OF_RANGE "The 'contact_tol' parameter must be finite and > 0 (units of a); "
                    "got %.17g.", contact_tol);
    if (!(isfinite(set_tol) && set_tol > 0.0))
        return rbs_fail(ld, RBS_ERR_FORMAT, OUT_OF_RANGE "The 'set_tol' parameter must be finite and > 0 (units of a); got "
                    "%.17g.", set_tol);
    int kfac_ok = n_kfac == RBS_N_FAMILIES;
    for (int k = 0; kfac_ok && k < n_kfac; k++) kfac_ok = kfac[k] > 0.0 && kfac[k] < 1.0;
    if (!kfac_ok)
        return rbs_fail(ld, RBS_ERR_FORMAT, OUT_OF_RANGE "The 'second_moment_factors' parameter must be %d numbers in (0, "
                    "1), one per shape code; got %d numbers, the first %.17g.", RBS_N_FAMILIES, n_kfac, kfac[0]);
    double *p = t->direct_parameters;
    p[P_ASPECT_MEAN] = mean;
    p[P_ASPECT_SD] = sd;
    p[P_ASPECT_LOW] = low;
    p[P_ASPECT_HIGH] = high;
    p[P_CDF_LOW] = rbs_normal_cdf((low - mean) / sd);
    p[P_CDF_HIGH] = rbs_normal_cdf((high - mean) / sd);
    p[P_KAPPA] = kappa;
    p[P_N_MAX] = (double)t->n_max;
    p[P_WALL] = t->restitution_k;
    p[P_WALL + 1] = t->restitution_p;
    p[P_WALL + 2] = q;
    p[P_CONTACT_TOL] = contact_tol;
    p[P_SET_TOL] = set_tol;
    p[P_MAX_STEPS] = (double)max_steps;
    for (int k = 0; k < RBS_N_FAMILIES; k++) p[P_KFAC + k] = kfac[k];
    t->has_direct = 1;
    return RBS_OK;
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
    for (int i = 0; i < 5; i++) {
        static const char *const names[] = {"created", "package_version", "config", "config_sha256", "master_seed"};
        if (!attribute_exists(file, names[i])) {
            rbs_fail(ld, RBS_ERR_FORMAT, "missing root attribute '%s'", names[i]);
            goto done;
        }
    }
    double kappa;
    if (read_double_attribute(ld, grid, "grid", "kappa", &kappa) != RBS_OK
        || read_double_attribute(ld, grid, "grid", "restitution_k", &t->restitution_k) != RBS_OK
        || read_double_attribute(ld, grid, "grid", "restitution_p", &t->restitution_p) != RBS_OK
        || read_integer_attribute(ld, grid, "grid", "particles_per_cell", &t->particles_per_cell) != RBS_OK
        || read_integer_attribute(ld, grid, "grid", "n_max", &t->n_max) != RBS_OK)
        goto done;
    if (!(isfinite(t->restitution_k) && t->restitution_k > 0.0 && isfinite(t->restitution_p) && t->restitution_p > 0.0)) {
        rbs_fail(ld, RBS_ERR_FORMAT, "the wall law attributes of group 'grid' must be finite and > 0: restitution_k = %g, "
             "restitution_p = %g", t->restitution_k, t->restitution_p);
        goto done;
    }
    if (read_shapes(ld, grid, t) != RBS_OK) goto done;
    if (check_family_names(ld, t) != RBS_OK) goto done;
    t->alpha1_deg = read_grid(ld, grid, "alpha1_deg", 0.0, 1, 90.0, 0.0, "deg", &t->n_alpha1);
    if (!t->alpha1_deg) goto done;
    t->speed_m_s = read_grid(ld, grid, "speed_m_s", SPEED_GRID_MIN, 0, SPEED_GRID_MAX, MAX_SPEED_RATIO, "m/s",
                             &t->n_speed);
    if (!t->speed_m_s) goto done;
    if (check_law_copies(ld, grid, t) != RBS_OK) goto done;

    const hsize_t lead[3] = {(hsize_t)t->n_shapes, (hsize_t)t->n_alpha1, (hsize_t)t->n_speed};
    const size_t n_cells = (size_t)t->n_shapes * (size_t)t->n_alpha1 * (size_t)t->n_speed;
    if ((double)n_cells * (double)C * ROW_SIZE > 4e9 || (double)n_cells * 6.0 * (double)M * (double)(L + 1) > 4e9) {
        rbs_fail(ld, RBS_ERR_FORMAT, "inconsistent table: %zu cells of %lld components are too large", n_cells, C);
        goto done;
    }
    /* every cell dataset's shape (only metadata: nothing read yet) */
    for (size_t i = 0; i < N_CELL_NAMES; i++) {
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
#undef READ_CELLS
    if (check_cell_values(ld, &raw, n_cells, (size_t)C, M, L) != RBS_OK) goto done;
    {
        const char *what = NULL;
        int code = rbs_derive(t, &raw, &what);
        if (code == RBS_ERR_MEMORY) rbs_fail(ld, code, "out of memory deriving the kernel arrays");
        else if (code != RBS_OK) rbs_fail(ld, code, "the derived kernel array %s is not finite (inconsistent table)", what);
    }
    if (ld->code == RBS_OK) {
        double aspect[4], kfac[RBS_N_FAMILIES];
        if (read_direct_parameters(ld, file, grid, t, kappa, aspect, kfac) == RBS_OK
            && rbs_shape_records_load(ld, file, t, kappa, aspect, kfac) == RBS_OK && t->has_direct
            && rbs_direct_shapes_build(t) != RBS_OK)
            rbs_fail(ld, RBS_ERR_MEMORY, "out of memory building the direct model's shapes");
    }

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
    if (!table) return rbs_fail(&ld, RBS_ERR_ARGUMENT, "no place for the table (table is NULL)");
    *table = NULL;
    if (!path) return rbs_fail(&ld, RBS_ERR_ARGUMENT, "no path given");
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

int rbs_table_shape_info(const rbs_table *t, int i, rbs_shape_info *info)
{
    if (!t || !info || i < 0 || i >= t->n_shapes) return RBS_ERR_ARGUMENT;
    const rbs_shape_records *r = &t->shapes;
    info->name = t->shape_names[i];
    info->kind = r->kind[i];
    info->family = r->family[i];
    info->n_vertices = (int)(r->vertex_start[i + 1] - r->vertex_start[i]);
    info->vertices = info->n_vertices ? r->vertices + 3 * r->vertex_start[i] : NULL;
    memcpy(info->inertia, r->inertia + 3 * i, sizeof info->inertia);
    memcpy(info->aspect, r->aspect + 4 * i, sizeof info->aspect);
    info->both_hands = r->both_hands[i];
    info->direct_shape = t->model_shape ? t->model_shape[i] : -1;
    return RBS_OK;
}

void rbs_table_alpha1_range(const rbs_table *t, double *lo, double *hi)
{
    if (lo) *lo = t ? t->alpha1_deg[0] : NAN;
    if (hi) *hi = t ? t->alpha1_deg[t->n_alpha1 - 1] : NAN;
}

void rbs_table_speed_range(const rbs_table *t, double *lo, double *hi)
{
    if (lo) *lo = t ? t->speed_m_s[0] : NAN;
    if (hi) *hi = t ? t->speed_m_s[t->n_speed - 1] : NAN;
}

const double *rbs_table_alpha1_grid(const rbs_table *t, int *count)
{
    if (count) *count = t ? t->n_alpha1 : 0;
    return t ? t->alpha1_deg : NULL;
}

const double *rbs_table_speed_grid(const rbs_table *t, int *count)
{
    if (count) *count = t ? t->n_speed : 0;
    return t ? t->speed_m_s : NULL;
}

void rbs_table_info_get(const rbs_table *t, rbs_table_info *info)
{
    if (!info) return;
    memset(info, 0, sizeof *info);
    if (!t) return;
    info->n_shapes = t->n_shapes;
    info->n_alpha1 = t->n_alpha1;
    info->n_speed = t->n_speed;
    info->n_clusters = t->n_clusters;
    info->n_levels = t->n_levels;
    info->n_dictionary = t->n_dictionary;
    info->n_pieces = t->n_pieces;
    info->format_major = t->format_major;
    info->format_minor = t->format_minor;
    info->particles_per_cell = t->particles_per_cell;
    info->n_max = t->n_max;
    info->restitution_k = t->restitution_k;
    info->restitution_p = t->restitution_p;
    info->kernel_bytes = (t->alpha1_axis_len + t->speed_axis_len + t->cells_len + (size_t)t->n_speed
                          + t->restitution_pieces_len) * sizeof(double)
                         + (t->clusters_len + t->dictionary_len) * sizeof(float);
}

int rbs_table_kernel_array(const rbs_table *t, const char *name, const void **data, size_t *count, int *dtype)
{
    const void *p = NULL;
    size_t n = 0;
    int type = RBS_FLOAT64;
    if (!t || !name) return RBS_ERR_ARGUMENT;
    if (strcmp(name, "alpha1_axis") == 0) { p = t->alpha1_axis; n = t->alpha1_axis_len; }
    else if (strcmp(name, "speed_axis") == 0) { p = t->speed_axis; n = t->speed_axis_len; }
    else if (strcmp(name, "cells") == 0) { p = t->cells; n = t->cells_len; }
    else if (strcmp(name, "clusters") == 0) { p = t->clusters; n = t->clusters_len; type = RBS_FLOAT32; }
    else if (strcmp(name, "dictionary") == 0) { p = t->dictionary; n = t->dictionary_len; type = RBS_FLOAT32; }
    else if (strcmp(name, "speed_restitution") == 0) { p = t->speed_restitution; n = (size_t)t->n_speed; }
    else if (strcmp(name, "restitution_pieces") == 0) { p = t->restitution_pieces; n = t->restitution_pieces_len; }
    else if (strcmp(name, "direct_parameters") == 0 && t->has_direct) { p = t->direct_parameters; n = N_PARAMS; }
    else return RBS_ERR_ARGUMENT;
    if (data) *data = p;
    if (count) *count = n;
    if (dtype) *dtype = type;
    return RBS_OK;
}
