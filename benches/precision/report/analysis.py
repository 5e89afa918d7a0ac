"""The report's reasons: why the targets are met or not, from this run's measurements, the
profile of `make bench-profile` and the split of one call."""

from __future__ import annotations

import math
import pathlib
import re

from precision.report.curves import fmt_t
from precision.report.names import GR, SAME_RHS

def parse_profile(text):
    """The figures of benches/work_precision/profile.rs's printout."""
    p = {}
    m = re.search(r"rtol ([0-9.e+-]+): ([0-9.]+) ms CPU per run", text)
    if m:
        p["rtol"], p["ms"] = float(m.group(1)), float(m.group(2))
    m = re.search(r"work: (\d+) RHS, (\d+) accepted \+ (\d+) rejected steps \((\d+) of them Taylor steps\), "
                  r"(\d+) edges", text)
    if m:
        p["rhs"], p["accepted"], p["rejected"], p["series"], p["edges"] = map(int, m.groups())
    m = re.search(r"free flight in closed form: (\d+) evaluations of the exact solution", text)
    if m:
        p["flight_evals"] = int(m.group(1))
    m = re.search(r"RHS per accepted DOPRI5 step ([0-9.]+); RHS on edges crossed out of a band \((\d+) of the "
                  r"\d+ edges.*?\) ([0-9.]+) % ; RHS on\s+rejected steps .*? ([0-9.]+) %", text, re.S)
    if m:
        p["rhs_per_step"], p["redone_edges"], p["edge_pct"], p["reject_pct"] = map(float, m.groups())
    p["regions"] = {}
    for m in re.finditer(r"^  (.+?)\s{2,}(\d+) RHS \(\s*([0-9.]+) %\)\s+([0-9.]+) ns each\s+([0-9.]+) % of the CPU", text, re.M):
        p["regions"][m.group(1).strip()] = dict(count=int(m.group(2)), pct=float(m.group(3)), ns=float(m.group(4)),
                                                cpu=float(m.group(5)))
    m = re.search(r"literal docs/MODEL.md RHS .*?: ([0-9./ ]+) ns per region; the run's RHS\s+would cost ([0-9.]+) %", text, re.S)
    if m:
        p["literal_ns"], p["literal_pct"] = m.group(1).strip(), float(m.group(2))
    m = re.search(r"right-hand sides ([0-9.]+) % of the CPU time; the rest \(([0-9.]+) %, ([0-9.]+) ns per RHS\)", text)
    if m:
        p["rhs_cpu"], p["other_cpu"], p["other_ns"] = map(float, m.groups())
    return p


def analysis(rows, s1, r_rust, n_rust, r_user, n_user, r_py, n_py, comm_rows, tol_1e9, bench):
    """Why the targets are met or not, from the measurements of this run."""
    out = []
    a = out.append
    a("## Why, and which lever would help most")
    a("")
    gr_c, _, gr_h = s1[GR]
    # the fastest crate configuration at 1e-9 m
    peers = [(s1[n][0], n) for n in SAME_RHS if s1[n][0] is not None and s1[n][1] != "above"]
    if gr_c and peers:
        pc, pn = min(peers)
        ph = s1[pn][2]
        a(f"**Against the Rust crates ({pc / gr_c:.2f}× at 1e-9 m on S1, target 3×).** The crates run here with "
          "GearRattle's own event handling (band edges located on the dense output, steps ending on them, "
          "restart in the next region), the same right-hand-side function and the same error weights, so what "
          "is left to compare is the integrator: GearRattle's, which crosses the gap in closed form and the "
          "full contacts by Taylor-series steps, against each crate's pair, which integrates both. At 1e-9 m on "
          f"S1 (1 s) GearRattle spends {gr_h:.3g} RHS (its Taylor steps not counted) against {ph:.3g} for {pn} "
          f"({ph / gr_h:.2f}×), at {gr_c / gr_h * 1e9:.0f} ns of CPU per RHS counted (the Taylor steps' cost "
          f"included) against {pc / ph * 1e9:.0f} ns.")
        a("")
    if gr_c and r_user is not None:
        uc, _, uh = s1[n_user]
        met = "met" if r_user >= 3 else "not met"
        a(f"**Against the Rust crates as users write them ({r_user:.2f}× at 1e-9 m on S1, target 3×: {met}).** "
          "Each crate on the right-hand side written literally from docs/MODEL.md (powf for |δ/G|^(α−1), the band's "
          "sine as written, the excitation's sin and cos, the region from ξ at each call), with its own stepping "
          "and no edge handling: steps straddle the kinks of the contact law. Fastest at 1e-9 m: "
          f"{n_user}, {fmt_t(uc)}" + (f" and {uh:.3g} RHS ({uh / gr_h:.2f}× GearRattle's)" if uh else "") +
          (f", at {uc / uh * 1e9:.0f} ns of CPU per RHS against GearRattle's {gr_c / gr_h * 1e9:.0f} ns"
           if uh else "") + ".")
        a("")
    prof_path = bench / "profile.txt"
    if prof_path.is_file():
        p = parse_profile(prof_path.read_text())
        reg = p.get("regions", {})
        gap = next((v for k, v in reg.items() if k.startswith("gap")), None)
        bands = [v for k, v in reg.items() if k.startswith("band")]
        contacts = [v for k, v in reg.items() if k.startswith("contact")]
        if "rhs_cpu" in p and gap:
            band_pct = sum(v["pct"] for v in bands)
            contact_pct = sum(v["pct"] for v in contacts)
            a(f"**Profile of GearRattle alone** (S1, 1 s, rtol {p.get('rtol', float('nan')):g}; RHS counted per "
              "region through a wrapper of `Rattle`, RHS cost per region timed in a loop, perf for the symbols): "
              f"{p['rhs']} RHS, {p['accepted']} accepted steps ({p.get('series', 0)} of them Taylor steps in full "
              f"contact) and {p['rejected']} rejected, {p['edges']} edges. "
              f"Right-hand sides take {p['rhs_cpu']:.0f} % of the CPU time; the integrator around them (DOPRI5's "
              f"stages, the Taylor steps, error norm, step control, edge search, output stops) {p['other_cpu']:.0f} %, i.e. "
              f"{p['other_ns']:.0f} ns per RHS. By region: contact {contact_pct:.0f} % of the RHS, bands "
              f"{band_pct:.0f} %, free flight {gap['pct']:.0f} %" +
              (f" (the gap is crossed in closed form: {p['flight_evals']} evaluations of the exact solution "
               "instead of steps)" if "flight_evals" in p else "") +
              f". The {p['redone_edges']:.0f} edges crossed out of a band cost {p['edge_pct']:.0f} % of the RHS "
              f"(each reached by a DOPRI5 step, redone to end on it, then a new first stage; the other edges are "
              f"reached at a Taylor step's polynomial or on the exact flight, at no extra RHS), rejected steps "
              f"{p['reject_pct']:.0f} %.")
            a("")
            a("What is left, with the most each lever could give in this run (the share of the time it could "
              "remove, as a speed-up bound; a cheaper right-hand side moves the ratio against the peers as users "
              "write them, not against those that call GearRattle's own). The levers in place, and those measured "
              "and dropped, are in [DECISIONS.md](DECISIONS.md).")
            a("")
            levers = [
                ("a cheaper right-hand side (all RHS time; by region: " +
                 ", ".join(f"{k.split(' (')[0]} {v['ns']:.0f} ns" for k, v in reg.items() if v["count"]) + ")",
                 p["rhs_cpu"]),
                ("leaner stepping (the integrator's own time per RHS: stages, error norm, control, "
                 "edge search)", p["other_cpu"]),
                ("cheaper edges (the redone step and the new first stage per edge out of a band)",
                 p["edge_pct"] * p["rhs_cpu"] / 100 + p["edge_pct"] * p["other_cpu"] / 100),
            ]
            for name, share in levers:
                bound = 1 / max(1e-9, 1 - share / 100)
                a(f"- {name}: {share:.0f} % of the time, ≤ {bound:.2f}× if removed entirely.")
            a("")
            perf_lines = [ln for ln in prof_path.read_text().splitlines() if re.match(r"\s+[0-9.]+%\s+\[", ln)]
            if perf_lines:
                a("perf, self time of the symbols (the whole run, S1 repeated): " +
                  "; ".join(re.sub(r"\s+", " ", ln.strip()).replace(" [.] ", " ") for ln in perf_lines[:8]) + ".")
                a("")
            if "literal_pct" in p:
                a(f"The RHS of the user's-RHS peers (peers::UserRhs, literally from docs/MODEL.md) costs "
                  f"{p['literal_ns']} ns per region (contact F+ / band F+ / gap / band F− / contact F−) in the same "
                  f"loop, i.e. {p['literal_pct']:.0f} % of GearRattle's RHS time over this run's evaluations: "
                  "GearRattle's RHS is " + ("cheaper" if p["literal_pct"] > 100 else "not cheaper") +
                  " than the one a user writes.")
                a("")
            perf = {}
            for ln in perf_lines:
                m = re.match(r"\s+([0-9.]+)%\s+\[.\]\s+(.*)", ln)
                if m:
                    perf[re.sub(r"(\s+-)+\s*$", "", m.group(2)).strip()] = float(m.group(1))

            libm = {k: v for k, v in perf.items() if k.startswith("__") and v >= 1}
            if perf:
                a("Library calls above 1 % of perf's samples: " +
                  (", ".join(f"{k} {v:.0f} %" for k, v in libm.items()) if libm else "none") + ".")
                a("")
    if comm_rows:
        key = [cr for cr in comm_rows if tol_1e9 and math.isclose(cr[0], tol_1e9)] or comm_rows[:1]
        rtol, cf, cs, rh, er = key[0]
        calls = 1e5  # DoSteps of S1 (1 s) at 10 µs
        per_call = (cf[1e-5] - cf[1e-2]) / calls * 1e9
        per_step_to = (cs[1e-5] - cs[1e-2]) / calls * 1e9
        a(f"**Communication steps** (rtol {rtol:g}): {rh[1e-2]:.3g} RHS for 1 s at 10 ms, {rh[1e-3]:.3g} at 1 ms, "
          f"{rh[1e-4]:.3g} at 0.1 ms, {rh[1e-5]:.3g} at 10 µs; CPU at 10 µs is {cf[1e-5] / cf[1e-2]:.1f}× that at 10 ms. "
          "In sine mode the FMU serves communication points from the dense output of its natural DOPRI5 and "
          "Taylor steps and from the closed-form free flight, and resumes from where they end "
          "(Solver::interpolate_ends and the kept passage), so the steps, and the RHS count, are those of a run "
          "without communication points, bit for bit (test `end_times_change_no_bit_of_the_trajectory`). "
          "What is left at 10 µs is the cost of each call: "
          f"{per_call:.0f} ns per fmi2DoStep + fmi2GetReal (ξ, ξ') through the C API, of which "
          f"{per_step_to:.0f} ns in Simulation::step_to and the outputs themselves (the interpolation, or one "
          "evaluation of the flight, with its exponential and one sine and cosine, in the gap), against "
          f"{cf[1e-2] * 1e3:.2f} ms of integration per simulated second: 100 000 calls cost "
          f"{per_call * 1e5 * 1e-6:.1f} ms. "
          + calls_split(bench) +
          "In inputs mode new inputs arrive at every DoStep and steps still end on the communication points. "
          f"FMI overhead at 0.1 ms: {(cf[1e-4] / cs[1e-4] - 1) * 100:+.0f} % (C API against Simulation::step_to: "
          "the C boundary, the guard around each call, argument checks and the fmi crate's wrappers).")
        a("")
    if r_py is not None:
        a(f"**Against scipy** ({r_py:.0f}× at 1e-9 m on S1, fastest {n_py}): a Python RHS costs microseconds where "
          "the Rust one costs tens of nanoseconds, and solve_ivp restarts at every edge (a new first step each "
          "time). The ratio is dominated by the interpreter, not by the method.")
    return "\n".join(out)


def calls_split(bench: pathlib.Path) -> str:
    """The split of one 10 µs call measured by `make bench-profile` (target/bench/calls.txt)."""
    path = bench / "calls.txt"
    if not path.is_file():
        return ""
    m = re.search(r"fmi2GetReal \(xi, xi'\) ([0-9]+) ns; fmi2DoStep ([0-9]+) ns against "
                  r"Simulation::step_to ([0-9]+) ns \(both with the integration: ([0-9]+) ns of it\); "
                  r"Simulation::real_output \(xi\) ([0-9]+) ns", path.read_text())
    if not m:
        return ""
    get, step, step_to, integ, out = (int(x) for x in m.groups())
    return (f"Timed apart (BENCH_PROFILE=calls, 100 000 calls each): fmi2GetReal of ξ and ξ' {get} ns, of which "
            f"{out} ns per output; fmi2DoStep {step} ns against {step_to} ns for Simulation::step_to, of which "
            f"{integ} ns are the integration's share: the C boundary and the guard cost about "
            f"{get - 2 * out + step - step_to} ns per DoStep + GetReal pair, the served point "
            f"{step_to - integ} ns. The 1.5× target would need the whole call under "
            f"{0.5 * integ:.0f} ns"
            + (f": fmi2GetReal of the two outputs alone, with no step at all, costs {get} ns, more than that. "
               if get > 0.5 * integ else ". "))
