//! `BENCH_TAYLOR=1 cargo bench -p gear_rattle_bench --bench work_precision`: the lever that
//! issue 3 has left, measured before it is built into the solver.
//!
//! One contact visit of S1 on flank F+ in full contact: from ξ = −ε moving inwards until ξ
//! comes back to −ε, at three impact speeds around S1's (7.4 mm/s mean, 15.3 max). Each visit
//! is integrated by GearRattle's DOPRI5 (`Solver` on `Rattle`, the five components of a run,
//! the exit located and landed on as in a run) and by a Taylor-series step of order P
//! ([`visit`], here only), at several tolerances. Error: exit time (as |Δt|·|ξ'|, a distance)
//! and exit speed against a reference, the Taylor step at order 24, checked against DOPRI5
//! at rtol 1e-13. Cost: median CPU per visit over interleaved repeats.
//!
//! Why a Taylor step fits the contact: in full contact δ stays at least ε away from the kink
//! of δ^(4/3) (MODEL.md §2), so the solution is analytic there, its Taylor coefficients
//! follow from a recurrence, and a step can cover a large part of the visit; its polynomial is
//! its own dense output, so an edge costs no redone step. Not covered here (what building it
//! into the solver needs): the bands (whose force vanishes with its derivatives at δ = 0),
//! error weights on ξ' and the hand-over to DOPRI5 and Radau IIA.

use super::cpu_now;
use super::profile::Counted;
use gear_rattle::integrator::{Method, Solver};
use gear_rattle::physics::{Dynamics, Excitation, GearParams, Region, Sine};
use gear_rattle::rattle::{E_CONTACT, E_LUBRICANT, N, Rattle, State, W_SHAFT, XI, XI_DOT};

/// S1's excitation (MODEL.md §5).
const A_RMS: f64 = 300.0;
const F_EXC: f64 = 30.0;

/// The exit of a visit: time and state where ξ is back at −ε.
type Exit = (f64, State);

/// Coefficients of the Taylor polynomials about the start of a step, ξ and the rates of the
/// three quadratures (MODEL.md §3's power flows), in full contact on F+ (s = 1, δ = ξ).
///
/// With u = −ξ/G > 0, F_k = −K* G u^(4/3); v = u^a (a = 4/3) has u v' = a u' v, hence
/// k u₀ v_k = Σ_{j=1..k} (a j − (k − j)) u_j v_{k−j}. The equation of motion (MODEL.md §3),
/// ξ'' = (r_L B − r_L² F − C (ξ' + r_M ω_M − r_L ω_S)) / I_L − r_M a_M, gives ξ_{k+2} from
/// the coefficients up to k. The shaft's ω_M and a_M are those of the sine about t.
struct Series<const P: usize> {
    xi: [f64; P],
    xi_dot: [f64; P],
    /// F = F_k + F_c, and the rates of E_CONTACT, E_LUBRICANT and W_SHAFT.
    rates: [[f64; P]; 3],
}

fn series<const P: usize>(p: &GearParams, sine: (f64, f64), t: f64, y: &State) -> Series<P> {
    let (amplitude, w) = sine;
    let (s0, c0) = gear_rattle::math::sin_cos(w * t);
    // sin and cos of wt + kπ/2: the k-th derivatives of sin and cos at wt.
    let quarter = [(s0, c0), (c0, -s0), (-s0, -c0), (-c0, s0)];
    let (mut omega_M, mut a_M) = ([0.0; P], [0.0; P]);
    let mut scale = 1.0; // w^k / k!
    for k in 0..P {
        let (sin_k, cos_k) = quarter[k % 4];
        omega_M[k] = -amplitude / w * scale * cos_k;
        a_M[k] = amplitude * scale * sin_k;
        scale *= w / (k + 1) as f64;
    }
    let (lever, drag) = (p.r_L * p.r_L / p.I_L, p.C / p.I_L);
    let (mut xi, mut u, mut v) = ([0.0; P], [0.0; P], [0.0; P]);
    xi[0] = y[XI];
    xi[1] = y[XI_DOT];
    u[0] = -xi[0] / p.G;
    v[0] = u[0] * gear_rattle::math::cbrt(u[0]);
    let inv_u0 = 1.0 / u[0];
    let mut force = [0.0; P];
    for k in 0..P - 1 {
        if k > 0 {
            u[k] = -xi[k] / p.G;
            let mut acc = 0.0;
            for j in 1..=k {
                acc += ((4.0 / 3.0) * j as f64 - (k - j) as f64) * u[j] * v[k - j];
            }
            v[k] = acc * inv_u0 / k as f64;
        }
        let xi_dot = (k + 1) as f64 * xi[k + 1];
        force[k] = -p.K_star * p.G * v[k] + p.C_LM * xi_dot;
        let mut xi_ddot = -lever * force[k] - drag * (xi_dot + p.r_M * omega_M[k]) - p.r_M * a_M[k];
        if k == 0 {
            xi_ddot += (p.r_L * p.B + p.C * p.r_L * p.omega_S) / p.I_L;
        }
        if k + 2 < P {
            xi[k + 2] = xi_ddot / ((k + 1) * (k + 2)) as f64;
        }
    }
    // The quadratures' rates, by Cauchy products: F_c ξ', C (ω_L − ω_S)², −r_M F ω_M.
    let xi_dot: [f64; P] = std::array::from_fn(|k| {
        if k + 1 < P {
            (k + 1) as f64 * xi[k + 1]
        } else {
            0.0
        }
    });
    let slip: [f64; P] = std::array::from_fn(|k| {
        (xi_dot[k] + p.r_M * omega_M[k]) / p.r_L - if k == 0 { p.omega_S } else { 0.0 }
    });
    let product = |a: &[f64; P], b: &[f64; P], c: f64| -> [f64; P] {
        std::array::from_fn(|k| c * (0..=k).map(|j| a[j] * b[k - j]).sum::<f64>())
    };
    Series {
        xi,
        xi_dot,
        rates: [
            product(&xi_dot, &xi_dot, p.C_LM),
            product(&slip, &slip, p.C),
            product(&force, &omega_M, -p.r_M),
        ],
    }
}

/// Σ c_k τ^k.
fn horner<const P: usize>(c: &[f64; P], tau: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &x| acc * tau + x)
}

/// The visit by Taylor steps of order P − 1 in ξ: each step as long as the last two terms
/// allow for an absolute error `tol` in ξ (Jorba and Zou's rule), the exit found by Newton on
/// the step's polynomial. Returns the exit and the number of steps.
fn visit<const P: usize>(
    p: &GearParams,
    sine: (f64, f64),
    t0: f64,
    y0: &State,
    tol: f64,
) -> (Exit, u32) {
    let level = -p.epsilon;
    let (mut t, mut y) = (t0, *y0);
    let log_tol = gear_rattle::math::log2_coarse(tol);
    for steps in 1.. {
        let s = series::<P>(p, sine, t, &y);
        let length = |k: usize| {
            gear_rattle::math::exp2_coarse(
                (log_tol - gear_rattle::math::log2_coarse(s.xi[k].abs())) / k as f64,
            )
        };
        let h = 0.9 * length(P - 2).min(length(P - 1));
        let motion = |tau: f64| (horner(&s.xi, tau), horner(&s.xi_dot, tau));
        let at = |tau: f64| -> State {
            let mut out = y;
            (out[XI], out[XI_DOT]) = motion(tau);
            for (i, rate) in [E_CONTACT, E_LUBRICANT, W_SHAFT].into_iter().zip(&s.rates) {
                let integral: [f64; P] = std::array::from_fn(|k| rate[k] / (k + 1) as f64);
                out[i] += tau * horner(&integral, tau);
            }
            out
        };
        let (xi_end, _) = motion(h);
        if xi_end > level && steps > 1 {
            // Newton from the secant's guess; the exit lies inside the step.
            let mut tau = h * (level - y[XI]) / (xi_end - y[XI]);
            for _ in 0..50 {
                let (xi, xi_dot) = motion(tau);
                let dt = (xi - level) / xi_dot;
                tau -= dt;
                if dt.abs() <= 1e-15 * h {
                    break;
                }
            }
            return ((t + tau, at(tau)), steps);
        }
        y = at(h);
        t += h;
    }
    unreachable!()
}

/// The visit by GearRattle's DOPRI5 from (t0, y0) in full contact on F+, up to `t_end`, and
/// the exit as the solver crossed it; the RHS it took in the contact.
fn dopri5(p: &GearParams, t0: f64, y0: &State, rtol: f64, t_end: f64) -> (Option<Exit>, u64) {
    let excitation = Excitation::Sine(Sine::new(A_RMS, F_EXC, 0.0));
    let mut inner = Rattle::new(Dynamics::new(*p), excitation, y0[XI]);
    inner.region = Region::ContactPlus;
    let mut sys = Counted::new(inner);
    let mut solver = Solver::with_method(sys.inner.tolerance(rtol), Method::Explicit);
    solver.interpolate_ends = true;
    let (mut t, mut y) = (t0, *y0);
    solver
        .advance(&mut sys, &mut t, &mut y, t_end)
        .expect("DOPRI5 visit");
    (sys.first_cross, sys.evals_in(Region::ContactPlus))
}

/// The median of a set of times.
fn median(times: &mut [f64]) -> f64 {
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

pub fn run() {
    let p = GearParams::paper();
    let sine = (
        std::f64::consts::SQRT_2 * A_RMS,
        2.0 * std::f64::consts::PI * F_EXC,
    );
    const REPEATS: usize = 7;
    const RUNS: usize = 300;
    println!(
        "One contact visit on F+ (S1's parameters and excitation), DOPRI5 against a Taylor step of order P"
    );
    println!(
        "err t: |Δt_exit|·|ξ'_exit| [m]; err v: |Δξ'_exit| [m/s]; CPU: median of {REPEATS} interleaved repeats of {RUNS} visits"
    );
    for (t0, speed) in [(0.0123, 7.4e-3), (0.031, 15e-3), (0.05, 3e-3)] {
        let mut y0 = [0.0; N];
        (y0[XI], y0[XI_DOT]) = (-p.epsilon, -speed);
        let ((t_ref, y_ref), _) = visit::<24>(&p, sine, t0, &y0, 1e-24);
        let (check, _) = dopri5(&p, t0, &y0, 1e-13, t_ref + 1e-6);
        let (t_chk, y_chk) = check.expect("the exit");
        println!(
            "\nvisit from t = {t0} s at {:.1} mm/s: exit at {t_ref:.9} s, {:.3} mm/s; reference against DOPRI5 1e-13: \
             Δt {:.1e} s, Δξ' {:.1e} m/s, ΔE_contact {:.1e} J of {:.2e}",
            speed * 1e3,
            y_ref[XI_DOT] * 1e3,
            t_chk - t_ref,
            y_chk[XI_DOT] - y_ref[XI_DOT],
            y_chk[E_CONTACT] - y_ref[E_CONTACT],
            y_ref[E_CONTACT]
        );
        let error = |(t, y): Exit| {
            (
                (t - t_ref).abs() * y_ref[XI_DOT].abs(),
                (y[XI_DOT] - y_ref[XI_DOT]).abs(),
            )
        };
        type Candidate = (String, Box<dyn Fn() -> (Exit, u64)>);
        let mut candidates: Vec<Candidate> = Vec::new();
        for rtol in [1e-6, 1e-7, 1e-8] {
            // End exactly where this tolerance's run crosses, so that no step follows the exit.
            let t_exit = dopri5(&p, t0, &y0, rtol, t_ref + 1e-6)
                .0
                .expect("the exit")
                .0;
            candidates.push((
                format!("DOPRI5 rtol {rtol:.0e}"),
                Box::new(move || {
                    let (exit, rhs) = dopri5(&p, t0, &y0, rtol, t_exit);
                    (exit.expect("the exit"), rhs)
                }),
            ));
        }
        for tol in [1e-12, 1e-13, 1e-14, 1e-15] {
            macro_rules! taylor {
                ($P:literal) => {
                    candidates.push((
                        format!("Taylor P={} tol {tol:.0e}", $P),
                        Box::new(move || {
                            let (exit, steps) = visit::<$P>(&p, sine, t0, &y0, tol);
                            (exit, steps as u64)
                        }),
                    ));
                };
            }
            taylor!(10);
            taylor!(12);
            taylor!(14);
        }
        let mut times = vec![Vec::new(); candidates.len()];
        for _ in 0..REPEATS {
            for (i, (_, f)) in candidates.iter().enumerate() {
                let start = cpu_now();
                for _ in 0..RUNS {
                    std::hint::black_box(f());
                }
                times[i].push((cpu_now() - start) / RUNS as f64);
            }
        }
        let rows: Vec<(String, u64, f64, (f64, f64))> = candidates
            .iter()
            .zip(times.iter_mut())
            .map(|((name, f), ts)| {
                let (exit, work) = f();
                (name.clone(), work, median(ts), error(exit))
            })
            .collect();
        for (name, work, cpu, (et, ev)) in &rows {
            let unit = if name.starts_with("DOPRI5") {
                "RHS in contact"
            } else {
                "steps"
            };
            println!(
                "  {name:24} {work:5} {unit:14} {:8.0} ns  err t {et:.1e}  err v {ev:.1e}",
                cpu * 1e9
            );
        }
        // Equal error: for each DOPRI5 run, the cheapest Taylor run at most as wrong in both.
        for (name, _, cpu, (et, ev)) in rows.iter().filter(|r| r.0.starts_with("DOPRI5")) {
            if let Some((tname, _, tcpu, _)) = rows
                .iter()
                .filter(|r| r.0.starts_with("Taylor") && r.3.0 <= *et && r.3.1 <= *ev)
                .min_by(|a, b| a.2.total_cmp(&b.2))
            {
                println!(
                    "  at the error of {name}: {tname}, {:.1}× less CPU",
                    cpu / tcpu
                );
            }
        }
    }
}
