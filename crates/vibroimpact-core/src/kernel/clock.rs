//! The run's clock and its stop rules: why a kernel step ends ([`Stop`]),
//! where a fixed step lands (the grid, the recorded window's start, a
//! stroboscopic instant, the end), and when a step is plain: nothing due
//! after it but counting it, which is what the fast path ("step until a stop
//! reason", [`crate::kernel::compact`]) takes at once. The kernel's own step
//! and the fast path read the same rules here.

use crate::kernel::events::{ContactTiming, RunOptions};

/// Chattering of compliant contacts: this many mode changes in a row, each
/// closer than the time's round-off can resolve, stop it.
pub(crate) const CHATTER_EVENTS: u64 = 16;
/// Events closer than this many units of round-off of the time itself
/// cannot be told apart.
const CHATTER_ULPS: f64 = 1e3;
/// Steps in a row at the round-off of time that stop a run.
pub(crate) const STALLED_STEPS: u64 = 64;

/// Why a kernel step ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stop {
    /// A step kept: on the grid, or as long as the error control allows.
    Step,
    /// A step kept, landed on the start of the recorded window.
    RecordWindow,
    /// A step kept, landed on a stroboscopic instant.
    Strobe,
    /// A step kept, ended on the event of interaction `interaction`.
    Event { interaction: usize },
    /// No step kept: one rejected by the error control or by its cut, or a
    /// grid point passed by an event; the kernel steps again.
    Retry,
    /// No step: the run is at its end.
    End,
}

/// Where a run stands: its time, the fixed-step grid's last point, the
/// steps kept, the steps to the next history row and the next strobe.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Clock {
    /// s.
    pub(crate) time: f64,
    /// The grid points passed (fixed steps): the next is `(grid + 1) dt`.
    pub(crate) grid: u64,
    pub(crate) accepted: u64,
    /// Steps to the next history row (counts down only while it matters).
    pub(crate) until_kept: u64,
    /// s.
    pub(crate) next_strobe: f64,
}

impl Clock {
    /// A plain step accepted on the grid, ending at `next` (s): the next grid
    /// point, one more step taken, one step fewer to the next history row.
    /// What every stretch of plain steps does after each of its steps.
    #[inline(always)]
    pub(crate) fn plain_step_to(&mut self, next: f64) {
        self.time = next;
        self.grid += 1;
        self.accepted += 1;
        self.until_kept = self.until_kept.saturating_sub(1);
    }
}

/// What a run's options fix about its steps (see [`Clock`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Schedule {
    pub(crate) adaptive: bool,
    /// The fixed step, s (NaN for an adaptive method given none).
    pub(crate) dt: f64,
    pub(crate) t_end: f64,
    pub(crate) keep_history: bool,
    pub(crate) every: u64,
    pub(crate) record_from: f64,
    pub(crate) strobe_period: f64,
    pub(crate) mean_square: bool,
    /// The run's time scale: `t_end` or the structure's longest period, s.
    pub(crate) time_scale: f64,
    /// Fixed stepping's timing of contacts (None: stepping by events).
    pub(crate) fixed: Option<ContactTiming>,
}

impl Schedule {
    pub(crate) fn new(
        options: &RunOptions,
        adaptive: bool,
        longest_period: f64,
        fixed: Option<ContactTiming>,
    ) -> Self {
        Self {
            adaptive,
            dt: options.dt.unwrap_or(f64::NAN),
            t_end: options.t_end,
            keep_history: options.keep_history,
            every: options.every,
            record_from: options.reduce.record_from,
            strobe_period: options.reduce.strobe_period,
            mean_square: options.reduce.mean_square,
            time_scale: options.t_end.min(longest_period),
            fixed,
        }
    }

    /// A fixed-step run on `t_end` to the round-off of the grid's times.
    #[inline(always)]
    pub(crate) fn at_end(&self, time: f64) -> bool {
        !self.adaptive && self.t_end - time <= 1e-9 * self.dt
    }

    /// Whether a run at `time` is done.
    #[inline(always)]
    pub(crate) fn done(&self, time: f64) -> bool {
        time >= self.t_end || self.at_end(time)
    }

    /// The fixed step to the grid's next point (or to `t_end`), s.
    #[inline(always)]
    pub(crate) fn grid_length(&self, clock: &Clock) -> f64 {
        ((clock.grid + 1) as f64 * self.dt - clock.time).min(self.t_end - clock.time)
    }

    /// Whether a step of `length` from `time` passes over the recorded
    /// window's start (it must land there: a step across it would be left
    /// out of the peak and RMS, or counted whole).
    #[inline(always)]
    pub(crate) fn lands_on_window(&self, time: f64, length: f64) -> bool {
        let from = self.record_from;
        from - time < length && from - time > 1e-9 * length
    }

    /// Whether a step of `length` from `time` passes over the next
    /// stroboscopic instant (it must land there).
    #[inline(always)]
    pub(crate) fn lands_on_strobe(&self, clock: &Clock, time: f64, length: f64) -> bool {
        let to = clock.next_strobe - time;
        to < length && to > 1e-9 * self.strobe_period
    }

    /// Whether a stroboscopic state is due at `time`.
    #[inline(always)]
    pub(crate) fn strobe_due(&self, clock: &Clock, time: f64) -> bool {
        time >= clock.next_strobe - 1e-9 * self.strobe_period
    }

    /// Whether a step of `length` from `time` is in the recorded window (one
    /// that starts within round-off of the window's start, which it was not
    /// cut to land on, is).
    #[inline(always)]
    pub(crate) fn in_window(&self, time: f64, length: f64) -> bool {
        time + 1e-9 * length >= self.record_from
    }

    /// Steps and event intervals within a thousand units of round-off of
    /// the time itself make no progress, s.
    #[inline(always)]
    pub(crate) fn chatter_interval(&self, time: f64) -> f64 {
        CHATTER_ULPS * f64::EPSILON * time.abs().max(self.time_scale)
    }

    /// The next fixed step where it is plain, and whether it is in the
    /// recorded window: a whole grid step after which the kernel would do
    /// nothing but count it (no landing on the window's start or a strobe
    /// instant, no strobe, history row or end of the run due after it, not
    /// a stall, no mean square to sum). None where the kernel's own step
    /// must follow, for the reason it will give ([`Stop`]).
    #[inline(always)]
    pub(crate) fn plain_step(&self, clock: &Clock) -> Option<(f64, bool)> {
        let (length, in_window) = self.plain_summed_step(clock)?;
        if in_window && self.mean_square {
            return None;
        }
        Some((length, in_window))
    }

    /// [`Self::plain_step`] where the mean squares are summed in the step
    /// (the compact RK4 stretch sums them).
    #[inline(always)]
    pub(crate) fn plain_summed_step(&self, clock: &Clock) -> Option<(f64, bool)> {
        let time = clock.time;
        if self.at_end(time) {
            return None;
        }
        let length = self.grid_length(clock);
        let next = time + length;
        if length <= 0.0
            || self.lands_on_window(time, length)
            || self.lands_on_strobe(clock, time, length)
            || self.strobe_due(clock, next)
            || self.done(next)
            || (self.keep_history && clock.until_kept <= 1)
            || length <= self.chatter_interval(next)
        {
            return None;
        }
        Some((length, self.in_window(time, length)))
    }

    /// The end of the next fixed step (`dt` from `clock.time`, on the grid)
    /// where it is plain, and whether it is in the recorded window: after it
    /// the kernel would do nothing but count it and add the contacts that
    /// go on (no strobe, history row or end of the run due, not a stall, no
    /// mean square to sum). None where the kernel's own fixed step must
    /// follow.
    #[inline(always)]
    pub(crate) fn plain_fixed_step(&self, clock: &Clock) -> Option<(f64, bool)> {
        let (next, in_window) = self.plain_fixed_summed_step(clock)?;
        if in_window && self.mean_square {
            return None;
        }
        Some((next, in_window))
    }

    /// How many plain fixed steps ([`Self::plain_fixed_step_of`]) follow in
    /// a row from `clock`, at most `most`: the rule asked of each step's clock
    /// as the steps before it leave it (on the grid, the row's countdown
    /// down by one a step). Its terms only grow with the grid (the time, the
    /// steps taken towards a row), so no step after one that is not plain
    /// is: the first found by doubling and bisection, a few rules asked
    /// instead of one a step. `summed`: the steps sum the mean squares
    /// themselves ([`Self::plain_fixed_summed_step`]).
    pub(crate) fn plain_fixed_run(&self, clock: &Clock, most: u64, summed: bool) -> u64 {
        let plain = |i: u64| {
            if i == 0 {
                return self.plain_fixed_step_of(clock, summed).is_some();
            }
            let grid = clock.grid + i;
            let at = Clock {
                time: grid as f64 * self.dt,
                grid,
                accepted: clock.accepted + i,
                until_kept: clock.until_kept.saturating_sub(i),
                next_strobe: clock.next_strobe,
            };
            self.plain_fixed_step_of(&at, summed).is_some()
        };
        if most == 0 || !plain(0) {
            return 0;
        }
        // plain(lo); hi is `most` or not plain.
        let (mut lo, mut stride) = (0, 1);
        let mut hi = loop {
            let probe = lo + stride;
            if probe >= most {
                break most;
            }
            if !plain(probe) {
                break probe;
            }
            lo = probe;
            stride *= 2;
        };
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if plain(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }

    /// [`Self::plain_fixed_summed_step`] where the step sums the mean
    /// squares (`summed`), else [`Self::plain_fixed_step`].
    #[inline(always)]
    pub(crate) fn plain_fixed_step_of(&self, clock: &Clock, summed: bool) -> Option<(f64, bool)> {
        if summed {
            self.plain_fixed_summed_step(clock)
        } else {
            self.plain_fixed_step(clock)
        }
    }

    /// [`Self::plain_fixed_step`] where the mean squares are summed in the
    /// step (the lockstep lanes and the compact fixed stretch sum them).
    #[inline(always)]
    pub(crate) fn plain_fixed_summed_step(&self, clock: &Clock) -> Option<(f64, bool)> {
        let time = clock.time;
        if self.at_end(time) {
            return None;
        }
        let next = (clock.grid + 1) as f64 * self.dt;
        if self.strobe_due(clock, next)
            || self.done(next)
            || (self.keep_history && clock.until_kept <= 1)
            || self.dt <= self.chatter_interval(next)
        {
            return None;
        }
        Some((next, self.in_window(time, self.dt)))
    }
}

#[cfg(test)]
mod tests {
    use super::{Clock, Schedule};

    /// A fixed-step schedule of `dt` to `t_end`, its window from
    /// `record_from`, strobes every `strobe_period` and rows kept where
    /// `keep_history`.
    fn schedule(t_end: f64, record_from: f64, strobe_period: f64, keep_history: bool) -> Schedule {
        Schedule {
            adaptive: false,
            dt: 1e-3,
            t_end,
            keep_history,
            every: 7,
            record_from,
            strobe_period,
            mean_square: false,
            time_scale: t_end,
            fixed: None,
        }
    }

    /// The clock on grid point `grid` (`until_kept` rows to go, the next
    /// strobe at `next_strobe`).
    fn clock(dt: f64, grid: u64, until_kept: u64, next_strobe: f64) -> Clock {
        Clock {
            time: grid as f64 * dt,
            grid,
            accepted: grid,
            until_kept,
            next_strobe,
        }
    }

    /// The rule asked step by step, as the kernel asks it: the steps in a
    /// row (at most `most`) that are `plain`, the clock moved on by each as
    /// a stretch moves it ([`Clock::plain_step_to`] the next grid point).
    fn one_by_one(s: &Schedule, c: &Clock, most: u64, plain: impl Fn(&Clock) -> bool) -> u64 {
        let mut at = *c;
        for i in 0..most {
            if !plain(&at) {
                return i;
            }
            at.plain_step_to((at.grid + 1) as f64 * s.dt);
        }
        most
    }

    #[test]
    fn the_runs_of_plain_steps_are_those_asked_one_by_one() {
        crate::testing::timeout(60, || {
            // Each rule's turn inside the range: the run's end (1 s), the
            // window's start (0.3 s, and on a grid point: 0.25 s), a strobe
            // (at 0.6 s) and a history row (every 7 steps). The fast path
            // (`Compact::fixed_stretch`) takes the steps the search allows
            // in a row; a search that allowed one too many would take a step
            // the kernel must take itself.
            let mut cases = vec![
                schedule(1.0, 0.3, f64::INFINITY, false),
                schedule(1.0, 0.25, f64::INFINITY, false),
                schedule(1.0, 0.0, 0.2, false),
                schedule(1.0, 0.0, f64::INFINITY, true),
                schedule(0.4005, 2.0, f64::INFINITY, false),
            ];
            // Mean squares summed: no step in the window is plain, unless
            // the steps sum them themselves (`summed`).
            cases.push(Schedule {
                mean_square: true,
                ..schedule(1.0, 0.3, f64::INFINITY, false)
            });
            let mut runs = 0;
            for s in &cases {
                for grid in 1..1001 {
                    for most in [1, 5, 64, 10_000] {
                        // No strobe due where there are none (as a run's clock
                        // starts them).
                        let strobe = if s.strobe_period.is_finite() {
                            0.6
                        } else {
                            f64::INFINITY
                        };
                        let c = clock(s.dt, grid, 7 + grid % 5, strobe);
                        for summed in [false, true] {
                            let plain = |at: &Clock| s.plain_fixed_step_of(at, summed).is_some();
                            let asked = one_by_one(s, &c, most, plain);
                            let run = s.plain_fixed_run(&c, most, summed);
                            assert_eq!(run, asked, "{grid} {most} {summed}");
                            if !summed {
                                runs += usize::from(asked > 0 && asked < most);
                            }
                        }
                    }
                }
            }
            // The rows' turns inside the runs searched, not only full runs.
            assert!(runs > 2000, "{runs}");
        });
    }
}
