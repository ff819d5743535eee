/*
 * planetary_translational.c -- hand-written C yardstick for gears on bearings (issue 39).
 *
 * Lin & Parker's translational-rotational planetary set written as one would by hand, in the physical
 * coordinates q (n = 3(N+3): x, y, and the rotation of sun, ring, carrier; each planet's radial, tangential
 * and rotation), time in forcing periods scaled to tau = omega_f t (so one period is 2 pi):
 *
 *   q'' = Minv (-(Kb q + Cb q') - sum_m w_m F_m + f0 + f1 cos(tau + Theta) - (G q' - KO q))
 *   F_m = k_m (1 + ka cos(tau + phase_m)) g(w_m . q, eta) + c_m w_m . q'
 *
 * Minv, Kb, Cb (bearings, supports), G, KO (the carrier frame's Coriolis and centripetal terms), the mesh
 * rows w_m and every number come from the file given as argv[1] (written by bench/bearings/__main__.py from
 * the gearsym model's own rows at its values, in the engine's units): the same equations as gearsym's, before
 * the reduction to relative coordinates (the rigid rotation is integrated too, as a hand-writer would).
 *
 * Scheme: classic RK4 on (y, Q), y = (q, q') in R^{2n}, Q' = J Q with the exact Jacobian
 * J = [[0, I], [A, B]], A = -Minv (Kb + sum k g' w w^T - KO), B = -Minv (Cb + sum c w w^T + G), g' in {0, 1};
 * the tangent product uses J's block structure (the top rows copy Q's bottom ones, the bottom rows are
 * A Q_top + B Q_bottom: dense 2n columns). Steps per period and periods from the file; after every period Q is
 * re-orthonormalised (modified Gram-Schmidt) and the logs of the column norms summed.
 *
 * Output: "seconds_per_step <s>" and the exponents per unit tau (largest first).
 * Build: gcc -O3 -std=gnu99 -o planetary_translational planetary_translational.c -lm
 */
#define _POSIX_C_SOURCE 199309L

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI  /* (POSIX, not ISO C: _POSIX_C_SOURCE above hides it in glibc) */
#define M_PI 3.14159265358979323846
#endif
#include <time.h>

static int n, nm, steps, periods;
static double *Minv, *Kb, *Cb, *G, *KO, *W, *kmean, *cmesh, *phase, *f0, *f1;
static double eta, ka, theta;

static double *vec(int k) { double *p = calloc((size_t)k, sizeof(double)); if (!p) exit(3); return p; }

static void read_array(FILE *f, double *a, int k) {
    for (int i = 0; i < k; i++)
        if (fscanf(f, "%lf", &a[i]) != 1) { fprintf(stderr, "bad input\n"); exit(2); }
}

static double g(double x) { return x >= 0 ? x : (x <= -eta ? x + eta : 0.0); }
static double dg(double x) { return (x >= 0 || x <= -eta) ? 1.0 : 0.0; }

/* dy/dtau and the blocks A, B of the Jacobian at (tau, y) */
static void rhs(double tau, const double *y, double *dy, double *A, double *B) {
    const double *q = y, *qd = y + n;
    double *force = dy + n;
    memcpy(dy, qd, sizeof(double) * (size_t)n);
    for (int i = 0; i < n; i++) {
        double s = f0[i] + f1[i] * cos(tau + theta);
        for (int j = 0; j < n; j++)
            s -= Kb[i * n + j] * q[j] + Cb[i * n + j] * qd[j] + G[i * n + j] * qd[j] - KO[i * n + j] * q[j];
        force[i] = s;
    }
    for (int i = 0; i < n * n; i++) { A[i] = -(Kb[i] - KO[i]); B[i] = -(Cb[i] + G[i]); }
    for (int m = 0; m < nm; m++) {
        const double *w = W + (size_t)m * n;
        double d = 0, dd = 0;
        for (int j = 0; j < n; j++) { d += w[j] * q[j]; dd += w[j] * qd[j]; }
        double k = kmean[m] * (1 + ka * cos(tau + phase[m]));
        double F = k * g(d) + cmesh[m] * dd, ks = k * dg(d), c = cmesh[m];
        for (int i = 0; i < n; i++) {
            if (w[i] == 0) continue;
            force[i] -= w[i] * F;
            for (int j = 0; j < n; j++) { A[i * n + j] -= ks * w[i] * w[j]; B[i * n + j] -= c * w[i] * w[j]; }
        }
    }
    for (int i = 0; i < n; i++) {
        force[i] *= Minv[i];
        for (int j = 0; j < n; j++) { A[i * n + j] *= Minv[i]; B[i * n + j] *= Minv[i]; }
    }
}

/* dQ = J Q for Q (2n x 2n, row-major) */
static void tangent(const double *A, const double *B, const double *Q, double *dQ) {
    int N2 = 2 * n;
    memcpy(dQ, Q + (size_t)n * N2, sizeof(double) * (size_t)n * N2);
    for (int i = 0; i < n; i++) {
        double *out = dQ + (size_t)(n + i) * N2;
        for (int c = 0; c < N2; c++) out[c] = 0;
        for (int j = 0; j < n; j++) {
            double a = A[i * n + j], b = B[i * n + j];
            const double *qt = Q + (size_t)j * N2, *qb = Q + (size_t)(n + j) * N2;
            if (a != 0) for (int c = 0; c < N2; c++) out[c] += a * qt[c];
            if (b != 0) for (int c = 0; c < N2; c++) out[c] += b * qb[c];
        }
    }
}

int main(int argc, char **argv) {
    if (argc < 2) { fprintf(stderr, "usage: %s input.txt\n", argv[0]); return 2; }
    FILE *f = fopen(argv[1], "r");
    if (!f) { perror(argv[1]); return 2; }
    if (fscanf(f, "%d %d %d %d %lf %lf %lf", &n, &nm, &steps, &periods, &eta, &ka, &theta) != 7) return 2;
    Minv = vec(n); Kb = vec(n * n); Cb = vec(n * n); G = vec(n * n); KO = vec(n * n); W = vec(nm * n);
    kmean = vec(nm); cmesh = vec(nm); phase = vec(nm); f0 = vec(n); f1 = vec(n);
    double *y = vec(2 * n);
    read_array(f, Minv, n); read_array(f, Kb, n * n); read_array(f, Cb, n * n); read_array(f, G, n * n);
    read_array(f, KO, n * n); read_array(f, W, nm * n); read_array(f, kmean, nm); read_array(f, cmesh, nm);
    read_array(f, phase, nm); read_array(f, f0, n); read_array(f, f1, n); read_array(f, y, 2 * n);
    fclose(f);
    int N2 = 2 * n;
    double *Q = vec(N2 * N2), *k1 = vec(N2), *k2 = vec(N2), *k3 = vec(N2), *k4 = vec(N2), *yt = vec(N2);
    double *K1 = vec(N2 * N2), *K2 = vec(N2 * N2), *K3 = vec(N2 * N2), *K4 = vec(N2 * N2), *Qt = vec(N2 * N2);
    double *A = vec(n * n), *B = vec(n * n), *sums = vec(N2);
    for (int i = 0; i < N2; i++) Q[i * N2 + i] = 1;
    double h = 2 * M_PI / steps;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int p = 0; p < periods; p++) {
        for (int s = 0; s < steps; s++) {
            double tau = s * h;
            rhs(tau, y, k1, A, B); tangent(A, B, Q, K1);
            for (int i = 0; i < N2; i++) yt[i] = y[i] + h / 2 * k1[i];
            for (int i = 0; i < N2 * N2; i++) Qt[i] = Q[i] + h / 2 * K1[i];
            rhs(tau + h / 2, yt, k2, A, B); tangent(A, B, Qt, K2);
            for (int i = 0; i < N2; i++) yt[i] = y[i] + h / 2 * k2[i];
            for (int i = 0; i < N2 * N2; i++) Qt[i] = Q[i] + h / 2 * K2[i];
            rhs(tau + h / 2, yt, k3, A, B); tangent(A, B, Qt, K3);
            for (int i = 0; i < N2; i++) yt[i] = y[i] + h * k3[i];
            for (int i = 0; i < N2 * N2; i++) Qt[i] = Q[i] + h * K3[i];
            rhs(tau + h, yt, k4, A, B); tangent(A, B, Qt, K4);
            for (int i = 0; i < N2; i++) y[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
            for (int i = 0; i < N2 * N2; i++) Q[i] += h / 6 * (K1[i] + 2 * K2[i] + 2 * K3[i] + K4[i]);
        }
        for (int c = 0; c < N2; c++) { /* modified Gram-Schmidt on the columns */
            for (int b = 0; b < c; b++) {
                double d = 0;
                for (int i = 0; i < N2; i++) d += Q[i * N2 + b] * Q[i * N2 + c];
                for (int i = 0; i < N2; i++) Q[i * N2 + c] -= d * Q[i * N2 + b];
            }
            double norm = 0;
            for (int i = 0; i < N2; i++) norm += Q[i * N2 + c] * Q[i * N2 + c];
            norm = sqrt(norm);
            sums[c] += log(norm);
            for (int i = 0; i < N2; i++) Q[i * N2 + c] /= norm;
        }
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    printf("seconds_per_step %.9g\n", seconds / ((double)periods * steps));
    printf("exponents");
    for (int c = 0; c < N2; c++) printf(" %.9g", sums[c] / (periods * 2 * M_PI));
    printf("\n");
    return 0;
}
