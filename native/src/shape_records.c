/*
 * shape_records.c: the shapes a table holds, as data (data_schema.shape_records): group /shapes of a table read
 * and checked as check_shape_datasets and records_from_arrays check it, in the same order. The only place the C
 * library reads these arrays.
 *
 * A built-in family's row must be the family's record at the table's κ and aspect-ratio law, bit for bit: kind,
 * vertices (the body of direct_model.registry.built_in_shape: rbs_body_vertices at b/a = c/b = 1, rows sorted and
 * repeated corners dropped, as numpy.unique), triangles (the fans of its faces, registry._faces_to_triangles),
 * inertia (the mass properties of that surface, direct_model.polyhedron.mass_properties; the ellipsoid's 2/5),
 * law and hands; a user polyhedron's record is rebuilt from its vertices and triangles as registry.polyhedron
 * does (a closed surface in its principal frame), and its mass properties must give its stored inertia bit for
 * bit. polyhedron.c computes both as Python does, so both loaders give one verdict on every table.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "polyhedron.h"
#include "runtime.h"
#include "shape_records.h"
#include "shapes.h"

#define MIN_HULL_VERTICES 4         /* data_schema.shape_records.MIN_HULL_VERTICES */
#define MIN_THICKNESS 1e-3          /* direct_model.registry.MIN_THICKNESS, units of a */
#define FRAME_CHECK 1e-9            /* direct_model.registry.FRAME_CHECK */
#define VERTEX_BOUND (1.5 * (1.0 + FRAME_CHECK))            /* data_schema.shape_records.VERTEX_BOUND */
#define INERTIA_BOUND (2.0 * VERTEX_BOUND * VERTEX_BOUND)   /* data_schema.shape_records.INERTIA_BOUND */
#define NAME_MAX_LENGTH (RBS_SHAPE_NAME_SIZE - 1)
#define MAX_FAMILY_NORMALS 14       /* the cut prism's faces: 6 sides and 8 corners */
#define MAX_FAMILY_TRIANGLES (2 * MAX_VERTICES - 4)         /* a family's surface: a hull of MAX_VERTICES at most */

_Static_assert(MAX_VERTICES <= MAX_STACK_VERTICES, "a family's hull takes no malloc (its checks have no memory error)");

void rbs_shape_records_free(rbs_shape_records *r)
{
    free(r->kind);
    free(r->family);
    free(r->vertex_start);
    free(r->vertices);
    free(r->triangle_start);
    free(r->triangles);
    free(r->inertia);
    free(r->aspect);
    free(r->both_hands);
    memset(r, 0, sizeof *r);
}

/* lexicographic order of two vertex rows (numpy.unique's order along axis 0) */
static int compare_rows(const void *a, const void *b)
{
    const double *p = a, *q = b;
    for (int k = 0; k < 3; k++)
        if (p[k] != q[k]) return p[k] < q[k] ? -1 : 1;
    return 0;
}

/* The family's body at b/a = c/b = 1 (direct_model.registry.built_in_shape): its distinct vertices, sorted, into out
 * (at most MAX_VERTICES rows); returns their number, 0 for the ellipsoid. */
static int family_vertices(int family, double kappa, double *out)
{
    int n = rbs_body_vertices(family, 1.0, 1.0, 1.0, kappa, 1.0, out), kept = 0;
    qsort(out, (size_t)n, 3 * sizeof(double), compare_rows);
    for (int i = 0; i < n; i++)
        if (kept == 0 || compare_rows(out + 3 * i, out + 3 * (kept - 1)) != 0) {
            memmove(out + 3 * kept, out + 3 * i, 3 * sizeof(double));
            kept++;
        }
    return kept;
}

/* The outward normals of the family's faces (direct_model.registry: _prism_body, _cut_prism_body,
 * _tetrahedron_body) into normals (at most MAX_FAMILY_NORMALS rows); their number. `body`: the family's distinct
 * vertices, sorted (family_vertices). */
static int family_normals(int family, const double *body, int n_body, double *normals)
{
    static const double axes[6][3] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0},
                                      {-1.0, -0.0, -0.0}, {-0.0, -1.0, -0.0}, {-0.0, -0.0, -1.0}};
    if (family == RBS_TETRAHEDRON) {                    /* each face faces away from the opposite vertex */
        for (int k = 0; k < 3 * n_body; k++) normals[k] = -body[k];
        return n_body;
    }
    memcpy(normals, axes, sizeof axes);
    int n = 6;
    if (family == RBS_CUT_PRISM)                        /* and the eight corners' cuts */
        for (int i = 0; i < 8; i++) {
            normals[3 * n] = i & 4 ? 1.0 : -1.0;
            normals[3 * n + 1] = i & 2 ? 1.0 : -1.0;
            normals[3 * n + 2] = i & 1 ? 1.0 : -1.0;
            n++;
        }
    return n;
}

/* numpy's max (min) of a running maximum (minimum) and one more value: NaN once any value is NaN */
static double numpy_max(double m, double x) { return isnan(m) || isnan(x) ? NAN : x > m ? x : m; }
static double numpy_min(double m, double x) { return isnan(m) || isnan(x) ? NAN : x < m ? x : m; }

/* What direct_model.registry.polyhedron makes of a hull given in its principal frame, units of a: its principal
 * J/m into inertia, 0; or -1 and, into `why`, the words of its ValueError (no volume) or ShapeError (not a
 * principal frame of unit size, too flat); -2 out of memory (a large hull's work space). Its checks as it writes
 * them (a comparison with NaN is false). */
static int hull_inertia(const double *vertices, int n_vertices, const int32_t *triangles, int n_triangles,
                        double inertia[3], char *why, size_t size)
{
    rbs_mass_properties props;
    int found = rbs_hull_mass_properties(vertices, n_vertices, triangles, n_triangles, &props);
    if (found == -2) return -2;
    if (found != 0) {
        snprintf(why, size, "the triangles enclose no volume (volume %.17g): not a closed outward surface",
                 props.volume);
        return -1;
    }
    double half[3], largest = -INFINITY, thinnest = INFINITY, centre = 0.0, off = 0.0;
    for (int c = 0; c < 3; c++) {
        double lo = vertices[c], hi = vertices[c];          /* finite (checked) */
        for (int i = 1; i < n_vertices; i++) {
            lo = fmin(lo, vertices[3 * i + c]);
            hi = fmax(hi, vertices[3 * i + c]);
        }
        half[c] = (hi - lo) / 2.0;
        largest = numpy_max(largest, half[c]);
        thinnest = numpy_min(thinnest, half[c]);
        centre = numpy_max(centre, fabs(props.centroid[c]));
        for (int d = 0; d < 3; d++)     /* inertia − diag(diag(inertia)) */
            off = numpy_max(off, fabs(props.inertia[c][d] - (c == d ? props.inertia[c][d] : 0.0)));
    }
    if (fabs(largest - 1.0) > FRAME_CHECK || centre > FRAME_CHECK || off > FRAME_CHECK) {
        snprintf(why, size, "the vertices are not in a principal frame of unit size (centre of mass [%.17g, %.17g, "
                 "%.17g], products of inertia up to %.3g, largest half-extent %.17g); build the record with grain()",
                 props.centroid[0], props.centroid[1], props.centroid[2], off, largest);
        return -1;
    }
    if (thinnest < MIN_THICKNESS) {
        snprintf(why, size, "the hull is flat: its thinnest half-extent is %.3g of its largest; allowed: >= %g",
                 thinnest, MIN_THICKNESS);
        return -1;
    }
    for (int k = 0; k < 3; k++) inertia[k] = props.inertia[k][k];
    return 0;
}

/* the law (mean, sd, low, high) is one direct_model.shapes.AspectRatioLaw takes */
static int law_ok(const double *law)
{
    return isfinite(law[0]) && isfinite(law[1]) && law[1] > 0.0 && 0.0 < law[2] && law[2] < law[3] && law[3] <= 1.0;
}

/* Dataset `name` of group shapes, of HDF5 class `cls` (a string, integer or float: data_schema.table._read_group's
 * check), read as `memtype` after checking its shape (`rank` × dims; dims[0] < 0: any first dimension, returned
 * in *rows). */
static void *read_member(loader *ld, hid_t group, const char *name, H5T_class_t cls, hid_t memtype, size_t size,
                         int rank, long long first, long long second, int64_t *rows)
{
    int found_rank = 0;
    hsize_t found[8], dims[2] = {(hsize_t)(first < 0 ? 0 : first), (hsize_t)second};
    if (rbs_dataset_shape(ld, group, "shapes", name, &found_rank, found) != RBS_OK) return NULL;
    hid_t ds = -1, type = -1;
    H5T_class_t stored = H5T_NO_CLASS;
    H5E_BEGIN_TRY {
        ds = H5Dopen2(group, name, H5P_DEFAULT);
        if (ds >= 0) type = H5Dget_type(ds);
        if (type >= 0) stored = H5Tget_class(type);
    } H5E_END_TRY;
    if (type >= 0) H5Tclose(type);
    if (ds >= 0) H5Dclose(ds);
    if (stored != cls) {
        rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/%s' is of another type (HDF5 class %d, expected %d)", name,
                 (int)stored, (int)cls);
        return NULL;
    }
    if (first < 0 && found_rank == rank) dims[0] = found[0];
    if (rows) *rows = (int64_t)dims[0];
    return rbs_read_dataset(ld, group, "shapes", name, memtype, size, rank, dims);
}

/* The checks of data_schema.shape_records.check_shape_datasets, then the families' rows (records_from_arrays). */
static int check_records(loader *ld, rbs_table *t, const char *names, const int32_t *triangles,
                         const int64_t *triangle_start, int64_t n_vertex, int64_t n_triangle, double kappa,
                         const double aspect[4])
{
    rbs_shape_records *r = &t->shapes;
    const int n = t->n_shapes;
    for (int i = 0; i < n; i++) {
        const char *name = t->shape_names[i], *copy = names + (size_t)i * RBS_SHAPE_NAME_SIZE;
        if (strcmp(name, copy) != 0)
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'grid/shapes' ('%s' at index %d) differs from its checksummed "
                            "copy 'shapes/name' ('%s')", name, i, copy);
        size_t length = strlen(name);
        int ok = length >= 1 && length <= NAME_MAX_LENGTH
                 && ((name[0] >= 'A' && name[0] <= 'Z') || (name[0] >= 'a' && name[0] <= 'z'));
        for (size_t k = 1; ok && k < length; k++)
            ok = (name[k] >= 'A' && name[k] <= 'Z') || (name[k] >= 'a' && name[k] <= 'z')
                 || (name[k] >= '0' && name[k] <= '9') || name[k] == '_';
        ok = ok && strcmp(name, "mix") != 0;
        for (int j = 0; ok && j < i; j++) ok = strcmp(name, t->shape_names[j]) != 0;
        if (!ok)
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/name' holds '%s' at index %d; each name must be a "
                            "built-in's (ellipsoid, prism, cut_prism, tetrahedron) or 1-64 letters, digits or "
                            "underscores starting with a letter (not 'mix'), each once", name, i);
        r->family[i] = rbs_shape_code(name);
    }
    for (int i = 0; i < n; i++)
        if (r->kind[i] != RBS_SMOOTH && r->kind[i] != RBS_POLYHEDRON)
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/kind' holds %d at element %d; its values must be 0 "
                            "(smooth) or 1 (convex polyhedron)", (int)r->kind[i], i);
    for (int which = 0; which < 2; which++) {
        const int64_t *start = which ? triangle_start : r->vertex_start, total = which ? n_triangle : n_vertex;
        int ok = start[0] == 0 && start[n] == total;
        for (int i = 0; ok && i < n; i++) ok = start[i + 1] >= start[i];
        if (!ok)
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/%s_start' must rise from 0 to %lld (the rows of "
                            "'shapes/%ss')", which ? "triangle" : "vertex", (long long)total,
                            which ? "triangle" : "vertex");
    }
    for (int i = 0; i < n; i++) {
        int64_t nv = r->vertex_start[i + 1] - r->vertex_start[i], nt = triangle_start[i + 1] - triangle_start[i];
        int polyhedral = r->kind[i] == RBS_POLYHEDRON;
        if (polyhedral && (nv < MIN_HULL_VERTICES || nv > MAX_HULL_VERTICES))
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/vertex_start' gives shape '%s' %lld vertices; "
                            "allowed: %d to %d for a convex polyhedron", t->shape_names[i], (long long)nv,
                            MIN_HULL_VERTICES, MAX_HULL_VERTICES);
        if (!polyhedral && nv != 0)
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/vertex_start' gives shape '%s' %lld vertices; "
                            "allowed: 0 for a smooth body", t->shape_names[i], (long long)nv);
        if (nt != (polyhedral ? 2 * nv - 4 : 0))
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/triangle_start' gives shape '%s' %lld triangles; a hull "
                            "of %lld vertices has %lld", t->shape_names[i], (long long)nt, (long long)nv,
                            (long long)(nv > 2 ? 2 * nv - 4 : 0));
        for (int64_t k = 3 * triangle_start[i]; k < 3 * triangle_start[i + 1]; k++)
            if (triangles[k] < 0 || triangles[k] >= nv)
                return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/triangles' of shape '%s' holds a vertex index "
                                "outside 0..%lld", t->shape_names[i], (long long)(nv - 1));
        if (polyhedral) { /* a vertex on no triangle is off the surface the contact search walks over */
            unsigned char *on = calloc((size_t)nv, 1);
            if (!on) return rbs_fail(ld, RBS_ERR_MEMORY, "out of memory checking the triangles of shape '%s'",
                                     t->shape_names[i]);
            for (int64_t k = 3 * triangle_start[i]; k < 3 * triangle_start[i + 1]; k++) on[triangles[k]] = 1;
            int64_t first = 0;
            while (first < nv && on[first]) first++;
            free(on);
            if (first < nv)
                return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/triangles' of shape '%s' leaves vertex %lld on no "
                                "triangle; every vertex of a hull is on its surface", t->shape_names[i],
                                (long long)first);
        }
    }
    for (int64_t k = 0; k < 3 * n_vertex; k++)
        if (!(fabs(r->vertices[k]) <= VERTEX_BOUND))
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/vertices' holds %.17g at element %lld; its values must "
                            "be finite and in [-%.17g, %.17g] (units of a)", r->vertices[k], (long long)k, VERTEX_BOUND,
                            VERTEX_BOUND);
    for (int i = 0; i < n; i++) {
        if (r->kind[i] != RBS_POLYHEDRON) continue;
        double half[3], largest = 0.0, thinnest = INFINITY;
        for (int c = 0; c < 3; c++) {
            double lo = INFINITY, hi = -INFINITY;
            for (int64_t v = r->vertex_start[i]; v < r->vertex_start[i + 1]; v++) {
                lo = fmin(lo, r->vertices[3 * v + c]);
                hi = fmax(hi, r->vertices[3 * v + c]);
            }
            half[c] = (hi - lo) / 2.0;
            largest = fmax(largest, half[c]);
            thinnest = fmin(thinnest, half[c]);
        }
        if (!(fabs(largest - 1.0) <= FRAME_CHECK && thinnest >= MIN_THICKNESS))
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/vertices' gives shape '%s' half-extents [%.17g, %.17g, "
                            "%.17g]; the largest must be 1 within %g (units of a) and the thinnest >= %g",
                            t->shape_names[i], half[0], half[1], half[2], FRAME_CHECK, MIN_THICKNESS);
    }
    for (int k = 0; k < 3 * n; k++)
        if (!(r->inertia[k] > 0.0 && r->inertia[k] <= INERTIA_BOUND))
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/inertia' holds %.17g at element %d; its values must be "
                            "in (0, %.17g] (units of a^2)", r->inertia[k], k, INERTIA_BOUND);
    for (int i = 0; i < n; i++) {
        const double *J = r->inertia + 3 * i, sum = J[0] + J[1] + J[2];
        if (2.0 * J[0] >= sum || 2.0 * J[1] >= sum || 2.0 * J[2] >= sum)
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/inertia' row %d [%.17g, %.17g, %.17g] breaks the "
                            "triangle inequality; each principal J/m must be below the sum of the other two", i, J[0],
                            J[1], J[2]);
    }
    for (int i = 0; i < n; i++) {
        const double *law = r->aspect + 4 * i;
        if (isnan(law[0]) && isnan(law[1]) && isnan(law[2]) && isnan(law[3])) continue;
        if (!law_ok(law))
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/aspect' row %d is [%.17g, %.17g, %.17g, %.17g]; a law "
                            "(mean, sd, low, high) must be finite with sd > 0 and 0 < low < high <= 1, or all NaN "
                            "(fixed proportions)", i, law[0], law[1], law[2], law[3]);
    }
    for (int i = 0; i < n; i++)
        if (r->both_hands[i] > 1)
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/both_hands' holds %d at element %d; its values must be "
                            "0 or 1", (int)r->both_hands[i], i);
    /* each row's record, in table order (records_from_arrays): a built-in name carries the family's record; a user
     * polyhedron's is rebuilt from its hull, whose mass properties must give its stored inertia */
    for (int i = 0; i < n; i++) {
        const char *name = t->shape_names[i];
        const int family = r->family[i];
        const int64_t v0 = r->vertex_start[i], nv = r->vertex_start[i + 1] - v0;
        const int64_t t0 = triangle_start[i], nt = triangle_start[i + 1] - t0;
        char why[384];
        if (family < 0) {
            double inertia[3];
            if (r->kind[i] != RBS_POLYHEDRON) continue;     /* a smooth body: its semi-axes come from its inertia */
            int made = hull_inertia(r->vertices + 3 * v0, (int)nv, triangles + 3 * t0, (int)nt, inertia, why,
                                    sizeof why);
            if (made == -2)
                return rbs_fail(ld, RBS_ERR_MEMORY, "out of memory for the mass properties of shape '%s' (%lld "
                                "vertices)", name, (long long)nv);
            if (made != 0)
                return rbs_fail(ld, RBS_ERR_FORMAT, "datasets 'shapes/vertices' and 'shapes/triangles' of shape '%s' "
                                "are not a hull in its principal frame: %s", name, why);
            const double *stored = r->inertia + 3 * i;
            if (memcmp(inertia, stored, sizeof inertia) != 0)
                return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/inertia' of shape '%s' ([%.17g, %.17g, %.17g]) "
                                "differs from the mass properties of its hull, datasets 'shapes/vertices' and "
                                "'shapes/triangles' ([%.17g, %.17g, %.17g])", name, stored[0], stored[1], stored[2],
                                inertia[0], inertia[1], inertia[2]);
            continue;
        }
        /* the family's record (direct_model.registry.built_in_shape; the ellipsoid takes no κ) */
        if (!law_ok(aspect) || (family != RBS_ELLIPSOID && !(kappa >= 0.0 && kappa < 1.0)))
            return rbs_fail(ld, RBS_ERR_FORMAT, "the built-in shape '%s' cannot be made at the table's kappa %.17g and "
                            "aspect-ratio law (%.17g, %.17g, %.17g, %.17g)", name, kappa, aspect[0], aspect[1],
                            aspect[2], aspect[3]);
        double body[3 * MAX_VERTICES], normals[3 * MAX_FAMILY_NORMALS], inertia[3] = {2.0 / 5.0, 2.0 / 5.0, 2.0 / 5.0};
        int32_t surface[3 * MAX_FAMILY_TRIANGLES];
        int n_body = family_vertices(family, kappa, body), n_surface = 0;
        if (family != RBS_ELLIPSOID) {
            /* at most MAX_VERTICES vertices: their work space on the stack, no malloc to fail */
            n_surface = rbs_faces_to_triangles(body, n_body, normals, family_normals(family, body, n_body, normals),
                                               surface, MAX_FAMILY_TRIANGLES);
            if (n_surface < 0) snprintf(why, sizeof why, "its faces give more than %d triangles", MAX_FAMILY_TRIANGLES);
            if (n_surface < 0 || hull_inertia(body, n_body, surface, n_surface, inertia, why, sizeof why) != 0)
                return rbs_fail(ld, RBS_ERR_FORMAT, "the built-in shape '%s' cannot be made at the table's kappa %.17g "
                                "and aspect-ratio law (%.17g, %.17g, %.17g, %.17g): %s", name, kappa, aspect[0],
                                aspect[1], aspect[2], aspect[3], why);
        }
        const char *differs = NULL;
        if (r->kind[i] != (family == RBS_ELLIPSOID ? RBS_SMOOTH : RBS_POLYHEDRON)) differs = "kind";
        else if (nv != n_body || memcmp(r->vertices + 3 * v0, body, (size_t)n_body * 3 * sizeof(double)) != 0)
            differs = "vertices";
        else if (nt != n_surface || memcmp(triangles + 3 * t0, surface, (size_t)n_surface * 3 * sizeof(int32_t)) != 0)
            differs = "triangles";
        else if (memcmp(r->inertia + 3 * i, inertia, sizeof inertia) != 0) differs = "inertia";
        else if (memcmp(r->aspect + 4 * i, aspect, 4 * sizeof(double)) != 0) differs = "aspect";
        else if (r->both_hands[i] != (family == RBS_TETRAHEDRON)) differs = "both_hands";
        if (differs)
            return rbs_fail(ld, RBS_ERR_FORMAT, "dataset 'shapes/%s' of the built-in shape '%s' differs from the "
                            "family's record at the table's kappa and aspect-ratio law (dataset 'model/parameters')", differs, name);
    }
    return RBS_OK;
}

int rbs_shape_records_load(loader *ld, hid_t file, rbs_table *t, double kappa, const double aspect[4])
{
    if (!rbs_link_exists(file, "shapes")) return rbs_fail(ld, RBS_ERR_FORMAT, "missing group 'shapes'");
    hid_t group = -1, name_type = -1;
    H5E_BEGIN_TRY { group = H5Gopen2(file, "shapes", H5P_DEFAULT); } H5E_END_TRY;
    if (group < 0) return rbs_fail(ld, RBS_ERR_FORMAT, "'shapes' is not a readable group (truncated or corrupt?)");
    rbs_shape_records *r = &t->shapes;
    const long long n = t->n_shapes;
    char *names = NULL;
    int64_t n_vertex = 0, n_triangle = 0;
    name_type = H5Tcopy(H5T_C_S1);
    H5Tset_size(name_type, RBS_SHAPE_NAME_SIZE);
    H5Tset_strpad(name_type, H5T_STR_NULLTERM);
    r->family = calloc((size_t)n, sizeof *r->family);
    if (!r->family) {
        rbs_fail(ld, RBS_ERR_MEMORY, "out of memory for the shapes' records");
        goto done;
    }
    /* the datasets in the order of data_schema.shape_records.SHAPE_DATASETS */
    if (!(names = read_member(ld, group, "name", H5T_STRING, name_type, RBS_SHAPE_NAME_SIZE, 1, n, 0, NULL))
        || !(r->kind = read_member(ld, group, "kind", H5T_INTEGER, H5T_NATIVE_INT8, 1, 1, n, 0, NULL))
        || !(r->vertex_start = read_member(ld, group, "vertex_start", H5T_INTEGER, H5T_NATIVE_INT64, 8, 1, n + 1, 0,
                                           NULL))
        || !(r->vertices = read_member(ld, group, "vertices", H5T_FLOAT, H5T_NATIVE_DOUBLE, 8, 2, -1, 3, &n_vertex))
        || !(r->triangle_start = read_member(ld, group, "triangle_start", H5T_INTEGER, H5T_NATIVE_INT64, 8, 1, n + 1,
                                             0, NULL))
        || !(r->triangles = read_member(ld, group, "triangles", H5T_INTEGER, H5T_NATIVE_INT32, 4, 2, -1, 3,
                                        &n_triangle))
        || !(r->inertia = read_member(ld, group, "inertia", H5T_FLOAT, H5T_NATIVE_DOUBLE, 8, 2, n, 3, NULL))
        || !(r->aspect = read_member(ld, group, "aspect", H5T_FLOAT, H5T_NATIVE_DOUBLE, 8, 2, n, 4, NULL))
        || !(r->both_hands = read_member(ld, group, "both_hands", H5T_INTEGER, H5T_NATIVE_UINT8, 1, 1, n, 0, NULL)))
        goto done;
    check_records(ld, t, names, r->triangles, r->triangle_start, n_vertex, n_triangle, kappa, aspect);
done:
    free(names);
    if (name_type >= 0) H5Tclose(name_type);
    H5Gclose(group);
    return ld->code;
}

void rbs_direct_shapes_free(rbs_table *t)
{
    rbs_shape_arrays *d = &t->direct_shapes;
    free((void *)d->kind);
    free((void *)d->vertex_start);
    free((void *)d->vertices);
    free((void *)d->second_moments);
    free((void *)d->aspect);
    free((void *)d->aspect_cdf);
    free((void *)d->both_hands);
    free((void *)d->half_extents);
    free((void *)d->graph_start);
    free((void *)d->graph);
    free((void *)d->starts);
    free((void *)d->far_start);
    free((void *)d->far);
    free(t->model_shape);
    memset(d, 0, sizeof *d);
    t->model_shape = NULL;
}

/* the derived arrays of t->direct_shapes (direct_model.shape_arrays.from_stored): every shape's half-extents, and a
 * walked hull's vertex graph, start map and farthest candidates (hull_walk.h) from the table's triangles; 0, or −1
 * out of memory (the caller frees what is set) */
static int walks_build(rbs_table *t)
{
    const rbs_shape_records *r = &t->shapes;
    rbs_shape_arrays *d = &t->direct_shapes;
    int n = d->n_shapes;
    int64_t rows = d->vertex_start[n];
    double *half = malloc((size_t)n * 3 * sizeof *half);
    int64_t *graph_start = calloc((size_t)rows + 1, sizeof *graph_start), *far_start = calloc((size_t)n + 1, 8);
    int32_t *starts = calloc((size_t)n * MAP_SIZE, sizeof *starts), *far = malloc((size_t)rows * sizeof *far);
    d->half_extents = half;
    d->graph_start = graph_start;
    d->starts = starts;
    d->far_start = far_start;
    d->far = far;
    if (!half || !graph_start || !far_start || !starts || !far) return -1;
    /* the record of direct shape j: table shape i with t->model_shape[i] == j */
    int *record = malloc((size_t)n * sizeof *record);
    if (!record) return -1;
    for (int i = 0; i < t->n_shapes; i++)
        if (t->model_shape[i] >= RBS_N_FAMILIES) record[t->model_shape[i]] = i;
    int64_t edges = 0;
    int32_t *graph = NULL;
    int failed = 0;
    for (int j = 0; j < n && !failed; j++) {
        int64_t lo = d->vertex_start[j], count = d->vertex_start[j + 1] - lo;
        if (d->kind[j] == KIND_ELLIPSOID) memcpy(half + 3 * j, d->vertices + 3 * lo, 3 * sizeof *half);
        else rbs_half_extents(d->vertices, lo, (int)count, half + 3 * j);
        for (int64_t k = lo; k < lo + count; k++) graph_start[k + 1] = edges;
        far_start[j + 1] = far_start[j];
        if (j < RBS_N_FAMILIES || count <= WALK_ABOVE) continue;
        int i = record[j];
        int64_t *start = NULL;
        int32_t *local = NULL, *grown = NULL;
        if (rbs_vertex_graph(r->triangles + 3 * r->triangle_start[i], r->triangle_start[i + 1] - r->triangle_start[i],
                             (int)count, &start, &local) != 0
            || !(grown = realloc(graph, (size_t)(edges + start[count]) * sizeof *graph))) {
            free(start);
            free(local);
            failed = 1;
            break;
        }
        graph = grown;
        memcpy(graph + edges, local, (size_t)start[count] * sizeof *graph);
        for (int64_t k = 0; k <= count; k++) graph_start[lo + k] = edges + start[k];
        rbs_start_map(d->vertices + 3 * lo, (int)count, start, local, starts + (int64_t)MAP_SIZE * j);
        edges += start[count];
        free(start);
        free(local);
        int kept = rbs_farthest_candidates(d->vertices + 3 * lo, (int)count, far + far_start[j]);
        if (kept < 0) failed = 1;
        else far_start[j + 1] = far_start[j] + kept;
    }
    free(record);
    d->graph = graph;
    return failed ? -1 : 0;
}

int rbs_direct_shapes_build(rbs_table *t)
{
    rbs_shape_records *r = &t->shapes;
    const double *p = t->direct_parameters;
    int n = RBS_N_FAMILIES;
    int64_t rows = FAMILY_VERTEX_ROWS;
    for (int i = 0; i < t->n_shapes; i++)
        if (r->family[i] < 0 && r->kind[i] == KIND_POLYHEDRON) {
            n++;
            rows += r->vertex_start[i + 1] - r->vertex_start[i];
        }
    int8_t *kind = malloc((size_t)n);
    int64_t *vertex_start = malloc((size_t)(n + 1) * sizeof *vertex_start);
    double *vertices = malloc((size_t)rows * 3 * sizeof *vertices);
    double *second_moments = malloc((size_t)n * 3 * sizeof *second_moments);
    double *aspect = malloc((size_t)n * 4 * sizeof *aspect);
    double *aspect_cdf = malloc((size_t)n * 2 * sizeof *aspect_cdf);
    uint8_t *both_hands = malloc((size_t)n);
    t->model_shape = malloc((size_t)t->n_shapes * sizeof *t->model_shape);
    t->direct_shapes = (rbs_shape_arrays){.n_shapes = n, .kind = kind, .vertex_start = vertex_start,
                                          .vertices = vertices, .second_moments = second_moments, .aspect = aspect,
                                          .aspect_cdf = aspect_cdf, .both_hands = both_hands};
    if (!kind || !vertex_start || !vertices || !second_moments || !aspect || !aspect_cdf || !both_hands
        || !t->model_shape) {
        rbs_direct_shapes_free(t);
        return RBS_ERR_MEMORY;
    }
    rbs_family_shapes_fill(kind, vertex_start, vertices, second_moments, aspect, aspect_cdf, both_hands, p[P_KAPPA],
                           p + P_ASPECT_MEAN, p + P_CDF_LOW, p + P_KFAC);
    /* then each user grain (surrogate.table.SurrogateTable.shape_arrays: direct_model.shape_arrays.shape_arrays of
     * its record); a smooth body that is no family has no semi-axes on file: the direct path refuses it (−1) */
    int j = RBS_N_FAMILIES;
    for (int i = 0; i < t->n_shapes; i++) {
        if (r->family[i] >= 0 || r->kind[i] != KIND_POLYHEDRON) {
            t->model_shape[i] = r->family[i];
            continue;
        }
        t->model_shape[i] = j;
        int64_t lo = r->vertex_start[i], count = r->vertex_start[i + 1] - lo;
        kind[j] = KIND_POLYHEDRON;
        vertex_start[j + 1] = vertex_start[j] + count;
        memcpy(vertices + 3 * vertex_start[j], r->vertices + 3 * lo, (size_t)count * 3 * sizeof *vertices);
        const double *inertia = r->inertia + 3 * i;
        double half_sum = (inertia[0] + inertia[1] + inertia[2]) / 2.0;
        for (int k = 0; k < 3; k++) second_moments[3 * j + k] = half_sum - inertia[k];
        const double *law = r->aspect + 4 * i;
        memcpy(aspect + 4 * j, law, 4 * sizeof *aspect);
        aspect_cdf[2 * j] = isnan(law[0]) ? NAN : rbs_normal_cdf((law[2] - law[0]) / law[1]);
        aspect_cdf[2 * j + 1] = isnan(law[0]) ? NAN : rbs_normal_cdf((law[3] - law[0]) / law[1]);
        both_hands[j] = r->both_hands[i];
        j++;
    }
    int built = walks_build(t);
    /* the triangles have given the walks their graphs: the runtime needs no surface */
    free(t->shapes.triangle_start);
    free(t->shapes.triangles);
    t->shapes.triangle_start = NULL;
    t->shapes.triangles = NULL;
    if (built != 0) {
        rbs_direct_shapes_free(t);
        return RBS_ERR_MEMORY;
    }
    return RBS_OK;
}
