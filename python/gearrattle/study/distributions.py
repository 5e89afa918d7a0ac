"""Tolerance distributions of a Monte Carlo study, written NAME=KIND:ARGS:
    normal:MEAN:SD, uniform:LO:HI, lognormal:MEAN:SD (of the value itself, not of its log),
    truncnormal:MEAN:SD:LO:HI (a normal cut to [LO, HI]).
Each maps a uniform number u in (0, 1) to a value through its quantile function, so that plain
Monte Carlo, Saltelli's Sobol' sampling and Morris' trajectories share one definition."""

import math
from dataclasses import dataclass

from .errors import StudyError

FORMS = {
    "normal": ("MEAN", "SD"),
    "uniform": ("LO", "HI"),
    "lognormal": ("MEAN", "SD"),
    "truncnormal": ("MEAN", "SD", "LO", "HI"),
}


@dataclass
class Dist:
    name: str
    kind: str
    args: tuple
    where: str

    def frozen(self):
        from scipy import stats

        k, a = self.kind, self.args
        if k == "normal":
            return stats.norm(a[0], a[1])
        if k == "uniform":
            return stats.uniform(a[0], a[1] - a[0])
        if k == "lognormal":  # the log's parameters from the value's mean and SD
            s2 = math.log1p((a[1] / a[0]) ** 2)
            return stats.lognorm(math.sqrt(s2), scale=a[0] * math.exp(-s2 / 2))
        mean, sd, lo, hi = a
        return stats.truncnorm((lo - mean) / sd, (hi - mean) / sd, loc=mean, scale=sd)

    def ppf(self, u):
        return self.frozen().ppf(u)

    def support(self):
        """(lowest, highest) value a sample can take: the 1e-12 and 1 - 1e-12 quantiles for the
        unbounded distributions, the bounds for the others."""
        if self.kind == "uniform":
            return self.args
        if self.kind == "truncnormal":
            return self.args[2:]
        return tuple(float(x) for x in self.ppf([U_EDGE, 1 - U_EDGE]))

    def __str__(self):
        return f"{self.name} ~ {self.kind}({', '.join(f'{x:g}' for x in self.args)})"


U_EDGE = 1e-12  # uniform numbers are kept within [U_EDGE, 1 - U_EDGE]: finite quantiles


def parse_dist(text, where):
    name, sep, rest = text.partition("=")
    parts = rest.split(":")
    kind = parts[0].strip().lower()
    if not sep or kind not in FORMS:
        raise StudyError(f"{where}: '{text}' is not NAME=KIND:ARGS with KIND one of "
                         + ", ".join(f"{k}:{':'.join(v)}" for k, v in FORMS.items()))
    form = FORMS[kind]
    if len(parts) - 1 != len(form):
        raise StudyError(f"{where}: {kind} takes {':'.join(form)} ({len(form)} numbers), got "
                         f"'{rest}'")
    try:
        args = tuple(float(p) for p in parts[1:])
    except ValueError:
        raise StudyError(f"{where}: '{rest}': {':'.join(form)} must be numbers") from None
    name = name.strip()
    d = Dist(name, kind, args, where)
    if kind == "uniform" and not args[0] < args[1]:
        raise StudyError(f"{where}: uniform {name} from {args[0]:g} to {args[1]:g} has a "
                         f"negative or zero width: give LO < HI")
    if kind != "uniform" and not args[1] > 0:
        raise StudyError(f"{where}: {kind} {name} with SD = {args[1]:g}: the width must be "
                         f"positive; give SD > 0")
    if kind == "lognormal" and not args[0] > 0:
        raise StudyError(f"{where}: lognormal {name} with MEAN = {args[0]:g}: a lognormal "
                         f"value is positive; give MEAN > 0")
    if kind == "truncnormal" and not args[2] < args[3]:
        raise StudyError(f"{where}: truncnormal {name} cut to [{args[2]:g}, {args[3]:g}]: an "
                         f"empty interval; give LO < HI")
    return d
