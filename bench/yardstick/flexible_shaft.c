/*
 * flexible_shaft.c -- hand-written C yardstick for the gearsym benchmark.
 *
 * Lyapunov spectrum of the gear pair on a flexible shaft (nondimensional
 * time tau, state y = (x1, v1, x2, v2)) over a continuation sweep in omega:
 *
 *   x1' = v1
 *   v1' = -2 zeta/omega v1 + (B0 + B1 cos(tau + Theta))/omega^2
 *         - k(tau) g(x1)/omega^2 - kS b1 x2/omega^2
 *   x2' = v2
 *   v2' = -kS b2 x2/omega^2 - 2 zeta b3/omega v1 - b3 k(tau) g(x1)/omega^2
 *
 *   b1 = 1/I2, b2 = 1/I2 + 1/I3, b3 = (r2^2/I2) / (r2^2/I2 + r1^2/I1)
 *   k(tau) = 1 + k_a * (six-harmonic mesh stiffness series, see mesh_k)
 *   g(x)   = backlash: x for x >= 0, 0 inside (-eta, 0), x + eta for x <= -eta
 *
 * Scheme (fixed so that other implementations can match it to ~1e-9):
 *   - forcing period T = 2 pi, N steps per period, h = T/N;
 *   - classic RK4 on the augmented 4 + 16 dimensional system (y, Q) with
 *     Q' = J(tau, y) Q, J the exact Jacobian (using g' = 0 or 1), evaluated
 *     at each stage's own state and time; the tangent product is done densely
 *     (full 4x4 times 4x4), this is the "dense tangent" yardstick;
 *   - stage times of step i are i h, i h + h/2, i h + h with tau = 0 at the
 *     start of every period (everything is 2 pi periodic). They are formed as
 *     j * (h/2), j = 2i, 2i+1, 2i+2, which is the same number as i*h + {0,h/2,h}
 *     up to rounding in the last bit and makes the --table and --direct
 *     variants bit-for-bit identical;
 *   - after every period Q is re-orthonormalised by modified Gram-Schmidt and
 *     log of each column norm is recorded; the first D of P periods are
 *     discarded, exponent_j = sum(log norm_j) / ((P - D) T);
 *   - amplitude A = (max - min)/2 of x1 and x2, sampled after every step of
 *     the measured periods.
 *
 * Variants:
 *   --table  (default) k(tau) and the forcing are 2 pi periodic and the step
 *            grid repeats every period, so their values at the 2N+1 half-step
 *            times are computed once per omega point and looked up.
 *   --direct evaluate them with cos() at the stage times (once per distinct
 *            time: the two middle stages share tau + h/2, and the end of a
 *            step is the start of the next one).
 *
 * Sweep: omega_i = omega_start + i * omega_step up to omega_stop; the first
 * point starts at y0 = (-2, -0.5, 0, 0), each further point starts from the
 * final state of the previous one (continuation); Q = I at every point.
 *
 * Output (stdout, after the timed sweep): CSV
 *   omega,lambda_1,lambda_2,lambda_3,lambda_4,A_x1,A_x2,seconds
 * with the exponents in Gram-Schmidt column order, then one "# y_end=x1,v1,x2,v2"
 * line per point (its final state) and "# total_seconds=...".
 *
 * Build: gcc -O3 -std=c99 -Wall -Wextra -o flexible_shaft flexible_shaft.c -lm
 */
#define _POSIX_C_SOURCE 199309L /* clock_gettime under -std=c99 */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define TWO_PI 6.283185307179586476925286766559
#define NS 20 /* augmented state: 4 state variables + 16 tangent entries */

/* Physical parameters (command-line adjustable). */
typedef struct {
    double zeta, B0, B1, Theta, eta, kS, k_a;
    double I1, I2, I3, r1, r2;
} Params;

/* Per-omega constants of the right-hand side, so the hot loop does no
 * divisions. kw = k(tau)/omega^2 and fw = forcing/omega^2 come per stage. */
typedef struct {
    double c1;  /* 2 zeta / omega          (damping of v1)            */
    double c3;  /* 2 zeta b3 / omega       (damping coupling into v2) */
    double s1;  /* kS b1 / omega^2         (shaft into v1)            */
    double s2;  /* kS b2 / omega^2         (shaft into v2)            */
    double b3;
    double eta;
} Coef;

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Time-varying mesh stiffness k(tau) (Fourier series of the paper). */
static double mesh_k(double tau, double k_a)
{
    return 1.0 + k_a * (1.18003861468 * cos(tau)
                        - 0.336894506314 * cos(2.0 * tau)
                        - 0.195632837787 * cos(3.0 * tau)
                        + 0.192724343884 * cos(4.0 * tau)
                        - 0.0605674179821 * cos(6.0 * tau)
                        + 0.0148837545288 * cos(7.0 * tau));
}

/* The two time-dependent coefficients at time tau, already divided by
 * omega^2. Both variants go through this one function (the table merely
 * caches it), which is what keeps them bit-identical. */
static void time_coefs(double tau, const Params *p, double inv_w2,
                       double *kw, double *fw)
{
    *kw = mesh_k(tau, p->k_a) * inv_w2;
    *fw = (p->B0 + p->B1 * cos(tau + p->Theta)) * inv_w2;
}

/* Right-hand side of the augmented system: ds = (f(y), J(y) Q).
 * s[0..3] = y, s[4..19] = Q stored column-major (column c at s[4 + 4c]). */
static inline void rhs(const double *restrict s, double kw, double fw,
                       const Coef *restrict c, double *restrict ds)
{
    const double x1 = s[0], v1 = s[1], x2 = s[2], v2 = s[3];

    /* Backlash and its slope; at x1 = -eta both branches give g = 0. */
    double g, gp;
    if (x1 >= 0.0) {
        g = x1;
        gp = 1.0;
    } else if (x1 <= -c->eta) {
        g = x1 + c->eta;
        gp = 1.0;
    } else {
        g = 0.0;
        gp = 0.0;
    }

    ds[0] = v1;
    ds[1] = -c->c1 * v1 + fw - kw * g - c->s1 * x2;
    ds[2] = v2;
    ds[3] = -c->s2 * x2 - c->c3 * v1 - c->b3 * kw * g;

    /* Full Jacobian, row-major. The structural zeros are kept on purpose:
     * this yardstick does the dense 4x4 by 4x4 tangent product. */
    const double J[4][4] = {
        {0.0, 1.0, 0.0, 0.0},
        {-kw * gp, -c->c1, -c->s1, 0.0},
        {0.0, 0.0, 0.0, 1.0},
        {-c->b3 * kw * gp, -c->c3, -c->s2, 0.0},
    };
    const double *Q = s + 4;
    double *dQ = ds + 4;
    for (int col = 0; col < 4; col++)
        for (int r = 0; r < 4; r++)
            dQ[4 * col + r] = J[r][0] * Q[4 * col + 0] + J[r][1] * Q[4 * col + 1]
                            + J[r][2] * Q[4 * col + 2] + J[r][3] * Q[4 * col + 3];
}

/* One classic RK4 step of size h; (kw0,fw0) at tau, (kwm,fwm) at tau + h/2,
 * (kw1,fw1) at tau + h. */
static inline void rk4_step(double *restrict s, double h, const Coef *restrict c,
                            double kw0, double fw0, double kwm, double fwm,
                            double kw1, double fw1)
{
    double k1[NS], k2[NS], k3[NS], k4[NS], t[NS];
    const double hh = 0.5 * h, h6 = h / 6.0;

    rhs(s, kw0, fw0, c, k1);
    for (int n = 0; n < NS; n++) t[n] = s[n] + hh * k1[n];
    rhs(t, kwm, fwm, c, k2);
    for (int n = 0; n < NS; n++) t[n] = s[n] + hh * k2[n];
    rhs(t, kwm, fwm, c, k3);
    for (int n = 0; n < NS; n++) t[n] = s[n] + h * k3[n];
    rhs(t, kw1, fw1, c, k4);
    for (int n = 0; n < NS; n++)
        s[n] += h6 * (k1[n] + 2.0 * k2[n] + 2.0 * k3[n] + k4[n]);
}

/* Modified Gram-Schmidt on the column-major 4x4 Q; lognorm[j] = log |q_j|
 * after removing the components along q_0..q_{j-1}. */
static void mgs(double *Q, double lognorm[4])
{
    for (int j = 0; j < 4; j++) {
        double *qj = Q + 4 * j;
        for (int i = 0; i < j; i++) {
            const double *qi = Q + 4 * i;
            double r = qi[0] * qj[0] + qi[1] * qj[1] + qi[2] * qj[2] + qi[3] * qj[3];
            for (int k = 0; k < 4; k++) qj[k] -= r * qi[k];
        }
        double nrm = sqrt(qj[0] * qj[0] + qj[1] * qj[1] + qj[2] * qj[2] + qj[3] * qj[3]);
        for (int k = 0; k < 4; k++) qj[k] /= nrm;
        lognorm[j] = log(nrm);
    }
}

typedef struct {
    double omega;
    double lambda[4];
    double amp[2];
    double y_end[4]; /* final state (the next point's start) */
    double seconds;
} Result;

/* One omega point: integrates P periods from state y (updated in place, for
 * continuation) and fills res. kw_tab/fw_tab are scratch of size 2N+1. */
static void run_point(double omega, const Params *p, int N, int P, int D,
                      int use_table, double *kw_tab, double *fw_tab,
                      double y[4], Result *res)
{
    const double T = TWO_PI, h = T / N, hh = 0.5 * h;
    const double inv_w2 = 1.0 / (omega * omega);
    const double b1 = 1.0 / p->I2;
    const double b2 = 1.0 / p->I2 + 1.0 / p->I3;
    const double a2 = p->r2 * p->r2 / p->I2, a1 = p->r1 * p->r1 / p->I1;
    const double b3 = a2 / (a2 + a1);
    const Coef c = {
        .c1 = 2.0 * p->zeta / omega,
        .c3 = 2.0 * p->zeta * b3 / omega,
        .s1 = p->kS * b1 * inv_w2,
        .s2 = p->kS * b2 * inv_w2,
        .b3 = b3,
        .eta = p->eta,
    };

    if (use_table)
        for (int j = 0; j <= 2 * N; j++)
            time_coefs(j * hh, p, inv_w2, &kw_tab[j], &fw_tab[j]);

    double s[NS];
    memcpy(s, y, 4 * sizeof(double));
    for (int n = 4; n < NS; n++) s[n] = 0.0;
    for (int k = 0; k < 4; k++) s[4 + 5 * k] = 1.0; /* Q = identity */

    double sumlog[4] = {0.0, 0.0, 0.0, 0.0};
    double xmin[2] = {INFINITY, INFINITY}, xmax[2] = {-INFINITY, -INFINITY};

    for (int per = 0; per < P; per++) {
        const int measured = per >= D;
        double kw0, fw0, kwm, fwm, kw1, fw1;
        if (!use_table) time_coefs(0.0, p, inv_w2, &kw1, &fw1); /* tau0 = 0 */

        for (int i = 0; i < N; i++) {
            if (use_table) {
                kw0 = kw_tab[2 * i];     fw0 = fw_tab[2 * i];
                kwm = kw_tab[2 * i + 1]; fwm = fw_tab[2 * i + 1];
                kw1 = kw_tab[2 * i + 2]; fw1 = fw_tab[2 * i + 2];
            } else {
                kw0 = kw1; fw0 = fw1; /* end of last step = start of this one */
                time_coefs((2 * i + 1) * hh, p, inv_w2, &kwm, &fwm);
                time_coefs((2 * i + 2) * hh, p, inv_w2, &kw1, &fw1);
            }
            rk4_step(s, h, &c, kw0, fw0, kwm, fwm, kw1, fw1);

            if (measured) {
                if (s[0] < xmin[0]) xmin[0] = s[0];
                if (s[0] > xmax[0]) xmax[0] = s[0];
                if (s[2] < xmin[1]) xmin[1] = s[2];
                if (s[2] > xmax[1]) xmax[1] = s[2];
            }
        }

        double lognorm[4];
        mgs(s + 4, lognorm);
        if (measured)
            for (int j = 0; j < 4; j++) sumlog[j] += lognorm[j];
    }

    memcpy(y, s, 4 * sizeof(double));
    memcpy(res->y_end, s, 4 * sizeof(double));
    res->omega = omega;
    for (int j = 0; j < 4; j++) res->lambda[j] = sumlog[j] / ((P - D) * T);
    res->amp[0] = 0.5 * (xmax[0] - xmin[0]);
    res->amp[1] = 0.5 * (xmax[1] - xmin[1]);
}

static void usage(const char *prog)
{
    fprintf(stderr,
            "usage: %s [--table|--direct] [--steps N] [--periods P] [--discard D]\n"
            "          [--omega-start a] [--omega-stop b] [--omega-step c]\n"
            "          [--y0 x1,v1,x2,v2]\n"
            "          [--zeta v] [--B0 v] [--B1 v] [--Theta v] [--eta v] [--kS v]\n"
            "          [--k_a v] [--I1 v] [--I2 v] [--I3 v] [--r1 v] [--r2 v]\n",
            prog);
}

static double parse_double(const char *flag, const char *text)
{
    char *end;
    double v = strtod(text, &end);
    if (end == text || *end != '\0') {
        fprintf(stderr, "bad number for %s: '%s'\n", flag, text);
        exit(2);
    }
    return v;
}

static int parse_int(const char *flag, const char *text)
{
    char *end;
    long v = strtol(text, &end, 10);
    if (end == text || *end != '\0' || v < 0 || v > 100000000L) {
        fprintf(stderr, "bad integer for %s: '%s'\n", flag, text);
        exit(2);
    }
    return (int)v;
}

int main(int argc, char **argv)
{
    Params p = {.zeta = 0.08, .B0 = 1.0, .B1 = 4.0, .Theta = 0.0, .eta = 10.0,
                .kS = 0.1, .k_a = 0.2,
                .I1 = 1.0, .I2 = 1.0, .I3 = 1.0, .r1 = 1.0, .r2 = 1.0};
    int use_table = 1, N = 200, P = 400, D = 100;
    double w_start = 0.1, w_stop = 2.0, w_step = 0.01;
    double y[4] = {-2.0, -0.5, 0.0, 0.0};

    /* Name -> field table for the physical parameters. */
    struct { const char *flag; double *field; } pflags[] = {
        {"--zeta", &p.zeta}, {"--B0", &p.B0}, {"--B1", &p.B1},
        {"--Theta", &p.Theta}, {"--eta", &p.eta}, {"--kS", &p.kS},
        {"--k_a", &p.k_a}, {"--I1", &p.I1}, {"--I2", &p.I2},
        {"--I3", &p.I3}, {"--r1", &p.r1}, {"--r2", &p.r2},
        {"--omega-start", &w_start}, {"--omega-stop", &w_stop},
        {"--omega-step", &w_step},
    };
    const int npflags = (int)(sizeof pflags / sizeof pflags[0]);

    for (int a = 1; a < argc; a++) {
        const char *arg = argv[a];
        if (!strcmp(arg, "--table")) { use_table = 1; continue; }
        if (!strcmp(arg, "--direct")) { use_table = 0; continue; }
        if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) { usage(argv[0]); return 0; }
        if (a + 1 >= argc) {
            fprintf(stderr, "missing value for %s\n", arg);
            usage(argv[0]);
            return 2;
        }
        const char *val = argv[++a];
        if (!strcmp(arg, "--steps")) { N = parse_int(arg, val); continue; }
        if (!strcmp(arg, "--periods")) { P = parse_int(arg, val); continue; }
        if (!strcmp(arg, "--discard")) { D = parse_int(arg, val); continue; }
        if (!strcmp(arg, "--y0")) {
            char *end;
            const char *q = val;
            for (int k = 0; k < 4; k++) {
                y[k] = strtod(q, &end);
                if (end == q || (k < 3 && *end != ',') || (k == 3 && *end != '\0')) {
                    fprintf(stderr, "bad --y0 '%s' (want x1,v1,x2,v2)\n", val);
                    return 2;
                }
                q = end + 1;
            }
            continue;
        }
        int found = 0;
        for (int f = 0; f < npflags; f++)
            if (!strcmp(arg, pflags[f].flag)) {
                *pflags[f].field = parse_double(arg, val);
                found = 1;
                break;
            }
        if (!found) {
            fprintf(stderr, "unknown option %s\n", arg);
            usage(argv[0]);
            return 2;
        }
    }
    if (N < 1 || P < 1 || D >= P || !(w_step > 0.0) || w_stop < w_start) {
        fprintf(stderr, "need steps >= 1, periods > discard >= 0, omega-step > 0, "
                        "omega-stop >= omega-start\n");
        return 2;
    }

    /* Point count with a small tolerance so that (2.0 - 0.1)/0.01 = 189.999..
     * still includes the end point. */
    const int npts = (int)floor((w_stop - w_start) / w_step + 1e-9) + 1;
    Result *res = malloc((size_t)npts * sizeof *res);
    double *kw_tab = malloc((size_t)(2 * N + 1) * sizeof(double));
    double *fw_tab = malloc((size_t)(2 * N + 1) * sizeof(double));
    if (!res || !kw_tab || !fw_tab) {
        fprintf(stderr, "out of memory\n");
        return 1;
    }

    const double t_begin = now_seconds();
    for (int i = 0; i < npts; i++) {
        const double t0 = now_seconds();
        run_point(w_start + w_step * i, &p, N, P, D, use_table, kw_tab, fw_tab,
                  y, &res[i]);
        res[i].seconds = now_seconds() - t0;
    }
    const double total = now_seconds() - t_begin;

    printf("omega,lambda_1,lambda_2,lambda_3,lambda_4,A_x1,A_x2,seconds\n");
    for (int i = 0; i < npts; i++)
        printf("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", res[i].omega,
               res[i].lambda[0], res[i].lambda[1], res[i].lambda[2], res[i].lambda[3],
               res[i].amp[0], res[i].amp[1], res[i].seconds);
    for (int i = 0; i < npts; i++)
        printf("# y_end=%.17g,%.17g,%.17g,%.17g\n", res[i].y_end[0], res[i].y_end[1],
               res[i].y_end[2], res[i].y_end[3]);
    printf("# variant=%s steps=%d periods=%d discard=%d points=%d\n",
           use_table ? "table" : "direct", N, P, D, npts);
    printf("# total_seconds=%.17g\n", total);

    free(res);
    free(kw_tab);
    free(fw_tab);
    return 0;
}
