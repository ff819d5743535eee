/*
 * one_stage.c -- hand-written C yardstick for the gearsym benchmark.
 *
 * Lyapunov spectrum of the one-stage gear pair (nondimensional time tau,
 * state y = (x, v)) over a continuation sweep in omega:
 *
 *   x' = v
 *   v' = -2 zeta/omega v + (B0 + B1 cos(tau + Theta))/omega^2 - k(tau) g(x)/omega^2
 *
 *   k(tau) = 1 + k_a * (six-harmonic mesh stiffness series, see mesh_k)
 *   g(x)   = backlash: x for x >= 0, 0 inside (-eta, 0), x + eta for x <= -eta
 *
 * Scheme: exactly that of flexible_shaft.c (read its header), for 2 states:
 *   - forcing period T = 2 pi, N steps per period, h = T/N;
 *   - classic RK4 on the augmented 2 + 4 dimensional system (y, Q) with
 *     Q' = J(tau, y) Q, J = [[0, 1], [-k g'/omega^2, -2 zeta/omega]] exact
 *     (g' = 0 or 1), evaluated at each stage's own state and time. For 2x2
 *     the tangent product is written out (no multiplications by 0 or 1);
 *   - stage times j * (h/2), j = 2i, 2i+1, 2i+2, tau = 0 at the start of
 *     every period, so --table and --direct are bit-for-bit identical;
 *   - modified Gram-Schmidt after every period, log of each column norm
 *     recorded; the first D of P periods are discarded,
 *     exponent_j = sum(log norm_j) / ((P - D) T);
 *   - amplitude A = (max - min)/2 of x, sampled after every step of the
 *     measured periods.
 *
 * Variants: --table (default; time coefficients at the 2N+1 half-step times
 * tabulated once per omega point) and --direct (cos() at the stage times,
 * once per distinct time), as in flexible_shaft.c.
 *
 * Sweep: omega_i = omega_start + i * omega_step up to omega_stop; the first
 * point starts at y0 = (-2, -0.5), each further point from the final state
 * of the previous one (continuation); Q = I at every point.
 *
 * Output (stdout, after the timed sweep): CSV
 *   omega,lambda_1,lambda_2,A_x,seconds
 * with the exponents in Gram-Schmidt column order, then one "# y_end=x,v"
 * line per point (its final state), "# variant=..." and "# total_seconds=...".
 *
 * Build: gcc -O3 -std=c99 -Wall -Wextra -o one_stage one_stage.c -lm
 */
#define _POSIX_C_SOURCE 199309L /* clock_gettime under -std=c99 */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define TWO_PI 6.283185307179586476925286766559
#define NS 6 /* augmented state: 2 state variables + 4 tangent entries */

/* Physical parameters (command-line adjustable). */
typedef struct {
    double zeta, B0, B1, Theta, eta, k_a;
} Params;

/* Per-omega constants of the right-hand side (no divisions in the hot loop);
 * kw = k(tau)/omega^2 and fw = forcing/omega^2 come per stage. */
typedef struct {
    double c1;  /* 2 zeta / omega */
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

/* The two time-dependent coefficients at tau, divided by omega^2. Both
 * variants go through this one function, which keeps them bit-identical. */
static void time_coefs(double tau, const Params *p, double inv_w2,
                       double *kw, double *fw)
{
    *kw = mesh_k(tau, p->k_a) * inv_w2;
    *fw = (p->B0 + p->B1 * cos(tau + p->Theta)) * inv_w2;
}

/* Right-hand side of the augmented system: ds = (f(y), J(y) Q).
 * s[0..1] = (x, v), s[2..5] = Q column-major (column c at s[2 + 2c]). */
static inline void rhs(const double *restrict s, double kw, double fw,
                       const Coef *restrict c, double *restrict ds)
{
    const double x = s[0], v = s[1];

    /* Backlash and its slope; at x = -eta both branches give g = 0. */
#ifdef BACKLASH_SELECT
    /* Profiling variant (bench/speed/profile.py): the branch-free selects CasADi generates for g and
     * g', (c ? a : 0) + (d ? b : 0), instead of the branches below. */
    const double g = ((x >= 0.0) ? x : 0.0) + ((x <= -c->eta) ? x + c->eta : 0.0);
    const double gp = ((x >= 0.0) ? 1.0 : 0.0) + ((x <= -c->eta) ? 1.0 : 0.0);
#else
    double g, gp;
    if (x >= 0.0) {
        g = x;
        gp = 1.0;
    } else if (x <= -c->eta) {
        g = x + c->eta;
        gp = 1.0;
    } else {
        g = 0.0;
        gp = 0.0;
    }
#endif

    ds[0] = v;
    ds[1] = -c->c1 * v + fw - kw * g;

    /* J Q with J = [[0, 1], [-kw gp, -c1]], written out. */
    const double j10 = -kw * gp;
    ds[2] = s[3];
    ds[3] = j10 * s[2] - c->c1 * s[3];
    ds[4] = s[5];
    ds[5] = j10 * s[4] - c->c1 * s[5];
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

/* Modified Gram-Schmidt on the column-major 2x2 Q; lognorm[j] = log |q_j|
 * after removing the component along q_0 (for j = 1). */
static void mgs(double *Q, double lognorm[2])
{
    double n0 = sqrt(Q[0] * Q[0] + Q[1] * Q[1]);
    Q[0] /= n0;
    Q[1] /= n0;
    lognorm[0] = log(n0);

    double r = Q[0] * Q[2] + Q[1] * Q[3];
    Q[2] -= r * Q[0];
    Q[3] -= r * Q[1];
    double n1 = sqrt(Q[2] * Q[2] + Q[3] * Q[3]);
    Q[2] /= n1;
    Q[3] /= n1;
    lognorm[1] = log(n1);
}

typedef struct {
    double omega;
    double lambda[2];
    double amp;
    double seconds;
    double y_end[2]; /* final state (the next point's start) */
} Result;

/* One omega point: integrates P periods from state y (updated in place, for
 * continuation) and fills res. kw_tab/fw_tab are scratch of size 2N+1. */
static void run_point(double omega, const Params *p, int N, int P, int D,
                      int use_table, double *kw_tab, double *fw_tab,
                      double y[2], Result *res)
{
    const double T = TWO_PI, h = T / N, hh = 0.5 * h;
    const double inv_w2 = 1.0 / (omega * omega);
    const Coef c = {.c1 = 2.0 * p->zeta / omega, .eta = p->eta};

    if (use_table)
        for (int j = 0; j <= 2 * N; j++)
            time_coefs(j * hh, p, inv_w2, &kw_tab[j], &fw_tab[j]);

    double s[NS] = {y[0], y[1], 1.0, 0.0, 0.0, 1.0}; /* Q = identity */
    double sumlog[2] = {0.0, 0.0};
    double xmin = INFINITY, xmax = -INFINITY;

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
                if (s[0] < xmin) xmin = s[0];
                if (s[0] > xmax) xmax = s[0];
            }
        }

        double lognorm[2];
        mgs(s + 2, lognorm);
        if (measured) {
            sumlog[0] += lognorm[0];
            sumlog[1] += lognorm[1];
        }
    }

    y[0] = res->y_end[0] = s[0];
    y[1] = res->y_end[1] = s[1];
    res->omega = omega;
    for (int j = 0; j < 2; j++) res->lambda[j] = sumlog[j] / ((P - D) * T);
    res->amp = 0.5 * (xmax - xmin);
}

static void usage(const char *prog)
{
    fprintf(stderr,
            "usage: %s [--table|--direct] [--steps N] [--periods P] [--discard D]\n"
            "          [--omega-start a] [--omega-stop b] [--omega-step c]\n"
            "          [--y0 x,v]\n"
            "          [--zeta v] [--B0 v] [--B1 v] [--Theta v] [--eta v] [--k_a v]\n",
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
                .k_a = 0.2};
    int use_table = 1, N = 200, P = 400, D = 100;
    double w_start = 0.1, w_stop = 2.0, w_step = 0.01;
    double y[2] = {-2.0, -0.5};

    /* Name -> field table for the physical parameters. */
    struct { const char *flag; double *field; } pflags[] = {
        {"--zeta", &p.zeta}, {"--B0", &p.B0}, {"--B1", &p.B1},
        {"--Theta", &p.Theta}, {"--eta", &p.eta}, {"--k_a", &p.k_a},
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
            for (int k = 0; k < 2; k++) {
                y[k] = strtod(q, &end);
                if (end == q || (k < 1 && *end != ',') || (k == 1 && *end != '\0')) {
                    fprintf(stderr, "bad --y0 '%s' (want x,v)\n", val);
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

    printf("omega,lambda_1,lambda_2,A_x,seconds\n");
    for (int i = 0; i < npts; i++)
        printf("%.17g,%.17g,%.17g,%.17g,%.17g\n", res[i].omega,
               res[i].lambda[0], res[i].lambda[1], res[i].amp, res[i].seconds);
    for (int i = 0; i < npts; i++)
        printf("# y_end=%.17g,%.17g\n", res[i].y_end[0], res[i].y_end[1]);
    printf("# variant=%s steps=%d periods=%d discard=%d points=%d\n",
           use_table ? "table" : "direct", N, P, D, npts);
    printf("# total_seconds=%.17g\n", total);

    free(res);
    free(kw_tab);
    free(fw_tab);
    return 0;
}
