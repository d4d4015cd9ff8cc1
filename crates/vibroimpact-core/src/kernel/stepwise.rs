//! A fixed-step run taken one step at a time by its caller: what the
//! lockstep lanes ([`crate::analysis::lanes`]) advance together. Each step is
//! the driver's ([`crate::kernel::events::integrate_system_stepped`] with
//! [`Stepping::Fixed`]): the same calls in the same order, so the same bits.

use crate::error::Result;
use crate::kernel::clock::Stop;
use crate::kernel::events::{ContactTiming, RunOptions, Stepping, SystemSolution};
use crate::kernel::memory::MAX_RECORD_BYTES;
use crate::kernel::run::Run;
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::Assembly;

/// A fixed-step run in progress.
pub(crate) struct FixedRun<'a> {
    pub(super) run: Run<'a>,
}

impl<'a> FixedRun<'a> {
    /// The run of `system` from `initial` in fixed steps timed by `timing`.
    pub(crate) fn new<S: SystemStepper>(
        system: &'a Assembly,
        stepper: &mut S,
        initial: &[f64],
        options: &'a RunOptions,
        timing: ContactTiming,
    ) -> Result<Self> {
        let stepping = Stepping::Fixed {
            contact_timing: timing,
        };
        let run = Run::new(
            system,
            stepper,
            (initial, &[]),
            options,
            stepping,
            MAX_RECORD_BYTES,
        )?;
        Ok(Self { run })
    }

    /// The next step and what follows it; false where the run has ended.
    pub(crate) fn step<S: SystemStepper>(
        &mut self,
        stepper: &mut S,
        interrupt: &mut dyn FnMut() -> bool,
    ) -> Result<bool> {
        if self.run.clock.time >= self.run.options.t_end {
            return Ok(false);
        }
        let stop = self.run.fixed_step(stepper)?;
        if stop == Stop::End {
            return Ok(false);
        }
        self.run.after_step(stop, interrupt)?;
        Ok(true)
    }

    /// The run's solution.
    pub(crate) fn finish<S: SystemStepper>(self, stepper: &S) -> SystemSolution {
        self.run.finish(stepper)
    }
}
