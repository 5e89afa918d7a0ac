"""The work-precision benchmark's paths, targets and the names of its suites and solvers, as
the CSVs of `make bench` spell them."""

import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[3]
BENCH = ROOT / "target" / "bench"
TARGET = 1e-9  # m: the error at which the targets are set (S1)
GR = "GearRattle (direct)"
EQUAL_SUITE = "rust-equal-error"
FMU_C = "GearRattle FMU (C API)"
STEPS = "GearRattle Simulation::step_to (no FMI)"
FMPY = "GearRattle FMU (fmpy)"
# Two kinds of Rust peer (benches/work_precision/peers.rs): the crates on GearRattle's RHS with
# GearRattle's edge handling (an integrator comparison), and the crates as users write them
# from docs/MODEL.md (their own literal RHS, region from xi at each call, no edge handling).
SAME_RHS = ["differential-equations DOPRI5", "differential-equations DOP853", "diffsol Tsit45"]
USER_RHS = [f"{n} (user's RHS)" for n in SAME_RHS]  # no comma: the CSV is not quoted
RUST_PEERS = SAME_RHS + USER_RHS
SCIPY = ["scipy RK45", "scipy DOP853", "scipy Radau", "scipy LSODA"]
COMM_LABEL = {1e-2: "10 ms", 1e-3: "1 ms", 1e-4: "0.1 ms", 1e-5: "10 us"}
