"""make bench-overhead: what the rattle statistics cost a run of S1, against the FMU library of a
base commit, all stepped from C in one process (benches/overhead/overhead.c), alternating, the
median over the rounds. Prints the figures; makes no timed assertion.

    .venv/bin/python scripts/bench_overhead.py --base target/dd70606 --new .

With --instructions, each case runs once more alone under callgrind (valgrind), which counts
the instructions executed inside fmi2DoStep: a measure the machine's load does not move.

Cases: the base's FMU with its defaults; this FMU as a user runs it who reads no statistics
(its defaults); this FMU with the statistics window open from --stats-from; then, for the
shares of the extras, a window asked for after the run's end (its quadratures integrated,
nothing counted) and a window open from the start. Each is checked to give the same
trajectory as the base (ξ, ξ', the impact counts, the solver's steps and right-hand sides, to
the last bit); the window's figures are shown.
"""

import argparse
import glob
import os
import statistics
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

# The paper's scene S1 in sine mode.
S1 = {"excitation": 1, "f_exc": 30.0, "A_rms": 300.0}
# The trajectory (compared to the last bit) and the window's figures (shown, non-zero).
SAME = (["xi", "xi_dot", "solver_steps", "solver_rhs"], ["impacts_Fplus", "impacts_Fminus"])
WINDOW = (["stat_window", "stat_a_rms", "stat_a_peak", "stat_F_std"], ["stat_impacts_Fplus"])


def description(xml):
    """A model description's root, GUID and variables (name: (vr, Integer))."""
    root = ET.parse(xml).getroot()
    variables = {v.get("name"): (int(v.get("valueReference")), v.find("Integer") is not None)
                 for v in root.iter("ScalarVariable")}
    return root, root.get("guid"), variables


def library(tree):
    """The release library of a source tree, its GUID and its variables."""
    lib = os.path.join(tree, "target", "release", "libgear_rattle.so")
    xmls = glob.glob(os.path.join(tree, "target", "release", "build", "gear_rattle-*", "out",
                                  "modelDescription.xml"))
    if not os.path.exists(lib) or not xmls:
        sys.exit(f"{tree}: no release build (cargo build --release --lib there)")
    _, guid, variables = description(max(xmls, key=os.path.getmtime))
    return lib, guid, variables


def case(label, tree, start, read):
    """The harness's input line of one case of a source tree's library."""
    return line(label, *library(tree), start, read)


def line(label, lib, guid, variables, start, read):
    """The harness's input line of one case: its start values, the Real and the Integer
    outputs it reads."""
    missing = [n for n in [*start, *read[0], *read[1]] if n not in variables]
    if missing:
        sys.exit(f"{lib}: no {missing}")
    reals = [f"{variables[n][0]} {v!r}" for n, v in start.items() if not variables[n][1]]
    ints = [f"{variables[n][0]} {int(v)}" for n, v in start.items() if variables[n][1]]
    words = [label, lib, guid, str(len(reals)), *reals, str(len(ints)), *ints]
    for names in read:
        words += [str(len(names)), *(str(variables[n][0]) for n in names)]
    return " ".join(words)


def instructions(harness, line, args, functions=("fmi2DoStep",)):
    """Instructions executed inside `functions` by one trajectory of the case `line`."""
    with tempfile.NamedTemporaryFile(suffix=".callgrind") as out:
        collect = [f"--toggle-collect={f}" for f in functions]
        subprocess.run(["valgrind", "--tool=callgrind", *collect,
                        f"--callgrind-out-file={out.name}", harness, "1", "1", *args],
                       input=line, capture_output=True, text=True, check=True)
        return int(re.search(r"^summary: (\d+)", open(out.name).read(), re.M).group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--base", required=True, help="source tree of the base commit, built")
    ap.add_argument("--new", default=".", help="source tree of this FMU, built")
    ap.add_argument("--harness", default="target/bench/overhead")
    ap.add_argument("--duration", type=float, default=1.0)
    ap.add_argument("--step", type=float, default=1e-4, help="communication step [s]")
    ap.add_argument("--tolerance", type=float, default=1e-5)
    ap.add_argument("--stats-from", type=float, default=0.2)
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--repeats", type=int, default=10)
    ap.add_argument("--instructions", action="store_true",
                    help="also count each case's instructions under callgrind (needs valgrind)")
    a = ap.parse_args()
    both = (SAME[0] + WINDOW[0], SAME[1] + WINDOW[1])
    cases = [("base", a.base, S1, SAME),
             ("no-statistics", a.new, S1, SAME),
             (f"window-from-{a.stats_from:g}s", a.new, dict(S1, stats_from=a.stats_from), both),
             # The shares of the extras: the window's quadratures alone (a window asked for
             # after the run's end), then the whole window open from the start.
             ("window-after-the-end", a.new, dict(S1, stats_from=2 * a.duration), both),
             ("window-from-0s", a.new, dict(S1, stats_from=0.0), both)]
    lines = [case(*c) + "\n" for c in cases]
    stdin = "".join(lines)
    run = [str(a.duration), str(a.step), str(a.tolerance)]
    argv = [a.harness, str(a.rounds), str(a.repeats), *run]
    out = subprocess.run(argv, input=stdin, capture_output=True, text=True, check=True).stdout
    times, values = {}, {}
    for row in out.splitlines():
        kind, label, *rest = row.split()
        if kind == "time":
            times.setdefault(label, []).append(float(rest[0]))
        else:
            values[label] = rest
    counted = [instructions(a.harness, line, run) if a.instructions else 0 for line in lines]
    base = statistics.median(times["base"])
    print(f"S1, {a.duration:g} s in communication steps of {a.step * 1e3:g} ms, tolerance {a.tolerance:g}: "
          f"CPU per trajectory, median of {a.rounds} rounds of {a.repeats} runs each, alternating")
    for (label, _, _, (reals, ints)), ir in zip(cases, counted):
        med = statistics.median(times[label])
        got = dict(zip(reals + ints, values[label]))
        same = all(got[n] == dict(zip(SAME[0] + SAME[1], values["base"]))[n] for n in SAME[0] + SAME[1])
        window = "  ".join(f"{n} {float(got[n]):.6g}" for n in reals + ints if n.startswith("stat_"))
        counts = f"{ir:11,d} instructions {ir / counted[0]:5.3f}x  " if a.instructions else ""
        print(f"  {label:20s} {med * 1e3:7.3f} ms  {med / base:5.3f}x base  {counts}steps {got['solver_steps']}, "
              f"rhs {got['solver_rhs']}, trajectory {'the same bits' if same else 'DIFFERENT'}  {window}")


if __name__ == "__main__":
    main()
