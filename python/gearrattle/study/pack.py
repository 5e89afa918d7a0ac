"""`gearrattle-study pack BOX.toml --out MyBox.fmu`: a copy of GearboxRattle.fmu whose start
values are the gearbox of BOX.toml (gearrattle.study.gearbox), so that a drivetrain tool runs
that gearbox with no setup.

Only the `start` attributes of the named parameters in modelDescription.xml change; every other
entry of the FMU (binaries, documentation) is copied byte for byte, and so is every other byte
of the XML. The GUID stays: the binary accepts at fmi2Instantiate only the GUID it was built
with (fmi2-shell's check_token against Identity.guid), so a new GUID would make the packed FMU
refuse to instantiate. Two packed FMUs of one build therefore share a GUID; tell them apart by
their file name.

The binary starts from its built-in defaults and does not read the model description: the
gearbox runs where the importer sets the parameters from the model description's start values,
as drivetrain tools do when they show an FMU's parameters (fmpy does so only when given them as
start_values). An importer that sets no parameter gets the default five-speed box."""

import re
import zipfile

from . import gearbox
from .errors import StudyError
from .model import read_model

XML = "modelDescription.xml"


def _start_text(var, value):
    return str(int(value)) if var.type != "Real" else repr(float(value))


def rewrite(xml, values, model):
    """The model description with the start values replaced (text, not a re-serialized tree:
    attribute order, comments and spacing stay as the generator wrote them)."""
    for name, (value, where) in values.items():
        pattern = re.compile(r'(<ScalarVariable name="' + re.escape(name)
                             + r'"[^>]*>\s*<(?:Real|Integer|Boolean|Enumeration)\b[^>]*?\bstart=")'
                             r'[^"]*(")')
        xml, n = pattern.subn(lambda m: m[1] + _start_text(model.parameters[name], value) + m[2],
                              xml, count=1)
        if n != 1:
            raise StudyError(f"{where}: {name} has no start value in {XML} to replace")
    return xml


def pack(box, fmu, out):
    """Write out: fmu with box's start values. Validates everything before writing."""
    if not zipfile.is_zipfile(fmu):
        raise StudyError(f"no FMU at {fmu}: build it first (make fmu) or give --fmu PATH")
    model = read_model(fmu)
    values = gearbox.read(box)
    gearbox.check(values, model)
    with zipfile.ZipFile(fmu) as src:
        xml = rewrite(src.read(XML).decode("utf-8"), values, model)
        with zipfile.ZipFile(out, "w") as dst:
            for info in src.infolist():
                data = xml.encode("utf-8") if info.filename == XML else src.read(info)
                dst.writestr(info, data)
    return model, values


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
              f"(GUID {model.guid}, kept: the binary checks it)")
    return 0


def packed_starts(fmu, model):
    """{name: start} of the parameters whose start value in the FMU's model description is not
    the binary's built-in one (a packed FMU's gearbox), read from an instance in initialization
    mode. The study runner sets them at every point, as a drivetrain tool would."""
    import shutil
    import tempfile

    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave

    path = extract(fmu, unzipdir=tempfile.mkdtemp(prefix="gearrattle-pack-"))
    try:
        slave = FMU2Slave(guid=model.guid, unzipDirectory=path,
                          modelIdentifier=model.model_identifier, instanceName="starts")
        slave.instantiate()
        try:
            slave.setupExperiment(startTime=0.0)
            slave.enterInitializationMode()
            real = [v for v in model.parameters.values() if v.type == "Real"]
            ints = [v for v in model.parameters.values() if v.type != "Real"]
            built_in = dict(zip((v.name for v in real), slave.getReal([v.vr for v in real])))
            built_in.update(zip((v.name for v in ints), slave.getInteger([v.vr for v in ints])))
        finally:
            slave.freeInstance()
    finally:
        shutil.rmtree(path, ignore_errors=True)
    return {n: v.start for n, v in model.parameters.items()
            if v.start is not None and built_in[n] != v.start}
