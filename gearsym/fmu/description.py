"""``modelDescription.xml`` (FMI 2.0) of an FMU, and ``sources/buildDescription.xml``: written from its
:class:`~.variables.Layout`, byte for byte the same for the same model (no date, attributes in a fixed order)."""
from __future__ import annotations

from xml.sax.saxutils import quoteattr

from ..version import __version__
from .frame import BASE_UNITS, Unit
from .variables import Layout, Variable

#: the log categories the wrapper uses
LOG_CATEGORIES = (("logStatusError", "errors: a value the engine does not take, a call not allowed now"),)


def model_description(lay: Layout, guid: str, sources: tuple[str, ...], experiment: tuple[float, float, float]) -> str:
    """The model description; ``sources``: the C files to compile (in ``sources/``); ``experiment``: the default
    experiment (start, stop, step)."""
    system = lay.system
    title = system.title or system.name
    files = "".join(f'      <File name={quoteattr(name)}/>\n' for name in sources)
    common = ('needsExecutionTool="false" canBeInstantiatedOnlyOncePerProcess="false" '
              'canNotUseMemoryManagementFunctions="false" canGetAndSetFMUstate="false" '
              'canSerializeFMUstate="false" providesDirectionalDerivative="false"')
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           f'<fmiModelDescription fmiVersion="2.0" modelName={quoteattr(system.name)} guid={quoteattr(guid)}',
           f'  description={quoteattr(_description(lay, title))}',
           f'  generationTool={quoteattr(f"gearsym {__version__}")} variableNamingConvention="structured"',
           f'  numberOfEventIndicators="{len(lay.indicators)}">',
           f'  <ModelExchange modelIdentifier={quoteattr(system.name)} {common} '
           'completedIntegratorStepNotNeeded="true">',
           f'    <SourceFiles>\n{files}    </SourceFiles>',
           '  </ModelExchange>',
           f'  <CoSimulation modelIdentifier={quoteattr(system.name)} {common} '
           'canHandleVariableCommunicationStepSize="true" canInterpolateInputs="false" maxOutputDerivativeOrder="0" '
           'canRunAsynchronuously="false">',
           f'    <SourceFiles>\n{files}    </SourceFiles>',
           '  </CoSimulation>']
    units = _units(lay)
    if units:
        out.append("  <UnitDefinitions>")
        out += [_unit(u) for u in units]
        out.append("  </UnitDefinitions>")
    out.append("  <LogCategories>")
    out += [f'    <Category name={quoteattr(n)} description={quoteattr(d)}/>' for n, d in LOG_CATEGORIES]
    out.append("  </LogCategories>")
    start, stop, step = experiment
    out.append(f'  <DefaultExperiment startTime="{start!r}" stopTime="{stop!r}" stepSize="{step!r}"/>')
    out.append("  <ModelVariables>")
    for i, v in enumerate(lay.variables, 1):
        out.append(_variable(i, v))
    out.append("  </ModelVariables>")
    out.append("  <ModelStructure>")
    outputs = [lay.index(v.name) for v in lay.outputs]
    derivatives = [lay.index(v.name) for v in lay.of_role("derivative")]
    initial = sorted([lay.index(v.name) for v in lay.outputs if v.initial != "exact"] + derivatives)
    for tag, indexes in (("Outputs", outputs), ("Derivatives", derivatives), ("InitialUnknowns", initial)):
        if indexes:
            out.append(f"    <{tag}>")
            out += [f'      <Unknown index="{i}"/>' for i in indexes]
            out.append(f"    </{tag}>")
    out.append("  </ModelStructure>")
    out.append("</fmiModelDescription>")
    return "\n".join(out) + "\n"


def build_description(identifier: str, sources: tuple[str, ...]) -> str:
    """``sources/buildDescription.xml`` (the FMI 3.0 form, which FMI 2.0.4 and FMPy read for an FMI 2.0 FMU)."""
    files = "".join(f'      <SourceFile name={quoteattr(name)}/>\n' for name in sources)
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            '<fmiBuildDescription fmiVersion="3.0">\n'
            f'  <BuildConfiguration modelIdentifier={quoteattr(identifier)}>\n'
            f'    <SourceFileSet language="C99">\n{files}'
            '      <IncludeDirectory name="."/>\n'
            '    </SourceFileSet>\n'
            '    <Library name="m" description="the C math library (libm on Unix)"/>\n'
            '  </BuildConfiguration>\n'
            '</fmiBuildDescription>\n')


def _description(lay: Layout, title: str) -> str:
    frame = lay.frame
    if frame.physical:
        return (f"{title}: gearsym's engine in SI units (time in s, coordinates in m, rates in m/s, forces in N); "
                f"time unit {frame.time_unit!r} s, length unit {frame.length_unit!r} m")
    return f"{title}: gearsym's nondimensional engine (time {lay.system.time.name})"


def _units(lay: Layout) -> list[Unit]:
    found: dict[str, Unit] = {}
    for v in lay.variables:
        if v.unit is not None:
            known = found.setdefault(v.unit.name, v.unit)
            if known != v.unit:  # two units of one name: merge their display units
                found[v.unit.name] = Unit(known.name, known.base, tuple(dict(known.displays + v.unit.displays).items()))
    return [found[name] for name in sorted(found)]


def _unit(u: Unit) -> str:
    exponents = dict(u.base)
    base = " ".join(f'{b}="{exponents[b]}"' for b in BASE_UNITS if exponents.get(b))
    displays = "".join(f'\n      <DisplayUnit name={quoteattr(name)} factor="{factor!r}"/>'
                       for name, factor in sorted(u.displays))
    return f'    <Unit name={quoteattr(u.name)}>\n      <BaseUnit {base}/>{displays}\n    </Unit>'


def _variable(index: int, v: Variable) -> str:
    attributes = [f"name={quoteattr(v.name)}", f'valueReference="{v.reference}"']
    if v.description:
        attributes.append(f"description={quoteattr(v.description)}")
    attributes += [f'causality="{v.causality}"', f'variability="{v.variability}"']
    if v.initial:
        attributes.append(f'initial="{v.initial}"')
    inner = []
    if v.start is not None:
        inner.append(f'start="{v.start!r}"' if v.type == "Real" else f'start="{int(v.start)}"')
    if v.unit is not None:
        inner.append(f"unit={quoteattr(v.unit.name)}")
        if v.display:
            inner.append(f"displayUnit={quoteattr(v.display)}")
    if v.derivative is not None:
        inner.append(f'derivative="{v.derivative}"')
    if v.minimum is not None:
        inner.append(f'min="{v.minimum!r}"' if v.type == "Real" else f'min="{int(v.minimum)}"')
    return (f"    <!-- {index} -->\n    <ScalarVariable {' '.join(attributes)}>\n"
            f"      <{v.type}{''.join(' ' + a for a in inner)}/>\n    </ScalarVariable>")

