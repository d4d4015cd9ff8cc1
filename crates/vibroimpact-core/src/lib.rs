//! vibroimpact-core: impact dampers and vibro-impact systems.
//!
//! Pure Rust, no Python: the two-mass impact damper ([`ImpactDamper`]),
//! compliant contact laws ([`contact`]), fixed-step integrators
//! ([`integrators`]) driven by one generic kernel ([`run::integrate`]) that
//! keeps a thinned history and a table of located contacts, and closed-form
//! references ([`closed_forms`], [`beam`], [`materials`]). SI units throughout.
//! Every run is bounded in steps and memory and checks its energy balance
//! (see [`run::simulate`]).

pub mod assembly;
mod balance;
pub mod beam;
pub mod closed_forms;
pub(crate) mod compact;
pub mod contact;
mod contact_balance;
pub mod ensemble;
pub mod error;
pub mod events;
pub mod exact;
mod hermite;
mod impacts;
pub mod integrators;
pub mod linalg;
pub mod materials;
pub mod matrix_flow;
pub mod memory;
pub mod modal;
pub mod model;
pub mod records;
pub mod reductions;
pub mod run;
mod series;
pub mod settings;
pub mod settling;
pub mod shooting;
pub mod signals;
mod sized;
pub mod step_control;
pub mod steppers;
pub mod structure;
pub mod study;
pub mod system;
pub mod system_events;
pub mod system_methods;
pub mod system_steppers;
pub mod tableau;
pub mod testing;

pub use contact::{Contact, ContactLaw, LawKind};
pub use error::{Error, Result};
pub use memory::MAX_RECORD_BYTES;
pub use records::{ContactRecord, History, Solution};
pub use run::simulate;
pub use settings::{
    ContactTiming, Method, MethodOptions, Settings, Stepping, DEFAULT_ENERGY_TOLERANCE,
    DEFAULT_MAX_ROWS,
};
pub use steppers::Tolerances;
pub use system::{ImpactDamper, State};
