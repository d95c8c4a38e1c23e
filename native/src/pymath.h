/*
 * pymath.h: Python's min and max of two floats as numba compiles them (the direct model's kernels use them):
 * min(a, b) is b if b < a else a, max(a, b) is b if b > a else a, so a NaN second argument is never taken
 * and a NaN first one is kept.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_PYMATH_H
#define RBS_PYMATH_H

static inline double py_min(double a, double b)
{
    return b < a ? b : a;
}

static inline double py_max(double a, double b)
{
    return b > a ? b : a;
}

#endif /* RBS_PYMATH_H */
