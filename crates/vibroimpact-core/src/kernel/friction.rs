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
    pub(super) fn settle_friction(&mut self, time: f64) {
        let system = self.system;
        for i in 0..self.modes.len() {
            // One switched at this event (a slip located where its holding force
            // passes the static force) keeps what the switch chose.
            if !system.interactions[i].law.is_friction() || self.just_switched[i] {
                continue;
            }
            let rate = system.gap(i, &self.y).1;
            let at_rest = rate.abs() <= system.rate_round_off(i, &self.y);
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
                _ => self.stick_or_slide(i, time),
            }
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
        let force = self.holding_force(i, time);
        if force.abs() <= system.static_force(i) {
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
        } else {
            self.slide(i, time, -force.signum());
        }
    }

    /// Friction element `i` sliding along `direction` from `time`: a stuck
    /// interval it was in is recorded.
    fn slide(&mut self, i: usize, time: f64, direction: f64) {
        let direction = if direction < 0.0 { -1.0 } else { 1.0 };
        self.modes[i] = Mode::Sliding { direction };
        if let Some(record) = self.open[i].take() {
            let pair = self.system.interactions[i].pair;
            self.contacts.push(record.close(pair, time, 0.0, 0.0));
        }
    }
}
