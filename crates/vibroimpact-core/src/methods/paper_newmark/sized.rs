//! The founding paper's Newmark in fixed-size arrays: its plain fixed steps
//! (`stepping = "fixed"`) on a system the compact path takes
//! ([`crate::kernel::compact`]: a few modes, dampers and walls, diagonal
//! matrices), with no heap slice or runtime length in the inner loop. A
//! declared specialisation of [`PaperNewmark`]'s step, not a method of its
//! own: the same operations in the same order (the same bits; a test holds
//! them to it), and the kernel's stop rules and records, as
//! [`crate::kernel::plain_fixed`] takes them, which serves every other
//! system. Stepping by events, its plain steps between events ([`events`]).
//!
//! Besides the sizes, it saves evaluations of the contact law that give
//! the same values: a step's lagged force is the last step's end force
//! (the same state and modes), and a contact's dissipated power at the
//! step's end ([`fixed::press`]) is its accumulator's rate there, where its
//! indentation and rate are the same numbers.

// Indexed loops over the fixed-size arrays, and copies written as loops:
// what compiles to tight code here (as in the compact path).
#![allow(clippy::needless_range_loop, clippy::manual_memcpy)]

use super::PaperNewmark;
use crate::kernel::compact::{
    peak_inside, widen_peaks, Stretch, MAX_DIM, MAX_LEN, MAX_MODES, MAX_WALLS,
};
use crate::kernel::events::ContactTiming;
use crate::kernel::fixed;
use crate::kernel::plain_fixed::stretch_timing;
use crate::kernel::sized::by_size;
use crate::model::assembly::{h_dot, Assembly, Mode, Scratch, CONTACT, INPUT, VISCOUS};
use crate::model::contact::{AnyLaw, ContactLaw};
use crate::numerics::linalg;

mod events;

/// The most harmonic loads held (a `harmonics` signal's terms).
const MAX_LOADS: usize = 4;
/// The accumulators' count at most: the powers and each wall's.
const MAX_RATES: usize = CONTACT + MAX_WALLS;

/// A compliant wall: its row, offset, law and contact damper (N s/m).
#[derive(Debug, Clone, Copy)]
struct Wall {
    h: [f64; MAX_DIM],
    offset: f64,
    law: AnyLaw,
    damping: f64,
    /// Whether `h` is the previous wall's negated (a damper's second wall).
    mirror: bool,
}

impl Wall {
    /// The indentation (m) and its rate (m/s) at `(x, v)`, as
    /// [`PaperNewmark`] takes them.
    #[inline(always)]
    fn indentation(&self, d: usize, x: &[f64], v: &[f64]) -> (f64, f64) {
        let h = &self.h[..d];
        (-(self.offset + h_dot(h, &x[..d])), -h_dot(h, &v[..d]))
    }
}

/// A harmonic load: amplitude (N), rad/s, phase and shape over the
/// coordinates.
#[derive(Debug, Clone, Copy)]
struct Load {
    amplitude: f64,
    omega: f64,
    phase: f64,
    shape: [f64; MAX_DIM],
}

/// [`PaperNewmark`]'s data in fixed-size arrays (see the module's text).
#[derive(Debug, Clone)]
pub(super) struct Sized {
    /// The structure's `C` and `K` (its `n x n` block) and `C`'s diagonal.
    damping: [[f64; MAX_MODES]; MAX_MODES],
    stiffness: [[f64; MAX_MODES]; MAX_MODES],
    viscous: [f64; MAX_MODES],
    constant: [f64; MAX_DIM],
    loads: [Load; MAX_LOADS],
    load_count: usize,
    walls: [Wall; MAX_WALLS],
    wall_count: usize,
    /// The accumulators' count.
    rate_count: usize,
}

impl Sized {
    /// `method`'s data for `system` where the compact path takes it (and
    /// its matrices are diagonal, its loads few), else None.
    pub(super) fn of(method: &PaperNewmark, system: &Assembly) -> Option<Self> {
        let (n, d) = (method.n, method.dim);
        let walls = system.interactions.len();
        if system.compact.is_none()
            || method.per_mass.is_none()
            || n > MAX_MODES
            || d > MAX_DIM
            || walls > MAX_WALLS
            || method.harmonics.len() > MAX_LOADS
            || method.compliant.len() != walls
            || system.state_len() > MAX_LEN
        {
            return None;
        }
        let mut sized = Self {
            damping: [[0.0; MAX_MODES]; MAX_MODES],
            stiffness: [[0.0; MAX_MODES]; MAX_MODES],
            viscous: [0.0; MAX_MODES],
            constant: [0.0; MAX_DIM],
            loads: [Load {
                amplitude: 0.0,
                omega: 0.0,
                phase: 0.0,
                shape: [0.0; MAX_DIM],
            }; MAX_LOADS],
            load_count: method.harmonics.len(),
            walls: [Wall {
                h: [0.0; MAX_DIM],
                offset: 0.0,
                law: method.compliant.first()?.law,
                damping: 0.0,
                mirror: false,
            }; MAX_WALLS],
            wall_count: walls,
            rate_count: system.state_len() - 2 * d,
        };
        for i in 0..n {
            for j in 0..n {
                sized.damping[i][j] = method.damping[i * d + j];
                sized.stiffness[i][j] = method.stiffness[i * d + j];
            }
            sized.viscous[i] = method.damping[i * d + i];
        }
        sized.constant[..d].copy_from_slice(&method.constant[..d]);
        for (load, harmonic) in sized.loads.iter_mut().zip(&method.harmonics) {
            load.amplitude = harmonic.amplitude;
            load.omega = harmonic.omega;
            load.phase = harmonic.phase;
            load.shape[..d].copy_from_slice(&harmonic.shape[..d]);
        }
        let mirrors = system.compact_parts()?.mirrors;
        for (w, c) in method.compliant.iter().enumerate() {
            // Every interaction is compliant: the entries are in order.
            if c.index != w {
                return None;
            }
            let it = &system.interactions[w];
            let wall = &mut sized.walls[w];
            wall.h[..d].copy_from_slice(&it.h[..d]);
            wall.offset = it.offset;
            wall.law = c.law;
            wall.damping = c.damping;
            wall.mirror = mirrors[w];
        }
        Some(sized)
    }

    /// Every wall's gap and rate at `y`, as [`Assembly::gaps`] sums them.
    #[inline(always)]
    fn gaps(&self, d: usize, y: &[f64; MAX_LEN], out: &mut [(f64, f64); MAX_WALLS]) {
        let mut products = (0.0, 0.0);
        for w in 0..self.wall_count.min(MAX_WALLS) {
            let wall = &self.walls[w];
            products = if wall.mirror {
                (-products.0, -products.1)
            } else {
                let (mut hx, mut hv) = (-0.0, -0.0);
                for i in 0..d {
                    hx += wall.h[i] * y[i];
                    hv += wall.h[i] * y[d + i];
                }
                (hx, hv)
            };
            out[w] = (wall.offset + products.0, products.1);
        }
    }

    /// Whether a wall's gap at `y` is below zero (the displacements alone,
    /// as [`Self::gaps`] sums them; a mirrored product differs from its own
    /// at most in the sign of a zero, which the test does not see).
    #[inline(always)]
    fn indented(&self, d: usize, y: &[f64; MAX_LEN]) -> bool {
        let mut indented = false;
        for w in 0..self.wall_count.min(MAX_WALLS) {
            let wall = &self.walls[w];
            let mut hx = -0.0;
            for i in 0..d {
                hx += wall.h[i] * y[i];
            }
            indented |= wall.offset + hx < 0.0;
        }
        indented
    }
}

/// What a step carries to the next: the accelerations, the accumulators'
/// rates, and each wall's lagged law force where its contact acts and it
/// is indented (`lagged`).
#[derive(Clone, Copy)]
struct Carried {
    accel: [f64; MAX_DIM],
    rates: [f64; MAX_RATES],
    lag: [f64; MAX_WALLS],
    lagged: [bool; MAX_WALLS],
}

impl PaperNewmark {
    /// [`Self::sized_steps`] for the system's sizes (constants in each arm).
    #[inline(never)]
    pub(super) fn sized_stretch<const FREE: bool>(
        &mut self,
        system: &Assembly,
        sized: &Sized,
        f: &mut Stretch<'_>,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        by_size!(system, |n, k| self.sized_steps::<FREE>(
            system,
            sized,
            (n, n + k),
            f,
            modes,
            scratch
        ))
    }

    /// Plain fixed steps from the kernel's state lent in `f`, as
    /// [`crate::kernel::plain_fixed::plain_fixed_steps`] takes them through
    /// [`Self::attempt`], for `n` structure coordinates of `d` (constants
    /// where [`crate::kernel::sized::by_size`] makes them). `FREE`: every
    /// wall open and out of contact, their terms left out at compile time
    /// (they add nothing then).
    #[inline(always)]
    fn sized_steps<const FREE: bool>(
        &mut self,
        system: &Assembly,
        sized: &Sized,
        (n, d): (usize, usize),
        f: &mut Stretch<'_>,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        let Some(timing) = stretch_timing(f, scratch) else {
            return;
        };
        let schedule = *f.schedule;
        let mut clock = *f.clock;
        if clock.accepted >= f.max_accepted {
            f.limited = true;
            return;
        }
        if schedule.plain_fixed_step(&clock).is_none() {
            return;
        }
        // The attempt's preparation, which only the first step may need
        // (the only one to touch the cache), and the inverse for the modes.
        let first_cache = scratch.first_cache().copied();
        self.prepare(system, clock.time, f.y, modes, scratch);
        let (dt, located) = (schedule.dt, timing == ContactTiming::Located);
        let (len, count, observed) = (f.y.len().min(MAX_LEN), sized.wall_count, system.observed());
        let count = count.min(MAX_WALLS);
        let rate_count = sized.rate_count.min(MAX_RATES);
        let modes = &modes[..count];
        let mut y = [0.0; MAX_LEN];
        y[..len].copy_from_slice(&f.y[..len]);
        let mut start_gaps = [(0.0, 0.0); MAX_WALLS];
        start_gaps[..count].copy_from_slice(&f.gaps[..count]);
        let (inverse, first) = self.sized_start::<FREE>(system, sized, (d, dt), &y, modes);
        // Two buffers the steps alternate between (the step's start's and
        // its end's), swapped where one is accepted: no copy per step.
        let (mut start_buffer, mut end_buffer) = (first, first);
        let (mut carried, mut next_carried) = (&mut start_buffer, &mut end_buffer);
        let (mut energy, mut end_gaps) = (*f.energy, [(0.0, 0.0); MAX_WALLS]);
        // Free, the walls' accumulators change in the first step alone, as
        // the step sums them (their rates are +0 at its end, and each later
        // step adds +0 to a sum that is not -0): left out of the steps.
        let mut first_walls = [0.0; MAX_RATES];
        for k in if FREE { CONTACT } else { MAX_RATES }..MAX_RATES {
            first_walls[k] = y[2 * d + k] + 0.5 * dt * (carried.rates[k] + 0.0);
        }
        // The stop rules asked once for the steps they allow in a row (the
        // most the stretch may take: it is then limited, if all were plain),
        // as the compact path's fixed stretch asks them.
        let most = f.max_accepted.saturating_sub(clock.accepted);
        let allowed = schedule.plain_fixed_run(&clock, most, false);
        f.limited = allowed == most;
        while f.steps < allowed {
            debug_assert!(schedule.plain_fixed_step(&clock).is_some());
            let time = clock.time;
            let next = (clock.grid + 1) as f64 * dt;
            let in_window = schedule.in_window(time, dt);
            let mut end = [0.0; MAX_LEN];
            let mut step = Step {
                end: [0.0; 2 * MAX_DIM],
                accumulators: [0.0; MAX_RATES],
                contact: [(0.0, 0.0); MAX_WALLS],
            };
            let steps = (&*carried, &mut *next_carried, &mut step);
            self.sized_step::<FREE>(sized, (n, d), (time, dt), (&y, &inverse), steps, modes);
            for i in 0..d {
                end[i] = step.end[i];
                end[d + i] = step.end[MAX_DIM + i];
            }
            let mut plain = end[..2 * d].iter().fold(0.0, |sum, v| sum + v * 0.0) == 0.0;
            if FREE {
                // No contact: none may begin (the gaps themselves are
                // needed only where the stretch ends).
                plain &= !sized.indented(d, &end);
            } else {
                sized.gaps(d, &end, &mut end_gaps);
                for w in 0..count {
                    // Indented at the end exactly where in contact: no onset
                    // or separation in the step.
                    plain &= (end_gaps[w].0 < 0.0) == f.open[w].is_some();
                }
            }
            if in_window && peak_inside(system, observed, (&y[..], &end[..]), d, n) {
                plain = false;
            }
            if !plain {
                if let (0, Some(saved), Some(cache)) = (f.steps, first_cache, scratch.first_cache())
                {
                    *cache = saved;
                }
                f.limited = false;
                break;
            }
            for w in 0..if FREE { 0 } else { count } {
                if let Some(oc) = f.open[w].as_mut() {
                    let ends = fixed::indentation_data(start_gaps[w], end_gaps[w], dt);
                    fixed::deepest(oc, ends, located);
                    // The power press takes, where its numbers are the
                    // accumulator's.
                    match sized.pressed_power(w, d, &end, modes[w], (&step, &*next_carried)) {
                        Some(power) => fixed::pressed(oc, power, dt),
                        None => {
                            let at = end;
                            fixed::press(system, w, oc, &at[..len], modes[w], dt)
                        }
                    }
                }
            }
            if in_window {
                let kept = observed.min(f.peaks.len());
                widen_peaks(system, &mut f.peaks[..kept], (&y[..], &end[..]), n);
                *f.recorded_time += dt;
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
                f.limited = false;
                break;
            }
        }
        if FREE && f.steps > 0 {
            sized.gaps(d, &y, &mut start_gaps);
        }
        self.evaluations += f.steps;
        self.accel[..d].copy_from_slice(&carried.accel[..d]);
        self.powers.start_rates()[..rate_count].copy_from_slice(&carried.rates[..rate_count]);
        *f.energy = energy;
        *f.clock = clock;
        f.y[..len].copy_from_slice(&y[..len]);
        f.gaps[..count].copy_from_slice(&start_gaps[..count]);
    }

    /// The inverse effective matrix for steps `dt` in `modes` and what the
    /// first step from `y` takes ([`Self::sized_steps`]).
    #[inline(always)]
    fn sized_start<const FREE: bool>(
        &mut self,
        system: &Assembly,
        sized: &Sized,
        (d, dt): (usize, f64),
        y: &[f64; MAX_LEN],
        modes: &[Mode],
    ) -> ([[f64; MAX_DIM]; MAX_DIM], Carried) {
        let any = self.contacts_of(modes);
        let inverse = self.sized_inverse(system, (d, dt), any);
        (inverse, self.sized_carried::<FREE>(sized, d, y, modes))
    }

    /// The inverse effective matrix for steps `h` with the contacts of
    /// [`Self::contacts_of`] (`any`: whether there are any), as the kernel's
    /// attempt takes it ([`Self::effective`]), in an array.
    #[inline(always)]
    fn sized_inverse(
        &mut self,
        system: &Assembly,
        (d, h): (usize, f64),
        any: bool,
    ) -> [[f64; MAX_DIM]; MAX_DIM] {
        self.effective(system, h, any);
        let kept = if any { &self.touching } else { &self.apart };
        let mut inverse = [[0.0; MAX_DIM]; MAX_DIM];
        for i in 0..d {
            inverse[i][..d].copy_from_slice(&kept.inverse[i * d..(i + 1) * d]);
        }
        inverse
    }

    /// What the first step from `y` in `modes` takes: the method's
    /// accelerations and rates, and the walls' lagged forces there.
    #[inline(always)]
    fn sized_carried<const FREE: bool>(
        &mut self,
        sized: &Sized,
        d: usize,
        y: &[f64; MAX_LEN],
        modes: &[Mode],
    ) -> Carried {
        let rate_count = sized.rate_count.min(MAX_RATES);
        let mut carried = Carried {
            accel: [0.0; MAX_DIM],
            rates: [0.0; MAX_RATES],
            lag: [0.0; MAX_WALLS],
            lagged: [false; MAX_WALLS],
        };
        carried.accel[..d].copy_from_slice(&self.accel[..d]);
        carried.rates[..rate_count].copy_from_slice(&self.powers.start_rates()[..rate_count]);
        for w in 0..if FREE { 0 } else { modes.len().min(MAX_WALLS) } {
            if let Mode::Compliant { approach_rate, .. } = modes[w] {
                let wall = &sized.walls[w];
                let (indentation, rate) = wall.indentation(d, &y[..d], &y[d..2 * d]);
                if indentation > 0.0 {
                    carried.lag[w] = wall.law.force(indentation, rate, approach_rate);
                    carried.lagged[w] = true;
                }
            }
        }
        carried
    }

    /// [`Self::step_sized`] and [`Self::end_powers`] in the arrays: the step
    /// `h` from `(time, y)` with the inverse effective matrix of the modes,
    /// from what the start `carried` and into `step` and what its end
    /// carries (`next`: every value the next step reads written).
    #[inline(always)]
    fn sized_step<const FREE: bool>(
        &self,
        sized: &Sized,
        (n, d): (usize, usize),
        (time, h): (f64, f64),
        (y, inverse): (&[f64; MAX_LEN], &[[f64; MAX_DIM]; MAX_DIM]),
        (carried, next, step): (&Carried, &mut Carried, &mut Step),
        modes: &[Mode],
    ) {
        let (beta, gamma) = (self.beta, self.gamma);
        let (db, dg) = ((0.5 - beta) * h * h, (1.0 - gamma) * h);
        let (mut xp, mut vp) = ([0.0; MAX_DIM], [0.0; MAX_DIM]);
        for i in 0..d {
            let a = carried.accel[i];
            xp[i] = y[i] + h * y[d + i] + db * a;
            vp[i] = y[d + i] + dg * a;
        }
        let mut residual = [0.0; MAX_DIM];
        let mut values = [0.0; MAX_LOADS];
        let loads = &sized.loads[..sized.load_count.min(MAX_LOADS)];
        if self.forced {
            for i in 0..d {
                residual[i] += sized.constant[i];
            }
            for (l, load) in loads.iter().enumerate() {
                let value = load.amplitude * (load.omega * (time + h) + load.phase).cos();
                values[l] = value;
                for i in 0..d {
                    residual[i] += value * load.shape[i];
                }
            }
        }
        let count = if FREE { 0 } else { modes.len() };
        for w in 0..count {
            if carried.lagged[w] {
                let (row, law) = (&sized.walls[w].h, carried.lag[w]);
                for i in 0..d {
                    if row[i] != 0.0 {
                        residual[i] += row[i] * law;
                    }
                }
            }
        }
        for i in 0..n {
            for j in 0..n {
                residual[i] -= sized.damping[i][j] * vp[j];
            }
            for j in 0..n {
                residual[i] -= sized.stiffness[i][j] * xp[j];
            }
        }
        for w in 0..count {
            if matches!(modes[w], Mode::Compliant { .. }) {
                let wall = &sized.walls[w];
                let (_, rate) = wall.indentation(d, &xp, &vp);
                let force = wall.damping * rate;
                for i in 0..d {
                    if wall.h[i] != 0.0 {
                        residual[i] += wall.h[i] * force;
                    }
                }
            }
        }
        let mut accel = [0.0; MAX_DIM];
        for i in 0..d {
            let mut sum = inverse[i][0] * residual[0];
            for j in 1..d {
                sum += inverse[i][j] * residual[j];
            }
            accel[i] = sum;
        }
        let (bb, gg) = (beta * h * h, gamma * h);
        let (mut x, mut v) = ([0.0; MAX_DIM], [0.0; MAX_DIM]);
        for i in 0..d {
            x[i] = xp[i] + bb * accel[i];
            v[i] = vp[i] + gg * accel[i];
        }
        // The accumulators' rates at the end (as `end_powers`).
        let mut rates = [0.0; MAX_RATES];
        rates[VISCOUS] = (0..n).map(|i| sized.viscous[i] * v[i] * v[i]).sum();
        for (l, load) in loads.iter().enumerate() {
            rates[INPUT] += values[l] * linalg::dot(&load.shape[..d], &v[..d]);
        }
        for w in 0..count {
            next.lagged[w] = false;
            let Mode::Compliant { approach_rate, .. } = modes[w] else {
                continue;
            };
            let wall = &sized.walls[w];
            let (indentation, rate) = wall.indentation(d, &x, &v);
            let (force, elastic) = if indentation > 0.0 {
                let (force, elastic) = wall.law.force_and_elastic(indentation, rate, approach_rate);
                (next.lag[w], next.lagged[w]) = (force, true);
                (force, elastic)
            } else {
                (0.0, 0.0)
            };
            rates[CONTACT + w] = (force + wall.damping * rate - elastic) * rate;
            step.contact[w] = (indentation, rate);
        }
        // The accumulators by the trapezoidal rule (`Trapezoid::integrate`;
        // free, the walls' are the stretch's, see `first_walls`).
        for k in 0..if FREE { CONTACT } else { MAX_RATES } {
            step.accumulators[k] = y[2 * d + k] + 0.5 * h * (carried.rates[k] + rates[k]);
        }
        next.accel = accel;
        next.rates = rates;
        step.end[..MAX_DIM].copy_from_slice(&x);
        step.end[MAX_DIM..].copy_from_slice(&v);
    }
}

/// A step: its end's coordinates and velocities (each `MAX_DIM` wide) and
/// accumulators, each wall's indentation and rate at its end (where in
/// contact mode).
#[derive(Clone, Copy)]
struct Step {
    end: [f64; 2 * MAX_DIM],
    accumulators: [f64; MAX_RATES],
    contact: [(f64, f64); MAX_WALLS],
}

impl Step {
    /// The step accepted into the state `y`: its `end` (`d` coordinates)
    /// and accumulators. Free, the walls' accumulators are left out of the
    /// steps: `first_walls` after the stretch's first step, as they were
    /// after the others.
    #[inline(always)]
    fn accept_into<const FREE: bool>(
        &self,
        (d, first_step): (usize, bool),
        end: &[f64; MAX_LEN],
        first_walls: &[f64; MAX_RATES],
        y: &mut [f64; MAX_LEN],
    ) {
        for i in 0..2 * d {
            y[i] = end[i];
        }
        for k in 0..if FREE { CONTACT } else { MAX_RATES } {
            y[2 * d + k] = self.accumulators[k];
        }
        if FREE && first_step {
            for k in CONTACT..MAX_RATES {
                y[2 * d + k] = first_walls[k];
            }
        }
    }
}

impl Sized {
    /// The dissipated power [`fixed::press`] takes for wall `w` at the
    /// step's `end` (in `mode`): the step's accumulator rate, where press's
    /// indentation and rate (the gap as [`Assembly::gap`] sums it) are the
    /// step's to the bit; else None (press evaluates it).
    #[inline(always)]
    fn pressed_power(
        &self,
        w: usize,
        d: usize,
        end: &[f64; MAX_LEN],
        mode: Mode,
        (step, carried): (&Step, &Carried),
    ) -> Option<f64> {
        let Mode::Compliant { .. } = mode else {
            return None;
        };
        let h = &self.walls[w].h[..d];
        let indentation = -(self.walls[w].offset + linalg::dot(h, &end[..d]));
        let rate = -linalg::dot(h, &end[d..2 * d]);
        let (i1, r1) = step.contact[w];
        (indentation.to_bits() == i1.to_bits() && rate.to_bits() == r1.to_bits()).then(|| {
            if indentation > 0.0 {
                carried.rates[CONTACT + w]
            } else {
                0.0
            }
        })
    }
}
