//! RK4 on a compact system as [`crate::methods::steppers::ExplicitRk`]
//! takes it (its compact path), except that the first attempt of a step
//! is the one the lockstep lanes made of it.

use super::lanes::LaneStep;
use crate::error::{Error, Result};
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::{Assembly, Mode, Scratch};

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

/// A lane's stepper (see the module's doc).
pub(crate) struct LaneStepper {
    first: Vec<f64>,
    start_valid: bool,
    evaluations: u64,
    stash: Option<Stash>,
}

impl LaneStepper {
    pub(crate) fn new(system: &Assembly) -> Self {
        Self {
            first: vec![0.0; system.state_len()],
            start_valid: false,
            evaluations: 0,
            stash: None,
        }
    }

    /// Lane `l` of the lanes' `step` from `time` of `h`, for the run's
    /// next attempt. The run's force cache has been through the step's
    /// stages already (the lanes took the values through it).
    pub(crate) fn stash(&mut self, time: f64, h: f64, step: &LaneStep, l: usize) {
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

    /// The run's step is over: an attempt not taken is stale.
    pub(crate) fn taken(&mut self) {
        if let Some(stash) = self.stash.as_mut() {
            stash.fresh = false;
        }
    }

    /// The evaluations of `steps` plain steps the lanes took for the run.
    pub(crate) fn plain_steps(&mut self, steps: u64) {
        self.evaluations += 4 * steps;
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
            self.evaluations += 4;
            self.start_valid = true;
            return Ok(0.0);
        }
        let compact = system.compact.as_ref().ok_or_else(|| {
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

    fn first_stage(&self) -> Option<&[f64]> {
        Some(&self.first)
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
