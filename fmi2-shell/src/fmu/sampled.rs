//! A co-simulation step sampled on a uniform grid inside it, in one call: what the sound
//! (docs/SOUND.md, "The force") needs of an FMU, the forces at every 5.2 µs, without a call
//! from the importer at each of them. It is outside FMI (the export
//! `gearRattleDoStepSampled`); an importer that does not find it takes the same steps with
//! fmi2DoStep and fmi2GetReal.

use super::Fmu;
use crate::contract::Kind;
use crate::slave::Slave;
use crate::state::FmiState;
use crate::status::{FmiError, FmiResult};
use crate::time;

impl<S: Slave> Fmu<S> {
    /// `n` steps of `dt` from `current`, exactly as the calls fmi2DoStep(current + j·dt, dt)
    /// for j = 0 .. n−1, each followed by fmi2GetReal of `vrs` into row j of `out` (n rows of
    /// vrs.len() values, n = out.len() / vrs.len()). The whole call is checked first (the
    /// first and the last step against the instance's time and the time axis, each value
    /// reference a Real variable, `out` a whole number of rows), so a refused call changes
    /// nothing; a step or read that fails leaves the instance in the error state at the time
    /// of the last sample written.
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
        for j in 0..n {
            let t = current + j as f64 * dt;
            self.step_with(t, dt, |s| s.step(t, dt).map(|()| t + dt))?;
            if m > 0
                && let Err(e) = self.slave.get_real(vrs, &mut out[j * m..(j + 1) * m])
            {
                self.state = FmiState::Error;
                return Err(e);
            }
        }
        Ok(())
    }

    /// The checks of [`do_step_sampled`](Self::do_step_sampled) before anything moves.
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
        time::check_step(current, dt, self.time)?;
        let last = current + (n - 1) as f64 * dt;
        time::check_step(last, dt, last)?;
        for vr in vrs {
            (S::IDENTITY.variable)(Kind::Real, *vr)?;
        }
        Ok(())
    }
}
