//! The approach rates the hysteretic laws latch at a contact's onset: the
//! force `K delta^1.5 (1 + alpha delta' / v0)` remembers `v0`, the closing
//! speed at the onset, which is a function of the state there. The tangent
//! flow carries its derivative by the start state as a row `L_i` for each
//! latching interaction: set at the onset from the state's derivative there
//! (the event's time shift included), `L_i = c_i Phi(t_e-)` with
//! `c_i = -[0, h] + (h . a- / h . v-) [h, 0]`; in contact the variational
//! equations gain `B_i L_i`, `B_i` the accelerations' derivative by `v0`
//! (`M^-1 h^T dF/dv0`), so each step's factor has a gain `G` besides its
//! `F`: `Phi <- F Phi + G L`.

use crate::model::assembly::{Assembly, InteractionLaw, Mode, Scratch};
use crate::model::contact::AnyLaw;
use crate::numerics::linalg;

/// What an onset's row is the derivative of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum OnsetRow {
    /// The closing speed (the rate latched).
    Closing,
    /// The law's floor, latched where the landing is slower.
    Floor,
    /// Neither: no derivative (a grazing).
    Undefined,
}

/// The latched rates' rows and the buffers their onsets need.
pub(super) struct Latched {
    /// Whether each interaction's law latches its approach rate.
    pub(super) which: Vec<bool>,
    /// `L`: row-major `interactions x 2 dim` (zero for those that do not
    /// latch, or are not in contact).
    pub(super) rows: Vec<f64>,
    /// A step's gain `G`: row-major `2 dim x interactions`.
    pub(super) gain: Vec<f64>,
    scratch: Scratch,
    full: Vec<f64>,
    rates: Vec<f64>,
    row: Vec<f64>,
    /// The last onset's `c_i` (the latched rate's derivative by the state
    /// just before it) and its time shift's part: the latched rate's change
    /// per unit of the gap's change at a fixed state (`h . a- / h . v-` for
    /// a closing speed): a parameter's column reads them.
    pub(super) onset_row: Vec<f64>,
    pub(super) onset_shift: f64,
}

impl Latched {
    /// None where no law latches.
    pub(super) fn new(system: &Assembly) -> Option<Self> {
        let which: Vec<bool> = system
            .interactions()
            .iter()
            .map(|it| it.law.latches())
            .collect();
        if !which.iter().any(|w| *w) {
            return None;
        }
        let (count, size) = (which.len(), 2 * system.dim);
        Some(Self {
            which,
            rows: vec![0.0; count * size],
            gain: vec![0.0; size * count],
            scratch: Scratch::new(system),
            full: vec![0.0; system.state_len()],
            rates: vec![0.0; system.state_len()],
            row: vec![0.0; size],
            onset_row: vec![0.0; size],
            onset_shift: 0.0,
        })
    }

    /// `dF/dv0` of interaction `i` (N s/m) at state `y` in `mode`: 0 apart
    /// or where the law does not latch.
    pub(super) fn force_by_rate(system: &Assembly, i: usize, y: &[f64], mode: Mode) -> f64 {
        let it = &system.interactions()[i];
        let (Mode::Compliant { approach_rate, .. }, InteractionLaw::Compliant { law, .. }) =
            (mode, it.law)
        else {
            return 0.0;
        };
        let (gap, rate) = system.gap(i, y);
        law.force_by_approach_rate(-gap, -rate, approach_rate)
    }

    /// At the run's start: a contact resumed there latched the state's own
    /// closing speed `|h . v|`, whose row is `sign(h . v) [0, h]`; one
    /// carried from the run before (its rate not the state's) has none.
    pub(super) fn resume(&mut self, system: &Assembly, y: &[f64], modes: &[Mode]) {
        let (d, size) = (system.dim, 2 * system.dim);
        self.rows.iter_mut().for_each(|v| *v = 0.0);
        for (i, mode) in modes.iter().enumerate() {
            if let (true, Mode::Compliant { approach_rate, .. }) = (self.which[i], mode) {
                let (_, rate) = system.gap(i, y);
                if (approach_rate - rate.abs()).abs() > 1e-12 * approach_rate {
                    continue;
                }
                let h = &system.interactions()[i].h;
                for (c, hc) in h.iter().enumerate() {
                    self.rows[i * size + d + c] = rate.signum() * hc;
                }
            }
        }
    }

    /// Interaction `i`'s contact starts at `time` from the state `before`
    /// (`x` then `v`) in `modes_before`, its latched rate `latched`: its row
    /// is `c_i (stretch matrix)`, `stretch` the flow since the last factor
    /// (None: none). Where the rate latched is the floor of a landing slower
    /// than the pressing's rate ([`crate::model::contact::AnyLaw::latched_approach_rate`]),
    /// `c_i` is the floor's derivative ([`Self::floor_row`]); where neither
    /// (no closing speed), no derivative: its row zero.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn onset(
        &mut self,
        system: &Assembly,
        (time, before, modes_before): (f64, &[f64], &[Mode]),
        i: usize,
        latched: f64,
        stretch: Option<&[f64]>,
        matrix: &[f64],
    ) -> OnsetRow {
        let (d, size) = (system.dim, 2 * system.dim);
        let h = &system.interactions()[i].h;
        let closing = -linalg::dot(h, &before[d..size]);
        let row = &mut self.rows[i * size..(i + 1) * size];
        row.iter_mut().for_each(|v| *v = 0.0);
        if closing.is_nan() || closing <= 0.0 {
            return OnsetRow::Undefined;
        }
        self.full[..size].copy_from_slice(before);
        let kind = if latched > closing * (1.0 + 1e-12) {
            if !self.floor_row(system, (time, modes_before), i, latched, closing) {
                return OnsetRow::Undefined;
            }
            OnsetRow::Floor
        } else {
            system.rates(
                time,
                &self.full,
                modes_before,
                &mut self.scratch,
                &mut self.rates,
            );
            let shift = linalg::dot(h, &self.rates[d..size]) / -closing;
            // c_i, then times the stretch.
            self.row.iter_mut().for_each(|v| *v = 0.0);
            for (c, hc) in h.iter().enumerate() {
                self.row[c] = shift * hc;
                self.row[d + c] = -hc;
            }
            self.onset_row.copy_from_slice(&self.row);
            self.onset_shift = shift;
            OnsetRow::Closing
        };
        if let Some(stretch) = stretch {
            let c_i = self.row.clone();
            for (col, out) in self.row.iter_mut().enumerate() {
                *out = (0..size).map(|k| c_i[k] * stretch[k * size + col]).sum();
            }
        }
        let row = &mut self.rows[i * size..(i + 1) * size];
        for (col, out) in row.iter_mut().enumerate() {
            *out = (0..size)
                .map(|k| self.row[k] * matrix[k * size + col])
                .sum();
        }
        kind
    }

    /// `c_i` into `self.row` where interaction `i`'s latched rate is its
    /// law's floor `r = sqrt(2 a delta_s)`, `a` the pressing (the gap's
    /// acceleration `G` negated) at the onset state in `self.full`, which
    /// `r` goes as `a^(5/6)`: `dr = -(5/6) (r / a) (dG/dy dy + G' dt)`, the
    /// onset's time shift `dt = h . dx / closing` (`G'` along the flow).
    /// `dG/dy` and `G'` by central differences (`G` is linear in the state
    /// where no other contact is on). False where the latched rate is not
    /// that floor.
    fn floor_row(
        &mut self,
        system: &Assembly,
        (time, modes): (f64, &[Mode]),
        i: usize,
        latched: f64,
        closing: f64,
    ) -> bool {
        let (d, size) = (system.dim, 2 * system.dim);
        let mut work = vec![0.0; system.state_len()];
        let mut gap_acceleration = |y: &[f64], t: f64, scratch: &mut Scratch| {
            system.gap_acceleration(i, t, y, modes, scratch, &mut work)
        };
        let Some((floor, pressing)) =
            floor_of(system, i, (time, &self.full, modes), &mut self.scratch)
        else {
            return false;
        };
        if (latched - floor).abs() > 1e-9 * floor {
            return false;
        }
        let factor = -(5.0 / 6.0) * floor / pressing;
        let mut moved = self.full.clone();
        // dG/dy, a column at a time.
        for k in 0..size {
            let block = if k < d { 0..d } else { d..size };
            let largest = self.full[block].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let step = 1e-6 * self.full[k].abs().max(1e-3 * largest).max(1e-300);
            moved[k] = self.full[k] + step;
            let up = gap_acceleration(&moved, time, &mut self.scratch);
            moved[k] = self.full[k] - step;
            let down = gap_acceleration(&moved, time, &mut self.scratch);
            moved[k] = self.full[k];
            self.row[k] = (up - down) / (2.0 * step);
        }
        // G' along the flow: the state moved by its rates over +-tau.
        system.rates(time, &self.full, modes, &mut self.scratch, &mut self.rates);
        let tau = 1e-6 * system.sticking_step.min(system.longest_period);
        let mut along = |sign: f64, scratch: &mut Scratch| {
            for (out, (y, r)) in moved
                .iter_mut()
                .zip(self.full.iter().zip(&self.rates))
                .take(size)
            {
                *out = y + sign * tau * r;
            }
            gap_acceleration(&moved, time + sign * tau, scratch)
        };
        let up = along(1.0, &mut self.scratch);
        let down = along(-1.0, &mut self.scratch);
        let rate = (up - down) / (2.0 * tau);
        let h = &system.interactions()[i].h;
        for (k, out) in self.row.iter_mut().enumerate().take(size) {
            let shifted = if k < d { rate * h[k] / closing } else { 0.0 };
            *out = factor * (*out + shifted);
        }
        // A parameter that moves the gap moves the onset by `dg/dp /
        // closing`, the floor with it along the flow.
        self.onset_row.copy_from_slice(&self.row);
        self.onset_shift = factor * rate / closing;
        self.row.iter().all(|v| v.is_finite()) && self.onset_shift.is_finite()
    }

    /// Interaction `i`'s contact ends: its rate is read no more.
    pub(super) fn separation(&mut self, i: usize, size: usize) {
        self.rows[i * size..(i + 1) * size]
            .iter_mut()
            .for_each(|v| *v = 0.0);
    }

    /// `product += G L` (row-major `size x size`).
    pub(super) fn add_gain(&self, product: &mut [f64], size: usize) {
        let count = self.which.len();
        for r in 0..size {
            for i in 0..count {
                let g = self.gain[r * count + i];
                if g == 0.0 {
                    continue;
                }
                for c in 0..size {
                    product[r * size + c] += g * self.rows[i * size + c];
                }
            }
        }
    }
}

/// Interaction `i`'s floor `sqrt(2 a delta_s)` ([`crate::model::contact::HysterHertz::resting_approach_rate`])
/// and the pressing `a` (m/s^2, the gap's acceleration negated) it is made
/// from, at `time`, state `y` (its full length) in `modes`: None where the
/// law has no floor there (not hysteretic, not pressed).
pub(super) fn floor_of(
    system: &Assembly,
    i: usize,
    (time, y, modes): (f64, &[f64], &[Mode]),
    scratch: &mut Scratch,
) -> Option<(f64, f64)> {
    let it = &system.interactions()[i];
    let InteractionLaw::Compliant {
        law: AnyLaw::HysterHertz(law),
        ..
    } = it.law
    else {
        return None;
    };
    let mut work = vec![0.0; system.state_len()];
    let pressing = -system.gap_acceleration(i, time, y, modes, scratch, &mut work);
    let floor = law.resting_approach_rate(1.0 / it.inverse_mass, pressing);
    (pressing > 0.0 && floor > 0.0).then_some((floor, pressing))
}
