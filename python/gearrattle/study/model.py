"""What a study needs from the FMU's modelDescription.xml: its GUID, the parameters (type, start,
range) and the metrics, i.e. every output whose name, or last component of a structured name
(`gear[2].stat_rattle_power` of GearboxRattle), starts with `stat_`.

A parameter's range is the statement its description ends with, "(range: I_L > 0)", as the
contract's generator writes it (exclusive bounds included, which FMI 2.0's min and max cannot
express), or else its min and max.

FMI 3.0's types are taken as FMI 2.0's (Float64 a Real, Int32, UInt64 and Enumeration
Integers); its structural parameters (GearboxRattle's `n_gears`) are parameters, and an array
parameter (`gear.I_L`, sized by `n_gears`) stands as its elements under FMI 2.0's names
(`gear[1].I_L` .. `gear[8].I_L`, up to its structural parameter's largest value), each with
the range of the array and the start its start list gives it (none past the list's end)."""

import math
import re
from dataclasses import dataclass, field

METRIC_PREFIX = "stat_"
STATS_FROM = "stats_from"


@dataclass(frozen=True)
class Var:
    name: str
    vr: int
    type: str  # "Real", "Integer" or "Boolean" (FMI 3.0's types as these)
    start: float | None
    min: float | None
    max: float | None
    unit: str | None
    min_exclusive: bool = False  # the value must be > min (else >= min)
    max_exclusive: bool = False  # the value must be < max (else <= max)
    description: str = ""

    def below(self, x):
        """x is under the range's lower end (at it, where the bound is exclusive)."""
        return self.min is not None and (x < self.min or (self.min_exclusive and x == self.min))

    def above(self, x):
        """x is over the range's upper end (at it, where the bound is exclusive)."""
        return self.max is not None and (x > self.max or (self.max_exclusive and x == self.max))

    def statement(self):
        """The range as the contract states it: 'I_L > 0', '0 <= excitation <= 2'."""
        lo = None if self.min is None else (f"{self.min:g}", "<" if self.min_exclusive else "<=")
        hi = None if self.max is None else (f"{self.max:g}", "<" if self.max_exclusive else "<=")
        if lo and hi:
            return f"{lo[0]} {lo[1]} {self.name} {hi[1]} {hi[0]}"
        if lo:
            return f"{self.name} {lo[1].replace('<', '>')} {lo[0]}"
        if hi:
            return f"{self.name} {hi[1]} {hi[0]}"
        return "any finite value"


@dataclass(frozen=True)
class Model:
    guid: str
    model_identifier: str
    parameters: dict  # name -> Var, in the order of the model description
    outputs: dict  # name -> Var
    metrics: tuple  # the stat_* outputs (Var), in the order of the model description
    # FMI 3.0: each array parameter's name -> (its structural parameter's name, the names of
    # its elements in `parameters`)
    arrays: dict = field(default_factory=dict)

    @property
    def has_stats_from(self):
        return STATS_FROM in self.parameters


def is_metric(name):
    """A `stat_*` output, of the model or of one of its parts (`gear[2].stat_regime`)."""
    return name.rsplit(".", 1)[-1].startswith(METRIC_PREFIX)


# FMI 3.0's types by FMI 2.0's name.
_FMI2_TYPE = {"Float64": "Real", "Float32": "Real", "Enumeration": "Integer"}
# Parameters: FMI 3.0's structural parameters besides FMI 2.0's.
_PARAMETER = ("parameter", "structuralParameter")


def _type(fmi_type):
    """"Real", "Integer" or "Boolean" for a type of FMI 2.0 or 3.0."""
    if fmi_type.startswith(("Int", "UInt")):
        return "Integer"
    return _FMI2_TYPE.get(fmi_type, fmi_type)


def _number(text, kind):
    if text is None:
        return None
    if kind == "Boolean":
        return float(text in (True, "true", "1", 1))
    return float(text)


def _range(name, description, xml_min, xml_max):
    """(min, min_exclusive, max, max_exclusive) from the description's statement, or from the
    XML's min and max (inclusive) where it states none."""
    found = re.search(r"\(range: ([^()]*)\)\s*$", description or "")
    n, num, op = re.escape(name), r"(\S+)", r"(<=?)"
    text = found[1] if found else ""
    try:
        if m := re.fullmatch(rf"{num} {op} {n} {op} {num}", text):
            return float(m[1]), m[2] == "<", float(m[4]), m[3] == "<"
        if m := re.fullmatch(rf"{n} (>=?) {num}", text):
            return float(m[2]), m[1] == ">", None, False
        if m := re.fullmatch(rf"{n} {op} {num}", text):
            return None, False, float(m[2]), m[1] == "<"
    except ValueError:
        pass
    return xml_min, False, xml_max, False


def _var(v, name=None, start=None):
    """The study's Var of fmpy's model variable v (as `name`, with `start`, for an element of
    an array: the array's range stated under its own name)."""
    kind = _type(v.type)
    lo, lo_open, hi, hi_open = _range(v.name, v.description, _number(v.min, kind),
                                      _number(v.max, kind))
    return Var(name or v.name, v.valueReference, kind,
               start if name else _number(v.start, kind), lo, hi, v.unit, lo_open, hi_open,
               v.description or "")


def _elements(v, size):
    """An FMI 3.0 array parameter `ARRAY.NAME` as its elements `ARRAY[i].NAME`, i = 1 .. the
    largest value of its structural parameter (the Var `size`)."""
    starts = [_number(t, _type(v.type)) for t in (v.start or "").split()]
    array, _, name = v.name.partition(".")
    count = int(size.max) if size.max is not None else len(starts)
    return [_var(v, f"{array}[{i}].{name}", starts[i - 1] if i <= len(starts) else None)
            for i in range(1, count + 1)]


def read_model(fmu):
    """The study's view of an FMU (a .fmu file or an extracted directory)."""
    from fmpy import read_model_description

    md = read_model_description(fmu)
    params, outs, arrays = {}, {}, {}
    for v in md.modelVariables:
        if v.causality in _PARAMETER and v.variability in ("fixed", "tunable"):
            if getattr(v, "dimensions", None):
                size = params[v.dimensions[0].variable.name]
                elements = _elements(v, size)
                params.update((e.name, e) for e in elements)
                arrays[v.name] = (size.name, [e.name for e in elements])
            else:
                params[v.name] = _var(v)
        elif v.causality == "output":
            outs[v.name] = _var(v)
    metrics = tuple(v for n, v in outs.items() if is_metric(n))
    return Model(md.guid, md.coSimulation.modelIdentifier, params, outs, metrics, arrays)
