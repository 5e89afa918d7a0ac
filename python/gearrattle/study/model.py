"""What a study needs from the FMU's modelDescription.xml: its GUID, the parameters (type, start,
range) and the metrics, i.e. every output whose name, or last component of a structured name
(`gear[2].stat_rattle_power` of GearboxRattle), starts with `stat_`.

A parameter's range is the statement its description ends with, "(range: I_L > 0)", as the
contract's generator writes it (exclusive bounds included, which FMI 2.0's min and max cannot
express), or else its min and max."""

import math
import re
from dataclasses import dataclass

METRIC_PREFIX = "stat_"
STATS_FROM = "stats_from"


@dataclass(frozen=True)
class Var:
    name: str
    vr: int
    type: str  # "Real", "Integer" or "Boolean"
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

    @property
    def has_stats_from(self):
        return STATS_FROM in self.parameters


def is_metric(name):
    """A `stat_*` output, of the model or of one of its parts (`gear[2].stat_regime`)."""
    return name.rsplit(".", 1)[-1].startswith(METRIC_PREFIX)


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


def read_model(fmu):
    """The study's view of an FMU (a .fmu file or an extracted directory)."""
    from fmpy import read_model_description

    md = read_model_description(fmu)
    params, outs = {}, {}
    for v in md.modelVariables:
        lo, lo_open, hi, hi_open = _range(v.name, v.description, _number(v.min, v.type),
                                          _number(v.max, v.type))
        var = Var(v.name, v.valueReference, v.type, _number(v.start, v.type), lo, hi, v.unit,
                  lo_open, hi_open, v.description or "")
        if v.causality == "parameter" and v.variability in ("fixed", "tunable"):
            params[v.name] = var
        elif v.causality == "output":
            outs[v.name] = var
    metrics = tuple(v for n, v in outs.items() if is_metric(n))
    return Model(md.guid, md.coSimulation.modelIdentifier, params, outs, metrics)
