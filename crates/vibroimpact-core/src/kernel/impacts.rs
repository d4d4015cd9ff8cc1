//! The rigid pairs at an event instant, resolved together.
//!
//! Every rigid pair on its wall at the instant takes part: those arriving
//! (impacts), those sticking, and those landing or touching at rest. The
//! impulses
//! `P >= 0` are the solution of Newton's law for several contacts, the
//! linear complementarity problem Siconos solves at an event:
//!
//! `u+ = u- + W P`, `W = H M^-1 H^T`, `0 <= P  _|_  u+ + e min(u-, 0) >= 0`
//!
//! (`u` the gaps' rates). An arriving pair leaves at `e` times its approach
//! unless the others' impulses push it off faster. A sticking pair (`e = 0`)
//! is held against impulses elsewhere, or lifted off by them. Where the pairs
//! do not share a coordinate, `W` is diagonal and this is each pair's own
//! Newton impact; where they do (two dampers on one point), one impact no
//! longer re-closes the other, as it did when they were applied one after the
//! other.
//!
//! Then a pair whose chattering sequence would finish within the run's
//! resolution, or one landing at rest, sticks: it is solved again with
//! `e = 0`, from the velocities before the instant. With the relative
//! acceleration `a` pressing the pair together and rebound speed `r`, the
//! flights `2 r e^n / |a|` add up to `2 r / (|a| (1 - e))` (exact for a
//! constant `a`, such as a ball on a floor), which is when its sticking
//! starts. A sticking pair that the impulses elsewhere would lift off by a
//! flight shorter than the resolution is held instead, as an equality (two
//! dampers settling on one wall launch each other at every landing, the
//! flights falling by the mass ratio: summed, both rest).
//!
//! A sequence no one pair's flights describe, a body squeezed between two
//! converging walls (a light particle between its floor and a heavier one
//! falling on it: it strikes each in turn, ever faster), is an inelastic
//! collapse: its impacts close in on one instant, where every pair in it
//! moves as one. [`Squeeze`] sees the events close in below the resolution;
//! at the next, every rigid pair within the distance the speeds cover in the
//! resolution is resolved plastically (`e = 0`) at once, and sticks.

use crate::kernel::complementarity::Complementarity;
use crate::kernel::events::{ContactKind, Open, PairContact};
use crate::kernel::locate::wall_round_off;
use crate::kernel::observe::Jump;
use crate::model::assembly::{Assembly, InteractionLaw, Mode, Scratch};

/// Rigid events in a row, each closer to the last than the resolution and
/// than the two before it were: an inelastic collapse (see the module's
/// docs). Below this count such a sequence is left to run.
const SQUEEZE_EVENTS: u32 = 8;

/// Watches the rigid events for an inelastic collapse ([`Self::armed`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Squeeze {
    shrinking: u32,
    /// The last two intervals between rigid events, s.
    intervals: [f64; 2],
}

impl Default for Squeeze {
    fn default() -> Self {
        Self {
            shrinking: 0,
            intervals: [f64::INFINITY; 2],
        }
    }
}

impl Squeeze {
    /// After an event at `time` (`rigid`: one the rigid pairs' problem resolved)
    /// `interval` s after the last, in a run of `resolution` s. Shorter than
    /// the longer of the two before it by a margin (equal flights, an
    /// elastic rattle, are no collapse), it closes in.
    pub(crate) fn after(&mut self, rigid: bool, (time, interval): (f64, f64), resolution: f64) {
        let before = self.intervals[0].max(self.intervals[1]);
        // Events at one instant to the time's round-off close in too (their
        // intervals, zero or an ulp, can shrink no further).
        let instant = interval <= 8.0 * f64::EPSILON * time.abs();
        let closing = rigid && interval < resolution && (interval < 0.999 * before || instant);
        self.shrinking = if closing { self.shrinking + 1 } else { 0 };
        self.intervals = [self.intervals[1], interval];
    }

    /// Whether [`SQUEEZE_EVENTS`] in a row closed in on one instant.
    pub(crate) fn armed(&self) -> bool {
        self.shrinking >= SQUEEZE_EVENTS
    }

    /// The collapse resolved: watch afresh.
    pub(crate) fn resolved(&mut self) {
        *self = Self::default();
    }
}

/// What a pair in the problem is doing at the instant.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Role {
    /// Arriving at `approach` (m/s, > 0) with restitution `e`.
    Impact { approach: f64, restitution: f64 },
    /// Sticking from this instant (landing at rest, or pressed after a
    /// graze), with the approach speed (m/s) it had.
    Stick { approach: f64 },
    /// Sticking before the instant.
    Held,
    /// Touching at rest, not pressed: in the problem (`e = 0`) so that the
    /// impulses elsewhere cannot drive it through its wall, then put a few
    /// units of round-off off the wall.
    Touch,
}

/// The rigid pairs' problem at one instant: buffers sized once per run.
#[derive(Debug, Clone)]
pub(crate) struct Impacts {
    /// Open rigid pairs at their walls, marked by the event handling.
    touching: Vec<bool>,
    members: Vec<usize>,
    roles: Vec<Role>,
    /// An impacting member found to stick: `(delay, rebound)`.
    stuck: Vec<Option<(f64, f64)>>,
    /// The members' rates before the instant (`u-`), m/s.
    before: Vec<f64>,
    /// Velocities before the instant.
    velocities: Vec<f64>,
    /// The largest speed before the instant, m/s.
    speed_scale: f64,
    lcp: Complementarity,
    /// The members touching at rest at this instant, and the problem that
    /// spaces them off their walls together ([`Self::space_touched`]).
    touched: Vec<usize>,
    spacing: Complementarity,
}

impl Impacts {
    pub(crate) fn new(system: &Assembly) -> Self {
        // A system without rigid pairs never resolves any: no buffers (a
        // run's set-up allocates each, and a short run's cost is set-up).
        let (count, dim) = if system.has_rigid() {
            (system.interactions.len(), system.dim)
        } else {
            (0, 0)
        };
        Self {
            touching: vec![false; count],
            members: Vec::with_capacity(count),
            roles: Vec::with_capacity(count),
            stuck: Vec::with_capacity(count),
            before: Vec::with_capacity(count),
            velocities: vec![0.0; dim],
            speed_scale: 0.0,
            lcp: Complementarity::new(count),
            touched: Vec::with_capacity(count),
            spacing: Complementarity::new(count),
        }
    }

    /// Whether interaction `i` is an open rigid pair: it is then marked, to
    /// be resolved with the others by [`Self::resolve`].
    pub(crate) fn mark(&mut self, system: &Assembly, i: usize, mode: Mode) -> bool {
        let open_rigid = mode == Mode::Open
            && matches!(system.interactions[i].law, InteractionLaw::Rigid { .. });
        if open_rigid {
            self.touching[i] = true;
        }
        open_rigid
    }

    /// Resolve the marked pairs and the sticking ones at `time`: impacts,
    /// sticking, release of sticking pairs lifted off. `resolution` (s) is the
    /// time below which a chattering sequence is summed, `instant` (s) the
    /// round-off of the time, `time_scale` (s) the system's. `collapse`: an
    /// inelastic collapse (see [`Squeeze`]), every member resolved
    /// plastically and stuck. Sets `just_switched` for the pairs that
    /// changed; returns whether any did or any impulse acted.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn resolve(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &mut [f64],
        modes: &mut [Mode],
        open: &mut [Option<Open>],
        contacts: &mut Vec<PairContact>,
        impact_loss: &mut f64,
        grazes: &mut u64,
        (resolution, instant, time_scale): (f64, f64, f64),
        collapse: bool,
        scratch: &mut Scratch,
        work: &mut [f64],
        just_switched: &mut [bool],
    ) -> bool {
        let d = system.dim;
        // The speeds before the instant (the impulses change them).
        self.speed_scale = y[d..2 * d].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let scales = (instant, time_scale);
        let any = self.classify(
            system,
            time,
            y,
            modes,
            grazes,
            (scales, collapse),
            scratch,
            work,
            just_switched,
        );
        if self.members.is_empty() {
            return any;
        }
        self.impulses(
            system,
            time,
            y,
            modes,
            (resolution, collapse),
            scratch,
            work,
        );
        self.record(
            system,
            time,
            y,
            modes,
            (open, contacts),
            impact_loss,
            grazes,
            (just_switched, collapse),
        ) || any
    }

    /// The largest speed before the last instant resolved, m/s.
    pub(crate) fn speed_scale(&self) -> f64 {
        self.speed_scale
    }

    /// The members the last event's impulses acted on (or held as
    /// equalities), each with the restitution its rate was resolved to
    /// (`u+ = -e u-`; 0 where it stuck, was held or touched at rest): the
    /// event's reset map, for the tangent flow ([`crate::kernel::observe`]).
    pub(crate) fn jumps(&self, out: &mut Vec<Jump>) {
        out.clear();
        for (s, &i) in self.members.iter().enumerate() {
            if self.lcp.z[s] == 0.0 && !self.lcp.bilateral[s] {
                continue;
            }
            let restitution = match (self.roles[s], self.stuck[s]) {
                (Role::Impact { restitution, .. }, None) if self.before[s] < 0.0 => restitution,
                _ => 0.0,
            };
            out.push(Jump {
                interaction: i,
                restitution,
                // As `resolve` records an impact: its role's, with an impulse.
                struck: matches!(self.roles[s], Role::Impact { .. }) && self.lcp.z[s] != 0.0,
            });
        }
    }

    /// The roles of the rigid pairs marked touching at `time`: impact,
    /// stick, touch (the members of the event's problem); whether any
    /// switched without one.
    #[allow(clippy::too_many_arguments)]
    fn classify(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &mut [f64],
        modes: &mut [Mode],
        grazes: &mut u64,
        ((instant, time_scale), collapse): ((f64, f64), bool),
        scratch: &mut Scratch,
        work: &mut [f64],
        just_switched: &mut [bool],
    ) -> bool {
        let speed_scale = self.speed_scale;
        self.members.clear();
        self.roles.clear();
        let mut any = false;
        for i in 0..self.touching.len() {
            if !std::mem::take(&mut self.touching[i]) {
                continue;
            }
            let InteractionLaw::Rigid { restitution } = system.interactions[i].law else {
                continue;
            };
            let (gap, rate) = system.gap(i, y);
            let approach = -rate;
            let round_off = flight_round_off(system, i, y);
            // The gap's acceleration with the pair free: < 0 presses it shut.
            let pressing = system.gap_acceleration(i, time, y, modes, scratch, work);
            let (landing, at_rest) = resting(approach, pressing, round_off, instant, time_scale);
            let moving = !landing && !at_rest;
            let arriving = approach > 1e-12 * speed_scale.max(f64::MIN_POSITIVE);
            let role = if arriving && system.locked(i) {
                // No clearance at all: the rebounds between two walls zero
                // apart add up at once, to moving together (plastic).
                just_switched[i] = true;
                modes[i] = Mode::Sticking;
                Role::Stick { approach }
            } else if arriving && moving {
                Role::Impact {
                    approach,
                    restitution,
                }
            } else if collapse {
                // In the collapse, not arriving: held with the others (the
                // impulses that stop them would close it next).
                just_switched[i] = true;
                any = true;
                modes[i] = Mode::Sticking;
                Role::Stick { approach: 0.0 }
            } else if -approach > 1e-9 * speed_scale && moving {
                // Located on the wall but leaving it (the start of a step
                // just after an impact): no event. Still past it by
                // round-off, it is put a few units of round-off off: leaving
                // at a rate of round-off too (a system come to rest), it
                // would be found there again at every step.
                if gap <= 0.0 {
                    system.release(i, y);
                }
                continue;
            } else {
                just_switched[i] = true;
                any = true;
                if !landing {
                    *grazes += 1;
                }
                if system.held_by_mirror(i, modes) {
                    // Its other wall (a zero clearance) took the touch.
                    continue;
                }
                if pressing >= 0.0 {
                    Role::Touch
                } else {
                    // At rest and pressed: a sequence whose flights would
                    // rise less than round-off. It sticks at once, whatever
                    // its restitution (even 1: a ball resting on a floor
                    // stays).
                    modes[i] = Mode::Sticking;
                    Role::Stick {
                        approach: approach.max(0.0),
                    }
                }
            };
            self.members.push(i);
            self.roles.push(role);
        }
        any
    }

    /// The impulses at the event: the members' problem solved, with the
    /// sticking pairs held and the chattering sequences that finish within
    /// `resolution` s summed to sticking.
    #[allow(clippy::too_many_arguments)]
    fn impulses(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &mut [f64],
        modes: &mut [Mode],
        (resolution, collapse): (f64, bool),
        scratch: &mut Scratch,
        work: &mut [f64],
    ) {
        let d = system.dim;
        let speed_scale = self.speed_scale;
        for (i, mode) in modes.iter().enumerate() {
            if *mode == Mode::Sticking && !self.members.contains(&i) {
                self.members.push(i);
                self.roles.push(Role::Held);
            }
        }
        let m = self.members.len();
        self.velocities.copy_from_slice(&y[d..2 * d]);
        self.before.clear();
        self.before
            .extend(self.members.iter().map(|&i| system.gap(i, y).1));
        self.lcp.set_matrix(system, &self.members);
        // A damper with no clearance, stuck, is locked to its point: held
        // with a force of either sign, never lifted off by impulses
        // elsewhere (its other wall is zero away).
        for (s, &i) in self.members.iter().enumerate() {
            if matches!(self.roles[s], Role::Held | Role::Stick { .. }) && system.locked(i) {
                self.lcp.bilateral[s] = true;
            }
        }
        self.stuck.clear();
        self.stuck.resize(m, None);
        if collapse {
            // The collapse's rest summed at once: each impact Newton's at
            // its own restitution, then plastic, as a summed sequence's.
            for (s, &i) in self.members.iter().enumerate() {
                if let Role::Impact {
                    approach,
                    restitution,
                } = self.roles[s]
                {
                    self.stuck[s] = Some((0.0, restitution * approach));
                    modes[i] = Mode::Sticking;
                }
            }
        }
        // Each round may find more pairs to stick or to hold: at most 2 m.
        for _ in 0..=2 * m {
            y[d..2 * d].copy_from_slice(&self.velocities);
            for (s, role) in self.roles.iter().enumerate() {
                let u = self.before[s];
                let e = match role {
                    Role::Impact { restitution, .. } if self.stuck[s].is_none() => *restitution,
                    _ => 0.0,
                };
                self.lcp.q[s] = if u < 0.0 { (1.0 + e) * u } else { u };
            }
            self.lcp.solve();
            for (s, &i) in self.members.iter().enumerate() {
                let impulse = self.lcp.z[s];
                if impulse != 0.0 {
                    system.interactions[i].add_push(impulse, &mut y[d..2 * d]);
                }
            }
            let mut more = false;
            for s in 0..m {
                if self.lcp.bilateral[s] || self.lcp.z[s] > 0.0 {
                    continue;
                }
                let i = self.members[s];
                let sticking = match self.roles[s] {
                    Role::Impact { .. } => self.stuck[s].is_some(),
                    Role::Touch => false,
                    Role::Stick { .. } | Role::Held => true,
                };
                // A sticking pair that the impulses elsewhere lift off its
                // wall, but whose flight would rise less than round-off or
                // land within the resolution (two dampers resting on one
                // wall: each landing launches the other, the flights falling
                // geometrically to an accumulation where both rest): the
                // sequence summed, it is held, with an impulse of either sign.
                let lift = system.gap(i, y).1;
                if !sticking || lift <= 1e-9 * speed_scale {
                    continue;
                }
                modes[i] = Mode::Open;
                let pressing = system.gap_acceleration(i, time, y, modes, scratch, work);
                modes[i] = Mode::Sticking;
                let round_off = flight_round_off(system, i, y);
                if summed(lift, pressing, 0.0, resolution, round_off).is_some() {
                    self.lcp.bilateral[s] = true;
                    more = true;
                }
            }
            for s in 0..m {
                let (Role::Impact { restitution, .. }, None) = (self.roles[s], self.stuck[s])
                else {
                    continue;
                };
                let i = self.members[s];
                // Would the rest of a chattering sequence finish within the
                // run's resolution (fixed-step methods: the step), or its
                // flights rise less than round-off? Then sum it and stick.
                let rebound = system.gap(i, y).1.max(0.0);
                let pressing = system.gap_acceleration(i, time, y, modes, scratch, work);
                let round_off = flight_round_off(system, i, y);
                if let Some(delay) = summed(rebound, pressing, restitution, resolution, round_off) {
                    self.stuck[s] = Some((delay, rebound));
                    modes[i] = Mode::Sticking;
                    more = true;
                }
            }
            if !more {
                break;
            }
        }
    }

    /// Member `s`'s rate after the impulses and its share of the energy
    /// they took, J: `-P (u- + u+) / 2` (the shares sum to the kinetic energy
    /// lost).
    fn share(&self, s: usize) -> (f64, f64) {
        let after = self.before[s] + self.lcp.w_minus_q(s);
        (after, -0.5 * self.lcp.z[s] * (self.before[s] + after))
    }

    /// In a collapse the pairs held from leaving take a share of either sign
    /// (an impulse against a rate that was opening): the arriving pairs'
    /// records carry the whole loss, each in proportion to its own. Their
    /// shares' sum and the factor on each (1 outside a collapse).
    fn collapse_shares(&self, collapse: bool) -> (f64, f64) {
        if !collapse {
            return (0.0, 1.0);
        }
        let (mut arriving, mut held) = (0.0, 0.0);
        for s in 0..self.members.len() {
            match self.roles[s] {
                Role::Impact { .. } => arriving += self.share(s).1,
                _ => held += self.share(s).1,
            }
        }
        let scale = if arriving > 0.0 {
            (arriving + held) / arriving
        } else {
            1.0
        };
        (arriving, scale)
    }

    /// Each member's share of the energy the impulses took, its record and
    /// its new mode; whether any impulse acted or pair lifted off.
    #[allow(clippy::too_many_arguments)]
    fn record(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &mut [f64],
        modes: &mut [Mode],
        (open, contacts): (&mut [Option<Open>], &mut Vec<PairContact>),
        impact_loss: &mut f64,
        grazes: &mut u64,
        (just_switched, collapse): (&mut [bool], bool),
    ) -> bool {
        let speed_scale = self.speed_scale;
        let mut any = false;
        let (arriving, scale) = self.collapse_shares(collapse);
        // Each pair's share of the energy the impulses take, J:
        // -P (u- + u+) / 2, which sums to the kinetic energy lost.
        for (s, &i) in self.members.iter().enumerate() {
            let impulse = self.lcp.z[s];
            let (after, own) = self.share(s);
            *impact_loss += own;
            let loss = match self.roles[s] {
                Role::Impact { .. } => scale * own,
                _ if arriving > 0.0 => 0.0,
                _ => own,
            };
            let pair = system.interactions[i].pair;
            any |= impulse != 0.0;
            match (self.roles[s], self.stuck[s]) {
                (
                    Role::Impact {
                        approach,
                        restitution,
                    },
                    stuck,
                ) => {
                    if impulse == 0.0 && stuck.is_none() {
                        // Pushed off by the others' impulses before its own
                        // acted: a touch, not an impact.
                        *grazes += 1;
                        continue;
                    }
                    just_switched[i] = true;
                    // Newton's share of the loss, and with a sticking the
                    // rest of the plastic impact's (the summed sequence's).
                    let kept = if stuck.is_some() && impulse != 0.0 {
                        restitution * restitution
                    } else {
                        0.0
                    };
                    // (Stuck with no impulse of its own: the others' held it.)
                    if impulse != 0.0 {
                        contacts.push(PairContact {
                            pair,
                            kind: ContactKind::Impact,
                            onset: time,
                            separation: time,
                            duration: 0.0,
                            max_indentation: 0.0,
                            approach_speed: approach,
                            rebound_speed: if stuck.is_some() {
                                restitution * approach
                            } else {
                                after
                            },
                            restitution: if stuck.is_some() {
                                restitution
                            } else {
                                after / approach
                            },
                            energy_dissipated: (1.0 - kept) * loss,
                            energy_change: -(1.0 - kept) * loss,
                        });
                    }
                    if let Some((delay, rebound)) = stuck {
                        open[i] = Some(Open {
                            kind: ContactKind::Sticking,
                            onset: time + delay,
                            approach_speed: rebound,
                            max_indentation: 0.0,
                            dissipated: kept * loss,
                            resting: false,
                            balance: Default::default(),
                            energy: f64::NAN,
                            power: 0.0,
                        });
                    }
                }
                (Role::Stick { .. }, _) if after > 1e-9 * speed_scale => {
                    // Lifted off by the impulses elsewhere: a touch.
                    modes[i] = Mode::Open;
                }
                (Role::Stick { approach }, _) => {
                    open[i] = Some(Open {
                        kind: ContactKind::Sticking,
                        onset: time,
                        approach_speed: approach,
                        max_indentation: 0.0,
                        dissipated: loss,
                        resting: false,
                        balance: Default::default(),
                        energy: f64::NAN,
                        power: 0.0,
                    });
                }
                (Role::Touch, _) => {
                    // Touching at rest, not pressed (a pair released at the
                    // instant its force turns, a zero clearance, a plastic
                    // landing as its wall's pull turns): put it a few units
                    // of round-off off the wall, or the same touch is found
                    // again at once, without end. (Within the events' band
                    // of round-off above the wall too: two loose masses
                    // touching in free fall close at a rate of exactly zero,
                    // which reads as arriving there.)
                    self.touched.push(i);
                }
                (Role::Held, _) => {
                    if impulse != 0.0 {
                        if let Some(oc) = open[i].as_mut() {
                            oc.dissipated += loss;
                        }
                    } else if after > 1e-9 * speed_scale && !just_switched[i] {
                        // Lifted off its wall by the impulses elsewhere. (One
                        // that stuck at this instant moves with its wall to
                        // round-off, which must not read as lifting.)
                        modes[i] = Mode::Open;
                        any = true;
                        if let Some(oc) = open[i].take() {
                            contacts.push(oc.close(pair, time, 0.0, oc.dissipated));
                        }
                    }
                }
            }
        }
        self.space_touched(system, y);
        any
    }

    /// The pairs touching at rest at this instant (`touched`) put a few units
    /// of round-off off their walls, or the same touch is found again at
    /// once, without end. One alone along its own `M^-1 h^T`
    /// ([`Assembly::release`]); several at once together, by the positions'
    /// complementarity problem `W z + (g - g*) >= 0`, `z >= 0` (`g*` the
    /// spacing release gives): a light body touching two heavier ones at rest
    /// (a stack lifting off as one block) had each release close the other
    /// gap, events 1e-17 s apart without end.
    fn space_touched(&mut self, system: &Assembly, y: &mut [f64]) {
        let touched = &self.touched;
        let below = |&i: &usize| system.gap(i, y).0 <= wall_round_off(system, i, y);
        if touched.len() == 1 && below(&touched[0]) {
            system.release(touched[0], y);
        } else if touched.len() > 1 && touched.iter().any(below) {
            self.spacing.set_matrix(system, touched);
            for (s, &i) in touched.iter().enumerate() {
                self.spacing.q[s] = system.gap(i, y).0 - system.released_gap(i, y);
            }
            self.spacing.solve();
            let d = system.dim;
            for (s, &i) in touched.iter().enumerate() {
                if self.spacing.z[s] > 0.0 {
                    system.interactions[i].add_push(self.spacing.z[s], &mut y[..d]);
                }
            }
        }
        self.touched.clear();
    }
}

/// Whether a pair touching its wall at `approach` (m/s, > 0 closing), with
/// `pressing` (m/s^2, < 0 presses it shut) lands at rest, and whether it is
/// at rest whatever the pressing: `(landing, at_rest)`. `round_off` (m) is
/// its flights' round-off ([`flight_round_off`]), `instant` (s) the time's,
/// `time_scale` (s) the system's. Shared by the rigid pairs and the compliant
/// contacts, whose resting onsets have no rebound ratio.
pub(crate) fn resting(
    approach: f64,
    pressing: f64,
    round_off: f64,
    instant: f64,
    time_scale: f64,
) -> (bool, bool) {
    // At rest whatever the pressing: a rate that would take the system's
    // time scale to move the gap by its round-off (a system come to rest,
    // where every speed is round-off and relative thresholds say nothing).
    let at_rest = approach.abs() * time_scale <= round_off;
    // Landing at rest: an approach (or a leaving) that the pressing gives
    // within a rise of round-off, or within the round-off of the time.
    let landing = pressing < 0.0
        && (approach * approach <= -2.0 * pressing * round_off
            || approach.abs() <= -pressing * instant
            || at_rest);
    (landing, at_rest)
}

/// Flights (or landings) of interaction `i` that rise less than this (m,
/// 1e-9 of its gap's scale at state `y`) are round-off: the positions'
/// round-off decides such impacts, not the dynamics, and the pair is at rest
/// on its wall.
pub(crate) fn flight_round_off(system: &Assembly, i: usize, y: &[f64]) -> f64 {
    1e-9 * system.gap_scale(i, y)
}

/// Whether a pair leaving its wall at `rebound` (m/s), `pressing` (m/s^2,
/// < 0) pulling it back, with restitution `e`, ends its flights within the
/// run's `resolution` (s) or rises less than `round_off` (m): then the
/// sequence is summed, and its accumulation instant is `Some` delay (s)
/// from now (0 for a sequence that never ends, restitution 1, cut where its
/// flights fell to round-off: now).
fn summed(rebound: f64, pressing: f64, e: f64, resolution: f64, round_off: f64) -> Option<f64> {
    if pressing >= 0.0 {
        return None;
    }
    let remaining = 2.0 * rebound / (-pressing * (1.0 - e));
    let height = rebound * rebound / (-2.0 * pressing);
    (remaining <= resolution || height <= round_off).then_some(if remaining.is_finite() {
        remaining
    } else {
        0.0
    })
}
