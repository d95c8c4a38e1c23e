/*
 * rotation.c: torque-free rotation of a rigid body (direct_model.rotation, whose module docstring gives the
 * method: Landau & Lifshitz section 37, Jacobi's theta series or the Landen/AGM chain, Carlson's R_F and R_J,
 * Celledoni et al. 2008),
 * function for function, each expression in numba's order (no contraction, numba's min/max and int(),
 * libm where numba calls it), so the same bits.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include "rotation.h"

#include <math.h>
#include <stdint.h>

#include "fastmath.h"

/* ---------------------------------------------------------------- layout of the parameter array */
#define MODE_STATIC 0.0     /* ell == 0: R = R0, omega = 0 */
#define MODE_STEADY 1.0     /* constant omega about a principal direction */
#define MODE_GENERAL 2.0    /* elliptic solution, 0 < k' <= 1 */
#define MODE_SEPARATRIX 3.0 /* elliptic solution on the separatrix, k' == 0 */
#define MODE_THETA 4.0      /* Jacobi's theta series, nome q <= 0.2, away from a steady spin */

#define NLEV_MAX 24         /* Landen levels; k' = 1e-9 needs 7, k' = 5e-324 needs 12 */
#define LANDEN_KTOL 1e-9    /* stop once k_n < this: sn(w|k_n) = sin w + O(k_n^2) */

#define I_MODE 0
#define I_C 1         /* 9 entries, row-major: C (elliptic modes) or R0 (static / steady) */
#define I_OMEGA 10    /* 3 entries: constant lab omega (steady mode) */
#define I_LJ 13       /* 3 entries: L / J_i, J_i the working moments */
#define I_A 16        /* 3 entries: amplitudes a_0, a_1, a_2 */
#define I_NU 19       /* du/dt */
#define I_U0 20       /* u at t = 0 */
#define I_TWOK 21     /* 2 K(k), period of the reduction of u */
#define I_INV2K 22    /* 1 / (2 K) */
#define I_L 23        /* |L| */
#define I_LIN 24      /* secular rate of psi */
#define I_KAPNU 25    /* kappa / nu */
#define I_BETA 26     /* beta = -alpha^2 of the third-kind integral */
#define I_G 27        /* g = sqrt(1 + beta) */
#define I_A2G 28      /* a_2 / g */
#define I_FORM2 29    /* 1.0 if beta > 1 (reflected form 2), else 0.0 */
#define I_ETA 30      /* characteristic of the R_J term: beta (form 1) or gamma = k^2/beta (form 2) */
#define I_DCOEF 31    /* eta (1 + eta) (eta + k^2): (p - x)(p - y)(p - z) = DCOEF sn^6 in R_J */
#define I_CPI 32      /* coefficient of sn^3 R_J in G_p: -L beta/3 (form 1), L gamma/3 (form 2) */
#define I_SQD 33      /* sqrt((1 + beta) (1 + gamma)) (form 2) */
#define I_LSQD 34     /* L / SQD (form 2) */
#define I_FOFF 35     /* mean integrand f_bar (form 2) or f_bar - L (form 1) */
#define I_G0 36       /* G_p(u_0) */
#define I_PERM 37     /* 3 entries: body axis of working axis i */
#define I_SIGN 40     /* 3 entries: sign of working axis i */
#define I_NLEV 43     /* number of Landen levels */
#define I_WSCALE 44   /* 1 / prod(1 + k_n) */
#define I_KN 45       /* NLEV_MAX entries: k_n, n = 1..N */
#define I_OMKN (I_KN + NLEV_MAX) /* NLEV_MAX entries: 1 - k_n */

_Static_assert(I_OMKN + NLEV_MAX == RBS_ROT_PARAMS_SIZE, "the layout of direct_model.rotation");

/* the theta mode keeps its series in the Landen chain's slots */
#define TH_TERMS 8               /* at most; q <= 0.2 needs 6 */
#define I_TH_N I_KN              /* number of terms */
#define I_TH_NUV (I_KN + 1)      /* dv/dt, v = pi u / (2 K) */
#define I_TH_V0 (I_KN + 2)       /* v at t = 0 */
#define I_TH_CRE (I_KN + 3)      /* e^{-i psi_raw(0)}: real and imaginary parts */
#define I_TH_CIM (I_KN + 4)
#define I_TH_M0 (I_KN + 5)       /* coefficients of cos((2n+1) v) in m_0 */
#define I_TH_M1 (I_TH_M0 + TH_TERMS) /* of sin((2n+1) v) in m_1 */
#define I_TH_M2 (I_TH_M1 + TH_TERMS) /* of cos(2n v) in m_2 */
#define I_TH_WR (I_TH_M2 + TH_TERMS) /* of cos(2n v) in Re w (sin((2n+1) v) reflected) */
#define I_TH_WI (I_TH_WR + TH_TERMS) /* of sin(2n v) in Im w (cos((2n+1) v) reflected) */
#define I_TH_REFLECT (I_TH_WI + TH_TERMS) /* 1.0 if w is taken through theta_1 (beta > k), else 0.0 */
#define THETA_LNQ_MAX (-1.6094379124341003)  /* ln 0.2: larger nomes (k^2 > 0.97) take the Landen path */
#define THETA_TOL 1e-17          /* the first term left out of every series is below this (relative) */
#define THETA_K2_MIN 1e-4        /* closer to a steady spin (k -> 0) the theta phases lose digits */

_Static_assert(I_TH_REFLECT < RBS_ROT_PARAMS_SIZE, "the theta series fit the parameter array");

#define SNAP (16.0 * 2.220446049250313e-16) /* relative size of rounding noise in R0^T ell */

/* duplication stops at these relative spreads (direct_model.rotation: series to degrees 11 and 9) */
#define RJ_TOL_INV (1.0 / 0.04)
#define RF_TOL_INV (1.0 / 0.025)

/* ---------------------------------------------------------------- Carlson's symmetric elliptic integrals */

/* R_C(1, 1 + e) for e > -1: atan(sqrt(e))/sqrt(e), atanh(sqrt(-e))/sqrt(-e), or the series for |e| < 1e-3 */
static double rbs_carlson_rc1(double e)
{
    if (fabs(e) < 1e-3)
        return 1.0 - e * (1.0 / 3.0 - e * (1.0 / 5.0 - e * (1.0 / 7.0 - e * (1.0 / 9.0 - e / 11.0))));
    if (e > 0.0) {
        double s = sqrt(e);
        return atan(s) / s;
    }
    double s = sqrt(-e);
    return atanh(s) / s;
}

/* the series of R_F to degree 9, A^(-1/2) factored out (DLMF 19.36.1 continued) */
static double rbs_rf_series(double e2, double e3)
{
    return 1.0 + (e2 * (-1.0 / 10.0 + e2 * (1.0 / 24.0 + e2 * (-5.0 / 208.0 + e2 * (35.0 / 2176.0))))
                  + e3 * (1.0 / 14.0 + e2 * (-3.0 / 44.0 + e2 * (1.0 / 16.0 - e2 * (35.0 / 608.0))))
                  + e3 * e3 * (3.0 / 104.0 - e2 * (15.0 / 272.0) + e3 * (5.0 / 304.0)));
}

/* the series of R_J to degree 11, A^(-3/2) factored out (DLMF 19.36.2 continued) */
static double rbs_rj_series(double e2, double e3, double e4, double e5)
{
    return 1.0 + (e2 * (-3.0 / 14.0 + e2 * (9.0 / 88.0 + e2 * (-1.0 / 16.0 + e2 * (105.0 / 2432.0
                                                                                - e2 * (189.0 / 5888.0)))))
                  + e3 * (1.0 / 6.0 + e2 * (-9.0 / 52.0 + e2 * (45.0 / 272.0 + e2 * (-5.0 / 32.0
                                                                                   + e2 * (189.0 / 1280.0))))
                          + e3 * (3.0 / 40.0 + e2 * (-45.0 / 304.0 + e2 * (315.0 / 1472.0))
                                  + e3 * (5.0 / 112.0 - e2 * (21.0 / 160.0))))
                  + e4 * (-3.0 / 22.0 + e2 * (3.0 / 20.0 + e2 * (-45.0 / 304.0 + e2 * (105.0 / 736.0)))
                          + e3 * (-9.0 / 68.0 + e2 * (15.0 / 56.0 - e2 * (63.0 / 160.0)) - e3 * (45.0 / 368.0))
                          + e4 * (9.0 / 152.0 - e2 * (45.0 / 368.0) + e3 * (9.0 / 80.0)))
                  + e5 * (3.0 / 26.0 + e2 * (-9.0 / 68.0 + e2 * (15.0 / 112.0 - e2 * (21.0 / 160.0)))
                          + e3 * (9.0 / 76.0 - e2 * (45.0 / 184.0) + e3 * (9.0 / 80.0))
                          + e4 * (-3.0 / 28.0 + e2 * (9.0 / 40.0)) + e5 * (9.0 / 184.0)));
}

/* the state of R_F's duplication (direct_model.rotation._rf_start): the arguments x, y, z, their mean a, the
 * spread's factor fac = 4^-m, qx = A_0 - x_0 and qy = A_0 - y_0 (X = qx fac / A_m free of cancellation) and
 * qmax, the spread over the tolerance: the steps go on while fac qmax > a */
typedef struct {
    double x, y, z, a, fac, qx, qy, qmax;
} rbs_rf_state;

static rbs_rf_state rbs_rf_start(double x, double y, double z)
{
    rbs_rf_state st;
    st.a = (x + y + z) / 3.0;
    st.qx = st.a - x;
    st.qy = st.a - y;
    st.qmax = rbs_fmax_py(rbs_fmax_py(fabs(st.qx), fabs(st.qy)), fabs(st.a - z)) * RF_TOL_INV;
    st.x = x;
    st.y = y;
    st.z = z;
    st.fac = 1.0;
    return st;
}

/* rbs_rf_start for R_F(x, y, 1) after its first step, which takes no square root with sx = sqrt(x), sy = sqrt(y)
 * known */
static rbs_rf_state rbs_rf_amp_start(double x, double sx, double y, double sy)
{
    rbs_rf_state st;
    double a = (x + y + 1.0) / 3.0;
    st.qx = a - x;
    st.qy = a - y;
    st.qmax = rbs_fmax_py(rbs_fmax_py(fabs(st.qx), fabs(st.qy)), fabs(a - 1.0)) * RF_TOL_INV;
    double lam = sx * (sy + 1.0) + sy;
    st.x = 0.25 * (x + lam);
    st.y = 0.25 * (y + lam);
    st.z = 0.25 * (1.0 + lam);
    st.a = 0.25 * (a + lam);
    st.fac = 0.25;
    return st;
}

/* one duplication step (Carlson 1995, section 2) */
static void rbs_rf_step(rbs_rf_state *st)
{
    double sx = sqrt(st->x);
    double sy = sqrt(st->y);
    double sz = sqrt(st->z);
    double lam = sx * (sy + sz) + sy * sz;
    st->x = 0.25 * (st->x + lam);
    st->y = 0.25 * (st->y + lam);
    st->z = 0.25 * (st->z + lam);
    st->a = 0.25 * (st->a + lam);
    st->fac = st->fac * 0.25;
}

/* R_F from the series once the duplication has stopped */
static double rbs_rf_end(const rbs_rf_state *st)
{
    double f = st->fac / st->a;
    double dx = st->qx * f;
    double dy = st->qy * f;
    double dz = -(dx + dy);
    return rbs_rf_series(dx * dy - dz * dz, dx * dy * dz) / sqrt(st->a);
}

/* 1 while the duplication needs another step: the spread fac qmax is above a */
static int rbs_rf_open(const rbs_rf_state *st)
{
    return st->fac * st->qmax > st->a;
}

/* R_F from a duplication state: steps while rbs_rf_open, then the series */
static double rbs_rf_tail(rbs_rf_state st)
{
    while (rbs_rf_open(&st)) rbs_rf_step(&st);
    return rbs_rf_end(&st);
}

double rbs_carlson_rf(double x, double y, double z)
{
    return rbs_rf_tail(rbs_rf_start(x, y, z));
}

/* R_F(x, y, 1) with sx = sqrt(x), sy = sqrt(y) known */
static double rbs_rf_amp(double x, double sx, double y, double sy)
{
    return rbs_rf_tail(rbs_rf_amp_start(x, sx, y, sy));
}

/* duplication steps of R_J with the R_C corrections (Carlson 1995, Algorithm 3), then the series */
static double rbs_rj_tail(double x, double y, double z, double p, double delta, double a, double fac, double acc,
                          double qx, double qy, double qz, double qmax)
{
    while (fac * qmax > a) {
        double sx = sqrt(x);
        double sy = sqrt(y);
        double sz = sqrt(z);
        double sp = sqrt(p);
        double lam = sx * (sy + sz) + sy * sz;
        double inv = 1.0 / ((sp + sx) * (sp + sy) * (sp + sz));
        acc += fac * rbs_carlson_rc1(fac * fac * fac * delta * inv * inv) * inv;
        x = 0.25 * (x + lam);
        y = 0.25 * (y + lam);
        z = 0.25 * (z + lam);
        p = 0.25 * (p + lam);
        a = 0.25 * (a + lam);
        fac *= 0.25;
    }
    double f = fac / a;
    double dx = qx * f;
    double dy = qy * f;
    double dz = qz * f;
    double dp = -0.5 * (dx + dy + dz);
    double xyz = dx * dy * dz;
    double dp2 = dp * dp;
    double e2 = dx * dy + dx * dz + dy * dz - 3.0 * dp2;
    double e3 = xyz + 2.0 * e2 * dp + 4.0 * dp2 * dp;
    double e4 = (2.0 * xyz + e2 * dp + 3.0 * dp2 * dp) * dp;
    double e5 = xyz * dp2;
    return fac * rbs_rj_series(e2, e3, e4, e5) / (a * sqrt(a)) + 6.0 * acc;
}

double rbs_carlson_rj(double x, double y, double z, double p)
{
    double delta = (p - x) * (p - y) * (p - z);
    double a = (x + y + z + 2.0 * p) / 5.0;
    double qx = a - x;
    double qy = a - y;
    double qz = a - z;
    double qmax = rbs_fmax_py(rbs_fmax_py(rbs_fmax_py(fabs(qx), fabs(qy)), fabs(qz)), fabs(a - p)) * RJ_TOL_INV;
    return rbs_rj_tail(x, y, z, p, delta, a, 1.0, 0.0, qx, qy, qz, qmax);
}

/* R_J(x, y, 1, p) with sx = sqrt(x), sy = sqrt(y) and delta = (p - x)(p - y)(p - 1) >= 0 given: the first
 * duplication step takes one square root */
static double rbs_rj_amp(double x, double sx, double y, double sy, double p, double delta)
{
    double a = (x + y + 1.0 + 2.0 * p) / 5.0;
    double qx = a - x;
    double qy = a - y;
    double qz = a - 1.0;
    double qmax = rbs_fmax_py(rbs_fmax_py(rbs_fmax_py(fabs(qx), fabs(qy)), fabs(qz)), fabs(a - p)) * RJ_TOL_INV;
    double sp = sqrt(p);
    double lam = sx * (sy + 1.0) + sy;
    double inv = 1.0 / ((sp + sx) * (sp + sy) * (sp + 1.0));
    double acc = rbs_carlson_rc1(delta * inv * inv) * inv;
    return rbs_rj_tail(0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (1.0 + lam), 0.25 * (p + lam), delta,
                       0.25 * (a + lam), 0.25, acc, qx, qy, qz, qmax);
}

/* ---------------------------------------------------------------- double-double helpers (Dekker 1971) */

/* s + e == a + b exactly, s = fl(a + b) (Knuth) */
static void rbs_two_sum(double a, double b, double *s, double *e)
{
    double sum = a + b;
    double bb = sum - a;
    *s = sum;
    *e = (a - (sum - bb)) + (b - bb);
}

/* p + e == a * b exactly, p = fl(a * b) (Veltkamp splitting, no FMA) */
static void rbs_two_prod(double a, double b, double *p, double *e)
{
    double prod = a * b;
    double ca = 134217729.0 * a;
    double ah = ca - (ca - a);
    double al = a - ah;
    double cb = 134217729.0 * b;
    double bh = cb - (cb - b);
    double bl = b - bh;
    *p = prod;
    *e = ((ah * bh - prod) + ah * bl + al * bh) + al * bl;
}

/* product of two double-double numbers (relative error ~ 1e-32) */
static void rbs_dd_mul(double ah, double al, double bh, double bl, double *sh, double *sl)
{
    double p, e;
    rbs_two_prod(ah, bh, &p, &e);
    e += ah * bl + al * bh;
    double s = p + e;
    *sh = s;
    *sl = e - (s - p);
}

/* H = (I_hi - I_mid) I_lo m_hi^2 - (I_mid - I_lo) I_hi m_lo^2 in double-double: H / (I_lo I_hi) =
 * L^2 - 2E I_mid, its sign the circulated axis, |H| k'^2 with full relative accuracy near k = 1 */
static double rbs_separatrix_distance(double i_lo, double i_mid, double i_hi, double m_lo, double m_hi)
{
    double dh, dl, qh, ql, t1h, t1l, t2h, t2l, s, e;
    rbs_two_sum(i_hi, -i_mid, &dh, &dl);
    rbs_two_prod(m_hi, m_hi, &qh, &ql);
    rbs_dd_mul(dh, dl, qh, ql, &t1h, &t1l);
    rbs_dd_mul(t1h, t1l, i_lo, 0.0, &t1h, &t1l);
    rbs_two_sum(i_mid, -i_lo, &dh, &dl);
    rbs_two_prod(m_lo, m_lo, &qh, &ql);
    rbs_dd_mul(dh, dl, qh, ql, &t2h, &t2l);
    rbs_dd_mul(t2h, t2l, i_hi, 0.0, &t2h, &t2l);
    rbs_two_sum(t1h, -t2h, &s, &e);
    return s + (e + (t1l - t2l));
}

/* ---------------------------------------------------------------- Jacobi elliptic functions, phase integral */

/* sn, cn, dn of u = w prod(1 + k_n) by climbing the stored Landen chain (Gauss transformation, DLMF
 * 22.7.1-22.7.3); up to 7 levels in homogeneous coordinates, one division at the end */
static void rbs_landen_sncndn(double w, const double *params, double *sn, double *cn, double *dn)
{
    double s = sin(w);
    double c = cos(w);
    double d = 1.0;
    int64_t nlev = rbs_trunc(params[I_NLEV]);
    if (nlev > 7) {
        for (int64_t i = nlev - 1; i > -1; i--) {
            double kn = params[I_KN + i];
            double s2 = s * s;
            double r = 1.0 / (1.0 + kn * s2);
            double d_new = (c * c + params[I_OMKN + i] * s2) * r;
            s = (1.0 + kn) * s * r;
            c = c * d * r;
            d = d_new;
        }
        *sn = s;
        *cn = c;
        *dn = d;
        return;
    }
    /* S' = (1 + k) S W V, C' = C D W, W' = V P, D' = C^2 + (1 - k) S^2, V' = P, P = W^2 + k S^2 */
    double hw = 1.0;
    double v = 1.0;
    for (int64_t i = nlev - 1; i > -1; i--) {
        double kn = params[I_KN + i];
        double s2 = s * s;
        double w2 = hw * hw;
        double pw = w2 + kn * s2;
        double dnew = c * c + params[I_OMKN + i] * s2;
        s = (1.0 + kn) * s * (hw * v);
        c = c * d * hw;
        hw = v * pw;
        v = pw;
        d = dnew;
    }
    double rw = 1.0 / hw;
    *sn = s * rw;
    *cn = c * rw;
    *dn = d / v;
}

/* the periodic part G_p of the phase integral at sin phi = s, cos phi = c >= 0, Delta = d, phi = am u_r,
 * u_r in [-K, K]: form 1 (beta <= 1) L (Pi - F) - a_2 T - (f_bar - L) u_r, form 2 L Pi - a_2 T - f_bar u_r */
static double rbs_gp_amp(const double *params, double s, double c, double d, double ur)
{
    double eta = params[I_ETA];
    if (eta == 0.0) return 0.0;
    double gp = -params[I_A2G] * atan2(params[I_G] * s, c) - params[I_FOFF] * ur;
    if (params[I_FORM2] != 0.0) gp += params[I_LSQD] * atan2(params[I_SQD] * s, c * d);
    if (s != 0.0) {
        double s2 = s * s;
        double rj = rbs_rj_amp(c * c, c, d * d, d, 1.0 + eta * s2, params[I_DCOEF] * (s2 * s2 * s2));
        gp += params[I_CPI] * (s * s2) * rj;
    }
    return gp;
}

/* sn(u), cn(u), dn(u) and the periodic part G_p(u) of the phase integral (the whole G on the separatrix) */
static void rbs_phase_state(const double *params, double u, double *sn, double *cn, double *dn, double *gval)
{
    if (params[I_MODE] == MODE_SEPARATRIX) {
        double beta = params[I_BETA];
        double g = params[I_G];
        double s = tanh(u);
        double c = 1.0 / cosh(u);
        double sb = sqrt(beta);
        double pi3 = (u + sb * atan(sb * s)) / (1.0 + beta);
        *sn = s;
        *cn = c;
        *dn = c;
        *gval = params[I_L] * pi3 - params[I_A + 2] * atan2(g * s, c) / g;
        return;
    }
    double twok = params[I_TWOK];
    int64_t j = rbs_trunc(floor(u * params[I_INV2K] + 0.5));   /* numba's math.floor returns an int64 */
    double ur = u - (double)j * twok;
    double s, c, d;
    rbs_landen_sncndn(ur * params[I_WSCALE], params, &s, &c, &d);
    *gval = rbs_gp_amp(params, s, fabs(c), d, ur);
    if (j & 1) { /* sn(u_r + 2jK) = (-1)^j sn(u_r), likewise cn; dn has period 2K */
        s = -s;
        c = -c;
    }
    *sn = s;
    *cn = c;
    *dn = d;
}

/* unit body angular momentum n = m / |m| in the working frame from sn, cn, dn */
static void rbs_unit_momentum(const double *params, double s, double c, double d, double n[3])
{
    double m0 = params[I_A + 0] * c;
    double m1 = params[I_A + 1] * s;
    double m2 = params[I_A + 2] * d;
    double inv = 1.0 / sqrt(m0 * m0 + m1 * m1 + m2 * m2);
    n[0] = m0 * inv;
    n[1] = m1 * inv;
    n[2] = m2 * inv;
}

/* ---------------------------------------------------------------- Jacobi's theta series (the theta mode) */

/* 1 while the AGM of (a, g) needs another step (a NaN ends the steps too, as in numba) */
static int rbs_agm_open(double a, double g)
{
    return fabs(a - g) > 1e-9 * a;
}

/* K(k), K(k'), R_F(ax, ay, az) for alpha or K' - alpha and R_F(x, y, 1) for u_0
 * (direct_model.rotation._theta_elliptic): four independent chains of square roots, their steps interleaved so
 * that the CPU runs them side by side, each with its own test and its own operations */
static void rbs_theta_elliptic(double k, double kp, double ax, double ay, double az, double x, double sx, double y,
                               double sy, double *kk, double *kkp, double *rf_shift, double *rf_u0)
{
    double a1 = 1.0, g1 = kp; /* AGM(1, k') */
    double a2 = 1.0, g2 = k;  /* AGM(1, k) */
    rbs_rf_state ra = rbs_rf_start(ax, ay, az);
    rbs_rf_state ru = rbs_rf_amp_start(x, sx, y, sy);
    for (;;) {
        int open1 = rbs_agm_open(a1, g1);
        int open2 = rbs_agm_open(a2, g2);
        int open3 = rbs_rf_open(&ra);
        int open4 = rbs_rf_open(&ru);
        if (!(open1 || open2 || open3 || open4)) break;
        if (open1) {
            double a_next = 0.5 * (a1 + g1);
            g1 = sqrt(a1 * g1);
            a1 = a_next;
        }
        if (open2) {
            double a_next = 0.5 * (a2 + g2);
            g2 = sqrt(a2 * g2);
            a2 = a_next;
        }
        if (open3) rbs_rf_step(&ra);
        if (open4) rbs_rf_step(&ru);
    }
    *kk = RBS_PI / (a1 + g1);
    *kkp = RBS_PI / (a2 + g2);
    *rf_shift = rbs_rf_end(&ra);
    *rf_u0 = rbs_rf_end(&ru);
}

/* Set up the theta mode from kk = K(k), kkp = K(k') and rf = R_F(k^2, k^2 (1 + beta), k^2 + beta) (alpha =
 * sqrt(beta) rf) or, reflected (beta > k), rf = R_F(beta, k^2 + beta, 1 + beta) = K' - alpha
 * (direct_model.rotation._theta_init); 0 if the state needs the Landen path */
static int rbs_theta_init(double *params, double kk, double kkp, double rf, double k, double kp, double beta,
                          int reflect, double lmag, double j0, double j1, double d20, double d21, double nu, double a0,
                          double a1, double a2, double u0)
{
    double lq = -RBS_PI * kkp / kk;
    if (!(lq <= THETA_LNQ_MAX)) return 0;
    double k2 = k * k;
    double hw = 0.5 * RBS_PI / kk;
    double q = exp(lq);
    double s4 = exp(0.25 * lq);
    double f0 = 2.0 * a0 * s4 / sqrt(k);
    double f1 = 2.0 * a1 * s4 / (sqrt(k) * sqrt(kp));
    params[I_TH_M0] = f0;
    params[I_TH_M1] = f1;
    params[I_TH_M2] = a2;
    double e = 1.0;
    double sh = 0.0, ch = 1.0;   /* sinh, cosh of (2n + 1) a (reflected) */
    double s2a = 0.0, c2a = 1.0; /* sinh, cosh of 2a */
    if (reflect) {
        double a = hw * rf;
        sh = sinh(a);
        ch = cosh(a);
        s2a = 2.0 * sh * ch;
        c2a = 1.0 + 2.0 * sh * sh;
        params[I_TH_WR] = ch;
        params[I_TH_WI] = -sh;
    } else {
        e = exp(2.0 * hw * sqrt(beta) * rf);
        params[I_TH_WR] = 1.0;
        params[I_TH_WI] = 0.0;
    }
    double qo = q;   /* q^(2n - 1) */
    double qn = 1.0; /* q^(n^2) */
    double qd = 1.0; /* q^(n (n + 1)) */
    double cp = 1.0; /* q^(n^2) e^(n at2), at2 = 2 alpha~ (reflected: the bound of _theta_init) */
    double cm = 1.0; /* q^(n^2) e^(-n at2) */
    double sgn = 1.0;
    double zn = 0.0; /* sums for Jacobi's zeta (reflected: sum (2n + 1) WR_n and -sum WI_n) */
    double zd = 1.0;
    if (reflect) {
        zn = ch;
        zd = sh;
    }
    int64_t n = 1;
    for (;;) {
        qn *= qo;
        qd *= qo * q;
        if (reflect) {
            double sh_next = sh * c2a + ch * s2a; /* no cancellation for small a */
            ch = ch * c2a + sh * s2a;
            sh = sh_next;
            cp = (double)(2 * n + 1) * qd * ch;
        } else {
            cp *= qo * e;
            cm *= qo / e;
        }
        if (!(cp > THETA_TOL || qn > THETA_TOL)) break;
        if (n == TH_TERMS) return 0;
        sgn = -sgn;
        double wr, wi;
        if (reflect) {
            wr = sgn * qd * ch;
            wi = -sgn * qd * sh;
            zn += (double)(2 * n + 1) * wr;
            zd -= wi;
        } else {
            wr = sgn * (cp + cm);
            wi = -sgn * (cp - cm);
            zn += (double)n * wi;
            zd += wr;
        }
        params[I_TH_M0 + n] = f0 * qd;
        params[I_TH_M1 + n] = sgn * f1 * qd;
        params[I_TH_M2 + n] = 2.0 * a2 * qn;
        params[I_TH_WR + n] = wr;
        params[I_TH_WI + n] = wi;
        qo *= q * q;
        n++;
    }
    /* Z(i alpha) = i z; D/P_a of the rate of phi_E */
    double z = reflect ? hw * (zn / zd - 1.0) /* from theta_1'/theta_1 at -i a */
                       : RBS_PI / kk * zn / zd; /* (pi/K) sum n WI_n / sum WR_n */
    double pa = sqrt(beta * (k2 + beta) * (1.0 + beta));
    double lin = lmag / j0 + lmag * (j0 - j1) * d20 / (j0 * j0 * d21) * z / pa;
    params[I_TH_NUV] = nu * hw;
    if (reflect) lin -= params[I_TH_NUV]; /* w's factor e^{-iv} */
    params[I_LIN] = lin;
    params[I_TH_N] = (double)n;
    params[I_TH_V0] = u0 * hw;
    params[I_TH_CRE] = 1.0;
    params[I_TH_CIM] = 0.0;
    params[I_TH_REFLECT] = reflect ? 1.0 : 0.0;
    return 1;
}

/* (sin x, cos x) of a phase: rbs_sincos on its domain |x| < 2^62, libm's beyond
 * (direct_model.rotation._phase_sincos) */
RBS_INLINE void rbs_phase_sincos(double x, double *s, double *c)
{
    if (fabs(x) < 0x1p62) {
        rbs_sincos(x, s, c);
    } else {
        *s = sin(x);
        *c = cos(x);
    }
}

/* the unit momentum n = m / |m| and (cos psi, sin psi) at time t in the theta mode
 * (direct_model.rotation._theta_state) */
RBS_INLINE void rbs_theta_state(const double *params, double t, double n[3], double *cpsi, double *spsi)
{
    double v = params[I_TH_NUV] * t + params[I_TH_V0];
    double s1, c1;
    rbs_phase_sincos(v, &s1, &c1);
    double c2 = c1 * c1 - s1 * s1;
    double s2 = 2.0 * s1 * c1;
    double co = c1, so = s1; /* cos, sin of (2n + 1) v */
    double ce = 1.0, se = 0.0; /* cos, sin of 2n v */
    double m0 = 0.0, m1 = 0.0, m2 = 0.0, wr = 0.0, wi = 0.0;
    int odd = params[I_TH_REFLECT] != 0.0; /* reflected: w = theta_1(v - i a), odd multiples of v */
    int64_t nterms = rbs_trunc(params[I_TH_N]);
    for (int64_t i = 0; i < nterms; i++) {
        m0 += params[I_TH_M0 + i] * co;
        m1 += params[I_TH_M1 + i] * so;
        m2 += params[I_TH_M2 + i] * ce;
        wr += params[I_TH_WR + i] * (odd ? so : ce);
        wi += params[I_TH_WI + i] * (odd ? co : se);
        double co_next = co * c2 - so * s2;
        so = so * c2 + co * s2;
        co = co_next;
        double ce_next = ce * c2 - se * s2;
        se = se * c2 + ce * s2;
        ce = ce_next;
    }
    double sa, ca;
    rbs_phase_sincos(params[I_LIN] * t, &sa, &ca);
    double r = 1.0 / sqrt((wr * wr + wi * wi) * (m0 * m0 + m1 * m1));
    double xr = wr * m0 + wi * m1; /* w (m_0 - i m_1) */
    double xi = wi * m0 - wr * m1;
    double yr = (xr * ca - xi * sa) * r;
    double yi = (xr * sa + xi * ca) * r;
    double cre = params[I_TH_CRE];
    double cim = params[I_TH_CIM];
    double inv = 1.0 / sqrt(m0 * m0 + m1 * m1 + m2 * m2);
    n[0] = m0 * inv;
    n[1] = m1 * inv;
    n[2] = m2 * inv;
    *cpsi = yr * cre - yi * cim;
    *spsi = yr * cim + yi * cre;
}

/* rotation B (row-major) about e_z x n taking e_z to the unit vector n: I + [v]x + [v]x^2 / (1 + n_2) */
static void rbs_ez_to_n(double n0, double n1, double n2, double b[9])
{
    double f = 1.0 / (1.0 + n2);
    double b01 = -f * n0 * n1;
    b[0] = 1.0 - f * n0 * n0;
    b[1] = b01;
    b[2] = n0;
    b[3] = b01;
    b[4] = 1.0 - f * n1 * n1;
    b[5] = n1;
    b[6] = -n0;
    b[7] = -n1;
    b[8] = n2;
}

/* ---------------------------------------------------------------- set-up */

/* (m0, m1, m2) an eigenvector of diag(k0, k1, k2) (exact comparison) */
static int rbs_is_steady(double m0, double m1, double m2, double k0, double k1, double k2)
{
    if (m0 != 0.0 && m1 != 0.0 && k0 != k1) return 0;
    if (m0 != 0.0 && m2 != 0.0 && k0 != k2) return 0;
    if (m1 != 0.0 && m2 != 0.0 && k1 != k2) return 0;
    return 1;
}

/* Store the descending Landen moduli; K(k) = pi/2 prod(1 + k_n) into *kcomp and (Pi(-eta | k) - K) / K
 * into *pik (the AGM of (1, k') with the third-kind sum of DLMF 19.8.6). The exit test is written so that a
 * NaN ends the loop too, as in numba. */
static void rbs_landen_agm(double k, double kp, double eta, double *params, double *kcomp, double *pik)
{
    int64_t n = 0;
    double prod = 1.0;
    double a = 1.0;
    double pp2 = 1.0 + eta;
    double num = eta + k * k / (1.0 + kp);
    double q = 1.0;
    double qsum = 1.0;
    for (;;) {
        double den = pp2 + a * a * kp;
        q *= 0.5 * num / den;
        qsum += q;
        int landen = k >= LANDEN_KTOL && n < NLEV_MAX;
        if (!landen && !(fabs(q) > 1e-17 * qsum)) break;
        double opk = 1.0 + kp;
        double r = 1.0 / opk;
        if (landen) {
            if (kp <= 0.5) {
                k = (1.0 - kp) * r;
            } else {
                double kr = k * r;
                k = kr * kr;
            }
            params[I_KN + n] = k;
            params[I_OMKN + n] = 2.0 * kp * r;
            prod *= 1.0 + k;
            n += 1;
        }
        a = 0.5 * a * opk;
        kp = 2.0 * sqrt(kp) * r;
        pp2 = den * den / (4.0 * pp2);
        num = pp2 - a * a * kp;
    }
    params[I_NLEV] = (double)n;
    params[I_WSCALE] = 1.0 / prod;
    *kcomp = 0.5 * RBS_PI * prod;
    *pik = -0.5 * eta / (1.0 + eta) * qsum;
}

/* C = R0 (static and steady modes) */
static void rbs_store_r0(const double R0[9], double *params)
{
    for (int i = 0; i < 9; i++) params[I_C + i] = R0[i];
}

/* RBS_HOT: the x86-64-v3 version has rbs_sincos's fma() as one instruction (the same bits either way) */
RBS_HOT void rbs_rotation_init(const double K[3], const double R0[9], const double ell[3], double *params)
{
    for (int i = 0; i < I_KN; i++) params[i] = 0.0;    /* the Landen levels beyond I_NLEV are never read */
    double mb0 = R0[0] * ell[0] + R0[3] * ell[1] + R0[6] * ell[2];
    double mb1 = R0[1] * ell[0] + R0[4] * ell[1] + R0[7] * ell[2];
    double mb2 = R0[2] * ell[0] + R0[5] * ell[1] + R0[8] * ell[2];
    double lmag = sqrt(mb0 * mb0 + mb1 * mb1 + mb2 * mb2);
    if (lmag == 0.0) {
        params[I_MODE] = MODE_STATIC;
        rbs_store_r0(R0, params);
        return;
    }

    /* steady rotation about an eigenvector of the inertia tensor */
    double thr = SNAP * lmag;
    double s0 = fabs(mb0) > thr ? mb0 : 0.0;
    double s1 = fabs(mb1) > thr ? mb1 : 0.0;
    double s2 = fabs(mb2) > thr ? mb2 : 0.0;
    if (rbs_is_steady(s0, s1, s2, K[0], K[1], K[2])) {
        params[I_MODE] = MODE_STEADY;
        rbs_store_r0(R0, params);
        double w0 = s0 / K[0];
        double w1 = s1 / K[1];
        double w2 = s2 / K[2];
        for (int r = 0; r < 3; r++)
            params[I_OMEGA + r] = R0[3 * r + 0] * w0 + R0[3 * r + 1] * w1 + R0[3 * r + 2] * w2;
        return;
    }

    /* working frame: sort the axes, pick the circulated one, fix the signs */
    const double mb[3] = {mb0, mb1, mb2};
    int i_lo = 0, i_mid = 1, i_hi = 2, swap;
    if (K[i_mid] < K[i_lo]) { swap = i_lo; i_lo = i_mid; i_mid = swap; }
    if (K[i_hi] < K[i_mid]) { swap = i_mid; i_mid = i_hi; i_hi = swap; }
    if (K[i_mid] < K[i_lo]) { swap = i_lo; i_lo = i_mid; i_mid = swap; }
    double hsep = rbs_separatrix_distance(K[i_lo], K[i_mid], K[i_hi], mb[i_lo], mb[i_hi]);
    int o0, o1, o2;
    if (hsep >= 0.0) { /* L^2 >= 2E I_mid: circulation around the axis of largest inertia */
        o0 = i_lo;
        o1 = i_mid;
        o2 = i_hi;
    } else {
        o0 = i_hi;
        o1 = i_mid;
        o2 = i_lo;
    }
    double parity = (o1 - o0) * (o2 - o0) * (o2 - o1) > 0 ? 1.0 : -1.0;
    double sg0 = mb[o0] >= 0.0 ? 1.0 : -1.0;
    double sg2 = mb[o2] >= 0.0 ? 1.0 : -1.0;
    double sg1 = parity * sg0 * sg2;
    double x = sg0 * mb[o0];
    double y = sg1 * mb[o1];
    double z = sg2 * mb[o2];
    double j0 = K[o0];
    double j1 = K[o1];
    double j2 = K[o2];
    params[I_PERM + 0] = o0;
    params[I_PERM + 1] = o1;
    params[I_PERM + 2] = o2;
    params[I_SIGN + 0] = sg0;
    params[I_SIGN + 1] = sg1;
    params[I_SIGN + 2] = sg2;
    params[I_LJ + 0] = lmag / j0;
    params[I_LJ + 1] = lmag / j1;
    params[I_LJ + 2] = lmag / j2;

    /* Landau-Lifshitz amplitudes, rate and modulus */
    double d10 = fabs(j1 - j0);
    double d20 = fabs(j2 - j0);
    double d21 = fabs(j2 - j1);
    double pp = x * x * d20 / j0 + y * y * d21 / j1;
    double ss = y * y * d10 / j1 + z * z * d20 / j2;
    double kp2 = rbs_fmin_py(d20 * fabs(hsep) / (j0 * j2 * d21 * ss), 1.0);
    double k2 = rbs_fmin_py(d10 * pp / (d21 * ss), 1.0);
    double a2 = sqrt(ss * j2 / d20);
    params[I_A + 0] = sqrt(pp * j0 / d20);
    params[I_A + 1] = sqrt(pp * j1 / d21);
    params[I_A + 2] = a2;
    double nu = copysign(sqrt(d21 * ss / (j0 * j1 * j2)), j2 - j1);
    params[I_NU] = nu;
    double beta = j2 * d10 / (j0 * d21);
    double gamma = pp * j0 / (ss * j2); /* = k^2 / beta */
    double gfac = sqrt(1.0 + beta);
    double sqd = sqrt((1.0 + beta) * (1.0 + gamma));
    double kappa = (j2 - j0) / (j0 * j2);
    params[I_BETA] = beta;
    params[I_G] = gfac;
    params[I_A2G] = a2 / gfac;
    params[I_L] = lmag;
    params[I_KAPNU] = kappa / nu;

    /* initial amplitude phi_0 (cos phi_0 >= 0) and phase u_0 = F(phi_0 | k) */
    double cf = x * sqrt(j1 * d20);
    double sf = y * sqrt(j0 * d21);
    double hinv = 1.0 / sqrt(cf * cf + sf * sf); /* no hypot: |ell| and K within 1e+-100 of 1 (rotation.py) */
    cf *= hinv;
    sf *= hinv;
    double s, c, d, gval, u0, n[3];
    int theta = kp2 != 0.0 && k2 >= THETA_K2_MIN; /* a candidate for the theta mode */
    double k = 0.0, kp = 0.0, kk = 0.0, kkp = 0.0, rf_shift = 0.0; /* set and read only if theta */
    int reflect = 0;
    if (kp2 == 0.0) {
        params[I_MODE] = MODE_SEPARATRIX;
        params[I_LIN] = lmag / j2;
        u0 = asinh(sf / cf);
    } else if (k2 == 0.0) { /* axisymmetric (J_0 = J_1): F(phi | 0) = phi */
        u0 = atan2(sf, cf);
    } else {
        d = sqrt(cf * cf + kp2 * sf * sf); /* dn(u_0) */
        double rf_u0;
        if (theta) {
            k = sqrt(k2);
            kp = sqrt(kp2);
            reflect = beta > k; /* alpha > K'/2: w passes near a zero of theta_4, so it is taken through theta_1 */
            rbs_theta_elliptic(k, kp, reflect ? beta : k2, reflect ? k2 + beta : k2 * (1.0 + beta),
                               reflect ? 1.0 + beta : k2 + beta, cf * cf, cf, d * d, d, &kk, &kkp, &rf_shift, &rf_u0);
        } else {
            rf_u0 = rbs_rf_amp(cf * cf, cf, d * d, d);
        }
        u0 = sf * rf_u0;
    }
    params[I_U0] = u0;
    if (theta && rbs_theta_init(params, kk, kkp, rf_shift, k, kp, beta, reflect, lmag, j0, j1, d20, d21, nu,
                                params[I_A + 0], params[I_A + 1], a2, u0)) {
        params[I_MODE] = MODE_THETA;
        double cr, ci;
        rbs_theta_state(params, 0.0, n, &cr, &ci);
        params[I_TH_CRE] = cr; /* then psi(0) = 0 and R(0) = R0 up to rounding */
        params[I_TH_CIM] = -ci;
    } else {
        if (kp2 != 0.0) {
            params[I_MODE] = MODE_GENERAL;
            /* the R_J term: Pi - F with eta = beta (form 1) or Pi(-gamma) - F (form 2) */
            int form2 = beta > 1.0;
            double eta = form2 ? gamma : beta;
            params[I_FORM2] = form2 ? 1.0 : 0.0;
            params[I_ETA] = eta;
            params[I_DCOEF] = eta * (1.0 + eta) * (eta + k2);
            params[I_CPI] = form2 ? lmag * gamma / 3.0 : -lmag * beta / 3.0;
            params[I_SQD] = sqd;
            params[I_LSQD] = lmag / sqd;
            double kcomp, pik;
            rbs_landen_agm(sqrt(k2), sqrt(kp2), eta, params, &kcomp, &pik);
            params[I_TWOK] = 2.0 * kcomp;
            params[I_INV2K] = 0.5 / kcomp;
            /* mean f_bar = G(K) / K; psi' = L/J_2 + kappa f  =>  mean rate L/J_2 + kappa f_bar */
            double g_quarter = -a2 * 0.5 * RBS_PI / gfac; /* -a_2 T(pi/2) */
            double foff;
            if (form2) {
                g_quarter += lmag * (0.5 * RBS_PI / sqd - pik * kcomp);
                foff = g_quarter / kcomp; /* f_bar */
                params[I_LIN] = lmag / j2 + kappa * foff;
            } else {
                foff = lmag * pik - a2 * 0.5 * RBS_PI / (gfac * kcomp); /* f_bar - L */
                params[I_LIN] = lmag / j0 + kappa * foff;
            }
            params[I_FOFF] = foff;
        }
        /* G_p and n at u_0 as rbs_rotation_at evaluates them: psi(0) = 0 and R(0) = R0 up to rounding */
        rbs_phase_state(params, u0, &s, &c, &d, &gval);
        params[I_G0] = gval;
        rbs_unit_momentum(params, s, c, d, n);
    }

    /* C = R0 Q B(n(0)): makes R(0) = R0 up to rounding */
    double b[9];
    rbs_ez_to_n(n[0], n[1], n[2], b);
    for (int r = 0; r < 3; r++) {
        double q0 = sg0 * R0[3 * r + o0];
        double q1 = sg1 * R0[3 * r + o1];
        double q2 = sg2 * R0[3 * r + o2];
        params[I_C + 3 * r + 0] = q0 * b[0] + q1 * b[3] + q2 * b[6];
        params[I_C + 3 * r + 1] = q0 * b[1] + q1 * b[4] + q2 * b[7];
        params[I_C + 3 * r + 2] = q0 * b[2] + q1 * b[5] + q2 * b[8];
    }
}

/* ---------------------------------------------------------------- evaluation */

RBS_HOT void rbs_rotation_at(const double *params, double t, double R_out[9], double omega_out[3])
{
    double mode = params[I_MODE];
    if (mode == MODE_STATIC) {
        for (int r = 0; r < 3; r++) {
            omega_out[r] = 0.0;
            for (int c = 0; c < 3; c++) R_out[3 * r + c] = params[I_C + 3 * r + c];
        }
        return;
    }
    if (mode == MODE_STEADY) {
        double w0 = params[I_OMEGA + 0];
        double w1 = params[I_OMEGA + 1];
        double w2 = params[I_OMEGA + 2];
        double wn = sqrt(w0 * w0 + w1 * w1 + w2 * w2);
        double e0 = w0 / wn;
        double e1 = w1 / wn;
        double e2 = w2 / wn;
        double sn = sin(wn * t);
        double sh = sin(0.5 * wn * t);
        double vc = 2.0 * (sh * sh); /* 1 - cos */
        /* Rodrigues: Rot = I + sin [e]x + (1 - cos) [e]x^2 */
        double r00 = 1.0 - vc * (e1 * e1 + e2 * e2);
        double r11 = 1.0 - vc * (e0 * e0 + e2 * e2);
        double r22 = 1.0 - vc * (e0 * e0 + e1 * e1);
        double r01 = vc * e0 * e1 - sn * e2;
        double r10 = vc * e0 * e1 + sn * e2;
        double r02 = vc * e0 * e2 + sn * e1;
        double r20 = vc * e0 * e2 - sn * e1;
        double r12 = vc * e1 * e2 - sn * e0;
        double r21 = vc * e1 * e2 + sn * e0;
        for (int c = 0; c < 3; c++) {
            double p0 = params[I_C + c];
            double p1 = params[I_C + 3 + c];
            double p2 = params[I_C + 6 + c];
            R_out[0 + c] = r00 * p0 + r01 * p1 + r02 * p2;
            R_out[3 + c] = r10 * p0 + r11 * p1 + r12 * p2;
            R_out[6 + c] = r20 * p0 + r21 * p1 + r22 * p2;
        }
        omega_out[0] = w0;
        omega_out[1] = w1;
        omega_out[2] = w2;
        return;
    }

    double n[3], b[9], cp, sp;
    if (mode == MODE_THETA) {
        rbs_theta_state(params, t, n, &cp, &sp);
    } else {
        double u = params[I_NU] * t + params[I_U0];
        double s, c, d, gval;
        rbs_phase_state(params, u, &s, &c, &d, &gval);
        rbs_unit_momentum(params, s, c, d, n);
        double psi = params[I_LIN] * t + params[I_KAPNU] * (gval - params[I_G0]);
        cp = cos(psi);
        sp = sin(psi);
    }
    rbs_ez_to_n(n[0], n[1], n[2], b);
    /* M = Rz(psi) B^T (rows of B^T are the columns of B) */
    double m00 = cp * b[0] - sp * b[1];
    double m01 = cp * b[3] - sp * b[4];
    double m02 = cp * b[6] - sp * b[7];
    double m10 = sp * b[0] + cp * b[1];
    double m11 = sp * b[3] + cp * b[4];
    double m12 = sp * b[6] + cp * b[7];
    /* working-frame angular velocity L n / J */
    double w0 = params[I_LJ + 0] * n[0];
    double w1 = params[I_LJ + 1] * n[1];
    double w2 = params[I_LJ + 2] * n[2];
    int64_t o0 = rbs_trunc(params[I_PERM + 0]);
    int64_t o1 = rbs_trunc(params[I_PERM + 1]);
    int64_t o2 = rbs_trunc(params[I_PERM + 2]);
    double sg0 = params[I_SIGN + 0];
    double sg1 = params[I_SIGN + 1];
    double sg2 = params[I_SIGN + 2];
    for (int r = 0; r < 3; r++) {
        double c0 = params[I_C + 3 * r + 0];
        double c1 = params[I_C + 3 * r + 1];
        double c2 = params[I_C + 3 * r + 2];
        double rw0 = c0 * m00 + c1 * m10 + c2 * b[2];
        double rw1 = c0 * m01 + c1 * m11 + c2 * b[5];
        double rw2 = c0 * m02 + c1 * m12 + c2 * b[8];
        R_out[3 * r + o0] = sg0 * rw0;
        R_out[3 * r + o1] = sg1 * rw1;
        R_out[3 * r + o2] = sg2 * rw2;
        omega_out[r] = rw0 * w0 + rw1 * w1 + rw2 * w2;
    }
}
