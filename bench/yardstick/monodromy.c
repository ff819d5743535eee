/* The hand-written yardstick of a stability chart (bench/stability): the monodromy matrix of the one-stage gear
   model linearised about its static state,

       x'' + (2 zeta / omega) x' + (k(tau) / omega^2) x = 0,   k(tau) = 1 + k_a cos(tau)

   (Mathieu's equation, damped), over one forcing period by classic RK4 of the tangent matrix at N steps, at
   every point of a grid of omega (columns) and k_a (rows): what a researcher would write by hand. Scalar, one
   point after another, the cosine tabulated once at the 2N + 1 half-step times, the two columns of the
   tangent matrix stepped side by side (the compiler may pack them). Prints the points, the unstable ones
   (max |mu| > 1 + 1e-9), the sum of max |mu| (to compare with gearsym's) and the seconds of the loop alone.

   usage: monodromy OMEGA0 OMEGA1 N_OMEGA KA0 KA1 N_KA ZETA STEPS */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double max_modulus(double a, double b, double c, double d) {
  double half = 0.5 * (a + d), det = a * d - b * c, disc = half * half - det;
  if (disc >= 0) {
    double r = sqrt(disc);
    return fmax(fabs(half + r), fabs(half - r));
  }
  return sqrt(det);  /* a complex pair: |mu|^2 = det */
}

int main(int argc, char** argv) {
  if (argc != 9) {
    fprintf(stderr, "usage: %s OMEGA0 OMEGA1 N_OMEGA KA0 KA1 N_KA ZETA STEPS\n", argv[0]);
    return 2;
  }
  double w0 = atof(argv[1]), w1 = atof(argv[2]), ka0 = atof(argv[4]), ka1 = atof(argv[5]), zeta = atof(argv[7]);
  long nw = atol(argv[3]), nk = atol(argv[6]), N = atol(argv[8]);
  const double pi = 3.14159265358979323846, h = 2 * pi / N;
  double* ct = malloc(sizeof(double) * (2 * N + 1));
  for (long s = 0; s <= 2 * N; ++s) ct[s] = cos(0.5 * h * s);
  long unstable = 0;
  double total = 0;
  struct timespec t0, t1;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t0);
  for (long i = 0; i < nk; ++i) {
    double ka = nk > 1 ? ka0 + (ka1 - ka0) * i / (nk - 1) : ka0;
    for (long j = 0; j < nw; ++j) {
      double w = nw > 1 ? w0 + (w1 - w0) * j / (nw - 1) : w0;
      double a = 1 / (w * w), d = -2 * zeta / w;
      double x[2] = {1, 0}, v[2] = {0, 1};  /* the columns of the tangent matrix */
      for (long k = 0; k < N; ++k) {
        double k0 = (1 + ka * ct[2 * k]) * a, km = (1 + ka * ct[2 * k + 1]) * a, k1 = (1 + ka * ct[2 * k + 2]) * a;
        for (int c = 0; c < 2; ++c) {
          double ax = v[c], av = -k0 * x[c] + d * v[c];
          double x2 = x[c] + 0.5 * h * ax, v2 = v[c] + 0.5 * h * av;
          double bx = v2, bv = -km * x2 + d * v2;
          double x3 = x[c] + 0.5 * h * bx, v3 = v[c] + 0.5 * h * bv;
          double cx = v3, cv = -km * x3 + d * v3;
          double x4 = x[c] + h * cx, v4 = v[c] + h * cv;
          double dx = v4, dv = -k1 * x4 + d * v4;
          x[c] += h / 6 * (ax + 2 * bx + 2 * cx + dx);
          v[c] += h / 6 * (av + 2 * bv + 2 * cv + dv);
        }
      }
      double m = max_modulus(x[0], x[1], v[0], v[1]);
      unstable += m > 1 + 1e-9;
      total += m;
    }
  }
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t1);
  printf("points %ld unstable %ld sum_max_modulus %.12g seconds %.6f\n", nw * nk, unstable, total,
         (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec));
  free(ct);
  return 0;
}
