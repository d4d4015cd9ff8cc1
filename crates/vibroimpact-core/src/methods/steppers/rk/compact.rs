//! The adaptive tableaus (Dormand-Prince 5(4), DOP853) on a small modal
//! system in fixed-size arrays, as RK4 takes them in [`Compact::rk4`]: the
//! stages in a store of fixed size, the tableau's constants static, every
//! loop over the coordinates of a length fixed at compile time where
//! [`crate::kernel::sized::by_size`] fixes the sizes. The arithmetic is the
//! general stages' ([`super::rk`]), term for term and in the same order: the
//! same bits (a test holds them to it).

// Indexed loops over the fixed-size arrays: what compiles to the tight code
// here (as in `kernel::compact`).
#![allow(clippy::needless_range_loop)]

use super::{dop853_error, embedded_error, ExplicitRk, Fixed};
use crate::kernel::compact::{Compact, Factors, MAX_LEN, MAX_WALLS};
use crate::kernel::sized::by_size;
use crate::methods::tableau::*;
use crate::model::assembly::{Assembly, Mode, Scratch, CONTACT};

/// The most stages a tableau has, plus `f` at the new point (DOP853's 12 + 1).
pub(super) const MAX_STAGES: usize = 13;

/// The stage derivatives of the compact path.
pub(super) type Stages = [[f64; MAX_LEN]; MAX_STAGES];

/// A tableau's constants (see [`crate::methods::tableau`]): constants of
/// the type, which the compiler folds into each stage written out (a zero
/// weight then costs nothing).
pub(super) trait Tableau<const S: usize> {
    const C: [f64; S];
    const A: [[f64; S]; S];
    const B: [f64; S];
}

pub(super) struct Dopri5;
impl Tableau<7> for Dopri5 {
    const C: [f64; 7] = DOPRI5_C;
    const A: [[f64; 7]; 7] = DOPRI5_A;
    const B: [f64; 7] = DOPRI5_B;
}

pub(super) struct Dop853;
impl Tableau<12> for Dop853 {
    const C: [f64; 12] = DOP853_C;
    const A: [[f64; 12]; 12] = DOP853_A;
    const B: [f64; 12] = DOP853_B;
}

/// A store for the stages, where a state of `len` values fits the arrays.
pub(super) fn stages(len: usize) -> Option<Box<Stages>> {
    (len <= MAX_LEN).then(|| Box::new([[0.0; MAX_LEN]; MAX_STAGES]))
}

/// `out = y + h sum_j weights_j k_j` over `len` values, skipping zero
/// weights: the general path's `combine`, term for term.
#[inline(always)]
fn combine<const J: usize>(
    out: &mut [f64; MAX_LEN],
    y: &[f64; MAX_LEN],
    len: usize,
    h: f64,
    weights: &[f64; J],
    k: &Stages,
) {
    let len = len.min(MAX_LEN);
    let mut first = true;
    for j in 0..J {
        let weight = weights[j];
        if weight == 0.0 {
            continue;
        }
        let hw = h * weight;
        let kj = &k[j];
        if first {
            for e in 0..len {
                out[e] = y[e] + hw * kj[e];
            }
            first = false;
        } else {
            for e in 0..len {
                out[e] += hw * kj[e];
            }
        }
    }
    if first {
        out[..len].copy_from_slice(&y[..len]);
    }
}

impl Compact {
    /// The stages of a step `h` from `(time, start)` by the tableau `T` for
    /// `n` modes and `k` dampers, and its new point into `out` (every wall's
    /// room); `stages[0]` holds `f(start)` where `start_valid`, and receives
    /// it where not. The general path's `tableau_stages` and `combine`, each
    /// stage written out (a loop over them keeps the weights in memory and
    /// tests each for zero).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn tableau_step<const S: usize, T: Tableau<S>>(
        &self,
        system: &Assembly,
        (n, k): (usize, usize),
        time: f64,
        start: &[f64; MAX_LEN],
        h: f64,
        modes: (&[Mode], &Factors),
        scratch: &mut Scratch,
        stages: &mut Stages,
        start_valid: bool,
        out: &mut [f64; MAX_LEN],
    ) {
        let coordinates = 2 * (n + k);
        if !start_valid {
            self.rates::<true, false>(system, n, k, time, start, modes, scratch, &mut stages[0]);
        }
        // The stage points need the coordinates and velocities only.
        let mut point = [0.0; MAX_LEN];
        macro_rules! stage {
            ($($i:literal)+) => {$(
                if $i < S {
                    let row: &[f64; $i] = T::A[$i][..$i].try_into().unwrap();
                    combine(&mut point, start, coordinates, h, row, stages);
                    let time = time + T::C[$i] * h;
                    let stage = &mut stages[$i];
                    self.rates::<true, false>(system, n, k, time, &point, modes, scratch, stage);
                }
            )+};
        }
        stage!(1 2 3 4 5 6 7 8 9 10 11);
        // Over every wall's room (a length fixed at compile time; the rooms
        // past the system's walls hold zeros in the start and every stage).
        let rooms = (coordinates + CONTACT + MAX_WALLS).min(MAX_LEN);
        combine(out, start, rooms, h, &T::B, stages);
    }

    /// [`Self::rates`] at `(time, y)` into `out`: `f` at a step's new point.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn end_rates(
        &self,
        system: &Assembly,
        (n, k): (usize, usize),
        time: f64,
        y: &[f64; MAX_LEN],
        modes: (&[Mode], &Factors),
        scratch: &mut Scratch,
        out: &mut [f64; MAX_LEN],
    ) {
        self.rates::<true, false>(system, n, k, time, y, modes, scratch, out);
    }
}

impl ExplicitRk {
    /// [`SystemStepper::attempt`](super::super::SystemStepper::attempt) on
    /// the compact path of `compact`, `system`'s own (the stepper holds a
    /// store of stages): the general path's steps and errors, to the bit.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn compact_attempt(
        &mut self,
        compact: &Compact,
        system: &Assembly,
        time: f64,
        y: &[f64],
        h: f64,
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) -> f64 {
        let Some((fixed, stages)) = &mut self.fixed else {
            unreachable!("the compact path has its store")
        };
        let len = system.state_len().min(MAX_LEN);
        let mut start = [0.0; MAX_LEN];
        start[..len].copy_from_slice(&y[..len]);
        let mut end = [0.0; MAX_LEN];
        let factors = compact.rate_factors(modes);
        let start_valid = self.start_valid;
        let rates = (modes, &factors);
        by_size!(system, |n, k| match fixed {
            Fixed::Dopri5 => compact.tableau_step::<7, Dopri5>(
                system,
                (n, k),
                time,
                &start,
                h,
                rates,
                scratch,
                stages,
                start_valid,
                &mut end,
            ),
            Fixed::Dop853 => {
                compact.tableau_step::<12, Dop853>(
                    system,
                    (n, k),
                    time,
                    &start,
                    h,
                    rates,
                    scratch,
                    stages,
                    start_valid,
                    &mut end,
                );
                let at_end = &mut stages[DOP853_C.len()];
                compact.end_rates(system, (n, k), time + h, &end, rates, scratch, at_end);
            }
        });
        let dop853 = *fixed == Fixed::Dop853;
        self.evaluations += (self.stages - usize::from(start_valid) + usize::from(dop853)) as u64;
        self.start_valid = true;
        out[..len].copy_from_slice(&end[..len]);
        let coordinates = 2 * system.dim;
        let (atol, rtol) = (self.atol, self.rtol);
        let scale = |n: usize| atol + rtol * start[n].abs().max(end[n].abs());
        if dop853 {
            self.end_slot = Some(DOP853_C.len());
            dop853_error(&DOP853_E5, &DOP853_E3, &stages[..], h, coordinates, scale)
        } else {
            self.end_slot = Some(DOPRI5_C.len() - 1);
            embedded_error(&DOPRI5_E, &stages[..], h, coordinates, scale)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::ExplicitRk;
    use crate::kernel::events::{integrate_system, ContactKind, RunOptions};
    use crate::kernel::reductions::ReduceOptions;
    use crate::model::assembly::{
        initial_state, Assembly, Damper, Excitation, Load, PairLaw, Side, Stop, SystemSpec,
    };
    use crate::model::contact::{Contact, LawKind};
    use crate::model::signals::Signal;
    use crate::model::structure::Structure;

    /// A forced oscillator with a damper of `law` and, where `stop`, a
    /// linear compliant stop below it and gravity (a rigid damper then
    /// rattles and sticks on the structure).
    fn oscillator(law: PairLaw, stop: bool) -> SystemSpec {
        let stops = vec![Stop {
            at: 0.0,
            side: Side::Lower,
            gap: 0.01,
            law: PairLaw::Compliant(Contact::new(LawKind::Linear, 2e4, None, 3.0).unwrap()),
            against: None,
        }];
        SystemSpec {
            structure: Structure::oscillator(1.0, 400.0, 0.5).unwrap(),
            dampers: vec![Damper {
                mass: 0.05,
                at: 0.0,
                lower_clearance: 3e-3,
                upper_clearance: 3e-3,
                law,
            }],
            collisions: vec![],
            frictions: vec![],
            stops: if stop { stops } else { vec![] },
            gravity: if stop { 9.81 } else { 0.0 },
            excitations: vec![Excitation {
                load: Load::Force { at: 0.0 },
                signal: Signal::harmonic(12.0, 3.0, 0.0).unwrap(),
            }],
            points: vec![],
            moments: vec![],
        }
    }

    #[test]
    fn adaptive_tableaus_compact_path_is_their_general_path_to_the_bit() {
        crate::testing::timeout(120, || {
            let hertz = Contact::new(LawKind::Hertz, 1e7, None, 0.0).unwrap();
            let hysteresis = Contact::new(LawKind::HysterHertz, 1e7, Some(0.7), 0.0).unwrap();
            let cases = [
                (PairLaw::Compliant(hertz), false),
                (PairLaw::Compliant(hysteresis), false),
                (PairLaw::rigid(0.6).unwrap(), true),
            ];
            for (law, stop) in cases {
                let system = Assembly::new(&oscillator(law, stop)).unwrap();
                assert!(system.compact.is_some());
                let y = initial_state(&system, &[0.0], &[0.3], &[0.0], &[0.0]).unwrap();
                let options = RunOptions {
                    dt: None,
                    t_end: 1.0,
                    every: 3,
                    keep_history: true,
                    max_steps: u64::MAX,
                    max_rows: u64::MAX,
                    energy_tolerance: 1e-2,
                    reduce: ReduceOptions {
                        record_from: 0.2,
                        strobe_period: 0.1,
                        mean_square: true,
                        ..ReduceOptions::default()
                    },
                };
                for rtol in [1e-6, 1e-10] {
                    let methods = [
                        |len, rtol| ExplicitRk::dopri5(len, rtol, 1e-3 * rtol),
                        |len, rtol| ExplicitRk::dop853(len, rtol, 1e-3 * rtol),
                    ];
                    for method in methods {
                        let [fast, general] = [true, false].map(|compact| {
                            let mut stepper = method(system.state_len(), rtol);
                            stepper.compact = compact;
                            integrate_system(&system, &mut stepper, &y, &options, &mut || false)
                        });
                        let contacts = &fast.as_ref().unwrap().contacts;
                        assert!(contacts.len() > 5, "{law:?}: {}", contacts.len());
                        if stop {
                            assert!(contacts.iter().any(|c| c.kind == ContactKind::Sticking));
                        }
                        let [fast, general] = [fast, general].map(|r| format!("{r:?}"));
                        assert!(fast == general, "{law:?} {rtol}");
                    }
                }
            }
        });
    }
}
