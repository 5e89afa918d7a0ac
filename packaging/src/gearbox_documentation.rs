//! `documentation/index.html` inside GearboxRattle's FMU: the model of docs/GEARBOX.md in
//! short, and the parameter and variable tables generated from its contract.

use crate::contracts::gearbox_rattle::VARIABLES;

const HEAD: &str = r#"<p>The loose gears (1 to 8, <code>n_gears</code>) of a manual gearbox rattling at idle, each
with the contact law of J.-L. Dion et al. (Mechanical Systems and Signal Processing 23(8),
2009), on an input side driven through a two-stage clutch damper. FMI 2.0 Co-Simulation
with the solver inside (adaptive Dormand-Prince 5(4), handing over to Radau IIA while the
equations are stiff, parameter <code>solver</code>), steps ending exactly on every gear's band
edges and on the damper's stage edges ±φ_1.</p>
<h2>Equations</h2>
<p>Gear i's transmission error <code>ξ_i = r_L,i θ_L,i − r_M,i ρ_i θ_I</code>, its contact force
F_i as GearRattle's. Damper twist <code>φ = θ_F − θ_I</code>, torque
<code>T_cl = T_k(φ) + H(φ) tanh(φ'/ω_h) + c_cl φ'</code> with
<code>T_k = k_1 φ</code> for |φ| ≤ φ_1 and <code>sign(φ)(k_1 φ_1 + k_2 (|φ| − φ_1))</code> beyond,
H = H_1 or H_2 by stage.</p>
<p><code>I_I ω_I' = T_cl + Σ ρ_i r_M,i F_i − c_I(T) ω_I</code>,
<code>I_L,i ω_L,i' = B_i − r_L,i F_i − C_i(T)(ω_L,i − σ_i ω_out)</code>.
The drags are given at 40 °C and follow the oil's viscosity (Vogel's law from ν_40, ν_100) at
<code>T_oil</code>.</p>
<h2>Drive</h2>
<p><code>excitation = 1</code> (default): the built-in engine, <code>rpm</code> (ramped by
<code>rpm_rate</code>) with two engine orders of angular-acceleration amplitudes a_1, a_2.
<code>excitation = 0</code>: the flywheel's θ_F, ω_F, α_F from the drivetrain (inputs),
extrapolated over each step; <code>tau_F</code> is the torque back on the flywheel.
<code>excitation = 2</code>: the input side's θ_I, ω_I, α_I from the drivetrain, without the
damper; <code>tau_I</code> is the gears' torque on it.</p>
<h2>Rattle statistics</h2>
<p>Per gear over the window from <code>stats_from</code> to now, as GearRattle's
<code>stat_*</code>; the box's <code>stat_rattle_power</code> sums them, each gear's
<code>stat_rattle_share</code> is its part and <code>stat_loudest_gear</code> the gear to treat
first.</p>
<h2>Use from fmpy</h2>
<pre>from fmpy import simulate_fmu
r = simulate_fmu("GearboxRattle.fmu", stop_time=1.0, output_interval=1e-3,
                 start_values={"T_oil": 40.0},
                 output=["phi", "gear[1].impacts_Fplus", "stat_rattle_power"])</pre>
<h2>FMI 3.0 edition</h2>
<p>The same model, its per-gear variables (<code>gear[i].NAME</code> below) declared once as the
arrays <code>gear.NAME</code> of length <code>n_gears</code>, a structural parameter set in
configuration mode (five gears by default: <code>output=["gear.impacts_Fplus"]</code> records
the five gears' counts at each point). Co-Simulation returns early at the first impact of any gear where the importer
allows it, with event mode.</p>
"#;

/// The whole page.
pub fn index_html() -> String {
    use crate::documentation::{head, tables};
    head("GearboxRattle") + HEAD + &tables(VARIABLES) + "</body></html>\n"
}
