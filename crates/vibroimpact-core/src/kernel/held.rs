//! The held interactions' dips within a step (a sticking pair's constraint
//! force, a stuck friction element's static force less its holding force,
//! past the limit and back between the step's ends), found from the forces'
//! cubic interpolant as a gap's dip is, for
//! [`crate::kernel::locate::find_crossing`] (which checks the step's end).

use crate::model::assembly::{Assembly, Mode, Scratch};
use crate::numerics::hermite;

/// What the held interactions' rates are found with: a state a little along
/// its rates, the rates, a work space of their own (the run's caches its
/// signals' last values: evaluations at other times would change the bits of
/// its next ones), and each interaction's holding force at the step's end,
/// a little after it, at its start and a little after that (`4 count`, N),
/// made once a step for all of them, where first needed.
pub(super) struct Probe<'a> {
    pub(super) shifted: &'a mut [f64],
    pub(super) rates: &'a mut [f64],
    pub(super) scratch: &'a mut Scratch,
    pub(super) forces: &'a mut [f64],
}

impl Probe<'_> {
    /// The holding forces at `(time, y)` and `delta` later along the state's
    /// rates, into `forces[at..at + 2 count]`.
    fn forces_at(
        &mut self,
        system: &Assembly,
        modes: &[Mode],
        (time, y): (f64, &[f64]),
        at: usize,
        delta: f64,
    ) {
        system.rates(time, y, modes, self.scratch, self.rates);
        holding_forces(self.scratch, &mut self.forces[at..at + modes.len()]);
        self.forces_later(system, modes, (time, y), at, delta);
    }

    /// The holding forces `delta` after `(time, y)` along the state's rates
    /// (in `rates`), into `forces[at + count..at + 2 count]`.
    fn forces_later(
        &mut self,
        system: &Assembly,
        modes: &[Mode],
        (time, y): (f64, &[f64]),
        at: usize,
        delta: f64,
    ) {
        let count = modes.len();
        let row = 2 * system.dim;
        for ((s, v), r) in self.shifted[..row]
            .iter_mut()
            .zip(&y[..row])
            .zip(&self.rates[..row])
        {
            *s = v + delta * r;
        }
        self.shifted[row..].copy_from_slice(&y[row..]);
        system.rates(time + delta, self.shifted, modes, self.scratch, self.rates);
        holding_forces(self.scratch, &mut self.forces[at + count..at + 2 * count]);
    }

    /// The forces at the step's end (`forces[..2 count]`): at the end, those
    /// of the run's own evaluation there (`scratch`, its rates in `rates`),
    /// which the end's values were found with.
    fn forces_at_end(
        &mut self,
        (system, modes): (&Assembly, &[Mode]),
        end: (f64, &[f64]),
        (scratch, rates): (&Scratch, &[f64]),
        delta: f64,
    ) {
        let count = modes.len();
        holding_forces(scratch, &mut self.forces[..count]);
        self.rates.copy_from_slice(rates);
        self.forces_later(system, modes, end, 0, delta);
    }
}

/// A step's start and end states.
type Ends<'a> = (&'a [f64], &'a [f64]);

/// The held interactions' crossings in a step: the holding forces their
/// values are made of, found once for all of them.
pub(super) struct Held<'p> {
    pub(super) probe: Probe<'p>,
    /// Whether the forces at the step's end and at its start are found.
    pub(super) end: bool,
    pub(super) start: bool,
}

impl Held<'_> {
    /// Where interaction `i`, held in `mode` with the value `v1` (>= 0) at
    /// the end of the step `start -> end` of length `h` from `time` (found
    /// with the run's `scratch`, its rates there in `work`), dips past its
    /// limit and back within the step: the force's cubic Hermite interpolant
    /// (from its values and rates at the ends) taken as a gap's is (a force
    /// that peaks past the static force between two steps' ends is a slip,
    /// not a stuck interval). The interpolant's lowest point and its first
    /// root, as fractions of the step.
    pub(super) fn dip(
        &mut self,
        (system, modes): (&Assembly, &[Mode]),
        (i, mode, v1): (usize, Mode, f64),
        ((time, h), (start, end)): ((f64, f64), Ends<'_>),
        (scratch, work): (&Scratch, &[f64]),
    ) -> Option<(f64, f64)> {
        let count = modes.len();
        // The difference step: a millionth of the step (the force is affine in
        // the state for a linear system, so the difference is its derivative
        // but for the forcing's curvature and round-off).
        let delta = 1e-6 * h;
        if !std::mem::replace(&mut self.end, true) {
            self.probe
                .forces_at_end((system, modes), (time + h, end), (scratch, work), delta);
        }
        let value = |f: f64| held_value(system, i, mode, f);
        let forces = &self.probe.forces;
        let r1 = (value(forces[count + i]) - value(forces[i])) / delta;
        // A dip needs the value rising at the end and falling at the start
        // (NaN, a force not finite, is no dip).
        if r1.is_nan() || r1 <= 0.0 {
            return None;
        }
        if !std::mem::replace(&mut self.start, true) {
            self.probe
                .forces_at(system, modes, (time, start), 2 * count, delta);
        }
        let forces = &self.probe.forces;
        let v0 = value(forces[2 * count + i]);
        let r0 = (value(forces[3 * count + i]) - v0) / delta;
        if v0.is_nan() || v0 <= 0.0 || r0.is_nan() || r0 >= 0.0 {
            return None;
        }
        let (m0, m1) = (r0 * h, r1 * h);
        let theta = hermite::peak(-v0, -v1, -m0, -m1);
        let low = hermite::eval(v0, v1, m0, m1, theta).0;
        // As a gap's dip: one the interpolant takes down to half of the
        // ends' lower value is checked on the method's own solution.
        (low < 0.5 * v0.min(v1)).then(|| (theta, hermite::root_within(v0, v1, m0, m1, 0.0, theta)))
    }
}

/// Each interaction's holding force (N; 0 where it is not held) as the
/// last evaluation of the rates with `scratch` found them, into `out`.
fn holding_forces(scratch: &Scratch, out: &mut [f64]) {
    for (i, f) in out.iter_mut().enumerate() {
        *f = scratch.force_of(i).unwrap_or(0.0);
    }
}

/// The event value of interaction `i`, held in `mode` (sticking or stuck),
/// whose holding force is `force` (N): a stuck element's static force left,
/// a sticking pair's force with its row's friction added.
pub(super) fn held_value(system: &Assembly, i: usize, mode: Mode, force: f64) -> f64 {
    match mode {
        Mode::Stuck { .. } => system.static_force(i) - force.abs(),
        _ => force + system.friction_hold[i],
    }
}
