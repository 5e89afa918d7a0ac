//! Integration of piecewise-smooth ODEs, knowing nothing of gears.
//!
//! - [`solver`]: the driver that reaches an exact end time piece by piece, ends steps exactly
//!   on the edges of the system's pieces, and carries what it knows from one call to the next.
//! - One stepper per kind of piece: `passage` for pieces with a solution in closed form (the
//!   free flight), crossed without steps, their exit found by a root search that cannot step
//!   over a crossing; [`taylor`] for pieces whose Taylor series the system gives;
//!   `runge_kutta` for the others: [`dopri5`] (the Dormand-Prince 5(4) pair with its
//!   4th-order dense output, Hairer, Nørsett & Wanner, *Solving ODEs I*, II.5) with the
//!   controller of [`control`], or [`radau5`] (Radau IIA of order 5) while the problem is
//!   stiff ([`stiffness`]), the first step into a piece learnt from earlier entries
//!   (`entries`).
//! - `edges`: where a step leaves its piece, among the system's guards, located on its dense
//!   output with [`roots`] (the Illinois root finder).
//! - `work`: the work counters ([`Stats`]), the errors ([`SolverError`]) and the limits of
//!   a call, shared by the driver and the steppers.
//! - [`options`]: the tuned constants, each with its reason.

pub mod control;
pub mod dopri5;
mod edges;
mod entries;
mod left_off;
pub mod linalg;
pub mod options;
mod passage;
pub mod radau5;
pub mod roots;
mod runge_kutta;
pub mod serde_array;
pub mod solver;
pub mod stiffness;
pub mod taylor;
#[cfg(test)]
mod test_systems;
#[cfg(test)]
mod tests;
mod work;

pub use control::Tolerance;
pub use radau5::Jacobian;
pub use solver::{Method, Solver, SolverError, Stats, resolution};

/// An ODE y' = f(t, y) with N components.
pub trait System<const N: usize> {
    fn rhs(&self, t: f64, y: &[f64; N]) -> [f64; N];
}

/// A step's ends and its dense output, whichever method took it: what edge location needs.
pub trait Dense<const N: usize> {
    /// y at the start and at the end of the step.
    fn ends(&self) -> (&[f64; N], &[f64; N]);
    /// Component i at t + θh, θ ∈ [0, 1].
    fn dense(&self, i: usize, theta: f64) -> f64;
}

/// A piece's solution in closed form from one start (t0, y0) ([`Piecewise::exact`]).
pub trait ClosedForm<const N: usize> {
    /// The state at t ≥ t0.
    fn at(&self, t: f64) -> [f64; N];
    /// A bound on |d² g / dt²| along the solution from t0 on, g being guard 0's component,
    /// for as long as it stays in the piece: what keeps the root search from stepping over a
    /// crossing.
    fn guard_acceleration_bound(&self) -> f64;
}

/// The closed form of a system that has none.
pub enum NoClosedForm {}

impl<const N: usize> ClosedForm<N> for NoClosedForm {
    fn at(&self, _: f64) -> [f64; N] {
        match *self {}
    }
    fn guard_acceleration_bound(&self) -> f64 {
        match *self {}
    }
}

/// Which edge of the current piece a trajectory leaves through.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Edge {
    Lower,
    Upper,
}

/// An edge crossed by one of a system's guards: guard `guard` leaves its piece through `edge`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Crossing {
    pub guard: usize,
    pub edge: Edge,
}

/// A system whose right-hand side is smooth only piecewise. It has `guards()` guards: guard k
/// is the component `guard(k).0` of the state, and the current piece is valid while every
/// guard k stays within its interval `piece(k)`. The component `guard(k).1` is the time
/// derivative of guard k (used to find its extrema inside a step, so that a grazing crossing
/// is not skipped). A step ends on the earliest crossing among all guards. A system with one
/// guard (the gear pair: ξ) loops over that one only, with the same arithmetic as if the
/// solver knew of no other.
pub trait Piecewise<const N: usize>: System<N> {
    /// How many guards the system has (at least 1): guards 0 .. guards() − 1.
    #[inline]
    fn guards(&self) -> usize {
        1
    }

    /// The components of guard k and of its rate.
    fn guard(k: usize) -> (usize, usize);

    /// The interval [lo, hi] of guard k over which the current piece is valid.
    fn piece(&self, k: usize) -> (f64, f64);

    /// Switches to the neighbouring piece through the edge `at` (of guard `at.guard`) at time
    /// t and state y.
    fn cross(&mut self, at: Crossing, t: f64, y: &[f64; N]);

    /// Whether the right-hand side of the piece just entered is rough where the piece begins
    /// (a non-integer power below 3 of the distance to its edge): the solution is then not
    /// smooth at the start of the first step, whose error estimate the solver distrusts.
    fn rough_start(&self) -> bool {
        false
    }

    /// Where the current piece has a solution in closed form (the free flight): that
    /// solution from (t0, y0). The solver then takes no steps in the piece; it follows the
    /// solution and finds where it leaves the piece by a root search on it (see `passage`).
    /// The system may keep what the solution's points share, for the next call from the
    /// same start. None (the default): the piece is crossed by steps. The passage watches
    /// guard 0 only: a system with several guards returns None.
    fn exact(&mut self, _t0: f64, _y0: &[f64; N]) -> Option<impl ClosedForm<N>> {
        None::<NoClosedForm>
    }

    /// Where the current piece's solution is analytic and the system can form its Taylor
    /// coefficients about (t, y): writes them into `c` and returns true; the solver then takes
    /// Taylor steps in the piece ([`taylor`]) while it steps explicitly. False (the default):
    /// DOPRI5 or Radau IIA steps.
    fn series(&self, _t: f64, _y: &[f64; N], _c: &mut taylor::Coefficients<N>) -> bool {
        false
    }

    /// Called with each accepted step from t0 of length h and its dense output, whole (also
    /// when it is then redone to end on an edge inside it, or kept past the end time): what
    /// the system records along its trajectory between the edges (the peak of an output) is
    /// taken here.
    fn observe<D: Dense<N>>(&mut self, _t0: f64, _h: f64, _step: &D) {}

    /// Moves every guard to the piece that contains it through each edge on the way (after a
    /// jump of the state from outside the integrator); returns how many edges were crossed.
    fn settle(&mut self, t: f64, y: &[f64; N]) -> usize {
        let mut crossed = 0;
        for guard in 0..self.guards() {
            let g = y[Self::guard(guard).0];
            loop {
                let (lo, hi) = self.piece(guard);
                let edge = if g < lo {
                    Edge::Lower
                } else if g > hi {
                    Edge::Upper
                } else {
                    break;
                };
                self.cross(Crossing { guard, edge }, t, y);
                crossed += 1;
            }
        }
        crossed
    }
}
