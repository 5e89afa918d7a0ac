"""The GearboxRattle FMU as its tests run it (gearrattle.gearbox_fmu) and what they compare
with the reference."""

import hashlib
import inspect
import os
import pickle

import numpy as np

from gearrattle import gearbox_fmu as GF
from gearrattle import gearbox_reference as R
from gearrattle import piecewise
from gearrattle import reference as gear_reference

GEARBOX_FMU_PATH = GF.GEARBOX_FMU
BUILD_GEARBOX_FMU = (
    "`make fmu` (or `cargo build --release -p gearbox_rattle_fmu && cargo run --profile quick "
    "-p packaging -- --model GearboxRattle --lib target/release/libgearbox_rattle_fmu.so --out target/fmu/GearboxRattle.fmu`)"
)
GEARBOX_FMU3_PATH = GF.ROOT / "target" / "fmu" / "fmi3" / "GearboxRattle.fmu"
BUILD_GEARBOX_FMU3 = (
    "`make fmu` (or `cargo build --release -p gearbox_rattle_fmu && cargo run --profile quick -p packaging -- "
    "--model GearboxRattle --fmi 3 --lib target/release/libgearbox_rattle_fmu.so --out target/fmu/fmi3/GearboxRattle.fmu`)"
)
# Each scene's pointwise-predictable window [s] (the reference's own perturbed runs: a 1e-10 G
# difference grows to 1e-4 G past it) and the rate spread of its perturbed runs beyond.
WINDOW = {"B1": 0.35, "R1": 0.40, "B2": 2.0}
RATE_SPREAD = np.array([0.10, 0.05, 0.05, 0.05, 0.05])


CACHE = GF.ROOT / "target" / "test-cache" / "gearbox_reference"


def reference_scene(scene: str, t_end: float, dt: float) -> R.Result:
    """R.scene(scene, t_end, dt), kept on disk under target/test-cache between sessions (its
    2 s scenes cost some 80 s): the key holds the source of both reference modules and of
    their piecewise integration, so that an edit of the reference recomputes it."""
    source = "".join(inspect.getsource(m) for m in (R, gear_reference, piecewise))
    key = hashlib.sha256(f"{source}|{scene}|{t_end!r}|{dt!r}".encode()).hexdigest()[:20]
    path = CACHE / f"{scene}-{key}.pickle"
    if path.is_file():
        with open(path, "rb") as f:
            return pickle.load(f)
    res = R.scene(scene, t_end, dt)
    CACHE.mkdir(parents=True, exist_ok=True)
    # Written aside, then renamed: a run started meanwhile never reads half a file.
    part = path.with_suffix(f".{os.getpid()}.part")
    with open(part, "wb") as f:
        pickle.dump(res, f)
    os.replace(part, path)
    return res


def gearbox_run(unzipdir, md, t_end, dt, fmi_type, tol, inputs, **start):
    return GF.simulate(unzipdir, t_end, dt, fmi_type, tol, inputs, model_description=md, **start)


def scene_start(scene: str) -> dict:
    """The FMU's start values of a reference scene (its overrides of the contract's defaults)."""
    return dict(R.SCENES[scene])


def counts_away_from_impacts(ref: R.Result, t: np.ndarray, counts: np.ndarray, margin: float = 1e-6):
    """The reference's cumulative impact counts per gear at the sample times t, and the FMU's
    `counts` there, leaving out the samples within `margin` of a reference impact (where the
    two may straddle it by the time tolerance)."""
    near = np.zeros(t.size, dtype=bool)
    for d in ref.impacts:
        k = np.searchsorted(t, d["t"])
        for j in (k - 1, k):
            ok = (j >= 0) & (j < t.size)
            near[j[ok][np.abs(t[j[ok]] - d["t"][ok]) < margin]] = True
    return ref.impact_counts(t)[:, ~near], counts[:, ~near]
