/*
 * test_rotation.c: the invariants of the free flight of rotation.c over whole flights, run under
 * AddressSanitizer and UndefinedBehaviorSanitizer by tests/native (no report may appear):
 *
 *   - the lab angular momentum R K R^T omega stays equal to ell (to 1e-9 |ell|, vector and length),
 *   - the kinetic energy (1/2) omega . K omega stays (1/2) sum m_i^2 / K_i of the initial state (1e-9
 *     relative),
 *   - R stays orthonormal (|R R^T - I| < 1e-12 entry by entry), and R(0) = R0 (1e-12),
 *
 * over random bodies and states of every mode (static, steady, general, separatrix, next to it,
 * axisymmetric, nearly axisymmetric, scaled by 1e+-30) at 200 times over 20 periods, then at 1e6 and 1e12
 * periods and negative times; and hostile arguments (NaN, inf, zero inertias or momenta, non-finite
 * times) end without a crash or undefined behaviour.
 *
 *   rbs_test_rotation [STATES_PER_KIND]
 *
 * Exit status 0 when every check passes; each failure is printed.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "rebound_scatter.h"
#include "rotation.h"

#define TWO_PI 6.283185307179586
#define TIMES_PER_FLIGHT 200
#define PERIODS_PER_FLIGHT 20.0
#define INVARIANT_TOL 1e-9
#define ORTHO_TOL 1e-12

static int failures = 0;
static double worst_momentum, worst_energy, worst_ortho_seen; /* the largest deviations of a kind, printed */

enum kind { GENERAL, SCALED, STATIC, STEADY, SPHERE, AXISYMMETRIC, NEARLY_AXISYMMETRIC, SEPARATRIX, NEAR_SEPARATRIX,
            N_KINDS };
static const char *kind_names[N_KINDS] = {"general", "scaled", "static", "steady", "sphere", "axisymmetric",
                                          "nearly axisymmetric", "separatrix", "near separatrix"};

static double uniform(rbs_rng *rng, double lo, double hi) { return lo + (hi - lo) * rbs_rng_uniform(rng); }

static double sign(rbs_rng *rng) { return rbs_rng_uniform(rng) < 0.5 ? -1.0 : 1.0; }

/* a random rotation matrix, row-major, from a random unit quaternion */
static void random_rotation(rbs_rng *rng, double R[9])
{
    double q[4], n2;
    do {
        n2 = 0.0;
        for (int k = 0; k < 4; k++) {
            q[k] = uniform(rng, -1.0, 1.0);
            n2 += q[k] * q[k];
        }
    } while (n2 < 1e-3 || n2 > 1.0);
    double w = q[0], x = q[1], y = q[2], z = q[3], s = 2.0 / n2;
    R[0] = 1 - s * (y * y + z * z), R[1] = s * (x * y - w * z), R[2] = s * (x * z + w * y);
    R[3] = s * (x * y + w * z), R[4] = 1 - s * (x * x + z * z), R[5] = s * (y * z - w * x);
    R[6] = s * (x * z - w * y), R[7] = s * (y * z + w * x), R[8] = 1 - s * (x * x + y * y);
}

/* one random body and state of a kind: K, R0 and the body-frame momentum m (ell = R0 m) */
static void random_state(rbs_rng *rng, enum kind kind, double K[3], double R0[9], double m[3])
{
    random_rotation(rng, R0);
    double scale = exp(uniform(rng, -3.0, 3.0));
    for (int k = 0; k < 3; k++) {
        K[k] = exp(uniform(rng, -2.0, 2.0));
        m[k] = uniform(rng, -1.0, 1.0) * scale;
    }
    int axis = (int)(3.0 * rbs_rng_uniform(rng)) % 3, a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    switch (kind) {
    case GENERAL:
        break;
    case SCALED: {
        double sk = pow(10.0, uniform(rng, -30.0, 30.0)), sm = pow(10.0, uniform(rng, -30.0, 30.0));
        for (int k = 0; k < 3; k++) {
            K[k] *= sk;
            m[k] *= sm;
        }
        break;
    }
    case STATIC:
        m[0] = m[1] = m[2] = 0.0;
        break;
    case STEADY:
        m[a1] = m[a2] = 0.0;
        break;
    case SPHERE:
        K[1] = K[2] = K[0];
        break;
    case AXISYMMETRIC:
        K[a2] = K[a1];
        break;
    case NEARLY_AXISYMMETRIC:
        K[a2] = K[a1] * (1.0 + sign(rng) * pow(10.0, uniform(rng, -15.0, -6.0)));
        break;
    case SEPARATRIX:
    case NEAR_SEPARATRIX: {
        /* K_mid the harmonic mean of K_lo = 1 and K_hi = 3: |m_lo| = |m_hi| is on the separatrix */
        double lo = sign(rng) * ldexp(floor(uniform(rng, 1.0, 1048576.0)), -10);
        double hi = sign(rng) * fabs(lo);
        if (kind == NEAR_SEPARATRIX) {
            hi *= 1.0 + sign(rng) * ldexp(floor(uniform(rng, 1.0, 5.0)), -52);
            double shrink = ldexp(1.0, -(int)uniform(rng, 0.0, 44.0));
            lo *= shrink;
            hi *= shrink;
        }
        K[axis] = 1.0, K[a1] = 1.5, K[a2] = 3.0;
        m[axis] = lo, m[a2] = hi;
        break;
    }
    default:
        break;
    }
}

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* the invariants at one time; returns 1 if they hold */
static int check_time(const double K[3], const double ell[3], double energy, const double R[9],
                      const double omega[3], double t, const char *name)
{
    double wb[3], lab[3], e = 0.0, worst_ortho = 0.0;
    for (int i = 0; i < 3; i++) wb[i] = R[i] * omega[0] + R[3 + i] * omega[1] + R[6 + i] * omega[2];
    for (int r = 0; r < 3; r++) lab[r] = R[3 * r] * K[0] * wb[0] + R[3 * r + 1] * K[1] * wb[1] + R[3 * r + 2] * K[2] * wb[2];
    for (int i = 0; i < 3; i++) e += 0.5 * K[i] * wb[i] * wb[i];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double dot = R[3 * i] * R[3 * j] + R[3 * i + 1] * R[3 * j + 1] + R[3 * i + 2] * R[3 * j + 2];
            worst_ortho = fmax(worst_ortho, fabs(dot - (i == j)));
        }
    double l = norm3(ell), dl[3] = {lab[0] - ell[0], lab[1] - ell[1], lab[2] - ell[2]};
    worst_momentum = fmax(worst_momentum, fmax(norm3(dl), fabs(norm3(lab) - l)) / l);
    worst_energy = fmax(worst_energy, fabs(e - energy) / energy);
    worst_ortho_seen = fmax(worst_ortho_seen, worst_ortho);
    int ok = 1;
    if (!(norm3(dl) <= INVARIANT_TOL * l) || !(fabs(norm3(lab) - l) <= INVARIANT_TOL * l)) {
        fprintf(stderr, "FAILED %s t=%.17g: lab angular momentum off by %.3g of |ell|\n", name, t, norm3(dl) / l);
        ok = 0;
    }
    if (!(fabs(e - energy) <= INVARIANT_TOL * energy)) {
        fprintf(stderr, "FAILED %s t=%.17g: kinetic energy off by %.3g relative\n", name, t, (e - energy) / energy);
        ok = 0;
    }
    if (!(worst_ortho <= ORTHO_TOL)) {
        fprintf(stderr, "FAILED %s t=%.17g: R R^T - I up to %.3g\n", name, t, worst_ortho);
        ok = 0;
    }
    return ok;
}

/* one flight: R(0) = R0, then the invariants over 20 periods, far out and at negative times */
static void check_flight(const double K[3], const double R0[9], const double m[3], rbs_rng *rng, const char *name)
{
    double ell[3], params[RBS_ROT_PARAMS_SIZE], R[9], omega[3];
    for (int r = 0; r < 3; r++) ell[r] = R0[3 * r] * m[0] + R0[3 * r + 1] * m[1] + R0[3 * r + 2] * m[2];
    rbs_rotation_init(K, R0, ell, params);
    rbs_rotation_at(params, 0.0, R, omega);
    for (int k = 0; k < 9; k++)
        if (!(fabs(R[k] - R0[k]) <= ORTHO_TOL)) {
            fprintf(stderr, "FAILED %s: R(0)[%d] - R0[%d] = %.3g\n", name, k, k, R[k] - R0[k]);
            failures++;
            return;
        }
    if (params[0] == 0.0) { /* static: nothing moves, omega = 0 */
        rbs_rotation_at(params, uniform(rng, -1e6, 1e6), R, omega);
        for (int k = 0; k < 9; k++)
            if (R[k] != R0[k] || (k < 3 && omega[k] != 0.0)) {
                fprintf(stderr, "FAILED %s: the static body moved\n", name);
                failures++;
                return;
            }
        return;
    }
    /* energy of the initial body-frame state; the period from omega's size (a time scale in every mode) */
    double mb[3], energy = 0.0;
    for (int i = 0; i < 3; i++) mb[i] = R0[i] * ell[0] + R0[3 + i] * ell[1] + R0[6 + i] * ell[2];
    for (int i = 0; i < 3; i++) energy += 0.5 * mb[i] * mb[i] / K[i];
    double period = TWO_PI / norm3(omega);
    double far[] = {1e6, -1e6, 1e12, -1e12, -0.5, -PERIODS_PER_FLIGHT};
    for (int k = 0; k <= TIMES_PER_FLIGHT + 6; k++) {
        double t = k <= TIMES_PER_FLIGHT ? PERIODS_PER_FLIGHT * period * k / TIMES_PER_FLIGHT
                                         : far[k - TIMES_PER_FLIGHT - 1] * period * uniform(rng, 0.5, 1.0);
        rbs_rotation_at(params, t, R, omega);
        if (!check_time(K, ell, energy, R, omega, t, name)) {
            fprintf(stderr, "  K = (%.17g, %.17g, %.17g), m = (%.17g, %.17g, %.17g), mode %g\n", K[0], K[1], K[2],
                    m[0], m[1], m[2], params[0]);
            failures++;
            return;
        }
    }
}

/* hostile arguments: every call returns, whatever comes out */
static void hostile(void)
{
    const double bad[] = {NAN, INFINITY, -INFINITY, 0.0, -1.0, 1e308, 5e-324};
    const int n_bad = (int)(sizeof bad / sizeof bad[0]);
    double R0[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, params[RBS_ROT_PARAMS_SIZE], R[9], omega[3];
    double times[] = {0.0, 1.0, -1e300, NAN, INFINITY, -INFINITY};
    int finished = 0;
    for (int i = 0; i < n_bad; i++)
        for (int slot = 0; slot < 6; slot++) {
            double K[3] = {1.0, 2.0, 3.0}, ell[3] = {0.3, 0.4, 0.5};
            if (slot < 3)
                K[slot] = bad[i];
            else
                ell[slot - 3] = bad[i];
            rbs_rotation_init(K, R0, ell, params);
            for (int k = 0; k < 6; k++) rbs_rotation_at(params, times[k], R, omega);
            finished++;
        }
    printf("hostile arguments: %d initialisations and %d evaluations returned\n", finished, 6 * finished);
}

int main(int argc, char **argv)
{
    int count = argc > 1 ? atoi(argv[1]) : 200;
    rbs_rng rng;
    rbs_rng_seed(&rng, 2027);
    for (int kind = 0; kind < N_KINDS; kind++) {
        worst_momentum = worst_energy = worst_ortho_seen = 0.0;
        for (int n = 0; n < count; n++) {
            double K[3], R0[9], m[3];
            random_state(&rng, (enum kind)kind, K, R0, m);
            check_flight(K, R0, m, &rng, kind_names[kind]);
        }
        printf("%s: %d flights, largest deviations: momentum %.2g, energy %.2g, R R^T - I %.2g\n",
               kind_names[kind], count, worst_momentum, worst_energy, worst_ortho_seen);
    }
    hostile();
    printf("%d failure(s)\n", failures);
    return failures != 0;
}
