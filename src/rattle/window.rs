//! The rattle statistics over the window [stats_from, t] (docs/STUDIES.md, "Metric
//! definitions"): what happens at the located events (impacts, runs, contact time) is counted
//! here as the integrator crosses the edges, and the peak pitch-line acceleration is taken on
//! each accepted step's dense output; the integrals (∫a² dt, ∫F dt, ∫F² dt and the dissipated
//! energies) are quadratures of the state, read as their increase since the window opened.
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

use crate::integrator::resolution;
use crate::physics::Region;

/// The quadratures of a gear pair's state, in this order from its `E_CONTACT` component on:
/// the energies of docs/MODEL.md §3's balance, then the integrals behind the RMS and the standard
/// deviation of the window (carried only by a pair with a window: the first [`ENERGIES`]
/// are the state of a pair without).
pub mod quadrature {
    /// ∫ F_c ξ' dt: energy dissipated in the contact damping [J].
    pub const E_CONTACT: usize = 0;
    /// ∫ C (ω_L − ω_S)² dt: energy dissipated by the lubricant [J].
    pub const E_LUBRICANT: usize = 1;
    /// ∫ −τ_M ω_M dt: work the main shaft feeds into the loose gear [J].
    pub const W_SHAFT: usize = 2;
    /// The energies and the work: the quadratures every pair carries.
    pub const ENERGIES: usize = 3;
    /// ∫ a² dt, a = r_L α_L the pitch-line acceleration [m²/s³].
    pub const A2: usize = 3;
    /// ∫ F dt [N s].
    pub const F1: usize = 4;
    /// ∫ F² dt [N² s].
    pub const F2: usize = 5;
    pub const COUNT: usize = 6;
}

pub type Quadratures = [f64; quadrature::COUNT];

/// What the window counts on one flank.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FlankStats {
    pub impacts: u64,
    pub runs: u64,
    pub run_max: u64,
    /// Σ v, Σ v² and max v over the impact speeds v = |ξ'| at the onsets [m/s].
    pub v_sum: f64,
    pub v2_sum: f64,
    pub v_max: f64,
}

/// The statistics window of a gear pair: opened at `from`, counting the events after it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Window {
    /// Where the window opens [s].
    pub from: f64,
    pub flanks: [FlankStats; 2],
    /// The flank (0: F+, 1: F−) and length of the run the last impact in the window belongs to.
    run: Option<(usize, u64)>,
    /// When the current contact began, if the pair is in contact.
    contact_since: Option<f64>,
    /// Time in contact inside the window, up to the start of the current contact [s].
    contact_time: f64,
    /// Peak |a| inside the window so far [m/s²].
    pub a_peak: f64,
    /// The last |a| sampled (at an accepted step's end or an edge) and its time, where the
    /// next step's sampling starts.
    pub last: Option<(f64, f64)>,
    /// The quadratures when the window opened; None until then.
    opened: Option<Quadratures>,
}

/// The window's figures at a time t (see the contract's stat_* outputs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// T = t − from, 0 before the window opens.
    pub length: f64,
    pub flanks: [FlankStats; 2],
    /// Σ ½ m_eq v² per flank [J].
    pub impact_energy: [f64; 2],
    pub contact_fraction: f64,
    pub a_rms: f64,
    pub a_peak: f64,
    pub F_std: f64,
    pub P_contact: f64,
    pub P_lubricant: f64,
}

/// ∂/∂q of the window's figures that move with the quadratures (Model Exchange's
/// directional derivatives): a row over the quadratures for each. The other figures change
/// at events only.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Slopes {
    pub a_rms: Quadratures,
    pub F_std: Quadratures,
    pub P_contact: Quadratures,
    pub P_lubricant: Quadratures,
}

/// Where a statistics window that opens at `from` opens in a step from t to t_end, if it
/// does: at `from`, or at the step's start or end where `from` lies within the resolution of
/// time of it (the solver could not step the sliver between them: [`resolution`]); None if
/// it opens later (or never: `from` infinite).
pub fn opening(from: f64, t: f64, t_end: f64) -> Option<f64> {
    // A step from a to b that the solver refuses (a backward one too).
    let refused = |a: f64, b: f64| b - a <= resolution(a, b);
    if !from.is_finite() {
        None
    } else if refused(t, from) {
        Some(t)
    } else if refused(from, t_end) && refused(t_end, from) {
        Some(t_end)
    } else {
        (from <= t_end).then_some(from)
    }
}

impl Window {
    /// A window opening at `from` for a pair that starts at t0 in `region`.
    pub fn new(from: f64, t0: f64, region: Region) -> Self {
        Window {
            from: from.max(t0),
            flanks: [FlankStats::default(); 2],
            run: None,
            contact_since: (region != Region::Gap).then_some(t0),
            contact_time: 0.0,
            a_peak: 0.0,
            last: None,
            opened: None,
        }
    }

    /// A window that never opens: nothing is counted, no peak sought.
    pub fn closed(region: Region) -> Self {
        Window::new(f64::INFINITY, 0.0, region)
    }

    /// Whether the window is open at t.
    #[inline]
    pub fn is_open_at(&self, t: f64) -> bool {
        t >= self.from
    }

    /// Whether the quadratures at the opening are kept (see [`Window::open`]).
    pub fn is_opened(&self) -> bool {
        self.opened.is_some()
    }

    /// Keeps the quadratures at the window's opening (called once, at t = `from`).
    pub fn open(&mut self, q: Quadratures) {
        self.opened.get_or_insert(q);
    }

    /// A contact onset on `flank` (0: F+, 1: F−) at t with speed v = |ξ'|.
    pub fn impact(&mut self, t: f64, flank: usize, v: f64) {
        self.contact_since = Some(t);
        if !self.is_open_at(t) {
            return;
        }
        let length = match self.run {
            Some((f, n)) if f == flank => n + 1,
            _ => {
                self.flanks[flank].runs += 1;
                1
            }
        };
        self.run = Some((flank, length));
        let s = &mut self.flanks[flank];
        s.impacts += 1;
        s.run_max = s.run_max.max(length);
        s.v_sum += v;
        s.v2_sum += v * v;
        s.v_max = s.v_max.max(v);
    }

    /// The pair back in the gap at t: the contact's time inside the window is counted.
    pub fn separation(&mut self, t: f64) {
        if let Some(since) = self.contact_since.take() {
            self.contact_time += self.in_window(since, t);
        }
    }

    /// |a| seen at t.
    #[inline]
    pub fn acceleration(&mut self, t: f64, a: f64) {
        if self.is_open_at(t) {
            self.a_peak = self.a_peak.max(a.abs());
        }
    }

    /// Length of [since, t] inside the window.
    fn in_window(&self, since: f64, t: f64) -> f64 {
        (t - since.max(self.from)).max(0.0)
    }

    /// The figures at t, from the quadratures `q` at t; `m_eq` = I_L / r_L².
    pub fn metrics(&self, t: f64, q: &Quadratures, m_eq: f64) -> Metrics {
        let length = (t - self.from).max(0.0);
        let (Some(q0), true) = (self.opened, length > 0.0) else {
            return Metrics {
                length: 0.0,
                flanks: self.flanks,
                impact_energy: [0.0; 2],
                contact_fraction: 0.0,
                a_rms: 0.0,
                a_peak: self.a_peak,
                F_std: 0.0,
                P_contact: 0.0,
                P_lubricant: 0.0,
            };
        };
        use quadrature::*;
        let per_second = |i: usize| (q[i] - q0[i]) / length;
        let contact = self.contact_time + self.contact_since.map_or(0.0, |s| self.in_window(s, t));
        let F_mean = per_second(F1);
        Metrics {
            length,
            flanks: self.flanks,
            impact_energy: self.flanks.map(|f| 0.5 * m_eq * f.v2_sum),
            contact_fraction: contact / length,
            a_rms: per_second(A2).max(0.0).sqrt(),
            a_peak: self.a_peak,
            F_std: (per_second(F2) - F_mean * F_mean).max(0.0).sqrt(),
            P_contact: per_second(E_CONTACT),
            P_lubricant: per_second(E_LUBRICANT),
        }
    }

    /// The slopes of [`Window::metrics`] at t: with Δq = q − q(from) and T = t − from,
    /// ∂(√(Δq_a²/T))/∂q_a² = 1 / (2 T a_rms), ∂F_std/∂q_F² = 1 / (2 T F_std),
    /// ∂F_std/∂q_F = −F_mean / (T F_std), ∂P/∂q_E = 1 / T. Zero before the window opens, and
    /// where a root is zero (its slope is infinite there; the figure is held at 0).
    pub fn slopes(&self, t: f64, q: &Quadratures) -> Slopes {
        use quadrature::*;
        let m = self.metrics(t, q, 1.0);
        let mut s = Slopes::default();
        let (Some(q0), true) = (self.opened, m.length > 0.0) else {
            return s;
        };
        let length = m.length;
        if m.a_rms > 0.0 {
            s.a_rms[A2] = 0.5 / (length * m.a_rms);
        }
        if m.F_std > 0.0 {
            s.F_std[F2] = 0.5 / (length * m.F_std);
            s.F_std[F1] = -(q[F1] - q0[F1]) / (length * length * m.F_std);
        }
        s.P_contact[E_CONTACT] = 1.0 / length;
        s.P_lubricant[E_LUBRICANT] = 1.0 / length;
        s
    }
}

impl FlankStats {
    /// Mean run length (0 without runs).
    pub fn run_mean(&self) -> f64 {
        ratio(self.impacts as f64, self.runs)
    }

    pub fn v_mean(&self) -> f64 {
        ratio(self.v_sum, self.impacts)
    }

    pub fn v_rms(&self) -> f64 {
        ratio(self.v2_sum, self.impacts).sqrt()
    }
}

fn ratio(sum: f64, n: u64) -> f64 {
    if n == 0 { 0.0 } else { sum / n as f64 }
}

impl Metrics {
    /// Regime code: 0 no impact, 1 one-sided, 2 double-sided; and the flank of one-sided
    /// rattle as the `contact` output codes it (1 F+, 2 F−), else 0.
    pub fn regime(&self) -> (i64, i64) {
        match (self.flanks[0].impacts > 0, self.flanks[1].impacts > 0) {
            (false, false) => (0, 0),
            (true, false) => (1, 1),
            (false, true) => (1, 2),
            (true, true) => (2, 0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hand-made event sequence: the runs, counts, speeds, contact time and the window's
    /// opening, each against the value worked out by hand.
    #[test]
    fn events_counted_from_the_window_on() {
        let mut w = Window::new(1.0, 0.0, Region::Gap);
        // Before the window: an impact on F+ and its contact (0.5 to 0.6 s).
        w.impact(0.5, 0, 0.3);
        w.separation(0.6);
        // Its contact lasts across the opening (0.9 to 1.2 s: 0.2 s inside).
        w.impact(0.9, 0, 0.3);
        w.open([0.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
        w.separation(1.2);
        // F+ F+ F− F+: runs F+ 2 (lengths 2 and 1), F− 1; contacts of 0.1 s each.
        for (t, flank, v) in [(1.5, 0, 0.1), (2.0, 0, 0.2), (2.5, 1, 0.4), (3.0, 0, 0.3)] {
            w.impact(t, flank, v);
            w.separation(t + 0.1);
        }
        // In contact again at 3.5 s, still at 4 s (0.5 s).
        w.impact(3.5, 1, 0.5);
        let q = [3.0, 4.0, 0.0, 12.0, 6.0, 24.0];
        let m = w.metrics(4.0, &q, 2.0);
        assert_eq!(m.length, 3.0);
        let [plus, minus] = m.flanks;
        assert_eq!((plus.impacts, plus.runs, plus.run_max), (3, 2, 2));
        assert_eq!((minus.impacts, minus.runs, minus.run_max), (2, 2, 1));
        assert!((plus.v_mean() - 0.2).abs() < 1e-15);
        assert!((plus.v_rms() - (0.14f64 / 3.0).sqrt()).abs() < 1e-15);
        assert_eq!(minus.v_max, 0.5);
        assert!((m.impact_energy[1] - (0.16 + 0.25)).abs() < 1e-15);
        assert!((m.contact_fraction - (0.2 + 0.4 + 0.5) / 3.0).abs() < 1e-15);
        assert_eq!((m.P_contact, m.P_lubricant), (1.0, 1.0));
        assert_eq!(m.a_rms, 2.0);
        assert_eq!(m.F_std, 2.0);
        assert_eq!(m.regime(), (2, 0));
    }

    /// A window opens where it is asked to, unless that lies within the resolution of time of
    /// the step's start or end: then there (the solver's resolution, 16 machine epsilons of
    /// the time, is 1.07e-16 s about 0.03 s, 30.7 ulps of 3.5e-18 s).
    #[test]
    fn a_window_opens_on_a_step_end_within_the_resolution_of_time() {
        let (t, t_end) = (0.029, 0.029 + 1e-3);
        let ulps = |x: f64, n: i64| f64::from_bits((x.to_bits() as i64 + n) as u64);
        assert_eq!(t_end, ulps(0.03, 1));
        let cases = [
            (0.03, Some(t_end)),
            (ulps(t_end, -30), Some(t_end)),
            (ulps(t_end, 30), Some(t_end)),
            (ulps(t_end, -31), Some(ulps(t_end, -31))),
            (ulps(t_end, 31), None),
            (t_end, Some(t_end)),
            (ulps(t, 29), Some(t)),
            (ulps(t, 30), Some(ulps(t, 30))),
            (t, Some(t)),
            (0.0295, Some(0.0295)),
            (f64::INFINITY, None),
        ];
        for (from, at) in cases {
            assert_eq!(opening(from, t, t_end), at, "{from}");
        }
    }

    /// Before the window opens, nothing is counted and every figure is zero.
    #[test]
    fn nothing_before_the_window() {
        let mut w = Window::new(1.0, 0.0, Region::ContactPlus);
        w.impact(0.5, 1, 0.2);
        w.acceleration(0.7, 300.0);
        let m = w.metrics(0.8, &[1.0; quadrature::COUNT], 1.0);
        assert_eq!(m.length, 0.0);
        assert_eq!(m.flanks[1].impacts, 0);
        assert_eq!((m.a_peak, m.contact_fraction), (0.0, 0.0));
        assert_eq!(m.regime(), (0, 0));
    }
}
