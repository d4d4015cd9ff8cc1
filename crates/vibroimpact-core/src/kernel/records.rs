//! What a run keeps after each step, within its limits: stroboscopic
//! states, history rows, room for the contacts, and the checks every step
//! passes (rows, stalls, the energy balance, steps, interrupts); and the
//! solution at the end.

use crate::error::{Error, Result};
use crate::kernel::balance::balance;
use crate::kernel::clock::{Stop, STALLED_STEPS};
use crate::kernel::events::SystemSolution;
use crate::kernel::fixed;
use crate::kernel::memory::{self, NoRoom, FIRST_ROWS};
use crate::kernel::run::{loss_slot, poll_due, Run};
use crate::methods::steppers::SystemStepper;

/// The longest a large system goes without asking whether to stop, s.
const POLL_SECONDS: f64 = 0.2;

impl Run<'_> {
    /// Bytes held by the records other than the history (strobes, contacts).
    fn others(&self) -> u64 {
        memory::held(&self.reductions.strobe)
            + memory::held(&self.reductions.strobe_time)
            + memory::held(&self.contacts)
    }

    /// The error of a run whose records find no room at `time`, with what
    /// they hold.
    fn no_room(&self, cause: NoRoom, time: f64) -> Error {
        let held = self.others() + memory::held(&self.time_rows) + memory::held(&self.states);
        cause.error(
            time,
            (
                self.time_rows.len() as u64,
                self.reductions.strobe_time.len() as u64,
            ),
            2 * self.system.dim as u64 + 1,
            self.contacts.len() as u64,
            held,
        )
    }

    /// A history row of the state now, at `time`.
    pub(super) fn push_history_row(&mut self, time: f64) -> Result<()> {
        let row = 2 * self.system.dim;
        let (strobe, strobe_time) = (&self.reductions.strobe, &self.reductions.strobe_time);
        let contacts = &self.contacts;
        memory::push_row(
            &mut self.time_rows,
            &mut self.states,
            (time, &self.y[..row]),
            self.first_rows,
            || memory::held(strobe) + memory::held(strobe_time) + memory::held(contacts),
            self.record_limit,
        )
        .map_err(|cause| self.no_room(cause, time))?;
        self.push_contact_forces(time)
    }

    /// The force of each pair with a compliant wall at the state now, a
    /// row of the history's contact-force column.
    fn push_contact_forces(&mut self, time: f64) -> Result<()> {
        let (system, pairs) = (self.system, self.force_pairs.len());
        if pairs == 0 {
            return Ok(());
        }
        let (rows, states) = (&self.time_rows, &self.states);
        let (strobe, contacts) = (&self.reductions.strobe, &self.contacts);
        let held = || {
            memory::held(rows)
                + memory::held(states)
                + memory::held(strobe)
                + memory::held(contacts)
        };
        memory::make_room(
            &mut self.contact_forces,
            pairs,
            pairs,
            held,
            self.record_limit,
        )
        .map_err(|cause| self.no_room(cause, time))?;
        let at = self.contact_forces.len();
        self.contact_forces.resize(at + pairs, 0.0);
        for (i, it) in system.interactions.iter().enumerate() {
            if let Some(column) = self.force_pairs.iter().position(|&p| p == it.pair) {
                let force = fixed::contact_force(system, i, &self.y, self.modes[i]);
                self.contact_forces[at + column] += force;
            }
        }
        Ok(())
    }

    /// The records after a kept step (a stroboscopic state, a history row,
    /// room for the next step's contacts) and the checks every kept step
    /// passes (rows, stalls, the energy balance, steps, interrupts); `stop`
    /// is why the step ended.
    pub(super) fn after_step(
        &mut self,
        stop: Stop,
        interrupt: &mut dyn FnMut() -> bool,
    ) -> Result<()> {
        let (schedule, time) = (self.schedule, self.clock.time);
        let row = 2 * self.system.dim;
        if schedule.strobe_due(&self.clock, time) {
            let (rows, states, contacts) = (&self.time_rows, &self.states, &self.contacts);
            memory::push_row(
                &mut self.reductions.strobe_time,
                &mut self.reductions.strobe,
                (time, &self.y[..row]),
                FIRST_ROWS,
                || memory::held(rows) + memory::held(states) + memory::held(contacts),
                self.record_limit,
            )
            .map_err(|cause| self.no_room(cause, time))?;
            self.clock.next_strobe =
                (self.reductions.strobe_time.len() + 1) as f64 * schedule.strobe_period;
        }
        let done = schedule.done(time);
        // Counts down only while it matters (no history: it stays at 0).
        self.clock.until_kept = self.clock.until_kept.saturating_sub(1);
        if schedule.keep_history && (self.clock.until_kept == 0 || done) {
            self.clock.until_kept = schedule.every;
            self.push_history_row(time)?;
        }
        // Room for the contacts the next step may close (a Vec's own
        // doubling could pass the limit, or abort where memory is refused).
        let (strobe, strobe_time) = (&self.reductions.strobe, &self.reductions.strobe_time);
        let (rows, states) = (&self.time_rows, &self.states);
        let held = || {
            memory::held(strobe)
                + memory::held(strobe_time)
                + memory::held(rows)
                + memory::held(states)
        };
        let more = 2 * self.modes.len() + 2;
        memory::make_room(&mut self.contacts, more, 8, held, self.record_limit)
            .map_err(|cause| self.no_room(cause, time))?;
        let rows = self.time_rows.len() + self.contacts.len() + self.reductions.strobe_time.len();
        if rows as u64 > self.options.max_rows {
            return Err(self.row_limit(rows as u64, time));
        }
        self.check_step(matches!(stop, Stop::Event { .. }), done, interrupt)
    }

    /// The run's `rows` (history, strobes and contacts) passed `max_rows` at
    /// `time`: the error counts what fit (the rows and contacts this step
    /// added past the cap are not kept) and says what to change.
    #[cold]
    fn row_limit(&self, rows: u64, time: f64) -> Error {
        let (max_rows, over) = (self.options.max_rows, rows - self.options.max_rows);
        let history = self.time_rows.len() as u64;
        let kept_rows = history.saturating_sub(over);
        let contacts = (self.contacts.len() as u64).saturating_sub(over - (history - kept_rows));
        let contacts_alone = !self.schedule.keep_history && self.reductions.strobe_time.is_empty();
        Error::RowLimit {
            time,
            max_rows,
            rows: kept_rows,
            contacts,
            advice: if contacts_alone {
                "the contacts alone fill it: shorten t_end or raise max_rows"
            } else {
                "raise every, set history = false, shorten t_end or raise max_rows"
            },
        }
    }

    /// The checks after a kept step (`event`: one that ended on an event;
    /// `done`: the run's last).
    fn check_step(
        &mut self,
        event: bool,
        done: bool,
        interrupt: &mut dyn FnMut() -> bool,
    ) -> Result<()> {
        let (time, taken, accepted) = (self.clock.time, self.taken, self.clock.accepted);
        // Steps within a thousand units of round-off of the time make no
        // progress: an event that recurs at once (a zero clearance, say)
        // would otherwise loop. (An adaptive method's own short steps, from
        // a tiny first step, grow.)
        // A step that did not move the time at all, whatever ended it, makes
        // none next either (a step size fallen to 0 had looped forever).
        let frozen = taken <= 0.0 && !event;
        if frozen
            || taken <= self.schedule.chatter_interval(time) && (event || !self.schedule.adaptive)
        {
            self.stalled += 1;
            if self.stalled >= STALLED_STEPS {
                return Err(if frozen {
                    Error::StepSizeTooSmall { time, step: taken }
                } else {
                    Error::Chattering {
                        time,
                        events: self.stalled,
                        interval: taken,
                    }
                });
            }
        } else {
            self.stalled = 0;
        }
        // The balance is checked every few steps and at the end; the energy
        // in play is sampled between, by the clock (see EnergySampler).
        self.energy
            .after_step(self.system, (&self.y, &self.modes), accepted, done, time)?;
        let max_steps = self.options.max_steps;
        if !done && accepted + self.control.rejected >= max_steps {
            return Err(Error::TooManySteps { time, max_steps });
        }
        // Large systems poll by the clock too: a step of hundreds of sticking
        // pairs (a constraint solve in each stage) takes a tenth of a second.
        let due = poll_due(accepted, self.poll_every)
            || (self.timed_polls && self.last_poll.elapsed().as_secs_f64() >= POLL_SECONDS);
        if due {
            self.last_poll = std::time::Instant::now();
            if interrupt() {
                return Err(Error::Interrupted { time });
            }
        }
        Ok(())
    }

    /// The solution: the contacts still open closed at NaN, those before
    /// the kept ones dropped, all in order of onset.
    pub(super) fn finish<S: SystemStepper>(mut self, stepper: &S) -> SystemSolution {
        let open_contacts = self.open_contacts();
        self.close_open();
        let from = self.options.reduce.contacts_from;
        if from > f64::NEG_INFINITY {
            self.contacts.retain(|c| c.onset >= from);
        }
        self.contacts.sort_by(|a, b| a.onset.total_cmp(&b.onset));
        let system = self.system;
        let energy = balance(
            system,
            &self.y,
            system.energy(&self.y, &self.modes),
            self.energy.stored_start,
            self.energy.impact_loss,
        );
        let row = 2 * system.dim;
        // The friction elements' losses over the window: at the end less at
        // its start.
        let at = loss_slot(system, 0);
        for (loss, end) in self.reductions.window_losses.iter_mut().zip(&self.y[at..]) {
            *loss = end - *loss;
        }
        SystemSolution {
            time: self.time_rows,
            states: self.states,
            contacts: self.contacts,
            final_state: self.y[..row].to_vec(),
            final_time: self.clock.time,
            energy_growth: self.energy.extremes.growth(
                system,
                energy.stored_start,
                energy.stored_end,
            ),
            energy_residual: self.energy.extremes.residual,
            energy,
            steps: self.clock.accepted,
            rejected_steps: self.control.rejected,
            rhs_evaluations: stepper.evaluations(),
            grazing_contacts: self.grazes,
            reductions: self.reductions,
            contact_force_pairs: self.force_pairs,
            contact_forces: self.contact_forces,
            open_contacts,
        }
    }
}
