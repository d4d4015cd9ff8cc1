//! RK4 steps of [`LANES`] compact systems at once: the same operations as
//! [`Compact::step`] (a fixed step from the rates at its start, no pair
//! sticking), term for term and in the same order, each over an array of
//! lanes that the compiler turns into vector instructions. The lanes share
//! their shape (sizes, walls, law kind, force or not); their values differ.
//! A contact branch becomes a select, which changes no result.

#![allow(clippy::needless_range_loop)]

use super::{Compact, MAX_DIM, MAX_LEN, MAX_MODES, MAX_WALLS};
use crate::methods::tableau::{RK4_A, RK4_B, RK4_C};
use crate::model::assembly::{elastic, Assembly, Mode, CONTACT, INPUT, VISCOUS};
use crate::model::contact::{AnyLaw, ContactLaw, Hertz, HysterHertz, Linear};
use crate::model::signals::Signal;

/// Systems stepped together.
pub(crate) const LANES: usize = 16;

/// One value per lane.
pub(super) type V = [f64; LANES];

/// A state (or its rates) per lane.
pub(crate) type LaneState = [V; MAX_LEN];

/// The most quantities the lanes observe (structure coordinates, points).
pub(crate) const MAX_OBSERVED: usize = 8;

/// RK4's stage times of a step `h` from `time` (the compact step's).
#[inline(always)]
pub(crate) fn stage_times(time: f64, h: f64) -> [f64; 4] {
    [
        time,
        time + RK4_C[1] * h,
        time + RK4_C[2] * h,
        time + RK4_C[3] * h,
    ]
}

/// [`HysterHertz`]'s rate below which it is elastic (its `GRAZING_RATE`;
/// the lanes' tests hold them to the same bits).
const GRAZING_RATE: f64 = 1e-12;

/// A concrete law taken out of [`AnyLaw`], its force written without a
/// branch (its own operations in its order, a select where it branches:
/// what vectorises over lanes).
pub(crate) trait LaneLaw: ContactLaw + Copy {
    fn of(law: &AnyLaw) -> Option<Self>;
    /// Its parameters.
    fn parts(&self) -> [f64; 2];
    /// [`ContactLaw::force_and_elastic`] of the law with `parts`, at the
    /// latched `approach` rate, `factor` its `parts[1] / approach` (the
    /// division, made once a step in the compact step and once a mode
    /// change here, [`Group::latch`]: the same bits).
    fn force_of(
        parts: [f64; 2],
        indentation: f64,
        rate: f64,
        approach: f64,
        factor: f64,
    ) -> (f64, f64);
}
impl LaneLaw for Hertz {
    fn of(law: &AnyLaw) -> Option<Self> {
        match law {
            AnyLaw::Hertz(l) => Some(*l),
            _ => None,
        }
    }
    fn parts(&self) -> [f64; 2] {
        [self.stiffness, 0.0]
    }
    #[inline(always)]
    fn force_of(parts: [f64; 2], indentation: f64, _: f64, _: f64, _: f64) -> (f64, f64) {
        let f = parts[0] * indentation * indentation.sqrt();
        (f, f)
    }
}
impl LaneLaw for HysterHertz {
    fn of(law: &AnyLaw) -> Option<Self> {
        match law {
            AnyLaw::HysterHertz(l) => Some(*l),
            _ => None,
        }
    }
    fn parts(&self) -> [f64; 2] {
        [self.stiffness, self.hysteresis]
    }
    #[inline(always)]
    fn force_of(
        parts: [f64; 2],
        indentation: f64,
        rate: f64,
        approach: f64,
        factor: f64,
    ) -> (f64, f64) {
        let elastic = parts[0] * indentation * indentation.sqrt();
        let damped = (elastic * (1.0 + factor * rate)).max(0.0);
        let force = if approach > GRAZING_RATE {
            damped
        } else {
            elastic
        };
        (force, elastic)
    }
}
impl LaneLaw for Linear {
    fn of(law: &AnyLaw) -> Option<Self> {
        match law {
            AnyLaw::Linear(l) => Some(*l),
            _ => None,
        }
    }
    fn parts(&self) -> [f64; 2] {
        [self.stiffness, 0.0]
    }
    #[inline(always)]
    fn force_of(parts: [f64; 2], indentation: f64, _: f64, _: f64, _: f64) -> (f64, f64) {
        let f = parts[0] * indentation;
        (f, f)
    }
}

/// A wall of every lane (all compliant).
#[derive(Debug, Clone, Copy)]
pub(super) struct Walls<L> {
    pub(super) h: [V; MAX_DIM],
    push: [V; MAX_DIM],
    pub(super) offset: V,
    /// Each lane's law's parameters.
    pub(super) parts: [V; 2],
    pub(super) damping: V,
    law: std::marker::PhantomData<L>,
    pub(super) mirror: bool,
}

impl<L: LaneLaw> Walls<L> {
    /// Lane `l`'s `(h . x, h . v)` at `y` (of `d` coordinates), as the
    /// vector sums them; the previous wall's negated where `mirrored` gives
    /// them.
    #[inline(always)]
    fn touch(&self, l: usize, y: &LaneState, d: usize, mirrored: Option<(f64, f64)>) -> (f64, f64) {
        if let Some((hx, hv)) = mirrored {
            return (-hx, -hv);
        }
        let (mut sx, mut sv) = ([-0.0; 2], [-0.0; 2]);
        for i in 0..d {
            sx[i % 2] += self.h[i][l] * y[i][l];
            sv[i % 2] += self.h[i][l] * y[d + i][l];
        }
        (sx[0] + sx[1], sv[0] + sv[1])
    }

    /// Lane `l`'s contact force on the wall with products `(hx, hv)`, in
    /// contact with the latched `approach` rate (`factor` its law's), added
    /// to its accelerations in `out` and its loss rate into slot `loss`:
    /// the vector's operations on that lane.
    #[inline(always)]
    fn push_lane(
        &self,
        l: usize,
        (hx, hv): (f64, f64),
        (approach, factor): (f64, f64),
        d: usize,
        out: &mut LaneState,
        loss: usize,
    ) {
        let (indentation, rate) = (-(self.offset[l] + hx), -hv);
        let parts = [self.parts[0][l], self.parts[1][l]];
        // Fixed stepping's modes (see `LaneModes::set`): no damper apart.
        let (force, elastic, damping) = if indentation > 0.0 {
            let (force, elastic) = L::force_of(parts, indentation, rate, approach, factor);
            (force, elastic, self.damping[l])
        } else {
            (0.0, 0.0, 0.0)
        };
        let total = force + damping * rate;
        if total != 0.0 {
            for i in 0..d {
                out[d + i][l] += self.push[i][l] * total;
            }
        }
        out[loss][l] = (total - elastic) * rate;
    }
}

/// `start + a k` of every lane in the first `count` entries, taken as one
/// run of values: the loop vectorises along contiguous values (taken entry
/// by entry, the compiler vectorised across the entries, in gathers and
/// scatters). The lanes' buffers are fields of one struct: as a function's
/// distinct references they are known not to overlap.
#[inline(always)]
fn stage_points(point: &mut LaneState, (start, a, k): (&LaneState, f64, &LaneState), count: usize) {
    let point = point[..count].as_flattened_mut();
    let (start, k) = (start[..count].as_flattened(), k[..count].as_flattened());
    for ((p, s), k) in point.iter_mut().zip(start).zip(k) {
        *p = s + a * k;
    }
}

/// `sum + h x` of every lane (see [`stage_points`]).
#[inline(always)]
fn accumulate(sum: &V, h: &V, x: &V) -> V {
    let mut out = [0.0; LANES];
    for l in 0..LANES {
        out[l] = sum[l] + h[l] * x[l];
    }
    out
}

/// `acceleration + push total` in the lanes where `add` is not 0 (see
/// [`stage_points`]).
#[inline(always)]
fn push_where(acceleration: &V, push: &V, total: &V, add: &V) -> V {
    let mut out = [0.0; LANES];
    for l in 0..LANES {
        let pushed = acceleration[l] + push[l] * total[l];
        out[l] = if add[l] != 0.0 {
            pushed
        } else {
            acceleration[l]
        };
    }
    out
}

/// RK4's end `start + w0 k0 + w1 k1 + w2 k2 + w3 k3` of every lane in the
/// first `count` entries (see [`stage_points`]).
#[inline(always)]
fn combine(
    end: &mut LaneState,
    start: &LaneState,
    w: &[f64; 4],
    [k0, k1, k2, k3]: [&LaneState; 4],
    count: usize,
) {
    let end = end[..count].as_flattened_mut();
    let start = start[..count].as_flattened();
    let [k0, k1, k2, k3] = [k0, k1, k2, k3].map(|k| k[..count].as_flattened());
    for i in 0..end.len().min(start.len()) {
        end[i] = start[i] + w[0] * k0[i] + w[1] * k1[i] + w[2] * k2[i] + w[3] * k3[i];
    }
}

/// Walls touched by at most this many lanes are evaluated lane by lane.
const LANE_BY_LANE: u32 = 4;

/// The lanes where `v` is not 0, a bit each (lane `l` bit `l`).
#[inline(always)]
pub(super) fn lanes_where(v: &V) -> u32 {
    let mut mask = 0u32;
    for l in 0..LANES {
        mask |= u32::from(v[l] != 0.0) << l;
    }
    mask
}

/// The lanes of `mask`, in order.
#[inline(always)]
pub(super) fn each_lane(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let l = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            l
        })
    })
}

/// The lanes' systems, their values side by side.
#[derive(Debug, Clone)]
pub(crate) struct Group<L> {
    pub(super) n: usize,
    pub(super) k: usize,
    pub(super) len: usize,
    /// `[M^-1 K, M^-1 C, C, r]` of each mode.
    modal: [[V; 4]; MAX_MODES],
    /// The force's `M^-1 row^T` and row, and each lane's signal.
    force: Option<([V; MAX_MODES], [V; MAX_MODES], Vec<Signal>)>,
    /// Each lane's harmonic's amplitude, angular frequency and phase,
    /// where every lane's signal is one.
    harmonics: Option<[V; 3]>,
    gravity: V,
    pub(super) walls: Vec<Walls<L>>,
    /// Each followed point's row over the modes (see
    /// [`Assembly::observe`]): the quantities observed past the modes.
    pub(super) points: Vec<[V; MAX_MODES]>,
}

/// The lanes' step: its end, and the rates at its start.
pub(crate) struct LaneStep {
    pub(crate) end: Box<LaneState>,
    pub(crate) first: Box<LaneState>,
    /// Each wall's dissipated power at the end of a plain step, where a
    /// lane is in contact with it ([`crate::kernel::fixed::press`]'s).
    pub(crate) power: [V; MAX_WALLS],
    pub(super) point: Box<LaneState>,
    pub(super) stages: Box<[LaneState; 3]>,
}

impl LaneStep {
    /// A state of every lane, zero.
    pub(crate) fn state() -> Box<LaneState> {
        Box::new([[0.0; LANES]; MAX_LEN])
    }
}

impl Default for LaneStep {
    fn default() -> Self {
        Self {
            end: Self::state(),
            first: Self::state(),
            power: [[0.0; LANES]; MAX_WALLS],
            point: Self::state(),
            stages: Box::new([[[0.0; LANES]; MAX_LEN]; 3]),
        }
    }
}

/// Each wall's mode per lane: in compliant contact, and its latched approach rate.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LaneModes {
    /// 1 in contact, 0 open (numbers: what the vector selects read).
    pub(super) active: [V; MAX_WALLS],
    pub(super) approach: [V; MAX_WALLS],
    /// What the steps read of them, made where they change
    /// ([`Group::latch`]): each wall's lanes in contact, a bit each, and
    /// each compliant law's `parts[1] / approach`.
    pub(super) touching: [u32; MAX_WALLS],
    pub(super) factor: [V; MAX_WALLS],
    /// Whether `touching` and `factor` are those of the modes now.
    latched: bool,
}

impl LaneModes {
    /// The modes of lane `l`; false where one is neither open nor
    /// fixed stepping's compliant contact, whose forces act only where the
    /// pair is indented (the lanes do not take it).
    pub(crate) fn set(&mut self, l: usize, modes: &[Mode]) -> bool {
        self.latched = false;
        for (w, mode) in modes.iter().enumerate().take(MAX_WALLS) {
            match mode {
                Mode::Open => self.active[w][l] = 0.0,
                Mode::Compliant {
                    approach_rate,
                    indented_only: true,
                } => {
                    self.active[w][l] = 1.0;
                    self.approach[w][l] = *approach_rate;
                }
                _ => return false,
            }
        }
        true
    }
}

impl Default for LaneModes {
    fn default() -> Self {
        Self {
            active: [[0.0; LANES]; MAX_WALLS],
            approach: [[0.0; LANES]; MAX_WALLS],
            touching: [0; MAX_WALLS],
            factor: [[0.0; LANES]; MAX_WALLS],
            latched: false,
        }
    }
}

/// Whether two systems have one shape: lanes of one group.
fn same_shape(a: &Compact, b: &Compact) -> bool {
    let kind = |c: &Compact, w: usize| c.walls[w].law.map(|(law, _)| std::mem::discriminant(&law));
    a.count == b.count
        && a.force.is_some() == b.force.is_some()
        && (0..a.count.min(MAX_WALLS))
            .all(|w| a.walls[w].mirror == b.walls[w].mirror && kind(a, w) == kind(b, w))
}

/// [`Group::step_in`] compiled for a processor feature (the same
/// operations, so the same bits, in wider vector instructions).
macro_rules! step_with {
    ($name:ident, $feature:literal) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feature)]
        unsafe fn $name(
            &self,
            start: &LaneState,
            h: f64,
            modes: &LaneModes,
            values: &[V; 4],
            out: &mut LaneStep,
        ) {
            self.step_in((self.n, self.k), start, h, modes, values, false, out)
        }
    };
}

impl<L: LaneLaw> Group<L> {
    /// The group of `systems` (the first repeated into lanes left empty),
    /// where each has a compact form, they share a shape and every wall has
    /// law `L`.
    pub(crate) fn of(assemblies: &[&Assembly]) -> Option<Self> {
        let systems: Vec<_> = assemblies
            .iter()
            .map(|s| Some((s.compact.as_ref()?, s.n, s.k, s.state_len())))
            .collect::<Option<_>>()?;
        let &(first, n, k, len) = systems.first()?;
        let observed = assemblies[0].observed();
        if systems.len() > LANES
            || observed > MAX_OBSERVED
            || assemblies.iter().any(|s| s.observed() != observed)
            || systems
                .iter()
                .any(|&(c, n2, k2, len2)| (n2, k2, len2) != (n, k, len) || !same_shape(first, c))
        {
            return None;
        }
        let lane = |l: usize| systems.get(l).unwrap_or(&systems[0]).0;
        let mut points = vec![[[0.0; LANES]; MAX_MODES]; observed - n];
        for (p, row) in points.iter_mut().enumerate() {
            for l in 0..LANES {
                let rows = &assemblies.get(l).unwrap_or(&assemblies[0]).point_rows;
                for i in 0..n {
                    row[i][l] = rows[p * n + i];
                }
            }
        }
        let d = n + k;
        let mut modal = [[[0.0; LANES]; 4]; MAX_MODES];
        let mut gravity = [0.0; LANES];
        for l in 0..LANES {
            let c = lane(l);
            for i in 0..n {
                for f in 0..4 {
                    modal[i][f][l] = c.modal[i][f];
                }
            }
            gravity[l] = c.gravity;
        }
        let force = first.force.as_ref().map(|_| {
            let (mut push, mut row) = ([[0.0; LANES]; MAX_MODES], [[0.0; LANES]; MAX_MODES]);
            let mut signals = Vec::with_capacity(LANES);
            for l in 0..LANES {
                let f = lane(l).force.as_ref().expect("one shape");
                for i in 0..n {
                    push[i][l] = f.push[i];
                    row[i][l] = f.row[i];
                }
                signals.push(f.signal.clone());
            }
            (push, row, signals)
        });
        let harmonics = force.as_ref().and_then(|(_, _, signals)| {
            let mut harmonics = [[0.0; LANES]; 3];
            for (l, signal) in signals.iter().enumerate() {
                let Signal::Harmonic(h) = signal else {
                    return None;
                };
                harmonics[0][l] = h.amplitude;
                // As the signal's cache makes it.
                harmonics[1][l] = std::f64::consts::TAU * h.frequency;
                harmonics[2][l] = h.phase;
            }
            Some(harmonics)
        });
        let mut walls = Vec::with_capacity(first.count);
        for w in 0..first.count.min(MAX_WALLS) {
            let (law, _) = first.walls[w].law?;
            L::of(&law)?;
            let mut wall = Walls {
                h: [[0.0; LANES]; MAX_DIM],
                push: [[0.0; LANES]; MAX_DIM],
                offset: [0.0; LANES],
                parts: [[0.0; LANES]; 2],
                damping: [0.0; LANES],
                law: std::marker::PhantomData,
                mirror: first.walls[w].mirror,
            };
            for l in 0..LANES {
                let it = &lane(l).walls[w];
                let (law, damping) = it.law?;
                for i in 0..d {
                    wall.h[i][l] = it.h[i];
                    wall.push[i][l] = it.push[i];
                }
                wall.offset[l] = it.offset;
                let parts = L::of(&law)?.parts();
                wall.parts[0][l] = parts[0];
                wall.parts[1][l] = parts[1];
                wall.damping[l] = damping;
            }
            walls.push(wall);
        }
        Some(Self {
            n,
            k,
            len,
            modal,
            force,
            harmonics,
            gravity,
            walls,
            points,
        })
    }

    /// [`Compact::rates`] of every lane (no pair sticking), the force's
    /// value of each lane in `value`.
    #[inline(always)]
    pub(super) fn rates(
        &self,
        (n, k): (usize, usize),
        y: &LaneState,
        value: &V,
        modes: &LaneModes,
        factor: &[V; MAX_WALLS],
        out: &mut LaneState,
    ) {
        let d = n + k;
        let mut inertial = [0.0; LANES];
        for l in 0..LANES {
            inertial[l] = 0.0 + self.gravity[l];
        }
        let mut input = [0.0; LANES];
        let mut viscous = [0.0; LANES];
        if let Some((push, row, _)) = &self.force {
            let mut power = [-0.0; LANES];
            for i in 0..n {
                let [k, c, damping, r] = &self.modal[i];
                for l in 0..LANES {
                    let (x, v) = (y[i][l], y[d + i][l]);
                    let own = elastic(k[l], c[l], r[l], inertial[l], x, v);
                    out[i][l] = v;
                    out[d + i][l] = own + push[i][l] * value[l];
                    viscous[l] += damping[l] * v * v;
                    power[l] += row[i][l] * v;
                }
            }
            for l in 0..LANES {
                input[l] += value[l] * power[l];
            }
        } else {
            for i in 0..n {
                let [k, c, damping, r] = &self.modal[i];
                for l in 0..LANES {
                    let (x, v) = (y[i][l], y[d + i][l]);
                    let own = elastic(k[l], c[l], r[l], inertial[l], x, v);
                    out[i][l] = v;
                    out[d + i][l] = own;
                    viscous[l] += damping[l] * v * v;
                }
            }
        }
        for j in n..d {
            for l in 0..LANES {
                out[j][l] = y[d + j][l];
                out[d + j][l] = -inertial[l];
            }
        }
        // The last wall's products where it was in contact (a mirror wall
        // takes them negated).
        let mut previous = [0.0; LANES];
        let mut previous_lanes = 0u32;
        let (mut px, mut pv) = ([0.0; LANES], [0.0; LANES]);
        for (w, wall) in self.walls.iter().enumerate() {
            let loss = 2 * d + CONTACT + w;
            let active = &modes.active[w];
            let touching = modes.touching[w];
            if touching.count_ones() <= LANE_BY_LANE {
                // No lane touches, or few: those few lane by lane (the
                // vector would evaluate the law in every lane).
                out[loss] = [0.0; LANES];
                for l in each_lane(touching) {
                    let mirrored = wall.mirror & (previous_lanes >> l & 1 != 0);
                    (px[l], pv[l]) = wall.touch(l, y, d, mirrored.then(|| (px[l], pv[l])));
                    let latched = (modes.approach[w][l], factor[w][l]);
                    wall.push_lane(l, (px[l], pv[l]), latched, d, out, loss);
                }
                previous = *active;
                previous_lanes = touching;
                continue;
            }
            previous_lanes = touching;
            // `h_dot`'s two sums, each lane innermost (what vectorises).
            let (mut sx, mut sv) = ([[-0.0; LANES]; 2], [[-0.0; LANES]; 2]);
            for i in 0..d {
                let (x, v) = (&mut sx[i % 2], &mut sv[i % 2]);
                *x = accumulate(x, &wall.h[i], &y[i]);
                *v = accumulate(v, &wall.h[i], &y[d + i]);
            }
            // In simple loops, each of which vectorises.
            let (mut indentation, mut rate) = ([0.0; LANES], [0.0; LANES]);
            for l in 0..LANES {
                let mirrored = wall.mirror & (previous[l] != 0.0);
                let hx = if mirrored {
                    -px[l]
                } else {
                    sx[0][l] + sx[1][l]
                };
                let hv = if mirrored {
                    -pv[l]
                } else {
                    sv[0][l] + sv[1][l]
                };
                indentation[l] = -(wall.offset[l] + hx);
                rate[l] = -hv;
                previous[l] = active[l];
                (px[l], pv[l]) = (hx, hv);
            }
            let (mut force, mut elastic) = ([0.0; LANES], [0.0; LANES]);
            let mut damping = [0.0; LANES];
            for l in 0..LANES {
                let parts = [wall.parts[0][l], wall.parts[1][l]];
                let approach = modes.approach[w][l];
                let (f, e) = L::force_of(parts, indentation[l], rate[l], approach, factor[w][l]);
                let inside = indentation[l] > 0.0;
                force[l] = if inside { f } else { 0.0 };
                elastic[l] = if inside { e } else { 0.0 };
                damping[l] = if inside { wall.damping[l] } else { 0.0 };
            }
            let mut total = [0.0; LANES];
            let mut add = [0.0; LANES];
            let mut loss_rate = [0.0; LANES];
            for l in 0..LANES {
                total[l] = force[l] + damping[l] * rate[l];
                add[l] = if (active[l] != 0.0) & (total[l] != 0.0) {
                    1.0
                } else {
                    0.0
                };
                loss_rate[l] = if active[l] != 0.0 {
                    (total[l] - elastic[l]) * rate[l]
                } else {
                    0.0
                };
            }
            out[loss] = loss_rate;
            for i in 0..d {
                out[d + i] = push_where(&out[d + i], &wall.push[i], &total, &add);
            }
        }
        out[2 * d + VISCOUS] = viscous;
        out[2 * d + INPUT] = input;
    }

    /// Each lane's force signal, if the lanes are forced, and their
    /// amplitudes, angular frequencies and phases where all are harmonic.
    pub(crate) fn signals(&self) -> Option<(&[Signal], Option<&[V; 3]>)> {
        let (_, _, signals) = self.force.as_ref()?;
        Some((signals, self.harmonics.as_ref()))
    }

    /// What the steps read of `modes` made again where they changed: each
    /// wall's lanes in contact, and each compliant law's `parts[1] /
    /// approach` (which the compact step makes once a step: the same bits
    /// made once a change).
    pub(crate) fn latch(&self, modes: &mut LaneModes) {
        if modes.latched {
            return;
        }
        for (w, wall) in self.walls.iter().enumerate().take(MAX_WALLS) {
            modes.touching[w] = lanes_where(&modes.active[w]);
            for l in 0..LANES {
                modes.factor[w][l] = wall.parts[1][l] / modes.approach[w][l];
            }
        }
        modes.latched = true;
    }

    /// One RK4 step `h` from `start` of every lane in `modes`, as
    /// [`Compact::step`] takes it with no first stage given: the end in
    /// `out.end`, the first stage in `out.first`; each lane's force at the
    /// four stages' times in `values` (each lane's through its own cache, in
    /// the order of the stages).
    pub(crate) fn step(
        &self,
        start: &LaneState,
        h: f64,
        modes: &LaneModes,
        values: &[V; 4],
        out: &mut LaneStep,
    ) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") {
                // SAFETY: the processor has the feature the function is built for.
                return unsafe { self.step_avx512(start, h, modes, values, out) };
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: as above.
                return unsafe { self.step_avx2(start, h, modes, values, out) };
            }
        }
        self.step_in((self.n, self.k), start, h, modes, values, false, out)
    }

    step_with!(step_avx512, "avx512f");
    step_with!(step_avx2, "avx2");

    /// `first_given`: `out.first` holds the first stage already (the rates
    /// at `start` with `values[0]`, the same bits).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn step_in(
        &self,
        (n, k): (usize, usize),
        start: &LaneState,
        h: f64,
        modes: &LaneModes,
        values: &[V; 4],
        first_given: bool,
        out: &mut LaneStep,
    ) {
        let coordinates = 2 * (n + k);
        let len = self.len.min(MAX_LEN);
        let hw = [h * RK4_A[1][0], h * RK4_A[2][1], h * RK4_A[3][2]];
        let w = [h * RK4_B[0], h * RK4_B[1], h * RK4_B[2], h * RK4_B[3]];
        let LaneStep {
            end,
            first,
            point,
            stages,
            ..
        } = out;
        // Every slot of the state's length is written by each rate (the
        // compact step's fresh zeros are not needed).
        debug_assert!(modes.latched, "the modes' factors made (Group::latch)");
        let factor = &modes.factor;
        if !first_given {
            self.rates((n, k), start, &values[0], modes, factor, first);
        }
        let [k1, k2, k3] = &mut **stages;
        stage_points(point, (start, hw[0], first), coordinates);
        self.rates((n, k), point, &values[1], modes, factor, k1);
        stage_points(point, (start, hw[1], k1), coordinates);
        self.rates((n, k), point, &values[2], modes, factor, k2);
        stage_points(point, (start, hw[2], k2), coordinates);
        self.rates((n, k), point, &values[3], modes, factor, k3);
        combine(end, start, &w, [first, k1, k2, k3], len);
    }
}
