"""A bad study is refused before anything runs: exit code 2, a message naming the line (or the
flag) and the fix, and no results directory."""

import os

import pytest

from gearrattle.study import cli, spec
from gearrattle.study.errors import StudyError

GOOD = """\
kind = "mc"
out = "{out}"
fmu = "{fmu}"
n = 8
seed = 1
duration = 0.2

[set]
f_exc = 30.0
A_rms = 300.0

[dist]
G = "truncnormal:25e-6:1.7e-6:20e-6:30e-6"
C = "normal:0.025:0.0017"
"""

# (what is wrong, a replacement in GOOD, the line named, words of the message)
CASES = [
    ("unknown parameter", ('C = "normal', 'Cx = "normal'), 14, ["'Cx'", "not a parameter",
                                                               "did you mean C"]),
    ("value above the FMU's maximum", ("A_rms = 300.0", "A_rms = 300.0\nexcitation = 3"), 11,
     ["excitation = 3", "above the FMU's maximum 2", "keep excitation within"]),
    ("malformed TOML", ("n = 8", "n = 8 8"), 4, ["malformed TOML", "Fix the syntax"]),
    ("negative width", ("0.025:0.0017", "0.025:-0.0017"), 14, ["width must be positive",
                                                              "SD > 0"]),
    ("empty truncation interval", ("20e-6:30e-6", "30e-6:20e-6"), 13, ["empty interval",
                                                                      "LO < HI"]),
    ("unknown key", ("seed = 1", "sead = 1"), 5, ["unknown key 'sead'", "did you mean 'seed'"]),
]


@pytest.mark.parametrize("what, change, line, words", CASES, ids=[c[0] for c in CASES])
def test_bad_study_file_is_refused_before_running(what, change, line, words, fmu, tmp_path,
                                                   capsys):
    out = tmp_path / "results"
    text = GOOD.format(out=out, fmu=fmu)
    assert change[0] in text
    path = tmp_path / "study.toml"
    path.write_text(text.replace(change[0], change[1]))
    assert cli.main(["run", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"line {line}" in err, err
    for w in words:
        assert w in err, err
    assert not os.path.exists(out)


def test_good_study_file_runs(fmu, tmp_path):
    out = tmp_path / "results"
    path = tmp_path / "study.toml"
    path.write_text(GOOD.format(out=out, fmu=fmu))
    assert cli.main(["run", str(path), "--workers", "0", "--quiet"]) == 0
    assert os.path.isfile(out / "points.parquet")


@pytest.mark.parametrize("args, words", [
    (["map", "--x", "f_exc=60:30:4"], ["--x f_exc=60:30:4", "empty range", "LO < HI"]),
    (["doe", "--param", "G=3e-5:1e-5", "--n", "4"], ["--param G=3e-5:1e-5", "empty range"]),
    (["mc", "--dist", "G=uniform:3e-5:1e-5", "--n", "4"], ["negative or zero width",
                                                           "LO < HI"]),
    (["mc", "--dist", "g=normal:2e-5:1e-6", "--n", "4"], ["'g'", "did you mean G"]),
    (["map", "--set", "solver=7"], ["solver = 7", "maximum 2"]),
    (["map", "--set", "I_L=0"], ["--set I_L=0", "I_L = 0 kg.m2", "exclusive minimum 0",
                                 "keep I_L within its range I_L > 0"]),
    (["doe", "--param", "G=-1e-5:5e-5", "--n", "4"], ["--param G=-1e-5:5e-5", "G = -1e-05 m",
                                                       "keep G within its range G > 0"]),
    (["mc", "--dist", "K_star=uniform:0:3e6", "--n", "4"], ["K_star = 0", "K_star > 0"]),
    (["map", "--set", "alpha=0.99"], ["alpha = 0.99", "minimum 1", "alpha >= 1"]),
    (["mc", "--dist", "G=uniform:2e-5:3e-5", "--n", "4", "--set", "f_exc=30", "--at",
      "f_exc=40"], ["--at f_exc=40", "also set or varied", "remove one"]),
], ids=["map empty range", "doe empty range", "mc negative width", "unknown name",
        "above maximum", "at an exclusive minimum", "range across an exclusive minimum",
        "support at an exclusive minimum", "below an inclusive minimum",
        "set and operating point"])
def test_bad_flags_are_refused_before_running(args, words, fmu, tmp_path, capsys):
    out = tmp_path / "results"
    assert cli.main([*args, "--fmu", fmu, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    for w in words:
        assert w in err, err
    assert not os.path.exists(out)


def test_stats_from_on_an_fmu_without_it_is_refused(fmu):
    """--stats-from sets the FMU's stats_from; an FMU without that parameter is refused, not
    run with the window silently at 0 (the FMU read, then stats_from taken out of it)."""
    import dataclasses

    from gearrattle.study.model import read_model

    model = read_model(fmu)
    older = dataclasses.replace(model, parameters={k: v for k, v in model.parameters.items()
                                                   if k != "stats_from"})
    st = spec.Study(kind="map", fmu=fmu, out="unused", stats_from=(0.3, "--stats-from 0.3"))
    st.axes = [spec.parse_axis("f_exc=30:60:2", "--x"), spec.parse_axis("A_rms=100:700:2", "--y")]
    with pytest.raises(StudyError, match=r"--stats-from 0.3: this FMU has no parameter "
                                              r"stats_from.*make fmu"):
        spec.validate(st, older)


def test_empty_range_in_a_doe_file_is_refused(fmu, tmp_path, capsys):
    out = tmp_path / "results"
    path = tmp_path / "doe.toml"
    path.write_text(f'kind = "doe"\nout = "{out}"\nfmu = "{fmu}"\nn = 8\n'
                    f'param = ["G=10e-6:80e-6",\n         "C=0.05:0.005"]\n')
    assert cli.main(["run", str(path)]) == 2
    err = capsys.readouterr().err
    assert "line 6" in err and "empty range C" in err and "LO < HI" in err, err
    assert not os.path.exists(out)


def test_values_at_inclusive_bounds_and_just_inside_exclusive_ones_pass(fmu):
    """The bounds the study checks are the FMU's: alpha = 1 and C = 0 are allowed, and so is
    the smallest positive I_L (I_L > 0 admits every positive double)."""
    from gearrattle.study.model import read_model

    st = spec.Study(kind="map", fmu=fmu, out="unused")
    st.axes = [spec.parse_axis("f_exc=30:60:2", "--x"), spec.parse_axis("A_rms=100:700:2", "--y")]
    st.fixed = {"alpha": (1.0, "--set"), "C": (0.0, "--set"), "I_L": (5e-324, "--set")}
    spec.validate(st, read_model(fmu))


@pytest.mark.parametrize("name, description, xml, want", [
    ("T_oil", "Oil temperature (range: T_oil > -95)", (-94.99999999999999, None),
     (-95.0, True, None, False)),
    ("n_gears", "Number of loose gears (range: 1 <= n_gears <= 8)", (1.0, 8.0),
     (1.0, False, 8.0, False)),
    ("gear[3].I_L", "Moment of inertia (range: gear[3].I_L > 0)", (5e-324, None),
     (0.0, True, None, False)),
    ("x", "An upper bound only (range: x < 1e-6)", (None, 9.999999999999999e-07),
     (None, False, 1e-6, True)),
    # No statement, or one about another name: the XML's min and max, inclusive.
    ("C", "Viscous drag", (0.0, None), (0.0, False, None, False)),
    ("C", "Viscous drag (range: G > 0)", (0.0, None), (0.0, False, None, False)),
])
def test_ranges_are_read_from_the_description_statement(name, description, xml, want):
    from gearrattle.study.model import _range

    assert _range(name, description, *xml) == want
