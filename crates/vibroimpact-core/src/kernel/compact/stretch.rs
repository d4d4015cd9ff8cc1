//! The fast path: plain RK4 steps on the grid taken at once in the compact
//! form's fixed-size arrays, up to the kernel's next stop reason (its own
//! rule, [`Schedule::plain_step`]), each the kernel's step to the bit.

#![allow(clippy::needless_range_loop, clippy::manual_memcpy)]

use super::press::deepen;
use super::stop_rules::{passed_over, shows_no_event};
use super::stretch_reductions::{peak_inside, widen_peaks, Sums};
use super::{Compact, Factors, MAX_LEN, MAX_WALLS};
use crate::error::Error;
use crate::kernel::balance::EnergyWatch;
use crate::kernel::clock::{Clock, Schedule};
use crate::kernel::events::{ContactTiming, Open};
use crate::kernel::sized::by_size;
use crate::model::assembly::CONTACT;
use crate::model::assembly::{Assembly, Mode, Scratch};

impl Compact {
    /// [`Self::stretch`] for the system's sizes, in AVX2 where the processor
    /// has it (the same operations: the same bits). Not in AVX-512, where
    /// there is that too: these loops are scalar arithmetic on a few
    /// values, and built for AVX-512 the 3-mode cantilever's steps with
    /// events ran at 75 % of their rate in AVX2 with the dampers rattling
    /// and 68 % without contact (`system_throughput`, alternated; no run
    /// measured faster in AVX-512).
    pub(crate) fn run_stretch(
        &self,
        system: &Assembly,
        f: &mut Stretch<'_>,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        // Fixed steps: free flight and contact in functions of their own
        // (sharing one, free flight's loop measured slower).
        let fixed = f.schedule.fixed.is_some();
        let free = fixed && self.free(modes) && f.open.iter().all(Option::is_none);
        // The events' stretches that sum the mean squares, in a function of
        // their own, from the recorded window on: one that starts before it
        // stops at it (`Schedule::plain_step`). The summing stretch taking
        // the steps before the window measured 4 % slower there.
        let (schedule, clock) = (f.schedule, &*f.clock);
        let summed = schedule.mean_square
            && schedule.in_window(clock.time, schedule.grid_length(clock))
            && !modes.contains(&Mode::Sticking);
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor has the feature the functions are built for.
            return unsafe {
                match (fixed, free) {
                    // Out of the events' stretches, which they would grow.
                    (true, true) => fixed_free_avx2(self, system, f, modes, scratch),
                    (true, false) => fixed_contact_avx2(self, system, f, modes, scratch),
                    (false, _) if summed => stretch_summed_avx2(self, system, f, modes, scratch),
                    (false, _) => stretch_avx2(self, system, f, modes, scratch),
                }
            };
        }
        if fixed {
            return fixed_baseline(self, system, f, modes, scratch, free);
        }
        if summed {
            return stretch_summed_sized(self, system, f, modes, scratch);
        }
        stretch_sized(self, system, f, modes, scratch)
    }

    /// [`Self::method_steps`] of `method`'s steps for the system's sizes: the
    /// events' stretches of a method other than RK4 (the implicit Newmark
    /// family's).
    #[inline(never)]
    pub(crate) fn method_stretch<M: ArraySteps>(
        &self,
        method: &mut M,
        system: &Assembly,
        f: &mut Stretch<'_>,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        method_sized(self, method, system, f, modes, scratch)
    }

    /// Plain RK4 steps on the grid, as the event kernel takes them, for as
    /// long as nothing but the step itself is due (the kernel's own rule,
    /// [`Schedule::plain_step`]), with the system's data in registers across
    /// them. Each step is the kernel's to the bit; one that turns out not to
    /// be plain (a gap that may cross, a compliant contact at its deepest, a
    /// peak inside the step, a state no longer finite) is taken back, for
    /// the kernel to take.
    // Out of line in debug builds: every size's and variant's copy in one
    // frame outgrew a thread's stack there.
    #[cfg_attr(debug_assertions, inline(never))]
    #[cfg_attr(not(debug_assertions), inline(always))]
    pub(crate) fn stretch<const STICKING: bool, const FREE: bool, const SUMMED: bool>(
        &self,
        system: &Assembly,
        n: usize,
        k: usize,
        f: &mut Stretch<'_>,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        let d = n + k;
        let row = 2 * d;
        let count = self.count.min(MAX_WALLS);
        let len = f.y.len().min(MAX_LEN);
        let observed = system.observed();
        let modes = &modes[..count];
        let mut y = [0.0; MAX_LEN];
        y[..len].copy_from_slice(&f.y[..len]);
        let mut start_gaps = [(0.0, 0.0); MAX_WALLS];
        start_gaps[..count].copy_from_slice(&f.gaps[..count]);
        let mut end = [0.0; MAX_LEN];
        let mut end_gaps = [(0.0, 0.0); MAX_WALLS];
        let mut stages = [[0.0; MAX_LEN]; 4];
        let (held, locked, releasable) = passed_over(system, modes);
        // None in free flight (only a sticking pair releases): `stages[0]`
        // then never carries over, known at compile time. (The contact
        // stretches keep the flag at run time: made a constant there too, a
        // rattling cantilever's run measured 15 % slower.)
        let releasable = !FREE && releasable;
        let factors = self.rate_factors(modes);
        // Whether `stages[0]` holds the rates at the step's start (the last
        // step's release test evaluated them there).
        let mut start_valid = false;
        // The mean squares' rates at the step's start and end (the
        // reductions' own, as `reduce_step` makes them): the last summed
        // step's end rates are the next one's start rates, to the bit.
        // `SUMMED`: the mean squares are summed, in the recorded window (the
        // caller, `run_stretch`, picks it from there on).
        debug_assert!(!SUMMED || (f.schedule.mean_square && !STICKING));
        let mut reduce_rates = [[0.0; MAX_LEN]; 2];
        let mut reduce_valid = false;
        // In registers through the loop, written back after it.
        let mut energy = *f.energy;
        let schedule = *f.schedule;
        let mut clock = *f.clock;
        loop {
            if clock.accepted >= f.max_accepted {
                f.limited = true;
                break;
            }
            let plain_step = if SUMMED {
                schedule.plain_summed_step(&clock)
            } else {
                schedule.plain_step(&clock)
            };
            let Some((length, in_window)) = plain_step else {
                break;
            };
            let time = clock.time;
            let next = time + length;
            let cache = scratch.first_cache().copied();
            self.step::<STICKING, FREE>(
                system,
                n,
                k,
                time,
                &y,
                length,
                (modes, &factors),
                scratch,
                &mut stages,
                start_valid,
                &mut end,
            );
            self.gaps(d, &end, &mut end_gaps);
            // What the kernel would do more than count the step: an event
            // search, a blow-up, a compliant contact's deepest point, a peak
            // inside the step.
            let mut plain = end[..row].iter().fold(0.0, |sum, v| sum + v * 0.0) == 0.0;
            plain &= shows_no_event(modes, &held, (&start_gaps, &end_gaps), length);
            if plain && releasable {
                // A sticking pair whose constraint force at the step's end
                // pulls is released: the forces as the event search takes
                // them.
                let at = (modes, &factors);
                self.rates::<true, false>(system, n, k, next, &end, at, scratch, &mut stages[0]);
                for w in 0..count {
                    if modes[w] == Mode::Sticking
                        && !locked[w]
                        && scratch.force_of(w).unwrap_or(0.0) < 0.0
                    {
                        plain = false;
                    }
                }
            }
            if in_window && peak_inside(system, observed, (&y[..], &end[..]), d, n) {
                plain = false;
            }
            if !plain {
                if let (Some(saved), Some(cache)) = (cache, scratch.first_cache()) {
                    *cache = saved;
                }
                break;
            }
            for w in 0..count {
                if let (Mode::Compliant { .. }, Some(contact)) = (modes[w], &mut f.open[w]) {
                    contact.max_indentation = contact.max_indentation.max(-end_gaps[w].0);
                }
            }
            if in_window {
                self.reduce_plain::<STICKING, FREE>(
                    system,
                    (n, k),
                    ((time, &y), (length, &end)),
                    (modes, &factors),
                    (&mut reduce_rates, reduce_valid, SUMMED),
                    f.sums(),
                );
            }
            reduce_valid = SUMMED && in_window;
            clock.plain_step_to(next);
            f.evaluations += 4;
            f.steps += 1;
            // Those rates are the next step's first stage.
            start_valid = releasable;
            y = end;
            start_gaps = end_gaps;
            let state = (&y, len, modes);
            if let Err(failure) = energy.after_step_of(system, state, clock.accepted, next) {
                f.unbalanced = Some(failure);
                break;
            }
        }
        f.keep(energy, clock, &y[..len], &start_gaps[..count]);
    }

    /// [`Self::stretch`]'s loop for another method's steps ([`ArraySteps`]):
    /// plain steps on the grid, as the event kernel takes them, for as long as nothing but the
    /// step itself is due (the kernel's own rule, [`Schedule::plain_step`]),
    /// with the system's data in registers across them. Each step is the
    /// kernel's to the bit; one that turns out not to be plain (a gap that
    /// may cross, a compliant contact at its deepest, a peak inside the step,
    /// a state no longer finite, an attempt that fails) is taken back, for
    /// the kernel to take.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn method_steps<M: ArraySteps, const STICKING: bool, const FREE: bool>(
        &self,
        method: &mut M,
        system: &Assembly,
        n: usize,
        k: usize,
        f: &mut Stretch<'_>,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        let d = n + k;
        let row = 2 * d;
        let count = self.count.min(MAX_WALLS);
        let len = f.y.len().min(MAX_LEN);
        let observed = system.observed();
        let modes = &modes[..count];
        let mut y = [0.0; MAX_LEN];
        y[..len].copy_from_slice(&f.y[..len]);
        let mut start_gaps = [(0.0, 0.0); MAX_WALLS];
        start_gaps[..count].copy_from_slice(&f.gaps[..count]);
        let mut end = [0.0; MAX_LEN];
        let mut end_gaps = [(0.0, 0.0); MAX_WALLS];
        let (held, locked, releasable) = passed_over(system, modes);
        // None in free flight (only a sticking pair releases): the end's
        // rates then never carry over, known at compile time. (The contact
        // stretches keep the flag at run time: made a constant there too, a
        // rattling cantilever's run measured 15 % slower.)
        let releasable = !FREE && releasable;
        let factors = self.rate_factors(modes);
        // In registers through the loop, written back after it.
        let mut energy = *f.energy;
        let schedule = *f.schedule;
        let mut clock = *f.clock;
        loop {
            if clock.accepted >= f.max_accepted {
                f.limited = true;
                break;
            }
            let Some((length, in_window)) = schedule.plain_step(&clock) else {
                break;
            };
            let time = clock.time;
            let next = time + length;
            let cache = scratch.first_cache().copied();
            let at = (modes, &factors);
            let made = method.step::<STICKING, FREE>(
                self,
                system,
                (n, k),
                (time, length),
                &y,
                at,
                scratch,
                &mut end,
            );
            self.gaps(d, &end, &mut end_gaps);
            // What the kernel would do more than count the step: an event
            // search, a blow-up, a compliant contact's deepest point, a peak
            // inside the step (or the attempt's failure, which it reports).
            let mut plain = end[..row].iter().fold(0.0, |sum, v| sum + v * 0.0) == 0.0;
            plain &= made.is_some();
            plain &= shows_no_event(modes, &held, (&start_gaps, &end_gaps), length);
            if plain && releasable {
                // A sticking pair whose constraint force at the step's end
                // pulls is released: the forces as the event search takes
                // them.
                let rates = method.end_rates();
                self.rates::<true, false>(system, n, k, next, &end, at, scratch, rates);
                for w in 0..count {
                    if modes[w] == Mode::Sticking
                        && !locked[w]
                        && scratch.force_of(w).unwrap_or(0.0) < 0.0
                    {
                        plain = false;
                    }
                }
            }
            if in_window && peak_inside(system, observed, (&y[..], &end[..]), d, n) {
                plain = false;
            }
            if !plain {
                if let (Some(saved), Some(cache)) = (cache, scratch.first_cache()) {
                    *cache = saved;
                }
                break;
            }
            for w in 0..count {
                if let (Mode::Compliant { .. }, Some(contact)) = (modes[w], &mut f.open[w]) {
                    contact.max_indentation = contact.max_indentation.max(-end_gaps[w].0);
                }
            }
            if in_window {
                let kept = observed.min(f.peaks.len());
                widen_peaks(system, &mut f.peaks[..kept], (&y[..], &end[..]), n);
                *f.recorded_time += length;
            }
            clock.plain_step_to(next);
            f.evaluations += made.unwrap_or(0);
            f.steps += 1;
            // Those rates are the next step's start's.
            method.keep(releasable);
            y = end;
            start_gaps = end_gaps;
            let state = (&y, len, modes);
            if let Err(failure) = energy.after_step_of(system, state, clock.accepted, next) {
                f.unbalanced = Some(failure);
                break;
            }
        }
        f.keep(energy, clock, &y[..len], &start_gaps[..count]);
    }

    /// Plain fixed steps of `dt` on the grid (`stepping = "fixed"`), as the
    /// kernel's fixed step takes them ([`crate::kernel::fixed`]), for as
    /// long as nothing but the step, the contacts that go on and its
    /// reductions are due (the kernel's rule, [`Schedule::plain_fixed_step_of`]:
    /// the stretch sums the mean squares in the window): each the kernel's
    /// to the bit. One that turns out not to be plain (a contact begins or ends
    /// in it, a peak inside it, a state no longer finite) is taken back, for
    /// the kernel to take. No pair sticks in fixed stepping (no rigid pair).
    /// `FREE`: free flight ([`Compact::free`]).
    #[inline(always)]
    pub(crate) fn fixed_stretch<const FREE: bool, const OUTSIDE: bool>(
        &self,
        system: &Assembly,
        n: usize,
        k: usize,
        f: &mut Stretch<'_>,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        let (d, count) = (n + k, self.count.min(MAX_WALLS));
        let len = f.y.len().min(MAX_LEN);
        let modes = &modes[..count];
        let mut y = [0.0; MAX_LEN];
        y[..len].copy_from_slice(&f.y[..len]);
        let mut start_gaps = [(0.0, 0.0); MAX_WALLS];
        start_gaps[..count].copy_from_slice(&f.gaps[..count]);
        let (mut end, mut end_gaps) = ([0.0; MAX_LEN], [(0.0, 0.0); MAX_WALLS]);
        let mut stages = [[0.0; MAX_LEN]; 4];
        let (mut energy, schedule, mut clock) = (*f.energy, *f.schedule, *f.clock);
        let (dt, located) = (schedule.dt, schedule.fixed == Some(ContactTiming::Located));
        let factors = self.rate_factors(modes);
        // The stop rules asked once for the steps they allow in a row (the
        // most the stretch may take: it is then limited, if all were plain).
        let most = f.max_accepted.saturating_sub(clock.accepted);
        // In the window, the mean squares summed here as the kernel's fixed
        // step sums them (`reduce_step` with the stages' signal caches):
        // from the step's first stage and the rates at its end.
        let summed = !OUTSIDE && schedule.mean_square;
        let mut reduce_rates = [[0.0; MAX_LEN]; 2];
        let allowed = schedule.plain_fixed_run(&clock, most, summed);
        f.limited = allowed == most;
        // The steps taken (counted into `f` after the loop).
        let mut taken = 0;
        // The state's rooms a step writes: the rest is never read.
        let room = (2 * d + CONTACT + MAX_WALLS).min(MAX_LEN);
        // `OUTSIDE` (free flight before the recorded window): the loop calls
        // nothing (a call in it, even one not made, keeps the state in
        // memory rather than in registers), so the energy balance, due every
        // few steps, is made between runs of steps, and a step into the
        // window is left to the kernel.
        let mut due = None;
        // In contact, the last step's dissipated power at its end is taken
        // from the next step's first stage (the rates at that state and
        // time) where it is the same bits (see `Compact::press`).
        let mut pressing = false;
        'steps: loop {
            if let Some(check) = due.take() {
                let copy = y;
                let state = (&copy[..len], modes);
                if let Err(failure) = energy.balance(system, state, check, clock.time) {
                    f.unbalanced = Some(failure);
                    f.limited = false;
                    break 'steps;
                }
            }
            while taken < allowed {
                debug_assert!(schedule.plain_fixed_step_of(&clock, summed).is_some());
                let time = clock.time;
                let next = (clock.grid + 1) as f64 * dt;
                let in_window = schedule.in_window(time, dt);
                if OUTSIDE && in_window {
                    f.limited = false;
                    break 'steps;
                }
                let in_window = !OUTSIDE && in_window;
                // The force's signal cache, to put back if the step is taken back.
                let cache = if OUTSIDE && self.force.is_none() {
                    None
                } else {
                    scratch.first_cache().copied()
                };
                self.step::<false, FREE>(
                    system,
                    n,
                    k,
                    time,
                    &y,
                    dt,
                    (modes, &factors),
                    scratch,
                    &mut stages,
                    false,
                    &mut end,
                );
                if !FREE && pressing {
                    pressing = false;
                    self.press(system, d, f.open, (&y, len, modes), Some(&stages[0]), dt);
                }
                let ends = (&y, &end);
                if !self.fixed_plain::<FREE>(system, (n, k), ends, &mut end_gaps, f.open, in_window)
                {
                    if let (Some(saved), Some(cache)) = (cache, scratch.first_cache()) {
                        *cache = saved;
                    }
                    f.limited = false;
                    break 'steps;
                }
                if !FREE {
                    pressing = deepen(&mut f.open[..count], (&start_gaps, &end_gaps), dt, located);
                }
                if in_window {
                    if summed {
                        f.reduce_scratch.signals_from(scratch);
                        reduce_rates[0] = stages[0];
                    }
                    self.reduce_plain::<false, FREE>(
                        system,
                        (n, k),
                        ((time, &y), (dt, &end)),
                        (modes, &factors),
                        (&mut reduce_rates, true, summed),
                        f.sums(),
                    );
                }
                clock.plain_step_to(next);
                taken += 1;
                for e in 0..room {
                    y[e] = end[e];
                }
                if !FREE {
                    start_gaps = end_gaps;
                }
                if OUTSIDE {
                    due = energy.due(clock.accepted, false, next);
                    if due.is_some() {
                        continue 'steps;
                    }
                } else {
                    let state = (&y, len, modes);
                    if let Err(failure) = energy.after_step_of(system, state, clock.accepted, next)
                    {
                        f.unbalanced = Some(failure);
                        f.limited = false;
                        break 'steps;
                    }
                }
            }
            break;
        }
        if !FREE && pressing {
            // The last step's power where no next step was made here.
            self.press(system, d, f.open, (&y, len, modes), None, dt);
        }
        f.steps += taken;
        f.evaluations += 4 * taken;
        if FREE && taken > 0 {
            self.gaps(d, &y, &mut start_gaps);
        }
        f.keep(energy, clock, &y[..len], &start_gaps[..count]);
    }
}

/// [`Compact::stretch`] for the system's sizes (constants in each arm).
#[inline(always)]
fn stretch_sized(
    compact: &Compact,
    system: &Assembly,
    f: &mut Stretch<'_>,
    modes: &[Mode],
    scratch: &mut Scratch,
) {
    // Without a sticking pair, no constraint solve is compiled in; in free
    // flight, no wall's force and no gravity.
    if modes.contains(&Mode::Sticking) {
        by_size!(system, |n, k| compact
            .stretch::<true, false, false>(system, n, k, f, modes, scratch))
    } else if compact.free(modes) {
        by_size!(system, |n, k| compact
            .stretch::<false, true, false>(system, n, k, f, modes, scratch))
    } else {
        by_size!(system, |n, k| compact
            .stretch::<false, false, false>(system, n, k, f, modes, scratch))
    }
}

/// [`stretch_sized`] summing the mean squares (no pair sticks: the kernel
/// sums them where one does).
#[inline(always)]
fn stretch_summed_sized(
    compact: &Compact,
    system: &Assembly,
    f: &mut Stretch<'_>,
    modes: &[Mode],
    scratch: &mut Scratch,
) {
    if compact.free(modes) {
        by_size!(system, |n, k| compact
            .stretch::<false, true, true>(system, n, k, f, modes, scratch))
    } else {
        by_size!(system, |n, k| compact
            .stretch::<false, false, true>(system, n, k, f, modes, scratch))
    }
}

/// [`Compact::method_steps`] of `method` for the system's sizes (constants in
/// each arm).
#[inline(always)]
fn method_sized<M: ArraySteps>(
    compact: &Compact,
    method: &mut M,
    system: &Assembly,
    f: &mut Stretch<'_>,
    modes: &[Mode],
    scratch: &mut Scratch,
) {
    // Without a sticking pair, no constraint solve is compiled in; in free
    // flight, no wall's force and no gravity.
    if modes.contains(&Mode::Sticking) {
        by_size!(system, |n, k| compact.method_steps::<M, true, false>(
            method, system, n, k, f, modes, scratch
        ))
    } else if compact.free(modes) {
        by_size!(system, |n, k| compact.method_steps::<M, false, true>(
            method, system, n, k, f, modes, scratch
        ))
    } else {
        by_size!(system, |n, k| compact.method_steps::<M, false, false>(
            method, system, n, k, f, modes, scratch
        ))
    }
}

/// A fixed-step method's step in the compact form's arrays, each as the
/// event kernel takes it through the method's attempt, to the bit: another
/// method's specialisation than RK4's (the implicit Newmark family's).
/// [`Compact::method_steps`] takes them in a row: [`Compact::stretch`]'s
/// loop, whose RK4 steps are its own (made generic over RK4 too, the
/// throughput example's RK4 events on the general kernel measured 30 %
/// slower).
pub(crate) trait ArraySteps {
    /// The step `length` from `(time, y)` (`at`) into `end` (every room of
    /// the accumulators), for `n` structure coordinates and `k` dampers
    /// (`sizes`), in `modes` with their rate factors: the right-hand-side
    /// evaluations it made, or None where the method's attempt fails (the
    /// kernel then makes it, and reports why).
    #[allow(clippy::too_many_arguments)]
    fn step<const STICKING: bool, const FREE: bool>(
        &mut self,
        compact: &Compact,
        system: &Assembly,
        sizes: (usize, usize),
        at: (f64, f64),
        y: &[f64; MAX_LEN],
        modes: (&[Mode], &Factors),
        scratch: &mut Scratch,
        end: &mut [f64; MAX_LEN],
    ) -> Option<u64>;
    /// Room for the rates at the last step's end (a sticking pair's release
    /// test evaluates them there).
    fn end_rates(&mut self) -> &mut [f64; MAX_LEN];
    /// The last step is kept; `end_rates`: whether [`Self::end_rates`]
    /// holds the rates at its end (the next step's start).
    fn keep(&mut self, end_rates: bool);
}

/// [`Compact::fixed_stretch`] in free flight for the system's sizes
/// (constants in each arm): before the recorded window, without its code.
#[inline(always)]
fn fixed_free_sized(
    compact: &Compact,
    system: &Assembly,
    f: &mut Stretch<'_>,
    modes: &[Mode],
    scratch: &mut Scratch,
) {
    if f.schedule.in_window(f.clock.time, f.schedule.dt) {
        by_size!(system, |n, k| compact
            .fixed_stretch::<true, false>(system, n, k, f, modes, scratch))
    } else {
        by_size!(system, |n, k| compact
            .fixed_stretch::<true, true>(system, n, k, f, modes, scratch))
    }
}

/// [`Compact::fixed_stretch`] in contact for the system's sizes.
#[inline(always)]
fn fixed_contact_sized(
    compact: &Compact,
    system: &Assembly,
    f: &mut Stretch<'_>,
    modes: &[Mode],
    scratch: &mut Scratch,
) {
    by_size!(system, |n, k| compact
        .fixed_stretch::<false, false>(system, n, k, f, modes, scratch))
}

/// The fixed stretches for the baseline processor, out of line (their
/// arms' arrays kept out of the caller's frame).
#[inline(never)]
fn fixed_baseline(
    compact: &Compact,
    system: &Assembly,
    f: &mut Stretch<'_>,
    modes: &[Mode],
    scratch: &mut Scratch,
    free: bool,
) {
    if free {
        fixed_free_sized(compact, system, f, modes, scratch)
    } else {
        fixed_contact_sized(compact, system, f, modes, scratch)
    }
}

/// [`stretch_sized`] (or a fixed stretch's) compiled for a processor feature.
macro_rules! stretch_with {
    ($name:ident, $sized:ident, $feature:literal) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feature)]
        unsafe fn $name(
            compact: &Compact,
            system: &Assembly,
            f: &mut Stretch<'_>,
            modes: &[Mode],
            scratch: &mut Scratch,
        ) {
            $sized(compact, system, f, modes, scratch)
        }
    };
}
stretch_with!(stretch_avx2, stretch_sized, "avx2");
stretch_with!(stretch_summed_avx2, stretch_summed_sized, "avx2");
stretch_with!(fixed_free_avx2, fixed_free_sized, "avx2");
stretch_with!(fixed_contact_avx2, fixed_contact_sized, "avx2");

/// What the fast path advances, lent by the kernel ([`crate::kernel::run`]):
/// its clock, state, gaps, open contacts (their deepest indentation), peaks
/// and energy balance, with its stop rules ([`Schedule`]) and the most
/// accepted steps it may reach (the next interrupt poll or the step limit).
/// It takes a step only where the kernel would take it whole and do nothing
/// after it but count it, or check the energy balance, which it does as the
/// kernel would. The memory and row limits the kernel checks after each
/// step hold through a stretch, which adds no contact and no row.
pub struct Stretch<'a> {
    pub(crate) clock: &'a mut Clock,
    pub(crate) schedule: &'a Schedule,
    /// The state, advanced in place, and each wall's gap and rate there.
    pub(crate) y: &'a mut [f64],
    pub(crate) gaps: &'a mut [(f64, f64)],
    /// Room for a step's end and its gaps (the methods without a compact
    /// form of their own: [`crate::kernel::plain_fixed`]).
    pub(crate) end: &'a mut [f64],
    pub(crate) end_gaps: &'a mut [(f64, f64)],
    pub(crate) open: &'a mut [Option<Open>],
    /// The reductions' peaks, mean squares' integrals and recorded time
    /// (used in the window), and their rates' work space (its signal
    /// caches: the reductions' own, [`crate::kernel::reductions::reduce_step`]).
    pub(crate) peaks: &'a mut [f64],
    pub(crate) squares: &'a mut [f64],
    pub(crate) reduce_scratch: &'a mut Scratch,
    pub(crate) recorded_time: &'a mut f64,
    pub(crate) energy: &'a mut EnergyWatch,
    /// The most accepted steps the stretch may reach, and whether it did.
    pub(crate) max_accepted: u64,
    pub(crate) limited: bool,
    /// Right-hand-side evaluations and steps made.
    pub(crate) evaluations: u64,
    pub(crate) steps: u64,
    /// The energy balance's failure, on which the stretch stopped.
    pub(crate) unbalanced: Option<Error>,
}

impl Stretch<'_> {
    /// The stretch's end written back to the kernel: its energy watch and
    /// clock, the state `y` and the walls' `gaps` there.
    #[inline(always)]
    pub(crate) fn keep(
        &mut self,
        energy: EnergyWatch,
        clock: Clock,
        y: &[f64],
        gaps: &[(f64, f64)],
    ) {
        *self.energy = energy;
        *self.clock = clock;
        self.y[..y.len()].copy_from_slice(y);
        self.gaps[..gaps.len()].copy_from_slice(gaps);
    }

    /// The reductions a plain step in the recorded window adds to.
    #[inline(always)]
    fn sums(&mut self) -> Sums<'_> {
        (
            self.peaks,
            self.squares,
            self.recorded_time,
            self.reduce_scratch,
        )
    }
}
