//! Studies: many runs of one system with some of its parameters varied, on
//! every core (rayon), each reduced to a few metrics instead of a history.
//!
//! A parameter is a dotted path into the scenario, parsed once
//! ([`Parameter::parse`]) and applied to a copy of the base system for each
//! run. Each run is independent of the others and of how they are shared out
//! among threads, so the results are the same bit for bit whatever the number
//! of threads. A run that fails (a blow-up, chattering, a bad combination of
//! values) is recorded with its reason and the others go on.
//!
//! Laid out by concern: `parameters` (the dotted paths a study varies,
//! parsed and applied), `settings` (how each run is made), `run` (the
//! runs on every core), `lockstep` (the bridge to the lockstep ensemble
//! for fixed steps) and `metrics` (what each run is reduced to).

mod compact_lanes;
mod lockstep;
mod metrics;
mod parameters;
mod run;
mod section;
mod settings;

pub use metrics::RunMetrics;
pub use parameters::{Parameter, Target, PATHS, STRUCTURE_KEYS};
pub use run::run_study;
pub use settings::{Analysis, StudySettings};
