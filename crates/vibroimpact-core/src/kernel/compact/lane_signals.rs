//! Each lane's cache of its force signal ([`Cached`]), held by the lanes
//! field by field while they step the runs: a fixed step's values are
//! rotations of each lane's phasor, made for every lane at once in vector
//! instructions (the cache's own multiplications, so the same bits); a lane
//! whose cache does not rotate (a first value, a new increment, a resync,
//! a signal that is not harmonic) takes the cache's own path.

#![allow(clippy::needless_range_loop)]

use super::lanes::{LANES, V};
use crate::model::assembly::{rotated, same_increment, same_instant, Cached, CachedParts, RESYNC};
use crate::model::signals::Signal;
use crate::numerics::series::{
    in_quadrant, quadrant_reduce, reduces, sin_cos_series, SERIES_ANGLE,
};

/// [`LaneCaches::values`] compiled for a processor feature (the same
/// operations, so the same bits, in wider vector instructions).
macro_rules! values_with {
    ($name:ident, $feature:literal) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feature)]
        unsafe fn $name(
            &mut self,
            signals: &[Signal],
            harmonics: Option<&[V; 3]>,
            live: &[bool; LANES],
            time: f64,
        ) -> V {
            self.values_in(signals, harmonics, live, time)
        }
    };
}

/// The caches of the lanes (see the module's doc).
#[derive(Debug, Clone)]
pub(crate) struct LaneCaches {
    time: V,
    value: V,
    cos: V,
    sin: V,
    delta: V,
    delta_cos: V,
    delta_sin: V,
    rotations: [u32; LANES],
}

impl Default for LaneCaches {
    /// Every lane's cache empty.
    fn default() -> Self {
        let mut me = Self {
            time: [0.0; LANES],
            value: [0.0; LANES],
            cos: [0.0; LANES],
            sin: [0.0; LANES],
            delta: [0.0; LANES],
            delta_cos: [0.0; LANES],
            delta_sin: [0.0; LANES],
            rotations: [0; LANES],
        };
        for l in 0..LANES {
            me.set(l, &Cached::EMPTY);
        }
        me
    }
}

impl LaneCaches {
    /// Lane `l`'s cache.
    pub(crate) fn get(&self, l: usize) -> Cached {
        Cached::of_parts(&CachedParts {
            values: [
                self.time[l],
                self.value[l],
                self.cos[l],
                self.sin[l],
                self.delta[l],
                self.delta_cos[l],
                self.delta_sin[l],
            ],
            rotations: self.rotations[l],
        })
    }

    /// Lane `l`'s cache set to `cache`.
    pub(crate) fn set(&mut self, l: usize, cache: &Cached) {
        let CachedParts { values, rotations } = cache.parts();
        [
            self.time[l],
            self.value[l],
            self.cos[l],
            self.sin[l],
            self.delta[l],
            self.delta_cos[l],
            self.delta_sin[l],
        ] = values;
        self.rotations[l] = rotations;
    }

    /// Each lane in `live` its signal's value at `time` through its cache,
    /// as [`Cached::value`] gives it; `harmonics`, each lane's harmonic's
    /// amplitude, angular frequency and phase where every lane's signal is
    /// one (the vector's path, see [`Self::turn`]).
    pub(crate) fn values(
        &mut self,
        signals: &[Signal],
        harmonics: Option<&[V; 3]>,
        live: &[bool; LANES],
        time: f64,
    ) -> V {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") {
                // SAFETY: the processor has the feature the function is built for.
                return unsafe { self.values_avx512(signals, harmonics, live, time) };
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: as above.
                return unsafe { self.values_avx2(signals, harmonics, live, time) };
            }
        }
        self.values_in(signals, harmonics, live, time)
    }

    values_with!(values_avx512, "avx512f");
    values_with!(values_avx2, "avx2");

    #[inline(always)]
    fn values_in(
        &mut self,
        signals: &[Signal],
        harmonics: Option<&[V; 3]>,
        live: &[bool; LANES],
        time: f64,
    ) -> V {
        let mut cold = *live;
        if let Some(harmonics) = harmonics {
            cold = self.turn(harmonics, live, time);
        }
        for l in 0..LANES {
            if cold[l] {
                let mut cache = self.get(l);
                cache.value(&signals[l], time);
                self.set(l, &cache);
            }
        }
        self.value
    }

    /// [`Cached::value`] of each lane's harmonic (`[amplitude, omega,
    /// phase]`) at `time`, kept in the lanes of `live` whose time is not
    /// `time` already (to its round-off, [`same_instant`]): a rotation by
    /// the cached increment, the increment's first (its rotation's series,
    /// then the rotation), or a direct
    /// evaluation (the reduced angle's series), each the cache's
    /// operations, the series made only where a lane needs them. The lanes
    /// of `live` it could not take (angles beyond the series', not
    /// numbers), to be taken lane by lane.
    #[inline(always)]
    fn turn(
        &mut self,
        [amplitude, omega, phase]: &[V; 3],
        live: &[bool; LANES],
        time: f64,
    ) -> [bool; LANES] {
        let (mut first, mut rotates, mut direct) = ([false; LANES], [false; LANES], [false; LANES]);
        let mut same = [false; LANES];
        let (mut any_first, mut any_direct, mut any_due) = (false, false, false);
        for l in 0..LANES {
            let due = live[l] & !same_instant(time, self.time[l]);
            any_due |= due;
            same[l] = same_increment(time - self.time[l], self.delta[l], time);
            let rotations = self.rotations[l];
            first[l] = due & same[l] & (rotations == 0);
            rotates[l] = due & same[l] & (rotations > 0) & (rotations < RESYNC);
            direct[l] = due & !first[l] & !rotates[l];
            any_first |= first[l];
            any_direct |= direct[l];
        }
        let mut cold = [false; LANES];
        if !any_due {
            // Every lane's value is its cached one (a step's repeated
            // midpoint, its start at the last one's end).
            return cold;
        }
        if any_first {
            // The increment's rotation, where it is its first repeat.
            for l in 0..LANES {
                let angle = omega[l] * self.delta[l];
                let (ds, dc) = sin_cos_series(angle);
                let series = angle.abs() <= SERIES_ANGLE;
                cold[l] |= first[l] & !series;
                first[l] &= series;
                self.delta_sin[l] = if first[l] { ds } else { self.delta_sin[l] };
                self.delta_cos[l] = if first[l] { dc } else { self.delta_cos[l] };
            }
        }
        let (mut xs, mut xc) = ([0.0; LANES], [0.0; LANES]);
        if any_direct {
            // The angle itself, elsewhere.
            for l in 0..LANES {
                let x = omega[l] * time + phase[l];
                let (k, r) = quadrant_reduce(x);
                let (rs, rc) = sin_cos_series(r);
                (xs[l], xc[l]) = in_quadrant(k, rs, rc);
                cold[l] |= direct[l] & !reduces(x);
                direct[l] &= reduces(x);
                let delta = time - self.time[l];
                self.delta[l] = if direct[l] & !same[l] {
                    delta
                } else {
                    self.delta[l]
                };
            }
        }
        for l in 0..LANES {
            let (c, s) = rotated(
                self.cos[l],
                self.sin[l],
                self.delta_cos[l],
                self.delta_sin[l],
            );
            let turned = first[l] | rotates[l];
            let (sin, cos) = if direct[l] { (xs[l], xc[l]) } else { (s, c) };
            let keep = turned | direct[l];
            self.sin[l] = if keep { sin } else { self.sin[l] };
            self.cos[l] = if keep { cos } else { self.cos[l] };
            self.value[l] = if keep {
                amplitude[l] * cos
            } else {
                self.value[l]
            };
            self.time[l] = if keep { time } else { self.time[l] };
            let rotations = if direct[l] {
                u32::from(same[l])
            } else {
                self.rotations[l] + u32::from(turned)
            };
            self.rotations[l] = rotations;
        }
        cold
    }
}
