//! The gearbox with the rattle statistics of each gear over the window [stats_from, t]
//! (docs/GEARBOX.md §7, docs/METRICS.md): the [`Window`] of GearRattle per gear, counting the
//! impacts, runs and contact time as the integrator crosses the band edges, and the
//! quadratures ∫a² dt, ∫F dt, ∫F² dt of each gear carried after the gearbox's state. A run
//! steps the plain [`Gearbox`] until the window opens and this one from then on, so that the
//! transient before the window, and a run that never opens it, pay nothing for them.
#![allow(non_snake_case)]

use serde::{Deserialize, Serialize};

use gear_rattle::gearbox::{self, Gear, Gearbox, MAX_GEARS, State, e_contact, e_lubricant, xi};
use gear_rattle::integrator::{Crossing, Dense, Jacobian, Piecewise, System, Tolerance};
use gear_rattle::physics::{self, Region};
use gear_rattle::rattle::refine_peak;
use gear_rattle::rattle::window::{Quadratures, Window, quadrature};

/// The gearbox's state, then ∫a² dt, ∫F dt, ∫F² dt of each gear slot.
pub const N: usize = gearbox::N + 3 * MAX_GEARS;
/// Gear i's window integrals ∫a² dt, ∫F dt, ∫F² dt in a windowed state.
pub const fn integrals(i: usize) -> std::ops::Range<usize> {
    gearbox::N + 3 * i..gearbox::N + 3 * i + 3
}

/// The integrands of a gear's window integrals from its loads: a², F, F² with a = r_L α_L.
pub fn integrands(gear: &Gear, load: &physics::Loads) -> [f64; 3] {
    let (a, force) = (gear.dynamics.params.r_L * load.alpha_L, load.force.total());
    [a * a, force, force * force]
}

/// The gearbox's part of a windowed state.
pub fn head(y: &[f64; N]) -> State {
    y[..gearbox::N]
        .try_into()
        .expect("the gearbox's state leads")
}

/// The gearbox and each gear's statistics window.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Windowed {
    pub inner: Gearbox,
    pub windows: [Window; MAX_GEARS],
}

impl Windowed {
    /// The gearbox at (t, y) with every gear's window opening now: the gearbox's state, the
    /// window's quadratures from 0.
    pub fn open(inner: Gearbox, t: f64, y: &State) -> (Self, [f64; N]) {
        let (_, regions) = inner.regions();
        let mut windows = regions.map(|region| Window::new(t, t, region));
        let mut w = [0.0; N];
        w[..gearbox::N].copy_from_slice(y);
        for (i, window) in windows.iter_mut().enumerate() {
            window.open(quadratures(&w, i));
        }
        (Windowed { inner, windows }, w)
    }

    pub fn tolerance(&self, rtol: f64) -> Tolerance<N> {
        let t = self.inner.tolerance(rtol);
        let mut atol = [0.0; N];
        atol[..gearbox::N].copy_from_slice(&t.atol);
        Tolerance {
            rtol: t.rtol,
            atol,
            controlled: t.controlled,
        }
    }

    /// Each gear's |a| at (t, y) for its window's peak (Model Exchange: after each of the importer's
    /// steps).
    pub fn sample_accelerations(&mut self, t: f64, y: &State) {
        let accelerations = self.accelerations(t, y);
        for (window, a) in self.windows.iter_mut().zip(accelerations) {
            if let Some(a) = a {
                window.acceleration(t, a);
            }
        }
    }

    /// Each gear's pitch-line acceleration |r_L α_L| at (t, y), for the gears whose ξ lies
    /// in its current piece (a point past an edge is not the piece's).
    fn accelerations(&self, t: f64, y: &State) -> [Option<f64>; MAX_GEARS] {
        let l = self.inner.loads(t, y);
        std::array::from_fn(|i| {
            let gear = &self.inner.gears[i];
            let (lo, hi) = gear.dynamics.law.bounds(gear.region);
            (i < self.inner.n_gears() && (lo..=hi).contains(&y[xi(i)]))
                .then(|| (gear.dynamics.params.r_L * l.gears[i].alpha_L).abs())
        })
    }
}

/// Gear i's quadratures in the order of [`quadrature`] (the work on the shaft unused).
pub fn quadratures(y: &[f64; N], i: usize) -> Quadratures {
    let mut q = [0.0; quadrature::COUNT];
    q[quadrature::E_CONTACT] = y[e_contact(i)];
    q[quadrature::E_LUBRICANT] = y[e_lubricant(i)];
    q[quadrature::A2..].copy_from_slice(&y[integrals(i)]);
    q
}

impl System<N> for Windowed {
    fn rhs(&self, t: f64, y: &[f64; N]) -> [f64; N] {
        let h = head(y);
        let l = self.inner.loads(t, &h);
        let mut f = [0.0; N];
        f[..gearbox::N].copy_from_slice(&self.inner.rhs_with(&l, &h));
        for (i, gear) in self.inner.gears[..self.inner.n_gears()].iter().enumerate() {
            f[integrals(i)].copy_from_slice(&integrands(gear, &l.gears[i]));
        }
        f
    }
}

impl Jacobian<N> for Windowed {
    /// The gearbox's; the quadratures' rows stay zero (they do not act back).
    fn jacobian(&self, t: f64, y: &[f64; N]) -> [[f64; N]; N] {
        let inner = self.inner.jacobian(t, &head(y));
        let mut j = [[0.0; N]; N];
        for (row, inner) in j.iter_mut().zip(&inner) {
            row[..gearbox::N].copy_from_slice(inner);
        }
        j
    }
}

impl Piecewise<N> for Windowed {
    fn guards(&self) -> usize {
        self.inner.guards()
    }

    fn guard(k: usize) -> (usize, usize) {
        Gearbox::guard(k)
    }

    fn piece(&self, k: usize) -> (f64, f64) {
        self.inner.piece(k)
    }

    fn rough_start(&self) -> bool {
        self.inner.rough_start()
    }

    /// The gearbox's crossing, with a gear's onset or separation counted in its window and
    /// its acceleration sampled there.
    fn cross(&mut self, at: Crossing, t: f64, y: &[f64; N]) {
        let h = head(y);
        let Some(i) = at.guard.checked_sub(1) else {
            self.inner.cross(at, t, &h);
            return;
        };
        if let Some(a) = self.accelerations(t, &h)[i] {
            self.windows[i].acceleration(t, a);
            self.windows[i].last = Some((t, a));
        }
        let before = self.inner.gears[i].impacts;
        self.inner.cross(at, t, &h);
        let gear = &self.inner.gears[i];
        if let Some(flank) = (0..2).find(|&f| gear.impacts.count[f] > before.count[f]) {
            self.windows[i].impact(t, flank, gear.impacts.last_speed);
        }
        if gear.region == Region::Gap {
            self.windows[i].separation(t);
        }
    }

    /// Each gear's largest |a| on an accepted step from t0 of length h, found as GearRattle
    /// finds its pair's ([`gear_rattle::rattle`]'s `step_peak`): a at the step's ends (the
    /// start's from the step before, when it ended at t0) and middle and, in contact, where
    /// the parabola through them peaks inside the step above the window's peak so far, that
    /// peak located by successive parabolic interpolation on the dense output. In the gap
    /// the ends alone: the free loose gear's |a| is monotonic there (docs/MODEL.md §3).
    fn observe<D: Dense<N>>(&mut self, t0: f64, h: f64, step: &D) {
        let a_at = |theta: f64| {
            let y: State = std::array::from_fn(|k| step.dense(k, theta));
            self.accelerations(t0 + theta * h, &y)
                .map(|a| a.unwrap_or(0.0))
        };
        let (mid, end) = (a_at(0.5), a_at(1.0));
        let mut start = None;
        let mut peaks = [0.0; MAX_GEARS];
        for (i, peak) in peaks.iter_mut().enumerate().take(self.inner.n_gears()) {
            let window = &self.windows[i];
            let a0 = match window.last {
                Some((t, a)) if t == t0 => a,
                _ => start.get_or_insert_with(|| a_at(0.0))[i],
            };
            *peak = a0.max(end[i]);
            if self.inner.gears[i].region == Region::Gap {
                continue;
            }
            let points = [(0.0, a0), (0.5, mid[i]), (1.0, end[i])];
            *peak = refine_peak(points, window.a_peak, |theta| a_at(theta)[i]);
        }
        let t = t0 + h;
        for ((window, peak), end) in self.windows.iter_mut().zip(peaks).zip(end) {
            window.acceleration(t, peak);
            window.last = Some((t, end));
        }
    }
}
