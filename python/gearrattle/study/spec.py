"""A study as the user describes it (command-line flags or a TOML file), and its validation
against the FMU before anything runs.

Every entry remembers where it came from (`--x f_exc=30:60:16`, `study.toml line 4`), so that a
refusal names the place and the fix. The TOML keys are the long flags with `_` for `-`, and take
the flags' strings (`x = "f_exc=30:60:16"`, `dist = { G = "normal:25e-6:2.5e-6" }`)."""

import difflib
import math
import re
import tomllib
from dataclasses import dataclass, field

from .distributions import Dist, parse_dist
from .errors import StudyError
from .model import METRIC_PREFIX, STATS_FROM

KINDS = ("map", "doe", "mc")
DESIGNS = ("lhs", "full")
SENSITIVITY = ("none", "sobol", "morris")
DEFAULT_DURATION = 1.0
DEFAULT_STATS_FROM = 0.2
# The studies run the FMU alone, with no master feeding its inputs: the paper's sine bench
# (excitation = 1) unless the study sets another mode.
STANDALONE = {"excitation": 1}


@dataclass
class Axis:  # map: NAME=LO:HI:COUNT
    name: str
    lo: float
    hi: float
    count: int
    where: str

    def values(self):
        import numpy as np

        return [float(v) for v in np.linspace(self.lo, self.hi, self.count)]


@dataclass
class Range:  # doe: NAME=LO:HI
    name: str
    lo: float
    hi: float
    where: str


@dataclass
class Exceed:  # mc: METRIC>VALUE (also >=, <, <=)
    metric: str
    op: str
    value: float
    where: str

    def test(self, x):
        import numpy as np

        return {">": np.greater, ">=": np.greater_equal, "<": np.less,
                "<=": np.less_equal}[self.op](x, self.value)

    def __str__(self):
        return f"{self.metric} {self.op} {self.value:g}"


@dataclass
class Study:
    kind: str
    fmu: str
    out: str
    fixed: dict = field(default_factory=dict)  # name -> (value, where)
    duration: float = DEFAULT_DURATION
    stats_from: tuple | None = None  # (value, where) when given; else the default
    workers: int | None = None  # None: one per core; 0: serial, in this process
    scheduler: str | None = None
    seed: int = 0
    n: int = 0
    axes: list = field(default_factory=list)  # map: [x, y]
    ranges: list = field(default_factory=list)  # doe
    design: str = "lhs"
    dists: list = field(default_factory=list)  # mc: [Dist]
    at: list = field(default_factory=list)  # mc operating points: [({name: value}, where)]
    exceed: list = field(default_factory=list)  # mc: [Exceed]
    sensitivity: str = "none"
    record: list = field(default_factory=list)  # outputs recorded besides the stat_* ones
    sound: bool = False  # the sound columns of each point (gearrattle.sound.study)
    source: str = "command line"
    gearbox: str | None = None  # a gearbox file whose values the study starts from

    def varied(self):
        return ([a.name for a in self.axes] + [r.name for r in self.ranges]
                + [d.name for d in self.dists])


# ------------------------------------------------------------------ parsing of the flag strings

def _split(text, where, form):
    name, sep, rest = text.partition("=")
    if not sep or not name.strip() or not rest.strip():
        raise StudyError(f"{where}: '{text}' is not {form}")
    return name.strip(), rest.strip()


def _float(text, where, what):
    try:
        return float(text)
    except (TypeError, ValueError):
        raise StudyError(f"{where}: {what} '{text}' is not a number") from None


def _fields(text, where, form, example):
    """NAME and the colon-separated fields of NAME=A:B[:C] as the form's names say."""
    name, rest = _split(text, where, f"{form} (e.g. {example})")
    parts = rest.split(":")
    if len(parts) != form.count(":") + 1:
        raise StudyError(f"{where}: '{text}' is not {form} (e.g. {example})")
    return name, parts


def parse_axis(text, where):
    name, parts = _fields(text, where, "NAME=LO:HI:COUNT", "f_exc=30:60:16")
    lo, hi = (_float(p, where, w) for p, w in zip(parts, ("LO", "HI")))
    try:
        count = int(parts[2])
    except ValueError:
        raise StudyError(f"{where}: COUNT '{parts[2]}' is not a whole number") from None
    if count < 1 or (count > 1 and not lo < hi):
        raise StudyError(f"{where}: empty range {name} = {lo:g}..{hi:g} in {count} values: "
                         f"give LO < HI and COUNT >= 2 (or COUNT = 1 for a single value)")
    return Axis(name, lo, hi, count, where)


def parse_range(text, where):
    name, parts = _fields(text, where, "NAME=LO:HI", "G=15e-6:35e-6")
    lo, hi = (_float(p, where, w) for p, w in zip(parts, ("LO", "HI")))
    if not lo < hi:
        raise StudyError(f"{where}: empty range {name} = {lo:g}..{hi:g}: give LO < HI")
    return Range(name, lo, hi, where)


def parse_set(text, where):
    name, rest = _split(text, where, "NAME=VALUE (e.g. excitation=1)")
    return name, _float(rest, where, "VALUE")


def parse_at(text, where):
    """An operating point: NAME=VALUE,NAME=VALUE."""
    return dict(parse_set(p, where) for p in text.split(",") if p.strip())


def parse_exceed(text, where):
    m = re.fullmatch(r"\s*([A-Za-z_][\w.]*)\s*(>=|<=|>|<)\s*(\S+)\s*", text)
    if not m:
        raise StudyError(f"{where}: '{text}' is not METRIC>VALUE (e.g. stat_regime>0; "
                         f"operators > >= < <=)")
    return Exceed(m[1], m[2], _float(m[3], where, "VALUE"), where)


# ------------------------------------------------------------------ the TOML file

KEYS = {"kind", "fmu", "out", "set", "duration", "stats_from", "workers", "scheduler", "seed",
        "n", "x", "y", "param", "design", "dist", "at", "exceed", "sensitivity", "record",
        "gearbox"}


def _locate(lines, key, token=None):
    """The 1-based line of `key = ...` (or the table [key]), or of token at or after it."""
    start = 0
    pat = re.compile(rf"^\s*(\[\s*{re.escape(key)}\s*\]|{re.escape(key)}\s*=)")
    for i, line in enumerate(lines):
        if pat.match(line):
            start = i
            break
    if token is not None:
        tok = re.compile(rf"(^|[^\w.]){re.escape(str(token))}($|[^\w.])")
        for i in range(start, len(lines)):
            if tok.search(lines[i]):
                return i + 1
    return start + 1


def _entries(value, where, key):
    """A TOML value given as a string, a list of strings or a table {NAME = "SPEC"}, as a list
    of (flag string, NAME or None) pairs."""
    if isinstance(value, str):
        return [(value, None)]
    if isinstance(value, list) and all(isinstance(v, str) for v in value):
        return [(v, None) for v in value]
    if isinstance(value, dict):
        return [(f"{k}={v}", k) for k, v in value.items()]
    raise StudyError(f"{where}: {key} must be a string, a list of strings or a table "
                     f"{{ NAME = \"...\" }}")


def load_toml(path, what):
    """(document, text) of a TOML file (what: "study", "gearbox"), or a StudyError saying why
    it cannot be read."""
    try:
        text = open(path, encoding="utf-8").read()
    except OSError as e:
        raise StudyError(f"{path}: cannot read the {what} file ({e.strerror})") from None
    try:
        return tomllib.loads(text), text
    except tomllib.TOMLDecodeError as e:
        raise StudyError(f"{path}: malformed TOML: {e}. Fix the syntax there (strings in "
                         f"quotes, one `key = value` a line, tables as [name])") from None


def from_toml(path, overrides=None):
    """Read a study file; overrides (from the `run` flags) replace its entries."""
    doc, text = load_toml(path, "study")
    lines = text.splitlines()

    def at(key, token=None):
        return f"{path} line {_locate(lines, key, token)}"

    for key in doc:
        if key not in KEYS:
            near = difflib.get_close_matches(key, KEYS, 1)
            raise StudyError(f"{at(key)}: unknown key '{key}'"
                             + (f": did you mean '{near[0]}'?" if near else "")
                             + f" (keys: {', '.join(sorted(KEYS))})")
    kind = doc.get("kind")
    if kind not in KINDS:
        raise StudyError(f"{at('kind')}: kind = {kind!r}: give kind = \"map\", \"doe\" or "
                         f"\"mc\"")
    for key in ("fmu", "out"):
        if not isinstance(doc.get(key, ""), str):
            raise StudyError(f"{at(key)}: {key} must be a path in quotes")
    st = Study(kind=kind, fmu=doc.get("fmu", ""), out=doc.get("out", ""), source=str(path))

    def number(key, kind_=float, default=None):
        if key not in doc:
            return default
        v = doc[key]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or (
                kind_ is int and not isinstance(v, int)):
            raise StudyError(f"{at(key)}: {key} = {v!r} must be a "
                             f"{'whole number' if kind_ is int else 'number'}")
        return kind_(v)

    st.duration = number("duration", default=DEFAULT_DURATION)
    if "stats_from" in doc:
        st.stats_from = (number("stats_from"), at("stats_from"))
    st.workers = number("workers", int)
    st.seed = number("seed", int, 0)
    st.n = number("n", int, 0)
    st.scheduler = doc.get("scheduler")
    st.design = doc.get("design", "lhs")
    st.sensitivity = doc.get("sensitivity", "none")
    set_ = doc.get("set", {})
    if isinstance(set_, dict):
        for k, v in set_.items():
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise StudyError(f"{at('set', k)}: set.{k} = {v!r} must be a number")
            st.fixed[k] = (float(v), at("set", k))
    else:
        for text, _ in _entries(set_, at("set"), "set"):
            name, value = parse_set(text, at("set", text.partition("=")[0]))
            st.fixed[name] = (value, at("set", name))
    for key in ("x", "y"):
        if key in doc:
            for text, _ in _entries(doc[key], at(key), key):
                st.axes.append(parse_axis(text, at(key)))
    for text, name in _entries(doc.get("param", []), at("param"), "param"):
        st.ranges.append(parse_range(text, at("param", name or text.partition("=")[0])))
    for text, name in _entries(doc.get("dist", []), at("dist"), "dist"):
        st.dists.append(parse_dist(text, at("dist", name or text.partition("=")[0])))
    for i, point in enumerate(doc.get("at", [])):
        if not isinstance(point, dict):
            raise StudyError(f"{at('at')}: at must be a list of tables, e.g. "
                             f"at = [{{ f_exc = 30, A_rms = 300 }}]")
        st.at.append(({k: float(v) for k, v in point.items()}, at("at", next(iter(point), None))))
    for text, _ in _entries(doc.get("exceed", []), at("exceed"), "exceed"):
        st.exceed.append(parse_exceed(text, at("exceed")))
    st.gearbox = doc.get("gearbox")
    rec = doc.get("record", [])
    st.record = [rec] if isinstance(rec, str) else list(rec)
    for key, value in (overrides or {}).items():
        if value is not None:
            setattr(st, key, value)
    if not st.fmu:
        raise StudyError(f"{path}: no FMU: add fmu = \"target/fmu/GearRattle.fmu\" or pass --fmu")
    if not st.out:
        raise StudyError(f"{path}: no output directory: add out = \"target/studies/NAME\" or "
                         f"pass --out")
    return st


# ------------------------------------------------------------------ validation against the FMU

def _near(name, names):
    """'did you mean X? ' for the names closest to name (case aside), or ''."""
    lower = {n.lower(): n for n in names}
    near = [lower[n] for n in difflib.get_close_matches(name.lower(), list(lower), 3)]
    return f"did you mean {' or '.join(near)}? " if near else ""


def _check_name(name, where, model, varied):
    params = model.parameters
    if name == STATS_FROM:
        raise StudyError(f"{where}: set stats_from with --stats-from (stats_from = ... in a "
                         f"study file), not as a parameter")
    if name not in params:
        kind = "an output" if name in model.outputs else "not a parameter of this FMU"
        raise StudyError(f"{where}: '{name}' is {kind}: {_near(name, list(params))}"
                         f"(parameters: {', '.join(n for n in params if n != STATS_FROM)})")
    if varied and params[name].type != "Real":
        raise StudyError(f"{where}: '{name}' is an {params[name].type} parameter: vary Real "
                         f"parameters only; set it with --set {name}=VALUE, one study per value")


def _check_bounds(name, lo, hi, where, model, what):
    """Refuse values of name from lo to hi that leave the FMU's range (exclusive bounds
    included: I_L = 0 against I_L > 0), naming the range and the fix."""
    v = model.parameters[name]
    unit = f" {v.unit}" if v.unit else ""
    fix = f"keep {name} within its range {v.statement()}"
    if math.isnan(lo) or math.isnan(hi):
        raise StudyError(f"{where}: {what} {name} is not a number: {fix}")
    if v.below(lo):
        side = ("not above the FMU's exclusive minimum" if v.min_exclusive
                else "below the FMU's minimum")
        raise StudyError(f"{where}: {what} {name} = {lo:g}{unit} is {side} {v.min:g}: {fix}")
    if v.above(hi):
        side = ("not below the FMU's exclusive maximum" if v.max_exclusive
                else "above the FMU's maximum")
        raise StudyError(f"{where}: {what} {name} = {hi:g}{unit} is {side} {v.max:g}: {fix}")


def check_value(name, value, where, model):
    """Refuse a start value the FMU does not take: not a parameter, not whole for an Integer,
    or out of the contract's range."""
    _check_name(name, where, model, False)
    if model.parameters[name].type != "Real" and value != int(value):
        raise StudyError(f"{where}: {name} = {value:g} must be a whole number")
    _check_bounds(name, value, value, where, model, "value of")


def validate(st, model):
    """Refuse a study that cannot run as meant, before anything runs. Fills in the defaults
    (excitation = 1, stats_from = 0.2 s when the FMU has it)."""
    src = st.source
    if st.kind not in KINDS:
        raise StudyError(f"{src}: unknown study kind '{st.kind}': map, doe or mc")
    if not (st.duration > 0 and math.isfinite(st.duration)):
        raise StudyError(f"{src}: duration {st.duration:g} s: give a duration > 0")
    if st.workers is not None and st.workers < 0:
        raise StudyError(f"{src}: workers = {st.workers}: give 0 (serial) or more")
    if st.stats_from is not None:
        value, where = st.stats_from
        if not model.has_stats_from:
            raise StudyError(f"{where}: this FMU has no parameter stats_from (no statistics "
                             f"window): rebuild it from a version with the stat_* outputs "
                             f"(make fmu), or leave out --stats-from")
        if not 0 <= value < st.duration:
            raise StudyError(f"{where}: stats_from = {value:g} s must be in [0, duration = "
                             f"{st.duration:g} s)")
    elif model.has_stats_from:
        st.stats_from = (min(DEFAULT_STATS_FROM, 0.5 * st.duration), "default")
    seen = {}
    for name, where in ([(a.name, a.where) for a in st.axes] + [(r.name, r.where) for r in
                        st.ranges] + [(d.name, d.where) for d in st.dists]):
        _check_name(name, where, model, True)
        if name in seen:
            raise StudyError(f"{where}: {name} is varied twice (also at {seen[name]}): vary it "
                             f"once")
        seen[name] = where
    for name, (value, where) in st.fixed.items():
        _check_name(name, where, model, False)
        if name in seen:
            raise StudyError(f"{where}: {name} is both set and varied (at {seen[name]}): "
                             f"remove one")
        check_value(name, value, where, model)
    for point, where in st.at:
        for name, value in point.items():
            _check_name(name, where, model, False)
            if name in seen or name in st.fixed:
                other = seen.get(name) or st.fixed[name][1]
                raise StudyError(f"{where}: {name} is in an operating point and also set or "
                                 f"varied (at {other}): remove one")
            _check_bounds(name, value, value, where, model, "operating point")
    for a in st.axes:
        _check_bounds(a.name, a.lo, a.hi, a.where, model, "range of")
    for r in st.ranges:
        _check_bounds(r.name, r.lo, r.hi, r.where, model, "range of")
    for d in st.dists:
        lo, hi = d.support()
        _check_bounds(d.name, lo, hi, d.where, model, "support of")
    for name in st.record:
        if name not in model.outputs:
            raise StudyError(f"{src}: record: '{name}' is not an output: "
                             f"{_near(name, list(model.outputs))}")
    metrics = [v.name for v in model.metrics] + st.record
    for e in st.exceed:
        if e.metric not in metrics:
            raise StudyError(f"{e.where}: '{e.metric}' is not a metric of this FMU: "
                             f"{_near(e.metric, metrics)}(metrics: "
                             f"{', '.join(metrics) or f'none: this FMU has no {METRIC_PREFIX}* outputs'})")
    _validate_kind(st)
    for name, value in STANDALONE.items():
        if name in model.parameters and name not in st.fixed and name not in seen:
            st.fixed[name] = (float(value), "default")
    return st


def _validate_kind(st):
    src = st.source
    if st.kind == "map":
        if len(st.axes) != 2:
            raise StudyError(f"{src}: a map needs two axes, --x NAME=LO:HI:COUNT and --y ...")
    elif st.kind == "doe":
        if not st.ranges:
            raise StudyError(f"{src}: a DOE needs at least one --param NAME=LO:HI")
        if st.design not in DESIGNS:
            raise StudyError(f"{src}: design '{st.design}': give lhs or full")
        if st.n < (2 if st.design == "full" else 1):
            raise StudyError(f"{src}: n = {st.n}: give --n >= 1 (lhs: points; full: levels "
                             f"per parameter, >= 2)")
    elif st.kind == "mc":
        if not st.dists:
            raise StudyError(f"{src}: a Monte Carlo needs at least one --dist "
                             f"NAME=normal:MEAN:SD (or uniform, lognormal, truncnormal)")
        if st.sensitivity not in SENSITIVITY:
            raise StudyError(f"{src}: sensitivity '{st.sensitivity}': give none, sobol or "
                             f"morris")
        if st.n < 1:
            raise StudyError(f"{src}: n = {st.n}: give --n >= 1")
        if st.sensitivity == "sobol" and st.n & (st.n - 1):
            raise StudyError(f"{src}: Sobol' sampling needs n a power of 2 (the base sample "
                             f"of Saltelli's scheme), e.g. --n {1 << max(st.n.bit_length() - 1, 1)}")
