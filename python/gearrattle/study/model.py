"""What a study needs from the FMU's modelDescription.xml: its GUID, the parameters (type, start,
min, max) and the metrics, i.e. every output whose name starts with `stat_`."""

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


def _number(text, kind):
    if text is None:
        return None
    if kind == "Boolean":
        return float(text in (True, "true", "1", 1))
    return float(text)


def read_model(fmu):
    """The study's view of an FMU (a .fmu file or an extracted directory)."""
    from fmpy import read_model_description

    md = read_model_description(fmu)
    params, outs = {}, {}
    for v in md.modelVariables:
        var = Var(v.name, v.valueReference, v.type, _number(v.start, v.type),
                  _number(v.min, v.type), _number(v.max, v.type), v.unit)
        if v.causality == "parameter" and v.variability in ("fixed", "tunable"):
            params[v.name] = var
        elif v.causality == "output":
            outs[v.name] = var
    metrics = tuple(v for n, v in outs.items() if n.startswith(METRIC_PREFIX))
    return Model(md.guid, md.coSimulation.modelIdentifier, params, outs, metrics)
