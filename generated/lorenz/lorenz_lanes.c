/* gearsym: the lanes of lorenz, L trajectories at once (see gearsym/codegen/lanes.py), around the step pieces of lorenz.c */

/* gearsym: the lanes, L trajectories at once (see gearsym/codegen/lanes.py) */
#if defined(__GNUC__) && !defined(__clang__)
/* a comparison's 0/1 times a value is a select: gcc may speculate it (if-convert the lane loop) only if floating
   point does not trap (the values are the same; clang assumes so by default) */
#pragma GCC optimize ("no-trapping-math")
#endif
/* GS_L trajectories per call: one AVX-512 register of doubles, two AVX ones (the second register's operations
   fill the latency of the first's: the RK4 stages are a chain; measured 1.8x over one register on AVX2) */
#if defined(__AVX512F__)
#define GS_L 8
#define GS_TARGETS
#elif defined(__AVX__)
#define GS_L 8
#define GS_TARGETS
#elif defined(__x86_64__) && defined(__GNUC__) && defined(__linux__) && defined(__has_attribute)
#if __has_attribute(target_clones)
/* a portable build: AVX2 chosen at load time where the CPU has it (no FMA: the baseline's bits) */
#define GS_L 8
#define GS_TARGETS __attribute__((target_clones("avx2", "default")))
#endif
#endif
#if !defined(GS_L) && defined(__SSE2__)
#define GS_L 4
#define GS_TARGETS
#endif
#ifndef GS_L
#define GS_L 1
#define GS_TARGETS
#endif
/* the loop over the lanes, left to the vectoriser (no dependence between lanes) */
#if defined(__GNUC__) && !defined(__clang__)
#define GS_LANES _Pragma("GCC ivdep") for (l = 0; l < GS_L; ++l)
#else
#define GS_LANES for (l = 0; l < GS_L; ++l)
#endif

#define GEARSYM_STEP_PIECES_ONLY
#include "lorenz.c"

/* tangent_state on every lane: the model's piece on lane l's entries */
static GEARSYM_INLINE void gsl_tangent_state(const casadi_real* restrict A0, const casadi_real* restrict A1, const casadi_real* restrict A2, const casadi_real* restrict A3, const casadi_real* restrict A4, casadi_real* restrict R0, casadi_real* restrict R1, casadi_real* restrict R2, casadi_real* restrict R3) {
  casadi_int l;
  GS_LANES gs_tangent_state_strided(A0 + l, A1 + l, A2 + l, A3 + l, A4 + l, R0 + l, R1 + l, R2 + l, R3 + l, GS_L);
}

/* tangent_vector on every lane: the model's piece on lane l's entries */
static GEARSYM_INLINE void gsl_tangent_vector(const casadi_real* restrict A0, const casadi_real* restrict A1, const casadi_real* restrict A2, casadi_real* restrict R0) {
  casadi_int l;
  GS_LANES gs_tangent_vector_strided(A0 + l, A1 + l, A2 + l, R0 + l, GS_L);
}

/* state_block on every lane: the model's piece on lane l's entries */
static GEARSYM_INLINE void gsl_state_block(const casadi_real* restrict A0, const casadi_real* restrict A1, const casadi_real* restrict A2, const casadi_real* restrict A3, const casadi_real* restrict A4, casadi_real* restrict R0, casadi_real* restrict R1, casadi_real* restrict R2) {
  casadi_int l;
  GS_LANES gs_state_block_strided(A0 + l, A1 + l, A2 + l, A3 + l, A4 + l, R0 + l, R1 + l, R2 + l, GS_L);
}

/* one block of tangent steps of every lane */
static GEARSYM_INLINE void gsl_tangent_step(const casadi_real* restrict y, const casadi_real* restrict Q, const casadi_real* restrict lo, const casadi_real* restrict hi, const casadi_real* restrict T, const casadi_real* restrict c, casadi_real* restrict y1, casadi_real* restrict Q1, casadi_real* restrict lo1, casadi_real* restrict hi1) {
  casadi_real J[19*GS_L]; casadi_int j;
  gsl_tangent_state(y, lo, hi, T, c, y1, lo1, hi1, J);
  for (j = 0; j < 3; ++j) gsl_tangent_vector(Q + GS_L*j, J, c, Q1 + GS_L*j);
}

/* blocks of tangent steps of every lane from (y, Q, lo, hi), in place, a -> b -> a */
static GEARSYM_INLINE void gsl_tangent_span(casadi_real* restrict y, casadi_real* restrict Q, casadi_real* restrict lo, casadi_real* restrict hi, const casadi_real* restrict T, const casadi_real* restrict c, casadi_int blocks) {
  casadi_real ya[3*GS_L], yb[3*GS_L]; casadi_real Qa[9*GS_L], Qb[9*GS_L]; casadi_real loa[3*GS_L], lob[3*GS_L]; casadi_real hia[3*GS_L], hib[3*GS_L];
  casadi_int k;
  gs_copy(y, 3*GS_L, ya); gs_copy(Q, 9*GS_L, Qa); gs_copy(lo, 3*GS_L, loa); gs_copy(hi, 3*GS_L, hia);
  for (k = 0; k < blocks; k += 2) {
    gsl_tangent_step(ya, Qa, loa, hia, T, c, yb, Qb, lob, hib);
    if (k + 1 == blocks) { gs_copy(yb, 3*GS_L, y); gs_copy(Qb, 9*GS_L, Q); gs_copy(lob, 3*GS_L, lo); gs_copy(hib, 3*GS_L, hi); return; }
    gsl_tangent_step(yb, Qb, lob, hib, T, c, ya, Qa, loa, hia);
  }
  gs_copy(ya, 3*GS_L, y); gs_copy(Qa, 9*GS_L, Q); gs_copy(loa, 3*GS_L, lo); gs_copy(hia, 3*GS_L, hi);
}

/* one block of state steps of every lane */
static GEARSYM_INLINE void gsl_state_step(const casadi_real* restrict y, const casadi_real* restrict lo, const casadi_real* restrict hi, const casadi_real* restrict T, const casadi_real* restrict c, casadi_real* restrict y1, casadi_real* restrict lo1, casadi_real* restrict hi1) {
  gsl_state_block(y, lo, hi, T, c, y1, lo1, hi1);
}

/* blocks of state steps of every lane from (y, lo, hi), in place, a -> b -> a */
static GEARSYM_INLINE void gsl_state_span(casadi_real* restrict y, casadi_real* restrict lo, casadi_real* restrict hi, const casadi_real* restrict T, const casadi_real* restrict c, casadi_int blocks) {
  casadi_real ya[3*GS_L], yb[3*GS_L]; casadi_real loa[3*GS_L], lob[3*GS_L]; casadi_real hia[3*GS_L], hib[3*GS_L];
  casadi_int k;
  gs_copy(y, 3*GS_L, ya); gs_copy(lo, 3*GS_L, loa); gs_copy(hi, 3*GS_L, hia);
  for (k = 0; k < blocks; k += 2) {
    gsl_state_step(ya, loa, hia, T, c, yb, lob, hib);
    if (k + 1 == blocks) { gs_copy(yb, 3*GS_L, y); gs_copy(lob, 3*GS_L, lo); gs_copy(hib, 3*GS_L, hi); return; }
    gsl_state_step(yb, lob, hib, T, c, ya, loa, hia);
  }
  gs_copy(ya, 3*GS_L, y); gs_copy(loa, 3*GS_L, lo); gs_copy(hia, 3*GS_L, hi);
}

/* the lanes of this build */
CASADI_SYMBOL_EXPORT int gearsym_lanes(void) { return GS_L; }

/* `periods` periods of the state of GS_L trajectories from y (n x GS_L, lane fastest; in place), with the
   constants c (nc x GS_L) and the tables of a period T (steps x rows x GS_L: entry j of step k of lane l at
   GS_L*(rows*k + j) + l), one of each per lane; each period's strobe, low and high written where given
   (periods x n x GS_L, periods x observed x GS_L) */
CASADI_SYMBOL_EXPORT GS_TARGETS int gearsym_lanes_orbit(const casadi_real* restrict T, const casadi_real* restrict c, casadi_int periods, casadi_real* restrict y, casadi_real* strobe, casadi_real* low, casadi_real* high) {
  casadi_real lo[3*GS_L], hi[3*GS_L]; casadi_int p, l;
  for (p = 0; p < periods; ++p) {
    for (l = 0; l < GS_L; ++l) { lo[GS_L*0 + l] = y[GS_L*0 + l]; hi[GS_L*0 + l] = y[GS_L*0 + l]; lo[GS_L*1 + l] = y[GS_L*1 + l]; hi[GS_L*1 + l] = y[GS_L*1 + l]; lo[GS_L*2 + l] = y[GS_L*2 + l]; hi[GS_L*2 + l] = y[GS_L*2 + l]; }
    gsl_state_span(y, lo, hi, T, c, 200);
    if (strobe) gs_copy(y, 3*GS_L, strobe + 3*GS_L*p);
    if (low) gs_copy(lo, 3*GS_L, low + 3*GS_L*p);
    if (high) gs_copy(hi, 3*GS_L, high + 3*GS_L*p);
  }
  return 0;
}

/* the same with n tangent vectors (Q: (r, j), row r of vector j, at GS_L*(r*n + j) + l; in place),
   re-orthonormalised every period per lane (the scalar loops' Gram-Schmidt); each period's log
   stretches written where given (periods x n x GS_L) */
CASADI_SYMBOL_EXPORT GS_TARGETS int gearsym_lanes_lyapunov(const casadi_real* restrict T, const casadi_real* restrict c, casadi_int periods, casadi_real* restrict y, casadi_real* restrict Q, casadi_real* strobe, casadi_real* logs, casadi_real* low, casadi_real* high) {
  casadi_real lo[3*GS_L], hi[3*GS_L], Qc[9], Qn[9], lg[3];
  casadi_int p, l, i;
  for (p = 0; p < periods; ++p) {
    for (l = 0; l < GS_L; ++l) { lo[GS_L*0 + l] = y[GS_L*0 + l]; hi[GS_L*0 + l] = y[GS_L*0 + l]; lo[GS_L*1 + l] = y[GS_L*1 + l]; hi[GS_L*1 + l] = y[GS_L*1 + l]; lo[GS_L*2 + l] = y[GS_L*2 + l]; hi[GS_L*2 + l] = y[GS_L*2 + l]; }
    gsl_tangent_span(y, Q, lo, hi, T, c, 200);
    for (l = 0; l < GS_L; ++l) {  /* Gram-Schmidt of each lane's vectors, as columns */
      for (i = 0; i < 9; ++i) Qc[(i % 3)*3 + i / 3] = Q[GS_L*i + l];
      gs_gram_schmidt(Qc, Qn, lg);
      for (i = 0; i < 9; ++i) Q[GS_L*i + l] = Qn[(i % 3)*3 + i / 3];
      if (logs) for (i = 0; i < 3; ++i) logs[3*GS_L*p + GS_L*i + l] = lg[i];
    }
    if (strobe) gs_copy(y, 3*GS_L, strobe + 3*GS_L*p);
    if (low) gs_copy(lo, 3*GS_L, low + 3*GS_L*p);
    if (high) gs_copy(hi, 3*GS_L, high + 3*GS_L*p);
  }
  return 0;
}

#ifdef __cplusplus
} /* extern "C" */
#endif
