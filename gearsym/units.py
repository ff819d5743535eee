"""Physical quantities at the edge: read, checked, and turned into SI numbers, so nothing inside sees a unit.

A quantity string is ``NUMBER [UNIT EXPRESSION]`` (``2e8 N/m``, ``3000 rpm``, ``2.1e-3 kg*m^2``, ``50 um``).
The text is checked against that grammar here, with a regular expression, before any of it reaches pint:
the number is read by ``float`` and only the unit expression goes to pint's ``parse_units``, which has its
own tokenizer and evaluator and never calls Python's ``eval``. No quantity string ever reaches SymPy.

What crosses into the model is a :class:`Measure`: the value in SI base units (kg, m, s; angles in
radians), the exponents of mass, length and time it is made of, and the unit it was given in (to show it
back in the user's units). The conversions back (``from_si``) are pint's own factors, applied at the
other edge (``gearsym.physical``). pint and its registry (over a second of CPU) load on first use only: the
grammar, :func:`looks_like_quantity` and :func:`shown` need neither, and a unit text pint has read once (in any
process) is read again from what pint said it means, kept in the user's cache (:class:`UnitMeaning`): the commands
of a model with units import no pint once they have met its units.

Frequencies: pint's ``Hz`` is ``1/s``, so ``3000 rpm`` would convert to 314 Hz (radians per second under
another name). Here ``Hz`` is one revolution (cycle) per second, so rpm, Hz and rad/s convert as a
drivetrain engineer expects: 3000 rpm = 50 Hz = 314.16 rad/s.
"""
from __future__ import annotations

import hashlib
import importlib.util
import math
import re
import warnings
from functools import lru_cache
from pathlib import Path

from .records import record_class
from .errors import GearsymError
from .files.memo import keep, recall_all

#: how long a quantity string may be (a unit expression is a few names, not a program)
MAX_LENGTH = 120
_NUMBER = r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?|[+-]?(?:nan|inf|infinity)"
_NAME = r"[A-Za-zµμΩ°][A-Za-z0-9µμΩ_]*"
_POWER = r"(?:\*\*|\^)\s*-?\d{1,2}"
_UNIT = rf"(?:{_NAME}|\(|1\s*/)(?:{_NAME}|\(|\)|{_POWER}|\*|/|\s)*"
QUANTITY = re.compile(rf"\s*(?P<number>{_NUMBER})\s*(?P<unit>{_UNIT})?\s*", re.IGNORECASE)
#: a power of a power (m**10**10): no unit needs one, and pint would compute it
POWER_OF_POWER = re.compile(rf"{_POWER}\s*(?:\*\*|\^)")
GRAMMAR = ("a quantity is a number and a unit made of unit names, * / ** ^ (whole powers) and parentheses, "
           "e.g. '2e8 N/m', '3000 rpm', '2.1e-3 kg*m^2', '50 um'")
#: the dimensions a drivetrain's values are made of (angles are dimensionless)
BASE = ("[mass]", "[length]", "[time]")
#: spellings people write that pint does not know, and what they mean
#: (min^-1 is how ISO 6336 and drive makers write a shaft speed: revolutions per minute)
ALIASES = {"rev/min": "rpm", "rev/s": "revolution/second", "1/min": "rpm", "min^-1": "rpm", "min**-1": "rpm",
           "rpms": None, "rad/sec": "rad/s"}
#: what gearsym adds to pint's registry (a kept unit's meaning depends on it: see :class:`UnitMeaning`)
DEFINITIONS = ("hertz = revolution / second = Hz",)


def looks_like_quantity(text: str) -> bool:
    """True if ``text`` is a number followed by a unit (``--set kZ='2e8 N/m'`` is a quantity, not a formula)."""
    match = QUANTITY.fullmatch(text) if len(text) <= MAX_LENGTH else None
    return bool(match and (match["unit"] or "").strip())


def shown(q, digits: int = 6) -> str:
    """A quantity as a person reads it: '2e+08 N / m', '3000 rpm' (a pint Quantity, a :class:`Measure` or any
    object with ``magnitude`` and ``units`` that formats as a short unit symbol)."""
    if isinstance(q, Measure):
        return q.text(digits)
    unit_text = f"{q.units:~P}" if not getattr(q, "dimensionless", False) or str(q.units) != "dimensionless" else ""
    return f"{_number(q.magnitude, digits)} {unit_text}".strip()


def _number(x: float, digits: int = 6) -> str:
    """``6000`` rather than ``6000.000000000001``: a number to ``digits`` significant digits."""
    return f"{float(x):.{digits}g}"


@lru_cache(maxsize=None)
def registry():
    """The one pint registry (made on first use)."""
    import pint

    ureg = pint.UnitRegistry(on_redefinition="ignore")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for definition in DEFINITIONS:
            ureg.define(definition)
    ureg.formatter.default_sort_func = None  # units in the order written: N·m, not pint's alphabetical m·N
    return ureg


def Quantity(value, unit=None):  # noqa: N802 (pint's name: a quantity of this module's registry)
    """A pint Quantity of :func:`registry` (for the edges that hand quantities to a Python user)."""
    return registry().Quantity(value, unit) if unit is not None else registry().Quantity(value)


def __getattr__(name: str):
    if name == "ureg":
        return registry()
    raise AttributeError(f"module 'gearsym.units' has no attribute {name!r}")


# ----------------------------------------------------------------------------------------- reading
def parse_quantity(text: str, where: str):
    """The pint quantity ``text`` stands for, or a one-line error naming ``where``."""
    number, unit_text, quoted = _split(text, where)
    if not unit_text:
        return Quantity(number)
    q = Quantity(number, unit(unit_text, where, quoted))
    try:
        magnitude = q.to_base_units().magnitude
    except (OverflowError, ZeroDivisionError):  # (pint's factor of rpm**-1e9 overflows before any check)
        magnitude = math.inf
    _check_range(magnitude, where, quoted)
    return q


def check_quantity(text: str, where: str) -> None:
    """The one-line error :func:`parse_quantity` would give for ``text``, if any (without pint when the unit's
    meaning is kept: :class:`UnitMeaning`)."""
    if _measured(text, where) is None:
        parse_quantity(text, where)


def _split(text: str, where: str) -> tuple[float, str, str]:
    """The number and the unit text of a quantity string (checked against the grammar), and the string quoted
    for a message."""
    quoted = repr(text if len(text) <= 60 else text[:57] + "...")
    if len(text) > MAX_LENGTH:
        raise GearsymError(f"{where}: {quoted} is longer than the {MAX_LENGTH} characters a quantity may have; {GRAMMAR}")
    match = QUANTITY.fullmatch(text)
    if not match:
        raise GearsymError(f"{where}: {quoted} is not a quantity; {GRAMMAR}")
    number = float(match["number"])
    unit_text = (match["unit"] or "").strip()
    if not math.isfinite(number):
        raise GearsymError(f"{where}: {quoted} is not a finite number; give a value such as "
                           f"'{'3000' if unit_text else '1.5'}{(' ' + unit_text) if unit_text else ''}'")
    if POWER_OF_POWER.search(unit_text):
        raise GearsymError(f"{where}: {quoted} raises a power to a power; {GRAMMAR}")
    if unit_text.count("(") != unit_text.count(")"):
        raise GearsymError(f"{where}: {quoted} has unbalanced parentheses; {GRAMMAR}")
    return number, unit_text, quoted


def _check_range(magnitude: float, where: str, quoted: str) -> None:
    if not (math.isfinite(magnitude) and (magnitude == 0 or 1e-300 < abs(magnitude) < 1e300)):
        raise GearsymError(f"{where}: {quoted} is {magnitude:g} in SI units, out of the range of a number; "
                           "give a value with an ordinary unit")


@lru_cache(maxsize=256)
def _units(text: str):
    return registry().parse_units(text)


def unit(text: str, where: str, quoted: str | None = None):
    """The pint unit of a unit expression (already checked against the grammar by the caller)."""
    import pint

    alias = _alias(text, where, quoted)
    try:
        units = _units(alias)
    except pint.UndefinedUnitError as exc:
        names = exc.unit_names if isinstance(exc.unit_names, (tuple, list)) else (exc.unit_names,)
        raise GearsymError(f"{where}: unknown unit {', '.join(map(repr, names))} in {quoted or repr(text)}; "
                           "units are pint's (N, m, mm, um, kg, s, rpm, Hz, rad, ...)") from None
    except Exception as exc:  # pint's own syntax errors: a unit expression it cannot read
        raise GearsymError(f"{where}: cannot read the unit of {quoted or repr(text)} ({exc}); {GRAMMAR}") from None
    return units


def _alias(text: str, where: str, quoted: str | None = None) -> str:
    """The unit text pint is given for ``text`` (:data:`ALIASES`), or a one-line error for a known misspelling."""
    alias = ALIASES.get(text.replace(" ", ""), text)
    if alias is None:
        raise GearsymError(f"{where}: unknown unit {text!r} in {quoted or repr(text)}; did you mean 'rpm'? "
                           "Units are pint's (N, m, mm, um, kg, s, rpm, Hz, rad, ...)")
    return alias


def as_quantity(value, where: str):
    """A quantity of this registry from a string, a number (dimensionless) or a pint Quantity (of any registry)."""
    if isinstance(value, bool):
        raise GearsymError(f"{where}: expected a quantity such as '2e8 N/m', got {value!r}")
    if isinstance(value, str):
        return parse_quantity(value, where)
    if isinstance(value, (int, float)):
        if not math.isfinite(value):
            raise GearsymError(f"{where}: {value!r} is not a finite number")
        return Quantity(float(value))
    if isinstance(value, Measure):
        return Quantity(value.given, value.unit) if value.unit else Quantity(value.given)
    if type(value).__module__.startswith("pint"):
        magnitude = getattr(value, "magnitude", None)
        if not isinstance(magnitude, (int, float)) or not math.isfinite(magnitude):
            raise GearsymError(f"{where}: expected one finite number with a unit, got {value!r}")
        return value if value._REGISTRY is registry() else Quantity(float(magnitude), str(value.units))
    raise GearsymError(f"{where}: expected a quantity such as '2e8 N/m' (a string or a pint Quantity), "
                       f"got {type(value).__name__}")


def dimension_text(dimensionality) -> str:
    """'[mass] / [time] ** 2' or 'dimensionless' (of a pint dimensionality or exponents of mass, length, time)."""
    if isinstance(dimensionality, tuple):
        parts = [f"{d}" + (f" ** {e:g}" if e != 1 else "") for d, e in zip(BASE, dimensionality) if e > 0]
        below = [f"{d}" + (f" ** {-e:g}" if e != -1 else "") for d, e in zip(BASE, dimensionality) if e < 0]
        text = " * ".join(parts) or ("1" if below else "")
        return (text + "".join(f" / {b}" for b in below)) or "dimensionless"
    text = str(dimensionality)
    return text if text else "dimensionless"


def is_quantity(value) -> bool:
    """A value with a unit: a quantity string, a pint Quantity or a :class:`Measure`."""
    return (isinstance(value, Measure) or type(value).__module__.startswith("pint")
            or (isinstance(value, str) and looks_like_quantity(value)))


# ----------------------------------------------------------------------------------------- SI numbers
@record_class
class Measure:
    """A physical value as it crosses into the model: ``si`` in kg, m, s (angles in rad) and the exponents of
    mass, length and time it is made of; ``given`` and ``unit`` are what the user wrote, to show it back."""

    si: float
    dims: tuple[float, float, float]
    given: float
    unit: str = ""

    @property
    def dimensionless(self) -> bool:
        return not any(self.dims)

    def text(self, digits: int = 6) -> str:
        """As the user gave it: '2e+08 N/m', '3000 rpm'."""
        return f"{_number(self.given, digits)} {symbol(self.unit) if self.unit else ''}".strip()

    def __str__(self) -> str:
        return self.text()

    def with_si(self, si: float) -> "Measure":
        """Another value of the same kind, shown in the same unit."""
        factor = self.si / self.given if self.given not in (0, 0.0) and self.si != 0 else si_factor(self.unit)
        return Measure(float(si), self.dims, float(si) / factor if factor else float(si), self.unit)


def measure(value, where: str) -> Measure:
    """``value`` (a quantity string, a number, a pint Quantity or a Measure) in SI: one line if it is not a
    finite quantity made of mass, length and time."""
    if isinstance(value, Measure):
        return value
    if isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value):
        return Measure(float(value), (0.0, 0.0, 0.0), float(value))
    if isinstance(value, str):
        known = _measured(value, where)
        if known is not None:
            return known
    q = as_quantity(value, where)
    base = q.to_base_units()
    dims = dict(q.dimensionality)
    other = sorted(set(dims) - set(BASE))
    if other:
        raise GearsymError(f"{where}: a drivetrain value is made of mass, length and time, but {shown(q)} has the "
                           f"dimension {dimension_text(q.dimensionality)}")
    unit_text = "" if q.dimensionless and str(q.units) == "dimensionless" else str(q.units)
    si = float(base.magnitude)
    if not math.isfinite(si):
        raise GearsymError(f"{where}: {shown(q)} is not a finite number in SI units")
    return Measure(si, tuple(float(dims.get(d, 0)) for d in BASE), float(q.magnitude), unit_text)


def measure_in(value: float, unit_text: str, where: str) -> Measure:
    """``value`` in ``unit_text`` (as pint reads it, no alias) in SI, as :func:`measure` gives it for
    ``Quantity(value, unit_text)``: without pint when the unit's meaning is kept."""
    meaning = _meaning(unit_text) if unit_text else None
    if (meaning is not None and isinstance(value, (int, float)) and not isinstance(value, bool)
            and math.isfinite(si := float(value) * meaning.factor)):
        return Measure(si, meaning.dims, float(value), meaning.name)
    return measure(Quantity(value, unit_text) if unit_text else value, where)


def _measured(text: str, where: str) -> Measure | None:
    """A quantity string in SI without pint when its unit's meaning is kept (else learnt from pint and kept);
    None if the unit is not plain (:class:`UnitMeaning`): pint reads it as a quantity."""
    number, unit_text, quoted = _split(text, where)
    if not unit_text:
        return Measure(number, (0.0, 0.0, 0.0), number)
    alias = _alias(unit_text, where, quoted)
    meaning = _recalled(alias) or _learnt(alias, unit(unit_text, where, quoted))
    if meaning is None:
        return None
    si = number * meaning.factor  # (pint's conversion of a multiplicative unit: the number times its factor)
    _check_range(si, where, quoted)
    return Measure(si, meaning.dims, number, meaning.name)


# ----------------------------------------------------------------------------------------- kept meanings
@record_class
class UnitMeaning:
    """What pint says a unit text means, as plain data: kept in the user's cache (:mod:`gearsym.files.memo`),
    so that a later process meeting the same text reads it there and imports no pint (pint's import and its
    registry cost over a second of CPU a process). pint stays the one parser: a meaning is what pint answered,
    under a name that hashes the text, pint's version and definitions and :data:`DEFINITIONS`. Only a plain
    unit is kept: multiplicative (no offset, not logarithmic) and made of mass, length and time."""

    name: str  # the unit as pint names it (``str(units)``): what a Measure keeps
    factor: float  # SI base units per one
    dims: tuple[float, float, float]  # the exponents of mass, length and time
    symbol: str  # pint's short form (``~P``)

    @classmethod
    def from_pint(cls, units) -> "UnitMeaning | None":
        """The meaning of a pint unit, or None if it is not plain."""
        try:
            dims = dict(Quantity(1.0, units).dimensionality)
            if set(dims) - set(BASE):
                return None
            zero, one, three = (Quantity(x, units).to_base_units().magnitude for x in (0.0, 1.0, 3.0))
            if zero != 0 or three != 3.0 * one or not math.isfinite(one) or one == 0:
                return None  # (an offset or logarithmic unit: its conversion is not a product)
            name = str(units)  # (a Measure keeps no unit for pint's 'dimensionless')
            return cls("" if name == "dimensionless" else name, float(one), tuple(float(dims.get(d, 0)) for d in BASE),
                       f"{units:~P}")
        except Exception:  # (pint could not convert it: it is read by pint, as before)
            return None


_WHAT = "kept meaning of a unit"
#: this process's answers of each kind ("units": unit text -> UnitMeaning, "unit-conversions": "source -> target" ->
#: factor): those earlier processes kept, read once on the kind's first question, and those learnt since
_KNOWN: dict[str, dict] = {}


def _known(kind: str) -> dict:
    """This process's answers of ``kind`` (see :data:`_KNOWN`)."""
    if kind not in _KNOWN:
        identity = _pint_identity()
        kept = recall_all(kind, identity, _WHAT) if identity is not None else {}
        read = _READ_KEPT[kind]
        _KNOWN[kind] = {question: answer for question, kept_answer in kept.items()
                        if (answer := read(kept_answer)) is not None}
    return _KNOWN[kind]


def _meaning_kept(kept: dict) -> UnitMeaning | None:
    """A unit's meaning as kept, or None if it does not read as one."""
    try:
        meaning = UnitMeaning(str(kept["name"]), float(kept["factor"]), tuple(float(d) for d in kept["dims"]),
                              str(kept["symbol"]))
    except (KeyError, TypeError, ValueError):
        return None
    return meaning if len(meaning.dims) == len(BASE) and math.isfinite(meaning.factor) and meaning.factor else None


def _factor_kept(kept: dict) -> float | None:
    """A conversion factor as kept, or None if it is not a finite number."""
    factor = kept.get("factor")
    return factor if isinstance(factor, float) and math.isfinite(factor) else None


_READ_KEPT = {"units": _meaning_kept, "unit-conversions": _factor_kept}


def _recalled(text: str) -> UnitMeaning | None:
    """The meaning of ``text`` (as pint reads it) kept by this or an earlier process, or None."""
    return _known("units").get(text)


def _learnt(text: str, units) -> UnitMeaning | None:
    """The meaning of the pint unit ``units`` read from ``text``, kept for later processes (and the meaning of
    its name, which a Measure keeps and shows); None if it is not plain."""
    meaning = UnitMeaning.from_pint(units)
    identity = _pint_identity()
    if meaning is None or identity is None:
        return meaning
    known = _known("units")
    for said, meant in ((text, meaning), (meaning.name, None)):
        if not said or said in known:
            continue
        if meant is None:
            try:
                meant = UnitMeaning.from_pint(_units(said))
            except Exception:  # (a name pint does not read back: not kept)
                continue
        if meant is not None:
            known[said] = meant
            keep("units", said, identity, {"name": meant.name, "factor": meant.factor, "dims": list(meant.dims),
                                           "symbol": meant.symbol})
    return meaning


def _meaning(unit_text: str) -> UnitMeaning | None:
    """The meaning of a unit text as pint reads it (no alias), kept or learnt; None if it is not plain or pint
    cannot read it (the caller asks pint, which says why)."""
    meaning = _recalled(unit_text)
    if meaning is None:
        try:
            meaning = _learnt(unit_text, _units(unit_text))
        except Exception:
            return None
    return meaning


@lru_cache(maxsize=None)
def _pint_identity() -> str | None:
    """What a pint answer depends on, found without importing pint: its version (the name of its installed
    metadata), a hash of its definitions files, and :data:`DEFINITIONS`; None if there is no pint."""
    try:
        spec = importlib.util.find_spec("pint")
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.origin:
        return None
    folder = Path(spec.origin).parent
    digest = hashlib.sha256()
    for name in sorted(folder.glob("*.txt")):  # (default_en.txt, constants_en.txt: the units pint knows)
        try:
            digest.update(name.name.encode() + b"\0" + name.read_bytes())
        except OSError:
            return None
    versions = sorted(p.name for p in folder.parent.glob("*.dist-info") if p.name.lower().startswith("pint-"))
    return f"{' '.join(versions) or 'pint'} {digest.hexdigest()[:32]} {' ; '.join(DEFINITIONS)}"


def conversion_factor(source: str, target: str) -> float:
    """How many ``target`` one ``source`` is (pint's factor, ``Quantity(1.0, source).to(target)``: not the ratio
    of the two SI factors, which may differ in the last bit), kept as a unit's meaning is."""
    question = f"{source} -> {target}"
    known = _known("unit-conversions")
    if question not in known:
        factor = float(Quantity(1.0, source).to(target).magnitude)
        identity = _pint_identity()
        if identity is not None and math.isfinite(factor):
            keep("unit-conversions", question, identity, {"factor": factor})
        known[question] = factor
    return known[question]


def si_factor(unit_text: str) -> float:
    """SI base units per one ``unit_text`` (1e-6 for 'um', 0.10472 for 'rpm')."""
    if not unit_text:
        return 1.0
    meaning = _meaning(unit_text)
    return meaning.factor if meaning is not None else _pint_factor(unit_text)


@lru_cache(maxsize=256)
def _pint_factor(unit_text: str) -> float:
    return float(Quantity(1.0, unit_text).to_base_units().magnitude)


@lru_cache(maxsize=256)
def unit_dims(unit_text: str) -> tuple[float, float, float]:
    """The exponents of mass, length and time of a unit."""
    return measure(f"1 {unit_text}", unit_text).dims if unit_text else (0.0, 0.0, 0.0)


def from_si(si, unit_text: str):
    """A number (or array) in SI base units, in ``unit_text``."""
    return si / si_factor(unit_text)


def to_si(number, unit_text: str):
    """A number (or array) in ``unit_text``, in SI base units."""
    return number * si_factor(unit_text)


def symbol(unit_text: str) -> str:
    """The short symbol of a unit, as pint prints it ('µm' for 'micrometer', 'N·m' for 'newton * meter')."""
    if not unit_text:
        return ""
    meaning = _meaning(unit_text)
    return meaning.symbol if meaning is not None else _pint_symbol(unit_text)


@lru_cache(maxsize=256)
def _pint_symbol(unit_text: str) -> str:
    return f"{Quantity(1, unit_text).units:~P}"


__all__ = ["BASE", "GRAMMAR", "MAX_LENGTH", "Measure", "QUANTITY", "Quantity", "UnitMeaning", "as_quantity",
           "check_quantity", "conversion_factor", "dimension_text", "from_si", "is_quantity", "looks_like_quantity",
           "measure", "measure_in", "parse_quantity", "registry", "shown", "si_factor", "symbol", "to_si", "unit",
           "unit_dims"]
