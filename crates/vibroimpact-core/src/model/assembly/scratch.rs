//! The work space of the rates: each signal's last value (a harmonic's
//! phasor) and the sticking pairs' constraint system.

use super::Assembly;
use crate::model::signals::{Harmonic, Signal};
use crate::numerics::series::{sin_cos, sin_cos_by_quadrant};

/// The last value of a signal: Runge-Kutta stages share times (RK4's two
/// midpoints, a step's end and the next one's start), and a harmonic's
/// cosine is the costliest part of a small system's right-hand side. For a
/// harmonic it also keeps the phasor `(cos, sin)` of its angle and the
/// rotation of the last time increment: fixed steps repeat the same
/// increments, so most values are a rotation (four multiplications), with a
/// direct evaluation every `RESYNC` rotations to keep round-off from growing.
/// Direct evaluations reduce the angle to a quadrant and take the short
/// series (see [`crate::numerics::series`]): the library's sine and cosine also save
/// and restore the rounding mode, which cost 5 % of a run with many events.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cached {
    time: f64,
    value: f64,
    cos: f64,
    sin: f64,
    delta: f64,
    delta_cos: f64,
    delta_sin: f64,
    rotations: u32,
}

/// Rotations between direct evaluations of a harmonic.
pub(crate) const RESYNC: u32 = 64;

/// The phasor `(c, s)` turned by the rotation `(delta_cos, delta_sin)`
/// (the cache's four multiplications, which the lockstep lanes make in
/// vector instructions: the same bits).
#[inline(always)]
pub(crate) fn rotated(c: f64, s: f64, delta_cos: f64, delta_sin: f64) -> (f64, f64) {
    (c * delta_cos - s * delta_sin, s * delta_cos + c * delta_sin)
}

/// Whether a time increment `delta` to `time` is the cached one, `cached`:
/// the same to the round-off of the times themselves (t + h/2 and t + h
/// differ by h/2 only to a few ulps of t), so rotating by the cached one
/// errs no more than the cosine's own argument does.
#[inline(always)]
pub(crate) fn same_increment(delta: f64, cached: f64, time: f64) -> bool {
    (delta - cached).abs() <= 8.0 * f64::EPSILON * time.abs()
}

/// Whether `time` is the `cached` instant, up to a time's round-off: a
/// fixed step's last stage `time + dt` and the next grid point
/// `(grid + 1) dt` differ in their last bits, and the signal's value there
/// is one value (the next step's first stage then takes the last one's,
/// and its increments stay the steps' own). Every path's caches take it
/// (an event's located instant, a step's end a few ulps from it too).
#[inline(always)]
pub(crate) fn same_instant(time: f64, cached: f64) -> bool {
    (time - cached).abs() <= 4.0 * f64::EPSILON * time.abs()
}

/// A [`Cached`]'s fields, for the lockstep lanes' copy of it.
pub(crate) struct CachedParts {
    /// `[time, value, cos, sin, delta, delta_cos, delta_sin]`.
    pub(crate) values: [f64; 7],
    pub(crate) rotations: u32,
}

impl Cached {
    pub(crate) const EMPTY: Self = Self {
        time: f64::NAN,
        value: 0.0,
        cos: 1.0,
        sin: 0.0,
        delta: f64::NAN,
        delta_cos: 1.0,
        delta_sin: 0.0,
        rotations: RESYNC,
    };

    /// The phasor turned by the cached increment.
    #[inline(always)]
    fn rotate(&mut self) {
        (self.cos, self.sin) = rotated(self.cos, self.sin, self.delta_cos, self.delta_sin);
        self.rotations += 1;
    }

    /// Its fields (see [`CachedParts`]).
    pub(crate) fn parts(&self) -> CachedParts {
        CachedParts {
            values: [
                self.time,
                self.value,
                self.cos,
                self.sin,
                self.delta,
                self.delta_cos,
                self.delta_sin,
            ],
            rotations: self.rotations,
        }
    }

    /// The cache of `parts`.
    pub(crate) fn of_parts(parts: &CachedParts) -> Self {
        let [time, value, cos, sin, delta, delta_cos, delta_sin] = parts.values;
        Self {
            time,
            value,
            cos,
            sin,
            delta,
            delta_cos,
            delta_sin,
            rotations: parts.rotations,
        }
    }

    /// The phasor at `time`, `delta` after the last, where the steps' path
    /// (`rotate`) does not serve: the first repeat of an increment, whose
    /// rotation it computes, or a new increment or a resync, where the angle
    /// is evaluated directly (a value then depends on its time alone, as in
    /// adaptive steps, whose increments do not repeat). `same`: whether the
    /// increment is the cached one. Out of line.
    #[cold]
    #[inline(never)]
    fn turn(&mut self, h: &Harmonic, time: f64, same: bool) {
        let omega = std::f64::consts::TAU * h.frequency;
        if same && self.rotations == 0 {
            (self.delta_sin, self.delta_cos) = sin_cos(omega * self.delta);
            self.rotate();
        } else {
            (self.sin, self.cos) = sin_cos_by_quadrant(omega * time + h.phase);
            if same {
                // A resync: the increment, and so its rotation, stands.
                self.rotations = 1;
            } else {
                self.delta = time - self.time;
                self.rotations = 0;
            }
        }
    }

    #[inline(always)]
    pub(crate) fn value(&mut self, signal: &Signal, time: f64) -> f64 {
        if same_instant(time, self.time) {
            return self.value;
        }
        match signal {
            Signal::Harmonic(h) => {
                let delta = time - self.time;
                let same = same_increment(delta, self.delta, time);
                if same && self.rotations > 0 && self.rotations < RESYNC {
                    self.rotate();
                } else {
                    self.turn(h, time, same);
                }
                self.value = h.amplitude * self.cos;
            }
            _ => self.value = signal.value(time),
        }
        self.time = time;
        self.value
    }
}

/// Work space of [`Assembly::rates`], allocated once per run.
#[derive(Debug, Clone)]
pub struct Scratch {
    pub(super) force_values: Vec<Cached>,
    pub(super) base_values: Vec<Cached>,
    pub(crate) sticking: Vec<usize>,
    pub(super) matrix: Vec<f64>,
    /// Constraint forces of the sticking interactions (N), after `rates`.
    pub forces: Vec<f64>,
    /// How many interactions were sticking in the last `rates`.
    pub count: usize,
}

impl Scratch {
    pub fn new(assembly: &Assembly) -> Self {
        // Only rigid pairs stick: without one the constraint system is
        // never solved (and a run's set-up allocates nothing for it).
        let m = if assembly.has_rigid() || assembly.has_friction() {
            assembly.interactions.len().max(1)
        } else {
            0
        };
        let empty = Cached::EMPTY;
        Self {
            force_values: vec![empty; assembly.forces.len()],
            base_values: vec![empty; assembly.base.len()],
            sticking: vec![0; m],
            matrix: vec![0.0; m * m],
            forces: vec![0.0; m],
            count: 0,
        }
    }

    /// The signals' caches of `stages` (the same system's): the values at
    /// the instants its stages last took, to the bit.
    pub(crate) fn signals_from(&mut self, stages: &Scratch) {
        self.force_values.copy_from_slice(&stages.force_values);
        self.base_values.copy_from_slice(&stages.base_values);
    }

    /// The first force's signal cache, which a step that is taken back
    /// restores (the next values then come as they would have).
    pub(crate) fn first_cache(&mut self) -> Option<&mut Cached> {
        self.force_values.first_mut()
    }

    /// Whether the first force's is the only signal cache (see
    /// [`Self::first_cache`]).
    pub(crate) fn first_cache_only(&self) -> bool {
        self.force_values.len() <= 1 && self.base_values.is_empty()
    }

    /// The first force's signal at `time`, through its cache (the value the
    /// general right-hand side takes, to the bit).
    #[inline(always)]
    pub(crate) fn first_force_value(&mut self, signal: &Signal, time: f64) -> f64 {
        self.force_values[0].value(signal, time)
    }

    /// The constraint force of interaction `i` in the last `rates` (N), or
    /// None when it was not sticking.
    pub fn force_of(&self, i: usize) -> Option<f64> {
        self.sticking[..self.count]
            .iter()
            .position(|&j| j == i)
            .map(|s| self.forces[s])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_harmonic_s_cached_value_is_its_cosine_along_steps_events_and_returns() {
        crate::testing::timeout(30, || {
            let signal = Signal::harmonic(0.5, 8.0, 0.3).unwrap();
            let Signal::Harmonic(h) = &signal else {
                unreachable!()
            };
            let exact =
                |t: f64| h.amplitude * (std::f64::consts::TAU * h.frequency * t + h.phase).cos();
            let mut cache = Cached::EMPTY;
            let (dt, mut time, mut worst) = (1e-5, 0.0, 0.0f64);
            let mut check = |cache: &mut Cached, t: f64| {
                worst = worst.max((cache.value(&signal, t) - exact(t)).abs());
            };
            for step in 0..200_000u64 {
                // RK4's stage times on the grid; every 97th step an event:
                // a fraction of a step, a look back, and a long jump every
                // 1001st (more than an eighth of a turn).
                let next = if step % 97 == 0 {
                    check(&mut cache, time - 0.3 * dt);
                    time + 0.37 * dt
                } else if step % 1001 == 0 {
                    time + 0.02
                } else {
                    (time / dt).floor() * dt + dt
                };
                for t in [time, time + 0.5 * (next - time), next] {
                    check(&mut cache, t);
                }
                time = next;
            }
            // The angle's own round-off at t ~ 5 s is ~1e-13 rad; rotations
            // by increments equal to a few ulps of t add ~1e-11.
            assert!(time > 4.0 && worst < 1e-10, "{time} {worst}");
        });
    }

    #[test]
    fn fixed_steps_take_a_harmonic_s_values_by_rotation_and_share_the_grid_points() {
        crate::testing::timeout(30, || {
            let signal = Signal::harmonic(0.5, 8.0, 0.3).unwrap();
            let exact = |t: f64| 0.5 * (std::f64::consts::TAU * 8.0 * t + 0.3).cos();
            let (dt, steps) = (1e-5, 100_000u64);
            let mut cache = Cached::EMPTY;
            let (mut direct, mut worst, mut last) = (0u64, 0.0f64, f64::NAN);
            for grid in 0..steps {
                // RK4's stage times of the fixed step from grid point
                // `grid`, as the kernel makes them.
                let time = grid as f64 * dt;
                for (stage, t) in [time, time + 0.5 * dt, time + 0.5 * dt, time + dt]
                    .into_iter()
                    .enumerate()
                {
                    let (before, was) = (cache.parts().rotations, cache.parts().values[0]);
                    let value = cache.value(&signal, t);
                    let (after, at) = (cache.parts().rotations, cache.parts().values[0]);
                    // A new time not reached by one rotation: evaluated directly.
                    let moved = at.to_bits() != was.to_bits();
                    direct += u64::from(moved && after != before + 1);
                    worst = worst.max((value - exact(t)).abs());
                    if stage == 0 && grid > 0 {
                        // The grid point is the last step's end, whose
                        // value it takes (`time + dt` and `(grid + 1) dt`
                        // differ in their last bits).
                        assert_eq!(value.to_bits(), last.to_bits(), "grid {grid}");
                    }
                    if stage == 3 {
                        last = value;
                    }
                }
                // The next step's start: the last stage's value.
                let next = (grid + 1) as f64 * dt;
                let value = cache.value(&signal, next);
                assert_eq!(value.to_bits(), last.to_bits(), "grid {grid}");
            }
            // Two rotations a step and a direct evaluation every RESYNC of
            // them (about one in 31 steps): not one or two each step, as
            // where a grid point missed the cache by its last bits.
            let most = steps / 16;
            assert!(direct <= most, "{direct} direct evaluations > {most}");
            assert!(worst < 1e-10, "{worst}");
        });
    }
}
