"""The binary of a packed FMU starts from the model description it ships with (fmi2-shell's
packed.rs): FMI 3.0 as FMI 2.0, the FMI 3.0 gearbox's arrays as the FMI 2.0 gearbox's gears; a
description that is not its model's, or a GUID it does not name, is refused with the GUID
expected; an invalid start value is refused naming the parameter and its range."""

import zipfile

import numpy as np
import pytest

from gearrattle import gearbox_fmu as GF
from gearrattle.study import pack as P
from gearrattle.study.errors import StudyError
from gearrattle.study.model import read_model
from support.fmu import FMU3_PATH

NOT_FOUND = "no model description matching it was found beside the binary"


def _packed(fmu, out, values, edit=lambda xml: xml):
    """out: fmu packed with values {name: value}, its model description then edited."""
    with zipfile.ZipFile(fmu) as z:
        xml = z.read(P.XML).decode("utf-8")
    values = {n: (v, "test") for n, v in values.items()}
    P.write(fmu, out, edit(P.rewrite(xml, values, read_model(fmu))))
    return str(out)


def _refusal(fmu, guid=None):
    """What the binary logs when fmi2Instantiate refuses (the GUID of fmu's model description
    unless `guid`), through support.slave's recording logger."""
    from types import SimpleNamespace

    from fmpy import extract, read_model_description

    from support import slave

    md = read_model_description(fmu, validate=False)
    md = SimpleNamespace(guid=guid or md.guid, coSimulation=md.coSimulation)
    with pytest.raises(Exception, match="Failed to instantiate"):
        slave.Slave(extract(fmu), md, "packed")
    # The refused instance's lines, routed by its name (Slave appends a counter).
    names = [n for n in slave._RECORDERS if n.startswith("packed_")]
    return " ".join(m for n in names for _, _, m in slave._RECORDERS.pop(n))


def test_fmi3_packed_runs_its_start_values(tmp_path):
    from fmpy import read_model_description, simulate_fmu

    if not FMU3_PATH.is_file():
        pytest.fail(f"{FMU3_PATH} is missing: build it with `make fmu`")
    want = {"G": 4e-5, "A_rms": 400.0}
    out = _packed(FMU3_PATH, tmp_path / "packed3.fmu", want)
    assert (read_model_description(out).instantiationToken
            != read_model_description(FMU3_PATH).instantiationToken)
    kw = dict(stop_time=0.1, output_interval=1e-3, output=["xi", "stat_impacts_Fplus"])
    packed = simulate_fmu(out, **kw)
    told = simulate_fmu(str(FMU3_PATH), start_values=want, **kw)
    default = simulate_fmu(str(FMU3_PATH), **kw)
    assert np.array_equal(packed["xi"], told["xi"])
    assert not np.array_equal(packed["xi"], default["xi"])


# Four gears (the FMU's default is five): gear 1 given a backlash, gear 2 an inertia, gear 4
# nothing of its own.
BOX4 = """
[box]
k_1 = 22.0
[[gear]]
G = 110e-6
[[gear]]
I_L = 0.5e-3
[[gear]]
C_LM = 45.0
[[gear]]
"""


def _box(tmp_path, text):
    path = tmp_path / "box.toml"
    path.write_text(text)
    return str(path)


def test_fmi3_gearbox_packs_as_the_fmi2_gearbox(gearbox_fmu, gearbox_fmu3, tmp_path):
    """The FMI 3.0 gearbox packed with a box of four gears: n_gears 4, each per-gear array's
    start list the FMI 2.0 packed description's four gears', and co-simulation with no start
    values equal to the FMI 2.0 gearbox packed with the same box, to the bit."""
    from fmpy import read_model_description, simulate_fmu
    from fmpy.validation import validate_fmu

    box = _box(tmp_path, BOX4)
    out2, out3 = str(tmp_path / "box2.fmu"), str(tmp_path / "box3.fmu")
    P.pack(box, gearbox_fmu, out2)
    P.pack(box, gearbox_fmu3, out3)
    assert validate_fmu(out3) == []
    fmi2 = {v.name: v for v in read_model_description(out2).modelVariables}
    fmi3 = {v.name: v for v in read_model_description(out3).modelVariables}
    assert fmi3["n_gears"].start == fmi2["n_gears"].start == "4"
    arrays = [n for n, v in fmi3.items() if v.dimensions and v.start is not None]
    assert len(arrays) == 13
    for name in arrays:
        each = [float(fmi2[name.replace("gear.", f"gear[{i}].")].start) for i in range(1, 5)]
        assert [float(x) for x in fmi3[name].start.split()] == each, name
    assert fmi3["gear.G"].start.split()[0] == repr(110e-6)
    kw = dict(stop_time=0.1, output_interval=1e-3)
    run2 = simulate_fmu(out2, output=GF.outputs(4), **kw)
    run3 = simulate_fmu(out3, output=list(GF.BOX_OUTPUTS) + [f"gear.{f}" for f in GF.GEAR_OUTPUTS],
                        **kw)
    for name in GF.BOX_OUTPUTS:
        assert np.array_equal(run3[name], run2[name]), name
    for field in GF.GEAR_OUTPUTS:
        each = np.array([run2[f"gear[{i}].{field}"] for i in range(1, 5)]).T
        assert np.array_equal(run3[f"gear.{field}"], each), field
    default = simulate_fmu(gearbox_fmu3, output=["gear.xi"], **kw)
    assert default["gear.xi"].shape[1] == 5
    assert not np.array_equal(default["gear.xi"][:, 0], run3["gear.xi"][:, 0])


def test_fmi3_gearbox_needs_the_extra_gears_values(gearbox_fmu3, tmp_path):
    """The FMI 3.0 description gives the starts of its five default gears only: a sixth gear
    needs all its values from the box, and is refused naming the first one missing."""
    six = _box(tmp_path, BOX4 + "[[gear]]\n[[gear]]\nG = 1e-4\n")
    with pytest.raises(StudyError) as e:
        P.pack(six, gearbox_fmu3, str(tmp_path / "six.fmu"))
    said = str(e.value)
    assert "gear[6].I_L has no start value" in said and "give it in the box" in said, said
    assert not (tmp_path / "six.fmu").exists()


def test_a_tampered_description_is_refused(gearbox_fmu, tmp_path):
    guid = read_model(gearbox_fmu).guid
    renamed = _packed(gearbox_fmu, tmp_path / "renamed.fmu", {"k_1": 20.0},
                      lambda xml: xml.replace('name="k_1"', 'name="k_one"'))
    said = _refusal(renamed)
    assert guid in said and NOT_FOUND in said and "variable k_one" in said, said
    packed = _packed(gearbox_fmu, tmp_path / "packed.fmu", {"k_1": 20.0})
    said = _refusal(packed, guid="{00000000-0000-0000-0000-000000000000}")
    assert guid in said and NOT_FOUND in said and "it names GUID" in said, said


def test_an_invalid_start_value_is_refused_naming_it(gearbox_fmu, tmp_path):
    bad = _packed(gearbox_fmu, tmp_path / "bad.fmu", {"gear[2].G": -5e-6})
    said = _refusal(bad)
    assert "parameter gear[2].G = -5e-6 is invalid: allowed gear[2].G > 0" in said, said
