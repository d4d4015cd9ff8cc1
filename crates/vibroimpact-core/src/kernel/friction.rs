//! Dry friction's stick-slip at events. A sliding element whose speed
//! reaches zero sticks if the force that holds it there is within its static
//! force, else slides back the way that force drives it; a stuck element
//! slips where its holding force passes the static force (the event kernel
//! locates both, [`crate::kernel::locate::event_value`]). An impact jumps
//! the velocities: each element's mode is then taken afresh from its
//! sliding speed ([`Run::settle_friction`]).

use crate::kernel::contact_balance::OnsetBalance;
use crate::kernel::events::{ContactKind, Open};
use crate::kernel::locate::constraint_force;
use crate::kernel::run::Run;
use crate::model::assembly::{h_dot, same_row, Mode};

impl Run<'_> {
    /// Friction element `i` at its own event at `time`: a sliding one came
    /// to rest (stick, or slide back), a stuck one's holding force passed
    /// the static force (slip).
    pub(super) fn friction_switch(&mut self, i: usize, time: f64) {
        match self.modes[i] {
            Mode::Stuck { .. } => {
                let force = self.holding_force(i, time);
                self.slide(i, time, -force.signum());
            }
            _ => self.stick_or_slide(i, time),
        }
    }

    /// Every friction element's mode after an event (an impact changed the
    /// velocities, a rigid pair that shadows one began or ended sticking),
    /// and at the start.
    /// `impulses`: the largest speed before the event's impulses (m/s; 0
    /// where none acted), whose round-off an impulse leaves in every rate.
    pub(super) fn settle_friction(&mut self, time: f64, impulses: f64) {
        let system = self.system;
        let d = system.dim;
        // The speeds in play (the state's, and its displacements' over the
        // system's time scale): a rate this far below them is at rest, though
        // a state come to rest holds round-off far below its own magnitudes.
        let speeds = self.y[d..2 * d].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let reach = self.y[..d].iter().fold(0.0f64, |m, x| m.max(x.abs())) / system.time_scale();
        let in_play = 64.0 * f64::EPSILON * (speeds + reach);
        for i in 0..self.modes.len() {
            // One switched at this event (a slip located where its holding force
            // passes the static force) keeps what the switch chose.
            if !system.interactions[i].law.is_friction() || self.just_switched[i] {
                continue;
            }
            let rate = system.gap(i, &self.y).1;
            // After an impulse a row brought to rest keeps the impulse's
            // round-off (a plastic landing on a wall on the row): at rest
            // within it, as the impacts judge rest (else its sign would
            // choose a slide, and the run would not be continuous in its
            // start).
            let row: f64 = system.interactions[i].h.iter().map(|h| h.abs()).sum();
            let round_off = system
                .rate_round_off(i, &self.y)
                .max(1e-9 * impulses * row)
                .max(in_play * row);
            // A stuck element's constraint holds its rate at zero: without an
            // impulse its rate is the integration's drift, not a slide (its
            // slip is its holding force passing the static force).
            let held = impulses == 0.0 && matches!(self.modes[i], Mode::Stuck { .. });
            let at_rest = held || rate.abs() <= round_off;
            match self.modes[i] {
                _ if !at_rest => self.slide(i, time, rate.signum()),
                Mode::Stuck { shadowed, offset } => match (shadowed, self.shadowed(i)) {
                    // The wall that held the row let go: the force holding the
                    // pair passed the static force there, so the element slips.
                    (true, false) => {
                        self.modes[i] = Mode::Stuck {
                            offset,
                            shadowed: false,
                        };
                        let force = self.holding_force(i, time);
                        self.slide(i, time, -force.signum());
                    }
                    (false, true) => {
                        self.modes[i] = Mode::Stuck {
                            offset,
                            shadowed: true,
                        }
                    }
                    _ => {}
                },
                // Held for now: which of the elements at rest slide is
                // decided with all of them in place (below), not one by
                // one in the rows' order (a damper judged before the
                // ground's element it rides on would be judged without
                // that element's sliding force).
                _ => self.stick(i, time),
            }
        }
        self.release_overloaded(time);
    }

    /// At the start of a run with friction: rigid pairs on their walls
    /// resolved at once, as an event would resolve them there (one at rest
    /// and pressed sticks, with no impulse), and the elements settled again
    /// with them in place. Left to the first step, a body resting at t = 0 on
    /// one that friction holds fell for that step's round-off, and its
    /// landing, 1e-10 m/s, jolted the held body into a slide that kinetic
    /// friction could not stop (a stack static friction holds slid away).
    pub(super) fn rest_at_start(&mut self) {
        let system = self.system;
        let mut rigid = false;
        for i in 0..self.modes.len() {
            if self.on_wall_at_start[i] && !system.held_by_mirror(i, &self.modes) {
                rigid |= self.impacts.mark(system, i, self.modes[i]);
            }
        }
        if !rigid {
            return;
        }
        self.just_switched.iter_mut().for_each(|s| *s = false);
        let scales = (
            self.resolution,
            self.schedule.chatter_interval(0.0),
            self.schedule.time_scale,
        );
        self.resolve_marked(0.0, scales, false);
        self.settle_friction(0.0, self.impacts.speed_scale());
    }

    /// Stuck elements whose holding force passes their static force once
    /// the event's switches are made (an element that stuck loads another
    /// on a coupled row) slide, the most overloaded first, until the rest
    /// hold: the event ends in modes that hold, not in a stuck interval of
    /// no length followed by a slip at the same instant.
    fn release_overloaded(&mut self, time: f64) {
        let system = self.system;
        for _ in 0..self.modes.len() {
            if !self.modes.iter().any(|m| {
                matches!(
                    m,
                    Mode::Stuck {
                        shadowed: false,
                        ..
                    }
                )
            }) {
                return;
            }
            let work = &mut self.buffers.work;
            system.rates(time, &self.y, &self.modes, &mut self.scratch, work);
            let mut worst: Option<(usize, f64, f64)> = None;
            for (i, mode) in self.modes.iter().enumerate() {
                if !matches!(
                    mode,
                    Mode::Stuck {
                        shadowed: false,
                        ..
                    }
                ) {
                    continue;
                }
                let force = self.scratch.force_of(i).unwrap_or(0.0);
                let held = system.static_force(i);
                let excess = force.abs() - held;
                if excess > 1e-12 * held && worst.is_none_or(|(_, most, _)| excess > most) {
                    worst = Some((i, excess, force));
                }
            }
            let Some((i, _, force)) = worst else {
                return;
            };
            self.slide(i, time, -force.signum());
            self.just_switched[i] = true;
        }
    }

    /// Whether a sticking rigid pair holds friction element `i`'s row (the
    /// same relative coordinate, either sign).
    fn shadowed(&self, i: usize) -> bool {
        let system = self.system;
        let h = &system.interactions[i].h;
        system
            .interactions
            .iter()
            .zip(&self.modes)
            .any(|(it, mode)| *mode == Mode::Sticking && same_row(h, &it.h))
    }

    /// The force that holds friction element `i` stuck at `time` (N, along
    /// its row), in the modes as they are.
    fn holding_force(&mut self, i: usize, time: f64) -> f64 {
        constraint_force(
            self.system,
            i,
            (time, &self.y, &self.modes),
            &mut self.scratch,
            &mut self.buffers.work,
        )
    }

    /// Friction element `i`, at rest to round-off: stuck at its place (its
    /// speed set to zero by the least change of the velocities) if the force
    /// that holds it there is within its static force, else sliding the way
    /// that force would not hold it.
    fn stick_or_slide(&mut self, i: usize, time: f64) {
        self.stick(i, time);
        let force = self.holding_force(i, time);
        if force.abs() > self.system.static_force(i) {
            self.slide(i, time, -force.signum());
        }
    }

    /// Friction element `i`, at rest to round-off, stuck at its place (its
    /// speed set to zero by the least change of the velocities), a stuck
    /// interval begun where it was not stuck.
    fn stick(&mut self, i: usize, time: f64) {
        let system = self.system;
        let it = &system.interactions[i];
        let d = system.dim;
        let rate = h_dot(&it.h, &self.y[d..2 * d]);
        // An impulse of round-off along the row: the momentum it changes is
        // the round-off's.
        let impulse = rate / it.inverse_mass;
        for (v, p) in self.y[d..2 * d].iter_mut().zip(&it.push) {
            *v -= p * impulse;
        }
        let was = self.modes[i];
        self.modes[i] = Mode::Stuck {
            offset: -h_dot(&it.h, &self.y[..d]),
            shadowed: self.shadowed(i),
        };
        if !matches!(was, Mode::Stuck { .. }) || self.open[i].is_none() {
            self.open[i] = Some(Open {
                kind: ContactKind::Sticking,
                onset: time,
                approach_speed: 0.0,
                max_indentation: 0.0,
                dissipated: 0.0,
                resting: true,
                balance: OnsetBalance::default(),
                energy: f64::NAN,
                power: 0.0,
            });
        }
    }

    /// Friction element `i` sliding along `direction` from `time`: a stuck
    /// interval it was in is recorded.
    fn slide(&mut self, i: usize, time: f64, direction: f64) {
        let direction = if direction < 0.0 { -1.0 } else { 1.0 };
        self.modes[i] = Mode::Sliding { direction };
        if let Some(record) = self.open[i].take().filter(|r| r.onset < time) {
            // (One stuck at this instant and sliding again was not held.)
            let pair = self.system.interactions[i].pair;
            self.contacts.push(record.close(pair, time, 0.0, 0.0));
        }
    }
}
