"""The binary of a packed FMU starts from the model description it ships with (fmi2-shell's
packed.rs): FMI 3.0 as FMI 2.0; a description that is not its model's, or a GUID it does not
name, is refused with the GUID expected; an invalid start value is refused naming the parameter
and its range."""

import zipfile

import numpy as np
import pytest

from gearrattle.study import pack as P
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
