//! The co-simulation slave, free of C types: FMI 2.0's calls as methods that return
//! `Ok(())` or the reason of a refusal.

use crate::model::{Causality, Params, State, VARIABLES, variable, vr};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Instantiated,
    Initialization,
    StepComplete,
    Terminated,
    Error,
}

/// Everything that determines the future of an instance (what fmi2GetFMUstate saves).
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub mode: Mode,
    pub t: f64,
    pub y: State,
    /// Parameters and the input, by value reference (index = vr).
    pub values: [f64; SLOTS],
    /// d tau_M / dt from fmi2SetRealInputDerivatives (0 unless set; kept until set again).
    pub tau_dot: f64,
}

/// Room for the value references of the parameters and the input (1..=10).
pub const SLOTS: usize = 11;

pub type Result<T = ()> = std::result::Result<T, String>;

pub struct Instance {
    pub s: Snapshot,
    params: Option<Params>,
}

fn start_values() -> [f64; SLOTS] {
    let mut values = [0.0; SLOTS];
    for v in VARIABLES
        .iter()
        .filter(|v| v.causality != Causality::Output)
    {
        values[v.vr as usize] = v.start;
    }
    values
}

impl Default for Instance {
    fn default() -> Self {
        Instance {
            s: Snapshot {
                mode: Mode::Instantiated,
                t: 0.0,
                y: [0.0; 4],
                values: start_values(),
                tau_dot: 0.0,
            },
            params: None,
        }
    }
}

impl Instance {
    fn expect(&self, allowed: &[Mode], call: &str) -> Result {
        if allowed.contains(&self.s.mode) {
            Ok(())
        } else {
            Err(format!("{call} is not allowed in state {:?}", self.s.mode))
        }
    }

    fn build(&self) -> Result<Params> {
        Params::from(|vr| self.s.values[vr as usize])
    }

    pub fn setup_experiment(&mut self, start_time: f64) -> Result {
        self.expect(&[Mode::Instantiated], "fmi2SetupExperiment")?;
        if !start_time.is_finite() {
            return Err(format!("startTime = {start_time} must be finite"));
        }
        self.s.t = start_time;
        Ok(())
    }

    pub fn enter_initialization_mode(&mut self) -> Result {
        self.expect(&[Mode::Instantiated], "fmi2EnterInitializationMode")?;
        self.s.mode = Mode::Initialization;
        Ok(())
    }

    /// Checks the parameters and sets the initial state: both shafts at idle speed.
    pub fn exit_initialization_mode(&mut self) -> Result {
        self.expect(&[Mode::Initialization], "fmi2ExitInitializationMode")?;
        let p = self.build()?;
        self.s.y = p.initial_state();
        self.params = Some(p);
        self.s.mode = Mode::StepComplete;
        Ok(())
    }

    pub fn terminate(&mut self) -> Result {
        self.expect(&[Mode::StepComplete, Mode::Error], "fmi2Terminate")?;
        self.s.mode = Mode::Terminated;
        Ok(())
    }

    pub fn reset(&mut self) {
        *self = Instance::default();
    }

    /// Parameters and state used for outputs: during initialisation, the initial state from
    /// the parameters set so far.
    fn current(&self) -> Result<(Params, State)> {
        match self.params {
            Some(p) if self.s.mode != Mode::Initialization && self.s.mode != Mode::Instantiated => {
                Ok((p, self.s.y))
            }
            _ => {
                let p = self.build()?;
                Ok((p, p.initial_state()))
            }
        }
    }

    pub fn get_real(&self, vrs: &[u32], out: &mut [f64]) -> Result {
        for (vr, out) in vrs.iter().zip(out.iter_mut()) {
            let var = variable(*vr)
                .ok_or_else(|| format!("unknown value reference {vr} for type Real"))?;
            *out = match var.causality {
                Causality::Output => {
                    let (p, y) = self.current()?;
                    p.output(*vr, &y, self.s.values[vr::tau_M as usize])
                        .expect("an output")
                }
                _ => self.s.values[*vr as usize],
            };
        }
        Ok(())
    }

    /// Sets parameters (before fmi2ExitInitializationMode) and the input. The whole call is
    /// checked first: a refused call changes nothing.
    pub fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> Result {
        self.expect(
            &[Mode::Instantiated, Mode::Initialization, Mode::StepComplete],
            "fmi2SetReal",
        )?;
        for (vr, value) in vrs.iter().zip(values) {
            let var = variable(*vr)
                .ok_or_else(|| format!("unknown value reference {vr} for type Real"))?;
            match var.causality {
                Causality::Output => {
                    return Err(format!("{} is an output: it cannot be set", var.name));
                }
                Causality::Parameter if self.s.mode == Mode::StepComplete => {
                    return Err(format!(
                        "{} is a fixed parameter: set it before fmi2ExitInitializationMode",
                        var.name
                    ));
                }
                _ => {}
            }
            if !value.is_finite() {
                return Err(format!(
                    "{} = {value} refused: values must be finite",
                    var.name
                ));
            }
        }
        for (vr, value) in vrs.iter().zip(values) {
            self.s.values[*vr as usize] = *value;
        }
        Ok(())
    }

    /// fmi2GetRealOutputDerivatives: order 1 only (maxOutputDerivativeOrder = 1).
    pub fn get_output_derivatives(&self, vrs: &[u32], orders: &[i32], out: &mut [f64]) -> Result {
        self.expect(&[Mode::StepComplete], "fmi2GetRealOutputDerivatives")?;
        let (p, y) = self.current()?;
        for ((vr, order), out) in vrs.iter().zip(orders).zip(out.iter_mut()) {
            if *order != 1 {
                return Err(format!(
                    "derivative order {order} refused: maxOutputDerivativeOrder is 1"
                ));
            }
            *out = p
                .output_derivative(*vr, &y, self.s.values[vr::tau_M as usize], self.s.tau_dot)
                .ok_or_else(|| format!("value reference {vr} is not a Real output"))?;
        }
        Ok(())
    }

    /// fmi2SetRealInputDerivatives: order 1 of tau_M, a ramp over the following steps.
    pub fn set_input_derivatives(&mut self, vrs: &[u32], orders: &[i32], values: &[f64]) -> Result {
        self.expect(
            &[Mode::Instantiated, Mode::Initialization, Mode::StepComplete],
            "fmi2SetRealInputDerivatives",
        )?;
        for ((vr, order), value) in vrs.iter().zip(orders).zip(values) {
            if *vr != vr::tau_M || *order != 1 || !value.is_finite() {
                return Err(format!(
                    "input derivative of order {order} = {value} for value reference {vr} refused: only the first derivative of tau_M ({}), finite",
                    vr::tau_M
                ));
            }
        }
        if let Some(value) = values.last() {
            self.s.tau_dot = *value;
        }
        Ok(())
    }

    pub fn do_step(&mut self, current: f64, h: f64) -> Result {
        self.expect(&[Mode::StepComplete], "fmi2DoStep")?;
        if !(h > 0.0 && h.is_finite()) {
            return Err(format!(
                "communicationStepSize = {h:e} refused: it must be finite and > 0"
            ));
        }
        // masters accumulate the communication point: accept rounding drift
        if !current.is_finite()
            || (current - self.s.t).abs() > 1e-9 * self.s.t.abs().max(h).max(1e-3)
        {
            return Err(format!(
                "currentCommunicationPoint = {current} does not match the instance's time {}",
                self.s.t
            ));
        }
        let p = self.params.expect("initialised");
        let tau = &mut self.s.values[vr::tau_M as usize];
        self.s.y = p.advance(&self.s.y, *tau, self.s.tau_dot, h);
        // the input follows its ramp until the master sets it again
        *tau += self.s.tau_dot * h;
        self.s.t = current + h;
        if self.s.y.iter().any(|x| !x.is_finite()) {
            self.s.mode = Mode::Error;
            return Err(format!("the state is no longer finite at t = {}", self.s.t));
        }
        Ok(())
    }

    pub fn time(&self) -> f64 {
        self.s.t
    }

    pub fn snapshot(&self) -> Snapshot {
        self.s.clone()
    }

    pub fn restore(&mut self, s: &Snapshot) -> Result {
        let params = match s.mode {
            Mode::Instantiated | Mode::Initialization => None,
            _ => Some(Params::from(|vr| s.values[vr as usize])?),
        };
        self.s = s.clone();
        self.params = params;
        Ok(())
    }
}

// Serialized FMU state: "FLYWHEEL", format version (u32), mode (u32), the f64s (t, y,
// values, tau_dot), then an FNV-1a 64 checksum of everything before it; all little-endian.
const MAGIC: &[u8; 8] = b"FLYWHEEL";
const FORMAT: u32 = 1;
pub const SERIALIZED_SIZE: usize = 8 + 4 + 4 + 8 * (1 + 4 + SLOTS + 1) + 8;

fn checksum(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x100_0000_01b3)
    })
}

const MODES: [Mode; 5] = [
    Mode::Instantiated,
    Mode::Initialization,
    Mode::StepComplete,
    Mode::Terminated,
    Mode::Error,
];

impl Snapshot {
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(SERIALIZED_SIZE);
        b.extend_from_slice(MAGIC);
        b.extend_from_slice(&FORMAT.to_le_bytes());
        let mode = MODES.iter().position(|m| *m == self.mode).expect("a mode") as u32;
        b.extend_from_slice(&mode.to_le_bytes());
        for x in std::iter::once(&self.t)
            .chain(&self.y)
            .chain(&self.values)
            .chain([&self.tau_dot])
        {
            b.extend_from_slice(&x.to_le_bytes());
        }
        let sum = checksum(&b);
        b.extend_from_slice(&sum.to_le_bytes());
        b
    }

    pub fn from_bytes(b: &[u8]) -> Result<Self> {
        if b.len() != SERIALIZED_SIZE || &b[..8] != MAGIC {
            return Err(format!(
                "not a serialized Flywheel state ({} bytes)",
                b.len()
            ));
        }
        let (body, sum) = b.split_at(SERIALIZED_SIZE - 8);
        if checksum(body).to_le_bytes() != sum {
            return Err("serialized Flywheel state refused: checksum mismatch".into());
        }
        let word = |i: usize| u32::from_le_bytes(body[i..i + 4].try_into().expect("4 bytes"));
        if word(8) != FORMAT {
            return Err(format!(
                "serialized Flywheel state of format {} refused: this binary reads format {FORMAT}",
                word(8)
            ));
        }
        let mode = *MODES
            .get(word(12) as usize)
            .ok_or("serialized Flywheel state: invalid mode")?;
        let f: Vec<f64> = body[16..]
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect();
        Ok(Snapshot {
            mode,
            t: f[0],
            y: [f[1], f[2], f[3], f[4]],
            values: f[5..5 + SLOTS].try_into().expect("SLOTS values"),
            tau_dot: f[5 + SLOTS],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn running() -> Instance {
        let mut i = Instance::default();
        i.setup_experiment(0.0).unwrap();
        i.enter_initialization_mode().unwrap();
        i.exit_initialization_mode().unwrap();
        i
    }

    #[test]
    fn rollback_is_bit_identical() {
        let mut i = running();
        i.set_real(&[vr::tau_M], &[-1.5]).unwrap();
        i.set_input_derivatives(&[vr::tau_M], &[1], &[30.0])
            .unwrap();
        i.do_step(0.0, 1e-3).unwrap();
        let saved = Snapshot::from_bytes(&i.snapshot().to_bytes()).unwrap();
        i.do_step(1e-3, 2.5e-3).unwrap();
        let first = i.snapshot();
        let mut j = Instance::default();
        j.restore(&saved).unwrap();
        j.do_step(1e-3, 2.5e-3).unwrap();
        assert_eq!(j.snapshot(), first);
    }

    #[test]
    fn corrupt_state_is_refused() {
        let mut b = running().snapshot().to_bytes();
        b[20] ^= 1;
        assert!(Snapshot::from_bytes(&b).unwrap_err().contains("checksum"));
        assert!(Snapshot::from_bytes(&b[..10]).is_err());
    }

    #[test]
    fn parameters_are_fixed_after_initialisation() {
        let mut i = running();
        assert!(i.set_real(&[vr::k_d], &[1.0]).is_err());
        assert!(i.set_real(&[vr::theta_M], &[1.0]).is_err());
        assert!(i.set_real(&[vr::tau_M], &[f64::NAN]).is_err());
    }

    #[test]
    fn invalid_parameter_keeps_initialisation_mode() {
        let mut i = Instance::default();
        i.enter_initialization_mode().unwrap();
        i.set_real(&[vr::I_M], &[0.0]).unwrap();
        assert!(i.exit_initialization_mode().unwrap_err().contains("I_M"));
        i.set_real(&[vr::I_M], &[0.01]).unwrap();
        i.exit_initialization_mode().unwrap();
    }

    #[test]
    fn long_step_equals_sub_steps() {
        // a 1 ms step is cut into 10 sub-steps of 0.1 ms: the same as ten 0.1 ms steps
        let mut a = running();
        let mut b = running();
        a.do_step(0.0, 1e-3).unwrap();
        for k in 0..10 {
            b.do_step(f64::from(k) * 1e-4, 1e-4).unwrap();
        }
        for (x, y) in a.s.y.iter().zip(&b.s.y) {
            assert!((x - y).abs() <= 1e-12 * x.abs().max(1.0));
        }
    }
}
