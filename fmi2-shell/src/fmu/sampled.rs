//! A co-simulation step sampled on a uniform grid inside it, in one call: what the sound
//! (docs/SOUND.md, "The force") needs of an FMU, the forces at every 5.2 µs, without a call
//! from the importer at each of them. It is outside FMI (the export
//! `gearRattleDoStepSampled`); an importer that does not find it takes the same steps with
//! fmi2DoStep and fmi2GetReal.

use super::Fmu;
use crate::contract::Kind;
#[cfg(doc)]
use crate::slave::Lifecycle;
use crate::slave::Slave;
use crate::state::FmiState;
use crate::status::{FmiError, FmiResult};
use crate::stepping::Grid;
use crate::time;

impl<S: Slave> Fmu<S> {
    /// `n` steps of `dt` from `current`, exactly as the calls fmi2DoStep(current + j·dt, dt)
    /// for j = 0 .. n−1, each followed by fmi2GetReal of `vrs` into row j of `out` (n rows of
    /// vrs.len() values, n = out.len() / vrs.len()). The whole call is checked first (every
    /// step against the time it starts from and the time axis, each value reference a Real
    /// variable, `out` a whole number of rows), so a refused call changes nothing; a step or
    /// read that fails leaves the instance in the error state at the time of the last sample
    /// written. The steps the model can serve without stepping ([`Lifecycle::sample`]) are
    /// served in runs, each to the bit as the ordinary step and read would give it; the others
    /// are taken the ordinary way.
    pub fn do_step_sampled(
        &mut self,
        current: f64,
        dt: f64,
        n: usize,
        vrs: &[u32],
        out: &mut [f64],
    ) -> FmiResult {
        self.check_sampled(current, dt, n, vrs, out.len())?;
        let m = vrs.len();
        let mut j = 0;
        while j < n {
            let grid = Grid {
                t0: current,
                dt,
                steps: j..n,
            };
            let served = self.slave.sample(&grid, vrs, &mut out[j * m..]);
            if served > 0 {
                j += served;
                self.time = (current + (j - 1) as f64 * dt) + dt;
                self.last_successful_time = self.time;
                continue;
            }
            let t = current + j as f64 * dt;
            self.step_with(t, dt, |s| s.step(t, dt).map(|()| t + dt))?;
            if m > 0
                && let Err(e) = self.slave.get_real(vrs, &mut out[j * m..(j + 1) * m])
            {
                self.state = FmiState::Error;
                return Err(e);
            }
            j += 1;
        }
        Ok(())
    }

    /// The checks of [`do_step_sampled`](Self::do_step_sampled) before anything moves: each
    /// step from where the one before ends, as fmi2DoStep would check it.
    fn check_sampled(&self, current: f64, dt: f64, n: usize, vrs: &[u32], len: usize) -> FmiResult {
        if n == 0 {
            return Err(FmiError::error(
                "nSamples = 0 refused: take at least one step",
            ));
        }
        if n.checked_mul(vrs.len()) != Some(len) {
            return Err(FmiError::error(format!(
                "the values array holds {len} values for nSamples = {n} and nvr = {}: it must hold nSamples * nvr",
                vrs.len()
            )));
        }
        let mut time = self.time;
        for j in 0..n {
            let t = current + j as f64 * dt;
            time::check_step(t, dt, time)?;
            time = t + dt;
        }
        for vr in vrs {
            (S::IDENTITY.variable)(Kind::Real, *vr)?;
        }
        Ok(())
    }
}
