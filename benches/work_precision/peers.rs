//! The peers of the work-precision benchmark: maintained Rust ODE crates stepping the same
//! gear-rattle equations.
//!
//! Every peer integrates the same piecewise ODE as GearRattle: the right-hand side is the one
//! of `gear_rattle::rattle::Rattle` (docs/MODEL.md §2-3 with the region's formula locked; the same
//! function, so one evaluation costs the same for every solver and the ratios measure the
//! integration), and the same event handling as GearRattle's solver: after each accepted step
//! the driver below checks whether ξ left the current region [lo, hi], at the step's end or
//! before a turning point inside the step (a grazing touch), locates the first crossing with an
//! Illinois search on the crate's dense output, redoes the step from its start so that it ends
//! exactly there (Newton on the step length while ξ misses the edge by more than 0.1·rtol·G),
//! sets ξ on the edge, and restarts the crate's method in the neighbouring region with the step
//! size it had proposed; impacts are counted as GearRattle counts them. Outputs: steps end on
//! the 1 ms grid points (the step size proposed before such a shortened step is kept), as
//! GearRattle's `advance` does.
//!
//! Why steps end on edges and grid points rather than using the crates' dense outputs for the
//! state: the dense outputs of differential-equations 0.7 are of lower order than its methods
//! (docs/DECISIONS.md, D20), which would charge an interpolation defect to the method. The
//! crates' event APIs (differential-equations' `Event`, diffsol's root functions) watch sign
//! changes at step ends only and would skip a grazing contact; they are not used.
//!
//! The second kind of peer is the crate as a user would use it after reading docs/MODEL.md: the
//! right-hand side written literally from it ([`UserRhs`]: powf for |δ/G|^(α−1), the band's
//! sine as written in §2, the excitation's sin and cos, the region found from ξ at each call),
//! one function shared by every crate, and no event handling: the crate's own stepping only,
//! steps straddling the kinks of the contact law. Outputs still end steps on the 1 ms grid
//! points (as each crate does at its final time), so that the error is the method's, not an
//! interpolant's.

use std::cell::Cell;

use gear_rattle::integrator::{Crossing, Edge, Piecewise, roots};
use gear_rattle::physics::{Dynamics, Excitation, GearParams, Region};
use gear_rattle::rattle::{N, Rattle, State, XI, XI_DOT};

/// docs/MODEL.md §2, §3 and §5 written out literally: the right-hand side a user of a general ODE
/// crate writes for the state [ξ, ξ', E_contact, E_lubricant, W_shaft], with the region taken
/// from ξ at each call (nothing of GearRattle's code: its own powf, sin, sin and cos).
#[derive(Clone, Copy, Debug)]
pub struct UserRhs {
    pub p: GearParams,
    /// A = √2 A_rms and w = 2πf of the bench sine.
    amplitude: f64,
    w: f64,
}

impl UserRhs {
    pub fn new(p: GearParams, a_rms: f64, f_exc: f64) -> Self {
        UserRhs {
            p,
            amplitude: 2f64.sqrt() * a_rms,
            w: 2.0 * std::f64::consts::PI * f_exc,
        }
    }

    #[inline]
    pub fn rhs(&self, t: f64, y: &State) -> State {
        use std::f64::consts::PI;
        let p = &self.p;
        let (xi, v) = (y[XI], y[XI_DOT]);
        let a_m = self.amplitude * (self.w * t).sin();
        let om_m = -self.amplitude / self.w * (self.w * t).cos();
        let (eps, g) = (p.epsilon, p.G);
        let (s, delta) = if xi <= -eps {
            (1.0, xi)
        } else if xi <= 0.0 {
            (0.5 * (1.0 - (PI / eps * (eps / 2.0 + xi)).sin()), xi)
        } else if xi <= g {
            (0.0, 0.0)
        } else if xi <= g + eps {
            (
                0.5 * (1.0 - (PI / eps * (eps / 2.0 - (xi - g))).sin()),
                xi - g,
            )
        } else {
            (1.0, xi - g)
        };
        let f_k = s * p.K_star * delta * (delta / g).abs().powf(p.alpha - 1.0);
        let f_c = s * p.C_LM * v;
        let f = f_k + f_c;
        let om_l = (v + p.r_M * om_m) / p.r_L;
        let dom_l = (p.B - p.r_L * f - p.C * (om_l - p.omega_S)) / p.I_L;
        [
            v,
            p.r_L * dom_l - p.r_M * a_m,
            f_c * v,
            p.C * (om_l - p.omega_S) * (om_l - p.omega_S),
            -p.r_M * f * om_m,
            0.0,
            0.0,
            0.0,
        ]
    }
}

/// The gear pair's right-hand side with the region read from a cell, so that a crate's
/// closure or trait object can follow region changes made by the driver. Counts evaluations.
pub struct Model {
    /// The gear pair; its own region is not used (the cell's is).
    pub rattle: Rattle,
    pub region: Cell<Region>,
    pub evals: Cell<u64>,
    /// The peer as a user writes it: this RHS instead of `Rattle`'s, and no event handling
    /// (steps straddle the kinks of the contact law).
    pub user: Option<UserRhs>,
}

impl Model {
    pub fn new(dynamics: Dynamics, excitation: Excitation, region: Region) -> Self {
        Model {
            rattle: Rattle::new(dynamics, excitation, 0.0),
            region: Cell::new(region),
            evals: Cell::new(0),
            user: None,
        }
    }

    /// f(t, y): `Rattle::rhs` with the current region's formula, or the user's RHS.
    #[inline]
    pub fn rhs(&self, t: f64, y: &State) -> State {
        self.evals.set(self.evals.get() + 1);
        if let Some(user) = &self.user {
            return user.rhs(t, y);
        }
        self.rattle.rhs_in(self.region.get(), t, y)
    }
}

/// One adaptive method of a crate, driven one accepted step at a time.
pub trait Stepper {
    /// (Re)starts at (t, y) with the model's current region; `h` > 0: the step to try first
    /// (the size proposed before the edge), 0: let the method choose.
    fn restart(&mut self, model: &Model, t: f64, y: &State, h: f64) -> Result<(), String>;
    /// Takes one accepted step, shortened if needed so as not to pass `t_stop`.
    fn step(&mut self, model: &Model, t_stop: f64) -> Result<(), String>;
    /// Start and end of the last accepted step, and the state there.
    fn t_prev(&self) -> f64;
    fn y_prev(&self) -> State;
    fn t(&self) -> f64;
    fn y(&self) -> State;
    /// The step size the method proposes next, and setting it.
    fn h(&self) -> f64;
    fn set_h(&mut self, h: f64);
    /// Dense output inside the last accepted step.
    fn dense(&mut self, t: f64) -> State;
}

/// What a run gives: the state on the output grid and the work done.
pub struct Run {
    pub xi: Vec<f64>,
    pub xi_dot: Vec<f64>,
    /// Impact counts (F+, F−) at each grid point.
    pub counts: Vec<[u64; 2]>,
    pub rhs: u64,
    pub steps: u64,
    pub edges: u64,
}

impl Run {
    /// An empty run with room for `n` grid points.
    pub fn with_capacity(n: usize) -> Self {
        Run {
            xi: Vec::with_capacity(n),
            xi_dot: Vec::with_capacity(n),
            counts: Vec::with_capacity(n),
            rhs: 0,
            steps: 0,
            edges: 0,
        }
    }
}

/// Root of g on [a, b] with g(a), g(b) of opposite signs, to a few ulps (the crate's Illinois
/// search): the end of the final bracket on a's side, so the root returned never lies past
/// the crossing.
fn illinois(g: impl FnMut(f64) -> f64, a: f64, b: f64) -> f64 {
    roots::illinois(g, a, b, 4.0 * f64::EPSILON * a.abs().max(b.abs()) + 1e-300)
}

/// The first exit of ξ from [lo, hi] during the last accepted step, if any. With a turning
/// point of ξ inside the step (ξ' changes sign), the excursion up to it is checked first (a
/// grazing touch); an exit at the step's end is then searched from the turning point, since
/// the step may start on the edge it entered through.
fn locate<S: Stepper>(s: &mut S, lo: f64, hi: f64) -> Option<(Edge, f64)> {
    let (t0, t1) = (s.t_prev(), s.t());
    let (y0, y1) = (s.y_prev(), s.y());
    let mut from = t0;
    if (y0[XI_DOT] < 0.0) != (y1[XI_DOT] < 0.0) && y0[XI_DOT] != 0.0 && y1[XI_DOT] != 0.0 {
        let t_turn = illinois(|t| s.dense(t)[XI_DOT], t0, t1);
        let x = s.dense(t_turn)[XI];
        if x < lo {
            return Some((Edge::Lower, illinois(|t| s.dense(t)[XI] - lo, t0, t_turn)));
        } else if x > hi {
            return Some((Edge::Upper, illinois(|t| s.dense(t)[XI] - hi, t0, t_turn)));
        }
        from = t_turn;
    }
    let (edge, level) = if y1[XI] < lo {
        (Edge::Lower, lo)
    } else if y1[XI] > hi {
        (Edge::Upper, hi)
    } else {
        return None;
    };
    Some((edge, illinois(|t| s.dense(t)[XI] - level, from, t1)))
}

/// Whether time `t` is the stop `stop` (within rounding).
fn reached(t: f64, stop: f64) -> bool {
    (t - stop).abs() <= 1e-13 * stop.abs().max(1.0)
}

/// Takes accepted steps from the current point until `stop` exactly; returns how many.
fn step_to<S: Stepper>(s: &mut S, model: &Model, stop: f64) -> Result<u64, String> {
    let mut steps = 0;
    while !reached(s.t(), stop) {
        s.step(model, stop)?;
        steps += 1;
    }
    Ok(steps)
}

/// Redoes the step from (tp, yp) so that it ends on the edge ξ = `level`, first at `tc`
/// (located on the dense output), then corrected by Newton on the step length while ξ misses
/// the edge by more than `tol`. Returns the state there and the steps taken.
fn land<S: Stepper>(
    s: &mut S,
    model: &Model,
    (tp, yp): (f64, &State),
    mut tc: f64,
    level: f64,
    tol: f64,
) -> Result<(f64, State, u64), String> {
    let mut steps = 0;
    for _ in 0..4 {
        s.restart(model, tp, yp, tc - tp)?;
        steps += step_to(s, model, tc)?;
        let y = s.y();
        let miss = y[XI] - level;
        if miss.abs() <= tol || y[XI_DOT] == 0.0 {
            return Ok((tc, y, steps));
        }
        let next = tc - miss / y[XI_DOT];
        // Newton leaving the step backwards, or NaN: keep the last length.
        if next.partial_cmp(&tp) != Some(std::cmp::Ordering::Greater) {
            return Ok((tc, y, steps));
        }
        tc = next;
    }
    Ok((tc, s.y(), steps))
}

/// Integrates the scene from (0, y0) to the last point of `grid` (increasing, from 0) with
/// `s`, ending steps on the grid points and on the region edges; `tol_xi` is how closely a
/// step must land on an edge.
pub fn drive<S: Stepper>(
    s: &mut S,
    model: &Model,
    y0: State,
    grid: &[f64],
    tol_xi: f64,
) -> Result<Run, String> {
    model.evals.set(0);
    let mut rattle = Rattle::new(model.rattle.dynamics, model.rattle.excitation, y0[XI]);
    model.region.set(rattle.region);
    let mut run = Run::with_capacity(grid.len());
    s.restart(model, 0.0, &y0, 0.0)?;
    let (mut t, mut y) = (0.0, y0);
    let mut k = 0;
    let mut stalls = 0;
    while k < grid.len() {
        if t >= grid[k] || reached(t, grid[k]) {
            run.xi.push(y[XI]);
            run.xi_dot.push(y[XI_DOT]);
            run.counts.push(rattle.impacts.count);
            k += 1;
            continue;
        }
        let stop = grid[k];
        let h_before = s.h();
        s.step(model, stop)?;
        run.steps += 1;
        let (lo, hi) = rattle.piece(0);
        if model.user.is_some() {
            // No edge handling: follow ξ's region after the step to count impacts.
            (t, y) = (s.t(), s.y());
            rattle.settle(t, &y);
            if reached(t, stop) {
                t = stop;
                let h = s.h().max(h_before);
                s.set_h(h);
            }
            continue;
        }
        match locate(s, lo, hi) {
            Some((edge, tc)) => {
                let level = if edge == Edge::Lower { lo } else { hi };
                let (tp, yp) = (s.t_prev(), s.y_prev());
                let h_next = s.h();
                let (tc, mut yc) = if tc > tp {
                    let (tc, yc, steps) = land(s, model, (tp, &yp), tc, level, tol_xi)?;
                    run.steps += steps;
                    (tc, yc)
                } else {
                    (tp, yp)
                };
                yc[XI] = level;
                stalls = if tc <= t { stalls + 1 } else { 0 };
                if stalls > 20 {
                    return Err(format!("edge crossings without progress at t = {tc}"));
                }
                rattle.cross(Crossing { guard: 0, edge }, tc, &yc);
                model.region.set(rattle.region);
                run.edges += 1;
                s.restart(model, tc, &yc, h_next)?;
                (t, y) = (tc, yc);
            }
            None => {
                (t, y) = (s.t(), s.y());
                if reached(t, stop) {
                    // A step cut short to land on an output point: keep the natural size.
                    t = stop;
                    let h = s.h().max(h_before);
                    s.set_h(h);
                }
            }
        }
    }
    run.rhs = model.evals.get();
    Ok(run)
}

// ---------------------------------------------------------------------------------------
// differential-equations 0.7: ExplicitRungeKutta (DOPRI5, DOP853), stepped by hand through
// its OrdinaryNumericalMethod and Interpolation traits.
// ---------------------------------------------------------------------------------------

pub mod de {
    use super::*;
    use differential_equations::interpolate::Interpolation;
    use differential_equations::ode::{ODE, OrdinaryNumericalMethod};

    struct Ode<'a>(&'a Model);

    impl ODE<f64, State> for Ode<'_> {
        #[inline]
        fn diff(&self, t: f64, y: &State, dydt: &mut State) {
            *dydt = self.0.rhs(t, y);
        }
    }

    pub struct De<M> {
        method: M,
        t_end: f64,
    }

    impl<M> De<M> {
        pub fn new(method: M, t_end: f64) -> Self {
            De { method, t_end }
        }
    }

    impl<M> Stepper for De<M>
    where
        M: OrdinaryNumericalMethod<f64, State> + Interpolation<f64, State>,
    {
        fn restart(&mut self, model: &Model, t: f64, y: &State, h: f64) -> Result<(), String> {
            // `init` evaluates f(t, y) (and the starting step, the first time only).
            // The crate checks its stored first step against tf - t: tf lies well beyond the
            // end, which the driver reaches by shortening the last step itself.
            self.method
                .init(&Ode(model), t, 2.0 * self.t_end + 1.0, y)
                .map_err(|e| format!("{e:?}"))?;
            if h > 0.0 {
                self.method.set_h(h);
            }
            Ok(())
        }

        fn step(&mut self, model: &Model, t_stop: f64) -> Result<(), String> {
            let ode = Ode(model);
            let t = self.method.t();
            loop {
                // Reach the stop exactly, as the crate's own driver does at tf.
                if self.method.t() + self.method.h() > t_stop {
                    self.method.set_h(t_stop - self.method.t());
                }
                self.method.step(&ode).map_err(|e| format!("{e:?}"))?;
                if self.method.t() != t {
                    return Ok(());
                }
            }
        }

        fn t_prev(&self) -> f64 {
            self.method.t_prev()
        }
        fn y_prev(&self) -> State {
            *self.method.y_prev()
        }
        fn t(&self) -> f64 {
            self.method.t()
        }
        fn y(&self) -> State {
            *self.method.y()
        }
        fn h(&self) -> f64 {
            self.method.h()
        }
        fn set_h(&mut self, h: f64) {
            self.method.set_h(h);
        }
        fn dense(&mut self, t: f64) -> State {
            let t = t.clamp(self.method.t_prev(), self.method.t());
            self.method.interpolate(t).expect("inside the last step")
        }
    }
}

// ---------------------------------------------------------------------------------------
// diffsol 0.18: the explicit Runge-Kutta solver with the Tsitouras 5(4) tableau, nalgebra
// vectors, stepped with OdeSolverMethod::step and restarted through state_mut.
// ---------------------------------------------------------------------------------------

pub mod ds {
    use super::*;
    use diffsol::{
        NalgebraVec, OdeEquations, OdeSolverMethod, OdeSolverStopReason, Vector, VectorCommon,
    };

    pub struct Ds<'a, Eqn, S> {
        pub solver: S,
        t_prev: f64,
        y_prev: State,
        dy_prev: State,
        /// The stop time last given to the solver.
        stop: f64,
        scratch: NalgebraVec<f64>,
        _eqn: std::marker::PhantomData<&'a Eqn>,
    }

    fn to_state(v: &NalgebraVec<f64>) -> State {
        let mut y = [0.0; N];
        y.copy_from_slice(v.inner().as_slice());
        y
    }

    impl<'a, Eqn, S> Ds<'a, Eqn, S>
    where
        Eqn: OdeEquations<T = f64, V = NalgebraVec<f64>> + 'a,
        S: OdeSolverMethod<'a, Eqn>,
    {
        pub fn new(solver: S) -> Self {
            let scratch = solver.state().y.clone();
            Ds {
                solver,
                t_prev: 0.0,
                y_prev: [0.0; N],
                dy_prev: [0.0; N],
                stop: f64::NAN,
                scratch,
                _eqn: std::marker::PhantomData,
            }
        }
    }

    impl<'a, Eqn, S> Stepper for Ds<'a, Eqn, S>
    where
        Eqn: OdeEquations<T = f64, V = NalgebraVec<f64>> + 'a,
        S: OdeSolverMethod<'a, Eqn>,
    {
        fn restart(&mut self, model: &Model, t: f64, y: &State, h: f64) -> Result<(), String> {
            if t == 0.0 && h == 0.0 {
                // The solver was built at t0 with y0 and its own starting step.
                return Ok(());
            }
            // Back to the start of the last step (to redo it): f there is known.
            let dy = if t == self.t_prev && *y == self.y_prev {
                self.dy_prev
            } else {
                model.rhs(t, y)
            };
            let state = self.solver.state_mut();
            state.y.inner_mut().as_mut_slice().copy_from_slice(y);
            state.dy.inner_mut().as_mut_slice().copy_from_slice(&dy);
            *state.t = t;
            if h > 0.0 {
                *state.h = h;
            }
            Ok(())
        }

        fn step(&mut self, _model: &Model, t_stop: f64) -> Result<(), String> {
            // diffsol shortens the step that would pass its stop time to land on it.
            if t_stop != self.stop {
                self.solver
                    .set_stop_time(t_stop)
                    .map_err(|e| format!("{e:?}"))?;
                self.stop = t_stop;
            }
            let state = self.solver.state();
            self.t_prev = state.t;
            self.y_prev = to_state(state.y);
            self.dy_prev = to_state(state.dy);
            let reason = self.solver.step().map_err(|e| format!("{e:?}"))?;
            if let OdeSolverStopReason::TstopReached = reason {
                self.stop = f64::NAN;
            }
            Ok(())
        }

        fn t_prev(&self) -> f64 {
            self.t_prev
        }
        fn y_prev(&self) -> State {
            self.y_prev
        }
        fn t(&self) -> f64 {
            self.solver.state().t
        }
        fn y(&self) -> State {
            to_state(self.solver.state().y)
        }
        fn h(&self) -> f64 {
            self.solver.state().h
        }
        fn set_h(&mut self, h: f64) {
            *self.solver.state_mut().h = h;
        }
        fn dense(&mut self, t: f64) -> State {
            let t = t.clamp(self.t_prev, self.t());
            self.solver
                .interpolate_inplace(t, &mut self.scratch)
                .expect("inside the last step");
            to_state(&self.scratch)
        }
    }
}
