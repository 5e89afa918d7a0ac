//! The rattling gear as a piecewise-smooth ODE for the integrator: the state layout, the
//! right-hand side (docs/MODEL.md §3 plus the dissipated energies and the shaft's work as
//! quadratures), the region as the current piece, and the impact counters (docs/MODEL.md §1: an
//! impact is ξ leaving the gap, across 0 downwards on F+ or G upwards on F−). [`torque`] is
//! the same gear pair with the main shaft an inertia driven by a torque (torque mode);
//! [`window`] the rattle statistics over a window of time. A pair carries the window's
//! quadratures only when a window is asked for ([`Rattle`]; [`LeanRattle`] without them).
#![allow(non_snake_case)]

pub mod torque;
pub mod window;

use serde::{Deserialize, Serialize};

use crate::integrator::taylor::{Coefficients, TERMS};
use crate::integrator::{ClosedForm, Dense, Edge, Jacobian, Piecewise, System, Tolerance};
use crate::math;
use crate::physics::{
    ContactLaw, ContactSeries, Dynamics, Excitation, Flight, FlightStart, FlightState, GearParams,
    Loads, Region, Shaft,
};
use window::{Quadratures, Window, quadrature};

/// Components of the state vector: ξ, ξ', then the quadratures of [`window::quadrature`]
/// (the dissipated energies, the shaft's work, and with a statistics window ∫a² dt, ∫F dt,
/// ∫F² dt).
pub const XI: usize = 0;
pub const XI_DOT: usize = 1;
pub const E_CONTACT: usize = 2;
pub const E_LUBRICANT: usize = E_CONTACT + quadrature::E_LUBRICANT;
pub const W_SHAFT: usize = E_CONTACT + quadrature::W_SHAFT;
/// Size of the state with the statistics window's quadratures.
pub const N: usize = E_CONTACT + quadrature::COUNT;
/// Size of the state without them: the energies and the work alone.
pub const N_LEAN: usize = E_CONTACT + quadrature::ENERGIES;

pub type State = [f64; N];

/// The pair with every quadrature, as a run with a statistics window needs it.
pub type Rattle = KinematicRattle<N>;
/// The pair without the window's quadratures (a run that asks for no statistics).
pub type LeanRattle = KinematicRattle<N_LEAN>;

/// Impacts counted so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Impacts {
    /// Contact onsets on flank F+ and F−.
    pub count: [u64; 2],
    /// |ξ'| at the last onset [m/s].
    pub last_speed: f64,
}

/// The gear pair, the region it is in, and what drives the main shaft; its state has `N`
/// components, the quadratures of [`window::quadrature`] up to `N` ([`Rattle`],
/// [`LeanRattle`]; with `N` = 2, ξ and ξ' alone, it measures what the energies cost:
/// tests/extras_cost.rs).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct KinematicRattle<const N: usize> {
    pub dynamics: Dynamics,
    pub region: Region,
    pub excitation: Excitation,
    pub impacts: Impacts,
    pub window: Window,
    /// The start of the free flight the solver is passing through, kept for its points
    /// ([`Piecewise::exact`]).
    flight_start: Option<FlightStart>,
}

impl<const N: usize> KinematicRattle<N> {
    /// The pair at ξ, with no statistics window (one opens with [`GearPair::with_window`]).
    pub fn new(dynamics: Dynamics, excitation: Excitation, xi: f64) -> Self {
        let region = dynamics.law.classify(xi);
        KinematicRattle {
            region,
            dynamics,
            excitation,
            impacts: Impacts::default(),
            window: Window::closed(region),
            flight_start: None,
        }
    }

    /// Error weights: ξ on the scale of G; ξ' relative to itself, with a floor of G per
    /// millisecond (or G times the contact frequency, if lower). An error δ in ξ' moves ξ by
    /// δ·G/|ξ'| over a flight across the gap, so ξ' must be held to rtol·|ξ'|, not to the
    /// contact's speed scale: with hard contacts (K* = 1e10) that looser floor let ξ drift by
    /// 100 rtol per flight. The energies are quadratures outside the error control. Each step
    /// gets [`LOCAL_SHARE`] of the requested rtol.
    pub fn tolerance(&self, rtol: f64) -> Tolerance<N> {
        let rtol = rtol * LOCAL_SHARE;
        let (xi_scale, xi_dot_scale) = scales(&self.dynamics.params);
        let mut atol = [0.0; N];
        (atol[XI], atol[XI_DOT]) = (rtol * xi_scale, rtol * xi_dot_scale);
        Tolerance {
            rtol,
            atol,
            controlled: 2,
        }
    }
}

/// What the co-simulation reads from the gear pair whatever drives its main shaft: ξ and ξ'
/// are the components `XI` and `XI_DOT` (the one guard and its rate); the quadratures of
/// [`window::quadrature`] follow each other from `E_CONTACT` on.
pub trait GearPair<const N: usize>: Piecewise<N> {
    const XI: usize;
    const XI_DOT: usize;
    const E_CONTACT: usize;
    fn dynamics(&self) -> &Dynamics;
    fn region(&self) -> Region;
    fn impacts(&self) -> &Impacts;
    fn window(&self) -> &Window;
    fn window_mut(&mut self) -> &mut Window;
    /// The pair starting at t0 with its statistics window opening at `stats_from`.
    fn with_window(mut self, t0: f64, stats_from: f64) -> Self
    where
        Self: Sized,
    {
        let region = self.region();
        *self.window_mut() = Window::new(stats_from, t0, region);
        self
    }
    /// θ_M, ω_M and a_M of the main shaft at (t, y).
    fn shaft(&self, t: f64, y: &[f64; N]) -> Shaft;
    /// The loads at (t, y) in the current region.
    fn loads_at(&self, t: f64, y: &[f64; N]) -> Loads {
        let shaft = self.shaft(t, y);
        let (xi, xi_dot) = (y[Self::XI], y[Self::XI_DOT]);
        self.dynamics().loads(self.region(), xi, xi_dot, &shaft)
    }
    /// The quadratures at y; 0 for those the state does not carry.
    fn quadratures(y: &[f64; N]) -> Quadratures {
        std::array::from_fn(|i| y.get(Self::E_CONTACT + i).copied().unwrap_or(0.0))
    }
}

/// Share of the requested tolerance given to each step's local error. The request is read as
/// a bound on the error after a few impacts, and the local errors of the steps add up over a
/// contact; with this share all 37 stress cases stay within 10 × rtol (docs/DECISIONS.md,
/// D21). It costs 4^(1/5) = 1.32 times the steps at a given request, not at a given error.
pub(crate) const LOCAL_SHARE: f64 = 0.25;

/// Scales of ξ and ξ' for the error weights (see [`Rattle::tolerance`]).
pub(crate) fn scales(p: &GearParams) -> (f64, f64) {
    const FLIGHT_RATE: f64 = 1e3;
    (p.G, p.G * p.contact_frequency().min(FLIGHT_RATE))
}

/// The region entered through `edge` at ξ' = xi_dot, and the flank (0: F+, 1: F−) of the
/// onset counted in `impacts` when it leaves the gap (docs/MODEL.md §1).
pub(crate) fn enter_region(
    law: &ContactLaw,
    region: Region,
    impacts: &mut Impacts,
    edge: Edge,
    xi_dot: f64,
) -> (Region, Option<usize>) {
    let onset = (region == Region::Gap).then(|| {
        let flank = if edge == Edge::Lower { 0 } else { 1 };
        impacts.count[flank] += 1;
        impacts.last_speed = xi_dot.abs();
        flank
    });
    let entered = match edge {
        Edge::Lower => law.below(region),
        Edge::Upper => law.above(region),
    };
    (entered, onset)
}

/// The region entered through `edge` at t ([`enter_region`]), with an onset recorded in the
/// window too, and a separation when it enters the gap.
pub(crate) fn cross_edge(
    dynamics: &Dynamics,
    region: Region,
    (impacts, window): (&mut Impacts, &mut Window),
    edge: Edge,
    t: f64,
    xi_dot: f64,
) -> Region {
    let (entered, onset) = enter_region(&dynamics.law, region, impacts, edge, xi_dot);
    if let Some(flank) = onset {
        window.impact(t, flank, xi_dot.abs());
    }
    if entered == Region::Gap {
        window.separation(t);
    }
    entered
}

impl<const N: usize> System<N> for KinematicRattle<N> {
    #[inline]
    fn rhs(&self, t: f64, y: &[f64; N]) -> [f64; N] {
        self.rhs_in(self.region, t, y)
    }
}

impl<const N: usize> KinematicRattle<N> {
    /// The right-hand side with the formula of `region` (the benchmark's peers keep the
    /// region apart, where their crates' closures can follow it).
    #[inline]
    pub fn rhs_in(&self, region: Region, t: f64, y: &[f64; N]) -> [f64; N] {
        let shaft = self.excitation.at(t);
        let loads = self.dynamics.loads(region, y[XI], y[XI_DOT], &shaft);
        let q = quadrature_rates(&self.dynamics.params, &loads, y[XI_DOT], shaft.omega);
        let mut f = [0.0; N];
        (f[XI], f[XI_DOT]) = (y[XI_DOT], loads.xi_ddot);
        f[E_CONTACT..].copy_from_slice(&q[..N - E_CONTACT]);
        f
    }
}

/// The rates of the quadratures of [`window::quadrature`]: docs/MODEL.md §3's energy balance (the
/// power lost in the contact damping F_c ξ', in the lubricant C (ω_L − ω_S)², the power
/// −τ_M ω_M the main shaft feeds in), then a², F and F² with a = r_L α_L.
#[inline]
pub(crate) fn quadrature_rates(
    p: &GearParams,
    loads: &Loads,
    xi_dot: f64,
    omega_M: f64,
) -> Quadratures {
    let slip = loads.omega_L - p.omega_S;
    let force = loads.force.total();
    let a = p.r_L * loads.alpha_L;
    [
        loads.force.dissipative * xi_dot,
        p.C * slip * slip,
        -p.r_M * force * omega_M,
        a * a,
        force,
        force * force,
    ]
}

/// The largest |a| on an accepted step from t0 of length h, for the window, and |a| at its
/// end: a at the step's ends (the start's from the step before, when it ended at t0) and
/// middle, and, where the parabola through them peaks inside the step above the window's
/// peak so far, that peak located by successive parabolic interpolation on the dense output.
/// In the gap the ends (or the window's opening) alone: the loose gear is free there,
/// I_L ω_L' = B − C (ω_L − ω_S) moves ω_L monotonically and a = (r_L / I_L)(B − C (ω_L − ω_S))
/// with it (docs/MODEL.md §3), so |a| peaks at an end. Points outside the current piece (past an
/// edge the step is redone to end on) are not the piece's and are left out.
pub(crate) fn step_peak<S: GearPair<N>, D: Dense<N>, const N: usize>(
    sys: &S,
    t0: f64,
    h: f64,
    step: &D,
) -> (f64, f64) {
    let (lo, hi) = sys.piece(0);
    let window = sys.window();
    let r_L = sys.dynamics().params.r_L;
    let a_at = |theta: f64| {
        let t = t0 + theta * h;
        // The loads read only the dynamic components, before the quadratures.
        let mut y = [0.0; N];
        for (i, y) in y.iter_mut().enumerate().take(S::E_CONTACT) {
            *y = step.dense(i, theta);
        }
        let xi = y[S::XI];
        if xi < lo || xi > hi || t < window.from {
            return 0.0;
        }
        (r_L * sys.loads_at(t, &y).alpha_L).abs()
    };
    let a0 = match window.last {
        Some((t, a)) if t == t0 => a,
        _ => a_at(0.0),
    };
    let a_end = a_at(1.0);
    if sys.region() == Region::Gap {
        let first = if t0 < window.from {
            a_at((window.from - t0) / h)
        } else {
            a0
        };
        return (first.max(a_end), a_end);
    }
    let points = [(0.0, a0), (0.5, a_at(0.5)), (1.0, a_end)];
    (refine_peak(points, window.a_peak, a_at), a_end)
}

/// The largest of |a| at three points (θ, |a|) of a step, θ = 0, ½, 1, and of the values
/// `a_at` gives where the parabola through the three around the largest so far peaks inside
/// the step above both that largest and `floor` (the window's peak so far): successive
/// parabolic interpolation, [`PEAK_ITERATIONS`] vertices at most.
pub fn refine_peak(
    mut points: [(f64, f64); 3],
    floor: f64,
    mut a_at: impl FnMut(f64) -> f64,
) -> f64 {
    let mut peak = points[0].1.max(points[1].1).max(points[2].1);
    for _ in 0..PEAK_ITERATIONS {
        let Some(theta) = parabola_peak(&points)
            .filter(|&(x, y)| (0.0..=1.0).contains(&x) && y > peak.max(floor))
            .map(|(x, _)| x)
        else {
            break;
        };
        let value = a_at(theta);
        peak = peak.max(value);
        // The three points around the largest value so far bracket the next vertex.
        let mut all = [points[0], points[1], points[2], (theta, value)];
        all.sort_by(|p, q| p.0.total_cmp(&q.0));
        let best = (1..3)
            .max_by(|&i, &j| all[i].1.total_cmp(&all[j].1))
            .unwrap_or(1);
        points = [all[best - 1], all[best], all[best + 1]];
    }
    peak
}

/// Vertices of successive parabolas tried per step: each adds about three correct digits to
/// the peak's position near a smooth maximum.
const PEAK_ITERATIONS: usize = 3;

/// Where the parabola through three points (in increasing x) peaks, and its value there;
/// None unless it opens downwards.
fn parabola_peak(p: &[(f64, f64); 3]) -> Option<(f64, f64)> {
    let [(x0, y0), (x1, y1), (x2, y2)] = *p;
    let (s01, s12) = ((y1 - y0) / (x1 - x0), (y2 - y1) / (x2 - x1));
    let curvature = (s12 - s01) / (x2 - x0);
    // y = y0 + s01 (x − x0) + curvature (x − x0)(x − x1), whose slope vanishes at the vertex.
    (curvature < 0.0).then(|| {
        let x = 0.5 * (x0 + x1) - 0.5 * s01 / curvature;
        (x, y0 + s01 * (x - x0) + curvature * (x - x0) * (x - x1))
    })
}

impl<const N: usize> Jacobian<N> for KinematicRattle<N> {
    /// ∂f/∂y of `rhs` for Radau IIA: the contact's slopes (docs/MODEL.md §2) through the equation of
    /// motion (§3), ∂ξ''/∂ξ = −(r_L²/I_L) ∂F/∂ξ and ∂ξ''/∂ξ' = −(r_L²/I_L) ∂F/∂ξ' − C/I_L. The
    /// rows of the quadratures (energies, work) are left zero: they do not act back on ξ, ξ',
    /// so Radau's simplified Newton iteration gives them their exact stage values from those
    /// of ξ, ξ' in each iteration, and they are outside the error control.
    fn jacobian(&self, _t: f64, y: &[f64; N]) -> [[f64; N]; N] {
        let p = &self.dynamics.params;
        let slopes = self.dynamics.law.slopes(self.region, y[XI], y[XI_DOT]);
        let lever = p.r_L * p.r_L / p.I_L;
        let mut j = [[0.0; N]; N];
        j[XI][XI_DOT] = 1.0;
        j[XI_DOT][XI] = -lever * slopes.d_xi;
        j[XI_DOT][XI_DOT] = -lever * slopes.d_xi_dot - p.C / p.I_L;
        j
    }
}

/// `GearPair` and `Piecewise` for a gear pair with fields `dynamics`, `region` and `impacts`,
/// and `window`, and ξ, ξ', the quadratures at the components `XI`, `XI_DOT`, `E_CONTACT` on
/// of its `N`-state (names resolved where it is used). `$shaft` is the pair's `GearPair::shaft`; the
/// pieces are the contact law's regions, and crossing out of the gap counts an impact;
/// `$extra` items go into the `Piecewise` impl.
macro_rules! contact_pieces {
    ($gear:ident, $shaft:item $(, $extra:item)*) => {
        impl<const N: usize> $crate::rattle::GearPair<N> for $gear<N> {
            const XI: usize = XI;
            const XI_DOT: usize = XI_DOT;
            const E_CONTACT: usize = E_CONTACT;
            fn dynamics(&self) -> &$crate::physics::Dynamics {
                &self.dynamics
            }
            fn region(&self) -> $crate::physics::Region {
                self.region
            }
            fn impacts(&self) -> &$crate::rattle::Impacts {
                &self.impacts
            }
            fn window(&self) -> &$crate::rattle::window::Window {
                &self.window
            }
            fn window_mut(&mut self) -> &mut $crate::rattle::window::Window {
                &mut self.window
            }
            $shaft
        }

        impl<const N: usize> $crate::integrator::Piecewise<N> for $gear<N> {
            $($extra)*

            fn guard(_: usize) -> (usize, usize) {
                (XI, XI_DOT)
            }

            fn piece(&self, _: usize) -> (f64, f64) {
                self.dynamics.law.bounds(self.region)
            }

            fn rough_start(&self) -> bool {
                self.dynamics.law.rough_at_onset(self.region)
            }

            fn cross(&mut self, at: $crate::integrator::Crossing, t: f64, y: &[f64; N]) {
                use $crate::rattle::GearPair;
                if self.window.is_open_at(t) {
                    let a = self.dynamics.params.r_L * self.loads_at(t, y).alpha_L;
                    self.window.acceleration(t, a);
                    self.window.last = Some((t, a.abs()));
                }
                self.region = $crate::rattle::cross_edge(
                    &self.dynamics,
                    self.region,
                    (&mut self.impacts, &mut self.window),
                    at.edge,
                    t,
                    y[XI_DOT],
                );
            }

            fn observe<D: $crate::integrator::Dense<N>>(&mut self, t0: f64, h: f64, step: &D) {
                if self.window.is_open_at(t0 + h) {
                    let (peak, end) = $crate::rattle::step_peak(self, t0, h, step);
                    self.window.acceleration(t0 + h, peak);
                    self.window.last = Some((t0 + h, end));
                }
            }
        }
    };
}
pub(crate) use contact_pieces;

contact_pieces!(
    KinematicRattle,
    fn shaft(&self, t: f64, _y: &[f64; N]) -> Shaft {
        self.excitation.at(t)
    },
    /// The gap is crossed in closed form ([`Flight`]): the free flight under the imposed
    /// motion of the main shaft, its start kept for the passage's points.
    fn exact(&mut self, t0: f64, y0: &[f64; N]) -> Option<impl ClosedForm<N>> {
        if self.region != Region::Gap {
            return None;
        }
        if !matches!(self.flight_start, Some(s) if s.is_from(t0, y0[XI], y0[XI_DOT])) {
            let (params, excitation) = (&self.dynamics.params, &self.excitation);
            let flight = Flight::new(params, excitation, t0, y0[XI], y0[XI_DOT]);
            self.flight_start = Some(flight.start);
        }
        let rattle = &*self;
        Some(FreeFlight {
            rattle,
            start: rattle.flight_start.as_ref()?,
            t0,
            y0,
        })
    },
    /// In full contact, entered through a band (ε > 0, so that δ stays away from the
    /// force's kink): the series of [`ContactSeries`] and the power flows'.
    fn series(&self, t: f64, y: &[f64; N], c: &mut Coefficients<N>) -> bool {
        self.dynamics.params.epsilon > 0.0 && self.contact_series(t, y, c)
    }
);

impl<const N: usize> KinematicRattle<N> {
    /// Taylor coefficients of the state in full contact (see [`ContactSeries`]); the
    /// quadratures' are those of their rates (`quadrature_rates`) integrated term by term.
    fn contact_series(&self, t: f64, y: &[f64; N], c: &mut Coefficients<N>) -> bool {
        let Some(s) = ContactSeries::<{ TERMS + 1 }>::new(
            &self.dynamics,
            &self.excitation,
            self.region,
            t,
            y[XI],
            y[XI_DOT],
        ) else {
            return false;
        };
        let p = &self.dynamics.params;
        let inv_r_L = 1.0 / p.r_L;
        let xi_dot: [f64; TERMS] = std::array::from_fn(|k| (k + 1) as f64 * s.xi[k + 1]);
        for k in 0..TERMS {
            c[k][XI] = s.xi[k];
            c[k][XI_DOT] = xi_dot[k];
        }
        // The rates' first TERMS − 1 coefficients, integrated term by term below.
        const RATES: usize = TERMS - 1;
        let xi_dot: [f64; RATES] = std::array::from_fn(|k| xi_dot[k]);
        let slip: [f64; RATES] = std::array::from_fn(|k| {
            (xi_dot[k] + p.r_M * s.omega_M[k]) * inv_r_L - if k == 0 { p.omega_S } else { 0.0 }
        });
        let force: [f64; RATES] = std::array::from_fn(|k| s.force[k]);
        let omega_M: [f64; RATES] = std::array::from_fn(|k| s.omega_M[k]);
        // a = r_L α_L = (r_L / I_L) (B − r_L F − C (ω_L − ω_S)).
        let lever = p.r_L / p.I_L;
        let a: [f64; RATES] = std::array::from_fn(|k| {
            lever * (if k == 0 { p.B } else { 0.0 } - p.r_L * force[k] - p.C * slip[k])
        });
        c[0][E_CONTACT..].copy_from_slice(&y[E_CONTACT..]);
        if N > E_CONTACT {
            let contact = math::series_product(&xi_dot, &xi_dot);
            let lubricant = math::series_product(&slip, &slip);
            let shaft = math::series_product(&force, &omega_M);
            for (k, row) in c.iter_mut().enumerate().skip(1) {
                // The coefficient k − 1 of each rate, integrated: / k.
                let inv_k = math::INVERSES[k];
                row[E_CONTACT] = p.C_LM * contact[k - 1] * inv_k;
                row[E_LUBRICANT] = p.C * lubricant[k - 1] * inv_k;
                row[W_SHAFT] = -p.r_M * shaft[k - 1] * inv_k;
            }
        }
        if N > E_CONTACT + quadrature::ENERGIES {
            let a2 = math::series_product(&a, &a);
            let f2 = math::series_product(&force, &force);
            for (k, row) in c.iter_mut().enumerate().skip(1) {
                let inv_k = math::INVERSES[k];
                row[E_CONTACT + quadrature::A2] = a2[k - 1] * inv_k;
                row[E_CONTACT + quadrature::F1] = force[k - 1] * inv_k;
                row[E_CONTACT + quadrature::F2] = f2[k - 1] * inv_k;
            }
        }
        true
    }
}

/// ∫ a² dτ over a free flight of length τ that ends in `f`: in the gap
/// a = (r_L / I_L) (B − C u) with u = ω_L − ω_S, so the integral is
/// (r_L / I_L)² (B² τ − 2 B C ∫u dτ + C ∫C u² dτ), the last being the lubricant's energy.
fn flight_a2(p: &GearParams, tau: f64, f: &FlightState) -> f64 {
    let lever = p.r_L / p.I_L;
    lever * lever * (p.B * (p.B * tau - 2.0 * p.C * f.slip_integral) + p.C * f.e_lubricant)
}

/// The free flight from one start (t0, y0), as the integrator follows it.
struct FreeFlight<'r, 'y, const N: usize> {
    rattle: &'r KinematicRattle<N>,
    start: &'r FlightStart,
    t0: f64,
    y0: &'y [f64; N],
}

impl<const N: usize> FreeFlight<'_, '_, N> {
    fn flight(&self) -> Flight<'_> {
        let (params, excitation) = (&self.rattle.dynamics.params, &self.rattle.excitation);
        Flight {
            params,
            excitation,
            start: *self.start,
        }
    }
}

impl<const N: usize> ClosedForm<N> for FreeFlight<'_, '_, N> {
    fn at(&self, t: f64) -> [f64; N] {
        let f = self.flight().at(t);
        let mut y = *self.y0;
        y[XI] = f.xi;
        y[XI_DOT] = f.xi_dot;
        if N > E_LUBRICANT {
            y[E_LUBRICANT] += f.e_lubricant;
        }
        if N > E_CONTACT + quadrature::A2 {
            y[E_CONTACT + quadrature::A2] +=
                flight_a2(&self.rattle.dynamics.params, t - self.t0, &f);
        }
        // No contact force in the gap: E_CONTACT, W_SHAFT, ∫F and ∫F² stay.
        y
    }

    fn guard_acceleration_bound(&self) -> f64 {
        self.flight().acceleration_bound()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::{GearParams, Sine};

    /// A state at (ξ, ξ') with the quadratures `q0`, `q0` + 1e-6, ...
    fn state(xi: f64, xi_dot: f64, q0: f64) -> State {
        let mut y = [0.0; N];
        (y[XI], y[XI_DOT]) = (xi, xi_dot);
        for (k, q) in y[E_CONTACT..].iter_mut().enumerate() {
            *q = q0 + 1e-6 * k as f64;
        }
        y
    }

    /// The Jacobian matches central differences of the right-hand side in every region, for
    /// the rows of ξ and ξ' (the quadratures' rows are zero on purpose, see `jacobian`).
    #[test]
    fn jacobian_matches_finite_differences_in_every_region() {
        let p = GearParams::paper();
        let excitation = Excitation::Sine(Sine::new(300.0, 30.0, 84.0));
        let xis = [-3e-6, -0.7e-6, -0.2e-6, 10e-6, p.G + 0.4e-6, p.G + 3e-6];
        for xi in xis {
            let rattle = Rattle::new(Dynamics::new(p), excitation, xi);
            let y = state(xi, 0.03, 0.0);
            let j = rattle.jacobian(0.004, &y);
            for (col, step) in [(XI, 1e-12), (XI_DOT, 1e-7)] {
                let (mut up, mut down) = (y, y);
                up[col] += step;
                down[col] -= step;
                let (fu, fd) = (rattle.rhs(0.004, &up), rattle.rhs(0.004, &down));
                for row in [XI, XI_DOT] {
                    let fd_slope = (fu[row] - fd[row]) / (2.0 * step);
                    let err = (j[row][col] - fd_slope).abs();
                    assert!(
                        err <= 1e-5 * fd_slope.abs().max(1.0),
                        "region {:?}, ∂f{row}/∂y{col}: {} vs {fd_slope}",
                        rattle.region,
                        j[row][col]
                    );
                }
            }
        }
    }

    /// In full contact on both flanks, with the sine and with a drivetrain's polynomial, B
    /// and ω_S not zero: the Taylor polynomial agrees with small DOPRI5 steps of the
    /// right-hand side (25 steps of 1e-6 s) over 2.5e-5 s, for ξ, ξ' and the three
    /// quadratures, within 1e-9 of their scales (or sizes); its first terms are y and
    /// f(t, y). Outside full contact there is none. Over so short a span the high terms barely
    /// show: `physics::series`'s tests check every coefficient.
    #[test]
    fn contact_series_follows_the_right_hand_side() {
        use crate::integrator::dopri5::{Trial, step};
        use crate::physics::{Polynomial, Shaft};
        let mut p = GearParams::paper();
        (p.B, p.omega_S) = (0.01, 3.0);
        let polynomial = Excitation::Polynomial(Polynomial {
            t0: 0.0,
            at_t0: Shaft {
                theta: 0.0,
                omega: 40.0,
                alpha: 900.0,
            },
        });
        for excitation in [Excitation::Sine(Sine::new(300.0, 30.0, 84.0)), polynomial] {
            for (xi, xi_dot) in [(-3e-6, 0.004), (p.G + 2e-6, -0.005)] {
                let rattle = Rattle::new(Dynamics::new(p), excitation, xi);
                let (t0, y0) = (0.0123, state(xi, xi_dot, 1e-6));
                let mut c = [[0.0; N]; TERMS];
                assert!(rattle.series(t0, &y0, &mut c));
                let f0 = rattle.rhs(t0, &y0);
                for i in 0..N {
                    assert_eq!(c[0][i], y0[i]);
                    assert!(
                        (c[1][i] - f0[i]).abs() <= 1e-12 * f0[i].abs(),
                        "{i}: {} vs {}",
                        c[1][i],
                        f0[i]
                    );
                }
                let (mut t, mut y, h) = (t0, y0, 1e-6);
                let mut trial = Trial::empty();
                for _ in 0..25 {
                    step(&rattle, t, &y, &rattle.rhs(t, &y), h, N, &mut trial);
                    (t, y) = (t + h, trial.y1);
                }
                let taylor = crate::integrator::taylor::Step::new(c, t - t0);
                let mut scales = [1e-6; N];
                (scales[XI], scales[XI_DOT]) = (p.G, p.G * 1e3);
                for i in 0..N {
                    let err = (taylor.y1[i] - y[i]).abs() / scales[i].max(y[i].abs());
                    assert!(
                        err < 1e-9,
                        "{:?} {i}: {} vs {} ({err:e})",
                        rattle.region,
                        taylor.y1[i],
                        y[i]
                    );
                }
            }
        }
        let gap = Rattle::new(
            Dynamics::new(p),
            Excitation::Sine(Sine::new(300.0, 30.0, 84.0)),
            1e-5,
        );
        assert!(!gap.series(0.0, &state(1e-5, 0.0, 0.0), &mut [[0.0; N]; TERMS]));
    }

    /// With `interpolate_ends`, the end times asked for change no bit of the trajectory:
    /// S2 (chaotic, so any difference would grow) over 31 ms, served every 2^-10 s and every
    /// 2^-13 s (binary fractions, so the common points are the same times), bands, contacts
    /// and flights included. The first DOPRI5 step had been capped by the first call's length.
    #[test]
    fn end_times_change_no_bit_of_the_trajectory() {
        use crate::integrator::Solver;
        let p = GearParams::paper();
        let run = |dt: f64| {
            let mut sys = Rattle::new(
                Dynamics::new(p),
                Excitation::Sine(Sine::new(300.0, 60.0, 0.0)),
                0.5 * p.G,
            );
            let mut solver = Solver::new(sys.tolerance(1e-6));
            solver.interpolate_ends = true;
            let (mut t, mut y) = (0.0, state(0.5 * p.G, 0.0, 0.0));
            let n = (0.03125 / dt) as usize;
            let every = (2f64.powi(-10) / dt) as usize;
            let mut at_common = vec![];
            for k in 1..=n {
                solver
                    .advance(&mut sys, &mut t, &mut y, k as f64 * dt)
                    .unwrap();
                if k % every == 0 {
                    at_common.push(y.map(f64::to_bits));
                }
            }
            (at_common, sys.impacts.count)
        };
        let (coarse, impacts) = run(2f64.powi(-10));
        let (fine, _) = run(2f64.powi(-13));
        assert!(impacts[0] + impacts[1] >= 4, "{impacts:?}");
        assert_eq!(coarse.len(), 32);
        assert_eq!(coarse, fine);
    }

    /// The free flight's kept start changes no bit of its points, and a flight from
    /// elsewhere does not use it.
    #[test]
    fn kept_flight_start_gives_the_same_bits() {
        let p = GearParams::paper();
        let excitation = Excitation::Sine(Sine::new(300.0, 30.0, 84.0));
        let fresh = Rattle::new(Dynamics::new(p), excitation, 10e-6);
        assert_eq!(fresh.region, Region::Gap);
        let (t0, y0) = (0.0123, state(10e-6, -0.04, 1e-3));
        let at = |mut r: Rattle, y0: &State, t: f64| r.exact(t0, y0).map(|f| f.at(t));
        let mut kept = fresh;
        assert!(kept.exact(t0, &y0).is_some());
        assert!(kept.flight_start.is_some());
        for t in [t0, 0.0124, 0.02] {
            assert_eq!(at(kept, &y0, t), at(fresh, &y0, t));
        }
        let other = state(11e-6, -0.04, 0.0);
        assert_eq!(at(kept, &other, 0.013), at(fresh, &other, 0.013));
        assert_ne!(at(kept, &other, 0.013), at(kept, &y0, 0.013));
    }

    /// The free flight's quadratures in closed form against small DOPRI5 steps of the
    /// right-hand side across the gap (with B, C and ω_S all non-zero, so that every term of
    /// `flight_a2` counts): ∫a² and the lubricant's energy agree within 1e-9, ∫F and ∫F² stay.
    #[test]
    fn flight_quadratures_follow_the_right_hand_side() {
        use crate::integrator::dopri5::{Trial, step};
        let mut p = GearParams::paper();
        (p.B, p.omega_S) = (0.02, 3.0);
        let rattle = Rattle::new(
            Dynamics::new(p),
            Excitation::Sine(Sine::new(300.0, 30.0, 84.0)),
            10e-6,
        );
        let (t0, y0) = (0.0123, state(10e-6, -0.004, 1e-6));
        let (mut t, mut y, h) = (t0, y0, 1e-6);
        let mut trial = Trial::empty();
        for _ in 0..1000 {
            step(&rattle, t, &y, &rattle.rhs(t, &y), h, N, &mut trial);
            (t, y) = (t + h, trial.y1);
        }
        let mut passing = rattle;
        let exact = passing.exact(t0, &y0).expect("in the gap").at(t);
        for i in [E_LUBRICANT, E_CONTACT + quadrature::A2] {
            let (gain, want) = (exact[i] - y0[i], y[i] - y0[i]);
            assert!(
                want > 0.0 && (gain - want).abs() <= 1e-9 * want,
                "{i}: {gain} vs {want}"
            );
        }
        for i in [
            E_CONTACT,
            W_SHAFT,
            E_CONTACT + quadrature::F1,
            E_CONTACT + quadrature::F2,
        ] {
            assert_eq!(exact[i], y0[i]);
        }
    }
}
