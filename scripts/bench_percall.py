"""make bench-percall: what one call at 10 µs communication steps costs GearRattle on S1, against
the Reference FMU Dahlquist (modelica/Reference-FMUs) in the same C harness
(benches/overhead/overhead.c with `each`): fmi2DoStep, then fmi2GetReal of the outputs, at
every step; both FMUs alternating, the median over the rounds. Prints the figures and their
ratio; makes no timed assertion.

    .venv/bin/python scripts/bench_percall.py --fmu target/fmu/host/GearRattle.fmu \\
        --reference target/bench/percall/build/fmus/Dahlquist.fmu

Cases: Dahlquist reading its output x; GearRattle reading ξ and ξ' (its state, as Dahlquist's
x is); GearRattle reading every Real output. The CPU per call is a run's CPU over its number
of calls (initialization included, a few µs in 100 000 calls). The same cases at --coarse steps
give what the integration costs GearRattle; less that, the call's own cost. With
--instructions, each case runs once more alone under callgrind (valgrind), which counts the
instructions executed inside fmi2DoStep and fmi2GetReal: a measure the machine's load does
not move.
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import zipfile

from bench_overhead import S1, description, instructions, line


def fmu(path, into):
    """An FMU's linux64 library (extracted under `into`), its GUID, its variables and the
    names of its Real outputs."""
    with zipfile.ZipFile(path) as z:
        z.extractall(into)
    root, guid, variables = description(os.path.join(into, "modelDescription.xml"))
    identifier = root.find("CoSimulation").get("modelIdentifier")
    lib = os.path.join(into, "binaries", "linux64", identifier + ".so")
    if not os.path.exists(lib):
        sys.exit(f"{path}: no binaries/linux64/{identifier}.so")
    outputs = [v.get("name") for v in root.iter("ScalarVariable")
               if v.get("causality") == "output" and v.find("Real") is not None]
    return (lib, guid, variables), outputs


def timed(harness, lines, a, step):
    """The median CPU of one trajectory of each case at communication step `step` [s]."""
    argv = [harness, str(a.rounds), str(a.repeats), str(a.duration), str(step), str(a.tolerance),
            "each"]
    out = subprocess.run(argv, input="".join(lines), capture_output=True, text=True, check=True)
    times, values = {}, {}
    for row in out.stdout.splitlines():
        kind, label, *rest = row.split()
        if kind == "time":
            times.setdefault(label, []).append(float(rest[0]))
        else:
            values[label] = rest
    return {k: statistics.median(v) for k, v in times.items()}, values


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fmu", default="target/fmu/host/GearRattle.fmu")
    ap.add_argument("--reference", action="append", required=True, metavar="LABEL=FMU",
                    help="a build of the Reference FMU Dahlquist.fmu (FMI 2.0); repeatable")
    ap.add_argument("--harness", default="target/bench/overhead")
    ap.add_argument("--duration", type=float, default=1.0)
    ap.add_argument("--step", type=float, default=1e-5, help="communication step [s]")
    ap.add_argument("--coarse", type=float, default=1e-2,
                    help="communication step of the integration's share [s]")
    ap.add_argument("--tolerance", type=float, default=1e-5)
    ap.add_argument("--rounds", type=int, default=31)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--instructions", action="store_true",
                    help="also count each case's instructions under callgrind (needs valgrind)")
    a = ap.parse_args()
    references = [r.split("=", 1) for r in a.reference]
    with tempfile.TemporaryDirectory() as tmp:
        gear, gear_outputs = fmu(a.fmu, os.path.join(tmp, "GearRattle"))
        cases = [(label, "x", fmu(path, os.path.join(tmp, label))[0], {}, ["x"])
                 for label, path in references]
        cases += [("GearRattle", "xi, xi_dot", gear, S1, ["xi", "xi_dot"]),
                  ("GearRattle-all", f"its {len(gear_outputs)} Real outputs", gear, S1, gear_outputs)]
        lines = [line(label, *lib, start, (reads, [])) + "\n" for label, _, lib, start, reads in cases]
        fine, values = timed(a.harness, lines, a, a.step)
        coarse, _ = timed(a.harness, lines, a, a.coarse)
        run = [str(a.duration), str(a.step), str(a.tolerance), "each"]
        functions = ("fmi2DoStep", "fmi2GetReal")
        counted = {label: instructions(a.harness, x, run, functions) if a.instructions else 0
                   for (label, *_), x in zip(cases, lines)}
    calls, coarse_calls = round(a.duration / a.step), round(a.duration / a.coarse)
    print(f"{a.duration:g} s in communication steps of {a.step * 1e6:g} µs: {calls} calls of fmi2DoStep "
          f"+ fmi2GetReal, GearRattle on S1 at tolerance {a.tolerance:g}. CPU per call (median of "
          f"{a.rounds} rounds of {a.repeats} runs each, alternating); the same less the run at "
          f"{a.coarse * 1e3:g} ms steps (the integration's share)"
          + ("; instructions per call inside fmi2DoStep and fmi2GetReal (callgrind)" if a.instructions else ""))
    for label, reads, *_ in cases:
        per_call = fine[label] / calls
        own = (fine[label] - coarse[label]) / (calls - coarse_calls)
        ratios = ", ".join(f"{fine[label] / fine[ref]:5.2f}x {ref}"
                           + (f" ({counted[label] / counted[ref]:.2f}x in instructions)" if a.instructions else "")
                           for ref, _ in references)
        counts = f"  {counted[label] / calls:5.0f} instructions" if a.instructions else ""
        print(f"  {label + ' (' + reads + ')':40s} {per_call * 1e9:6.1f} ns, less the integration "
              f"{own * 1e9:6.1f} ns{counts};  {ratios};  at {a.duration:g} s: {' '.join(values[label][:2])}")


if __name__ == "__main__":
    main()
