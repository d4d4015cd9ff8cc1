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
use crate::numerics::linalg;

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
    /// just before it) and its time shift's part, `h . a- / h . v-` (per
    /// unit of the gap's change): a parameter's column reads them.
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
    /// (None: none). False where the rate latched is not the closing speed
    /// (a landing slower than the pressing's rate, [`crate::model::contact::AnyLaw::latched_approach_rate`]):
    /// no derivative, its row zero.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn onset(
        &mut self,
        system: &Assembly,
        (time, before, modes_before): (f64, &[f64], &[Mode]),
        i: usize,
        latched: f64,
        stretch: Option<&[f64]>,
        matrix: &[f64],
    ) -> bool {
        let (d, size) = (system.dim, 2 * system.dim);
        let h = &system.interactions()[i].h;
        let closing = -linalg::dot(h, &before[d..size]);
        let row = &mut self.rows[i * size..(i + 1) * size];
        row.iter_mut().for_each(|v| *v = 0.0);
        if closing.is_nan() || closing <= 0.0 || latched > closing * (1.0 + 1e-12) {
            return false;
        }
        self.full[..size].copy_from_slice(before);
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
        if let Some(stretch) = stretch {
            let c_i = self.row.clone();
            for (col, out) in self.row.iter_mut().enumerate() {
                *out = (0..size).map(|k| c_i[k] * stretch[k * size + col]).sum();
            }
        }
        for (col, out) in row.iter_mut().enumerate() {
            *out = (0..size)
                .map(|k| self.row[k] * matrix[k * size + col])
                .sum();
        }
        true
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
