//! What the compact stretches add to the reductions in the recorded
//! window (see [`crate::kernel::reductions::reduce_step`]): the observed
//! quantities' peaks and mean squares, in the fixed-size arrays.

#![allow(clippy::needless_range_loop)]

use super::{Compact, Factors, MAX_LEN, MAX_MODES};
use crate::kernel::reductions::{quintic, square_integral};
use crate::model::assembly::{Assembly, Mode, Scratch};

impl Compact {
    /// A plain step of `length` from `(time, y)` to `end` in the recorded
    /// window added to the stretch's reductions `sums` as
    /// [`crate::kernel::reductions::reduce_step`] adds it: the observed
    /// quantities' peaks at its ends, the recorded time and, where `summed`,
    /// the mean squares, with the rates at its ends made as it makes them
    /// (through the reductions' own scratch): `rates` holds those at its
    /// start where `valid`, and receives those at its end in their place.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn reduce_plain<const STICKING: bool, const FREE: bool>(
        &self,
        system: &Assembly,
        (n, k): (usize, usize),
        ((time, y), (length, end)): (Timed<'_>, Timed<'_>),
        at: (&[Mode], &Factors),
        (rates, valid, summed): (&mut [[f64; MAX_LEN]; 2], bool, bool),
        (peaks, squares, recorded_time, scratch): Sums<'_>,
    ) {
        let observed = system.observed();
        let kept = observed.min(peaks.len());
        widen_peaks(system, &mut peaks[..kept], (&y[..], &end[..]), n);
        *recorded_time += length;
        if !summed {
            return;
        }
        let [start_rates, end_rates] = rates;
        if !valid {
            self.rates::<STICKING, FREE>(system, n, k, time, y, at, scratch, start_rates);
        }
        // The end's time as the kernel's reductions make it.
        let next = time + length;
        self.rates::<STICKING, FREE>(system, n, k, next, end, at, scratch, end_rates);
        let ends = ((y, end), (&*start_rates, &*end_rates));
        let kept = observed.min(squares.len());
        add_mean_squares(system, &mut squares[..kept], ends, (n + k, n), length);
        *start_rates = *end_rates;
    }
}

/// A stretch's reductions: the observed quantities' peaks and mean-square
/// integrals, the recorded time (s), and the reductions' own scratch.
pub(super) type Sums<'s> = (&'s mut [f64], &'s mut [f64], &'s mut f64, &'s mut Scratch);

/// `n` values of `y` from `from`, copied: a runtime index into the state
/// itself would keep the compact path's state in memory rather than in
/// registers.
#[inline(always)]
fn block(y: &[f64], from: usize, n: usize) -> [f64; MAX_MODES] {
    let mut out = [0.0; MAX_MODES];
    for i in 0..n.min(MAX_MODES) {
        out[i] = y[from + i];
    }
    out
}

/// Whether an observed velocity changes sign in the step from `y` to `end`
/// (`d` coordinates, `n` of the structure, at most [`MAX_MODES`]): a peak
/// inside it, for the kernel to find.
#[inline(always)]
pub(crate) fn peak_inside(
    system: &Assembly,
    observed: usize,
    (y, end): (&[f64], &[f64]),
    d: usize,
    n: usize,
) -> bool {
    if n > MAX_MODES {
        let of = |j, block: &[f64]| system.observe(j, &block[d..d + n]);
        return (0..observed).any(|j| of(j, y) * of(j, end) < 0.0);
    }
    let (v0, v1) = (block(y, d, n), block(end, d, n));
    (0..observed).any(|j| system.observe(j, &v0[..n]) * system.observe(j, &v1[..n]) < 0.0)
}

/// The step of `length` from `y` to `end` (structure rates `rates` at its
/// ends) added to the observed quantities' mean-square integrals `squares`
/// (`d` coordinates, `n` of the structure), as
/// [`crate::kernel::reductions::reduce_step`] adds a step with no peak
/// inside: the integral of the square of the step's quintic interpolant.
#[inline(always)]
fn add_mean_squares(
    system: &Assembly,
    squares: &mut [f64],
    ((y, end), (start_rates, end_rates)): Ends<'_>,
    (d, n): (usize, usize),
    h: f64,
) {
    if n > MAX_MODES {
        let (x, v) = (0..n, d..d + n);
        for (j, square) in squares.iter_mut().enumerate() {
            let of = |block: &[f64]| system.observe(j, block);
            let a = quintic(
                of(&y[x.clone()]),
                of(&end[x.clone()]),
                h * of(&y[v.clone()]),
                h * of(&end[v.clone()]),
                h * h * of(&start_rates[v.clone()]),
                h * h * of(&end_rates[v.clone()]),
            );
            *square += h * square_integral(&a);
        }
        return;
    }
    // Copies: a runtime index into the states would keep them in memory.
    let (x0, x1) = (block(y, 0, n), block(end, 0, n));
    let (v0, v1) = (block(y, d, n), block(end, d, n));
    let (a0, a1) = (block(start_rates, d, n), block(end_rates, d, n));
    for (j, square) in squares.iter_mut().enumerate() {
        let a = quintic(
            system.observe(j, &x0[..n]),
            system.observe(j, &x1[..n]),
            h * system.observe(j, &v0[..n]),
            h * system.observe(j, &v1[..n]),
            h * h * system.observe(j, &a0[..n]),
            h * h * system.observe(j, &a1[..n]),
        );
        *square += h * square_integral(&a);
    }
}

/// A state and a time (or a step's length) that goes with it.
type Timed<'s> = (f64, &'s [f64; MAX_LEN]);

/// A step's ends and the rates there.
type Ends<'s> = (
    (&'s [f64; MAX_LEN], &'s [f64; MAX_LEN]),
    (&'s [f64; MAX_LEN], &'s [f64; MAX_LEN]),
);

/// The observed displacements' peaks widened to the step's ends.
#[inline(always)]
pub(crate) fn widen_peaks(
    system: &Assembly,
    peaks: &mut [f64],
    (y, end): (&[f64], &[f64]),
    n: usize,
) {
    let widen = |peaks: &mut [f64], x0: &[f64], x1: &[f64]| {
        for (j, peak) in peaks.iter_mut().enumerate() {
            let (p0, p1) = (system.observe(j, x0), system.observe(j, x1));
            *peak = peak.max(p0.abs().max(p1.abs()));
        }
    };
    if n > MAX_MODES {
        return widen(peaks, &y[..n], &end[..n]);
    }
    let (x0, x1) = (block(y, 0, n), block(end, 0, n));
    widen(peaks, &x0[..n], &x1[..n]);
}
