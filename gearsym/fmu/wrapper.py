"""The C wrapper of an FMU: gearsym's one wrapper (``c/gearsym_fmu.c``, the same for every model) and the header
that gives it one model (``gearsym_model.h``: sizes, value references, tables, the engine's C included)."""
from __future__ import annotations

from importlib import resources

from ..analysis.divergence import BOUND
from ..options import STEPS_PER_PERIOD
from ..system import FirstOrderSystem
from .functions import INDICATORS, OUTPUTS, TABLE
from .variables import SUBSTEPS, Layout

#: the wrapper's files in the FMU's sources
WRAPPER, HEADER = "gearsym_fmu.c", "gearsym_model.h"


def wrapper_source() -> str:
    """The text of the one wrapper (package data)."""
    return resources.files(__package__).joinpath("c", WRAPPER).read_text()


#: where the GUID goes in the header (it is a hash of the header without it, among others)
GUID_MARK = "@GUID@"


def model_header(lay: Layout, engine_source: str, constants: int, tables: int, guid: str = GUID_MARK,
                 steps_per_period: int = STEPS_PER_PERIOD) -> str:
    """``gearsym_model.h`` of the FMU laid out as ``lay`` around the engine's C file ``engine_source``, whose
    constants function gives ``constants`` values (the step last) and whose tables have ``tables`` rows;
    ``steps_per_period``: the engine's RK4 steps per period of the system (its longest step: a co-simulation takes
    as many substeps as keep each within it, whatever the communication step)."""
    system, frame = lay.system, lay.frame
    n, nq, nm, ns, nk, nz = (len(system.states), len(lay.parameters), len(lay.meshes), len(lay.shafts),
                             len(lay.contacts), len(lay.indicators))
    engine = list(system.parameters)
    terms = [(engine.index(t.engine), i, t.exponent, t.reference)
             for i, p in enumerate(lay.parameters) for t in p.terms]
    observed = system.observed_indices
    meshes = {c.coordinate for c in system.couplings if c.kind == "mesh"}
    bounded = meshes if system.couplings else set(system.state_names)  # (as a run's divergence counts them)
    reals = [v for v in lay.variables if v.type == "Real"]
    first_output = 1 + 2 * n + nq  # (after time, the states, their derivatives and the parameters)
    tau = next((v.reference for v in reals if v.role == "tau"), len(reals))
    sizes = {"NX": n, "NQ": nq, "NP": len(engine), "NZ": nz, "NK": nk, "NM": nm, "NOBS": len(observed),
             "NOUT": 4 * nm + ns, "NTERMS": len(terms)}
    kinds = [{"length": 1, "rate": 2, "angle": 1, "angular_rate": 2}.get(frame.kinds.get(s), 0)
             for s in system.state_names]
    starts = [next(v.start for v in lay.variables if v.name == s) for s in system.state_names]
    damping = [_index(lay, frame.mesh_damping.get(c.name)) for c in lay.meshes]
    lines = [
        f"/* {lay.system.name} as an FMU: written by gearsym (gearsym/fmu/wrapper.py) for {WRAPPER} */",
        "#ifndef GEARSYM_MODEL_H", "#define GEARSYM_MODEL_H", "",
        f"#define GS_IDENTIFIER {_c_string(system.name)}",
        f"#define GS_GUID {_c_string(guid)}",
        *(f"#define GS_{k} {v}\n#define GS_{k}_A {max(1, v)}" for k, v in sizes.items()),
        f"#define GS_NT {tables}",
        f"#define GS_NC {constants}",
        f"#define GS_OMEGA {engine.index(frame.omega) if frame.physical else -1}",
        f"#define GS_TIME_UNIT {frame.time_unit!r}",
        f"#define GS_LENGTH_UNIT {frame.length_unit!r}",
        f"#define GS_SUBSTEPS {SUBSTEPS}",
        f"#define GS_STEPS_PER_PERIOD {int(steps_per_period)}",
        f"#define GS_BOUND {BOUND!r}",
        "/* value references: Real */",
        "#define GS_VR_TIME 0",
        "#define GS_VR_STATES 1",
        f"#define GS_VR_DERIVATIVES {1 + n}",
        f"#define GS_VR_PARAMETERS {1 + 2 * n}",
        f"#define GS_VR_OUTPUTS {first_output}",
        f"#define GS_VR_TAU {tau}",
        f"#define GS_NREAL {len(reals)}",
        "/* value references: Integer */",
        "#define GS_IVR_SUBSTEPS 0",
        "#define GS_IVR_CONTACTS 1",
        "",
        "/* the engine's C of the model, as gearsym generates it: its functions static here, so that the C",
        "   compiler drops the ones the FMU does not call (the Lyapunov and orbit loops) instead of compiling them */",
        "#define CASADI_SYMBOL_EXPORT static",
        f'#include "{engine_source}"',
        "",
        _array("const double", "gs_parameter_start", [p.value for p in lay.parameters]),
        _array("const int", "gs_parameter_tunable", [int(p.tunable) for p in lay.parameters]),
        _array("const char* const", "gs_parameter_names", [_c_string(p.name) for p in lay.parameters], raw=True),
        _array("const double", "gs_engine_base", [lay.engine_base[name] for name in engine]),
        _array("const char* const", "gs_engine_names", [_c_string(name) for name in engine], raw=True),
        _array("const int", "gs_engine_rule", [_rule(system, name)[0] for name in engine]),
        _array("const double", "gs_engine_low", [_rule(system, name)[1] for name in engine]),
        _array("const double", "gs_engine_high", [_rule(system, name)[2] for name in engine]),
        _array("const char* const", "gs_engine_must", [_c_string(_rule(system, name)[3]) for name in engine], raw=True),
        _array("const int", "gs_term_engine", [t[0] for t in terms]),
        _array("const int", "gs_term_parameter", [t[1] for t in terms]),
        _array("const int", "gs_term_exponent", [t[2] for t in terms]),
        _array("const double", "gs_term_reference", [t[3] for t in terms]),
        _array("const double", "gs_state_start", starts),
        _array("const int", "gs_state_kind", kinds),
        _array("const char* const", "gs_state_names", [_c_string(s) for s in system.state_names], raw=True),
        _array("const int", "gs_state_bounded", [int(s in bounded) for s in system.state_names]),
        _array("const double", "gs_state_scale", [frame.scales.get(s, 1.0) for s in system.state_names]),
        _array("const double", "gs_mesh_force_unit",  # N of one unit of each mesh's engine force (its own stiffness)
               [frame.mesh_stiffness.get(c.name, 1.0) * frame.length_unit for c in lay.meshes]),
        _array("const double", "gs_shaft_scale", [frame.scales.get(c.coordinate, 1.0) for c in lay.shafts]),
        _array("const int", "gs_observed", observed),
        _array("const int", "gs_mesh_damping", damping),
        _array("const int", "gs_contact_mesh", [lay.meshes.index(c) for c in lay.contacts]),
        "",
        "/* the FMU's own functions (gearsym_fmu_functions.c) */",
        *(_prototype(name) for name in (TABLE, INDICATORS, OUTPUTS)),
        "", "#endif", "",
    ]
    return "\n".join(lines)


def _index(lay: Layout, parameter: str | None) -> int:
    names = [p.name for p in lay.parameters]
    return names.index(parameter) if parameter in names else -1


def _rule(system: FirstOrderSystem, name: str) -> tuple[int, float, float, str]:
    """What values the engine's parameter ``name`` may take (its constraint), as the wrapper checks them:
    (0 any, 1 not negative, 2 positive, 3 in [low, high), 4 a whole number in [low, high]; low, high; the rule in
    words, for the message)."""
    constraint = system.constraints.get(name)
    if constraint is None:
        return (2, 0.0, 0.0, "must be positive") if name == "omega" else (0, 0.0, 0.0, "")
    if constraint.whole is not None:
        first, last = constraint.whole
        return 4, float(first), float(last), f"must be a whole number from {first} to {last} ({constraint.meaning})"
    if constraint.below is not None:
        return 3, 0.0, float(constraint.below), (f"must be at least 0 and less than {constraint.below:g} "
                                                 f"({constraint.meaning})")
    if constraint.zero_allowed:
        return 1, 0.0, 0.0, f"must not be negative ({constraint.meaning})"
    return 2, 0.0, 0.0, f"must be positive ({constraint.meaning})"


def _c_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _array(kind: str, name: str, values, raw: bool = False) -> str:
    items = [v if raw else (repr(float(v)) if "double" in kind else str(int(v))) for v in values] or ["0"]
    return f"static {kind} {name}[{len(items)}] = {{{', '.join(items)}}};"


def _prototype(name: str) -> str:
    return (f"int {name}(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem);\n"
            f"int {name}_work(casadi_int* sz_arg, casadi_int* sz_res, casadi_int* sz_iw, casadi_int* sz_w);")
