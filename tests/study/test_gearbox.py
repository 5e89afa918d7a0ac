"""Studies of GearboxRattle.fmu: a gearbox TOML packed into an FMU that runs it with no setup,
bad gearbox files refused with their fix, a small map with every gear's columns and the figure
of which gear rattles where."""

import os
import re
import zipfile

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from gearrattle.study import pack as P
from gearrattle.study.errors import StudyError
from gearrattle.study.model import read_model
from support.study import study

# A three-speed box far from the FMU's defaults (five gears, k_1 = 28.6 N m/rad, G = 60-80 µm).
BOX = """
[box]
k_1 = 20.0
phi_1 = 0.07
I_I = 0.01

[[gear]]
I_L = 0.9e-3
G = 120e-6

[[gear]]
G = 50e-6

[[gear]]
C_LM = 40.0
"""
WANT = {"n_gears": 3, "k_1": 20.0, "phi_1": 0.07, "I_I": 0.01, "gear[1].I_L": 0.9e-3,
        "gear[1].G": 120e-6, "gear[2].G": 50e-6, "gear[3].C_LM": 40.0}
OUT = ["phi", "stat_rattle_power", "gear[1].xi", "gear[2].xi", "gear[3].xi"]


def _box(tmp_path, text=BOX):
    path = tmp_path / "box.toml"
    path.write_text(text)
    return str(path)


def test_pack_runs_the_gearbox_with_no_setup(gearbox_fmu, tmp_path):
    from fmpy import read_model_description, simulate_fmu
    from fmpy.validation import validate_fmu

    out = str(tmp_path / "MyBox.fmu")
    study("pack", _box(tmp_path), "--fmu", gearbox_fmu, "--out", out)
    assert not validate_fmu(out)
    starts = {v.name: v.start for v in read_model_description(out).modelVariables}
    for name, value in WANT.items():
        assert float(starts[name]) == value, name
    # The packed FMU, given no start values, runs as the original told the TOML's values, in
    # both interfaces (the binary starts from the model description it ships with).
    kw = dict(stop_time=0.2, output_interval=1e-3, output=OUT)
    for interface in ("CoSimulation", "ModelExchange"):
        packed = simulate_fmu(out, fmi_type=interface, **kw)
        told = simulate_fmu(gearbox_fmu, fmi_type=interface, start_values=WANT, **kw)
        for name in OUT:
            assert np.array_equal(packed[name], told[name]), (interface, name)
    default = simulate_fmu(gearbox_fmu, **kw)
    assert not np.array_equal(packed["gear[1].xi"], default["gear[1].xi"])
    # Every other entry is the original's, byte for byte, beside the description's copy among
    # the resources; the GUID is the box's own, the same for the same box.
    with zipfile.ZipFile(gearbox_fmu) as a, zipfile.ZipFile(out) as b:
        assert b.namelist() == a.namelist() + [P.RESOURCE_XML]
        for name in a.namelist():
            if name != P.XML:
                assert a.read(name) == b.read(name), name
        assert b.read(P.RESOURCE_XML) == b.read(P.XML)
    again = str(tmp_path / "again.fmu")
    P.pack(_box(tmp_path), gearbox_fmu, again)
    other = str(tmp_path / "other.fmu")
    P.pack(_box(tmp_path, BOX.replace("k_1 = 20.0", "k_1 = 21.0")), gearbox_fmu, other)
    guids = [read_model(f).guid for f in (gearbox_fmu, out, again, other)]
    assert guids[1] == guids[2] and len(set(guids)) == 3, guids
    # A study of the packed FMU (its instances reset between points) is the original's told
    # the TOML's values, under the packed FMU's GUID.
    for fmu, extra in ((out, []), (gearbox_fmu, [f"--set={n}={v}" for n, v in WANT.items()])):
        study("map", "--fmu", fmu, "--x", "rpm=800:900:2", "--y", "T_oil=40:40:1",
              "--duration", "0.4", "--workers", "0", "--out", tmp_path / fmu[-8:], *extra)
    a_, b_ = (pq.read_table(tmp_path / fmu[-8:] / "points.parquet").drop(["cpu_s", "point_id"])
              for fmu in (out, gearbox_fmu))
    shared = [c for c in b_.column_names if c not in WANT and c != "guid"]
    assert a_.select(shared).equals(b_.select(shared)), "the packed FMU's study differs"
    assert set(a_["guid"].to_pylist()) == {guids[1]}


@pytest.mark.parametrize("text,named,fix", [
    (BOX.replace("G = 50e-6", "G = -5e-6"), "gear[2].G", "keep gear[2].G within its range"),
    (BOX.replace("C_LM = 40.0", "backlash = 1e-4"), "gear[3].backlash", "did you mean"),
    (BOX.replace("k_1 = 20.0", "k_1 = \"soft\""), "k_1", "must be a number"),
    ("[box]\nn_gears = 2\n" + BOX.partition("[[gear]]")[1] + BOX.partition("[[gear]]")[2],
     "n_gears", "remove n_gears"),
    ("[[gear]]\nG = 1e-4\n" * 9, "n_gears", "keep n_gears within its range"),
])
def test_a_bad_gearbox_is_refused_with_its_fix(gearbox_fmu, tmp_path, text, named, fix):
    out = tmp_path / "MyBox.fmu"
    with pytest.raises(StudyError) as e:
        P.pack(_box(tmp_path, text), gearbox_fmu, str(out))
    assert named in str(e.value) and fix in str(e.value), str(e.value)
    assert "box.toml" in str(e.value)
    assert not out.exists()


def test_the_example_gearbox_is_the_documented_default(gearbox_fmu):
    """five_speed.toml describes GEARBOX.md §6's box: the FMU's own defaults."""
    from gearrattle.study import gearbox

    model = read_model(gearbox_fmu)
    root = os.path.dirname(os.path.dirname(os.path.dirname(__file__)))
    values = gearbox.read(os.path.join(root, "examples", "gearboxes", "five_speed.toml"))
    gearbox.check(values, model)
    for name, (value, _) in values.items():
        assert value == pytest.approx(model.parameters[name].start, rel=1e-12), name


def test_gearbox_map_has_every_gear_and_the_gear_figure(gearbox_fmu, tmp_path):
    from gearrattle.study import figures, spec

    out = str(tmp_path / "map")
    study("map", "--fmu", gearbox_fmu, "--x", "rpm=700:900:3", "--y", "T_oil=20:60:2",
          "--duration", "0.6", "--set", "n_gears=3", "--workers", "0", "--out", out)
    table = pq.read_table(os.path.join(out, "points.parquet"))
    for i in (1, 2, 3):
        assert f"gear[{i}].stat_rattle_power" in table.column_names
        assert f"gear[{i}].stat_impact_rate_Fplus" in table.column_names
    assert os.path.isfile(os.path.join(out, "map_gears.png"))
    st = spec.Study(kind="map", fmu=gearbox_fmu, out=out, duration=0.6,
                    axes=[spec.parse_axis("rpm=700:900:3", "x"),
                          spec.parse_axis("T_oil=20:60:2", "y")])
    plt, fig = figures.gear_figure(st, read_model(gearbox_fmu), table, [1, 2, 3])
    panels = [ax for ax in fig.axes if ax.get_title()]
    assert [ax.get_title() for ax in panels] == ["gear 1", "gear 2", "gear 3",
                                                 "the box (all gears)"]
    assert all(ax.get_xlabel() == "rpm [rpm]" and ax.get_ylabel() == "T_oil [°C]"
               for ax in panels)
    assert "stat_rattle_power [W]" in [ax.get_ylabel() for ax in fig.axes]  # the colour bar
    plt.close(fig)


def test_figures_say_what_they_show(fmu, tmp_path):
    """The paper map of GearRattle.fmu: titles in words, units from the model description on
    every axis and colour bar, no folder path, no panel for a metric constant over the map."""
    from gearrattle.study import figures, report, spec

    out = str(tmp_path / "map")
    study("map", "--fmu", fmu, "--x", "f_exc=30:60:3", "--y", "A_rms=100:700:3",
          "--duration", "0.5", "--workers", "0", "--out", out)
    table = pq.read_table(os.path.join(out, "points.parquet"))
    model = read_model(fmu)
    metrics = [v.name for v in model.metrics]
    constant = table.set_column(table.column_names.index("stat_rattle_power"),
                                "stat_rattle_power", pa.array([0.25] * table.num_rows))
    drawn = report.figure_metrics(constant, metrics, [])
    assert "stat_rattle_power" not in drawn and "stat_impact_rate_Fplus" in drawn
    st = spec.Study(kind="map", fmu=fmu, out=out, duration=0.5,
                    axes=[spec.parse_axis("f_exc=30:60:3", "x"),
                          spec.parse_axis("A_rms=100:700:3", "y")])
    drawn = report.figure_metrics(table, metrics, [])
    plt, fig = figures.map_figure(st, model, table, drawn)
    panels = [ax for ax in fig.axes if ax.get_title()]
    assert [ax.get_title() for ax in panels] == [
        re.sub(" (in|over) the window$", "", model.outputs[m].description.split(":")[0]
               .split(" (")[0])
        for m in drawn]
    assert {ax.get_xlabel() for ax in panels} == {"f_exc [Hz]"}
    assert {ax.get_ylabel() for ax in panels} == {"A_rms [rad/s²]"}
    bars = {ax.get_ylabel() for ax in fig.axes if not ax.get_title()}
    assert "stat_impact_rate_Fplus [impacts/s]" in bars
    if "stat_rattle_power" in drawn:
        assert "stat_rattle_power [W]" in bars
    if "stat_a_rms" in drawn:
        assert "stat_a_rms [m/s²]" in bars
    assert out not in fig._suptitle.get_text()
    plt.close(fig)


def test_a_study_file_names_its_gearbox(tmp_path):
    """`gearbox = "BOX.toml"`: the box's values are the study's start values, under what the
    study varies or sets itself."""
    from gearrattle.study import cli

    path = tmp_path / "study.toml"
    path.write_text(f'kind = "doe"\nfmu = "x.fmu"\nout = "o"\ngearbox = "{_box(tmp_path)}"\n'
                    f'param = ["k_1=15:25"]\nset = {{ I_I = 0.02 }}\nn = 2\n')
    st = cli.from_args(cli.parser().parse_args(["run", str(path)]))
    fixed = {n: v for n, (v, _) in st.fixed.items()}
    assert fixed == {**{n: v for n, v in WANT.items() if n != "k_1"}, "I_I": 0.02}
