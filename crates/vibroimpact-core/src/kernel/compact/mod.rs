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

use crate::error::Error;
use crate::kernel::balance::{check_balance, EnergySampler, ENERGY_INTERVAL};
use crate::kernel::sized::by_size;
use crate::methods::tableau::{RK4_A, RK4_B, RK4_C};
use crate::model::assembly::{
    h_dot, Assembly, InteractionLaw, Mode, Scratch, CONTACT, INPUT, VISCOUS,
};
use crate::model::contact::{AnyLaw, ContactLaw};
use crate::model::signals::Signal;

/// The largest system held: as many structure coordinates and dampers as
/// [`crate::kernel::sized::by_size`] compiles for, and walls for two dampers and
/// two stops.
pub(crate) const MAX_MODES: usize = 4;
pub(crate) const MAX_DAMPERS: usize = 2;
const MAX_DIM: usize = MAX_MODES + MAX_DAMPERS;
const MAX_WALLS: usize = 2 * MAX_DAMPERS + 2;
/// The longest state: coordinates, velocities and the accumulators.
const MAX_LEN: usize = 2 * MAX_DIM + CONTACT + MAX_WALLS;

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
    /// Whether `r * inertial` is +0 for every mode (no gravity, every `r`
    /// >= +0), and so may be left out: `a - (+0) = a` to the bit.
    inertial_free: bool,
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
                InteractionLaw::Rigid { .. } => None,
            };
        }
        Some(Self {
            modal,
            force,
            gravity: parts.gravity,
            inertial_free: parts.gravity == 0.0
                && modal[..n].iter().all(|m| m[3].is_sign_positive()),
            walls,
            count: system.interactions.len(),
        })
    }

    /// [`Assembly::rates_with`] for `n` modes and `k` dampers (constants
    /// where inlined); sticking pairs' constraint forces by `system`'s own
    /// solve.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn rates<const STICKING: bool>(
        &self,
        system: &Assembly,
        n: usize,
        k: usize,
        time: f64,
        y: &[f64; MAX_LEN],
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64; MAX_LEN],
    ) {
        let d = n + k;
        // The general path's sum of no base signal and gravity.
        let inertial = 0.0 + self.gravity;
        let mut input = 0.0;
        let mut viscous = 0.0;
        if let Some(force) = &self.force {
            let value = scratch.first_force_value(&force.signal, time);
            let mut power = -0.0;
            for i in 0..n {
                let [k, c, damping, r] = self.modal[i];
                let (x, v) = (y[i], y[d + i]);
                out[i] = v;
                let elastic = if self.inertial_free {
                    -(k * x + c * v)
                } else {
                    -(k * x + c * v) - r * inertial
                };
                out[d + i] = elastic + force.push[i] * value;
                viscous += damping * v * v;
                power += force.row[i] * v;
            }
            input += value * power;
        } else {
            for i in 0..n {
                let [k, c, damping, r] = self.modal[i];
                let (x, v) = (y[i], y[d + i]);
                out[i] = v;
                out[d + i] = -(k * x + c * v) - r * inertial;
                viscous += damping * v * v;
            }
        }
        for j in n..d {
            out[j] = y[d + j];
            out[d + j] = -inertial;
        }
        let count = self.count.min(MAX_WALLS);
        let modes = &modes[..count];
        let mut products: Option<(f64, f64)> = None;
        let mut sticking = 0;
        for w in 0..count {
            let wall = &self.walls[w];
            let loss = 2 * d + CONTACT + w;
            out[loss] = 0.0;
            let previous = products.take();
            if let (Mode::Compliant { approach_rate }, Some((law, damping))) =
                (&modes[w], &wall.law)
            {
                let (hx, hv) = match previous {
                    Some((hx, hv)) if wall.mirror => (-hx, -hv),
                    _ => wall.products(d, y),
                };
                products = Some((hx, hv));
                let (indentation, rate) = (-(wall.offset + hx), -hv);
                let (force, elastic) = if indentation > 0.0 {
                    law.force_and_elastic(indentation, rate, *approach_rate)
                } else {
                    (0.0, 0.0)
                };
                let total = force + *damping * rate;
                if total != 0.0 {
                    for i in 0..d {
                        out[d + i] += wall.push[i] * total;
                    }
                }
                out[loss] = (total - elastic) * rate;
            } else if STICKING && modes[w] == Mode::Sticking {
                scratch.sticking[sticking] = w;
                sticking += 1;
            }
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
    }

    /// One RK4 step `h` from `(time, start)` into `out`, the state's
    /// `len` values, for `n` modes and `k` dampers (`STICKING`: whether a
    /// pair may stick): the general stages' arithmetic. `stages[0]` holds `f(start)` where
    /// `start_valid`, and receives it where not.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn step<const STICKING: bool>(
        &self,
        system: &Assembly,
        n: usize,
        k: usize,
        time: f64,
        start: &[f64; MAX_LEN],
        len: usize,
        h: f64,
        modes: &[Mode],
        scratch: &mut Scratch,
        stages: &mut [[f64; MAX_LEN]; 4],
        start_valid: bool,
        out: &mut [f64; MAX_LEN],
    ) {
        let coordinates = 2 * (n + k);
        let len = len.min(MAX_LEN);
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
            self.rates::<STICKING>(system, n, k, times[0], start, modes, scratch, k0);
        }
        // The stages written out (a loop over them keeps less in registers).
        let mut point = [0.0; MAX_LEN];
        for e in 0..coordinates {
            point[e] = start[e] + hw[0] * k0[e];
        }
        self.rates::<STICKING>(system, n, k, times[1], &point, modes, scratch, k1);
        for e in 0..coordinates {
            point[e] = start[e] + hw[1] * k1[e];
        }
        self.rates::<STICKING>(system, n, k, times[2], &point, modes, scratch, k2);
        for e in 0..coordinates {
            point[e] = start[e] + hw[2] * k2[e];
        }
        self.rates::<STICKING>(system, n, k, times[3], &point, modes, scratch, k3);
        for e in 0..len {
            out[e] = start[e] + w[0] * k0[e] + w[1] * k1[e] + w[2] * k2[e] + w[3] * k3[e];
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
        // One body for every mode (with no pair sticking, the constraint
        // branch is skipped at run time): the stretches, where speed counts,
        // compile the two apart.
        self.step::<true>(
            system,
            n,
            k,
            time,
            &start,
            len,
            h,
            modes,
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

    /// [`Self::stretch`] for the system's sizes, in the widest vector
    /// instructions the processor has (the same operations: the same bits).
    pub(crate) fn run_stretch(
        &self,
        system: &Assembly,
        f: &mut Stretch<'_>,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") {
                // SAFETY: the processor has the feature the function is built for.
                return unsafe { stretch_avx512(self, system, f, modes, scratch) };
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: as above.
                return unsafe { stretch_avx2(self, system, f, modes, scratch) };
            }
        }
        stretch_sized(self, system, f, modes, scratch)
    }

    /// Plain RK4 steps on the grid, as the event kernel takes them, for as
    /// long as nothing but the step itself is due (see [`Stretch`]), with
    /// the system's data in registers across them. Each step is the general
    /// loop's to the bit; one that turns out not to be plain (a gap that may
    /// cross, a compliant contact at its deepest, a peak inside the step, a
    /// state no longer finite) is taken back, for the general loop to take.
    #[inline(always)]
    pub(crate) fn stretch<const STICKING: bool>(
        &self,
        system: &Assembly,
        n: usize,
        k: usize,
        f: &mut Stretch<'_>,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        let d = n + k;
        let row = 2 * d;
        let count = self.count.min(MAX_WALLS);
        let len = f.y.len().min(MAX_LEN);
        let observed = system.observed();
        let modes = &modes[..count];
        let mut y = [0.0; MAX_LEN];
        y[..len].copy_from_slice(&f.y[..len]);
        let mut start_gaps = [(0.0, 0.0); MAX_WALLS];
        start_gaps[..count].copy_from_slice(&f.gaps[..count]);
        let mut end = [0.0; MAX_LEN];
        let mut end_gaps = [(0.0, 0.0); MAX_WALLS];
        let mut stages = [[0.0; MAX_LEN]; 4];
        // Walls the event search passes over: the open wall of a sticking
        // damper, and sticking walls of a damper without clearance; whether
        // a sticking pair may release.
        let mut held = [false; MAX_WALLS];
        let mut locked = [false; MAX_WALLS];
        let mut releasable = false;
        for w in 0..count {
            held[w] = modes[w] == Mode::Open && system.held_by_mirror(w, modes);
            locked[w] = system.locked(w);
            releasable |= modes[w] == Mode::Sticking && !locked[w];
        }
        // Whether `stages[0]` holds the rates at the step's start (the last
        // step's release test evaluated them there).
        let mut start_valid = false;
        // In a register through the loop, written back after it.
        let mut sampler = f.energy_sampler;
        loop {
            if f.accepted >= f.max_accepted {
                f.limited = true;
                break;
            }
            let time = f.time;
            if f.t_end - time <= 1e-9 * f.dt {
                break;
            }
            let length = ((f.grid + 1) as f64 * f.dt - time).min(f.t_end - time);
            let next = time + length;
            let from = f.record_from;
            if length <= 0.0
                || (from - time < length && from - time > 1e-9 * length)
                || (f.next_strobe - time < length && f.next_strobe - time > 1e-9 * f.strobe_period)
                || next >= f.next_strobe - 1e-9 * f.strobe_period
                || next >= f.t_end
                || f.t_end - next <= 1e-9 * f.dt
                || (f.keep_history && f.until_kept <= 1)
                || length <= f.chatter_factor * next.abs().max(f.time_scale)
            {
                break;
            }
            let in_window = time + 1e-9 * length >= f.record_from;
            if in_window && f.mean_square {
                break;
            }
            let cache = scratch.first_cache().copied();
            self.step::<STICKING>(
                system,
                n,
                k,
                time,
                &y,
                len,
                length,
                modes,
                scratch,
                &mut stages,
                start_valid,
                &mut end,
            );
            self.gaps(d, &end, &mut end_gaps);
            // What the general loop would do more than count the step: an
            // event search, a blow-up, a compliant contact's deepest point,
            // a peak inside the step.
            let mut plain = end[..row].iter().fold(0.0, |sum, v| sum + v * 0.0) == 0.0;
            for w in 0..count {
                match modes[w] {
                    // The event search passes over these (see `find_crossing`).
                    Mode::Sticking => {}
                    Mode::Open if held[w] => {}
                    mode => {
                        plain &= !mode.may_cross(start_gaps[w], end_gaps[w]);
                        if let Mode::Compliant { .. } = mode {
                            let (m0, m1) = (start_gaps[w].1 * length, end_gaps[w].1 * length);
                            plain &= !(m0 < 0.0 && m1 > 0.0);
                        }
                    }
                }
            }
            if plain && releasable {
                // A sticking pair whose constraint force at the step's end
                // pulls is released: the forces as the event search takes
                // them.
                self.rates::<true>(system, n, k, next, &end, modes, scratch, &mut stages[0]);
                for w in 0..count {
                    if modes[w] == Mode::Sticking
                        && !locked[w]
                        && scratch.force_of(w).unwrap_or(0.0) < 0.0
                    {
                        plain = false;
                    }
                }
            }
            if in_window {
                for j in 0..observed {
                    let (s0, s1) = (
                        system.observe(j, &y[d..d + n]),
                        system.observe(j, &end[d..d + n]),
                    );
                    if s0 * s1 < 0.0 {
                        plain = false;
                    }
                }
            }
            if !plain {
                if let (Some(saved), Some(cache)) = (cache, scratch.first_cache()) {
                    *cache = saved;
                }
                break;
            }
            for w in 0..count {
                if let Mode::Compliant { .. } = modes[w] {
                    f.deepest[w] = f.deepest[w].max(-end_gaps[w].0);
                }
            }
            if in_window {
                for (j, peak) in f.peaks.iter_mut().enumerate().take(observed) {
                    let (p0, p1) = (system.observe(j, &y[..n]), system.observe(j, &end[..n]));
                    *peak = peak.max(p0.abs().max(p1.abs()));
                }
                *f.recorded_time += length;
            }
            f.time = next;
            f.grid += 1;
            f.accepted += 1;
            f.until_kept = f.until_kept.saturating_sub(1);
            f.evaluations += 4;
            f.steps += 1;
            // Those rates are the next step's first stage.
            start_valid = releasable;
            for e in 0..len {
                y[e] = end[e];
            }
            for w in 0..count {
                start_gaps[w] = end_gaps[w];
            }
            let check = f.accepted % ENERGY_INTERVAL == 0;
            if check || sampler.due(f.time) {
                if let Err(failure) = check_balance(
                    system,
                    &y[..len],
                    modes,
                    f.stored_start,
                    &mut f.energy_scale,
                    f.impact_loss,
                    (f.energy_tolerance, check),
                    f.t_end,
                    f.time,
                ) {
                    f.unbalanced = Some(failure);
                    break;
                }
            }
        }
        f.energy_sampler = sampler;
        f.y[..len].copy_from_slice(&y[..len]);
        f.gaps[..count].copy_from_slice(&start_gaps[..count]);
    }
}

/// [`Compact::stretch`] for the system's sizes (constants in each arm).
#[inline(always)]
fn stretch_sized(
    compact: &Compact,
    system: &Assembly,
    f: &mut Stretch<'_>,
    modes: &[Mode],
    scratch: &mut Scratch,
) {
    // Without a sticking pair, no constraint solve is compiled in.
    if modes.contains(&Mode::Sticking) {
        by_size!(system, |n, k| compact
            .stretch::<true>(system, n, k, f, modes, scratch))
    } else {
        by_size!(system, |n, k| compact
            .stretch::<false>(system, n, k, f, modes, scratch))
    }
}

/// [`stretch_sized`] compiled for a processor feature.
macro_rules! stretch_with {
    ($name:ident, $feature:literal) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feature)]
        unsafe fn $name(
            compact: &Compact,
            system: &Assembly,
            f: &mut Stretch<'_>,
            modes: &[Mode],
            scratch: &mut Scratch,
        ) {
            stretch_sized(compact, system, f, modes, scratch)
        }
    };
}
stretch_with!(stretch_avx512, "avx512f");
stretch_with!(stretch_avx2, "avx2");

/// The event kernel's state that a stretch advances, and where it must stop:
/// it takes a step only where the general loop would take it whole and do
/// nothing after it but count it (no landing on the recording window's
/// start or a strobe instant, no history row, step limit or end of the run
/// due), or check the energy balance, which the stretch does as the kernel
/// would, or poll for an interrupt, which the kernel then does (a stretch
/// ends on that step). The memory and row limits
/// the loop checks after each step hold through a stretch, which adds no
/// contact and no row (the kernel starts none before its own first step).
pub struct Stretch<'a> {
    pub time: f64,
    pub grid: u64,
    pub accepted: u64,
    pub until_kept: u64,
    /// The state, advanced in place, and each wall's gap and rate there.
    pub y: &'a mut [f64],
    pub gaps: &'a mut [(f64, f64)],
    /// Each compliant contact's deepest indentation so far (m).
    pub deepest: &'a mut [f64],
    /// The reductions' peaks and recorded time (used in the window).
    pub peaks: &'a mut [f64],
    pub recorded_time: &'a mut f64,
    /// Right-hand-side evaluations and steps made.
    pub evaluations: u64,
    pub steps: u64,
    /// The most accepted steps the stretch may reach, and whether it did.
    pub max_accepted: u64,
    pub limited: bool,
    pub dt: f64,
    pub t_end: f64,
    pub record_from: f64,
    pub mean_square: bool,
    pub next_strobe: f64,
    pub strobe_period: f64,
    pub keep_history: bool,
    /// A step no longer than `chatter_factor * max(|t|, time_scale)` makes
    /// no progress (the kernel's stall test).
    pub chatter_factor: f64,
    pub time_scale: f64,
    /// The energy balance, checked every [`ENERGY_INTERVAL`] accepted steps
    /// as the kernel checks it (the scale kept across checks); the error
    /// where it failed, on which the stretch stops.
    pub stored_start: f64,
    pub energy_scale: f64,
    /// When the energy in play is sampled between the checks.
    pub energy_sampler: EnergySampler,
    pub impact_loss: f64,
    pub energy_tolerance: f64,
    pub unbalanced: Option<Error>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Result;
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
            let compact = system.compact.as_deref().unwrap();
            let len = system.state_len();
            let count = system.interactions.len();
            let modes = vec![Mode::Open; count];
            let mut y = initial_state(&system, &[], &[], &[], &[]).unwrap();
            let mut gaps = vec![(0.0, 0.0); count];
            system.gaps(&y, &mut gaps);
            let (mut deepest, mut peaks, mut recorded) = (vec![f64::NAN; count], vec![0.0; 3], 0.0);
            let dt = 1e-5;
            let (stored_start, energy_scale) = system.energy_terms(&y, &modes);
            let mut stretch = Stretch {
                time: 0.0,
                grid: 0,
                accepted: 0,
                until_kept: 0,
                y: &mut y,
                gaps: &mut gaps,
                deepest: &mut deepest,
                peaks: &mut peaks,
                recorded_time: &mut recorded,
                evaluations: 0,
                steps: 0,
                max_accepted: 20,
                limited: false,
                dt,
                t_end: 1.0,
                record_from: 0.0,
                mean_square: false,
                next_strobe: f64::INFINITY,
                strobe_period: f64::INFINITY,
                keep_history: false,
                chatter_factor: 1e3 * f64::EPSILON,
                time_scale: 1.0,
                stored_start,
                energy_scale,
                energy_sampler: EnergySampler::new(&system, 1.0),
                impact_loss: 0.0,
                energy_tolerance: 1e-6,
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
