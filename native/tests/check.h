/*
 * check.h: the failure counter and CHECK macro of the C test programs (native/tests).
 *
 * CHECK(condition, format, ...) prints "FAILED condition: message" on stderr and counts a failure when the
 * condition does not hold; a program returns a non-zero status when `failures` is not 0.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_TESTS_CHECK_H
#define RBS_TESTS_CHECK_H

#include <stdio.h>

static int failures = 0;

#define CHECK(condition, ...)                           \
    do {                                                \
        if (!(condition)) {                             \
            fprintf(stderr, "FAILED %s: ", #condition); \
            fprintf(stderr, __VA_ARGS__);               \
            fprintf(stderr, "\n");                      \
            failures++;                                 \
        }                                               \
    } while (0)

#endif
