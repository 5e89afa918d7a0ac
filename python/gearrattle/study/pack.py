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
the packed box, and fmi2Reset returns to it."""

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
    return repr(float(value)) if var.type in ("Real", "Float64") else str(int(value))


def packed_guid(guid, values):
    """The GUID of `guid`'s model packed with values {name: (value, where)}: a name-based UUID
    of both, in the original's braces."""
    text = guid + "".join(f";{n}={float(v)!r}" for n, (v, _) in sorted(values.items()))
    return "{" + str(uuid.uuid5(uuid.NAMESPACE_OID, text)) + "}"


def rewrite(xml, values, model):
    """The model description (FMI 2.0 or 3.0) with the start values replaced and the packed
    GUID (text, not a re-serialized tree: attribute order, comments and spacing stay as the
    generator wrote them)."""
    for name, (value, where) in values.items():
        n = re.escape(name)
        pattern = re.compile(r'((?:<ScalarVariable name="' + n + r'"[^>]*>\s*<(?:Real|Integer|'
                             r'Enumeration)\b|<(?:Float64|Int32|Enumeration) name="' + n
                             + r'")[^>]*?\bstart=")[^"]*(")')
        xml, count = pattern.subn(lambda m: m[1] + _start_text(model.parameters[name], value)
                                  + m[2], xml, count=1)
        if count != 1:
            raise StudyError(f"{where}: {name} has no start value in {XML} to replace")
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
