//! Plain fixed steps (`stepping = "fixed"`) in a row through any fixed-step
//! method's own attempt: the kernel's fixed step ([`crate::kernel::fixed`])
//! without the bookkeeping a plain step does not need (the driver's stop
//! reason, records, contact changes), for as long as nothing but the step
//! and the contacts that go on is due (the kernel's rule,
//! [`crate::kernel::clock::Schedule::plain_fixed_step`]). Each step is the
//! kernel's to the bit: the same attempt, acceptance and finish, in the same
//! order. One that is not plain (a contact begins or ends in it, a peak
//! inside it, a state no longer finite, an attempt that fails) is left for
//! the kernel to take. The founding paper's Newmark takes them here (its
//! attempt depends on the accepted steps alone, so one taken back leaves no
//! trace); RK4 on a compact system has its own, in fixed-size arrays
//! ([`crate::kernel::compact`]).

use crate::kernel::balance::ENERGY_INTERVAL;
use crate::kernel::compact::{peak_inside, widen_peaks, Stretch};
use crate::kernel::events::ContactTiming;
use crate::kernel::fixed;
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::{Assembly, Mode, Scratch};

/// The contacts' timing of a fixed-step run whose plain steps may be taken
/// in a stretch; None where the kernel takes every step. A step that is not
/// plain is taken back, and with it the first force's signal cache (its
/// harmonic advances by rotation from the last time asked: the values
/// depend on the order of the times); with more signals than that one, the
/// kernel takes every step.
#[inline(always)]
pub(crate) fn stretch_timing(f: &Stretch<'_>, scratch: &Scratch) -> Option<ContactTiming> {
    f.schedule.fixed.filter(|_| scratch.first_cache_only())
}

/// Plain fixed steps of `stepper` on `system` from the kernel's state lent
/// in `f` (see [`Stretch`]), each the kernel's fixed step to the bit.
pub(crate) fn plain_fixed_steps<S: SystemStepper + ?Sized>(
    stepper: &mut S,
    system: &Assembly,
    f: &mut Stretch<'_>,
    modes: &[Mode],
    scratch: &mut Scratch,
) {
    let Some(timing) = stretch_timing(f, scratch) else {
        return;
    };
    let (n, d) = (system.n, system.dim);
    let (row, observed) = (2 * d, system.observed());
    let (dt, located) = (f.schedule.dt, timing == ContactTiming::Located);
    let schedule = *f.schedule;
    loop {
        if f.clock.accepted >= f.max_accepted {
            f.limited = true;
            break;
        }
        let Some((next, in_window)) = schedule.plain_fixed_step(f.clock) else {
            break;
        };
        let time = f.clock.time;
        let cache = scratch.first_cache().copied();
        let evaluations = stepper.evaluations();
        let attempted = stepper.attempt(system, time, f.y, dt, modes, scratch, f.end);
        system.gaps(f.end, f.end_gaps);
        let mut plain =
            attempted.is_ok() && f.end[..row].iter().fold(0.0, |sum, v| sum + v * 0.0) == 0.0;
        for (w, open) in f.open.iter().enumerate() {
            // Indented at the end exactly where in contact: no onset or
            // separation in the step.
            plain &= (f.end_gaps[w].0 < 0.0) == open.is_some();
        }
        if in_window && peak_inside(system, observed, (f.y, f.end), d, n) {
            plain = false;
        }
        if !plain {
            if let (Some(saved), Some(cache)) = (cache, scratch.first_cache()) {
                *cache = saved;
            }
            stepper.uncount(stepper.evaluations() - evaluations);
            break;
        }
        for (w, open) in f.open.iter_mut().enumerate() {
            if let Some(oc) = open.as_mut() {
                let ends = fixed::indentation_data(f.gaps[w], f.end_gaps[w], dt);
                fixed::deepest(oc, ends, located);
                fixed::press(system, w, oc, f.end, modes[w], dt);
            }
        }
        if in_window {
            let kept = observed.min(f.peaks.len());
            widen_peaks(system, &mut f.peaks[..kept], (f.y, f.end), n);
            *f.recorded_time += dt;
        }
        stepper.accept();
        // As the kernel settles it: the run's end is never plain.
        let settle = (f.clock.accepted + 1) % ENERGY_INTERVAL == 0;
        let finished = stepper.finish(system, time, f.y, dt, modes, scratch, f.end, settle);
        if let Err(failure) = finished {
            f.unbalanced = Some(failure);
            break;
        }
        f.clock.plain_step_to(next);
        // (The stepper counts its own evaluations.)
        f.steps += 1;
        f.y.copy_from_slice(f.end);
        f.gaps.copy_from_slice(f.end_gaps);
        let accepted = f.clock.accepted;
        if let Err(failure) = f
            .energy
            .after_step(system, (f.y, modes), accepted, false, next)
        {
            f.unbalanced = Some(failure);
            break;
        }
    }
}
