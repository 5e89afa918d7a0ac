//! `documentation/index.html` inside GearRattle's FMU: the equations of docs/MODEL.md with the
//! paper's numbers, and the parameter and variable tables generated from the contract.

use crate::contracts::gear_rattle::{Causality, VARIABLES, Variable};

/// The start of a model's page up to its title.
pub fn head(model: &str) -> String {
    format!(
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{model}</title>
<style>body{{font-family:sans-serif;max-width:60em;margin:2em auto;line-height:1.4}}
table{{border-collapse:collapse}}td,th{{border:1px solid #bbb;padding:.2em .5em;text-align:left}}
code,pre{{background:#f4f4f4}}</style></head><body>
<h1>{model}</h1>
"#
    )
}

const HEAD: &str = r#"<p>A loose gear rattling in its backlash against a main shaft, after J.-L. Dion, S. Le Moyne,
G. Chevallier, H. Sebbah, <i>Gear impacts and idle gear noise: experimental study and non-linear
dynamic model</i>, Mechanical Systems and Signal Processing 23(8), 2009, pp. 2608-2628.
FMI 2.0 Co-Simulation and Model Exchange. In Co-Simulation the solver is inside (adaptive Dormand-Prince 5(4) with error control,
Taylor-series steps of order 11 in full contact, handing over to Radau IIA of order 5 while
the equations are stiff (parameter <code>solver</code>), and steps that end exactly on the
edges of the contact law).</p>
<h2>Equations</h2>
<p>Transmission error on the pitch line (the integrated coordinate, so hours of running lose
no micrometres): <code>ξ = r_L θ_L − r_M θ_M</code>, <code>ξ' = r_L ω_L − r_M ω_M</code>.
Gap: <code>0 &lt; ξ &lt; G</code>; flank F+ is <code>ξ ≤ 0</code>, flank F− is <code>ξ ≥ G</code>.</p>
<p>Smoothing over the manufacturing-error width ε: s = 1 for ξ ≤ −ε;
s = ½(1 − sin(π/ε (ε/2 + ξ))) for −ε ≤ ξ ≤ 0; s = 0 in the gap;
s = ½(1 − sin(π/ε (ε/2 − (ξ − G)))) for G ≤ ξ ≤ G + ε; s = 1 for ξ ≥ G + ε.</p>
<p>Contact force, with the penetration δ = ξ on F+ and δ = ξ − G on F−:
<code>F = s K* δ |δ/G|^(α−1) + s C_LM ξ'</code>.</p>
<p>Loose gear: <code>I_L ω_L' = B − r_L F − C (ω_L − ω_S)</code>.
Torque on the main shaft: <code>τ_M = r_M F</code>.</p>
<p>An impact is a contact onset: ξ leaving the gap (crossing 0 downwards on F+, G upwards on
F−); its speed is |ξ'| at that instant.</p>
<h2>Main shaft</h2>
<p><code>excitation = 1</code> (sine): the paper's bench, a_M = √2 A_rms sin(2π f_exc t) on a mean
speed ω̄, exact θ_M, ω_M, a_M inside every step; no wiring needed.
<code>excitation = 0</code> (inputs, default): the master sets θ_M, ω_M and optionally α_M at each
communication point; within the step the FMU extrapolates θ_M + ω_M τ + α_M τ²/2 (never a
zero-order hold, which would make ξ jump by r_M ω_M h). An input the master does not set again
continues along that extrapolation. Setting new inputs moves ξ and ξ' at once (the loose gear
does not move), so outputs read right after reflect them.</p>
<p><code>excitation = 2</code> (torque): the main shaft is a rigid inertia I_M driven by the
drivetrain's torque <code>tau_in</code> and by the contact's reaction,
<code>I_M ω_M' = τ_in + τ_M</code> with <code>τ_M = r_M F</code>; θ_M and ω_M are integrated with
the gear pair, starting from the values of the inputs theta_M and omega_M at
fmi2ExitInitializationMode, and come out as theta_M_out, omega_M_out, alpha_M_out.
τ_in is held over the step, or ramped with its first derivative
(fmi2SetRealInputDerivatives); a new τ_in moves alpha_M_out at once by Δτ_in / I_M. With
C = C_LM = B = 0, <code>½ I_L ω_L² + ½ I_M ω_M² + V(ξ) − ∫ τ_in ω_M dt</code> is constant.</p>
<h2>Use from fmpy</h2>
<pre>from fmpy import simulate_fmu
r = simulate_fmu("GearRattle.fmu", stop_time=1.0, output_interval=1e-5,
                 start_values={"excitation": 1, "f_exc": 30.0, "A_rms": 300.0},
                 output=["xi", "a_pitch_L", "impacts_Fplus", "impacts_Fminus"])</pre>
<h2>Rattle statistics</h2>
<p>Set <code>stats_from</code> &ge; 0 to get them (by default, &minus;1, no window is open,
the outputs read 0 and cost nothing). Over the window from <code>stats_from</code> to the
current time T long (the outputs
<code>stat_*</code>, listed below with their formulas): impacts are counted at the located
contact onsets, with their speeds v = |ξ'|, runs of consecutive impacts on one flank and impact
energies ½ m_eq v² (m_eq = I_L / r_L²); the RMS of the pitch-line acceleration a = r_L α_L
(√(∫a² dt / T)), the contact force's standard deviation and the dissipated powers come from
integrals carried with the state; the peak |a| is located on each internal step.</p>
<h2>Model Exchange</h2>
<p>The importer integrates ten continuous states: ξ, ω_L, the main shaft's θ_M and ω_M
(torque mode; otherwise unused), the dissipated energies, the shaft's work and the integrals
∫a², ∫F, ∫F² (the locals <code>der(...)</code> are their derivatives). Five event indicators:
ξ + ε, ξ, ξ − G, ξ − G − ε (the contact law's edges) and ξ' while in the gap (turning points);
impacts are counted at the events. In the inputs mode the derivatives read theta_M and
omega_M as set.</p>
<h2>Error against run time</h2>
<p>Error (max |Δξ| against a tight independent reference) against CPU time on the paper's
scene S1, beside Rust ODE crates and scipy on the same equations (<code>make bench</code> in the
repository; docs/BENCHMARKS.md there has the tables).</p>
<img src="work_precision.png" alt="work-precision plot" style="max-width:100%">
<h2>Use from libcosim</h2>
<p>In a drivetrain (<code>excitation = 0</code>): the partner drives <code>theta_M</code>,
<code>omega_M</code>, <code>alpha_M</code> (value references 20, 21, 22) and takes <code>tau_M</code>
(value reference 37). With libcosimpy and a main-shaft FMU whose outputs theta_M, omega_M,
alpha_M are value references 20, 21, 22 and whose torque input is 10 (the repository's
partners/flywheel):</p>
<pre>from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimSlave import CosimLocalSlave

ex = CosimExecution.from_step_size(step_size=100_000)          # 0.1 ms, in ns
gear = ex.add_local_slave(CosimLocalSlave(fmu_path="GearRattle.fmu", instance_name="gear"))
shaft = ex.add_local_slave(CosimLocalSlave(fmu_path="Flywheel.fmu", instance_name="flywheel"))
for vr in (20, 21, 22):                                        # theta_M, omega_M, alpha_M
    ex.connect_real_variables(shaft, vr, gear, vr)
ex.connect_real_variables(gear, 37, shaft, 10)                  # tau_M -> the shaft
ex.simulate_until(target_time=500_000_000)                      # 0.5 s</pre>
"#;

/// The work-precision plot of `make bench` (docs/work_precision.png), shown on the page.
pub const WORK_PRECISION_PNG: &[u8] = include_bytes!("../../docs/work_precision.png");

/// The tables of a model's parameters, inputs, outputs and Model Exchange locals, generated
/// from its contract's variables.
pub fn tables(variables: &[Variable]) -> String {
    [
        ("Parameters", Causality::Parameter),
        ("Inputs", Causality::Input),
        ("Outputs", Causality::Output),
        ("Model Exchange states and derivatives", Causality::Local),
    ]
    .iter()
    .map(|&(title, causality)| fmi2_shell::table::html(title, variables, causality))
    .collect()
}

/// The whole page.
pub fn index_html() -> String {
    head("GearRattle")
        + HEAD
        + &tables(VARIABLES)
        + "<p>The defaults are the paper's model values (§7), including its 25 µm model backlash; \
the paper's measurements suggest an actual backlash near 80 µm.</p>\n</body></html>\n"
}
