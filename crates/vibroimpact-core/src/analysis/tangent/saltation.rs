//! The saltation matrix of an event: the jump of the tangent flow where the
//! located interaction's event value `g` reaches zero, the reset map `R`
//! acts and the rates change from `f-` to `f+`:
//! `S = R + (f+ - R f-) grad(g)^T / (dg/dt)`, `dg/dt = grad(g) . f- +
//! dg/dt|_y` the value's rate along the flow before it.
//!
//! `g` is a pair's gap (no time of its own); a sliding friction element's
//! speed along its row (it comes to rest: it sticks, or slides back); or
//! the margin of a held one's force, the static force less the force that
//! holds a stuck element (it slips), or a sticking pair's force plus the
//! friction that helps to hold it (it leaves its wall). That force depends
//! on the state and, through the loads, on time: its gradient and time
//! rate are central differences, exact to round-off where it is affine in
//! the state (a linear structure with rigid pairs) ([`Saltation::margin`]).

use super::parameters::Parameters;
use crate::kernel::observe::{EventView, Jump};
use crate::model::assembly::{Assembly, Interaction, Mode, Scratch};
use crate::numerics::linalg;

/// A closing speed below this fraction of the speeds in play is a touch at
/// rest or a grazing: the kernel's own threshold for a pair leaving its
/// wall (see `kernel::impacts`).
const GRAZING_SPEED: f64 = 1e-9;

/// What the event was, for the flow's report.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Outcome {
    /// A grazing: the located pair's closing speed (m/s, of round-off), the
    /// pair neither sticking nor resting after it.
    pub grazing: Option<f64>,
}

/// The located interaction's event value: a pair's gap, a sliding
/// element's speed along its row, or a held one's force margin.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Value {
    Gap,
    Speed,
    Margin,
}

/// Buffers for [`Saltation::matrix`], made once per flow.
pub(super) struct Saltation {
    scratch: Scratch,
    full: Vec<f64>,
    minus: Vec<f64>,
    plus: Vec<f64>,
    reset: Vec<f64>,
    column: Vec<f64>,
    coupling: Vec<f64>,
    /// The last event's `(f+ - R f-) / (dg/dt)` (see `shift`): the
    /// saltation's column per unit of the located event value's change
    /// (zero where the event had no time shift: a release, a grazing, a
    /// landing at rest).
    jump: Vec<f64>,
    /// Whether the last event was a landing at rest (its displacements
    /// projected as the velocities are).
    landed: bool,
    /// What the last event's located value was (how a parameter moves it).
    value: Value,
    /// The located event value's gradient (`2 dim`), and room for the
    /// rates of [`Self::margin`]'s probes.
    gradient: Vec<f64>,
    probe: Vec<f64>,
    /// Buffers of [`Self::parameter_columns`].
    velocities: Vec<f64>,
    values: Vec<f64>,
    parameter: Vec<f64>,
}

impl Saltation {
    pub(super) fn new(system: &Assembly) -> Self {
        let (len, d) = (system.state_len(), system.dim);
        Self {
            scratch: Scratch::new(system),
            full: vec![0.0; len],
            minus: vec![0.0; len],
            plus: vec![0.0; len],
            reset: vec![0.0; d * d],
            column: Vec::new(),
            coupling: Vec::new(),
            jump: vec![0.0; 2 * d],
            landed: false,
            value: Value::Gap,
            gradient: vec![0.0; 2 * d],
            probe: vec![0.0; len],
            velocities: vec![0.0; d],
            values: Vec::new(),
            parameter: vec![0.0; 2 * d],
        }
    }

    /// The velocities' reset map `R_v = I - Push_A W^-1 (I + E) H_A` of the
    /// pairs the impulses acted on (`A`, each resolved to `u+ = -e u-`), into
    /// `self.reset` (row-major `dim x dim`).
    fn reset_map(&mut self, system: &Assembly, jumps: &[Jump]) {
        let d = system.dim;
        self.reset.iter_mut().for_each(|v| *v = 0.0);
        for i in 0..d {
            self.reset[i * d + i] = 1.0;
        }
        if jumps.is_empty() {
            return;
        }
        let its = &system.interactions;
        // Column c: the unit velocity e_c less what moves the pairs' rates by
        // (1 + e) h . e_c.
        for c in 0..d {
            self.column.clear();
            self.column.extend(
                jumps
                    .iter()
                    .map(|j| (1.0 + j.restitution) * its[j.interaction].h[c]),
            );
            self.velocities.iter_mut().for_each(|v| *v = 0.0);
            self.velocities[c] = 1.0;
            push_back(
                its,
                jumps,
                &mut self.column,
                &mut self.velocities,
                &mut self.coupling,
            );
            for (r, value) in self.velocities.iter().enumerate() {
                self.reset[r * d + c] = *value;
            }
        }
    }

    /// The saltation matrix of `view`'s event into `out` (row-major `2 dim x
    /// 2 dim`). Where pairs start to stick, its rows are projected onto their
    /// constraints (gaps and rates held), so that the directions they lose
    /// are lost to round-off of the rows, not carried as the round-off of a
    /// difference `1 + (v+ - v-) / u` that the growth elsewhere multiplies.
    /// Friction elements that start to stick hold their rows' rates, not
    /// their places (a perturbed slide stops elsewhere): only the velocity
    /// rows are projected for them.
    pub(super) fn matrix(
        &mut self,
        system: &Assembly,
        view: &EventView<'_>,
        out: &mut [f64],
    ) -> Outcome {
        let outcome = self.jump_matrix(system, view, out);
        let sticking = sticking(view);
        let mut held = sticking.clone();
        held.extend(newly_stuck(view));
        self.project(system, (&sticking, &held), out);
        outcome
    }

    /// The rows of `out` (`2 dim x 2 dim`) projected onto the constraints
    /// of `modes` where a run starts in them: sticking pairs hold their gaps
    /// and rates, stuck friction elements their rates (a flow that starts
    /// stuck does not carry a velocity along the stuck row).
    pub(super) fn start_in(&mut self, system: &Assembly, modes: &[Mode], out: &mut [f64]) {
        let held_as = |keep: fn(&Mode) -> bool| -> Vec<Jump> {
            (0..modes.len())
                .filter(|&i| keep(&modes[i]))
                .map(|interaction| Jump {
                    interaction,
                    restitution: 0.0,
                    struck: false,
                })
                .collect()
        };
        let sticking = held_as(|m| *m == Mode::Sticking);
        let held = held_as(|m| {
            matches!(
                m,
                Mode::Sticking
                    | Mode::Stuck {
                        shadowed: false,
                        ..
                    }
            )
        });
        self.project(system, (&sticking, &held), out);
    }

    /// `out`'s displacement rows projected onto the gaps of `sticking` held,
    /// its velocity rows onto the rates of `held` held.
    fn project(
        &mut self,
        system: &Assembly,
        (sticking, held): (&[Jump], &[Jump]),
        out: &mut [f64],
    ) {
        let d = system.dim;
        for (block, list) in [(0, sticking), (d, held)] {
            if list.is_empty() {
                continue;
            }
            self.reset_map(system, list);
            let size = 2 * d;
            let mut column = vec![0.0; d];
            for c in 0..size {
                for (r, value) in column.iter_mut().enumerate() {
                    *value = (0..d)
                        .map(|k| self.reset[r * d + k] * out[(block + k) * size + c])
                        .sum();
                }
                for (r, value) in column.iter().enumerate() {
                    out[(block + r) * size + c] = *value;
                }
            }
        }
    }

    /// [`Self::matrix`] before the projection.
    fn jump_matrix(&mut self, system: &Assembly, view: &EventView<'_>, out: &mut [f64]) -> Outcome {
        let (d, size) = (system.dim, 2 * system.dim);
        self.reset_map(system, view.jumps);
        out.iter_mut().for_each(|v| *v = 0.0);
        for i in 0..d {
            out[i * size + i] = 1.0;
            for j in 0..d {
                out[(d + i) * size + d + j] = self.reset[i * d + j];
            }
        }
        let located = view.located;
        self.jump.iter_mut().for_each(|v| *v = 0.0);
        self.landed = false;
        self.value = Value::Gap;
        if view.jumps.is_empty() && view.modes_before == view.modes_after {
            // Nothing switched (a gap met while a friction element holds it
            // on its wall): the flow goes on smooth.
            return Outcome { grazing: None };
        }
        let side = match view.modes_before[located] {
            Mode::Open => 1.0,
            Mode::Compliant { .. } => -1.0,
            // A release with no friction on its row: the constraint force is
            // zero there, so the rates are continuous and the flow smooth
            // (no time shift).
            Mode::Sticking if system.friction_hold[located] == 0.0 => {
                return Outcome { grazing: None }
            }
            Mode::Sticking | Mode::Sliding { .. } | Mode::Stuck { .. } => {
                return self.friction_jump(system, view, out)
            }
        };
        let h = &system.interactions[located].h;
        let closing = side * linalg::dot(h, &view.before[d..size]);
        let speeds = view.before[d..size]
            .iter()
            .chain(&view.after[d..size])
            .fold(0.0f64, |m, v| m.max(v.abs()));
        if closing.abs() <= GRAZING_SPEED * speeds.max(f64::MIN_POSITIVE) {
            // No crossing to shift in time: a landing at rest, else a grazing,
            // where the flow has no derivative.
            let rests = view.modes_after[located] == Mode::Sticking
                || view.jumps.iter().any(|j| j.interaction == located);
            if rests {
                self.landed = true;
                // The limit of a plastic impact's saltation as its speed goes
                // to zero: the displacements projected as the velocities are
                // (`I + (v+ - v-) h^T / u` is `R_v` there), a perturbation off
                // the wall landing back on it, and the accelerations' jump
                // vanishing with the speed (`a+ = R_v a-` once stuck).
                for i in 0..d {
                    for j in 0..d {
                        out[i * size + j] = self.reset[i * d + j];
                    }
                }
            }
            return Outcome {
                grazing: (!rests).then_some(closing.abs()),
            };
        }
        self.rates(system, view.time, view.before, view.modes_before, false);
        self.rates(system, view.time, view.after, view.modes_after, true);
        // The gap's own rate `h . v-` (`side` squared is 1: the same bits as
        // dividing `side (f+ - R f-)` by `closing`).
        self.shift(d, side * closing, h, out);
        Outcome { grazing: None }
    }

    /// The time shift of the located event's value `g`, of rate `rate` along
    /// the flow before the event and gradient `gradient` (over the first
    /// coordinates; the rest zero): `(f+ - R f-) grad(g)^T / (dg/dt)` added
    /// to `out` (the velocities' jump, then the accelerations'), the jump
    /// per unit of `g` kept for the parameter columns.
    fn shift(&mut self, d: usize, rate: f64, gradient: &[f64], out: &mut [f64]) {
        let size = 2 * d;
        for r in 0..size {
            let jump = (self.plus[r] - self.reset_minus(d, r)) / rate;
            self.jump[r] = jump;
            for (c, g) in gradient.iter().enumerate() {
                out[r * size + c] += jump * g;
            }
        }
    }

    /// Row `r` of `R f-` (`self.minus` through the velocities' reset).
    fn reset_minus(&self, d: usize, r: usize) -> f64 {
        if r < d {
            self.minus[r]
        } else {
            let row = &self.reset[(r - d) * d..(r - d + 1) * d];
            linalg::dot(row, &self.minus[d..2 * d])
        }
    }

    /// [`Self::jump_matrix`]'s time shift where the located interaction's
    /// value is not a gap: a sliding element coming to rest (`g` its speed
    /// along its row, `dg/dt` that speed's acceleration), or a held one's
    /// force reaching what holds it ([`Self::margin`]). A value that only
    /// touches zero (a slide whose acceleration along its row is of
    /// round-off where it stops, a force that reaches its bound and turns
    /// back) is a grazing: the flow has no derivative there.
    fn friction_jump(
        &mut self,
        system: &Assembly,
        view: &EventView<'_>,
        out: &mut [f64],
    ) -> Outcome {
        let (d, size, located) = (system.dim, 2 * system.dim, view.located);
        self.rates(system, view.time, view.before, view.modes_before, false);
        self.rates(system, view.time, view.after, view.modes_after, true);
        let sliding = matches!(view.modes_before[located], Mode::Sliding { .. });
        self.value = if sliding { Value::Speed } else { Value::Margin };
        let (closing, scale) = if sliding {
            let h = &system.interactions[located].h;
            self.gradient[..d].iter_mut().for_each(|v| *v = 0.0);
            self.gradient[d..size].copy_from_slice(h);
            let accelerations = self.minus[d..size]
                .iter()
                .chain(&self.plus[d..size])
                .fold(0.0f64, |m, a| m.max(a.abs()));
            let norm = linalg::dot(h, h).sqrt();
            (linalg::dot(h, &self.minus[d..size]), norm * accelerations)
        } else {
            self.margin(system, view)
        };
        // Rates that do not change (a sliding element that stops on a row a
        // sticking pair holds: the pair's constraint took its force) shift
        // nothing, whatever the time shift.
        let (mut change, mut magnitude) = (0.0f64, 0.0f64);
        for r in 0..size {
            change = change.max((self.plus[r] - self.reset_minus(d, r)).abs());
            magnitude = magnitude.max(self.plus[r].abs()).max(self.minus[r].abs());
        }
        if change <= 1e-12 * magnitude {
            return Outcome { grazing: None };
        }
        if closing.abs() <= GRAZING_SPEED * scale || !closing.is_finite() {
            return Outcome {
                grazing: Some(closing.abs()),
            };
        }
        // Taken out for the call (no copy: an empty vector in its place).
        let gradient = std::mem::take(&mut self.gradient);
        self.shift(d, closing, &gradient, out);
        self.gradient = gradient;
        Outcome { grazing: None }
    }

    /// The held located interaction's value (the static force less the
    /// force holding a stuck element, or a sticking pair's force plus the
    /// friction on its row) before the event: its gradient into
    /// `self.gradient`, and its rate along the flow before the event with
    /// the scale below which that rate is round-off. The gradient is a
    /// central difference in each coordinate (steps a millionth of the
    /// state's size, or of what the held force displaces: the force is
    /// affine in the state for a linear structure, where any step gives it
    /// to round-off), the time's a five-point one
    /// over a ten-thousandth of the system's time scale (a backward one
    /// within the last stretch of samples where a load is a record).
    fn margin(&mut self, system: &Assembly, view: &EventView<'_>) -> (f64, f64) {
        let (d, size) = (system.dim, 2 * system.dim);
        let y = view.before;
        let largest = |block: &[f64]| block.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let period = system.time_scale();
        let period = if period.is_finite() { period } else { 1.0 };
        // At least the displacement the held force makes over the time
        // scale's radian (a state near zero has no size of its own).
        let i = view.located;
        let force = system.static_force(i).max(system.friction_hold[i]);
        let radian = period / std::f64::consts::TAU;
        let pressed = force * system.interactions[i].inverse_mass * radian * radian;
        let length = largest(&y[..d])
            .max(largest(&y[d..size]) * radian)
            .max(pressed)
            .max(1e-12)
            * 1e-6;
        let mut point = y.to_vec();
        for j in 0..size {
            let step = if j < d { length } else { length / radian };
            point[j] = y[j] + step;
            let up = self.held_value(system, view, view.time, &point);
            point[j] = y[j] - step;
            let down = self.held_value(system, view, view.time, &point);
            point[j] = y[j];
            self.gradient[j] = (up - down) / (2.0 * step);
        }
        let step = 1e-4 * period;
        let at = |k: f64| view.time + k * step;
        // (Without loads the values are equal, and the rate exactly zero.)
        let by_time = if system.has_breakpoints() {
            // Loads interpolated between samples: the rate just before the
            // event, within the stretch of samples it ends in (a stencil
            // across a kink would mix two slopes): a backward difference of
            // second order, exact on a straight stretch.
            let mut back = step;
            let tiny = 1e-15 * period.max(view.time.abs());
            while system.next_breakpoint(view.time - 2.0 * back) < view.time && back > tiny {
                back *= 0.5;
            }
            let values =
                [0.0, 1.0, 2.0].map(|k| self.held_value(system, view, view.time - k * back, y));
            (3.0 * values[0] - 4.0 * values[1] + values[2]) / (2.0 * back)
        } else {
            let values = [-2.0, -1.0, 1.0, 2.0].map(|k| self.held_value(system, view, at(k), y));
            (values[0] - 8.0 * values[1] + 8.0 * values[2] - values[3]) / (12.0 * step)
        };
        let along = linalg::dot(&self.gradient, &self.minus[..size]);
        let scale = self
            .gradient
            .iter()
            .zip(&self.minus[..size])
            .fold(by_time.abs(), |m, (g, f)| m + (g * f).abs());
        (along + by_time, scale)
    }

    /// The located held interaction's event value at `(time, y)` in the
    /// modes before the event.
    fn held_value(&mut self, system: &Assembly, view: &EventView<'_>, time: f64, y: &[f64]) -> f64 {
        let room = (&mut self.full[..], &mut self.probe[..]);
        held_value(system, &mut self.scratch, room, view, (time, y))
    }

    /// The event's columns by the parameters into `out` (row-major `2 dim x
    /// m`), after [`Self::matrix`] of the same event: `W+ = S W- + out`.
    /// They hold the reset moved, `(dR/dp) v-`; the time shift moved by the
    /// located value's `dg/dp` (a gap's, a sliding speed's, a held force
    /// margin's in the shifted systems); and where pairs land at rest or
    /// start to stick, their gaps (and rates) held at zero from moved
    /// offsets, as are the rates of friction elements that start to stick.
    pub(super) fn parameter_columns(
        &mut self,
        system: &Assembly,
        parameters: &Parameters,
        view: &EventView<'_>,
        out: &mut [f64],
    ) {
        let (d, size, m) = (system.dim, 2 * system.dim, parameters.count());
        let sticking = sticking(view);
        let mut held = sticking.clone();
        held.extend(newly_stuck(view));
        let v_minus = &view.before[d..size];
        for (j, s) in parameters.shifted.iter().enumerate() {
            let mut column = std::mem::take(&mut self.parameter);
            column.iter_mut().for_each(|v| *v = 0.0);
            // (R(p + delta) - R(p - delta)) v- / (2 delta).
            let resets = if view.jumps.is_empty() {
                &[][..]
            } else {
                &[(&s.plus, 1.0), (&s.minus, -1.0)][..]
            };
            for &(other, sign) in resets {
                self.values.clear();
                self.values.extend(view.jumps.iter().map(|jump| {
                    let e = Parameters::restitution_in(system, other, jump);
                    (1.0 + e) * linalg::dot(&other.interactions[jump.interaction].h, v_minus)
                }));
                self.velocities.copy_from_slice(v_minus);
                push_back(
                    &other.interactions,
                    view.jumps,
                    &mut self.values,
                    &mut self.velocities,
                    &mut self.coupling,
                );
                for r in 0..d {
                    column[d + r] += sign * self.velocities[r] / (2.0 * s.delta);
                }
            }
            let moved = match self.value {
                Value::Gap => parameters.gap_by(j, view.located, view.before).0,
                Value::Speed => parameters.gap_by(j, view.located, view.before).1,
                Value::Margin => {
                    let mut by = [(&s.plus, 1.0), (&s.minus, -1.0)].map(|(other, sign)| {
                        let room = (&mut self.full[..], &mut self.probe[..]);
                        let scratch = &mut Scratch::new(other);
                        sign * held_value(other, scratch, room, view, (view.time, view.before))
                    });
                    by[0] += by[1];
                    by[0] / (2.0 * s.delta)
                }
            };
            for (value, jump) in column.iter_mut().zip(&self.jump) {
                *value += jump * moved;
            }
            if self.landed {
                self.values.clear();
                self.values.extend(view.jumps.iter().map(|jump| {
                    (1.0 + jump.restitution) * parameters.gap_by(j, jump.interaction, view.before).0
                }));
                let its = &system.interactions;
                push_back(
                    its,
                    view.jumps,
                    &mut self.values,
                    &mut column[..d],
                    &mut self.coupling,
                );
            }
            // Displacements held for sticking pairs; rates for them and for
            // friction elements that start to stick.
            for (block, list, state) in [(0, &sticking, view.before), (d, &held, view.after)] {
                if list.is_empty() {
                    continue;
                }
                self.reset_map(system, list);
                self.velocities.copy_from_slice(&column[block..block + d]);
                for (r, value) in column[block..block + d].iter_mut().enumerate() {
                    *value = linalg::dot(&self.reset[r * d..(r + 1) * d], &self.velocities);
                }
                self.values.clear();
                self.values.extend(list.iter().map(|jump| {
                    let moved = parameters.gap_by(j, jump.interaction, state);
                    if block == 0 {
                        moved.0
                    } else {
                        moved.1
                    }
                }));
                let its = &system.interactions;
                let part = &mut column[block..block + d];
                push_back(its, list, &mut self.values, part, &mut self.coupling);
            }
            for (r, value) in column.iter().enumerate() {
                out[r * m + j] = *value;
            }
            self.parameter = column;
        }
    }

    /// The rates at `time` in state `y` (`x` then `v`) and `modes`, into
    /// `self.plus` (`after`) or `self.minus`.
    fn rates(&mut self, system: &Assembly, time: f64, y: &[f64], modes: &[Mode], after: bool) {
        let size = 2 * system.dim;
        self.full[..size].copy_from_slice(y);
        let out = if after {
            &mut self.plus
        } else {
            &mut self.minus
        };
        system.rates(time, &self.full, modes, &mut self.scratch, out);
    }
}

/// The located held interaction's event value in `system` (the run's, or
/// one a parameter shifted, with its own `scratch`) at `(time, y)` in the
/// modes before `view`'s event: the static force less the force holding a
/// stuck element, or a sticking pair's force plus the friction on its row.
fn held_value(
    system: &Assembly,
    scratch: &mut Scratch,
    (full, probe): (&mut [f64], &mut [f64]),
    view: &EventView<'_>,
    (time, y): (f64, &[f64]),
) -> f64 {
    let i = view.located;
    full[..y.len()].copy_from_slice(y);
    system.rates(time, full, view.modes_before, scratch, probe);
    let force = scratch.force_of(i).unwrap_or(0.0);
    match view.modes_before[i] {
        Mode::Stuck { .. } => system.static_force(i) - force.abs(),
        _ => force + system.friction_hold[i],
    }
}

/// The friction elements `view`'s event left stuck, holding their rows
/// (not shadowed by a sticking pair), that were not (as jumps of
/// restitution 0: their rates' projection).
fn newly_stuck(view: &EventView<'_>) -> Vec<Jump> {
    let holds = |m: &Mode| {
        matches!(
            m,
            Mode::Stuck {
                shadowed: false,
                ..
            }
        )
    };
    (0..view.modes_after.len())
        .filter(|&i| holds(&view.modes_after[i]) && !holds(&view.modes_before[i]))
        .map(|interaction| Jump {
            interaction,
            restitution: 0.0,
            struck: false,
        })
        .collect()
}

/// The pairs of `view`'s event that start to stick (as jumps of restitution
/// 0: their constraints' projection).
fn sticking(view: &EventView<'_>) -> Vec<Jump> {
    view.jumps
        .iter()
        .filter(|j| view.modes_after[j.interaction] == Mode::Sticking)
        .map(|j| Jump {
            interaction: j.interaction,
            restitution: 0.0,
            struck: false,
        })
        .collect()
}

/// `out -= sum_a push_a z_a` with `W z = values` (`W_ab = h_a . push_b`
/// over the pairs `jumps`): what moves those pairs' gaps (or their rates,
/// `out` velocities) by `-values` (`values` is overwritten).
fn push_back(
    its: &[Interaction],
    jumps: &[Jump],
    values: &mut [f64],
    out: &mut [f64],
    coupling: &mut Vec<f64>,
) {
    let m = jumps.len();
    if m == 0 {
        return;
    }
    coupling.clear();
    for a in jumps {
        for b in jumps {
            coupling.push(linalg::dot(&its[a.interaction].h, &its[b.interaction].push));
        }
    }
    linalg::solve_in_place(coupling, values, m);
    for (jump, z) in jumps.iter().zip(values.iter()) {
        for (value, p) in out.iter_mut().zip(&its[jump.interaction].push) {
            *value -= p * z;
        }
    }
}
