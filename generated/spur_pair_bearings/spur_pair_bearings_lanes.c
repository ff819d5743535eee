/* gearsym: the lanes of spur_pair_bearings, L trajectories at once (see gearsym/codegen/lanes.py), around the step pieces of spur_pair_bearings.c */

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
#include "spur_pair_bearings.c"

/* tangent_state on every lane: the model's piece on lane l's entries */
static GEARSYM_INLINE void gsl_tangent_state(const casadi_real* restrict A0, const casadi_real* restrict A1, const casadi_real* restrict A2, casadi_real* restrict R0, casadi_real* restrict R1, casadi_real* restrict R2) {
  casadi_int l;
  GS_LANES gs_tangent_state_strided(A0 + l, A1 + l, A2 + l, R0 + l, R1 + l, R2 + l, GS_L);
}

/* tangent_vector on every lane: the model's piece on lane l's entries */
static GEARSYM_INLINE void gsl_tangent_vector(const casadi_real* restrict A0, const casadi_real* restrict A1, const casadi_real* restrict A2, casadi_real* restrict R0) {
  casadi_int l;
  GS_LANES gs_tangent_vector_strided(A0 + l, A1 + l, A2 + l, R0 + l, GS_L);
}

/* state_try on every lane: the model's piece on lane l's entries */
static GEARSYM_INLINE void gsl_state_try(const casadi_real* restrict A0, const casadi_real* restrict A1, const casadi_real* restrict A2, casadi_real* restrict R0, casadi_real* restrict R1) {
  casadi_int l;
  GS_LANES gs_state_try_strided(A0 + l, A1 + l, A2 + l, R0 + l, R1 + l, GS_L);
}

/* state_keep on every lane: the model's piece on lane l's entries */
static GEARSYM_INLINE void gsl_state_keep(const casadi_real* restrict A0, const casadi_real* restrict A1, const casadi_real* restrict A2, const casadi_real* restrict A3, const casadi_real* restrict A4, const casadi_real* restrict A5, casadi_real* restrict R0, casadi_real* restrict R1, casadi_real* restrict R2) {
  casadi_int l;
  GS_LANES gs_state_keep_strided(A0 + l, A1 + l, A2 + l, A3 + l, A4 + l, A5 + l, R0 + l, R1 + l, R2 + l, GS_L);
}

/* constants on every lane: the model's piece on lane l's entries */
static GEARSYM_INLINE void gsl_constants(const casadi_real* restrict A0, casadi_real* restrict R0, casadi_real* restrict R1) {
  casadi_int l;
  GS_LANES gs_constants_strided(A0 + l, R0 + l, R1 + l, GS_L);
}

/* one block of tangent steps of every lane */
static GEARSYM_INLINE void gsl_tangent_step(const casadi_real* restrict y, const casadi_real* restrict Q, const casadi_real* restrict lo, const casadi_real* restrict hi, const casadi_real* restrict T, const casadi_real* restrict c, casadi_real* restrict y1, casadi_real* restrict Q1, casadi_real* restrict lo1, casadi_real* restrict hi1) {
  casadi_real yt[6*GS_L], flag[GS_L], J[21*GS_L]; casadi_int j, l, i; int any, finite;
  gsl_tangent_state(y, T, c, yt, flag, J);
  for (j = 0; j < 6; ++j) gsl_tangent_vector(Q + GS_L*j, J, c, Q1 + GS_L*j);
  gsl_state_keep(y, lo, hi, yt, T, c, y1, lo1, hi1);
  any = 0;
  GS_LANES any |= flag[l] != 0;
  if (GEARSYM_UNLIKELY(any)) for (l = 0; l < GS_L; ++l) if (flag[l] != 0) {  /* this lane crosses */
    casadi_real ys[6], los[3], his[3], yts[6], cs[15], Ts[6], y1s[6], lo1s[3], hi1s[3];
    casadi_real Qc[36], Qc1[36];
    for (i = 0; i < 6; ++i) ys[i] = y[GS_L*i + l];
    for (i = 0; i < 3; ++i) los[i] = lo[GS_L*i + l];
    for (i = 0; i < 3; ++i) his[i] = hi[GS_L*i + l];
    for (i = 0; i < 6; ++i) yts[i] = yt[GS_L*i + l];
    for (i = 0; i < 15; ++i) cs[i] = c[GS_L*i + l];
    for (i = 0; i < 6; ++i) Ts[i] = T[GS_L*i + l];
    for (i = 0, finite = 1; i < 6; ++i) finite &= ys[i] - ys[i] == 0;
    if (!finite) continue;  /* a lane that diverged keeps the try (every flag of it would split) */
    for (i = 0; i < 36; ++i) Qc[(i % 6)*6 + i / 6] = Q[GS_L*i + l];
    gs_tangent_split(ys, Qc, los, his, yts, Qc, Ts, cs, y1s, Qc1, lo1s, hi1s);
    for (i = 0; i < 36; ++i) Q1[GS_L*i + l] = Qc1[(i % 6)*6 + i / 6];
    for (i = 0; i < 6; ++i) y1[GS_L*i + l] = y1s[i];
    for (i = 0; i < 3; ++i) lo1[GS_L*i + l] = lo1s[i];
    for (i = 0; i < 3; ++i) hi1[GS_L*i + l] = hi1s[i];
  }
}

/* blocks of tangent steps of every lane from (y, Q, lo, hi), in place, a -> b -> a */
static GEARSYM_INLINE void gsl_tangent_span(casadi_real* restrict y, casadi_real* restrict Q, casadi_real* restrict lo, casadi_real* restrict hi, const casadi_real* restrict T, const casadi_real* restrict c, casadi_int blocks) {
  casadi_real ya[6*GS_L], yb[6*GS_L]; casadi_real Qa[36*GS_L], Qb[36*GS_L]; casadi_real loa[3*GS_L], lob[3*GS_L]; casadi_real hia[3*GS_L], hib[3*GS_L];
  casadi_int k;
  gs_copy(y, 6*GS_L, ya); gs_copy(Q, 36*GS_L, Qa); gs_copy(lo, 3*GS_L, loa); gs_copy(hi, 3*GS_L, hia);
  for (k = 0; k < blocks; k += 2) {
    gsl_tangent_step(ya, Qa, loa, hia, T + 6*GS_L*(k), c, yb, Qb, lob, hib);
    if (k + 1 == blocks) { gs_copy(yb, 6*GS_L, y); gs_copy(Qb, 36*GS_L, Q); gs_copy(lob, 3*GS_L, lo); gs_copy(hib, 3*GS_L, hi); return; }
    gsl_tangent_step(yb, Qb, lob, hib, T + 6*GS_L*(k + 1), c, ya, Qa, loa, hia);
  }
  gs_copy(ya, 6*GS_L, y); gs_copy(Qa, 36*GS_L, Q); gs_copy(loa, 3*GS_L, lo); gs_copy(hia, 3*GS_L, hi);
}

/* one block of state steps of every lane */
static GEARSYM_INLINE void gsl_state_step(const casadi_real* restrict y, const casadi_real* restrict lo, const casadi_real* restrict hi, const casadi_real* restrict T, const casadi_real* restrict c, casadi_real* restrict y1, casadi_real* restrict lo1, casadi_real* restrict hi1) {
  casadi_real yt[6*GS_L], flag[GS_L]; casadi_int l, i; int any, finite;
  gsl_state_try(y, T, c, yt, flag);
  gsl_state_keep(y, lo, hi, yt, T, c, y1, lo1, hi1);
  any = 0;
  GS_LANES any |= flag[l] != 0;
  if (GEARSYM_UNLIKELY(any)) for (l = 0; l < GS_L; ++l) if (flag[l] != 0) {  /* this lane crosses */
    casadi_real ys[6], los[3], his[3], yts[6], cs[15], Ts[6], y1s[6], lo1s[3], hi1s[3];
    for (i = 0; i < 6; ++i) ys[i] = y[GS_L*i + l];
    for (i = 0; i < 3; ++i) los[i] = lo[GS_L*i + l];
    for (i = 0; i < 3; ++i) his[i] = hi[GS_L*i + l];
    for (i = 0; i < 6; ++i) yts[i] = yt[GS_L*i + l];
    for (i = 0; i < 15; ++i) cs[i] = c[GS_L*i + l];
    for (i = 0; i < 6; ++i) Ts[i] = T[GS_L*i + l];
    for (i = 0, finite = 1; i < 6; ++i) finite &= ys[i] - ys[i] == 0;
    if (!finite) continue;  /* a lane that diverged keeps the try (every flag of it would split) */
    gs_state_split(ys, los, his, yts, Ts, cs, y1s, lo1s, hi1s);
    for (i = 0; i < 6; ++i) y1[GS_L*i + l] = y1s[i];
    for (i = 0; i < 3; ++i) lo1[GS_L*i + l] = lo1s[i];
    for (i = 0; i < 3; ++i) hi1[GS_L*i + l] = hi1s[i];
  }
}

/* blocks of state steps of every lane from (y, lo, hi), in place, a -> b -> a */
static GEARSYM_INLINE void gsl_state_span(casadi_real* restrict y, casadi_real* restrict lo, casadi_real* restrict hi, const casadi_real* restrict T, const casadi_real* restrict c, casadi_int blocks) {
  casadi_real ya[6*GS_L], yb[6*GS_L]; casadi_real loa[3*GS_L], lob[3*GS_L]; casadi_real hia[3*GS_L], hib[3*GS_L];
  casadi_int k;
  gs_copy(y, 6*GS_L, ya); gs_copy(lo, 3*GS_L, loa); gs_copy(hi, 3*GS_L, hia);
  for (k = 0; k < blocks; k += 2) {
    gsl_state_step(ya, loa, hia, T + 6*GS_L*(k), c, yb, lob, hib);
    if (k + 1 == blocks) { gs_copy(yb, 6*GS_L, y); gs_copy(lob, 3*GS_L, lo); gs_copy(hib, 3*GS_L, hi); return; }
    gsl_state_step(yb, lob, hib, T + 6*GS_L*(k + 1), c, ya, loa, hia);
  }
  gs_copy(ya, 6*GS_L, y); gs_copy(loa, 3*GS_L, lo); gs_copy(hia, 3*GS_L, hi);
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
    for (l = 0; l < GS_L; ++l) { lo[GS_L*0 + l] = y[GS_L*0 + l]; hi[GS_L*0 + l] = y[GS_L*0 + l]; lo[GS_L*1 + l] = y[GS_L*2 + l]; hi[GS_L*1 + l] = y[GS_L*2 + l]; lo[GS_L*2 + l] = y[GS_L*4 + l]; hi[GS_L*2 + l] = y[GS_L*4 + l]; }
    gsl_state_span(y, lo, hi, T, c, 200);
    if (strobe) gs_copy(y, 6*GS_L, strobe + 6*GS_L*p);
    if (low) gs_copy(lo, 3*GS_L, low + 3*GS_L*p);
    if (high) gs_copy(hi, 3*GS_L, high + 3*GS_L*p);
  }
  return 0;
}

/* the same with n tangent vectors (Q: (r, j), row r of vector j, at GS_L*(r*n + j) + l; in place),
   re-orthonormalised every period per lane (the scalar loops' Gram-Schmidt); each period's log
   stretches written where given (periods x n x GS_L) */
CASADI_SYMBOL_EXPORT GS_TARGETS int gearsym_lanes_lyapunov(const casadi_real* restrict T, const casadi_real* restrict c, casadi_int periods, casadi_real* restrict y, casadi_real* restrict Q, casadi_real* strobe, casadi_real* logs, casadi_real* low, casadi_real* high) {
  casadi_real lo[3*GS_L], hi[3*GS_L], Qc[36], Qn[36], lg[6], acc[6*GS_L];
  casadi_int p, l, i, g;
  for (p = 0; p < periods; ++p) {
    for (l = 0; l < GS_L; ++l) { lo[GS_L*0 + l] = y[GS_L*0 + l]; hi[GS_L*0 + l] = y[GS_L*0 + l]; lo[GS_L*1 + l] = y[GS_L*2 + l]; hi[GS_L*1 + l] = y[GS_L*2 + l]; lo[GS_L*2 + l] = y[GS_L*4 + l]; hi[GS_L*2 + l] = y[GS_L*4 + l]; }
    for (i = 0; i < 6*GS_L; ++i) acc[i] = 0;
    for (g = 0; g < 8; ++g) {
      gsl_tangent_span(y, Q, lo, hi, T + 6*GS_L*(25*g), c, 25);
      for (l = 0; l < GS_L; ++l) {  /* Gram-Schmidt of each lane's vectors, as columns */
        for (i = 0; i < 36; ++i) Qc[(i % 6)*6 + i / 6] = Q[GS_L*i + l];
        gs_gram_schmidt(Qc, Qn, lg);
        for (i = 0; i < 36; ++i) Q[GS_L*i + l] = Qn[(i % 6)*6 + i / 6];
        for (i = 0; i < 6; ++i) acc[GS_L*i + l] += lg[i];
      }
    }
    if (logs) for (i = 0; i < 6*GS_L; ++i) logs[6*GS_L*p + i] = acc[i];
    if (strobe) gs_copy(y, 6*GS_L, strobe + 6*GS_L*p);
    if (low) gs_copy(lo, 3*GS_L, low + 3*GS_L*p);
    if (high) gs_copy(hi, 3*GS_L, high + 3*GS_L*p);
  }
  return 0;
}

/* `periods` periods of `count` parameter points, state and tangent, GS_L lanes at a time: point i has the parameters
   p + 16*i, its tables at pool + 1200*tix[i] (rows x steps of one period, column-major, as the
   scalar loops read them: points whose tables are the same share one), its constants computed here from
   its parameters; the state after them is written over y + n*i, the tangent map to M + n*n*i (row r of column j at
   r*n + j: d y_r / d y0_j). work: room for GS_L tables. */
CASADI_SYMBOL_EXPORT GS_TARGETS int gearsym_lanes_monodromies(const casadi_real* restrict pool, const long long* restrict tix, const casadi_real* restrict p, long long count, long long periods, casadi_real* restrict y, casadi_real* restrict M, casadi_real* restrict work) {
  casadi_real pl[16*GS_L], cl[15*GS_L], per[GS_L], yl[6*GS_L], Ql[36*GS_L], lo[3*GS_L], hi[3*GS_L];
  long long last[GS_L], b, k, g, q, total = count; casadi_int l, i;
  for (l = 0; l < GS_L; ++l) last[l] = -1;
  for (b = 0; b < total; b += GS_L) {
    for (l = 0; l < GS_L; ++l) {  /* (lanes past the end repeat the last one: finite numbers) */
      g = b + l < total ? b + l : total - 1;
      q = g;
      for (i = 0; i < 16; ++i) pl[GS_L*i + l] = p[16*q + i];
      for (i = 0; i < 6; ++i) yl[GS_L*i + l] = y[6*g + i];
      for (i = 0; i < 36; ++i) Ql[GS_L*i + l] = i % 7 == 0;
      if (tix[q] != last[l]) {  /* a table of another point: copied into this lane */
        const casadi_real* t = pool + 1200*tix[q];
        for (i = 0; i < 1200; ++i) work[GS_L*i + l] = t[i];
        last[l] = tix[q];
      }
    }
    gsl_constants(pl, cl, per);
    for (k = 0; k < periods; ++k) {
      for (l = 0; l < GS_L; ++l) { lo[GS_L*0 + l] = yl[GS_L*0 + l]; hi[GS_L*0 + l] = yl[GS_L*0 + l]; lo[GS_L*1 + l] = yl[GS_L*2 + l]; hi[GS_L*1 + l] = yl[GS_L*2 + l]; lo[GS_L*2 + l] = yl[GS_L*4 + l]; hi[GS_L*2 + l] = yl[GS_L*4 + l]; }
      gsl_tangent_span(yl, Ql, lo, hi, work, cl, 200);
    }
    for (l = 0; l < GS_L && b + l < total; ++l) {
      for (i = 0; i < 6; ++i) y[6*(b + l) + i] = yl[GS_L*i + l];
      for (i = 0; i < 36; ++i) M[36*(b + l) + i] = Ql[GS_L*i + l];
    }
  }
  return 0;
}

/* `periods` periods of `count` parameter points, the state alone, GS_L lanes at a time: point i has the parameters
   p + 16*i, its tables at pool + 1200*tix[i] (rows x steps of one period, column-major, as the
   scalar loops read them: points whose tables are the same share one), its constants computed here from
   its parameters; with columns = 0 it starts at y + n*i and its state after them is written there; with columns = c,
   lane g runs point g / c from the column g % c of the identity and writes its state to y + n*g. work: room for GS_L tables. */
CASADI_SYMBOL_EXPORT GS_TARGETS int gearsym_lanes_states(const casadi_real* restrict pool, const long long* restrict tix, const casadi_real* restrict p, long long count, long long periods, long long columns, casadi_real* restrict y, casadi_real* restrict work) {
  casadi_real pl[16*GS_L], cl[15*GS_L], per[GS_L], yl[6*GS_L], lo[3*GS_L], hi[3*GS_L];
  long long last[GS_L], b, k, g, q, total = (columns ? count * columns : count); casadi_int l, i;
  for (l = 0; l < GS_L; ++l) last[l] = -1;
  for (b = 0; b < total; b += GS_L) {
    for (l = 0; l < GS_L; ++l) {  /* (lanes past the end repeat the last one: finite numbers) */
      g = b + l < total ? b + l : total - 1;
      q = (columns ? g / columns : g);
      for (i = 0; i < 16; ++i) pl[GS_L*i + l] = p[16*q + i];
      for (i = 0; i < 6; ++i) yl[GS_L*i + l] = columns ? (i == g % columns) : y[6*g + i];
      if (tix[q] != last[l]) {  /* a table of another point: copied into this lane */
        const casadi_real* t = pool + 1200*tix[q];
        for (i = 0; i < 1200; ++i) work[GS_L*i + l] = t[i];
        last[l] = tix[q];
      }
    }
    gsl_constants(pl, cl, per);
    for (k = 0; k < periods; ++k) {
      for (l = 0; l < GS_L; ++l) { lo[GS_L*0 + l] = yl[GS_L*0 + l]; hi[GS_L*0 + l] = yl[GS_L*0 + l]; lo[GS_L*1 + l] = yl[GS_L*2 + l]; hi[GS_L*1 + l] = yl[GS_L*2 + l]; lo[GS_L*2 + l] = yl[GS_L*4 + l]; hi[GS_L*2 + l] = yl[GS_L*4 + l]; }
      gsl_state_span(yl, lo, hi, work, cl, 200);
    }
    for (l = 0; l < GS_L && b + l < total; ++l) {
      for (i = 0; i < 6; ++i) y[6*(b + l) + i] = yl[GS_L*i + l];
    }
  }
  return 0;
}

#ifdef __cplusplus
} /* extern "C" */
#endif
