//! The physics of the gear pair, as restated in `docs/MODEL.md`: parameters (§4), the
//! contact law (§2), the equation of motion written for the transmission error ξ (§1, §3)
//! and the excitation of the main shaft (§5), imposed or, in torque mode, an inertia driven
//! by a torque (motion.rs); the free flight in the gap in closed form (flight.rs). For the
//! gearbox (`docs/GEARBOX.md`): the clutch damper (damper.rs, §2), the built-in engine
//! (engine.rs, §4), the oil's viscosity (oil.rs, §5). Knows nothing of integrators or FMI.

pub mod contact;
pub mod damper;
pub mod engine;
pub mod excitation;
pub mod flight;
pub mod motion;
pub mod oil;
pub mod params;
pub mod series;

pub use contact::{ContactLaw, ForceSlopes, Region};
pub use damper::{Damper, DamperParams, DamperSlopes, Stage};
pub use engine::{Engine, EngineOrder, EngineParams};
pub use excitation::{Excitation, Polynomial, Shaft, Sine, TorqueRamp};
pub use flight::{Flight, FlightStart, FlightState};
pub use motion::{Dynamics, Loads, MainShaft};
pub use oil::Oil;
pub use params::GearParams;
pub use series::ContactSeries;
