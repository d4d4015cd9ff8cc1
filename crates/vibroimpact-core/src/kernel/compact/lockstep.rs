//! A group of at most [`LANES`] fixed-step RK4 runs of compact systems in
//! lockstep (see [`crate::analysis::lanes`]). Each lane is the kernel's own
//! run ([`FixedRun`]); its plain steps (the rule of
//! [`Compact::fixed_stretch`](super::Compact), the single run's fast path:
//! no onset or separation in the step, nothing due after it but counting
//! it, the contacts that go on and the reductions) are taken for all lanes
//! at once in fixed-size arrays ([`Group`]), the state, gaps and
//! reductions of each run held there ([`LaneRuns`]) meanwhile; a lane whose
//! step is not plain is handed back to its run, which takes that step
//! itself (from the lanes' attempt, [`LaneStepper`]) and whatever follows
//! it. The same operations in the same order as the single run: the same
//! bits.

#![allow(clippy::needless_range_loop)]

use super::lane_signals::LaneCaches;
use super::lane_stepper::LaneStepper;
use super::lane_steps::{LaneGaps, LaneRuns, PlainStep};
use super::lanes::{each_lane, lanes_where, stage_times, Group, LaneLaw, LaneModes, LaneStep};
use super::lanes::{LANES, V};
use super::{MAX_LEN, MAX_WALLS};
use crate::error::{Error, Result};
use crate::kernel::clock::Schedule;
use crate::kernel::events::{ContactTiming, RunOptions, SystemSolution};
use crate::kernel::fixed;
use crate::kernel::stepwise::FixedRun;
use crate::model::assembly::Assembly;
use crate::model::contact::{Hertz, HysterHertz, Linear};

/// Group steps between the caller's interrupt polls.
const POLL_INTERVAL: u64 = 1024;

/// Each run of `members` (systems with a compact form, and their starts),
/// in fixed RK4 steps of `options.dt` with located contacts, advanced in
/// lockstep: each run's solution or error, in order. Only an interrupt
/// fails the whole.
pub(crate) fn run_group(
    members: &[(&Assembly, &Vec<f64>)],
    options: &RunOptions,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<Result<SystemSolution>>> {
    let systems: Vec<&Assembly> = members.iter().map(|(s, _)| *s).collect();
    if let Some(g) = Group::<HysterHertz>::of(&systems) {
        return Lockstep::new(members, options, true).run(Some(&g), interrupt);
    }
    if let Some(g) = Group::<Hertz>::of(&systems) {
        return Lockstep::new(members, options, true).run(Some(&g), interrupt);
    }
    // Lanes that differ in shape are stepped by their runs alone.
    let group = Group::<Linear>::of(&systems);
    Lockstep::new(members, options, group.is_some()).run(group.as_ref(), interrupt)
}

/// The group's runs and what the lanes hold of them.
struct Lockstep<'a> {
    /// Whether the lanes step the runs (else each run steps alone).
    vector: bool,
    mean_square: bool,
    systems: Vec<&'a Assembly>,
    runs: Vec<Option<FixedRun<'a>>>,
    steppers: Vec<LaneStepper>,
    results: Vec<Option<Result<SystemSolution>>>,
    lanes: LaneRuns,
    modes: LaneModes,
    /// Each wall's contact per lane (1 in contact).
    open: [V; MAX_WALLS],
    /// Whether the lanes take lane `l`'s steps (its modes are theirs).
    fed: [bool; LANES],
    /// Whether the lanes' reductions' rates at the end of lane `l`'s last
    /// step are those at its state now, made with its force `end_values`
    /// (the last stage's).
    end_rates: [bool; LANES],
    end_values: V,
    /// Plain steps each lane took since its run was last brought up to date.
    pending: [u64; LANES],
    /// The grid point before which each run's steps are plain by its
    /// schedule, as last found ([`Self::plain_window`]; 0 not known), and
    /// the least of them over the runs in progress (0 not known).
    plain_until: [u64; LANES],
    rows_until: u64,
    /// A run's schedule: the group's recorded window.
    window: Option<Schedule>,
    /// Each run's most accepted steps before its step limit.
    max_accepted: [u64; LANES],
    /// Each run's force cache (its stages', which a fixed step's
    /// reductions take their values from; the run's while the lanes step
    /// it, see [`Self::store`]).
    stage_caches: LaneCaches,
    step: LaneStep,
    end_gaps: LaneGaps,
    dt: f64,
}

impl<'a> Lockstep<'a> {
    fn new(members: &[(&'a Assembly, &Vec<f64>)], options: &'a RunOptions, vector: bool) -> Self {
        let count = members.len();
        let mut me = Self {
            vector,
            mean_square: options.reduce.mean_square,
            systems: members.iter().map(|(s, _)| *s).collect(),
            runs: Vec::with_capacity(count),
            steppers: members.iter().map(|(s, _)| LaneStepper::new(s)).collect(),
            results: vec![None; count],
            lanes: LaneRuns::default(),
            modes: LaneModes::default(),
            open: [[0.0; LANES]; MAX_WALLS],
            fed: [false; LANES],
            end_rates: [false; LANES],
            end_values: [0.0; LANES],
            pending: [0; LANES],
            plain_until: [0; LANES],
            rows_until: 0,
            window: None,
            max_accepted: [0; LANES],
            stage_caches: LaneCaches::default(),
            step: LaneStep::default(),
            end_gaps: [[[0.0; LANES]; 2]; MAX_WALLS],
            dt: options.dt.unwrap_or(f64::NAN),
        };
        for (l, (system, initial)) in members.iter().enumerate() {
            let run = FixedRun::new(
                system,
                &mut me.steppers[l],
                initial,
                options,
                ContactTiming::Located,
            );
            match run {
                Ok(run) => {
                    me.window = Some(run.run.schedule);
                    me.max_accepted[l] = options
                        .max_steps
                        .saturating_sub(run.run.control.rejected + 1);
                    me.runs.push(Some(run));
                    me.load(l);
                }
                Err(e) => {
                    me.results[l] = Some(Err(e));
                    me.runs.push(None);
                }
            }
        }
        me
    }

    fn run<L: LaneLaw>(
        mut self,
        group: Option<&Group<L>>,
        interrupt: &(dyn Fn() -> bool + Sync),
    ) -> Result<Vec<Result<SystemSolution>>> {
        // Every run is on the grid's `grid`-th point: a fixed step, plain
        // or the kernel's, is one grid step and one accepted step.
        let mut grid = 0u64;
        while self.runs.iter().any(Option::is_some) {
            let time = grid as f64 * self.dt;
            match group.and_then(|g| Some((g, self.plain_window(grid)?))) {
                Some((group, in_window)) => self.plain_steps(group, grid, in_window),
                None => {
                    if let Some(group) = group {
                        self.attempt(group, time);
                    }
                    for l in 0..self.runs.len() {
                        self.kernel_step(l);
                    }
                }
            }
            grid += 1;
            if grid % POLL_INTERVAL == 0 && interrupt() {
                return Err(Error::Interrupted { time });
            }
        }
        Ok(self
            .results
            .into_iter()
            .map(|r| r.expect("every run ended"))
            .collect())
    }

    /// Whether every run's next step from grid point `grid` may be plain
    /// (the kernel's rule, after its first step, within the step limit),
    /// and if so whether it is in the recorded window. Each run's row of
    /// such steps is found once ([`Schedule::plain_fixed_run`], the rule
    /// asked of each step's clock as its plain steps leave it) and counted
    /// down, not asked again each step: only the run's own step changes
    /// its clock otherwise ([`Self::kernel_step`] forgets the rows).
    fn plain_window(&mut self, grid: u64) -> Option<bool> {
        if grid == 0 {
            return None;
        }
        if grid >= self.rows_until {
            self.rows_until = self.rows(grid)?;
        }
        // Every run's window is the group's options' (one schedule's rule).
        let schedule = self.window.as_ref()?;
        Some(schedule.in_window(grid as f64 * self.dt, schedule.dt))
    }

    /// The grid point before which every run's steps from `grid` are plain
    /// by its schedule (each run's row found where not known), None where
    /// one's next step is not.
    fn rows(&mut self, grid: u64) -> Option<u64> {
        let mut until = u64::MAX;
        for (l, run) in self.runs.iter().enumerate() {
            let Some(run) = run else { continue };
            if !self.fed[l] || grid >= self.max_accepted[l] {
                return None;
            }
            let run = &run.run;
            if grid >= self.plain_until[l] {
                let mut clock = run.clock;
                clock.until_kept = clock.until_kept.saturating_sub(self.pending[l]);
                (clock.grid, clock.accepted) = (grid, grid);
                clock.time = grid as f64 * self.dt;
                let most = self.max_accepted[l] - grid;
                let row = run.schedule.plain_fixed_run(&clock, most, true);
                self.plain_until[l] = grid + row;
                if row == 0 {
                    return None;
                }
            }
            until = until.min(self.plain_until[l]);
        }
        Some(until)
    }

    /// Each run's force at the stages of the step from `time` (through its
    /// own cache, in the stages' order), and the lanes' attempt of that
    /// step, which a run taking the step itself is given.
    fn attempt<L: LaneLaw>(&mut self, group: &Group<L>, time: f64) {
        group.latch(&mut self.modes);
        let values = self.stage_values(group, time, &self.live());
        group.step(&self.lanes.y, self.dt, &self.modes, &values, &mut self.step);
        for (l, stepper) in self.steppers.iter_mut().enumerate() {
            if self.fed[l] && self.runs[l].is_some() {
                stepper.stash(time, self.dt, &self.step, l);
            }
        }
    }

    /// The lanes with a run in progress.
    fn live(&self) -> [bool; LANES] {
        let mut live = [false; LANES];
        for (l, run) in self.runs.iter().enumerate() {
            live[l] = run.is_some();
        }
        live
    }

    /// Each run's force at the stages of the step from `time` through its
    /// stages' cache, in the stages' order (0 where the lanes are not forced).
    fn stage_values<L: LaneLaw>(
        &mut self,
        group: &Group<L>,
        time: f64,
        live: &[bool; LANES],
    ) -> [V; 4] {
        let mut values = [[0.0; LANES]; 4];
        if let Some((signals, harmonics)) = group.signals() {
            for (value, t) in values.iter_mut().zip(stage_times(time, self.dt)) {
                *value = self.stage_caches.values(signals, harmonics, live, t);
            }
        }
        values
    }

    /// A step from grid point `grid` of every lane: plain for the lanes
    /// whose step is, the kernel's for the others.
    fn plain_steps<L: LaneLaw>(&mut self, group: &Group<L>, grid: u64, in_window: bool) {
        let (dt, time) = (self.dt, grid as f64 * self.dt);
        let next = (grid + 1) as f64 * dt;
        let live = self.live();
        group.latch(&mut self.modes);
        let values = self.stage_values(group, time, &live);
        let summed = in_window && self.mean_square;
        // The first stage is the reductions' rates at the last step's end
        // where every lane's state and force are that end's (the force's
        // value at a grid point is one, [`same_instant`]).
        let mut first_kept = true;
        for l in 0..LANES {
            let same = values[0][l].to_bits() == self.end_values[l].to_bits();
            first_kept &= !live[l] | (self.end_rates[l] & same);
        }
        let step = PlainStep {
            first_kept,
            summed,
            h: dt,
            modes: &self.modes,
            open: &self.open,
            live,
            in_window,
            values: &values,
        };
        let plain = group.plain_step(&step, &mut self.lanes, &mut self.step, &mut self.end_gaps);
        for l in 0..LANES {
            self.end_rates[l] = summed & plain[l];
        }
        self.end_values = values[3];
        self.go_on(&plain);
        group.advance(&plain, &self.step.end, &self.end_gaps, &mut self.lanes);
        for l in 0..self.runs.len() {
            if plain[l] {
                self.pending[l] += 1;
                self.balance(l, grid + 1, next);
            } else if live[l] {
                self.steppers[l].stash(time, dt, &self.step, l);
                self.kernel_step(l);
            }
        }
    }

    /// The contacts that go on through the plain steps of the lanes in
    /// `plain`: their deepest indentation and dissipation, as the kernel's
    /// fixed step sums them.
    fn go_on(&mut self, plain: &[bool; LANES]) {
        let dt = self.dt;
        let located = true;
        let mut plain_lanes = 0u32;
        for l in 0..LANES {
            plain_lanes |= u32::from(plain[l]) << l;
        }
        for w in 0..MAX_WALLS {
            for l in each_lane(lanes_where(&self.open[w]) & plain_lanes) {
                let Some(run) = self.runs.get_mut(l).and_then(Option::as_mut) else {
                    continue;
                };
                let Some(Some(oc)) = run.run.open.get_mut(w) else {
                    continue;
                };
                let start = (self.lanes.gaps[w][0][l], self.lanes.gaps[w][1][l]);
                let end = (self.end_gaps[w][0][l], self.end_gaps[w][1][l]);
                fixed::deepest(oc, fixed::indentation_data(start, end, dt), located);
                // `fixed::press`, with the power the lanes made.
                fixed::pressed(oc, self.step.power[w][l], dt);
            }
        }
    }

    /// The energy balance after lane `l`'s plain `accepted`-th step, ending
    /// at `time`, where it is due (the kernel's cadence); a failure ends
    /// the run.
    fn balance(&mut self, l: usize, accepted: u64, time: f64) {
        let Some(run) = self.runs[l].as_mut() else {
            return;
        };
        let run = &mut run.run;
        let Some(check) = run.energy.due(accepted, false, time) else {
            return;
        };
        let len = run.y.len().min(MAX_LEN);
        for e in 0..len {
            run.y[e] = self.lanes.y[e][l];
        }
        let system = self.systems[l];
        if let Err(e) = run
            .energy
            .balance(system, (&run.y, &run.modes), check, time)
        {
            self.runs[l] = None;
            self.results[l] = Some(Err(e));
        }
    }

    /// Run `l`'s next step taken by the run itself (and what follows it),
    /// brought up to date with the lanes before and read back after.
    fn kernel_step(&mut self, l: usize) {
        if self.runs[l].is_none() {
            return;
        }
        self.store(l);
        (self.plain_until[l], self.rows_until) = (0, 0);
        let (Some(run), stepper) = (self.runs[l].as_mut(), &mut self.steppers[l]) else {
            return;
        };
        let next = run.step(stepper, &mut || false);
        stepper.taken();
        match next {
            Ok(true) => self.load(l),
            Ok(false) => {
                let run = self.runs[l].take().expect("a run in progress");
                self.results[l] = Some(Ok(run.finish(&self.steppers[l])));
            }
            Err(e) => {
                self.runs[l] = None;
                self.results[l] = Some(Err(e));
            }
        }
    }

    /// Run `l` brought up to date: the lanes' state, gaps and reductions,
    /// and its clock, step count and evaluations past its plain steps.
    fn store(&mut self, l: usize) {
        let (true, Some(run)) = (self.vector, self.runs[l].as_mut()) else {
            return;
        };
        let run = &mut run.run;
        let len = run.y.len().min(MAX_LEN);
        for e in 0..len {
            run.y[e] = self.lanes.y[e][l];
        }
        for (w, gap) in run.gaps.start.iter_mut().enumerate().take(MAX_WALLS) {
            *gap = (self.lanes.gaps[w][0][l], self.lanes.gaps[w][1][l]);
        }
        let reductions = &mut run.reductions;
        for (j, peak) in reductions.peaks.iter_mut().enumerate() {
            *peak = self.lanes.peaks[j][l];
        }
        for (j, square) in reductions.square_integrals.iter_mut().enumerate() {
            *square = self.lanes.squares[j][l];
        }
        reductions.recorded_time = self.lanes.recorded[l];
        if let Some(cache) = run.scratch.first_cache() {
            *cache = self.stage_caches.get(l);
        }
        let pending = std::mem::take(&mut self.pending[l]);
        if pending > 0 {
            let clock = &mut run.clock;
            clock.grid += pending;
            clock.accepted += pending;
            clock.until_kept = clock.until_kept.saturating_sub(pending);
            clock.time = clock.grid as f64 * self.dt;
            run.stalled = 0;
            self.steppers[l].plain_steps(pending);
        }
    }

    /// The lanes' copy of run `l` (after its own step).
    fn load(&mut self, l: usize) {
        let (true, Some(run)) = (self.vector, self.runs[l].as_mut()) else {
            return;
        };
        let run = &mut run.run;
        if let Some(cache) = run.scratch.first_cache() {
            self.stage_caches.set(l, cache);
        }
        for (e, v) in run.y.iter().enumerate().take(MAX_LEN) {
            self.lanes.y[e][l] = *v;
        }
        for (w, (gap, rate)) in run.gaps.start.iter().enumerate().take(MAX_WALLS) {
            (self.lanes.gaps[w][0][l], self.lanes.gaps[w][1][l]) = (*gap, *rate);
        }
        let reductions = &run.reductions;
        for (j, peak) in reductions.peaks.iter().enumerate() {
            self.lanes.peaks[j][l] = *peak;
        }
        for (j, square) in reductions.square_integrals.iter().enumerate() {
            self.lanes.squares[j][l] = *square;
        }
        self.lanes.recorded[l] = reductions.recorded_time;
        self.fed[l] = self.modes.set(l, &run.modes);
        self.end_rates[l] = false;
        for (w, oc) in run.open.iter().enumerate().take(MAX_WALLS) {
            self.open[w][l] = if oc.is_some() { 1.0 } else { 0.0 };
        }
    }
}
