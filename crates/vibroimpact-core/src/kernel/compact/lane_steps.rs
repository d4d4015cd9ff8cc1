//! What a plain fixed step does beside the RK4 step itself, for every lane
//! at once: the walls' gaps at its end, whether it is plain (the rule of
//! [`Compact::fixed_stretch`](super::Compact): finite, no contact begun or
//! ended, no observed velocity changing sign in the recorded window) and
//! its reductions (peaks, mean squares, recorded time) as
//! [`crate::kernel::reductions::reduce_step`] adds them, term for term and
//! in the same order, each over an array of lanes.

#![allow(clippy::needless_range_loop)]

use super::lanes::{
    each_lane, lanes_where, Group, LaneLaw, LaneModes, LaneState, LaneStep, LANES, MAX_OBSERVED, V,
};
use super::MAX_WALLS;
use crate::kernel::reductions::{quintic, square_integral};

/// Each wall's gap and rate, per lane.
pub(crate) type LaneGaps = [[V; 2]; MAX_WALLS];

/// What the lanes keep of each run between the kernel's steps: the state,
/// its walls' gaps, and the reductions.
pub(crate) struct LaneRuns {
    pub(crate) y: Box<LaneState>,
    pub(crate) gaps: LaneGaps,
    pub(crate) peaks: [V; MAX_OBSERVED],
    pub(crate) squares: [V; MAX_OBSERVED],
    pub(crate) recorded: V,
    /// The rates at the last step's end (the mean squares' accelerations,
    /// and the next step's first stage), for the lanes whose last step made
    /// them (the lockstep's `end_rates`; a first stage swapped in otherwise).
    pub(crate) end_rates: Box<LaneState>,
}

impl Default for LaneRuns {
    fn default() -> Self {
        Self {
            y: LaneStep::state(),
            gaps: [[[0.0; LANES]; 2]; MAX_WALLS],
            peaks: [[0.0; LANES]; MAX_OBSERVED],
            squares: [[0.0; LANES]; MAX_OBSERVED],
            recorded: [0.0; LANES],
            end_rates: LaneStep::state(),
        }
    }
}

/// What a plain step of the lanes reads besides their runs.
pub(crate) struct PlainStep<'s> {
    pub(crate) h: f64,
    pub(crate) modes: &'s LaneModes,
    /// Each wall's contact per lane (1 in contact).
    pub(crate) open: &'s [V; MAX_WALLS],
    /// The lanes with a run in progress.
    pub(crate) live: [bool; LANES],
    pub(crate) in_window: bool,
    /// Each lane's force at the four stages' times (the last, the step's
    /// end's: the mean squares' rates there take it, as the kernel's fixed
    /// step takes its stages').
    pub(crate) values: &'s [V; 4],
    /// Whether the mean squares are summed (the rates at the step's end made).
    pub(crate) summed: bool,
    /// Whether the runs' rates at the last step's end are this step's first
    /// stage (every lane's state and force that end's), to the bit.
    pub(crate) first_kept: bool,
}

/// [`Group::plain_step_in`] compiled for a processor feature (the same
/// operations, so the same bits, in wider vector instructions).
macro_rules! plain_step_with {
    ($name:ident, $feature:literal) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feature)]
        unsafe fn $name(
            &self,
            p: &PlainStep<'_>,
            runs: &mut LaneRuns,
            out: &mut LaneStep,
            end_gaps: &mut LaneGaps,
        ) -> [bool; LANES] {
            // The common sizes as constants (loops unrolled, no bounds
            // checks); the same arithmetic in every arm.
            match (self.n, self.k) {
                (1, 1) => self.plain_step_in((1, 1), p, runs, out, end_gaps),
                (2, 1) => self.plain_step_in((2, 1), p, runs, out, end_gaps),
                (2, 2) => self.plain_step_in((2, 2), p, runs, out, end_gaps),
                (3, 2) => self.plain_step_in((3, 2), p, runs, out, end_gaps),
                sizes => self.plain_step_in(sizes, p, runs, out, end_gaps),
            }
        }
    };
}

/// `if keep { new } else { old }` of every lane (a select, which vectorises);
/// a copy where `keep` holds every lane (`all`, the common step: no mask).
#[inline(always)]
fn select(keep: &[bool; LANES], all: bool, new: &V, old: &mut V) {
    if all {
        *old = *new;
        return;
    }
    for l in 0..LANES {
        old[l] = if keep[l] { new[l] } else { old[l] };
    }
}

impl<L: LaneLaw> Group<L> {
    /// The fixed RK4 step of `p.h` of every lane from its state in `runs`
    /// (its end and first stage into `out`, the walls' gaps at its end into
    /// `end_gaps`): which lanes' step is plain ([`Self::plain`]), those
    /// lanes' reductions added (in the recorded window). Their state is
    /// left at the step's start (see [`Self::advance`]).
    pub(crate) fn plain_step(
        &self,
        p: &PlainStep<'_>,
        runs: &mut LaneRuns,
        out: &mut LaneStep,
        end_gaps: &mut LaneGaps,
    ) -> [bool; LANES] {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") {
                // SAFETY: the processor has the feature the function is built for.
                return unsafe { self.plain_step_avx512(p, runs, out, end_gaps) };
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: as above.
                return unsafe { self.plain_step_avx2(p, runs, out, end_gaps) };
            }
        }
        self.plain_step_in((self.n, self.k), p, runs, out, end_gaps)
    }

    plain_step_with!(plain_step_avx512, "avx512f");
    plain_step_with!(plain_step_avx2, "avx2");

    #[inline(always)]
    fn plain_step_in(
        &self,
        sizes: (usize, usize),
        p: &PlainStep<'_>,
        runs: &mut LaneRuns,
        out: &mut LaneStep,
        end_gaps: &mut LaneGaps,
    ) -> [bool; LANES] {
        if p.first_kept {
            // The buffers trade places: the end's rates are overwritten
            // where they are made again (`reduce`).
            std::mem::swap(&mut out.first, &mut runs.end_rates);
        }
        self.step_in(sizes, &runs.y, p.h, p.modes, p.values, p.first_kept, out);
        self.gaps(sizes, &out.end, end_gaps);
        let mut plain = self.plain(sizes, (&runs.y, &out.end), end_gaps, p.open, p.in_window);
        self.power(sizes, &out.end, p, &mut out.power);
        for l in 0..LANES {
            plain[l] &= p.live[l];
        }
        if p.in_window {
            let end_value = p.summed.then_some(&p.values[3]);
            let ends = (&*out.first, &*out.end, p.h);
            self.reduce(sizes, ends, p.modes, end_value, &plain, runs);
        }
        plain
    }

    /// Observed quantity `j` of every lane's `block` (structure coordinates'
    /// values from `at`), as [`crate::model::assembly::Assembly::observe`].
    #[inline(always)]
    fn observe(&self, n: usize, j: usize, block: &LaneState, at: usize) -> V {
        if j < n {
            return block[at + j];
        }
        let row = &self.points[j - n];
        // `linalg::dot`'s sum, in order.
        let mut sum = [-0.0; LANES];
        for i in 0..n {
            for l in 0..LANES {
                sum[l] += row[i][l] * block[at + i][l];
            }
        }
        sum
    }

    /// Every wall's gap and rate at `y`, as [`super::Compact::gaps`] gives them.
    #[inline(always)]
    pub(crate) fn gaps(&self, (n, k): (usize, usize), y: &LaneState, out: &mut LaneGaps) {
        let d = n + k;
        let (mut px, mut pv) = ([0.0; LANES], [0.0; LANES]);
        for (w, wall) in self.walls.iter().enumerate() {
            if wall.mirror {
                for l in 0..LANES {
                    (px[l], pv[l]) = (-px[l], -pv[l]);
                }
            } else {
                (px, pv) = ([-0.0; LANES], [-0.0; LANES]);
                for i in 0..d {
                    for l in 0..LANES {
                        px[l] += wall.h[i][l] * y[i][l];
                        pv[l] += wall.h[i][l] * y[d + i][l];
                    }
                }
            }
            for l in 0..LANES {
                out[w][0][l] = wall.offset[l] + px[l];
                out[w][1][l] = pv[l];
            }
        }
    }

    /// Each wall's dissipated power at `end` where a lane is in contact
    /// with it (`p.open`), as [`crate::kernel::fixed::press`] takes it from
    /// the interaction's gap ([`crate::model::assembly::Assembly::gap`]'s
    /// sums), its law at the latched approach rate and its damper.
    #[inline(always)]
    fn power(
        &self,
        (n, k): (usize, usize),
        end: &LaneState,
        p: &PlainStep<'_>,
        out: &mut [V; MAX_WALLS],
    ) {
        let d = n + k;
        for (w, wall) in self.walls.iter().enumerate() {
            let open = lanes_where(&p.open[w]);
            if open == 0 {
                continue;
            }
            // `linalg::dot`'s sums, in order.
            let (mut hx, mut hv) = ([-0.0; LANES], [-0.0; LANES]);
            for i in 0..d {
                for l in 0..LANES {
                    hx[l] += wall.h[i][l] * end[i][l];
                    hv[l] += wall.h[i][l] * end[d + i][l];
                }
            }
            let (active, approach) = (&p.modes.active[w], &p.modes.approach[w]);
            // Lane by lane: few lanes are in contact at once (the law's
            // root and division only in those).
            for l in each_lane(open) {
                let (indentation, rate) = (-(wall.offset[l] + hx[l]), -hv[l]);
                // Apart (or not a number): no power, the law not evaluated.
                out[w][l] = if indentation > 0.0 {
                    let parts = [wall.parts[0][l], wall.parts[1][l]];
                    let latched = if active[l] != 0.0 { approach[l] } else { 0.0 };
                    let factor = parts[1] / latched;
                    let (force, elastic) = L::force_of(parts, indentation, rate, latched, factor);
                    let total = force + wall.damping[l] * rate;
                    (total - elastic) * rate
                } else {
                    0.0
                };
            }
        }
    }

    /// Which lanes' fixed step `start -> end` (walls' gaps `end_gaps` at its
    /// end) is plain: a finite end, indented at the end exactly where in
    /// contact (`open`, 1 in contact: no onset or separation in the step),
    /// and `in_window`, no observed velocity changing sign (no peak inside).
    #[inline(always)]
    pub(crate) fn plain(
        &self,
        (n, k): (usize, usize),
        (start, end): (&LaneState, &LaneState),
        end_gaps: &LaneGaps,
        open: &[V; MAX_WALLS],
        in_window: bool,
    ) -> [bool; LANES] {
        let d = n + k;
        // v * 0 is 0 for a finite v, NaN otherwise (the kernel's test).
        let mut sum = [0.0; LANES];
        for e in 0..2 * d {
            for l in 0..LANES {
                sum[l] += end[e][l] * 0.0;
            }
        }
        let mut plain = [false; LANES];
        for l in 0..LANES {
            plain[l] = sum[l] == 0.0;
        }
        for w in 0..self.walls.len() {
            for l in 0..LANES {
                plain[l] &= (end_gaps[w][0][l] < 0.0) == (open[w][l] != 0.0);
            }
        }
        if in_window {
            for j in 0..n + self.points.len() {
                let (s0, s1) = (self.observe(n, j, start, d), self.observe(n, j, end, d));
                for l in 0..LANES {
                    // Not `>= 0`: a NaN product is no sign change.
                    let turning = s0[l] * s1[l] < 0.0;
                    plain[l] &= !turning;
                }
            }
        }
        plain
    }

    /// The plain fixed step of `h` from the lanes' state in `runs` to
    /// `end` (its first stage `first`) of the lanes in `plain` added to
    /// their reductions, as `reduce_step` adds a step with no peak inside:
    /// each observed quantity's peak, with `end_value` (each lane's force
    /// at the step's end, its last stage's) its mean square over the step's
    /// quintic interpolant, and the recorded time.
    #[inline(always)]
    pub(crate) fn reduce(
        &self,
        (n, k): (usize, usize),
        (first, end, h): (&LaneState, &LaneState, f64),
        modes: &LaneModes,
        end_value: Option<&V>,
        plain: &[bool; LANES],
        runs: &mut LaneRuns,
    ) {
        let d = n + k;
        let all = plain.iter().all(|&p| p);
        let LaneRuns {
            y: start,
            peaks,
            squares,
            recorded,
            end_rates,
            ..
        } = runs;
        let start: &LaneState = start;
        // The rates at the start are the step's first stage.
        if let Some(value) = end_value {
            self.rates((n, k), end, value, modes, &modes.factor, end_rates);
        }
        for j in 0..n + self.points.len() {
            let (p0, p1) = (self.observe(n, j, start, 0), self.observe(n, j, end, 0));
            let mut peak = [0.0; LANES];
            for l in 0..LANES {
                peak[l] = peaks[j][l].max(p0[l].abs().max(p1[l].abs()));
            }
            select(plain, all, &peak, &mut peaks[j]);
            if end_value.is_none() {
                continue;
            }
            let (s0, s1) = (self.observe(n, j, start, d), self.observe(n, j, end, d));
            let c0 = self.observe(n, j, first, d);
            let c1 = self.observe(n, j, end_rates, d);
            let mut square = [0.0; LANES];
            for l in 0..LANES {
                let a = quintic(
                    p0[l],
                    p1[l],
                    h * s0[l],
                    h * s1[l],
                    h * h * c0[l],
                    h * h * c1[l],
                );
                square[l] = squares[j][l] + h * square_integral(&a);
            }
            select(plain, all, &square, &mut squares[j]);
        }
        let mut sum = [0.0; LANES];
        for l in 0..LANES {
            sum[l] = recorded[l] + h;
        }
        select(plain, all, &sum, recorded);
    }

    /// The lanes in `plain` moved to the step's end `end` (walls' gaps
    /// `end_gaps`).
    #[inline(always)]
    pub(crate) fn advance(
        &self,
        plain: &[bool; LANES],
        end: &LaneState,
        end_gaps: &LaneGaps,
        runs: &mut LaneRuns,
    ) {
        let all = plain.iter().all(|&p| p);
        for e in 0..self.len.min(super::MAX_LEN) {
            select(plain, all, &end[e], &mut runs.y[e]);
        }
        for w in 0..self.walls.len() {
            for g in 0..2 {
                select(plain, all, &end_gaps[w][g], &mut runs.gaps[w][g]);
            }
        }
    }
}
