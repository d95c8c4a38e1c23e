/*
 * runtime.h: the direct model at run time (direct_model.runtime): one particle's whole rebound in the model's
 * frame from RBS_U_PER_REBOUND uniforms and the parameter array P_* (direct_model.runtime.model_parameters).
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_RUNTIME_H
#define RBS_RUNTIME_H

/* layout of the parameter array (float64; direct_model.runtime: P_ASPECT_MEAN ... P_KFAC, N_PARAMS) */
#define P_ASPECT_MEAN 0     /* the aspect-ratio law (b/a and c/b): mean, sd, low, high */
#define P_ASPECT_SD 1
#define P_ASPECT_LOW 2
#define P_ASPECT_HIGH 3
#define P_CDF_LOW 4         /* Φ((low − mean)/sd), Φ((high − mean)/sd): the law's CDF bounds */
#define P_CDF_HIGH 5
#define P_KAPPA 6
#define P_N_MAX 7
#define P_WALL 8            /* the wall law (k, p, q) at 8, 9, 10 */
#define P_CONTACT_TOL 11    /* units of a */
#define P_SET_TOL 12        /* units of a */
#define P_MAX_STEPS 13      /* search steps per flight */
#define P_KFAC 14           /* second-moment factor s per shape code, 14..17 */
#define N_PARAMS 18

/* the uniforms of one rebound (direct_model.runtime: U_ORIENTATION, U_RATIOS, U_HAND, U_AXIS) */
#define U_ORIENTATION 0
#define U_RATIOS 3
#define U_HAND 5
#define U_AXIS 6

#endif /* RBS_RUNTIME_H */
