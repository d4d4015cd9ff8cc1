//! Lockstep lanes of compact systems: fixed-step RK4 runs of small modal
//! systems (those [`crate::kernel::compact`] takes: a few modes, a damper or
//! two, a stop or two, compliant laws, at most one harmonic force, gravity)
//! advanced [`LANES`] at a time.
//!
//! Each lane is the single fixed-step run the general kernel makes of its
//! system ([`crate::kernel::events::integrate_system_stepped`] with
//! [`Stepping::Fixed`](crate::kernel::events::Stepping), RK4, located
//! contacts), bit for bit: the kernel's own run ([`FixedRun`]) takes every
//! step, and only the RK4 attempt that starts each step (the bulk of its
//! arithmetic) is made for all lanes at once, in vector instructions, by
//! [`Group::step`] (the compact path's operations in its order). Whatever
//! else a step needs (a step taken again where a contact began inside it,
//! the reductions' probes) the lane's stepper makes alone, as the compact
//! path does. What a run keeps (contacts, peaks, mean squares, final state)
//! and how it fails (a blow-up, an energy balance) are the kernel's, lane
//! by lane: a lane that fails stops and the others go on.
//!
//! Lanes share a step and a shape (sizes, walls, law kind, force or not); a
//! group whose systems differ in shape is stepped lane by lane (the same
//! bits, without the vector speed).

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::kernel::compact::{Group, LaneModes, LaneState, LaneStep, LANES};
use crate::kernel::events::{ContactTiming, RunOptions, SystemSolution};
use crate::kernel::stepwise::FixedRun;
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::{Assembly, Mode, Scratch};
use crate::model::contact::{Hertz, HysterHertz, Linear};

/// Group steps between the caller's interrupt polls.
const POLL_INTERVAL: u64 = 1024;

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

/// The lanes' vector steps, by the law kind they share.
enum Lanes {
    Hertz(Box<Group<Hertz>>),
    HysterHertz(Box<Group<HysterHertz>>),
    Linear(Box<Group<Linear>>),
}

impl Lanes {
    fn of(members: &[(&Assembly, &Vec<f64>)]) -> Option<Self> {
        let systems: Vec<_> = members
            .iter()
            .map(|(s, _)| (s.compact.as_deref(), s.n, s.k, s.state_len()))
            .map(|(c, n, k, len)| c.map(|c| (c, n, k, len)))
            .collect::<Option<_>>()?;
        if let Some(g) = Group::<HysterHertz>::of(&systems) {
            return Some(Self::HysterHertz(Box::new(g)));
        }
        if let Some(g) = Group::<Hertz>::of(&systems) {
            return Some(Self::Hertz(Box::new(g)));
        }
        Group::<Linear>::of(&systems).map(|g| Self::Linear(Box::new(g)))
    }

    fn step(
        &self,
        time: f64,
        start: &LaneState,
        h: f64,
        modes: &LaneModes,
        scratch: &mut [Scratch],
        out: &mut LaneStep,
    ) {
        match self {
            Self::Hertz(g) => g.step(time, start, h, modes, scratch, out),
            Self::HysterHertz(g) => g.step(time, start, h, modes, scratch, out),
            Self::Linear(g) => g.step(time, start, h, modes, scratch, out),
        }
    }
}

/// A group of at most [`LANES`] runs in lockstep.
fn run_group(
    members: &[(&Assembly, &Vec<f64>)],
    options: &RunOptions,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<Result<SystemSolution>>> {
    let count = members.len();
    let mut steppers: Vec<LaneStepper> = members.iter().map(|(s, _)| LaneStepper::new(s)).collect();
    let mut results: Vec<Option<Result<SystemSolution>>> = vec![None; count];
    let mut runs: Vec<Option<FixedRun>> = Vec::with_capacity(count);
    for (l, (system, initial)) in members.iter().enumerate() {
        match FixedRun::new(
            system,
            &mut steppers[l],
            initial,
            options,
            ContactTiming::Located,
        ) {
            Ok(run) => runs.push(Some(run)),
            Err(e) => {
                results[l] = Some(Err(e));
                runs.push(None);
            }
        }
    }
    let lanes = Lanes::of(members);
    let mut scratch: Vec<Scratch> = (0..LANES)
        .map(|l| Scratch::new(members[l.min(count - 1)].0))
        .collect();
    let mut start = LaneStep::state();
    let mut modes = LaneModes::default();
    let mut step = LaneStep::default();
    let dt = options.dt.unwrap_or(f64::NAN);
    let mut taken = 0u64;
    while let Some(time) = runs.iter().flatten().map(FixedRun::time).next() {
        if let Some(lanes) = &lanes {
            let mut fed = [false; LANES];
            for (l, run) in runs.iter_mut().enumerate() {
                let Some(run) = run else { continue };
                if run.time().to_bits() != time.to_bits() || !modes.set(l, run.modes()) {
                    continue;
                }
                for (e, v) in run.state().iter().enumerate() {
                    start[e][l] = *v;
                }
                if let (Some(to), Some(from)) =
                    (scratch[l].first_cache(), run.scratch().first_cache())
                {
                    *to = *from;
                }
                fed[l] = true;
            }
            lanes.step(time, &start, dt, &modes, &mut scratch, &mut step);
            for (l, stepper) in steppers.iter_mut().enumerate() {
                if fed[l] {
                    stepper.stash(time, dt, &step, l);
                }
            }
        }
        for l in 0..count {
            let Some(run) = runs[l].as_mut() else {
                continue;
            };
            let stepper = &mut steppers[l];
            std::mem::swap(&mut stepper.cache, &mut scratch[l]);
            let next = run.step(stepper, &mut || false);
            std::mem::swap(&mut stepper.cache, &mut scratch[l]);
            if let Some(stash) = stepper.stash.as_mut() {
                stash.fresh = false;
            }
            match next {
                Ok(true) => {}
                Ok(false) => {
                    let run = runs[l].take().expect("a run in progress");
                    results[l] = Some(Ok(run.finish(stepper)));
                }
                Err(e) => {
                    runs[l] = None;
                    results[l] = Some(Err(e));
                }
            }
        }
        taken += 1;
        if taken % POLL_INTERVAL == 0 && interrupt() {
            return Err(Error::Interrupted { time });
        }
    }
    Ok(results
        .into_iter()
        .map(|r| r.expect("every run ended"))
        .collect())
}

/// The attempt the lanes made of a step.
#[derive(Debug, Clone)]
struct Stash {
    time: f64,
    h: f64,
    end: Vec<f64>,
    first: Vec<f64>,
    /// Not yet taken (the buffers are kept for the next step's).
    fresh: bool,
}

/// RK4 on a compact system as [`crate::methods::steppers::ExplicitRk`]
/// takes it (its compact path), except that the first attempt of a step
/// is the one the lanes made.
struct LaneStepper {
    first: Vec<f64>,
    start_valid: bool,
    evaluations: u64,
    stash: Option<Stash>,
    /// The force's cache after the lanes' attempt (swapped in for the step).
    cache: Scratch,
}

impl LaneStepper {
    fn new(system: &Assembly) -> Self {
        let len = system.state_len();
        Self {
            first: vec![0.0; len],
            start_valid: false,
            evaluations: 0,
            stash: None,
            cache: Scratch::new(system),
        }
    }

    /// Lane `l` of the lanes' `step` from `time` of `h`.
    fn stash(&mut self, time: f64, h: f64, step: &LaneStep, l: usize) {
        let mut stash = self.stash.take().unwrap_or_else(|| Stash {
            time,
            h,
            end: vec![0.0; self.first.len()],
            first: vec![0.0; self.first.len()],
            fresh: false,
        });
        (stash.time, stash.h, stash.fresh) = (time, h, true);
        for (e, (end, first)) in stash.end.iter_mut().zip(&mut stash.first).enumerate() {
            *end = step.end[e][l];
            *first = step.first[e][l];
        }
        self.stash = Some(stash);
    }
}

impl SystemStepper for LaneStepper {
    fn name(&self) -> &'static str {
        "rk4"
    }

    fn is_adaptive(&self) -> bool {
        false
    }

    fn reset(&mut self) {
        self.start_valid = false;
    }

    fn attempt(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &[f64],
        h: f64,
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) -> Result<f64> {
        let len = system.state_len();
        let start_valid = self.start_valid;
        let made = self.stash.as_mut().filter(|s| {
            s.fresh
                && !start_valid
                && s.time.to_bits() == time.to_bits()
                && s.h.to_bits() == h.to_bits()
        });
        if let Some(stash) = made {
            stash.fresh = false;
            out[..len].copy_from_slice(&stash.end);
            self.first.copy_from_slice(&stash.first);
            if let (Some(to), Some(from)) = (scratch.first_cache(), self.cache.first_cache()) {
                *to = *from;
            }
            self.evaluations += 4;
            self.start_valid = true;
            return Ok(0.0);
        }
        let compact = system.compact.as_deref().ok_or_else(|| {
            Error::Inconsistent("lockstep lanes take small modal systems only".into())
        })?;
        compact.rk4(
            system,
            system.n,
            system.k,
            time,
            &y[..len],
            h,
            modes,
            scratch,
            &mut self.first,
            self.start_valid,
            &mut out[..len],
        );
        self.evaluations += if self.start_valid { 3 } else { 4 };
        self.start_valid = true;
        Ok(0.0)
    }

    fn accept(&mut self) {
        // RK4's end is not the next start's first stage (as ExplicitRk).
        self.start_valid = false;
    }

    fn shrink(&self, error: f64) -> f64 {
        error.powf(-1.0 / 5.0)
    }

    fn evaluations(&self) -> u64 {
        self.evaluations
    }
}

#[cfg(test)]
#[path = "lanes_tests.rs"]
mod tests;
