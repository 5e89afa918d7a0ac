"""valgrind memcheck over the packaged FMU as Python loads it (fmpy): whole lifecycles through
the low-level FMU2Slave (instantiate, set up, step in sine and inputs mode, read, get / set /
serialize / deserialize / free FMU states, refused calls, reset, terminate, free) and one
simulate_fmu run. Part of `make check-memory` (mk/hardening.mk).

    .venv/bin/python scripts/memcheck_fmpy.py --fmu target/fmu/GearRattle.fmu

runs itself under valgrind (with PYTHONMALLOC=malloc, so that valgrind sees Python's own
allocations) and judges the log: the memory errors and the definitely lost blocks whose stack
passes through the FMU's library must be 0; the whole process's counts (Python, numpy) are
printed beside them. Exit status 1 if the FMU has any."""

from __future__ import annotations

import argparse
import os
import pathlib
import re
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
LIBRARY = "GearRattle.so"
# A frame of the library's own code names the library, its source files (--fullpath-after=)
# or a function of its crates.
SOURCES = (str(ROOT / "src") + "/", str(ROOT / "fmi2-shell") + "/")
CRATES = ("gear_rattle", "fmi2_shell")


def lifecycles(fmu: str) -> None:
    from fmpy import extract, read_model_description, simulate_fmu
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    outputs = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    unzipdir = extract(fmu, unzipdir=tempfile.mkdtemp(prefix="memcheck_"))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="memcheck")
    slave.instantiate(loggingOn=True)

    def refused(call, *args):
        try:
            call(*args)
        except FMICallException:
            return
        raise AssertionError(f"{call.__name__}{args} was not refused")

    for excitation in (1, 0):
        slave.setupExperiment(tolerance=1e-6, startTime=0.0)
        slave.enterInitializationMode()
        slave.setInteger([vr["excitation"]], [excitation])
        slave.exitInitializationMode()
        h = 2e-4
        for k in range(50):
            if excitation == 0:
                slave.setReal([vr["theta_M"], vr["omega_M"]], [1e-3 * k, 1.0])
            slave.doStep(k * h, h)
            values = slave.getReal(outputs)
            assert all(abs(x) < float("inf") for x in values), values
            if k % 10 == 5:
                state = slave.getFMUstate()
                data = slave.serializeFMUstate(state)
                back = slave.deSerializeFMUstate(data)
                slave.setFMUstate(back)
                slave.freeFMUstate(back)
                slave.freeFMUstate(state)
                refused(slave.getReal, [9999])
                refused(slave.setReal, [vr["omega_M"]], [float("nan")])
                refused(slave.doStep, (k + 1) * h, -h)
                refused(slave.deSerializeFMUstate, bytes(data[:-1]) + b"\0")
        slave.terminate()
        slave.reset()
    slave.freeInstance()
    start = {"excitation": 1}
    simulate_fmu(unzipdir, model_description=md, stop_time=0.01, step_size=1e-4, start_values=start)


def judge(log: pathlib.Path) -> int:
    """Counts the records of the valgrind log, those of the FMU's library apart."""
    text = log.read_text(errors="replace")
    records = re.split(r"\n==\d+== \n", text)
    ours_errors = ours_lost = all_errors = all_lost = 0
    for r in records:
        lost = re.search(r"([\d,]+)(?: \(([\d,]+) direct, [\d,]+ indirect\))? bytes in [\d,]+ blocks are definitely lost", r)
        is_error = re.search(r"==\d+== (Invalid|Conditional jump|Use of uninitialised|Syscall param|Mismatched|Source and destination)", r)
        mine = LIBRARY in r or any(x in r for x in SOURCES) or any(f"{crate}::" in r for crate in CRATES)
        if lost:
            n = int((lost.group(2) or lost.group(1)).replace(",", ""))
            all_lost += n
            ours_lost += n if mine else 0
        elif is_error:
            all_errors += 1
            ours_errors += mine
    summary = re.search(r"ERROR SUMMARY: .*", text)
    print(
        f"valgrind memcheck of fmpy's lifecycles: {ours_errors} errors and {ours_lost} bytes definitely lost "
        f"with {LIBRARY} on the stack; the whole Python process: {all_errors} errors, {all_lost} bytes "
        f"definitely lost (valgrind's {summary.group(0) if summary else 'summary missing'}, which counts "
        f"Python's possibly lost blocks too); log: {log}"
    )
    return 1 if ours_errors or ours_lost else 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fmu", default=str(ROOT / "target" / "fmu" / "GearRattle.fmu"))
    ap.add_argument("--log", default=str(ROOT / "target" / "memcheck" / "fmpy.log"))
    ap.add_argument("--inside", action="store_true", help="run the lifecycles (under valgrind)")
    args = ap.parse_args()
    if args.inside:
        lifecycles(args.fmu)
        return 0
    log = pathlib.Path(args.log)
    log.parent.mkdir(parents=True, exist_ok=True)
    cmd = [
        "valgrind", "--tool=memcheck", "--leak-check=full", "--show-leak-kinds=definite",
        "--error-limit=no", "--fullpath-after=",
        f"--log-file={log}", sys.executable, __file__, "--inside", "--fmu", args.fmu,
    ]
    done = subprocess.run(cmd, env={**os.environ, "PYTHONMALLOC": "malloc"})
    if done.returncode != 0:
        print(f"the lifecycles failed under valgrind (exit {done.returncode}); log: {log}")
        return 1
    return judge(log)


if __name__ == "__main__":
    sys.exit(main())
