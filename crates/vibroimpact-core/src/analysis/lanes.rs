//! Lockstep lanes of compact systems: fixed-step RK4 runs of small modal
//! systems (those [`crate::kernel::compact`] takes: a few modes, a damper or
//! two, a stop or two, compliant laws, at most one harmonic force, gravity)
//! advanced [`LANES`] at a time.
//!
//! Each lane is the single fixed-step run the general kernel makes of its
//! system ([`crate::kernel::events::integrate_system_stepped`] with
//! [`Stepping::Fixed`](crate::kernel::events::Stepping), RK4, located
//! contacts), bit for bit: the plain steps (no contact begun or ended in
//! the step, nothing due after it but the contacts that go on, the peaks
//! and mean squares, the energy check) are taken for all lanes at once in
//! vector instructions, as the single run's fast path takes them one by
//! one; a step that is not plain is the kernel's own, from the lanes'
//! attempt (see [`crate::kernel::compact`]'s `lockstep`). What a run keeps
//! (contacts, peaks, mean squares, final state) and how it fails (a
//! blow-up, an energy balance) are the kernel's, lane by lane: a lane that
//! fails stops and the others go on.
//!
//! Lanes share a step and a shape (sizes, walls, law kind, force or not); a
//! group whose systems differ in shape is stepped lane by lane (the same
//! bits, without the vector speed).

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::kernel::compact::{run_group, LANES};
use crate::kernel::events::{RunOptions, SystemSolution};
use crate::model::assembly::Assembly;

/// The fixed RK4 runs of `systems` (each with a compact form) from
/// `initials` (see [`crate::model::assembly::initial_state`]), with
/// `options` (`dt` required), on `threads` threads (0: all cores): each
/// run's solution or error, in order. The same bits whatever the number of
/// threads or the grouping. Only an interrupt fails the whole.
pub fn run_lanes(
    systems: &[Assembly],
    initials: &[Vec<f64>],
    options: &RunOptions,
    threads: usize,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<Result<SystemSolution>>> {
    if let Some(i) = systems.iter().position(|s| s.compact.is_none()) {
        return Err(Error::Inconsistent(format!(
            "lockstep lanes take small modal systems only (run {i} has none)"
        )));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::Inconsistent(format!("cannot start the lanes' threads: {e}")))?;
    let members: Vec<(&Assembly, &Vec<f64>)> = systems.iter().zip(initials).collect();
    let groups: Vec<Result<Vec<Result<SystemSolution>>>> = pool.install(|| {
        members
            .par_chunks(LANES)
            .map(|group| run_group(group, options, interrupt))
            .collect()
    });
    let mut out = Vec::with_capacity(systems.len());
    for group in groups {
        out.extend(group?);
    }
    Ok(out)
}

#[cfg(test)]
#[path = "lanes_tests.rs"]
mod tests;
