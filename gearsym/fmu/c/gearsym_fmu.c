/* gearsym: a model's generated C as an FMI 2.0 FMU, model exchange and co-simulation.

   The same file for every model; "gearsym_model.h" (written by gearsym/fmu/wrapper.py) holds one model's
   sizes and tables and includes the engine's C of the model (generated/<model>/<model>.c, unchanged), whose
   static step functions this file calls:

   - model exchange: the derivatives are the engine's right-hand side rhs(tau, y, p); the event indicators are
     each mesh's deflection x and -(x + eta), where the backlash g(x, eta) changes slope;
   - co-simulation: doStep runs RK4 steps of the engine's own kind (gs_state_span: the step whose crossings of
     the backlash are located and split, as in every gearsym run), as many as keep each within the engine's
     step (a period over GS_STEPS_PER_PERIOD) and at least `substeps`, whatever the communication step the
     importer asks: its accuracy is gearsym's, not the importer's. The tables of time are taken at the steps'
     times (gearsym_fmu_table) and the step length in the constants' last entry. A motion that leaves the bound
     a gearsym run calls diverged (GS_BOUND times the start's scale, on the meshes' deflections) or becomes
     non-finite ends the simulation with fmi2Error and a logged message, as the command line stops there.

   The FMU's variables are in its own units (SI for a model with physical values): a state is
   scale x the engine's, where scale is L for a length, L d(tau)/dt for a rate (L the length unit); time
   maps to the forcing phase as tau = tau_ref + rate (time - t_ref), rate = omega / T (1 for a nondimensional
   model), kept continuous when a parameter changes the rate during a run. The engine's parameters are made
   from the FMU's: engine[j] = base[j] x prod (P[i] / reference) ** exponent over the terms of j. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "fmi2Functions.h"
#include "gearsym_model.h"

typedef int (*gs_function)(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem);
typedef int (*gs_sizes)(casadi_int* sz_arg, casadi_int* sz_res, casadi_int* sz_iw, casadi_int* sz_w);

enum { GS_INSTANTIATED, GS_INITIALIZING, GS_RUNNING, GS_EVENT, GS_TERMINATED, GS_FAILED };

typedef struct {
  fmi2CallbackLogger logger;
  fmi2CallbackAllocateMemory allocate;
  fmi2CallbackFreeMemory release;
  fmi2ComponentEnvironment environment;
  char name[128];
  fmi2Type type;
  int mode;
  fmi2Boolean logging;
  double time;
  double x[GS_NX_A];       /* the states, in the FMU's units */
  double P[GS_NQ_A];       /* the FMU's Real parameters */
  int substeps;
  double p[GS_NP_A];       /* the engine's parameters, made from P */
  double c[GS_NC];         /* the engine's constants; the last is the RK4 step */
  double rate;             /* d tau / d time */
  double longest;          /* the engine's step: the longest RK4 step a co-simulation takes (tau) */
  double bound;            /* a bounded state beyond this (engine units) has diverged */
  double t_ref, tau_ref;   /* tau = tau_ref + rate (time - t_ref) */
  int stale;               /* p, c and rate must be made again from P */
  int side[GS_NZ_A];       /* model exchange: each indicator's side (1: >= 0) since the last event */
  int contact[GS_NK_A];    /* model exchange: each contact state, held between events */
  double* table;           /* co-simulation: the tables of time of one communication step */
  long table_size;
  const casadi_real** arg;
  casadi_real** res;
  casadi_int* iw;
  casadi_real* w;
} Instance;

/* ------------------------------------------------------------------ messages */

static void gs_log(Instance* m, fmi2Status status, const char* category, const char* format, ...) {
  char text[1024];
  va_list args;
  if (!m || !m->logger) return;
  if (status == fmi2OK && !m->logging) return;
  va_start(args, format);
  vsnprintf(text, sizeof text, format, args);
  va_end(args);
  m->logger(m->environment, m->name, status, category, "%s", text);
}

static fmi2Status gs_error(Instance* m, const char* format, const char* what) {
  gs_log(m, fmi2Error, "logStatusError", format, what);
  return fmi2Error;
}

static int gs_in(Instance* m, const char* function, int modes) {
  if (!m) return 0;
  if (modes & (1 << m->mode)) return 1;
  gs_log(m, fmi2Error, "logStatusError", "%s is not allowed now (the FMU is %s)", function,
         m->mode == GS_INSTANTIATED ? "instantiated" : m->mode == GS_INITIALIZING ? "initializing"
         : m->mode == GS_RUNNING ? "running" : m->mode == GS_EVENT ? "in event mode"
         : m->mode == GS_TERMINATED ? "terminated" : "failed");
  return 0;
}

#define GS_MODES(a) (1 << (a))
#define GS_ANY (GS_MODES(GS_INSTANTIATED) | GS_MODES(GS_INITIALIZING) | GS_MODES(GS_RUNNING) \
                | GS_MODES(GS_EVENT) | GS_MODES(GS_TERMINATED) | GS_MODES(GS_FAILED))
#define GS_LIVE (GS_MODES(GS_INSTANTIATED) | GS_MODES(GS_INITIALIZING) | GS_MODES(GS_RUNNING) | GS_MODES(GS_EVENT))

/* ------------------------------------------------------------------ the engine's functions */

static int gs_call(Instance* m, gs_function f, const casadi_real* in0, const casadi_real* in1, const casadi_real* in2,
                   casadi_real* out0, casadi_real* out1) {
  m->arg[0] = in0; m->arg[1] = in1; m->arg[2] = in2;
  m->res[0] = out0; m->res[1] = out1;
  return f(m->arg, m->res, m->iw, m->w, 0);
}

/* the engine's parameters, constants and phase rate from the FMU's parameters (a one-line error if a value is
   not one the engine takes) */
static fmi2Status gs_engine(Instance* m) {
  int j, k;
  double period;
  if (!m->stale) return fmi2OK;
  for (j = 0; j < GS_NP; ++j) m->p[j] = gs_engine_base[j];
  for (k = 0; k < GS_NTERMS; ++k) {
    double ratio = m->P[gs_term_parameter[k]] / gs_term_reference[k];
    m->p[gs_term_engine[k]] *= gs_term_exponent[k] == 1 ? ratio : pow(ratio, gs_term_exponent[k]);
  }
  for (j = 0; j < GS_NP; ++j) {
    double v = m->p[j];
    int rule = gs_engine_rule[j], bad;
    if (!isfinite(v)) return gs_error(m, "the parameter values give the engine's %s no finite value",
                                      gs_engine_names[j]);
    bad = (rule == 1 && v < 0) || (rule == 2 && !(v > 0))
          || (rule == 3 && !(v >= gs_engine_low[j] && v < gs_engine_high[j]))
          || (rule == 4 && !(v == floor(v) && v >= gs_engine_low[j] && v <= gs_engine_high[j]));
    if (bad) {
      gs_log(m, fmi2Error, "logStatusError", "the parameter values make the engine's %s %g, but it %s",
             gs_engine_names[j], v, gs_engine_must[j]);
      return fmi2Error;
    }
  }
  if (gs_call(m, constants, m->p, 0, 0, m->c, &period)) return gs_error(m, "%s: constants failed", m->name);
  m->longest = period / GS_STEPS_PER_PERIOD;
  m->rate = GS_OMEGA >= 0 ? m->p[GS_OMEGA] / GS_TIME_UNIT : 1.0;
  m->stale = 0;
  return fmi2OK;
}

static double gs_tau(const Instance* m) { return m->tau_ref + m->rate * (m->time - m->t_ref); }

/* a state's unit in the FMU: its value there is scale x the engine's */
static double gs_scale(const Instance* m, int i) {
  return gs_state_scale[i] * (gs_state_kind[i] == 1 ? GS_LENGTH_UNIT : gs_state_kind[i] == 2 ? GS_LENGTH_UNIT * m->rate
                               : 1.0);  /* (scale: 1, or 1/radius for a shaft's twist in rad) */
}

static void gs_engine_state(const Instance* m, double* y) {
  int i;
  for (i = 0; i < GS_NX; ++i) y[i] = m->x[i] / gs_scale(m, i);
}

/* the first state that is not finite, or (bounded states) beyond the bound, in the engine's units; -1 if none */
static int gs_escaped(const Instance* m, const double* y) {
  int i;
  for (i = 0; i < GS_NX; ++i)
    if (!isfinite(y[i]) || (gs_state_bounded[i] && fabs(y[i]) > m->bound)) return i;
  return -1;
}

/* the run's bound from its start (as gearsym's: GS_BOUND times the larger of 1 and the start's largest value);
   a start that is not finite is named */
static fmi2Status gs_start_bound(Instance* m) {
  double y[GS_NX_A], scale = 1.0;
  int i;
  gs_engine_state(m, y);
  for (i = 0; i < GS_NX; ++i) {
    if (!isfinite(m->x[i])) {
      gs_log(m, fmi2Error, "logStatusError", "the start value of %s is %g: every state needs a finite start "
             "value", gs_state_names[i], m->x[i]);
      return fmi2Error;
    }
    if (fabs(y[i]) > scale) scale = fabs(y[i]);
  }
  m->bound = GS_BOUND * scale;
  return fmi2OK;
}

static int gs_contact_of(double deflection, double backlash) {
  return deflection >= 0 ? 1 : deflection <= -backlash ? -1 : 0;
}

/* ------------------------------------------------------------------ getting values */

static fmi2Status gs_real(Instance* m, fmi2ValueReference vr, fmi2Real* value) {
  double y[GS_NX_A], out[GS_NOUT_A], dy[GS_NX_A], tau;
  if (vr == GS_VR_TIME) { *value = m->time; return fmi2OK; }
  if (vr >= GS_VR_STATES && vr < GS_VR_STATES + GS_NX) { *value = m->x[vr - GS_VR_STATES]; return fmi2OK; }
  if (vr >= GS_VR_PARAMETERS && vr < GS_VR_PARAMETERS + GS_NQ) {
    *value = m->P[vr - GS_VR_PARAMETERS];
    return fmi2OK;
  }
  if (vr >= GS_NREAL) return gs_error(m, "%s: no Real variable has this value reference", m->name);
  if (gs_engine(m) != fmi2OK) return fmi2Error;
  gs_engine_state(m, y);
  tau = gs_tau(m);
  if (vr < GS_VR_PARAMETERS) {  /* a derivative: scale x rate x f */
    int i = (int) (vr - GS_VR_DERIVATIVES);
    if (gs_call(m, rhs, &tau, y, m->p, dy, 0)) return gs_error(m, "%s: rhs failed", m->name);
    *value = gs_scale(m, i) * m->rate * dy[i];
    return fmi2OK;
  }
  if (vr == GS_VR_TAU) { *value = tau; return fmi2OK; }
  if (gs_call(m, gearsym_fmu_outputs, &tau, y, m->p, out, 0)) return gs_error(m, "%s: outputs failed", m->name);
  {
    int k = (int) (vr - GS_VR_OUTPUTS);
    if (k < 2 * GS_NM) {
      int mesh = k / 2;
      if (k % 2 == 0) { *value = GS_LENGTH_UNIT * out[mesh]; return fmi2OK; }
      *value = gs_mesh_force_unit[mesh] * out[GS_NM + mesh];  /* (from the mesh's own stiffness) */
      if (gs_mesh_damping[mesh] >= 0)  /* (a physical model: its damping in N s/m times the rate in m/s) */
        *value += m->P[gs_mesh_damping[mesh]] * GS_LENGTH_UNIT * m->rate * out[2 * GS_NM + mesh];
      return fmi2OK;
    }
    *value = GS_LENGTH_UNIT * gs_shaft_scale[k - 2 * GS_NM] * out[4 * GS_NM + (k - 2 * GS_NM)];  /* rad */
  }
  return fmi2OK;
}

/* each contact state, from the state (co-simulation, and at the start) */
static fmi2Status gs_contacts_now(Instance* m, int* contact) {
  double y[GS_NX_A], out[GS_NOUT_A], tau;
  int k;
  if (GS_NK == 0) return fmi2OK;
  if (gs_engine(m) != fmi2OK) return fmi2Error;
  gs_engine_state(m, y);
  tau = gs_tau(m);
  if (gs_call(m, gearsym_fmu_outputs, &tau, y, m->p, out, 0)) return gs_error(m, "%s: outputs failed", m->name);
  for (k = 0; k < GS_NK; ++k) contact[k] = gs_contact_of(out[gs_contact_mesh[k]], out[3 * GS_NM + gs_contact_mesh[k]]);
  return fmi2OK;
}

/* model exchange: the indicators' sides, each flipped where it is zero (the importer stopped there because it
   crossed), and the contact states they give: mesh k's indicators are 2k (x) and 2k + 1 (-(x + eta)) */
static fmi2Status gs_update_sides(Instance* m, int first) {
  double y[GS_NX_A], z[GS_NZ_A], tau;
  int k;
  if (GS_NZ == 0) return fmi2OK;
  if (gs_engine(m) != fmi2OK) return fmi2Error;
  gs_engine_state(m, y);
  tau = gs_tau(m);
  if (gs_call(m, gearsym_fmu_indicators, &tau, y, m->p, z, 0)) return gs_error(m, "%s: indicators failed", m->name);
  for (k = 0; k < GS_NZ; ++k) m->side[k] = z[k] > 0 ? 1 : z[k] < 0 ? 0 : first ? 1 : 1 - m->side[k];
  for (k = 0; k < GS_NK; ++k) m->contact[k] = m->side[2 * k] ? 1 : m->side[2 * k + 1] ? -1 : 0;
  return fmi2OK;
}

/* ------------------------------------------------------------------ instances */

static void gs_start(Instance* m) {
  int i;
  for (i = 0; i < GS_NX; ++i) m->x[i] = gs_state_start[i];
  for (i = 0; i < GS_NQ; ++i) m->P[i] = gs_parameter_start[i];
  m->substeps = GS_SUBSTEPS;
  m->time = 0; m->t_ref = 0; m->tau_ref = 0;
  m->stale = 1;
  m->mode = GS_INSTANTIATED;
}

static void* gs_allocate(Instance* m, size_t n, size_t size) {
  return m->allocate(n ? n : 1, size);
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions* functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
  Instance* m;
  gs_sizes sizes[] = {rhs_work, constants_work, gearsym_fmu_table_work, gearsym_fmu_indicators_work,
                      gearsym_fmu_outputs_work};
  casadi_int most[4] = {3, 2, 0, 0};
  unsigned i, j;
  (void) fmuResourceLocation; (void) visible;
  if (!functions || !functions->allocateMemory || !functions->freeMemory) return NULL;
  m = (Instance*) functions->allocateMemory(1, sizeof(Instance));
  if (!m) return NULL;
  m->logger = functions->logger;
  m->allocate = functions->allocateMemory;
  m->release = functions->freeMemory;
  m->environment = functions->componentEnvironment;
  snprintf(m->name, sizeof m->name, "%s", instanceName ? instanceName : GS_IDENTIFIER);
  m->type = fmuType;
  m->logging = loggingOn;
  if (!fmuGUID || strcmp(fmuGUID, GS_GUID) != 0) {
    gs_log(m, fmi2Error, "logStatusError", "the GUID %s is not this FMU's (%s): the model description and the "
           "binary come from different exports", fmuGUID ? fmuGUID : "(none)", GS_GUID);
    functions->freeMemory(m);
    return NULL;
  }
  for (i = 0; i < sizeof sizes / sizeof sizes[0]; ++i) {
    casadi_int got[4];
    sizes[i](&got[0], &got[1], &got[2], &got[3]);
    for (j = 0; j < 4; ++j) if (got[j] > most[j]) most[j] = got[j];
  }
  m->arg = (const casadi_real**) gs_allocate(m, (size_t) most[0], sizeof(casadi_real*));
  m->res = (casadi_real**) gs_allocate(m, (size_t) most[1], sizeof(casadi_real*));
  m->iw = (casadi_int*) gs_allocate(m, (size_t) most[2], sizeof(casadi_int));
  m->w = (casadi_real*) gs_allocate(m, (size_t) most[3], sizeof(casadi_real));
  if (!m->arg || !m->res || !m->iw || !m->w) {
    gs_log(m, fmi2Error, "logStatusError", "%s", "out of memory");
    fmi2FreeInstance(m);
    return NULL;
  }
  gs_start(m);
  return m;
}

void fmi2FreeInstance(fmi2Component c) {
  Instance* m = (Instance*) c;
  if (!m) return;
  if (m->table) m->release(m->table);
  if (m->arg) m->release((void*) m->arg);
  if (m->res) m->release(m->res);
  if (m->iw) m->release(m->iw);
  if (m->w) m->release(m->w);
  m->release(m);
}

const char* fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char* fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
  Instance* m = (Instance*) c;
  (void) nCategories; (void) categories;
  if (!m) return fmi2Error;
  m->logging = loggingOn;
  return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
  Instance* m = (Instance*) c;
  (void) toleranceDefined; (void) tolerance; (void) stopTimeDefined; (void) stopTime;
  if (!gs_in(m, "fmi2SetupExperiment", GS_MODES(GS_INSTANTIATED))) return fmi2Error;
  m->time = startTime;
  return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
  Instance* m = (Instance*) c;
  if (!gs_in(m, "fmi2EnterInitializationMode", GS_MODES(GS_INSTANTIATED))) return fmi2Error;
  m->mode = GS_INITIALIZING;
  return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
  Instance* m = (Instance*) c;
  if (!gs_in(m, "fmi2ExitInitializationMode", GS_MODES(GS_INITIALIZING))) return fmi2Error;
  if (gs_engine(m) != fmi2OK) { m->mode = GS_FAILED; return fmi2Error; }
  if (gs_start_bound(m) != fmi2OK) { m->mode = GS_FAILED; return fmi2Error; }
  if (gs_update_sides(m, 1) != fmi2OK) { m->mode = GS_FAILED; return fmi2Error; }
  m->mode = m->type == fmi2ModelExchange ? GS_EVENT : GS_RUNNING;
  return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c) {
  Instance* m = (Instance*) c;
  if (!gs_in(m, "fmi2Terminate", GS_MODES(GS_RUNNING) | GS_MODES(GS_EVENT))) return fmi2Error;
  m->mode = GS_TERMINATED;
  return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
  Instance* m = (Instance*) c;
  if (!gs_in(m, "fmi2Reset", GS_ANY)) return fmi2Error;
  gs_start(m);
  return fmi2OK;
}

/* ------------------------------------------------------------------ values */

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
  Instance* m = (Instance*) c;
  size_t i;
  if (!gs_in(m, "fmi2GetReal", GS_ANY)) return fmi2Error;
  for (i = 0; i < nvr; ++i)
    if (gs_real(m, vr[i], &value[i]) != fmi2OK) return fmi2Error;
  return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
  Instance* m = (Instance*) c;
  int now[GS_NK_A];
  size_t i;
  if (!gs_in(m, "fmi2GetInteger", GS_ANY)) return fmi2Error;
  if (nvr == 0) return fmi2OK;
  if (m->type == fmi2CoSimulation || m->mode == GS_INSTANTIATED || m->mode == GS_INITIALIZING) {
    if (gs_contacts_now(m, now) != fmi2OK) return fmi2Error;
  } else {
    memcpy(now, m->contact, sizeof now);
  }
  for (i = 0; i < nvr; ++i) {
    if (vr[i] == GS_IVR_SUBSTEPS) value[i] = m->substeps;
    else if (vr[i] >= GS_IVR_CONTACTS && vr[i] < GS_IVR_CONTACTS + GS_NK) value[i] = now[vr[i] - GS_IVR_CONTACTS];
    else return gs_error(m, "%s: no Integer variable has this value reference", m->name);
  }
  return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
  (void) vr; (void) value;
  return nvr ? gs_error((Instance*) c, "%s has no Boolean variables", GS_IDENTIFIER) : fmi2OK;
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
  (void) vr; (void) value;
  return nvr ? gs_error((Instance*) c, "%s has no String variables", GS_IDENTIFIER) : fmi2OK;
}

/* a parameter changed while running: the phase stays continuous, the engine's values are made again */
static void gs_retune(Instance* m) {
  if (m->mode == GS_RUNNING || m->mode == GS_EVENT) {
    if (gs_engine(m) == fmi2OK) {
      m->tau_ref = gs_tau(m);
      m->t_ref = m->time;
    }
  }
  m->stale = 1;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
  Instance* m = (Instance*) c;
  size_t i;
  int before = m && (m->mode == GS_INSTANTIATED || m->mode == GS_INITIALIZING);
  if (!gs_in(m, "fmi2SetReal", GS_LIVE)) return fmi2Error;
  for (i = 0; i < nvr; ++i) {
    if (vr[i] >= GS_VR_STATES && vr[i] < GS_VR_STATES + GS_NX && before) {
      m->x[vr[i] - GS_VR_STATES] = value[i];
    } else if (vr[i] >= GS_VR_PARAMETERS && vr[i] < GS_VR_PARAMETERS + GS_NQ) {
      int k = (int) (vr[i] - GS_VR_PARAMETERS);
      if (value[i] == m->P[k]) continue;
      if (!gs_parameter_tunable[k])
        return gs_error(m, "%s is baked into the engine's values of this FMU: export it again with "
                        "gearsym fmu ... --set to change it", gs_parameter_names[k]);
      if (!isfinite(value[i])) return gs_error(m, "%s must be a finite number", gs_parameter_names[k]);
      if (!before) gs_retune(m);
      m->P[k] = value[i];
      m->stale = 1;
    } else {
      return gs_error(m, "%s: this Real variable cannot be set now", m->name);
    }
  }
  return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
  Instance* m = (Instance*) c;
  size_t i;
  if (!gs_in(m, "fmi2SetInteger", GS_LIVE)) return fmi2Error;
  for (i = 0; i < nvr; ++i) {
    if (vr[i] != GS_IVR_SUBSTEPS) return gs_error(m, "%s: this Integer variable cannot be set", m->name);
    if (value[i] < 1) return gs_error(m, "%s", "substeps must be at least 1");
    m->substeps = value[i];
  }
  return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
  (void) vr; (void) value;
  return nvr ? gs_error((Instance*) c, "%s has no Boolean variables", GS_IDENTIFIER) : fmi2OK;
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
  (void) vr; (void) value;
  return nvr ? gs_error((Instance*) c, "%s has no String variables", GS_IDENTIFIER) : fmi2OK;
}

/* ------------------------------------------------------------------ what this FMU does not offer */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* s) {
  (void) s;
  return gs_error((Instance*) c, "%s cannot get its state (canGetAndSetFMUstate is false)", GS_IDENTIFIER);
}
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
  (void) s;
  return gs_error((Instance*) c, "%s cannot set its state (canGetAndSetFMUstate is false)", GS_IDENTIFIER);
}
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* s) {
  (void) s;
  return gs_error((Instance*) c, "%s has no FMU states", GS_IDENTIFIER);
}
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t* size) {
  (void) s; (void) size;
  return gs_error((Instance*) c, "%s cannot serialize its state", GS_IDENTIFIER);
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t size) {
  (void) s; (void) b; (void) size;
  return gs_error((Instance*) c, "%s cannot serialize its state", GS_IDENTIFIER);
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t size, fmi2FMUstate* s) {
  (void) s; (void) b; (void) size;
  return gs_error((Instance*) c, "%s cannot serialize its state", GS_IDENTIFIER);
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz, const fmi2Real dv[], fmi2Real dz[]) {
  (void) u; (void) nu; (void) z; (void) nz; (void) dv; (void) dz;
  return gs_error((Instance*) c, "%s provides no directional derivatives", GS_IDENTIFIER);
}

/* ------------------------------------------------------------------ model exchange */

fmi2Status fmi2EnterEventMode(fmi2Component c) {
  Instance* m = (Instance*) c;
  if (!gs_in(m, "fmi2EnterEventMode", GS_MODES(GS_RUNNING) | GS_MODES(GS_EVENT))) return fmi2Error;
  m->mode = GS_EVENT;
  return fmi2OK;
}

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo* info) {
  Instance* m = (Instance*) c;
  if (!gs_in(m, "fmi2NewDiscreteStates", GS_MODES(GS_EVENT))) return fmi2Error;
  if (gs_update_sides(m, 0) != fmi2OK) return fmi2Error;
  info->newDiscreteStatesNeeded = fmi2False;
  info->terminateSimulation = fmi2False;
  info->nominalsOfContinuousStatesChanged = fmi2False;
  info->valuesOfContinuousStatesChanged = fmi2False;
  info->nextEventTimeDefined = fmi2False;
  info->nextEventTime = 0;
  return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
  Instance* m = (Instance*) c;
  if (!gs_in(m, "fmi2EnterContinuousTimeMode", GS_MODES(GS_EVENT))) return fmi2Error;
  m->mode = GS_RUNNING;
  return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean* enterEventMode, fmi2Boolean* terminateSimulation) {
  Instance* m = (Instance*) c;
  (void) noSetFMUStatePriorToCurrentPoint;
  double y[GS_NX_A];
  int i;
  if (!gs_in(m, "fmi2CompletedIntegratorStep", GS_MODES(GS_RUNNING))) return fmi2Error;
  *enterEventMode = fmi2False;
  *terminateSimulation = fmi2False;
  gs_engine_state(m, y);
  i = gs_escaped(m, y);
  if (i >= 0) {
    *terminateSimulation = fmi2True;
    m->mode = GS_FAILED;
    gs_log(m, fmi2Error, "logStatusError", "%s: the motion diverged at time %g: %s reached %g, beyond the bound "
           "%g a gearsym run calls diverged (no bounded motion at these parameter values)", m->name, m->time,
           gs_state_names[i], m->x[i], m->bound * gs_scale(m, i));
    return fmi2Error;
  }
  return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
  Instance* m = (Instance*) c;
  if (!gs_in(m, "fmi2SetTime", GS_MODES(GS_INSTANTIATED) | GS_MODES(GS_INITIALIZING) | GS_MODES(GS_RUNNING)
             | GS_MODES(GS_EVENT))) return fmi2Error;
  m->time = time;
  return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
  Instance* m = (Instance*) c;
  if (!gs_in(m, "fmi2SetContinuousStates", GS_LIVE)) return fmi2Error;
  if (nx != GS_NX) return gs_error(m, "%s: wrong number of states", m->name);
  memcpy(m->x, x, nx * sizeof(double));
  return fmi2OK;
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx) {
  Instance* m = (Instance*) c;
  double y[GS_NX_A], dy[GS_NX_A], tau;
  size_t i;
  if (!gs_in(m, "fmi2GetDerivatives", GS_ANY)) return fmi2Error;
  if (nx != GS_NX) return gs_error(m, "%s: wrong number of states", m->name);
  if (gs_engine(m) != fmi2OK) return fmi2Error;
  gs_engine_state(m, y);
  tau = gs_tau(m);
  if (gs_call(m, rhs, &tau, y, m->p, dy, 0)) return gs_error(m, "%s: rhs failed", m->name);
  for (i = 0; i < nx; ++i) derivatives[i] = gs_scale(m, (int) i) * m->rate * dy[i];
  return fmi2OK;
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real z[], size_t ni) {
  Instance* m = (Instance*) c;
  double y[GS_NX_A], tau;
  if (!gs_in(m, "fmi2GetEventIndicators", GS_ANY)) return fmi2Error;
  if (ni != GS_NZ) return gs_error(m, "%s: wrong number of event indicators", m->name);
  if (ni == 0) return fmi2OK;
  if (gs_engine(m) != fmi2OK) return fmi2Error;
  gs_engine_state(m, y);
  tau = gs_tau(m);
  if (gs_call(m, gearsym_fmu_indicators, &tau, y, m->p, z, 0)) return gs_error(m, "%s: indicators failed", m->name);
  return fmi2OK;
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
  Instance* m = (Instance*) c;
  if (!gs_in(m, "fmi2GetContinuousStates", GS_ANY)) return fmi2Error;
  if (nx != GS_NX) return gs_error(m, "%s: wrong number of states", m->name);
  memcpy(x, m->x, nx * sizeof(double));
  return fmi2OK;
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx) {
  Instance* m = (Instance*) c;
  size_t i;
  if (!gs_in(m, "fmi2GetNominalsOfContinuousStates", GS_ANY)) return fmi2Error;
  if (nx != GS_NX) return gs_error(m, "%s: wrong number of states", m->name);
  if (gs_engine(m) != fmi2OK) return fmi2Error;
  for (i = 0; i < nx; ++i) x_nominal[i] = gs_scale(m, (int) i);
  return fmi2OK;
}

/* ------------------------------------------------------------------ co-simulation */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
  (void) vr; (void) order; (void) value;
  return nvr ? gs_error((Instance*) c, "%s has no inputs", GS_IDENTIFIER) : fmi2OK;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
  (void) vr; (void) order; (void) value;
  return nvr ? gs_error((Instance*) c, "%s gives no output derivatives", GS_IDENTIFIER) : fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentCommunicationPoint) {
  Instance* m = (Instance*) c;
  double y[GS_NX_A], lo[GS_NOBS_A], hi[GS_NOBS_A], tau0, step, half;
  long k, n, rows = 3 * GS_NT, i;
  (void) noSetFMUStatePriorToCurrentCommunicationPoint;
  if (!gs_in(m, "fmi2DoStep", GS_MODES(GS_RUNNING))) return fmi2Error;
  if (!(communicationStepSize >= 0)) return gs_error(m, "%s: the communication step must not be negative", m->name);
  m->time = currentCommunicationPoint;
  if (communicationStepSize == 0) return fmi2OK;
  if (gs_engine(m) != fmi2OK) return fmi2Error;
  n = m->substeps;
  {  /* as many steps as keep each within the engine's (a hair over: rounding of the importer's step) */
    double needed = ceil(fabs(m->rate * communicationStepSize) / m->longest * (1.0 - 1e-9));
    if (!(needed < 1e9)) return gs_error(m, "%s: the communication step is more than a billion of the engine's "
                                         "steps; take shorter communication steps", m->name);
    if (needed > n) n = (long) needed;
  }
  if (GS_NT && m->table_size < rows * n) {
    if (m->table) m->release(m->table);
    m->table = (double*) m->allocate((size_t) (rows * n), sizeof(double));
    m->table_size = m->table ? rows * n : 0;
    if (!m->table) return gs_error(m, "%s: out of memory", m->name);
  }
  tau0 = gs_tau(m);
  step = m->rate * communicationStepSize / (double) n;
  half = step / 2;
  for (k = 0; GS_NT && k < n; ++k) {  /* the tables at each step's start, middle and end, as the engine's */
    for (i = 0; i < 3; ++i) {
      double t = tau0 + (double) (2 * k + i) * half;
      if (gs_call(m, gearsym_fmu_table, &t, m->p, 0, m->table + rows * k + GS_NT * i, 0))
        return gs_error(m, "%s: table failed", m->name);
    }
  }
  gs_engine_state(m, y);
  for (i = 0; i < GS_NOBS; ++i) lo[i] = hi[i] = y[gs_observed[i]];
  m->c[GS_NC - 1] = step;
  gs_state_span(y, lo, hi, GS_NT ? m->table : gs_zeros, m->c, (casadi_int) n);
  i = gs_escaped(m, y);
  if (i >= 0) {
    m->mode = GS_FAILED;
    if (isfinite(y[i]))
      gs_log(m, fmi2Error, "logStatusError", "%s: the motion diverged in the step from %g: %s reached %g, beyond "
             "the bound %g a gearsym run calls diverged (no bounded motion at these parameter values)", m->name,
             currentCommunicationPoint, gs_state_names[i], gs_scale(m, (int) i) * y[i],
             gs_scale(m, (int) i) * m->bound);
    else
      gs_log(m, fmi2Error, "logStatusError", "%s: the motion diverged in the step from %g: %s became non-finite "
             "(no bounded motion at these parameter values)", m->name, currentCommunicationPoint, gs_state_names[i]);
    return fmi2Error;
  }
  m->time = currentCommunicationPoint + communicationStepSize;
  for (i = 0; i < GS_NX; ++i) m->x[i] = gs_scale(m, (int) i) * y[i];
  return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c) {
  return gs_error((Instance*) c, "%s: doStep never runs asynchronously, there is nothing to cancel", GS_IDENTIFIER);
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status* value) {
  (void) c; (void) s; (void) value;
  return fmi2Discard;  /* (doStep never runs asynchronously: there is no pending status) */
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real* value) {
  Instance* m = (Instance*) c;
  if (m && s == fmi2LastSuccessfulTime) { *value = m->time; return fmi2OK; }
  return fmi2Discard;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer* value) {
  (void) c; (void) s; (void) value;
  return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean* value) {
  (void) c;
  if (s == fmi2Terminated) { *value = fmi2False; return fmi2OK; }
  return fmi2Discard;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String* value) {
  (void) c; (void) s; (void) value;
  return fmi2Discard;
}
