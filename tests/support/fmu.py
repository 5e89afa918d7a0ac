"""The built FMUs and GearRattle's contract as the FMU tests read them, and the main-shaft
input signal that drives the FMU in input mode."""

import pathlib
import tomllib

import numpy as np
import pytest

from gearrattle import reference as R

ROOT = pathlib.Path(__file__).resolve().parents[2]
FMU_PATH = ROOT / "target" / "fmu" / "GearRattle.fmu"
# How to build it, as a missing build's failure says.
BUILD_FMU = "`make fmu` (or `cargo run --release -p packaging -- --model GearRattle`)"
CONTRACT_PATH = ROOT / "modelDescription" / "GearRattle.toml"


def contract_outputs() -> list:
    """Every output of the contract, in its order: the FMU runs record them all, so an output
    added to modelDescription/GearRattle.toml is recorded without an edit here."""
    with open(CONTRACT_PATH, "rb") as f:
        return [v["name"] for v in tomllib.load(f)["variable"] if v["causality"] == "output"]


OUTPUTS = contract_outputs()


def main_shaft_input(scene: str, t_end: float, dt: float = 1e-4, fields=("theta_M", "omega_M", "alpha_M"), **overrides):
    """Structured input array for fmpy: the analytic sine motion of the main shaft (§5)."""
    p = R.params(scene, **overrides)
    n = int(round(t_end / dt))
    t = np.arange(n + 1) * dt
    th, om, al = R.main_shaft(t, p)
    values = {"theta_M": th, "omega_M": om, "alpha_M": al}
    sig = np.zeros(t.size, dtype=[("time", np.float64)] + [(f, np.float64) for f in fields])
    sig["time"] = t
    for f in fields:
        sig[f] = values[f]
    return sig


FMU3_PATH = ROOT / "target" / "fmu" / "fmi3" / "GearRattle.fmu"
BUILD_FMU3 = "`make fmu` (or `cargo run --release -p packaging -- --model GearRattle --fmi 3`)"


def require(path: pathlib.Path, build: str) -> str:
    """`path` as a string. A missing FMU FAILS the test (never skips it) with how to build it
    (`build`, e.g. "`make fmu`"), so that a missing build cannot pass silently."""
    if not path.is_file():
        pytest.fail(f"{path} does not exist: build it first with {build}, then rerun the tests", pytrace=False)
    return str(path)


def session_fixtures(path: pathlib.Path, build: str, names: tuple):
    """The session fixtures of the FMU at `path`, named `names`: its path ([`require`]), its
    model description (read with FMPy's validation: its checks and the XML schema), its
    extracted directory and, where `names` has a fourth, its value references by name. A conftest or test module
    binds them: `fmu_path, md, unzipdir, vrs = session_fixtures(...)`."""
    path_name, md_name, unzip_name, *vrs_name = names

    @pytest.fixture(scope="session", name=path_name)
    def fmu_path() -> str:
        return require(path, build)

    @pytest.fixture(scope="session", name=md_name)
    def model_description(request):
        from fmpy import read_model_description

        return read_model_description(request.getfixturevalue(path_name))

    @pytest.fixture(scope="session", name=unzip_name)
    def unzipdir(request, tmp_path_factory) -> str:
        from fmpy import extract

        return extract(request.getfixturevalue(path_name), unzipdir=str(tmp_path_factory.mktemp(f"{path.stem}_fmu")))

    if not vrs_name:
        return fmu_path, model_description, unzipdir

    @pytest.fixture(scope="session", name=vrs_name[0])
    def vrs(request) -> dict:
        """name -> value reference."""
        return {v.name: v.valueReference for v in request.getfixturevalue(md_name).modelVariables}

    return fmu_path, model_description, unzipdir, vrs
