//! vibroimpact-core: impact dampers and vibro-impact systems, in pure Rust (no
//! Python). SI units throughout.
//!
//! The crate is laid out as it works:
//! - [`model`]: what is simulated, importing no solver: a structure
//!   ([`model::structure`], cantilevers in [`model::beam`]), interactions
//!   (gaps linear in the coordinates, with a law: rigid or compliant,
//!   [`model::contact`]), excitation signals ([`model::signals`]), all
//!   assembled into one system ([`model::assembly::Assembly`]); materials
//!   and closed-form references; the two-mass impact damper
//!   ([`ImpactDamper`]).
//! - [`kernel`]: the event-driven simulation of any assembled system
//!   ([`kernel::events::integrate_system`]): crossings located on the
//!   method's own solution, rigid impacts resolved together
//!   (`kernel::impacts`), records, limits and the energy balance, and the
//!   fixed-size fast path for small systems.
//! - [`methods`]: the steppers (explicit Runge-Kutta over tableaux, the
//!   Newmark family, the exact flow of piecewise-linear systems) and the
//!   registry of methods by name ([`methods::registry`]).
//! - [`analysis`]: settling, shooting for periodic orbits, studies of many
//!   runs on every core and lockstep ensembles.
//! - [`numerics`]: small dense linear algebra, Hermite interpolation, series.
//!
//! The two-mass impact damper's run is the preset on the general kernel:
//! [`simulate`] (from [`methods::registry::two_mass`]) with its [`Settings`],
//! returning a [`SystemSolution`] whose contacts are [`PairContact`]s.
//!
//! Every run is bounded in steps and memory and checks its energy balance.

pub mod analysis;
pub mod error;
pub mod kernel;
pub mod methods;
pub mod model;
pub mod numerics;
pub mod testing;

pub use error::{Error, Result};
pub use kernel::events::{PairContact, SystemSolution};
pub use kernel::memory::MAX_RECORD_BYTES;
pub use methods::registry::two_mass::{
    simulate, ContactTiming, Method, MethodOptions, Settings, Stepping, Tolerances,
    DEFAULT_ENERGY_TOLERANCE, DEFAULT_MAX_ROWS,
};
pub use model::contact::{Contact, ContactLaw, LawKind};
pub use model::impact_damper::{ImpactDamper, State};
