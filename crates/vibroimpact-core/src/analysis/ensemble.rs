//! Lockstep ensembles: many fixed-step RK4 runs of the two-mass impact damper
//! advanced together, [`LANES`] at a time, so that the compiler turns each
//! lane loop into vector instructions (AVX-512 or AVX2 where the processor
//! has them, chosen at run time; SSE2 otherwise).
//!
//! Each lane is the run the fixed-step kernel ([`crate::legacy::run::integrate`]
//! with [`crate::legacy::integrators::Rk4`]) makes of its member, bit for bit: the
//! same operations in the same order (the contact branch becomes a select,
//! which changes no result), the same provisional approach-rate latch while
//! apart and the same located onset rate in contact. What a lane keeps is
//! reduced: its contacts (counted, onsets located in the step by the cubic
//! Hermite interpolant), the main mass's peak |w| (step ends, and extrema
//! located inside steps by the same interpolant) and RMS (trapezoidal rule
//! over the step ends), and its final state. The rare work (a contact
//! opening or closing, an extremum, the checks) leaves the vector loop for
//! the lane concerned. A lane whose state stops being finite, or whose
//! mechanical energy grows past its start by more than the energy tolerance
//! (an unforced damped system can only lose energy; more is the step's
//! error), is failed with its reason and the others go on.

// Lane loops index several arrays by the same lane, which is what vectorises.
#![allow(clippy::needless_range_loop)]

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::legacy::equations::{Free, Model};
use crate::model::contact::{Contact, ContactLaw, Hertz, HysterHertz, LawKind, Linear};
use crate::model::impact_damper::{ImpactDamper, State};
use crate::numerics::hermite;

/// Runs advanced together: two independent vector chains of eight on
/// AVX-512 (sixteen hide the latency of the square roots and divisions that
/// one chain of eight waits on; 1.6e8 against 1.27e8 trajectory-steps/s).
pub const LANES: usize = 16;
/// Steps between the checks (finite state, energy, interruption).
const CHECK_INTERVAL: u64 = 1024;

/// One run of an ensemble.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Member {
    pub system: ImpactDamper,
    pub contact: Contact,
    pub initial: State,
}

/// The fixed step and what to keep, shared by every member.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnsembleOptions {
    /// s (> 0).
    pub dt: f64,
    /// Steps of `dt` from t = 0.
    pub steps: u64,
    /// Reductions from this time on, s.
    pub record_from: f64,
    /// Largest growth of the mechanical energy, relative to its start.
    pub energy_tolerance: f64,
}

/// What one run kept. On failure `reason` says why and the numbers are NaN.
#[derive(Debug, Clone, PartialEq)]
pub struct MemberResult {
    pub reason: Option<String>,
    /// Contacts whose located onset is at or after `record_from`.
    pub contacts: u64,
    /// Largest |w| recorded, m.
    pub peak: f64,
    /// RMS of w over the recorded time, m (NaN when none is recorded).
    pub rms: f64,
    pub final_state: State,
}

/// Run `members` in lockstep groups on `threads` threads (0: all cores). The
/// results, in the members' order, do not depend on the number of threads
/// nor on how members are grouped. Every member must have the same law kind.
pub fn run_ensemble(
    members: &[Member],
    options: &EnsembleOptions,
    threads: usize,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<MemberResult>> {
    if !(options.dt > 0.0 && options.dt.is_finite()) {
        return Err(Error::Inconsistent(format!(
            "dt must be a finite time step > 0 s, got {}",
            options.dt
        )));
    }
    let Some(first) = members.first() else {
        return Ok(Vec::new());
    };
    let kind = first.contact.law;
    if members.iter().any(|m| m.contact.law != kind) {
        return Err(Error::Inconsistent(
            "an ensemble's members must share one contact law".into(),
        ));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::Inconsistent(format!("cannot start the ensemble's threads: {e}")))?;
    let groups: Vec<Result<Vec<MemberResult>>> = pool.install(|| {
        members
            .par_chunks(LANES)
            .map(|group| match kind {
                LawKind::Hertz => run_group(group, options, interrupt, |c| Hertz {
                    stiffness: c.stiffness,
                }),
                LawKind::Linear => run_group(group, options, interrupt, |c| Linear {
                    stiffness: c.stiffness,
                }),
                LawKind::HysterHertz => run_group(group, options, interrupt, |c| {
                    HysterHertz::paper(c.stiffness, c.restitution)
                }),
                LawKind::HertzDamped => run_group(group, options, interrupt, |c| {
                    HysterHertz::rebounding_at(c.stiffness, c.restitution)
                }),
            })
            .collect()
    });
    let mut results = Vec::with_capacity(members.len());
    for group in groups {
        results.extend(group?);
    }
    Ok(results)
}

/// A quantity of every lane's state `(w, w', y, y')`: the state itself, or
/// its rate (a stage's slopes).
#[derive(Clone, Copy)]
struct Quad {
    w: [f64; LANES],
    wv: [f64; LANES],
    y: [f64; LANES],
    yv: [f64; LANES],
}

impl Quad {
    /// Lane `l`'s state.
    #[inline(always)]
    fn lane(&self, l: usize) -> State {
        State {
            main_displacement: self.w[l],
            main_velocity: self.wv[l],
            impact_displacement: self.y[l],
            impact_velocity: self.yv[l],
        }
    }

    /// `self + h k`, lane by lane (RK4's stage points).
    #[inline(always)]
    fn offset(&self, h: f64, k: &Quad) -> Quad {
        Quad {
            w: std::array::from_fn(|l| self.w[l] + h * k.w[l]),
            wv: std::array::from_fn(|l| self.wv[l] + h * k.wv[l]),
            y: std::array::from_fn(|l| self.y[l] + h * k.y[l]),
            yv: std::array::from_fn(|l| self.yv[l] + h * k.yv[l]),
        }
    }
}

/// The lanes' state and constants, structure of arrays.
#[derive(Clone, Copy)]
struct Lanes<L: ContactLaw> {
    state: Quad,
    damping_per_mass: [f64; LANES],
    stiffness_per_mass: [f64; LANES],
    inverse_main: [f64; LANES],
    inverse_impact: [f64; LANES],
    clearance: [f64; LANES],
    contact_damping: [f64; LANES],
    law: [L; LANES],
}

/// What the rare work of each lane keeps.
struct Tally {
    /// Side of the open contact (0 when apart).
    side: f64,
    approach: f64,
    contacts: u64,
    peak: f64,
    squares: f64,
    failed: Option<String>,
    energy_start: f64,
}

/// The member in lane `l`: the group is padded with copies of its last
/// member, whose results are dropped.
fn padded(group: &[Member], l: usize) -> &Member {
    &group[l.min(group.len() - 1)]
}

fn run_group<L: ContactLaw>(
    group: &[Member],
    options: &EnsembleOptions,
    interrupt: &(dyn Fn() -> bool + Sync),
    law_of: impl Fn(&Contact) -> L,
) -> Result<Vec<MemberResult>> {
    let models: [Model<L, Free>; LANES] = std::array::from_fn(|l| {
        let m = padded(group, l);
        Model::new(&m.system, law_of(&m.contact), m.contact.damping, Free)
    });
    let mut lanes = Lanes {
        state: Quad {
            w: std::array::from_fn(|l| padded(group, l).initial.main_displacement),
            wv: std::array::from_fn(|l| padded(group, l).initial.main_velocity),
            y: std::array::from_fn(|l| padded(group, l).initial.impact_displacement),
            yv: std::array::from_fn(|l| padded(group, l).initial.impact_velocity),
        },
        damping_per_mass: models.map(|m| m.damping_per_mass),
        stiffness_per_mass: models.map(|m| m.stiffness_per_mass),
        inverse_main: models.map(|m| m.inverse_main_mass),
        inverse_impact: models.map(|m| m.inverse_impact_mass),
        clearance: models.map(|m| m.clearance),
        contact_damping: models.map(|m| m.contact_damping),
        law: models.map(|m| m.law),
    };
    let mut tallies = tallies_of(group, &models, options);
    for (l, tally) in tallies.iter_mut().enumerate() {
        if tally.failed.is_some() {
            park(&mut lanes, tally, l);
        }
    }
    let dt = options.dt;
    let first_kept = first_kept(options);
    let kept_steps = options.steps.saturating_sub(first_kept);
    if first_kept == 0 {
        for (l, tally) in tallies.iter_mut().enumerate() {
            tally.peak = lanes.state.w[l].abs();
            tally.squares = 0.5 * lanes.state.w[l] * lanes.state.w[l];
        }
    }
    let mut n = 0u64;
    while n < options.steps {
        let stop = (n + CHECK_INTERVAL).min(options.steps);
        advance(
            &mut lanes,
            &mut tallies,
            &models,
            n,
            stop,
            first_kept,
            options,
        );
        n = stop;
        check_lanes(&mut lanes, &mut tallies, &models, n as f64 * dt, options);
        if interrupt() {
            return Err(Error::Interrupted {
                time: n as f64 * dt,
            });
        }
    }
    Ok(results_of(
        group.len(),
        &lanes,
        &tallies,
        (first_kept, kept_steps),
        options,
    ))
}

/// Each lane's tally at the start: its open contact, if any (counted where
/// recorded from the start), and whether its start is refused.
fn tallies_of<L: ContactLaw>(
    group: &[Member],
    models: &[Model<L, Free>; LANES],
    options: &EnsembleOptions,
) -> Vec<Tally> {
    (0..LANES)
        .map(|l| {
            let s = padded(group, l).initial;
            let model = &models[l];
            let start = model.contact(&s, model.side(&s) * s.relative_velocity());
            let failed = crate::legacy::records::check_start(model, &s)
                .err()
                .map(|e| e.to_string());
            let open = start.indentation > 0.0;
            Tally {
                side: if open { start.side } else { 0.0 },
                approach: start.rate,
                // A contact open at the start is one (as in the kernel's table).
                contacts: u64::from(open && options.record_from <= 0.0),
                peak: 0.0,
                squares: 0.0,
                failed,
                energy_start: model.energy(&s),
            }
        })
        .collect()
}

/// The first step end recorded (index k, t = k dt).
fn first_kept(options: &EnsembleOptions) -> u64 {
    let dt = options.dt;
    if options.record_from <= 0.0 {
        0
    } else {
        // The first k with k dt >= record_from (the division may round up past it).
        let mut k = (options.record_from / dt).ceil() as u64;
        if k > 0 && (k - 1) as f64 * dt >= options.record_from {
            k -= 1;
        }
        k.min(options.steps + 1)
    }
}

/// The lanes' check at time `t` (s) after a stretch of steps: a state no
/// longer finite, or energy created beyond the tolerance, fails its lane,
/// which is parked.
fn check_lanes<L: ContactLaw>(
    lanes: &mut Lanes<L>,
    tallies: &mut [Tally],
    models: &[Model<L, Free>; LANES],
    t: f64,
    options: &EnsembleOptions,
) {
    for (l, tally) in tallies.iter_mut().enumerate() {
        if tally.failed.is_some() {
            continue;
        }
        let s = lanes.state.lane(l);
        if !s.is_finite() {
            tally.failed = Some(format!(
                "numerical blow-up by t = {t:.6e} s: the state is no longer finite (reduce dt)"
            ));
        } else {
            let energy = models[l].energy(&s);
            let allowed = tally.energy_start * (1.0 + options.energy_tolerance);
            if energy > allowed && energy - tally.energy_start > 1e-300 {
                tally.failed = Some(format!(
                    "energy created by t = {t:.6e} s: the mechanical energy grew from \
                     {:.6e} J to {energy:.6e} J (more than energy_tolerance = {:e} of it) \
                     in an unforced damped system; reduce dt",
                    tally.energy_start, options.energy_tolerance
                ));
            }
        }
        if tally.failed.is_some() {
            park(lanes, tally, l);
        }
    }
}

/// The results of the group's `members` lanes (the padding dropped), the
/// peak and RMS over the steps from `first_kept` on (`kept_steps` of them).
fn results_of<L: ContactLaw>(
    members: usize,
    lanes: &Lanes<L>,
    tallies: &[Tally],
    (first_kept, kept_steps): (u64, u64),
    options: &EnsembleOptions,
) -> Vec<MemberResult> {
    let dt = options.dt;
    let recorded = kept_steps as f64 * dt;
    (0..members)
        .map(|l| {
            let tally = &tallies[l];
            if let Some(reason) = &tally.failed {
                let nan = f64::NAN;
                return MemberResult {
                    reason: Some(reason.clone()),
                    contacts: 0,
                    peak: nan,
                    rms: nan,
                    final_state: State {
                        main_displacement: nan,
                        main_velocity: nan,
                        impact_displacement: nan,
                        impact_velocity: nan,
                    },
                };
            }
            let w = lanes.state.w[l];
            let rms = if kept_steps > 0 {
                ((tally.squares - 0.5 * w * w) * dt / recorded).sqrt()
            } else {
                f64::NAN
            };
            MemberResult {
                reason: None,
                contacts: tally.contacts,
                peak: if first_kept <= options.steps {
                    tally.peak
                } else {
                    f64::NAN
                },
                rms,
                final_state: lanes.state.lane(l),
            }
        })
        .collect()
}

/// A failed lane is parked at rest, apart: no more events, no NaN.
fn park<L: ContactLaw>(lanes: &mut Lanes<L>, tally: &mut Tally, l: usize) {
    tally.side = 0.0;
    lanes.state.w[l] = 0.0;
    lanes.state.wv[l] = 0.0;
    lanes.state.y[l] = 0.0;
    lanes.state.yv[l] = 0.0;
}

/// Steps `n .. stop`, with the widest vector instructions the processor has.
fn advance<L: ContactLaw>(
    lanes: &mut Lanes<L>,
    tallies: &mut [Tally],
    models: &[Model<L, Free>; LANES],
    n: u64,
    stop: u64,
    first_kept: u64,
    options: &EnsembleOptions,
) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the processor has the features the function is built for.
            return unsafe { advance_avx512(lanes, tallies, models, n, stop, first_kept, options) };
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: as above.
            return unsafe { advance_avx2(lanes, tallies, models, n, stop, first_kept, options) };
        }
    }
    steps(lanes, tallies, models, n, stop, first_kept, options)
}

/// [`steps`] compiled for a processor feature (the same operations, so the
/// same bits, in wider vector instructions).
macro_rules! steps_with {
    ($name:ident, $feature:literal) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feature)]
        unsafe fn $name<L: ContactLaw>(
            lanes: &mut Lanes<L>,
            tallies: &mut [Tally],
            models: &[Model<L, Free>; LANES],
            n: u64,
            stop: u64,
            first_kept: u64,
            options: &EnsembleOptions,
        ) {
            steps(lanes, tallies, models, n, stop, first_kept, options)
        }
    };
}
steps_with!(advance_avx512, "avx512f");
steps_with!(advance_avx2, "avx2");

/// The rates of every lane's state, `(w', w'', y', y'')`: the velocities and
/// [`Model::accelerations`] of an unforced model, with the contact branch as
/// selects (the same operations on the lanes that touch; the side is the
/// sign of `y - w` there, as [`Model::side`] finds it, since the clearance
/// is >= 0).
#[inline(always)]
fn derivative<L: ContactLaw>(lanes: &Lanes<L>, s: &Quad, approach: &[f64; LANES]) -> Quad {
    let mut rate = Quad {
        w: s.wv,
        wv: [0.0; LANES],
        y: s.yv,
        yv: [0.0; LANES],
    };
    for l in 0..LANES {
        // As Model::structural_acceleration.
        let main = (-lanes.damping_per_mass[l]) * s.wv[l] - lanes.stiffness_per_mass[l] * s.w[l];
        let u = s.y[l] - s.w[l];
        let touching = u.abs() > lanes.clearance[l];
        let side = if u > 0.0 { 1.0 } else { -1.0 };
        let indentation = side * u - lanes.clearance[l];
        let speed = side * (s.yv[l] - s.wv[l]);
        let total =
            lanes.law[l].force(indentation, speed, approach[l]) + lanes.contact_damping[l] * speed;
        let push = side * total;
        rate.wv[l] = if touching {
            main + push * lanes.inverse_main[l]
        } else {
            main
        };
        rate.yv[l] = if touching {
            -push * lanes.inverse_impact[l]
        } else {
            0.0
        };
    }
    rate
}

/// Steps `n .. stop` of every lane: [`crate::legacy::integrators::Rk4`]'s stages in
/// its order, then the rare work of the lanes that need it.
#[inline(always)]
fn steps<L: ContactLaw>(
    lanes: &mut Lanes<L>,
    tallies: &mut [Tally],
    models: &[Model<L, Free>; LANES],
    n: u64,
    stop: u64,
    first_kept: u64,
    options: &EnsembleOptions,
) {
    let dt = options.dt;
    let half = 0.5 * dt;
    let sixth = dt / 6.0;
    let mut approach: [f64; LANES] = std::array::from_fn(|l| tallies[l].approach);
    // The side of each lane's open contact, 0 for a lane apart.
    let mut open_side: [f64; LANES] = std::array::from_fn(|l| tallies[l].side);
    let mut squares: [f64; LANES] = std::array::from_fn(|l| tallies[l].squares);
    let mut peak: [f64; LANES] = std::array::from_fn(|l| tallies[l].peak);
    for step in n..stop {
        let s = lanes.state;
        // The provisional latch of the lanes apart (the fixed-step kernel's),
        // for the laws that read it.
        if L::USES_APPROACH_RATE {
            for l in 0..LANES {
                let u = s.y[l] - s.w[l];
                let v = s.yv[l] - s.wv[l];
                let side = if u > 0.0 || (u == 0.0 && v >= 0.0) {
                    1.0
                } else {
                    -1.0
                };
                if open_side[l] == 0.0 {
                    approach[l] = side * v;
                }
            }
        }
        let k1 = derivative(lanes, &s, &approach);
        let k2 = derivative(lanes, &s.offset(half, &k1), &approach);
        let k3 = derivative(lanes, &s.offset(half, &k2), &approach);
        let k4 = derivative(lanes, &s.offset(dt, &k3), &approach);
        let mut rare = false;
        let kept = step + 1 >= first_kept;
        // The trapezoidal rule: the first recorded end counts half.
        let weight = if step + 1 == first_kept { 0.5 } else { 1.0 };
        let sum = |a: f64, b: f64, c: f64, d: f64| sixth * (a + 2.0 * (b + c) + d);
        for l in 0..LANES {
            let w1 = s.w[l] + sum(k1.w[l], k2.w[l], k3.w[l], k4.w[l]);
            let wv1 = s.wv[l] + sum(k1.wv[l], k2.wv[l], k3.wv[l], k4.wv[l]);
            let y1 = s.y[l] + sum(k1.y[l], k2.y[l], k3.y[l], k4.y[l]);
            let yv1 = s.yv[l] + sum(k1.yv[l], k2.yv[l], k3.yv[l], k4.yv[l]);
            lanes.state.w[l] = w1;
            lanes.state.wv[l] = wv1;
            lanes.state.y[l] = y1;
            lanes.state.yv[l] = yv1;
            let u1 = y1 - w1;
            // A contact opens where |u| passes d, closes where the open
            // side's indentation is no longer positive; an extremum of w
            // where w' changes sign.
            let d = lanes.clearance[l];
            let indented = open_side[l] * u1 - d > 0.0;
            let changes = if open_side[l] != 0.0 {
                !indented
            } else {
                u1.abs() > d
            };
            let turns = (s.wv[l] > 0.0) != (wv1 > 0.0);
            rare |= changes | (turns & kept);
            if kept {
                squares[l] += weight * w1 * w1;
                peak[l] = peak[l].max(w1.abs());
            }
        }
        if rare {
            for l in 0..LANES {
                tallies[l].approach = approach[l];
                tallies[l].squares = squares[l];
                tallies[l].peak = peak[l];
            }
            rare_work(lanes, tallies, models, &s, step, first_kept, options);
            for l in 0..LANES {
                approach[l] = tallies[l].approach;
                open_side[l] = tallies[l].side;
                peak[l] = tallies[l].peak;
            }
        }
    }
    for l in 0..LANES {
        tallies[l].approach = approach[l];
        tallies[l].squares = squares[l];
        tallies[l].peak = peak[l];
    }
}

/// The rare work after step `step` (from `step dt` to `(step + 1) dt`): a
/// contact opening (its onset and rate located on the cubic Hermite
/// interpolant of the gap, the rate latched as the fixed-step kernel does)
/// or closing, and an extremum of w located inside the step.
#[inline(never)]
fn rare_work<L: ContactLaw>(
    lanes: &Lanes<L>,
    tallies: &mut [Tally],
    models: &[Model<L, Free>; LANES],
    old: &Quad,
    step: u64,
    first_kept: u64,
    options: &EnsembleOptions,
) {
    let dt = options.dt;
    let t = step as f64 * dt;
    for l in 0..LANES {
        let tally = &mut tallies[l];
        if tally.failed.is_some() {
            continue;
        }
        let s0 = old.lane(l);
        let s1 = lanes.state.lane(l);
        let d = models[l].clearance;
        if tally.side == 0.0 {
            if s1.relative_displacement().abs() > d {
                let side = models[l].side(&s1);
                let onset = models[l].onset_in_step(&s0, &s1, side, dt);
                tally.side = side;
                tally.approach = onset.rate;
                if t + onset.theta * dt >= options.record_from {
                    tally.contacts += 1;
                }
            }
        } else {
            let indented = tally.side * s1.relative_displacement() - d > 0.0;
            if !indented {
                tally.side = 0.0;
            }
        }
        // An extremum of w inside a recorded step.
        let (v0, v1) = (s0.main_velocity, s1.main_velocity);
        if step >= first_kept && (v0 > 0.0) != (v1 > 0.0) {
            let sign = if v0 > 0.0 { 1.0 } else { -1.0 };
            let (g0, g1) = (sign * s0.main_displacement, sign * s1.main_displacement);
            let (m0, m1) = (sign * v0 * dt, sign * v1 * dt);
            if m0 > 0.0 && m1 <= 0.0 {
                let theta = hermite::argmax(g0, g1, m0, m1);
                let top = hermite::eval(g0, g1, m0, m1, theta).0;
                tally.peak = tally.peak.max(top.abs());
            }
        }
    }
}
