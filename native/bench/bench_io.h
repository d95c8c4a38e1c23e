/*
 * bench_io.h: what the C bench programs share: opening the table and the states file of the benchmark
 * scripts (int64 count first, then float64 arrays), each reporting a failure on stderr.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_BENCH_IO_H
#define RBS_BENCH_IO_H

#include <stdio.h>

#include "rebound_scatter.h"

/* The table at path, or NULL after its error message. */
static rbs_table *bench_open_table(const char *path)
{
    char message[1024];
    rbs_table *table = NULL;
    if (rbs_table_open(path, &table, message, sizeof message) != RBS_OK) {
        fprintf(stderr, "%s\n", message);
        return NULL;
    }
    return table;
}

/* The states file at path, read past its int64 count (> 0, into *count), or NULL after a message. */
static FILE *bench_open_states(const char *path, size_t *count)
{
    FILE *f = fopen(path, "rb");
    long long n = 0;
    if (!f || fread(&n, sizeof n, 1, f) != 1 || n <= 0) {
        fprintf(stderr, "%s: cannot read the states\n", path);
        if (f) fclose(f);
        return NULL;
    }
    *count = (size_t)n;
    return f;
}

#endif
