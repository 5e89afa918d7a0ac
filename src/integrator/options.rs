//! The integrator's tuned constants in one place: what each one does, why it has its value,
//! and where the measurement behind it is (docs/DECISIONS.md). Hairer's textbook constants of
//! RADAU5 stay in `radau5`, next to the algorithm they belong to.

/// The tuned constants of the driver and its steppers. The one value in use is [`OPTIONS`];
/// its fields are compile-time constants wherever they are read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Most steps (Taylor steps and Runge-Kutta attempts) one call of `Solver::advance` may
    /// take before it gives up ([`super::SolverError::TooManySteps`]): a guard against a
    /// step size collapsing without falling below the resolution of time.
    pub max_steps: u64,
    /// Edge crossings at one instant, without progress in time, before the solver gives up
    /// ([`super::SolverError::Chattering`]): a state that keeps being sent back and forth
    /// across an edge.
    pub crossings_at_once: u32,
    /// A step is too small when it is at most this many machine epsilons of the time
    /// ([`super::SolverError::StepTooSmall`]): t + h could no longer be told from t.
    pub min_step_ulps: f64,
    /// A step that would end within this factor of the end time is stretched to end on it
    /// (Hairer's 1.01), so that no sliver of a step is left.
    pub sliver: f64,
    /// The first DOPRI5 step into a piece that is rough at its start
    /// (`Piecewise::rough_start`) is accepted at 1/`first_step_distrust` of the tolerance:
    /// where a force law starts at the edge as a non-integer power (F ∝ δ^α), DOPRI5's
    /// embedded estimate understates the first step's error 6 to 20 times; applied at every
    /// crossing the factor only moves errors around (docs/DECISIONS.md, D6).
    pub first_step_distrust: f64,
    /// Taylor coefficients per component, order 11: near orders cost about the same at
    /// equal error on S1 (docs/DECISIONS.md, D2).
    pub taylor_terms: usize,
    /// Share of the error weights (atol + rtol·|y|) given to a Taylor step's last two terms.
    /// DOPRI5's weight bounds its embedded 4th-order estimate, which overstates the error of
    /// the solution it propagates; a series' last terms are close to its truncation error,
    /// hence a smaller share. With 1, S2's impact rates leave what
    /// `test_sine_s2_statistics` allows; above 0.1 the contacts' share of S1's error grows
    /// (docs/DECISIONS.md, D2).
    pub taylor_share: f64,
    /// Pieces whose first step is learnt (`entries`); with more entered in turn the oldest
    /// is forgotten. A gear pair has five regions (docs/DECISIONS.md, D4).
    pub entry_slots: usize,
    /// The learnt ratio of the first step into a piece to its base stays within
    /// [`entry_ratio_min`, `entry_ratio_max`]: 5 is the controller's largest growth
    /// (docs/DECISIONS.md, D4).
    ///
    /// [`entry_ratio_min`]: Options::entry_ratio_min
    /// [`entry_ratio_max`]: Options::entry_ratio_max
    pub entry_ratio_min: f64,
    pub entry_ratio_max: f64,
    /// DOPRI5's controller: the safety factor on each new step and the PI controller's β
    /// (Hairer's 0.9 and 0.04; 0.7, 0.8, 0.95 and β = 0.08 were no better at equal error:
    /// docs/DECISIONS.md, D8).
    pub safety: f64,
    pub beta: f64,
    /// Largest shrink and growth of DOPRI5's step from one step to the next (Hairer's 1/10
    /// and 5).
    pub min_factor: f64,
    pub max_factor: f64,
    /// h·ρ above which a DOPRI5 step counts as held back by stability, both ways of the
    /// hand-over (`stiffness`): below Hairer's 3.25 because DOPRI5's stability radius
    /// shrinks towards the imaginary axis, where a damped contact's eigenvalues lie (3.0 at
    /// a damping ratio of 0.2, 2.3 at 0.035).
    pub stiff_h_rho: f64,
    /// Stiff verdicts that make a problem stiff, and accepted Radau IIA steps in a row
    /// within DOPRI5's stability that make it non-stiff again: 5, not Hairer's 15, because
    /// a gear pair's stiff phases are short (a contact between two impacts) and each verdict
    /// waited for costs a step bounded by stability (or a short implicit one); S1 (never
    /// stiff) is not handed over either way (docs/DECISIONS.md, D38).
    pub stiff_steps: u32,
    /// Non-stiff verdicts in a row that restart the count of stiff ones (Hairer's 6).
    pub calm_steps: u32,
    /// A passage through a piece in closed form leaves it when its guard is within this
    /// share of the guard's absolute tolerance of an edge (or within `min_step_ulps` rounding
    /// errors of the edge's value), moving out.
    pub exit_share: f64,
    /// Most evaluations of a closed-form solution in one call's search for its exit
    /// ([`super::SolverError::SearchStalled`]): a guard creeping along an edge.
    pub max_exit_evals: u64,
}

/// The constants in use.
pub const OPTIONS: Options = Options {
    max_steps: 10_000_000,
    crossings_at_once: 8,
    min_step_ulps: 16.0,
    sliver: 1.01,
    first_step_distrust: 20.0,
    taylor_terms: 12,
    taylor_share: 0.1,
    entry_slots: 8,
    entry_ratio_min: 0.01,
    entry_ratio_max: 5.0,
    safety: 0.9,
    beta: 0.04,
    min_factor: 0.1,
    max_factor: 5.0,
    stiff_h_rho: 2.0,
    stiff_steps: 5,
    calm_steps: 6,
    exit_share: 1e-3,
    max_exit_evals: 100_000,
};
