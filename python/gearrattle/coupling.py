"""Coupling-error study: GearRattle + its drivetrain partner (Flywheel) co-simulated
with Jacobi coupling at communication steps from 1 ms to 10 us, against the monolithic
reference of the same drivetrain (gearrattle.monolithic), with and without input
derivatives; and the same drivetrain integrated monolithically through GearRattle's Model
Exchange interface (gearrattle.model_exchange) at a few solver tolerances, with its cost.
Writes docs/COUPLING.md (tables, the command) and docs/coupling_error.png, and the raw
figures to target/coupling/coupling.csv and target/coupling/model_exchange.csv
(`make coupling-study`, scripts/coupling_study.py).

Variants (fmpy's hand-written master, gearrattle.masters; libcosim and Ecos connect like
"alpha"):
  linear           theta_M, omega_M to GearRattle; tau_M back, held over the step
  alpha            + alpha_M as an input (what libcosim and Ecos run here)
  derivatives      theta_M, omega_M + their derivatives by fmi2SetRealInputDerivatives
                   (needs GearRattle's canInterpolateInputs)
  derivatives+tau  + d tau_M / dt from GearRattle's fmi2GetRealOutputDerivatives into the
                   Flywheel's fmi2SetRealInputDerivatives (needs maxOutputDerivativeOrder >= 1)
"""

from __future__ import annotations

import csv
import dataclasses
import math
import pathlib
import platform
import sys
import time

import numpy as np

from . import masters as MS
from . import model_exchange as ME
from . import monolithic as M
from . import reference as R

ROOT = MS.ROOT

WINDOW = 0.1  # s: pointwise errors are compared over [0, WINDOW] (see the report)
DEFAULT_STEPS = (1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5)
DEFAULT_ME_RTOLS = (1e-6, 1e-8, 1e-10)
DEFAULT_ME_SOLVERS = ("LSODA", "Radau")
STEPS = ",".join(f"{h:g}" for h in DEFAULT_STEPS)  # the same defaults as the flags' strings
ME_RTOLS = ",".join(f"{r:g}" for r in DEFAULT_ME_RTOLS)
ME_SOLVERS = ",".join(DEFAULT_ME_SOLVERS)
ME_DT = 1e-5  # s: the Model Exchange runs are sampled on their dense output every 10 µs
G = R.DEFAULTS["G"]


def variants() -> list[tuple[str, str]]:
    """(label, master) pairs available with the FMUs as built."""
    out = [("fmpy linear", "linear"), ("fmpy alpha", "alpha")]
    if MS.can_interpolate_inputs():
        out.append(("fmpy derivatives", "derivatives"))
        if MS.max_output_derivative_order() >= 1:
            out.append(("fmpy derivatives+tau", "derivatives+tau"))
    out += [("libcosim", "libcosim"), ("Ecos", "ecos")]
    return out


def run(kind: str, t_end: float, h: float) -> dict:
    if kind in MS.INPUT_MODES:
        return MS.run_fmpy(t_end, h, inputs=kind)
    return MS.MASTERS[kind](t_end, h)


def errors(rec: dict, ref: M.Result) -> dict:
    t = rec["time"]
    w = (t <= WINDOW + 1e-12) & np.isfinite(rec["xi"])
    c = MS.compare(rec, ref)
    return dict(
        omega_window=float(np.max(np.abs(rec["omega_M"][w] - ref.omega_M[w]))),
        xi_window=float(np.max(np.abs(rec["xi"][w] - ref.xi[w])) / G),
        omega_run=c["omega_M"],
        rate=c["rate"],
        rate_ref=c["rate_ref"],
        rate_rel=c["rate_rel"],
        impacts=int(rec["impacts_Fplus"][-1] + rec["impacts_Fminus"][-1]),
    )


def order(hs, es):
    """Observed order between the largest and smallest step: log(e1/e2) / log(h1/h2)."""
    hs, es = np.asarray(hs), np.asarray(es)
    ok = es > 0
    if ok.sum() < 2:
        return float("nan")
    hs, es = hs[ok], es[ok]
    return float(np.log(es[0] / es[-1]) / np.log(hs[0] / hs[-1]))


def fmt_h(h: float) -> str:
    return f"{h * 1e3:g} ms" if h >= 1e-3 else f"{h * 1e6:g} µs"


def plot(rows, labels, me_rows, out_png: pathlib.Path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(13, 9))
    axes = axes.ravel()
    panels = [
        ("omega_window", f"max |ω_M − ω_M,ref| over [0, {WINDOW:g} s]  [rad/s]"),
        ("xi_window", f"max |ξ − ξ_ref| / G over [0, {WINDOW:g} s]"),
        ("rate", "impacts per second over the whole run (both flanks)"),
    ]
    styles = {"fmpy linear": "o-", "fmpy alpha": "s-", "fmpy derivatives": "x--", "fmpy derivatives+tau": "D-", "libcosim": "^:", "Ecos": "v:"}
    for ax, (key, title) in zip(axes[:3], panels):
        for label in labels:
            pts = [(r["h"], r[key]) for r in rows if r["variant"] == label]
            hs, es = zip(*pts)
            plot_fn = ax.semilogx if key == "rate" else ax.loglog
            plot_fn(hs, es, styles.get(label, "o-"), label=label, markersize=5)
        hs = np.array(sorted({r["h"] for r in rows}))
        if key == "rate":
            ax.axhline(rows[0]["rate_ref"], color="k", lw=1.0, label="monolithic reference")
            ax.legend(fontsize=7)
        else:
            # guides through the smallest step's points of the first- and second-order variants
            for label, power, style in (("fmpy alpha", 1, "k:"), ("fmpy derivatives+tau", 2, "k-.")):
                e = [r[key] for r in rows if r["h"] == hs[0] and r["variant"] == label]
                if e and e[0] > 0:
                    ax.loglog(hs, 0.5 * e[0] * (hs / hs[0]) ** power, style, lw=0.8, label=f"∝ h{'²' if power == 2 else ''}")
        ax.set_xlabel("communication step h [s]")
        ax.set_title(title, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    ax = axes[3]
    for label in labels:
        pts = sorted((r["wall"], r["xi_window"]) for r in rows if r["variant"] == label)
        ax.loglog(*zip(*pts), styles.get(label, "o-"), label=f"{label} (h)", markersize=5)
    for solver in sorted({r["solver"] for r in me_rows}):
        pts = sorted((r["wall"], r["xi_window"]) for r in me_rows if r["solver"] == solver)
        ax.loglog(*zip(*pts), "*-", label=f"Model Exchange, {solver} (rtol)", markersize=8)
    ax.set_xlabel("wall time of one run [s]")
    ax.set_title(f"max |ξ − ξ_ref| / G over [0, {WINDOW:g} s] against the cost", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.suptitle("GearRattle + Flywheel: Jacobi co-simulation and Model Exchange vs the monolithic reference", fontsize=10)
    fig.tight_layout()
    fig.savefig(out_png, dpi=110)
    plt.close(fig)


def table(rows, labels, key, fmt, hs):
    head = "| variant | " + " | ".join(fmt_h(h) for h in hs) + " |"
    sep = "|---|" + "---:|" * len(hs)
    lines = [head, sep]
    for label in labels:
        by_h = {r["h"]: r for r in rows if r["variant"] == label}
        lines.append(f"| {label} | " + " | ".join(fmt(by_h[h][key]) if h in by_h else "–" for h in hs) + " |")
    return "\n".join(lines)


def me_table(me_rows, nx: int) -> str:
    """The Model Exchange runs; a Jacobian costs nx + 2 fmi2GetDirectionalDerivative calls."""
    head = ("| solver | rtol | max \\|Δω_M\\| window (rad/s) | max \\|Δξ\\| / G window | max \\|Δω_M\\| run (rad/s)"
            " | impacts/s (error) | wall (s) | right-hand sides | indicator evaluations | steps | events"
            " | Jacobians, exact (fmi2GetDirectionalDerivative calls) |")
    lines = [head, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in me_rows:
        lines.append(
            f"| {r['solver']} | {r['rtol']:.0e} | {r['omega_window']:.2e} | {r['xi_window']:.2e} | {r['omega_run']:.2e}"
            f" | {r['rate']:.0f} ({100 * r['rate_rel']:.1f} %) | {r['wall']:.2f} | {r['rhs']} | {r['indicators']}"
            f" | {r['steps']} | {r['events']} | {r['jacobians']} ({r['jacobians'] * (nx + 2)}) |"
        )
    return "\n".join(lines)


def side_by_side(rows, me_rows, hs) -> str:
    """The co-simulation runs of the fmpy loop (held and ramped τ_M) at each step, and the
    Model Exchange runs at each tolerance: error against wall time."""
    lines = [
        "| interface | run | max \\|Δξ\\| / G window | max \\|Δω_M\\| window (rad/s) | impact rate error | wall (s) |",
        "|---|---|---:|---:|---:|---:|",
    ]
    by = {(r["variant"], r["h"]): r for r in rows}
    for label in ("fmpy alpha", "fmpy derivatives+tau"):
        for h in hs:
            if (label, h) in by:
                r = by[(label, h)]
                lines.append(f"| co-simulation | {label}, h = {fmt_h(h)} | {r['xi_window']:.2e} | {r['omega_window']:.2e}"
                             f" | {100 * r['rate_rel']:.1f} % | {r['wall']:.2f} |")
    for r in me_rows:
        lines.append(f"| Model Exchange | {r['solver']}, rtol {r['rtol']:.0e} | {r['xi_window']:.2e} | {r['omega_window']:.2e}"
                     f" | {100 * r['rate_rel']:.1f} % | {r['wall']:.2f} |")
    return "\n".join(lines)


def me_section(rows, me_rows, hs, t_end, ref_check) -> list[str]:
    from fmpy import read_model_description

    md = read_model_description(str(MS.GEAR_FMU))
    nx = md.numberOfContinuousStates
    lines = [
        "## Model Exchange: the same drivetrain in one solver",
        "",
        "- **Set-up**: GearRattle.fmu through its Model Exchange interface (fmpy's `FMU2Model`),",
        "  inputs mode, with the main shaft, the clutch damper and the engine written in Python",
        "  around it (python/gearrattle/model_exchange.py; the equations are the reference's own,",
        f"  `monolithic.drivetrain`): one state vector (GearRattle's {nx} states, θ_M, ω_M, φ, ω_E),",
        "  one scipy solver, absolute tolerances rtol × each state's nominal. After each accepted",
        f"  step the FMU's {md.numberOfEventIndicators} event indicators are compared with the step's start; the first",
        "  crossing is located on the step's dense output (Brent's method) and the step cut there;",
        "  fmi2CompletedIntegratorStep after every step; at an event fmi2EnterEventMode,",
        "  fmi2NewDiscreteStates until no new discrete states are needed,",
        "  fmi2EnterContinuousTimeMode, the states read back, and the solver restarted.",
        "- **Why the inputs mode**: the FMU keeps the connections of the co-simulation runs (θ_M,",
        "  ω_M in, τ_M out), so only the coupling changes, and the shaft's equation is the",
        "  reference's. τ_M depends on the states and on θ_M, ω_M (with ω_L a state, not on α_M):",
        "  no algebraic loop. The torque mode (the shaft inside the FMU, τ_in from the damper)",
        "  would serve as well.",
        "- **Call order** of an evaluation: the time and the inputs θ_M, ω_M, then the states,",
        "  so that the states are taken with the shaft's speed they belong to.",
        f"- **Run**: the same {t_end:g} s from the same initial state; ξ and ω_M sampled every",
        f"  {ME_DT * 1e6:g} µs on the solver's dense output against the reference sampled there,",
        f"  the errors over [0, {WINDOW:g} s] as above; the impact rate over the whole run.",
        "- **Jacobian**: exact, passed to the solver (LSODA uses it in its stiff phases): the",
        "  gear pair's ∂(der(x), τ_M)/∂(x, θ_M, ω_M) from fmi2GetDirectionalDerivative, one call",
        f"  per state and input with a unit seed ({nx + 2} calls), at the point set as for a right-hand",
        "  side; the shaft's and the engine's partials analytic (`monolithic.drivetrain_partials`),",
        "  τ_M's entering the shaft's acceleration by the chain rule. No right-hand side is spent",
        "  on difference Jacobians.",
        "- **Cost columns**: right-hand sides = fmi2GetDerivatives calls (each with fmi2SetTime,",
        "  fmi2SetReal, fmi2SetContinuousStates, fmi2GetReal of τ_M); indicator evaluations =",
        "  fmi2GetEventIndicators calls (step ends and event location); events = event",
        "  iterations, each a solver restart; Jacobians = evaluations of the exact Jacobian, in",
        "  brackets the fmi2GetDirectionalDerivative calls they made.",
        "",
        "### Error and cost by solver and tolerance",
        "",
        me_table(me_rows, nx),
        "",
        "### Side by side with co-simulation",
        "",
        side_by_side(rows, me_rows, hs),
        "",
    ]
    co = [r for r in rows if r["variant"].startswith("fmpy")]
    if co and me_rows:
        best = min(co, key=lambda r: r["xi_window"])
        near = min(me_rows, key=lambda r: abs(math.log(r["wall"] / best["wall"])))
        tight = min(me_rows, key=lambda r: (r["xi_window"], r["wall"]))
        lines += [
            "Reading, from the tables:",
            "",
            f"- The best co-simulation run here ({best['variant']}, h = {fmt_h(best['h'])}) reaches",
            f"  {best['xi_window']:.1e} G in ξ and {best['omega_window']:.1e} rad/s in ω_M in {best['wall']:.2f} s. The Model",
            f"  Exchange run closest in wall time ({near['solver']}, rtol {near['rtol']:.0e}, {near['wall']:.2f} s) reaches",
            f"  {near['xi_window']:.1e} G and {near['omega_window']:.1e} rad/s; the most accurate one ({tight['solver']}, rtol",
            f"  {tight['rtol']:.0e}) {tight['xi_window']:.1e} G and {tight['omega_window']:.1e} rad/s in {tight['wall']:.2f} s, with",
            f"  {tight['rhs']} right-hand sides and {tight['events']} events. The reference itself is good to",
            f"  {ref_check['xi']:.1e} G over the run (rtol 1e-10 against 1e-12): errors below that measure",
            "  agreement, not accuracy.",
            "- Model Exchange's error follows the solver's tolerance alone: there is no",
            "  communication step, so no hold of τ_M and no extrapolation of the shaft.",
            "- Its cost is the importer's: every right-hand side crosses the FMI boundary (here from",
            "  Python), and every edge crossing and turning point in the gap is an event that",
            f"  restarts the solver: {tight['events'] / max(tight['impacts'], 1):.1f} events per impact in the run above.",
            "",
        ]
    return lines


def report(rows, labels, hs, t_end, ref_check, wall, command, out_md: pathlib.Path, me_rows=()):
    e3 = lambda x: f"{x:.2e}"  # noqa: E731
    g3 = lambda x: f"{x:.3g}"  # noqa: E731
    pct = lambda x: f"{100 * x:.1f} %"  # noqa: E731
    orders = {lab: order(*zip(*[(r["h"], r["omega_window"]) for r in rows if r["variant"] == lab])) for lab in labels}
    rate_ref = rows[0]["rate_ref"]
    by = {(r["variant"], r["h"]): r for r in rows}
    h_test = MS.H_TEST
    alpha_t, both_t = by.get(("fmpy alpha", h_test)), by.get(("fmpy derivatives+tau", h_test))
    have_deriv = "fmpy derivatives" in labels
    have_tau = "fmpy derivatives+tau" in labels
    lines = [
        "# Coupling error: GearRattle with a drivetrain partner, co-simulation and Model Exchange",
        "",
        "Generated by `scripts/coupling_study.py`; rerun with",
        "",
        "    make coupling-study",
        "",
        f"(this run: `{command}`, {wall:.0f} s on {platform.machine()}, 2 cores).",
        "",
        "## Set-up",
        "",
        "- **Coupled system**: GearRattle (inputs mode, the paper's parameters but the lubricant",
        "  drag C = 1e-3 N m s, see below) and its drivetrain partner `partners/flywheel`",
        "  (target/fmu/Flywheel.fmu): a 4-cylinder engine at 800 rpm idle, T_E = 15 N m + 80 N m",
        "  sin(2 θ_E), I_E = 0.15 kg m², clutch damper k_d = 150 N m/rad, c_d = 0.3 N m s, main",
        "  shaft I_M = 0.008 kg m² (values and their reasons: partners/flywheel/README.md).",
        "  Flywheel.theta_M, omega_M, alpha_M → GearRattle; GearRattle.tau_M → Flywheel.tau_M.",
        f"- **Run**: {t_end:g} s from both shafts at idle speed and the loose gear at rest in the",
        "  middle of the backlash, fixed communication step h, Jacobi coupling (both FMUs step",
        "  from the values exchanged at t_n). GearRattle at its default tolerance (1e-6); the",
        "  Flywheel integrates with RK4 sub-steps of at most 0.1 ms.",
        "- **Reference**: the same drivetrain as one ODE (python/gearrattle/monolithic.py: the contact",
        "  law and loose-gear equation of python/gearrattle/reference.py, the Flywheel's equations),",
        "  scipy DOP853 at rtol 1e-10 with steps ending on the band edges; against rtol 1e-12 it",
        f"  differs by {ref_check['xi']:.1e} G in ξ and {ref_check['omega']:.1e} rad/s in ω_M over the run.",
        f"  It gives {rate_ref:.0f} impacts per second (both flanks) over the run.",
        "- **Variants** (fmpy's hand-written master unless named):",
        "  - *linear*: θ_M, ω_M only; GearRattle extrapolates the shaft linearly over the step;",
        "  - *alpha*: θ_M, ω_M and α_M connected; GearRattle extrapolates quadratically;",
        "    libcosim and Ecos run this connection set;",
        "  - *derivatives*: θ_M, ω_M and, instead of the α_M connection, their time derivatives",
        "    (the Flywheel's fmi2GetRealOutputDerivatives into GearRattle's",
        "    fmi2SetRealInputDerivatives: θ_M orders 1 and 2, ω_M order 1);",
        "  - *derivatives+tau*: the same, and dτ_M/dt (GearRattle's fmi2GetRealOutputDerivatives)",
        "    into the Flywheel's fmi2SetRealInputDerivatives, which then ramps τ_M over the step",
        "    instead of holding it.",
        "",
        f"Pointwise errors are taken over the first {WINDOW:g} s only: beyond it a near-graze",
        "of the loose gear can put one impact a step earlier or later, after which ξ differs",
        "by a fraction of G and ω_M by a few",
        "0.01 rad/s whatever the step (the rattle is pointwise predictable only for a while, as",
        "docs/MODEL.md notes for the bench scene S2); the impact rate over the whole run stays",
        "comparable.",
        "",
        "## Results",
        "",
        f"### Main-shaft speed, max |ω_M − ω_M,ref| over [0, {WINDOW:g} s] (rad/s)",
        "",
        table(rows, labels, "omega_window", e3, hs),
        "",
        "Observed order (1 ms → 10 µs): " + ", ".join(f"{lab} {orders[lab]:.2f}" for lab in labels) + ".",
        "",
        f"### Transmission error, max |ξ − ξ_ref| / G over [0, {WINDOW:g} s]",
        "",
        table(rows, labels, "xi_window", g3, hs),
        "",
        f"### Impact rate over the whole run, relative error (reference: {rate_ref:.0f} /s)",
        "",
        table(rows, labels, "rate_rel", pct, hs),
        "",
        "### Main-shaft speed, max |ω_M − ω_M,ref| over the whole run (rad/s)",
        "",
        table(rows, labels, "omega_run", e3, hs),
        "",
        "### Wall time of one run (s)",
        "",
        table(rows, labels, "wall", lambda x: f"{x:.2f}", hs),
        "",
        "![coupling error](coupling_error.png)",
        "",
        "## Reading",
        "",
        "- With τ_M held over the step (every variant but *derivatives+tau*) the coupling is",
        "  of first order: the Flywheel sees the contact torque as a staircase. Contacts last",
        "  about a millisecond, so at 1 ms the staircase misses whole impacts' torque shapes.",
        "  At small steps this hold dominates and the three variants that hold τ_M converge to",
        "  the same error, whatever GearRattle's extrapolation of the shaft.",
        "- *linear* is much worse at large steps: without α_M GearRattle extrapolates the shaft",
        "  with a constant speed, an error of α_M h²/2 on the pitch line (0.013 mm, half the",
        "  backlash, at h = 1 ms and α_M = 900 rad/s²): impacts appear that do not happen.",
    ]
    if have_deriv:
        lines += [
            "- *derivatives* gives the same run as *alpha*: GearRattle takes θ_M' and θ_M'' = ω_M'",
            "  from fmi2SetRealInputDerivatives as the ω_M and α_M of its extrapolation, the same",
            "  numbers the α_M connection brings.",
        ]
    if have_tau and alpha_t and both_t:
        lines += [
            "- *derivatives+tau* makes the exchange second order in both directions: at the test",
            f"  step ({fmt_h(h_test)}) the ω_M error over the window falls from {alpha_t['omega_window']:.1e}"
            f" to {both_t['omega_window']:.1e} rad/s and ξ's from {alpha_t['xi_window']:.2g} G to"
            f" {both_t['xi_window']:.2g} G. At 1 ms the",
            "  linear ramp of a contact torque overshoots (a contact is shorter than the step), so",
            "  input derivatives pay from about 0.5 ms down.",
        ]
    elif not have_deriv:
        lines += [
            "- The GearRattle FMU this run used does not declare canInterpolateInputs: the",
            "  *derivatives* variants were left out (the script checks the model description).",
        ]
    lines += [
        "- libcosim and Ecos agree with each other and, to within the coupling error itself,",
        "  with fmpy's *alpha* loop: they pass on GearRattle's τ_M as it stands after its step",
        "  (computed from GearRattle's own extrapolation of the shaft), where fmpy's loop",
        "  exchanges in dependency order (τ_M recomputed from the Flywheel's new θ_M, ω_M); the",
        "  difference is of first order in h like the coupling error.",
        "",
        "## What each master needed",
        "",
        "- **fmpy** (`FMU2Slave`, loop in python/gearrattle/masters.py): nothing beyond the FMI",
        "  calls; the loop exchanges once in initialisation mode, so that GearRattle's ω_M input",
        "  holds the idle speed before fmi2ExitInitializationMode, and then at each step in",
        "  dependency order (α_M depends on τ_M at once).",
        "- **libcosim** (PyPI libcosimpy 0.0.6, a manylinux wheel): the step in integer",
        "  nanoseconds; `connect_real_variables` returns 0 on success (not a bool); it",
        "  initialises the FMUs in the first `step()` and passes the connected values in",
        "  initialisation mode itself; its last-value observer has no sample before that step.",
        "  GearRattle's Integer outputs (impact counters) are observed as usual.",
        "- **Ecos** (PyPI ecospy 0.7.2): Debian's libtbb12 (its libecosc.so links",
        "  libtbb.so.12); GearRattle's parameter C as an initial-value parameter set",
        "  (`gear::C`); connections by `instance::variable` names; it too passes connected",
        "  values in initialisation.",
        "",
        *me_section(rows, me_rows, hs, t_end, ref_check),
        "## Coupling by torque (excitation = 2)",
        "",
        "The runs above couple kinematically: the Flywheel integrates the main shaft and hands",
        "GearRattle θ_M, ω_M (α_M), and GearRattle hands back τ_M, which the Flywheel holds (or",
        "ramps) over the step. A master whose drivetrain exchanges torques can instead set",
        "GearRattle's `excitation = 2`: the main shaft is then an inertia `I_M` inside GearRattle",
        "(I_M ω_M' = τ_in + τ_M, default 0.008 kg m², the Flywheel's own I_M), the drivetrain's",
        "torque on it comes in as `tau_in` (held, or ramped with its derivative of order 1), and the",
        "shaft's motion goes out as `theta_M_out`, `omega_M_out`. The contact's reaction on the",
        "shaft, the term whose staircase dominates the errors above, is then resolved inside",
        "GearRattle's error control; only the drivetrain's torque (for this drivetrain the clutch",
        "damper's k_d φ + c_d (ω_E − ω_M), smooth at 22 Hz) crosses the interface. Not measured",
        "here: the Flywheel has no variant that hands out its damper torque.",
        "",
        "## Why C = 1e-3 N m s in the coupled runs",
        "",
        "The paper's lubricant drag C = 0.025 N m s was identified on a bench whose shaft",
        "oscillates about zero mean speed. At idle the loose gear turns at 640 rpm against its",
        "output shaft at rest (ω_S = 0): 1.6 N m of drag, which keeps it on one flank unless the",
        "main shaft's angular acceleration exceeds C ω_L r_L / (I_L r_M) ≈ 6500 rad/s², seven",
        "times what a plausible idle gives (≈ 900 rad/s²). 1e-3 N m s makes the spin drag",
        "0.064 N m, the order measured on loose gears, and the threshold ≈ 260 rad/s².",
        "",
    ]
    out_md.write_text("\n".join(lines))


def write_study(out="docs", t_end=0.5, steps=STEPS, me_rtols=ME_RTOLS, me_solvers=ME_SOLVERS):
    """Run the study (steps, me_rtols, me_solvers: comma-separated) and write its report and
    figure into `out`, its raw figures into target/coupling."""
    for path in (MS.GEAR_FMU, MS.FLYWHEEL_FMU):
        if not path.is_file():
            sys.exit(f"{path} missing: run `make coupling-study` (it builds both FMUs)")
    out_arg, out = out, pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    raw = ROOT / "target" / "coupling"
    raw.mkdir(parents=True, exist_ok=True)
    hs = sorted((float(x) for x in steps.split(",")), reverse=True)
    started = time.time()
    labels = [lab for lab, _ in variants()]
    kinds = dict(variants())

    # the reference's own accuracy: rtol 1e-10 against 1e-12
    t = np.linspace(0.0, t_end, 2001)
    a, b = M.simulate(t_end, t, rtol=1e-10), M.simulate(t_end, t, rtol=1e-12)
    ref_check = dict(xi=float(np.max(np.abs(a.xi - b.xi)) / G), omega=float(np.max(np.abs(a.omega_M - b.omega_M))))
    print(f"reference rtol 1e-10 vs 1e-12: {ref_check['xi']:.1e} G, {ref_check['omega']:.1e} rad/s", flush=True)

    refs = {}

    def reference_at(h):
        """The reference sampled every h (each h computed once)."""
        if h not in refs:
            refs[h] = M.simulate(t_end, np.arange(int(round(t_end / h)) + 1) * h)
        return refs[h]

    rows = []
    for h in hs:
        ref = reference_at(h)
        for label in labels:
            t0 = time.time()
            rec = run(kinds[label], t_end, h)
            row = dict(variant=label, h=h, wall=time.time() - t0, **errors(rec, ref))
            rows.append(row)
            print(
                f"h = {fmt_h(h):>7}  {label:22s} omega {row['omega_window']:.2e} rad/s  xi {row['xi_window']:.3g} G"
                f"  rate {row['rate']:.0f}/s ({100 * row['rate_rel']:.1f} %)  {row['wall']:.1f} s",
                flush=True,
            )
    me_rows = []
    for solver in me_solvers.split(","):
        for rtol in (float(x) for x in me_rtols.split(",")):
            rec, cost = ME.simulate(t_end, ME_DT, rtol, solver, jacobian=True)
            row = dict(solver=solver, rtol=rtol, **dataclasses.asdict(cost), **errors(rec, reference_at(ME_DT)))
            me_rows.append(row)
            print(
                f"Model Exchange {solver:6s} rtol {rtol:.0e}  omega {row['omega_window']:.2e} rad/s  xi {row['xi_window']:.3g} G"
                f"  rate {row['rate']:.0f}/s ({100 * row['rate_rel']:.1f} %)  {row['wall']:.1f} s, {row['rhs']} rhs, {row['events']} events",
                flush=True,
            )
    for name, table_rows in (("coupling.csv", rows), ("model_exchange.csv", me_rows)):
        with open(raw / name, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(table_rows[0]))
            w.writeheader()
            w.writerows(table_rows)
    plot(rows, labels, me_rows, out / "coupling_error.png")
    default = [f"{h:g}" for h in DEFAULT_STEPS]
    command = "scripts/coupling_study.py --out " + str(out_arg)
    if [f"{h:g}" for h in hs] != default:
        command += f" --steps {steps}"
    if not math.isclose(t_end, 0.5):
        command += f" --t-end {t_end:g}"
    if me_rtols != ME_RTOLS:
        command += f" --me-rtols {me_rtols}"
    if me_solvers != ME_SOLVERS:
        command += f" --me-solvers {me_solvers}"
    report(rows, labels, hs, t_end, ref_check, time.time() - started, command, out / "COUPLING.md", me_rows)
    print(f"wrote {out / 'COUPLING.md'}, {out / 'coupling_error.png'}, {raw / 'coupling.csv'}, {raw / 'model_exchange.csv'}")
