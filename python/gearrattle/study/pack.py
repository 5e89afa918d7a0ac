"""`gearrattle-study pack BOX.toml --out MyBox.fmu`: a copy of GearboxRattle.fmu whose start
values are the gearbox of BOX.toml (gearrattle.study.gearbox), so that a drivetrain tool runs
that gearbox with no setup.

Only modelDescription.xml changes: the `start` attributes of the named parameters and the GUID
(FMI 3.0: instantiationToken), every other byte as the generator wrote it; a copy of it goes to
resources/modelDescription.xml, where the binary finds it also when an importer unpacks only the
binaries and resources (fmpy's simulate_fmu); every other entry of the FMU (binaries,
documentation) is copied byte for byte. The GUID is a UUID derived from
the original's and the box's values, so the same box packed from the same FMU has the same
GUID and two boxes differ. The binary, given a GUID other than its built-in one, reads the
model description it ships with and takes its start values if that description names the GUID
and the binary's variables (fmi2-shell's packed.rs): an importer that sets no parameter runs
the packed box, and fmi2Reset returns to it.

FMI 3.0's GearboxRattle declares each per-gear parameter once, as an array sized by `n_gears`
(docs/DECISIONS.md D46): its start list gets n_gears values, the box's at its gears and the
FMU's elsewhere. That description lists the starts of its default gears only (1..5), so a box
of more gears gives each of the extra gears all its values (or packs the FMI 2.0 FMU)."""

import re
import uuid
import zipfile

from . import gearbox
from .errors import StudyError
from .model import read_model

XML = "modelDescription.xml"
# The model description's copy among the resources, which every importer unpacks.
RESOURCE_XML = "resources/" + XML


def _start_text(var, value):
    return repr(float(value)) if var.type == "Real" else str(int(value))


def packed_guid(guid, values):
    """The GUID of `guid`'s model packed with values {name: (value, where)}: a name-based UUID
    of both, in the original's braces."""
    text = guid + "".join(f";{n}={float(v)!r}" for n, (v, _) in sorted(values.items()))
    return "{" + str(uuid.uuid5(uuid.NAMESPACE_OID, text)) + "}"


def _start(name):
    """The pattern of the start attribute of the variable `name` (FMI 2.0 or 3.0): the text
    before its value, the value, the closing quote."""
    n = re.escape(name)
    return re.compile(r'((?:<ScalarVariable name="' + n + r'"[^>]*>\s*<(?:Real|Integer|'
                      r'Enumeration)\b|<(?:Float64|Int32|UInt64|Enumeration) name="' + n
                      + r'")[^>]*?\bstart=")([^"]*)(")')


def _replace_start(xml, name, where, text):
    """xml with the start of `name` replaced by text(its current start)."""
    xml, count = _start(name).subn(lambda m: m[1] + text(m[2]) + m[3], xml, count=1)
    if count != 1:
        raise StudyError(f"{where}: {name} has no start value in {XML} to replace")
    return xml


def _array_start(values, model, array, old):
    """The start list of the FMI 3.0 array parameter `array` (its start `old`, text) for
    values: one value per element up to its structural parameter's value (the box's, else
    the FMU's), each the box's or else the FMU's start (its text kept)."""
    size, elements = model.arrays[array]
    n, n_where = values.get(size, (model.parameters[size].start, XML))
    n = int(n)
    for name in elements[n:]:
        if name in values:
            raise StudyError(f"{values[name][1]}: {name} is past {size} = {n} ({n_where}): an "
                             f"FMI 3.0 array holds elements 1..{size} only")
    listed = old.split()
    starts = []
    for i, name in enumerate(elements[:n]):
        if name in values:
            starts.append(_start_text(model.parameters[name], values[name][0]))
        elif i < len(listed):
            starts.append(listed[i])
        else:
            raise StudyError(f"{n_where}: {name} has no start value in the FMI 3.0 {XML} "
                             f"(which gives elements 1..{len(listed)} of {array}): give it in "
                             f"the box, or pack the FMI 2.0 FMU, whose description has one")
    return " ".join(starts)


def rewrite(xml, values, model):
    """The model description (FMI 2.0 or 3.0) with the start values replaced and the packed
    GUID (text, not a re-serialized tree: attribute order, comments and spacing stay as the
    generator wrote them). FMI 3.0's array parameters get start lists as long as their
    structural parameter says, where that or one of their elements changes."""
    elements = {e: a for a, (_, names) in model.arrays.items() for e in names}
    for name, (value, where) in values.items():
        if name not in elements:
            xml = _replace_start(xml, name, where,
                                 lambda _: _start_text(model.parameters[name], value))
    for array, (size, names) in model.arrays.items():
        if size in values or any(n in values for n in names):
            xml = _replace_start(xml, array, XML,
                                 lambda old: _array_start(values, model, array, old))
    guid = re.compile(r'(<fmiModelDescription\b[^>]*?\b(?:guid|instantiationToken)=")[^"]*(")')
    return guid.sub(lambda m: m[1] + packed_guid(model.guid, values) + m[2], xml, count=1)


def pack(box, fmu, out):
    """Write out: fmu with box's start values. Validates everything before writing."""
    if not zipfile.is_zipfile(fmu):
        raise StudyError(f"no FMU at {fmu}: build it first (make fmu) or give --fmu PATH")
    model = read_model(fmu)
    values = gearbox.read(box)
    gearbox.check(values, model)
    with zipfile.ZipFile(fmu) as src:
        xml = rewrite(src.read(XML).decode("utf-8"), values, model)
    write(fmu, out, xml)
    return model, values


def write(fmu, out, xml):
    """Write out: fmu with the model description xml (text), at its place and in resources/."""
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(out, "w") as dst:
        for info in src.infolist():
            if info.filename != RESOURCE_XML:
                dst.writestr(info, xml.encode("utf-8") if info.filename == XML else src.read(info))
        md = src.getinfo(XML)
        copy = zipfile.ZipInfo(RESOURCE_XML, md.date_time)
        copy.compress_type = md.compress_type
        dst.writestr(copy, xml.encode("utf-8"))


def add_parser(sub):
    p = sub.add_parser("pack", help="a copy of GearboxRattle.fmu with a gearbox's start values")
    p.add_argument("gearbox", help="BOX.toml (e.g. examples/gearboxes/five_speed.toml)")
    p.add_argument("--fmu", default="target/fmu/GearboxRattle.fmu",
                   help="the FMU to copy (default target/fmu/GearboxRattle.fmu)")
    p.add_argument("--out", required=True, help="the FMU to write, e.g. MyBox.fmu")
    p.add_argument("--quiet", action="store_true", help="no message")


def main(a):
    model, values = pack(a.gearbox, a.fmu, a.out)
    if not a.quiet:
        print(f"{a.out}: {a.fmu} with {len(values)} start values of {a.gearbox} "
              f"(GUID {packed_guid(model.guid, values)})")
    return 0
