"""A gearbox described once in a TOML file (examples/gearboxes/five_speed.toml): the box's
parameters in [box], each loose gear's in one [[gear]] table (gear 1 first), under the names of
GearboxRattle's contract. Studies take its values as their fixed start values (`gearbox = ...`
in a study file, `--gearbox` on the command line); `pack` writes them into an FMU."""

from .errors import StudyError

GEAR_COUNT = "n_gears"


def _where(path, lines, key, table=None):
    """'path line N' of the key's first line inside the table's text (or anywhere)."""
    start = 0
    if table is not None:
        heads = [i for i, t in enumerate(lines) if t.strip().startswith(table[0])]
        start = heads[table[1]] if table[1] < len(heads) else 0
    for i in range(start, len(lines)):
        if lines[i].split("=", 1)[0].strip() == key:
            return f"{path} line {i + 1}"
    return str(path)


def read(path):
    """The gearbox's start values {name: (value, where)}, n_gears counted from its [[gear]]
    tables. Raises StudyError naming the line and the fix for what is not a gearbox file."""
    from .spec import load_toml

    doc, text = load_toml(path, "gearbox")
    lines = text.splitlines()
    unknown = [k for k in doc if k not in ("box", "gear")]
    if unknown:
        raise StudyError(f"{_where(path, lines, unknown[0])}: '{unknown[0]}' is neither [box] "
                         f"nor [[gear]]: put the box's parameters under [box] and each loose "
                         f"gear's under its own [[gear]]")
    box, gears = doc.get("box", {}), doc.get("gear", [])
    if not isinstance(box, dict) or not isinstance(gears, list):
        raise StudyError(f"{path}: write the box as a table [box] and the gears as [[gear]] "
                         f"tables (double brackets), one per loose gear")
    values = {}

    def put(name, value, where):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise StudyError(f"{where}: {name} = {value!r} must be a number (SI units, as the "
                             f"contract states them)")
        values[name] = (float(value), where)

    for key, value in box.items():
        if key.startswith("gear["):
            raise StudyError(f"{_where(path, lines, key, ('[box]', 0))}: {key} belongs in its "
                             f"[[gear]] table (as {key.partition('.')[2] or 'NAME'} = ...)")
        put(key, value, _where(path, lines, key, ("[box]", 0)))
    for i, gear in enumerate(gears):
        for key, value in gear.items():
            put(f"gear[{i + 1}].{key}", value, _where(path, lines, key, ("[[gear]]", i)))
    if gears:
        given = values.get(GEAR_COUNT)
        if given and given[0] != len(gears):
            raise StudyError(f"{given[1]}: n_gears = {given[0]:g} but the file describes "
                             f"{len(gears)} [[gear]] tables: remove n_gears (it is the number "
                             f"of [[gear]] tables) or add the missing gears")
        values[GEAR_COUNT] = (float(len(gears)), f"{path}: its {len(gears)} [[gear]] tables")
    return values


def check(values, model):
    """Refuse values the FMU does not take, with the range and the fix (spec's checks)."""
    from .spec import check_value

    # the gear count first: nine [[gear]] tables are one too many, not an unknown gear[9]
    for name in sorted(values, key=lambda n: n != GEAR_COUNT):
        check_value(name, *values[name], model)


def apply(st, path):
    """The gearbox's values as the study's fixed start values."""
    underlay(st, read(path))


def underlay(st, entries):
    """Start values {name: (value, where)} as the study's fixed ones, under what the study sets,
    varies or samples itself."""
    mine = set(st.fixed) | set(st.varied()) | {n for point, _ in st.at for n in point}
    for name, entry in entries.items():
        if name not in mine:
            st.fixed[name] = entry
