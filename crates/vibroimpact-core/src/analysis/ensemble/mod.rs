//! Lockstep ensembles: many fixed-step RK4 runs of the two-mass impact damper
//! advanced together, [`LANES`] at a time, so that the compiler turns each
//! lane loop into vector instructions (AVX-512 or AVX2 where the processor
//! has them, chosen at run time; SSE2 otherwise).
//!
//! A declared specialisation of the one fixed RK4 for the two-mass preset
//! ([`ImpactDamper::assembly`]): each lane is the general kernel's fixed-step
//! run of its member ([`crate::methods::registry::two_mass::simulate`] with
//! RK4, `stepping = "fixed"`, located contacts), bit for bit. The stages are
//! the compact path's ([`crate::kernel::compact`]: its rates and tableau
//! weights, term for term in its order, the preset's constants read from its
//! assembly; the two walls' branch becomes a select on the side, which
//! changes no result since only one wall can be indented), and the contact
//! modes are the kernel's fixed stepping's ([`crate::kernel::fixed`]): a
//! wall apart feels no force; a step that ends a wall indented is taken
//! again with that wall's force, latched at the indentation rate of the
//! step's start; an onset latches the rate located on the cubic Hermite
//! interpolant of the gap; a separation opens the wall. What a lane keeps is
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

mod step;

use step::{rk4, Lanes, OneWall, Quad, V};

use crate::error::{Error, Result};
use crate::kernel::compact::LaneLaw;
use crate::model::assembly::{Assembly, InteractionLaw, Mode};
use crate::model::contact::{Contact, Hertz, HysterHertz, LawKind, Linear};
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
                LawKind::Hertz => run_group::<Hertz>(group, options, interrupt),
                LawKind::Linear => run_group::<Linear>(group, options, interrupt),
                LawKind::HysterHertz | LawKind::HertzDamped => {
                    run_group::<HysterHertz>(group, options, interrupt)
                }
            })
            .collect()
    });
    let mut results = Vec::with_capacity(members.len());
    for group in groups {
        results.extend(group?);
    }
    Ok(results)
}

/// What the rare work of each lane keeps.
struct Tally {
    /// Each wall's contact open.
    open: [bool; 2],
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

/// Every wall in compliant contact: the energy's modes (each indented
/// wall's elastic energy counted).
const ALL_COMPLIANT: [Mode; 2] = [Mode::Compliant {
    approach_rate: 0.0,
    indented_only: true,
}; 2];

/// Lane `l`'s stored energy (J) at `s`, as the kernel sums it.
fn energy(system: &Assembly, s: &State) -> f64 {
    let y = [
        s.main_displacement,
        s.impact_displacement,
        s.main_velocity,
        s.impact_velocity,
    ];
    system.energy(&y, &ALL_COMPLIANT)
}

/// The lanes of `group` with their constants from `systems`.
fn lanes_of<L: LaneLaw>(group: &[Member], systems: &[&Assembly]) -> Lanes<L> {
    let zeros = [0.0; LANES];
    let mut lanes = Lanes {
        state: Quad {
            w: zeros,
            wv: zeros,
            y: zeros,
            yv: zeros,
        },
        stiffness: zeros,
        damping: zeros,
        h: [zeros; 2],
        offset: [zeros; 2],
        push: [[zeros; 2]; 2],
        parts: [zeros; 2],
        contact_damping: zeros,
        active: [zeros; 2],
        approach: [zeros; 2],
        factor: [zeros; 2],
        one: OneWall {
            active: zeros,
            sign: zeros,
            offset: zeros,
            approach: zeros,
            factor: zeros,
            push: [zeros; 2],
        },
        law: std::marker::PhantomData,
    };
    for (l, system) in systems.iter().enumerate() {
        lanes.state.set(l, &padded(group, l).initial);
        let parts = system.compact_parts().expect("the preset is modal");
        let [k, c, _, _] = parts.diagonals[0];
        (lanes.stiffness[l], lanes.damping[l]) = (k, c);
        let walls = &system.interactions;
        lanes.h[0][l] = walls[0].h[0];
        lanes.h[1][l] = walls[0].h[1];
        for w in 0..2 {
            lanes.offset[w][l] = walls[w].offset;
            lanes.push[w][0][l] = walls[w].push[0];
            lanes.push[w][1][l] = walls[w].push[1];
        }
        if let InteractionLaw::Compliant { law, damping } = &walls[0].law {
            let damping = *damping;
            let law = L::of(law).expect("the group's law");
            [lanes.parts[0][l], lanes.parts[1][l]] = law.parts();
            lanes.contact_damping[l] = damping;
        }
        lanes.sync(l);
    }
    lanes
}

fn run_group<L: LaneLaw>(
    group: &[Member],
    options: &EnsembleOptions,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<MemberResult>> {
    // Each lane's assembly, made once for lanes in a row of the same system
    // (a study varying the start: Assembly::new in every lane tripled the
    // per-run overhead).
    let mut assemblies: Vec<Assembly> = Vec::with_capacity(LANES);
    let mut which = [0; LANES];
    for l in 0..LANES {
        let m = padded(group, l);
        let previous = padded(group, l.saturating_sub(1));
        let same = l > 0 && previous.system == m.system && previous.contact == m.contact;
        if !same {
            assemblies.push(m.system.assembly(&m.contact)?);
        }
        which[l] = assemblies.len() - 1;
    }
    let systems: [&Assembly; LANES] = std::array::from_fn(|l| &assemblies[which[l]]);
    let mut lanes = lanes_of::<L>(group, &systems);
    let mut tallies = tallies_of(group, &systems, &mut lanes, options);
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
        advance(&mut lanes, &mut tallies, n, stop, first_kept, options);
        n = stop;
        check_lanes(&mut lanes, &mut tallies, &systems, n as f64 * dt, options);
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

/// Each lane's tally at the start, and its walls' modes: a wall indented
/// at the start is a contact (counted where recorded from the start),
/// latched at its indentation rate (the kernel's resumed contact); a start
/// the kernel refuses fails the lane.
fn tallies_of<L: LaneLaw>(
    group: &[Member],
    systems: &[&Assembly],
    lanes: &mut Lanes<L>,
    options: &EnsembleOptions,
) -> Vec<Tally> {
    (0..LANES)
        .map(|l| {
            let member = padded(group, l);
            let s = member.initial;
            let failed = s
                .check_apart(member.system.clearance)
                .err()
                .map(|e| e.to_string());
            let mut open = [false; 2];
            for (w, (gap, rate)) in lanes.gaps(l, &s).into_iter().enumerate() {
                if gap < 0.0 {
                    open[w] = true;
                    lanes.activate(l, w, -rate);
                }
            }
            Tally {
                open,
                contacts: u64::from((open[0] || open[1]) && options.record_from <= 0.0),
                peak: 0.0,
                squares: 0.0,
                failed,
                energy_start: energy(systems[l], &s),
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
fn check_lanes<L: LaneLaw>(
    lanes: &mut Lanes<L>,
    tallies: &mut [Tally],
    systems: &[&Assembly],
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
            let energy = energy(systems[l], &s);
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
fn results_of<L: LaneLaw>(
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
fn park<L: LaneLaw>(lanes: &mut Lanes<L>, tally: &mut Tally, l: usize) {
    tally.open = [false; 2];
    lanes.state.set(l, &State::default());
    for w in 0..2 {
        lanes.deactivate(l, w);
    }
}

/// Steps `n .. stop`, with the widest vector instructions the processor has.
fn advance<L: LaneLaw>(
    lanes: &mut Lanes<L>,
    tallies: &mut [Tally],
    n: u64,
    stop: u64,
    first_kept: u64,
    options: &EnsembleOptions,
) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the processor has the features the function is built for.
            return unsafe { advance_avx512(lanes, tallies, n, stop, first_kept, options) };
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: as above.
            return unsafe { advance_avx2(lanes, tallies, n, stop, first_kept, options) };
        }
    }
    steps(lanes, tallies, n, stop, first_kept, options)
}

/// [`steps`] compiled for a processor feature (the same operations, so the
/// same bits, in wider vector instructions).
macro_rules! steps_with {
    ($name:ident, $feature:literal) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feature)]
        unsafe fn $name<L: LaneLaw>(
            lanes: &mut Lanes<L>,
            tallies: &mut [Tally],
            n: u64,
            stop: u64,
            first_kept: u64,
            options: &EnsembleOptions,
        ) {
            steps(lanes, tallies, n, stop, first_kept, options)
        }
    };
}
steps_with!(advance_avx512, "avx512f");
steps_with!(advance_avx2, "avx2");

/// Steps `n .. stop` of every lane, then the rare work of the lanes that
/// need it, and the reductions.
#[inline(always)]
fn steps<L: LaneLaw>(
    lanes: &mut Lanes<L>,
    tallies: &mut [Tally],
    n: u64,
    stop: u64,
    first_kept: u64,
    options: &EnsembleOptions,
) {
    let dt = options.dt;
    let mut squares: V = std::array::from_fn(|l| tallies[l].squares);
    let mut peak: V = std::array::from_fn(|l| tallies[l].peak);
    for step in n..stop {
        let s = lanes.state;
        lanes.state = rk4::<true, L>(lanes, &s, dt);
        let kept = step + 1 >= first_kept;
        let mut rare = false;
        for l in 0..LANES {
            let e = &lanes.state;
            // A wall's contact begins where an open wall's gap ends below
            // zero, ends where an active wall's does not; an extremum of w
            // where w' changes sign.
            let hx = lanes.h[0][l] * e.w[l] + lanes.h[1][l] * e.y[l];
            let closed0 = lanes.offset[0][l] + hx < 0.0;
            let closed1 = lanes.offset[1][l] + -hx < 0.0;
            let changes =
                (closed0 != (lanes.active[0][l] != 0.0)) | (closed1 != (lanes.active[1][l] != 0.0));
            let turns = (s.wv[l] > 0.0) != (e.wv[l] > 0.0);
            rare |= changes | (turns & kept);
        }
        if rare {
            for l in 0..LANES {
                tallies[l].peak = peak[l];
            }
            rare_work(lanes, tallies, &s, step, first_kept, options);
            for l in 0..LANES {
                peak[l] = tallies[l].peak;
            }
        }
        if kept {
            // The trapezoidal rule: the first recorded end counts half.
            let weight = if step + 1 == first_kept { 0.5 } else { 1.0 };
            for l in 0..LANES {
                let w1 = lanes.state.w[l];
                squares[l] += weight * w1 * w1;
                peak[l] = peak[l].max(w1.abs());
            }
        }
    }
    for l in 0..LANES {
        tallies[l].squares = squares[l];
        tallies[l].peak = peak[l];
    }
}

/// The rare work after step `step` (from `step dt` to `(step + 1) dt`, from
/// `old`), as the kernel's fixed step does it: the lanes whose open wall
/// ends the step indented take it again with that wall's force (latched at
/// its indentation rate at the step's start), and a wall so given its
/// force that still ends apart is open again; then each wall's onset (its
/// time and rate located on the cubic Hermite interpolant of the gap, the
/// rate latched) or separation; and an extremum of w inside a recorded step.
#[inline(never)]
fn rare_work<L: LaneLaw>(
    lanes: &mut Lanes<L>,
    tallies: &mut [Tally],
    old: &Quad,
    step: u64,
    first_kept: u64,
    options: &EnsembleOptions,
) {
    let dt = options.dt;
    let t = step as f64 * dt;
    let mut again = [false; LANES];
    for l in 0..LANES {
        if tallies[l].failed.is_some() {
            continue;
        }
        let (start, end) = (
            lanes.gaps(l, &old.lane(l)),
            lanes.gaps(l, &lanes.state.lane(l)),
        );
        for w in 0..2 {
            if lanes.active[w][l] == 0.0 && end[w].0 < 0.0 {
                lanes.activate(l, w, -start[w].1);
                again[l] = true;
            }
        }
    }
    if again.contains(&true) {
        let retaken = rk4::<false, L>(lanes, old, dt);
        for l in (0..LANES).filter(|&l| again[l]) {
            let end = retaken.lane(l);
            lanes.state.set(l, &end);
            for (w, (gap, _)) in lanes.gaps(l, &end).into_iter().enumerate() {
                if !tallies[l].open[w] && gap >= 0.0 {
                    lanes.deactivate(l, w);
                }
            }
        }
    }
    for l in 0..LANES {
        let tally = &mut tallies[l];
        if tally.failed.is_some() {
            continue;
        }
        let (s0, s1) = (old.lane(l), lanes.state.lane(l));
        let (start, end) = (lanes.gaps(l, &s0), lanes.gaps(l, &s1));
        for w in 0..2 {
            // The indentation and its rate times the step (the kernel's data).
            let (i0, i1) = (-start[w].0, -end[w].0);
            let (m0, m1) = (-start[w].1 * dt, -end[w].1 * dt);
            if !tally.open[w] && i1 > 0.0 {
                let theta = if i0 <= 0.0 {
                    hermite::root(i0, i1, m0, m1)
                } else {
                    0.0
                };
                let rate = hermite::eval(i0, i1, m0, m1, theta).1 / dt;
                tally.open[w] = true;
                lanes.activate(l, w, rate);
                if t + theta * dt >= options.record_from {
                    tally.contacts += 1;
                }
            } else if tally.open[w] && i1 <= 0.0 {
                tally.open[w] = false;
                lanes.deactivate(l, w);
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
