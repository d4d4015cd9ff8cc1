//! The founding paper's method on its own two-mass system, written out here
//! from its equations (`shared/reference/paper-model.md`): the reference for
//! the general stepper on the preset ([`ImpactDamper::assembly`]) and for the
//! general kernel's fixed stepping of it. The reference takes the operations
//! in the order 0.1 took them (each term of the accelerations over its own
//! mass, the 2x2 inverse by its adjugate), which the stepper keeps on the
//! preset: the same bits, step by step and over whole runs.

use super::*;
use crate::kernel::events::{
    integrate_system_stepped, ContactTiming, PairContact, RunOptions, Stepping,
};
use crate::model::contact::{exact_hysteresis, Contact, LawKind};
use crate::model::impact_damper::{ImpactDamper, State};

/// The two-mass system of Table 1 (M = 1 kg, K = 1 N/m, C = 0.01 N s/m,
/// m = 0.25 kg) with clearance `d` (m).
pub(super) fn table_1(d: f64) -> ImpactDamper {
    ImpactDamper::new(1.0, 1.0, 0.01, 0.25, d).unwrap()
}

/// A contact law of the paper (N, pushing the bodies apart) at indentation
/// `delta` > 0 (m), indentation rate `rate` (m/s) and the rate latched at
/// the contact's onset `approach` (m/s).
#[derive(Debug, Clone, Copy)]
enum Law {
    /// `F = K delta^(3/2)`.
    Hertz(f64),
    /// `F = K delta^(3/2) (1 + alpha delta' / delta'_minus)`, never pulling.
    Hysteretic { stiffness: f64, alpha: f64 },
    /// `F = k1 delta`.
    Linear(f64),
}

impl Law {
    fn of(contact: &Contact) -> Self {
        let (k, e) = (contact.stiffness, contact.restitution);
        match contact.law {
            LawKind::Hertz => Law::Hertz(k),
            // The paper's alpha = (3/4)(1 - e^2).
            LawKind::HysterHertz => Law::Hysteretic {
                stiffness: k,
                alpha: 0.75 * (1.0 - e * e),
            },
            // The alpha whose rebound is e (its relation is tested in
            // model/contact.rs).
            LawKind::HertzDamped => Law::Hysteretic {
                stiffness: k,
                alpha: exact_hysteresis(e).unwrap(),
            },
            LawKind::Linear => Law::Linear(k),
        }
    }

    fn elastic(self, delta: f64) -> f64 {
        match self {
            Law::Hertz(k) | Law::Hysteretic { stiffness: k, .. } => k * delta * delta.sqrt(),
            Law::Linear(k) => k * delta,
        }
    }

    fn force(self, delta: f64, rate: f64, approach: f64) -> f64 {
        match self {
            Law::Hysteretic { alpha, .. } => {
                (self.elastic(delta) * (1.0 + (alpha / approach) * rate)).max(0.0)
            }
            _ => self.elastic(delta),
        }
    }

    /// The elastic energy stored at `delta` (J).
    fn potential(self, delta: f64) -> f64 {
        match self {
            Law::Hertz(k) | Law::Hysteretic { stiffness: k, .. } => 0.4 * k * delta.powf(2.5),
            Law::Linear(k) => 0.5 * k * delta * delta,
        }
    }
}

/// `[w, y, w', y']`: the main mass's and the impact mass's displacements
/// (m) and velocities (m/s), in the general state's order.
type Point = [f64; 4];

/// A contact in force through a step: its wall (0 at `y - w = +d`, the
/// preset's first interaction; 1 at `-d`) and the indentation rate latched
/// at its onset (m/s).
type Latch = Option<(usize, f64)>;

/// The paper's system and contact.
#[derive(Debug, Clone, Copy)]
struct Paper {
    damper: ImpactDamper,
    /// The contact damper c1 (N s/m).
    c1: f64,
    law: Law,
}

/// +1 for wall 0, -1 for wall 1.
fn side(wall: usize) -> f64 {
    if wall == 0 {
        1.0
    } else {
        -1.0
    }
}

impl Paper {
    fn new(damper: ImpactDamper, contact: &Contact) -> Self {
        Self {
            damper,
            c1: contact.damping,
            law: Law::of(contact),
        }
    }

    /// Wall `wall`'s indentation `side (y - w) - d` (m, > 0 in contact) and
    /// its rate (m/s).
    fn indentation(&self, s: &Point, wall: usize) -> (f64, f64) {
        let side = side(wall);
        (
            side * (s[1] - s[0]) - self.damper.clearance,
            side * (s[3] - s[2]),
        )
    }

    /// The wall indented at `s`, if any.
    fn indented(&self, s: &Point) -> Option<usize> {
        (0..2).find(|&wall| self.indentation(s, wall).0 > 0.0)
    }

    /// The accelerations `(w'', y'')` (m/s^2) of `M w'' + C w' + K w = F`,
    /// `m y'' = -F`, with `F = side (F_law + c1 delta')` while `latch` holds
    /// (the law's force where indented), each term over its own mass.
    fn accelerations(&self, s: &Point, latch: Latch) -> [f64; 2] {
        let ImpactDamper {
            main_mass,
            impact_mass,
            stiffness,
            damping,
            ..
        } = self.damper;
        let main = (-(damping / main_mass)) * s[2] - (stiffness / main_mass) * s[0];
        let Some((wall, approach)) = latch else {
            return [main, 0.0];
        };
        let (delta, rate) = self.indentation(s, wall);
        let law = if delta > 0.0 {
            self.law.force(delta, rate, approach)
        } else {
            0.0
        };
        let push = side(wall) * (law + self.c1 * rate);
        [main + push * (1.0 / main_mass), -push * (1.0 / impact_mass)]
    }

    /// One step `dt` of the paper's Newmark-beta (average acceleration) from
    /// `s` with accelerations `a`, the contact `latch` in force through it:
    /// the law's force taken at the step's start (the paper's lag), the
    /// structure's spring and damper and the contact damper implicit,
    ///
    /// `[M 0; 0 m] a1 + [C + c1, -c1; -c1, c1] v1 + [K 0; 0 0] x1 = [F; -F](t)`
    ///
    /// with `x1 = x* + beta dt^2 a1`, `v1 = v* + gamma dt a1` from the
    /// predictor `x*`, `v*`. The end and its accelerations.
    fn step(&self, s: &Point, a: [f64; 2], dt: f64, latch: Latch) -> (Point, [f64; 2]) {
        let ImpactDamper {
            main_mass,
            impact_mass,
            stiffness,
            damping,
            ..
        } = self.damper;
        let (beta, gamma) = (0.25, 0.5);
        let (db, dg) = ((0.5 - beta) * dt * dt, (1.0 - gamma) * dt);
        let (xw, xy) = (s[0] + dt * s[2] + db * a[0], s[1] + dt * s[3] + db * a[1]);
        let (vw, vy) = (s[2] + dg * a[0], s[3] + dg * a[1]);
        let push = match latch {
            Some((wall, approach)) => {
                let (delta, rate) = self.indentation(s, wall);
                if delta > 0.0 {
                    side(wall) * self.law.force(delta, rate, approach)
                } else {
                    0.0
                }
            }
            None => 0.0,
        };
        let mut rw = push - damping * vw - stiffness * xw;
        let mut ry = -push;
        let (g, b) = (gamma * dt, beta * dt * dt);
        let main = main_mass + g * damping + b * stiffness;
        let (a11, a12, a22) = if latch.is_some() {
            let damper = self.c1 * (vy - vw);
            rw += damper;
            ry -= damper;
            (main + g * self.c1, -g * self.c1, impact_mass + g * self.c1)
        } else {
            (main, 0.0, impact_mass)
        };
        let det = a11 * a22 - a12 * a12;
        let (i11, i12, i22) = (a22 / det, -a12 / det, a11 / det);
        let (aw, ay) = (i11 * rw + i12 * ry, i12 * rw + i22 * ry);
        let end = [xw + b * aw, xy + b * ay, vw + g * aw, vy + g * ay];
        (end, [aw, ay])
    }

    /// The stored energy (J): kinetic, the spring's, the contact's elastic.
    fn energy(&self, s: &Point) -> f64 {
        let d = &self.damper;
        let contact: f64 = (0..2)
            .map(|wall| self.indentation(s, wall).0)
            .filter(|delta| *delta > 0.0)
            .map(|delta| self.law.potential(delta))
            .sum();
        0.5 * (d.main_mass * s[2] * s[2] + d.impact_mass * s[3] * s[3])
            + 0.5 * d.stiffness * s[0] * s[0]
            + contact
    }

    /// The power (W) the contact at `wall` dissipates at `s` (its law's
    /// non-elastic part and its damper; none apart).
    fn power(&self, s: &Point, wall: usize, approach: f64) -> f64 {
        let (delta, rate) = self.indentation(s, wall);
        if delta <= 0.0 {
            return 0.0;
        }
        (self.law.force(delta, rate, approach) + self.c1 * rate - self.law.elastic(delta)) * rate
    }
}

/// The cubic Hermite interpolant over a step of a quantity from `i0` to
/// `i1` with slopes `m0`, `m1` (per unit fraction of the step), in power
/// form: its value and slope at the fraction `theta`.
fn cubic((i0, i1, m0, m1): (f64, f64, f64, f64), theta: f64) -> (f64, f64) {
    let c2 = 3.0 * (i1 - i0) - 2.0 * m0 - m1;
    let c3 = 2.0 * (i0 - i1) + m0 + m1;
    let value = i0 + theta * (m0 + theta * (c2 + theta * c3));
    let slope = m0 + theta * (2.0 * c2 + theta * 3.0 * c3);
    (value, slope)
}

/// Where `f` changes sign in [0, 1] (`f(0)` and `f(1)` of opposite signs,
/// or `f(0)` zero), by bisection to the last bit.
fn bisect(f: impl Fn(f64) -> f64) -> f64 {
    let rising = f(1.0) > f(0.0);
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    loop {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            return mid;
        }
        if (f(mid) > 0.0) == rising {
            hi = mid;
        } else {
            lo = mid;
        }
    }
}

/// Where the interpolant of an indentation crosses zero in a step (0 when
/// the step starts on the far side already) and the indentation rate there
/// (m/s).
fn crossing(data: (f64, f64, f64, f64), dt: f64, starts_across: bool) -> (f64, f64) {
    let theta = if starts_across {
        0.0
    } else {
        bisect(|t| cubic(data, t).0)
    };
    (theta, cubic(data, theta).1 / dt)
}

/// A contact of a fixed-step run, as 0.1 recorded them and the general
/// kernel's fixed stepping does (kernel/fixed.rs's rules, written again).
#[derive(Debug, Clone, Copy)]
struct Record {
    onset: f64,
    separation: f64,
    approach: f64,
    rebound: f64,
    deepest: f64,
    dissipated: f64,
    energy_change: f64,
    /// The dissipated power at the last step's end (W) and the stored
    /// energy at the onset (J).
    power: f64,
    energy: f64,
}

/// A fixed-step run of the paper's method.
struct FixedRun {
    /// Closed contacts, then any still open (separation NaN).
    records: Vec<Record>,
    end: Point,
    steps: u64,
    /// The indentation rate at each located onset (m/s).
    onset_rates: Vec<f64>,
}

impl Paper {
    /// Fixed steps of `dt` from `start` (apart) until `t_end`: a contact
    /// begins at the first step's end indented (its onset where the step's
    /// interpolant crosses the wall, or counted in whole steps), holds
    /// from the next step on with the onset's indentation rate latched
    /// (`latches`, in order, else this run's own), and ends at the first
    /// step's end apart. Its dissipation is the trapezoidal sum of its
    /// power (the onset's and separation's steps in part), its energy
    /// change the stored energy's, interpolated to the onset and the
    /// separation; its deepest indentation the steps' ends' and, located,
    /// the interpolant's peaks.
    fn fixed_run(
        &self,
        start: Point,
        (dt, t_end): (f64, f64),
        located: bool,
        latches: &[f64],
    ) -> FixedRun {
        let (mut s, mut a) = (start, self.accelerations(&start, None));
        let mut open: [Option<Record>; 2] = [None, None];
        let (mut records, mut onset_rates) = (vec![], vec![]);
        let mut steps = 0u64;
        while t_end - steps as f64 * dt > 1e-9 * dt {
            let (t, t1) = (steps as f64 * dt, (steps + 1) as f64 * dt);
            let latch = (0..2).find_map(|w| open[w].map(|r| (w, r.approach)));
            let (end, a1) = self.step(&s, a, dt, latch);
            let (e0, e1) = (self.energy(&s), self.energy(&end));
            let within = |theta: f64| e0 + theta * (e1 - e0);
            for (wall, slot) in open.iter_mut().enumerate() {
                let ((i0, r0), (i1, r1)) =
                    (self.indentation(&s, wall), self.indentation(&end, wall));
                let data = (i0, i1, r0 * dt, r1 * dt);
                match slot {
                    None if i1 > 0.0 => {
                        let (theta, rate) = crossing(data, dt, i0 > 0.0);
                        onset_rates.push(rate);
                        let approach = latches.get(onset_rates.len() - 1).copied().unwrap_or(rate);
                        let power = self.power(&end, wall, approach);
                        let start_power = self.c1 * approach * approach;
                        *slot = Some(Record {
                            onset: if located {
                                t + theta * dt
                            } else if i0 >= 0.0 {
                                t
                            } else {
                                t1
                            },
                            separation: f64::NAN,
                            approach,
                            rebound: f64::NAN,
                            deepest: i1,
                            dissipated: 0.5 * (1.0 - theta) * dt * (start_power + power),
                            energy_change: f64::NAN,
                            power,
                            energy: within(theta),
                        });
                    }
                    None => {}
                    Some(r) => {
                        if located && data.2 > 0.0 && data.3 <= 0.0 {
                            let peak = bisect(|t| cubic(data, t).1);
                            r.deepest = r.deepest.max(cubic(data, peak).0);
                        }
                        r.deepest = r.deepest.max(i1);
                        if i1 > 0.0 {
                            let power = self.power(&end, wall, r.approach);
                            r.dissipated += 0.5 * dt * (r.power + power);
                            r.power = power;
                            continue;
                        }
                        let (theta, rate) = crossing(data, dt, i0 <= 0.0);
                        r.separation = if located { t + theta * dt } else { t1 };
                        r.dissipated += 0.5 * theta * dt * (r.power + self.c1 * rate * rate);
                        r.rebound = -rate;
                        r.energy_change = within(theta) - r.energy;
                        records.push(*r);
                        *slot = None;
                    }
                }
            }
            (s, a) = (end, a1);
            steps += 1;
        }
        records.extend(open.iter().flatten());
        FixedRun {
            records,
            end: s,
            steps,
            onset_rates,
        }
    }
}

/// The paper's Newmark written out ([`Paper::step`]) and the general
/// stepper on the preset driven side by side over `steps` steps `dt` from
/// `start`: a contact holds from the step after the first step's end
/// indented (the rate where that step's interpolant crosses the wall
/// latched) to the first step's end apart, the stepper told that the step
/// was not cut there. Calls `each` with both ends of every step; returns
/// the contacts begun.
fn side_by_side(
    damper: ImpactDamper,
    contact: &Contact,
    start: Point,
    dt: f64,
    steps: usize,
    mut each: impl FnMut(&Point, &[f64]),
) -> usize {
    let paper = Paper::new(damper, contact);
    let system = damper.assembly(contact).unwrap();
    let mut ours = PaperNewmark::new(&system, 0.25, 0.5).unwrap();
    let mut scratch = Scratch::new(&system);
    let [w, y, vw, vy] = start;
    let mut general = State::new(w, vw, y, vy).unwrap().vector(&system).unwrap();
    let mut end = general.clone();
    let (mut s, mut a) = (start, paper.accelerations(&start, None));
    let mut latch: Latch = None;
    let mut modes = vec![Mode::Open; 2];
    let mut contacts = 0;
    for n in 0..steps {
        let t = n as f64 * dt;
        let (s1, a1) = paper.step(&s, a, dt, latch);
        ours.attempt(&system, t, &general, dt, &modes, &mut scratch, &mut end)
            .unwrap();
        ours.accept();
        each(&s1, &end);
        let before = modes.clone();
        modes = vec![Mode::Open; 2];
        let held = latch;
        latch = paper.indented(&s1).map(|wall| match held {
            Some((held, approach)) if held == wall => (wall, approach),
            _ => {
                contacts += 1;
                let (i0, r0) = paper.indentation(&s, wall);
                let (i1, r1) = paper.indentation(&s1, wall);
                (wall, crossing((i0, i1, r0 * dt, r1 * dt), dt, i0 > 0.0).1)
            }
        });
        if let Some((wall, approach_rate)) = latch {
            modes[wall] = Mode::Compliant {
                approach_rate,
                indented_only: true,
            };
        }
        if modes != before {
            ours.switched_within_step();
        }
        (s, a) = (s1, a1);
        general.copy_from_slice(&end);
    }
    contacts
}

#[test]
fn two_mass_steps_are_the_paper_s_equations_to_the_bit() {
    crate::testing::timeout(60, || {
        // Rattling between both walls (d = 5 mm, 0.1 m/s apart), from a
        // start with the main mass moving: every step, contact or not, the
        // paper's equations' bits, for each law.
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for (law, restitution) in [
            (LawKind::Hertz, None),
            (LawKind::HysterHertz, Some(0.9)),
            (LawKind::HertzDamped, Some(0.6)),
            (LawKind::Linear, None),
        ] {
            let stiffness = if law == LawKind::Linear {
                49.05
            } else {
                3000.0
            };
            let contact = Contact::new(law, stiffness, restitution, 0.01).unwrap();
            // Table 1's, and masses other than 1 kg (terms divided by M
            // where the assembly multiplies by its inverse).
            let other = ImpactDamper::new(1.2, 3.7, 0.02, 0.3, 0.005).unwrap();
            for damper in [table_1(0.005), other] {
                let start = [1e-3, 0.0045, 0.02, 0.1];
                let mut steps = 0;
                let contacts = side_by_side(damper, &contact, start, 1e-4, 12_000, |s, y| {
                    assert_eq!(
                        bits(s),
                        bits(&y[..4]),
                        "{law:?}, step {steps}: the paper's {s:?}, ours {:?}",
                        &y[..4]
                    );
                    steps += 1;
                });
                assert!(contacts >= 3, "{law:?}: {contacts} contacts");
            }
        }
    });
}

#[test]
fn restarts_take_the_paper_s_accelerations_per_unit_mass_to_the_bit() {
    crate::testing::timeout(30, || {
        // The paper's equations with each term over its own mass, -(C/M) v
        // - (K/M) x + F/M, where the assembly multiplies -(k x + c v) by
        // the inverse mass: the two differ in the last bit for half of all
        // states (M = 1.2 kg here), apart and in contact with either wall.
        let contact = Contact::new(LawKind::HysterHertz, 3000.0, Some(0.8), 0.01).unwrap();
        let damper = ImpactDamper::new(1.2, 3.7, 0.02, 0.3, 0.005).unwrap();
        let paper = Paper::new(damper, &contact);
        let system = damper.assembly(&contact).unwrap();
        let mut ours = PaperNewmark::new(&system, 0.25, 0.5).unwrap();
        let mut scratch = Scratch::new(&system);
        let mut differ = 0;
        for k in 0..200 {
            let phase = k as f64;
            let (w, v) = (2e-3 * phase.sin(), 3e-2 * (1.7 * phase).cos());
            let u = 0.0058 * (0.3 * phase).sin();
            let s = [w, w + u, v, v + 0.1 * (0.7 * phase).sin()];
            let approach = 0.1;
            let mut modes = vec![Mode::Open; 2];
            let latch = paper.indented(&s).map(|wall| (wall, approach));
            if let Some((wall, _)) = latch {
                modes[wall] = Mode::Compliant {
                    approach_rate: approach,
                    indented_only: false,
                };
            }
            // [w, y, w', y'] and the accumulators (a start inside a wall
            // is refused by `initial_state`, not by a restart).
            let mut y = vec![0.0; system.state_len()];
            y[..4].copy_from_slice(&s);
            ours.reset();
            ours.start(&system, 0.0, &y, &modes, &mut scratch);
            let [aw, ay] = paper.accelerations(&s, latch);
            assert_eq!(
                (aw.to_bits(), ay.to_bits()),
                (ours.accel[0].to_bits(), ours.accel[1].to_bits()),
                "{s:?}: the paper's ({aw}, {ay}), ours {:?}",
                ours.accel
            );
            differ += usize::from(ours.rates[2].to_bits() != aw.to_bits());
        }
        // The assembly's own accelerations would not do.
        assert!(differ > 20, "{differ}");
    });
}

/// One collision from the onset (`y - w = d`, `y' = 0.1` m/s, the main
/// mass at rest) stepped by the paper's equations and ours side by side at
/// `dt` (the same bits): the rebound-to-approach ratio of the relative
/// speed at the first step apart, and the stored energy's change then (J).
fn collision(damper: ImpactDamper, contact: &Contact, dt: f64) -> (f64, f64) {
    let d = damper.clearance;
    let system = damper.assembly(contact).unwrap();
    let y0 = State::new(0.0, 0.0, d, 0.1)
        .unwrap()
        .vector(&system)
        .unwrap();
    let mut after = None;
    let mut touched = false;
    let steps = (0.2 / dt) as usize;
    side_by_side(damper, contact, [0.0, d, 0.0, 0.1], dt, steps, |s, y| {
        let same = s.iter().zip(y).all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "{s:?} vs {:?}", &y[..4]);
        let apart = (y[1] - y[0]).abs() <= d;
        touched |= !apart;
        if touched && apart && after.is_none() {
            after = Some(y.to_vec());
        }
    });
    let y1 = after.expect("the bodies part within 0.2 s");
    let modes = [Mode::Open; 2];
    let change = system.energy(&y1, &modes) - system.energy(&y0, &modes);
    (-(y1[3] - y1[2]) / 0.1, change)
}

#[test]
fn the_lagged_contact_force_creates_energy_at_first_order() {
    crate::testing::timeout(60, || {
        // Two free bodies on a Hertz contact rebound exactly at their
        // approach speed. Lagging the force one step creates energy at
        // every step size, an error of first order in dt: the rebound
        // ratio's excess falls by the step's ratio. The bodies' momentum
        // is kept (equal and opposite forces), so all of the change is in
        // the relative motion, 0.5 m_eff v^2 (e^2 - 1).
        let hertz = Contact::new(LawKind::Hertz, 3000.0, None, 0.0).unwrap();
        let two_bodies = ImpactDamper::new(1.0, 0.0, 0.0, 0.25, 0.005).unwrap();
        let relative = 0.5 * two_bodies.effective_mass() * 0.1 * 0.1;
        let mut excess = vec![];
        for dt in [1e-4, 2e-5] {
            let (ratio, change) = collision(two_bodies, &hertz, dt);
            assert!(change > 0.0, "dt {dt}: {change} J");
            let kept = relative * (ratio * ratio - 1.0);
            assert!((change - kept).abs() < 1e-6 * change, "{change} vs {kept}");
            excess.push(ratio - 1.0);
        }
        let order = (excess[0] / excess[1]).ln() / 5f64.ln();
        assert!((order - 1.0).abs() < 0.05, "order {order}");
        // Table 1's collision (K, C and c1 = 0.01 N s/m: exactly, a
        // rebound at 0.99635 of the approach speed, paper-model.md): the
        // paper's method rebounds faster than it came, at 1.0015 at its
        // dt = 1e-4 s and 1.049 at 1e-3 s (0.1 documented 1.0016 and
        // 1.049, its ratio located within the step).
        let paper = Contact::new(LawKind::Hertz, 3000.0, None, 0.01).unwrap();
        let (fine, _) = collision(table_1(0.005), &paper, 1e-4);
        assert!((fine - 1.0015).abs() < 1e-4, "{fine}");
        let (coarse, created) = collision(table_1(0.005), &paper, 1e-3);
        assert!((coarse - 1.049).abs() < 1e-3 && created > 0.0, "{coarse}");
    });
}

/// The general kernel's fixed-step run of the paper's Newmark of `damper`
/// with `contact` from `start` to `t_end` at `dt`, with `timing`.
fn kernel_run(
    damper: ImpactDamper,
    contact: &Contact,
    start: Point,
    (dt, t_end): (f64, f64),
    timing: ContactTiming,
) -> crate::kernel::events::SystemSolution {
    let system = damper.assembly(contact).unwrap();
    let options = RunOptions {
        dt: Some(dt),
        t_end,
        every: 1,
        keep_history: false,
        max_steps: 10_000_000,
        max_rows: 10_000_000,
        energy_tolerance: 0.05,
        reduce: Default::default(),
    };
    let [w, y, vw, vy] = start;
    let mut stepper = PaperNewmark::new(&system, 0.25, 0.5).unwrap();
    integrate_system_stepped(
        &system,
        &mut stepper,
        &State::new(w, vw, y, vy).unwrap().vector(&system).unwrap(),
        &options,
        Stepping::Fixed {
            contact_timing: timing,
        },
        &mut || false,
        crate::MAX_RECORD_BYTES,
    )
    .unwrap()
}

/// `ours` against the written-out run's `reference` record, its crossings
/// found by other arithmetic: times to 1e-14 s, speeds and the deepest
/// indentation to 1e-13 of theirs, the dissipation to 1e-12 of it and the
/// energy change to 1e-17 J (measured: 1e-15 relative in the rebound and the
/// deepest indentation, the rest the same bits).
fn assert_record_matches(case: &str, reference: &Record, ours: &PairContact) {
    let close = |name: &str, a: f64, b: f64, tolerance: f64| {
        assert!(
            (a - b).abs() <= tolerance || (a.is_nan() && b.is_nan()),
            "{case}: {name} {a} vs the paper's {b} ({reference:?}, {ours:?})"
        );
    };
    close("onset", ours.onset, reference.onset, 1e-14);
    close("separation", ours.separation, reference.separation, 1e-14);
    let duration = reference.separation - reference.onset;
    close("duration", ours.duration, duration, 1e-14);
    let speed = 1e-13 * reference.approach;
    close("approach", ours.approach_speed, reference.approach, 0.0);
    close("rebound", ours.rebound_speed, reference.rebound, speed);
    let deepest = 1e-13 * reference.deepest;
    close("deepest", ours.max_indentation, reference.deepest, deepest);
    let dissipated = 1e-12 * reference.dissipated.abs() + 1e-20;
    close(
        "dissipated",
        ours.energy_dissipated,
        reference.dissipated,
        dissipated,
    );
    close(
        "energy change",
        ours.energy_change,
        reference.energy_change,
        1e-17,
    );
}

#[test]
fn fixed_steps_on_the_general_kernel_are_the_paper_s_run() {
    crate::testing::timeout(60, || {
        // The paper's collision, and tests/test_one_engine.py's rattle (a
        // released main mass on a stiff spring, contacts on both walls, the
        // main damper and the contact damper acting): the written-out run,
        // given the kernel's latched approach rates (each its own located
        // one to round-off), to the bit in the final state, the same steps
        // and evaluations, the same contacts, their records to round-off
        // (kernel/fixed_tests.rs checks the records against an
        // event-driven reference on a stiff system without dampers).
        let paper = (table_1(0.01), [0.0, 0.01, 0.0, 0.1], 0.3);
        let rattle = (
            ImpactDamper::new(1.0, 40.0, 0.01, 0.25, 0.01).unwrap(),
            [0.05, 0.05, 0.02, 0.0],
            2.9,
        );
        for (law, restitution) in [
            (LawKind::Hertz, None),
            (LawKind::HysterHertz, Some(0.9)),
            (LawKind::HertzDamped, Some(0.7)),
        ] {
            let contact = Contact::new(law, 3000.0, restitution, 0.01).unwrap();
            for (damper, start, t_end) in [paper, rattle] {
                for timing in [ContactTiming::Located, ContactTiming::StepCount] {
                    let case = format!("{law:?}, t_end {t_end}, {timing:?}");
                    let ours = kernel_run(damper, &contact, start, (1e-4, t_end), timing);
                    let latches: Vec<f64> =
                        ours.contacts.iter().map(|c| c.approach_speed).collect();
                    let located = timing == ContactTiming::Located;
                    let reference = Paper::new(damper, &contact).fixed_run(
                        start,
                        (1e-4, t_end),
                        located,
                        &latches,
                    );
                    assert!(!reference.records.is_empty(), "{case}");
                    let last = reference.records.last().unwrap();
                    assert!(last.separation.is_finite(), "{case}: ends apart");
                    assert_eq!(reference.records.len(), ours.contacts.len(), "{case}");
                    assert_eq!(
                        (reference.steps, reference.steps),
                        (ours.steps, ours.rhs_evaluations),
                        "{case}"
                    );
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&reference.end), bits(&ours.final_state[..4]), "{case}");
                    for (own, latched) in reference.onset_rates.iter().zip(&latches) {
                        assert!(
                            (own - latched).abs() <= 1e-13 * own,
                            "{case}: {own} {latched}"
                        );
                    }
                    for (a, b) in reference.records.iter().zip(&ours.contacts) {
                        assert_record_matches(&case, a, b);
                    }
                }
            }
        }
    });
}

// Fails until kernel/contacts.rs close_open takes a fixed-step contact's
// running sum of its dissipation: it subtracts that sum from the pair's loss
// accumulator, as for events (1.16e-4 J here for the running sum's 1.62e-5 J).
#[test]
#[ignore = "kernel/contacts.rs close_open: see the comment above"]
fn a_contact_open_at_the_end_of_fixed_steps_reports_its_running_dissipation() {
    crate::testing::timeout(60, || {
        // The rattle of the test above, run on into its next contact.
        let contact = Contact::new(LawKind::Hertz, 3000.0, None, 0.01).unwrap();
        let damper = ImpactDamper::new(1.0, 40.0, 0.01, 0.25, 0.01).unwrap();
        let start = [0.05, 0.05, 0.02, 0.0];
        let ours = kernel_run(damper, &contact, start, (1e-4, 3.0), ContactTiming::Located);
        let reference = Paper::new(damper, &contact).fixed_run(start, (1e-4, 3.0), true, &[]);
        let (a, b) = (
            reference.records.last().unwrap(),
            ours.contacts.last().unwrap(),
        );
        assert!(a.separation.is_nan() && b.separation.is_nan());
        assert!((a.onset - b.onset).abs() <= 1e-13, "{a:?} {b:?}");
        assert!(
            (a.dissipated - b.energy_dissipated).abs() <= 1e-10 * a.dissipated,
            "{a:?} {b:?}"
        );
    });
}
