//! RK4 on a small modal system in fixed-size arrays: the impact damper's
//! common case (a few modes, a damper or two, a stop or two, at most one
//! force, gravity) with no heap pointer or slice length in its inner loop.
//!
//! The general stages ([`crate::methods::steppers`]) read the system through
//! `Vec`s and the state through slices whose length is known only at run
//! time; here every array has a fixed capacity and every loop over the
//! coordinates a length fixed at compile time, which roughly halves the
//! instructions of a step. The arithmetic is the general stages' and
//! [`Assembly::rates_with`]'s, term for term and in the same order: the
//! same bits (a test holds them to it).

// Indexed loops over the fixed-size arrays, and copies written as loops:
// what compiles to the tight code here (iterator chains and `copy_from_slice`
// between the arrays measured slower: calls to memcpy, bounds not folded).
#![allow(clippy::needless_range_loop, clippy::manual_memcpy)]

mod lane_signals;
mod lane_stepper;
mod lane_steps;
mod lanes;
mod lockstep;
mod press;
mod stop_rules;
mod stretch;
mod stretch_reductions;
pub(crate) use lanes::LaneLaw;
pub(crate) use lanes::LANES;
pub(crate) use lockstep::run_group;
pub(crate) use stop_rules::{passed_over, shows_no_event};
pub(crate) use stretch::{ArraySteps, Stretch};
pub(crate) use stretch_reductions::{peak_inside, widen_peaks};

use crate::methods::tableau::{RK4_A, RK4_B, RK4_C};
use crate::model::assembly::{
    apart_damping, elastic, h_dot, Assembly, InteractionLaw, Mode, Scratch, CONTACT, INPUT, VISCOUS,
};
use crate::model::contact::{AnyLaw, ContactLaw, HysterHertz};
use crate::model::signals::Signal;

/// The largest system held: as many structure coordinates and dampers as
/// [`crate::kernel::sized::by_size`] compiles for, and walls for two dampers and
/// two stops.
pub(crate) const MAX_MODES: usize = 4;
pub(crate) const MAX_DAMPERS: usize = 2;
pub(crate) const MAX_DIM: usize = MAX_MODES + MAX_DAMPERS;
pub(crate) const MAX_WALLS: usize = 2 * MAX_DAMPERS + 2;
/// The longest state: coordinates, velocities and the accumulators.
pub(crate) const MAX_LEN: usize = 2 * MAX_DIM + CONTACT + MAX_WALLS;

/// Per wall, the damping factor of its law in the modes stepped (see
/// [`Compact::rate_factors`]).
pub(crate) type Factors = [f64; MAX_WALLS];

/// One wall of a pair (see [`crate::model::assembly::Interaction`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Wall {
    h: [f64; MAX_DIM],
    push: [f64; MAX_DIM],
    offset: f64,
    /// The compliant law and contact damping (N s/m); None for a rigid wall.
    law: Option<(AnyLaw, f64)>,
    /// Whether `h` is the previous wall's negated (a damper's second wall).
    mirror: bool,
    /// `h M^-1 h^T`, 1/kg.
    inverse_mass: f64,
}

impl Wall {
    /// `(h . x, h . v)` at `y` for the gap the events watch, summed in
    /// order as the general path sums them.
    #[inline(always)]
    fn gap_products(&self, d: usize, y: &[f64; MAX_LEN]) -> (f64, f64) {
        let (mut hx, mut hv) = (-0.0, -0.0);
        for i in 0..d {
            hx += self.h[i] * y[i];
            hv += self.h[i] * y[d + i];
        }
        (hx, hv)
    }

    /// `(h . x, h . v)` at `y` for a compliant wall's force, summed as the
    /// general path sums them (see [`crate::model::assembly::h_dot`]).
    #[inline(always)]
    fn products(&self, d: usize, y: &[f64; MAX_LEN]) -> (f64, f64) {
        let h = &self.h[..d];
        (h_dot(h, &y[..d]), h_dot(h, &y[d..2 * d]))
    }
}

/// The first force: its signal, `M^-1 row^T` and the point's row.
#[derive(Debug, Clone, PartialEq)]
struct Force {
    signal: Signal,
    push: [f64; MAX_MODES],
    row: [f64; MAX_MODES],
}

/// A small modal system's plain data in fixed-size arrays.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Compact {
    /// `[M^-1 K, M^-1 C, C, r]` of each mode.
    modal: [[f64; 4]; MAX_MODES],
    force: Option<Force>,
    gravity: f64,
    walls: [Wall; MAX_WALLS],
    count: usize,
}

impl Compact {
    /// The system's compact form, where it has one: diagonal (modal)
    /// matrices, sizes within the capacities, no base excitation and at
    /// most one force.
    pub(crate) fn of(system: &Assembly) -> Option<Self> {
        let parts = system.compact_parts()?;
        let (n, d) = (system.n, system.dim);
        if n > MAX_MODES
            || system.k > MAX_DAMPERS
            || system.interactions.len() > MAX_WALLS
            || parts.forces.len() > 1
            || parts.has_base
            || system.has_friction()
        {
            return None;
        }
        let mut modal = [[0.0; 4]; MAX_MODES];
        modal[..n].copy_from_slice(&parts.diagonals[..n]);
        let force = parts.forces.first().map(|(signal, push, row)| {
            let mut f = Force {
                signal: (*signal).clone(),
                push: [0.0; MAX_MODES],
                row: [0.0; MAX_MODES],
            };
            f.push[..n].copy_from_slice(&push[..n]);
            f.row[..n].copy_from_slice(&row[..n]);
            f
        });
        let empty = Wall {
            h: [0.0; MAX_DIM],
            push: [0.0; MAX_DIM],
            offset: 0.0,
            law: None,
            mirror: false,
            inverse_mass: 0.0,
        };
        let mut walls = [empty; MAX_WALLS];
        for ((wall, it), mirror) in walls
            .iter_mut()
            .zip(&system.interactions)
            .zip(parts.mirrors)
        {
            wall.h[..d].copy_from_slice(&it.h[..d]);
            wall.push[..d].copy_from_slice(&it.push[..d]);
            wall.offset = it.offset;
            wall.mirror = *mirror;
            wall.inverse_mass = it.inverse_mass;
            wall.law = match it.law {
                InteractionLaw::Compliant { law, damping } => Some((law, damping)),
                InteractionLaw::Rigid { .. } | InteractionLaw::Friction { .. } => None,
            };
        }
        Some(Self {
            modal,
            force,
            gravity: parts.gravity,
            walls,
            count: system.interactions.len(),
        })
    }

    /// [`Assembly::rates_with`] for `n` modes and `k` dampers (constants
    /// where inlined); sticking pairs' constraint forces by `system`'s own
    /// solve. `FREE`: every wall open and no gravity (see [`Self::free`]),
    /// the walls' and the inertial load's terms then left out at compile
    /// time (the zeros they add: the same bits).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn rates<const STICKING: bool, const FREE: bool>(
        &self,
        system: &Assembly,
        n: usize,
        k: usize,
        time: f64,
        y: &[f64; MAX_LEN],
        (modes, factors): (&[Mode], &Factors),
        scratch: &mut Scratch,
        out: &mut [f64; MAX_LEN],
    ) {
        let d = n + k;
        // The general path's sum of no base signal and gravity (+0 without
        // gravity: a constant the elastic term's test folds).
        let inertial = if FREE { 0.0 } else { 0.0 + self.gravity };
        let mut input = 0.0;
        let mut viscous = 0.0;
        // The accelerations, summed here term by term in the general path's
        // order and stored once: a contact force's term then waits on no
        // store and load of `out` (a stage's critical path in contact).
        let mut accel = [0.0; MAX_DIM];
        if let Some(force) = &self.force {
            let value = scratch.first_force_value(&force.signal, time);
            let mut power = -0.0;
            for i in 0..n {
                let [k, c, damping, r] = self.modal[i];
                let (x, v) = (y[i], y[d + i]);
                out[i] = v;
                accel[i] = elastic(k, c, r, inertial, x, v) + force.push[i] * value;
                viscous += damping * v * v;
                power += force.row[i] * v;
            }
            input += value * power;
        } else {
            for i in 0..n {
                let [k, c, damping, r] = self.modal[i];
                let (x, v) = (y[i], y[d + i]);
                out[i] = v;
                accel[i] = elastic(k, c, r, inertial, x, v);
                viscous += damping * v * v;
            }
        }
        for j in n..d {
            out[j] = y[d + j];
            accel[j] = -inertial;
        }
        let count = self.count.min(MAX_WALLS);
        let modes = &modes[..count];
        let mut products: Option<(f64, f64)> = None;
        let mut sticking = 0;
        // Each wall's loss rate, held apart: indexed by the wall (a number
        // known at run time), the stages themselves would be kept in memory.
        let mut losses = [0.0; MAX_WALLS];
        // Free: every wall open, no force and no loss (as the loop finds).
        for w in 0..if FREE { 0 } else { count } {
            let wall = &self.walls[w];
            let previous = products.take();
            if let (
                Mode::Compliant {
                    approach_rate,
                    indented_only,
                },
                Some((law, damping)),
            ) = (&modes[w], &wall.law)
            {
                let (hx, hv) = match previous {
                    Some((hx, hv)) if wall.mirror => (-hx, -hv),
                    _ => wall.products(d, y),
                };
                products = Some((hx, hv));
                let (indentation, rate) = (-(wall.offset + hx), -hv);
                let (force, elastic, damping) = if law.acts(indentation, *indented_only) {
                    let (force, elastic) = match law {
                        AnyLaw::HysterHertz(l) => HysterHertz::force_of(
                            l.parts(),
                            indentation,
                            rate,
                            *approach_rate,
                            factors[w],
                        ),
                        _ => law.force_and_elastic(indentation, rate, *approach_rate),
                    };
                    (force, elastic, *damping)
                } else {
                    (0.0, 0.0, apart_damping(*damping, *indented_only))
                };
                let total = force + damping * rate;
                if total != 0.0 {
                    for i in 0..d {
                        accel[i] += wall.push[i] * total;
                    }
                }
                losses[w] = (total - elastic) * rate;
            } else if STICKING && modes[w] == Mode::Sticking {
                scratch.sticking[sticking] = w;
                sticking += 1;
            }
        }
        for i in 0..d {
            out[d + i] = accel[i];
        }
        if STICKING && sticking == 1 {
            // One constraint, as `Assembly::add_constraint_forces` solves it.
            let wall = &self.walls[scratch.sticking[0].min(MAX_WALLS - 1)];
            // `h . a` summed as `h_dot` sums it, written out over the array
            // (through slices of `out` the run measured 2 % slower).
            let mut sum = [-0.0; 2];
            for i in 0..d {
                sum[i % 2] += wall.h[i] * out[d + i];
            }
            let lambda = -(sum[0] + sum[1]) / wall.inverse_mass;
            scratch.forces[0] = lambda;
            for i in 0..d {
                out[d + i] += wall.push[i] * lambda;
            }
        } else if STICKING && sticking > 1 {
            system.add_constraint_forces(sticking, &mut out[d..2 * d], scratch);
        }
        scratch.count = sticking;
        out[2 * d + VISCOUS] = viscous;
        out[2 * d + INPUT] = input;
        for w in 0..MAX_WALLS {
            out[2 * d + CONTACT + w] = losses[w];
        }
    }

    /// One RK4 step `h` from `(time, start)` into `out` (every wall's room),
    /// for `n` modes and `k` dampers (`STICKING`: whether a
    /// pair may stick): the general stages' arithmetic. `stages[0]` holds `f(start)` where
    /// `start_valid`, and receives it where not.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn step<const STICKING: bool, const FREE: bool>(
        &self,
        system: &Assembly,
        n: usize,
        k: usize,
        time: f64,
        start: &[f64; MAX_LEN],
        h: f64,
        modes: (&[Mode], &Factors),
        scratch: &mut Scratch,
        stages: &mut [[f64; MAX_LEN]; 4],
        start_valid: bool,
        out: &mut [f64; MAX_LEN],
    ) {
        let coordinates = 2 * (n + k);
        // The general stages' times and weights (written out: `map` over
        // arrays is not inlined here).
        let times = [
            time,
            time + RK4_C[1] * h,
            time + RK4_C[2] * h,
            time + RK4_C[3] * h,
        ];
        let hw = [h * RK4_A[1][0], h * RK4_A[2][1], h * RK4_A[3][2]];
        let w = [h * RK4_B[0], h * RK4_B[1], h * RK4_B[2], h * RK4_B[3]];
        let [k0, k1, k2, k3] = stages;
        if !start_valid {
            self.rates::<STICKING, FREE>(system, n, k, times[0], start, modes, scratch, k0);
        }
        // The stages written out (a loop over them keeps less in registers).
        let mut point = [0.0; MAX_LEN];
        for e in 0..coordinates {
            point[e] = start[e] + hw[0] * k0[e];
        }
        self.rates::<STICKING, FREE>(system, n, k, times[1], &point, modes, scratch, k1);
        for e in 0..coordinates {
            point[e] = start[e] + hw[1] * k1[e];
        }
        self.rates::<STICKING, FREE>(system, n, k, times[2], &point, modes, scratch, k2);
        for e in 0..coordinates {
            point[e] = start[e] + hw[2] * k2[e];
        }
        self.rates::<STICKING, FREE>(system, n, k, times[3], &point, modes, scratch, k3);
        // Over every wall's room (a length fixed at compile time; the rooms
        // past the system's walls hold zeros).
        let walls = coordinates + CONTACT;
        for e in 0..if FREE { walls } else { walls + MAX_WALLS } {
            out[e] = start[e] + w[0] * k0[e] + w[1] * k1[e] + w[2] * k2[e] + w[3] * k3[e];
        }
        if FREE {
            // No loss in any stage: `w k` is +0 (`h > 0`), and the sum the
            // start's plus zeros.
            for e in walls..walls + MAX_WALLS {
                out[e] = start[e] + 0.0;
            }
        }
    }

    /// [`Self::step`] over slices: `first` holds `f(y)` where
    /// `start_valid`, and receives it where not.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn rk4(
        &self,
        system: &Assembly,
        n: usize,
        k: usize,
        time: f64,
        y: &[f64],
        h: f64,
        modes: &[Mode],
        scratch: &mut Scratch,
        first: &mut [f64],
        start_valid: bool,
        out: &mut [f64],
    ) {
        let len = y.len().min(MAX_LEN);
        let mut start = [0.0; MAX_LEN];
        start[..len].copy_from_slice(&y[..len]);
        let mut stages = [[0.0; MAX_LEN]; 4];
        if start_valid {
            stages[0][..len].copy_from_slice(&first[..len]);
        }
        let mut end = [0.0; MAX_LEN];
        let factors = self.rate_factors(modes);
        // One body for every mode (with no pair sticking, the constraint
        // branch is skipped at run time): the stretches, where speed counts,
        // compile the two apart.
        self.step::<true, false>(
            system,
            n,
            k,
            time,
            &start,
            h,
            (modes, &factors),
            scratch,
            &mut stages,
            start_valid,
            &mut end,
        );
        if !start_valid {
            first[..len].copy_from_slice(&stages[0][..len]);
        }
        out[..len].copy_from_slice(&end[..len]);
    }

    /// Whether the stages in `modes` are free flight: every wall open and
    /// no gravity (`FREE` in [`Self::rates`]).
    pub(crate) fn free(&self, modes: &[Mode]) -> bool {
        self.gravity == 0.0 && modes.iter().all(|m| *m == Mode::Open)
    }

    /// Each wall's damping factor on the indentation rate where its law
    /// damps ([`HysterHertz`]: `alpha / delta'_minus`, the latched approach
    /// rate's quotient): the division made once for the steps in `modes`
    /// (the law's own, the same bits), not in every stage.
    #[inline(always)]
    pub(crate) fn rate_factors(&self, modes: &[Mode]) -> Factors {
        let mut factors = [0.0; MAX_WALLS];
        for w in 0..self.count.min(MAX_WALLS).min(modes.len()) {
            if let (Mode::Compliant { approach_rate, .. }, Some((AnyLaw::HysterHertz(law), _))) =
                (modes[w], &self.walls[w].law)
            {
                factors[w] = law.hysteresis / approach_rate;
            }
        }
        factors
    }

    /// Whether a wall's gap at `y` is below zero: the gaps' displacements
    /// alone, as [`Self::gaps`] sums them.
    #[inline(always)]
    fn indented(&self, d: usize, y: &[f64; MAX_LEN]) -> bool {
        let mut hx = 0.0;
        let mut indented = false;
        for w in 0..self.count.min(MAX_WALLS) {
            let wall = &self.walls[w];
            hx = if wall.mirror {
                -hx
            } else {
                wall.gap_products(d, y).0
            };
            indented |= wall.offset + hx < 0.0;
        }
        indented
    }

    /// Every wall's gap and rate at `y`, as [`Assembly::gaps`] gives them.
    #[inline(always)]
    fn gaps(&self, d: usize, y: &[f64; MAX_LEN], out: &mut [(f64, f64); MAX_WALLS]) {
        let count = self.count.min(MAX_WALLS);
        let mut products = (0.0, 0.0);
        for w in 0..count {
            let wall = &self.walls[w];
            products = if wall.mirror {
                (-products.0, -products.1)
            } else {
                wall.gap_products(d, y)
            };
            out[w] = (wall.offset + products.0, products.1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Result;
    use crate::kernel::balance::EnergyWatch;
    use crate::kernel::clock::{Clock, Schedule};
    use crate::kernel::events::{
        integrate_system, integrate_system_within, ContactKind, RunOptions, SystemSolution,
    };
    use crate::kernel::memory::MAX_RECORD_BYTES;
    use crate::kernel::reductions::ReduceOptions;
    use crate::methods::steppers::{ExplicitRk, SystemStepper};
    use crate::model::assembly::{
        initial_state, Damper, Excitation, Load, PairLaw, Side, Stop, SystemSpec,
    };
    use crate::model::contact::{Contact, LawKind};
    use crate::model::structure::Structure;

    /// The 3-mode cantilever of the throughput goal: two compliant dampers
    /// (with contact damping), a tip force, gravity if asked.
    fn beam(gravity: f64) -> SystemSpec {
        let contact = Contact::new(LawKind::HertzDamped, 1e7, Some(0.6), 0.5).unwrap();
        let damper = |at, clearance| Damper {
            mass: 0.01,
            at,
            lower_clearance: clearance,
            upper_clearance: clearance,
            law: PairLaw::Compliant(contact),
        };
        SystemSpec {
            structure: Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 3, 0.01).unwrap(),
            dampers: vec![damper(0.5, 2e-4), damper(0.25, 1e-4)],
            collisions: vec![],
            frictions: vec![],
            stops: vec![],
            gravity,
            excitations: vec![Excitation {
                load: Load::Force { at: 0.5 },
                signal: Signal::harmonic(0.5, 8.0, 0.3).unwrap(),
            }],
            points: vec![],
            moments: vec![],
        }
    }

    /// A forced oscillator on a compliant (linear, damped) stop below it,
    /// with a rigid damper rattling on it and gravity: impacts, and stops
    /// of each kind of wall.
    fn oscillator() -> SystemSpec {
        let stop = Contact::new(LawKind::Linear, 2e4, None, 3.0).unwrap();
        SystemSpec {
            structure: Structure::oscillator(1.0, 400.0, 0.5).unwrap(),
            dampers: vec![Damper {
                mass: 0.05,
                at: 0.0,
                lower_clearance: 3e-3,
                upper_clearance: 3e-3,
                law: PairLaw::rigid(0.6).unwrap(),
            }],
            collisions: vec![],
            frictions: vec![],
            stops: vec![Stop {
                at: 0.0,
                side: Side::Lower,
                gap: 0.01,
                law: PairLaw::Compliant(stop),
                against: None,
            }],
            gravity: 9.81,
            excitations: vec![Excitation {
                load: Load::Force { at: 0.0 },
                signal: Signal::harmonic(12.0, 3.0, 0.0).unwrap(),
            }],
            points: vec![],
            moments: vec![],
        }
    }

    fn options(dt: f64, t_end: f64) -> RunOptions {
        RunOptions {
            dt: Some(dt),
            t_end,
            every: 1,
            keep_history: false,
            max_steps: u64::MAX,
            max_rows: u64::MAX,
            energy_tolerance: 1e-2,
            reduce: ReduceOptions::default(),
        }
    }

    /// The run with RK4's compact path and without it (interrupted at the
    /// `polls`-th poll, its records within `record_limit` bytes).
    fn both_within(
        spec: &SystemSpec,
        options: &RunOptions,
        polls: Option<u32>,
        record_limit: u64,
    ) -> [Result<SystemSolution>; 2] {
        let system = Assembly::new(spec).unwrap();
        assert!(system.compact.is_some(), "the system has a compact form");
        let y = initial_state(&system, &[], &[], &[], &[]).unwrap();
        [true, false].map(|compact| {
            let mut stepper = ExplicitRk::rk4(system.state_len());
            stepper.compact = compact;
            let mut left = polls.unwrap_or(u32::MAX);
            let mut interrupt = || {
                left = left.saturating_sub(1);
                left == 0
            };
            integrate_system_within(
                &system,
                &mut stepper,
                &y,
                options,
                &mut interrupt,
                record_limit,
            )
        })
    }

    fn both(
        spec: &SystemSpec,
        options: &RunOptions,
        polls: Option<u32>,
    ) -> [Result<SystemSolution>; 2] {
        both_within(spec, options, polls, MAX_RECORD_BYTES)
    }

    /// Debug text tells every bit of every number apart (and -0 from 0).
    fn same(runs: &[Result<SystemSolution>; 2]) {
        let [a, b] = runs.each_ref().map(|r| format!("{r:?}"));
        assert!(a == b, "compact:\n{a:.2000}\ngeneral:\n{b:.2000}");
    }

    #[test]
    fn runs_are_those_of_the_general_path_to_the_bit() {
        crate::testing::timeout(120, || {
            let mut o = options(1e-5, 0.12);
            o.keep_history = true;
            o.every = 7;
            o.reduce = ReduceOptions {
                record_from: 0.02,
                strobe_period: 0.0133,
                mean_square: false,
                ..ReduceOptions::default()
            };
            let runs = both(&beam(0.0), &o, None);
            let solution = runs[0].as_ref().unwrap();
            assert!(solution.contacts.len() > 10 && solution.reductions.strobe_time.len() > 5);
            same(&runs);
            // Gravity, the mean square, no history; points followed.
            o.keep_history = false;
            o.reduce.mean_square = true;
            let mut spec = beam(9.81);
            spec.points = vec![0.1, 0.4];
            same(&both(&spec, &o, None));
            // Impacts, chatter and sticking: a compliant stop and a rigid
            // damper; the beam of the example file (one damper rigid).
            let runs = both(&oscillator(), &options(1e-4, 3.0), None);
            let contacts = &runs[0].as_ref().unwrap().contacts;
            assert!(contacts.len() > 20);
            assert!(contacts.iter().any(|c| c.kind == ContactKind::Sticking));
            same(&runs);
            let mut spec = beam(0.0);
            (
                spec.dampers[1].lower_clearance,
                spec.dampers[1].upper_clearance,
            ) = (1e-4, 3e-4);
            spec.dampers[1].law = PairLaw::rigid(0.5).unwrap();
            let runs = both(&spec, &options(1e-5, 0.3), None);
            let contacts = &runs[0].as_ref().unwrap().contacts;
            assert!(contacts.iter().any(|c| c.kind == ContactKind::Sticking));
            same(&runs);
            // A contact still pressing in at the end of the run (and a
            // rigid damper's impacts meanwhile).
            let system = Assembly::new(&oscillator()).unwrap();
            let y = initial_state(&system, &[-0.0099], &[-1.0], &[-0.0099], &[-1.0]).unwrap();
            let runs = [true, false].map(|compact| {
                let mut stepper = ExplicitRk::rk4(system.state_len());
                stepper.compact = compact;
                let o = options(1e-5, 0.004);
                integrate_system(&system, &mut stepper, &y, &o, &mut || false)
            });
            let contacts = &runs[0].as_ref().unwrap().contacts;
            assert!(contacts
                .iter()
                .any(|c| c.separation.is_nan() && c.max_indentation > 1e-3));
            same(&runs);
        });
    }

    #[test]
    fn runs_fail_as_the_general_path_fails() {
        crate::testing::timeout(60, || {
            // The step limit, the energy check (a tolerance no run meets)
            // and an interrupt, each reached inside what would be a stretch.
            let mut o = options(1e-5, 0.5);
            o.max_steps = 5000;
            let runs = both(&beam(0.0), &o, None);
            assert!(runs[0].is_err());
            same(&runs);
            let mut o = options(1e-5, 0.5);
            o.energy_tolerance = 1e-300;
            let runs = both(&beam(0.0), &o, None);
            assert!(runs[0].is_err());
            same(&runs);
            let runs = both(&beam(0.0), &options(1e-5, 0.5), Some(2));
            assert!(runs[0].is_err());
            same(&runs);
            // Records past their limits: bytes (the contacts' room, checked
            // after the first step), and rows (the first kept after it).
            let runs = both_within(&beam(0.0), &options(1e-5, 0.01), None, 200);
            assert!(runs[0].is_err());
            same(&runs);
            let mut o = options(1e-5, 0.01);
            (o.keep_history, o.every, o.max_rows) = (true, 10, 0);
            let runs = both(&beam(0.0), &o, None);
            assert!(runs[0].is_err());
            same(&runs);
        });
    }

    #[test]
    fn a_stretch_takes_plain_steps_as_the_general_attempts_do() {
        crate::testing::timeout(60, || {
            let system = Assembly::new(&beam(0.0)).unwrap();
            let compact = system.compact.as_ref().unwrap();
            let len = system.state_len();
            let count = system.interactions.len();
            let modes = vec![Mode::Open; count];
            let mut y = initial_state(&system, &[], &[], &[], &[]).unwrap();
            let mut gaps = vec![(0.0, 0.0); count];
            system.gaps(&y, &mut gaps);
            let (mut open, mut peaks, mut recorded) = (vec![None; count], vec![0.0; 3], 0.0);
            let dt = 1e-5;
            let (stored_start, scale) = system.energy_terms(&y, &modes);
            let mut clock = Clock {
                time: 0.0,
                grid: 0,
                accepted: 0,
                until_kept: 0,
                next_strobe: f64::INFINITY,
            };
            let schedule = Schedule {
                adaptive: false,
                dt,
                t_end: 1.0,
                keep_history: false,
                every: 1,
                record_from: 0.0,
                strobe_period: f64::INFINITY,
                mean_square: false,
                time_scale: 1.0,
                fixed: None,
            };
            let mut energy = EnergyWatch {
                stored_start,
                scale,
                sampler: crate::kernel::balance::EnergySampler::new(&system, 1.0),
                impact_loss: 0.0,
                tolerance: 1e-6,
                t_end: 1.0,
                extremes: Default::default(),
            };
            let mut stretch = Stretch {
                clock: &mut clock,
                schedule: &schedule,
                y: &mut y,
                gaps: &mut gaps,
                end: &mut [],
                end_gaps: &mut [],
                open: &mut open,
                peaks: &mut peaks,
                squares: &mut [],
                reduce_scratch: &mut Scratch::new(&system),
                recorded_time: &mut recorded,
                energy: &mut energy,
                max_accepted: 20,
                limited: false,
                evaluations: 0,
                steps: 0,
                unbalanced: None,
            };
            let mut scratch = Scratch::new(&system);
            compact.run_stretch(&system, &mut stretch, &modes, &mut scratch);
            assert_eq!((stretch.steps, stretch.evaluations), (20, 80));
            assert!(stretch.limited);
            // The same steps through the general attempt.
            let mut general = ExplicitRk::rk4(len);
            general.compact = false;
            let mut scratch = Scratch::new(&system);
            let mut at = initial_state(&system, &[], &[], &[], &[]).unwrap();
            let mut end = vec![0.0; len];
            let mut time = 0.0;
            for step in 0..20u32 {
                let length = f64::from(step + 1) * dt - time;
                general
                    .attempt(&system, time, &at, length, &modes, &mut scratch, &mut end)
                    .unwrap();
                general.accept();
                std::mem::swap(&mut at, &mut end);
                time += length;
            }
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&y), bits(&at));
            assert_eq!(recorded, time);
            assert!(peaks[0] > 0.0);
        });
    }
}
