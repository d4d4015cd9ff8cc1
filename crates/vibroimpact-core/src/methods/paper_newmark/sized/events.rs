//! The paper's Newmark in fixed-size arrays, stepping by events
//! (`stepping = "events"`): the plain steps between events (each on the
//! grid, or to it after an event) taken at once, up to the kernel's next
//! stop reason (its own rule, [`crate::kernel::clock::Schedule::plain_step`],
//! as the RK4 stretch of the compact path reads it). Each is the kernel's
//! step to the bit: [`PaperNewmark::sized_step`], the step of the fixed
//! stretch, which is [`PaperNewmark`]'s attempt in arrays. One that turns
//! out not to be plain (a gap that may cross, a compliant contact at its
//! deepest, a peak inside it, a state no longer finite) is left for the
//! kernel to take.

#![allow(clippy::needless_range_loop)]

use super::{Carried, Sized, Step, MAX_RATES};
use crate::kernel::compact::{
    passed_over, peak_inside, shows_no_event, widen_peaks, Stretch, MAX_DIM, MAX_LEN, MAX_WALLS,
};
use crate::kernel::sized::by_size;
use crate::methods::paper_newmark::PaperNewmark;
use crate::model::assembly::{Assembly, Mode, CONTACT};

/// The inverse effective matrices of the last two step lengths: after an
/// event the steps end on the grid's points, whose differences round to a
/// few neighbouring lengths, each its own matrix (the method's own cache
/// keeps one; a length's inverse is the same numbers whenever made).
struct Inverses {
    steps: [u64; 2],
    inverse: [[[f64; MAX_DIM]; MAX_DIM]; 2],
    /// The slot the next new length takes.
    next: usize,
}

impl PaperNewmark {
    /// [`Self::sized_event_steps`] for the system's sizes (constants in
    /// each arm).
    #[inline(never)]
    pub(in crate::methods::paper_newmark) fn sized_event_stretch<const FREE: bool>(
        &mut self,
        system: &Assembly,
        sized: &Sized,
        f: &mut Stretch<'_>,
        modes: &[Mode],
    ) {
        by_size!(system, |n, k| self.sized_event_steps::<FREE>(
            system,
            sized,
            (n, n + k),
            f,
            modes
        ))
    }

    /// The inverse for a step of `h` from `inverses`, made
    /// ([`Self::sized_inverse`]) where it holds none for `h`. The slot is
    /// picked without a branch: the lengths alternate as the grid's points
    /// round, which no branch predictor follows.
    #[inline(always)]
    fn inverse_for<'a>(
        &mut self,
        system: &Assembly,
        inverses: &'a mut Inverses,
        (d, h): (usize, f64),
        any: bool,
    ) -> &'a [[f64; MAX_DIM]; MAX_DIM] {
        let bits = h.to_bits();
        let slot = usize::from(inverses.steps[1] == bits);
        if inverses.steps[slot] == bits {
            return &inverses.inverse[slot];
        }
        let slot = inverses.next;
        inverses.inverse[slot] = self.sized_inverse(system, (d, h), any);
        inverses.steps[slot] = bits;
        inverses.next = 1 - slot;
        &inverses.inverse[slot]
    }

    /// Plain steps by events from the kernel's state lent in `f`, as its
    /// step ([`crate::kernel::run`]) takes them through [`Self::attempt`],
    /// for `n` structure coordinates of `d`. Only from a point where the
    /// method holds its accelerations and rates (after an event or a
    /// restart, the kernel's step makes them). `FREE`: every wall open, the
    /// walls' terms left out at compile time (they add nothing then).
    #[inline(always)]
    fn sized_event_steps<const FREE: bool>(
        &mut self,
        system: &Assembly,
        sized: &Sized,
        (n, d): (usize, usize),
        f: &mut Stretch<'_>,
        modes: &[Mode],
    ) {
        if !(self.valid && self.powers_valid) {
            return;
        }
        let schedule = *f.schedule;
        let mut clock = *f.clock;
        let (len, observed) = (f.y.len().min(MAX_LEN), system.observed());
        let count = sized.wall_count.min(MAX_WALLS);
        let rate_count = sized.rate_count.min(MAX_RATES);
        let modes = &modes[..count];
        let (held, _, _) = passed_over(system, modes);
        let mut y = [0.0; MAX_LEN];
        y[..len].copy_from_slice(&f.y[..len]);
        let mut start_gaps = [(0.0, 0.0); MAX_WALLS];
        start_gaps[..count].copy_from_slice(&f.gaps[..count]);
        let mut end_gaps = [(0.0, 0.0); MAX_WALLS];
        let any = self.contacts_of(modes);
        let first: Carried = self.sized_carried::<FREE>(sized, d, &y, modes);
        // Two buffers the steps alternate between (the step's start's and
        // its end's), swapped where one is accepted: no copy per step.
        let (mut start_buffer, mut end_buffer) = (first, first);
        let (mut carried, mut next_carried) = (&mut start_buffer, &mut end_buffer);
        let mut inverses = Inverses {
            steps: [u64::MAX; 2],
            inverse: [[[0.0; MAX_DIM]; MAX_DIM]; 2],
            next: 0,
        };
        let mut energy = *f.energy;
        // Free, the walls' accumulators change in the first step alone (as
        // in the fixed stretch).
        let mut first_walls = [0.0; MAX_RATES];
        loop {
            if clock.accepted >= f.max_accepted {
                f.limited = true;
                break;
            }
            let Some((length, in_window)) = schedule.plain_step(&clock) else {
                break;
            };
            let (time, next) = (clock.time, clock.time + length);
            let inverse = self.inverse_for(system, &mut inverses, (d, length), any);
            if FREE && f.steps == 0 {
                for k in CONTACT..MAX_RATES {
                    first_walls[k] = y[2 * d + k] + 0.5 * length * (carried.rates[k] + 0.0);
                }
            }
            let mut step = Step {
                end: [0.0; 2 * MAX_DIM],
                accumulators: [0.0; MAX_RATES],
                contact: [(0.0, 0.0); MAX_WALLS],
            };
            let at = (&y, inverse);
            let steps = (&*carried, &mut *next_carried, &mut step);
            self.sized_step::<FREE>(sized, (n, d), (time, length), at, steps, modes);
            let mut end = [0.0; MAX_LEN];
            for i in 0..d {
                end[i] = step.end[i];
                end[d + i] = step.end[MAX_DIM + i];
            }
            sized.gaps(d, &end, &mut end_gaps);
            // What the kernel would do more than count the step: an event
            // search, a blow-up, a compliant contact's deepest point, a
            // peak inside the step.
            let mut plain = end[..2 * d].iter().fold(0.0, |sum, v| sum + v * 0.0) == 0.0;
            if FREE {
                // Every wall open and none held (that takes a sticking
                // pair): the event search's test of an open wall, whose mode
                // is then known at compile time.
                for w in 0..count {
                    plain &= !Mode::Open.may_cross(start_gaps[w], end_gaps[w]);
                }
            } else {
                plain &= shows_no_event(modes, &held, (&start_gaps, &end_gaps), length);
            }
            if in_window && peak_inside(system, observed, (&y[..], &end[..]), d, n) {
                plain = false;
            }
            if !plain {
                break;
            }
            for w in 0..if FREE { 0 } else { count } {
                if let (Mode::Compliant { .. }, Some(contact)) = (modes[w], &mut f.open[w]) {
                    contact.max_indentation = contact.max_indentation.max(-end_gaps[w].0);
                }
            }
            if in_window {
                let kept = observed.min(f.peaks.len());
                widen_peaks(system, &mut f.peaks[..kept], (&y[..], &end[..]), n);
                *f.recorded_time += length;
            }
            // Accepted (the method's `finish` has nothing to add).
            std::mem::swap(&mut carried, &mut next_carried);
            step.accept_into::<FREE>((d, f.steps == 0), &end, &first_walls, &mut y);
            clock.plain_step_to(next);
            f.steps += 1;
            start_gaps = end_gaps;
            let state = (&y, len, modes);
            if let Err(failure) = energy.after_step_of(system, state, clock.accepted, next) {
                f.unbalanced = Some(failure);
                break;
            }
        }
        self.evaluations += f.steps;
        self.accel[..d].copy_from_slice(&carried.accel[..d]);
        self.powers.start_rates()[..rate_count].copy_from_slice(&carried.rates[..rate_count]);
        f.keep(energy, clock, &y[..len], &start_gaps[..count]);
    }
}
