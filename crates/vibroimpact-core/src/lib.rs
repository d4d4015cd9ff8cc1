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
//! Every run is bounded in steps and memory and checks its energy balance;
//! its inputs are checked when it starts (a literal of a public struct
//! too), and a bad one is an [`Error`] naming the field, never a panic.
//!
//! The two-mass impact damper (the founding paper's Table 1 system) with a
//! Hertzian contact, by RK4 at fixed steps:
//!
//! ```
//! use vibroimpact_core::{simulate, Contact, ContactTiming, ImpactDamper, LawKind};
//! use vibroimpact_core::{Method, Settings, State};
//!
//! let damper = ImpactDamper::new(1.0, 1.0, 0.01, 0.25, 0.01)?; // kg, N/m, N s/m, kg, m
//! let contact = Contact::new(LawKind::Hertz, 3000.0, None, 0.0)?; // N/m^1.5
//! let start = State::new(0.0, 0.0, 0.01, 0.1)?; // on the wall, at 0.1 m/s
//! let settings = Settings::new(Method::Rk4, Some(1e-4), 2.0, 1, ContactTiming::Located, None, 1_000_000)?;
//! let run = simulate(&damper, &contact, &start, &settings, &mut || false)?;
//! assert!(!run.contacts.is_empty());
//! // The ledger closes: stored energy + dissipated - input = the energy at the start.
//! assert!(run.energy.residual.abs() < 1e-6 * run.energy.stored_start);
//! # Ok::<(), vibroimpact_core::Error>(())
//! ```
//!
//! Any system: a structure, dampers (and stops, collisions, friction), its
//! excitations, assembled and run by a method named as the registry names
//! it. A ball dropped 1 m onto a rigid floor rebounds at `e` times its
//! approach speed, `sqrt(2 g h)`:
//!
//! ```
//! use vibroimpact_core::kernel::events::RunOptions;
//! use vibroimpact_core::methods::registry::{AnyStepper, Options};
//! use vibroimpact_core::model::assembly::{initial_state, Assembly, Damper, PairLaw, SystemSpec};
//! use vibroimpact_core::model::structure::Structure;
//!
//! let floor = Structure::oscillator(1e6, 1e12, 0.0)?; // a massive, stiff floor: kg, N/m, N s/m
//! let ball = Damper {
//!     mass: 0.1,
//!     at: 0.0,
//!     lower_clearance: 1.0,
//!     upper_clearance: f64::INFINITY,
//!     law: PairLaw::rigid(0.8)?,
//! };
//! let mut spec = SystemSpec::of(floor, vec![ball]);
//! spec.gravity = 9.81;
//! let system = Assembly::new(&spec)?;
//! let sag = -1e6 * 9.81 / 1e12; // the floor at rest under its own weight, m
//! let y0 = initial_state(&system, &[sag], &[0.0], &[sag], &[0.0])?;
//! let mut method = AnyStepper::new(&system, "dop853", &Options::default())?;
//! let options = RunOptions {
//!     dt: None,
//!     t_end: 1.0,
//!     every: 1,
//!     keep_history: false,
//!     max_steps: 1_000_000,
//!     max_rows: 1_000_000,
//!     energy_tolerance: 1e-6,
//!     reduce: Default::default(),
//! };
//! let run = method.integrate(&system, &y0, &options, &mut || false)?;
//! let first = &run.contacts[0];
//! let approach = (2.0f64 * 9.81 * 1.0).sqrt();
//! assert!((first.approach_speed - approach).abs() < 1e-6 * approach);
//! assert!((first.rebound_speed - 0.8 * first.approach_speed).abs() < 1e-6 * approach);
//! # Ok::<(), vibroimpact_core::Error>(())
//! ```

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
