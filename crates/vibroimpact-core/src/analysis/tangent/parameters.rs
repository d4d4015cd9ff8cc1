//! The tangent flow's columns by parameters: the derivative of the state by
//! each parameter asked for, `W` (row-major `2 dim x m`), carried beside the
//! map by the forward sensitivity equations `W' = J W + df/dp` over every
//! step and through every event by the saltation's own terms (see
//! [`super::saltation`]): the event's time shift moved by the gap's
//! derivative `dg/dp`, the reset's `(dR/dp) v-`, a sticking constraint's
//! moved offset, a latched approach rate's derivative.
//!
//! `df/dp`, `dg/dp` and `dR/dp` are central differences of the system's
//! rates, gaps and resets at one state between two assemblies made at
//! `p +- delta`, never of whole runs (as CVODES's difference-quotient
//! sensitivities take `df/dp`): no event moves between the two, and where
//! the parameter enters linearly (forces, stiffnesses, damping, clearances,
//! restitution) the quotient is exact.

use crate::error::{Error, Result};
use crate::kernel::observe::Jump;
use crate::model::assembly::{apart_damping, Assembly, Interaction, InteractionLaw, Mode, Scratch};
use crate::model::contact::ContactLaw;
use crate::numerics::linalg;

use super::latched::{floor_of, OnsetRow};

/// A parameter's two assemblies: the system made at `p + delta` and at
/// `p - delta`.
#[derive(Debug, Clone)]
pub struct Shifted {
    pub plus: Assembly,
    pub minus: Assembly,
    /// The half step, in the parameter's unit (> 0).
    pub delta: f64,
}

/// The columns by the parameters and the buffers they need.
pub(super) struct Parameters {
    pub(super) shifted: Vec<Shifted>,
    /// `W`: row-major `2 dim x m`.
    pub(super) columns: Vec<f64>,
    /// The latched approach rates' derivatives (row-major `interactions x
    /// m`; zero where none is latched).
    pub(super) latched: Vec<f64>,
    /// Each shifted system's own work space (a signal's cached value is
    /// its system's).
    scratches: Vec<[Scratch; 2]>,
    full: Vec<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
}

/// Whether two laws are of one kind (rigid, friction, or the same compliant
/// law).
fn same_kind(a: &InteractionLaw, b: &InteractionLaw) -> bool {
    match (a, b) {
        (InteractionLaw::Rigid { .. }, InteractionLaw::Rigid { .. })
        | (InteractionLaw::Friction { .. }, InteractionLaw::Friction { .. }) => true,
        (InteractionLaw::Compliant { law: x, .. }, InteractionLaw::Compliant { law: y, .. }) => {
            std::mem::discriminant(x) == std::mem::discriminant(y)
        }
        _ => false,
    }
}

impl Parameters {
    /// Refused where a shifted assembly is not the same system in shape (its
    /// coordinates, pairs and kinds of law): a parameter that changes
    /// which laws act has no derivative.
    pub(super) fn new(system: &Assembly, shifted: Vec<Shifted>) -> Result<Self> {
        for (j, s) in shifted.iter().enumerate() {
            if !(s.delta.is_finite() && s.delta > 0.0) {
                return Err(Error::Inconsistent(format!(
                    "parameter {j}: its half step must be a finite number > 0, got {}",
                    s.delta
                )));
            }
            for other in [&s.plus, &s.minus] {
                let alike = other.n == system.n
                    && other.k == system.k
                    && other.pairs == system.pairs
                    && other.interactions.len() == system.interactions.len()
                    && other
                        .interactions
                        .iter()
                        .zip(&system.interactions)
                        .all(|(a, b)| same_kind(&a.law, &b.law));
                if !alike {
                    return Err(Error::Inconsistent(format!(
                        "parameter {j}: the system it makes has other coordinates, pairs or \
                         laws than the run's; a derivative is taken only in a parameter \
                         that changes values, not the system's shape"
                    )));
                }
            }
        }
        let (size, m) = (2 * system.dim, shifted.len());
        Ok(Self {
            latched: vec![0.0; system.interactions.len() * m],
            columns: vec![0.0; size * m],
            scratches: shifted
                .iter()
                .map(|s| [Scratch::new(&s.plus), Scratch::new(&s.minus)])
                .collect(),
            shifted,
            full: vec![0.0; system.state_len()],
            plus: vec![0.0; system.state_len()],
            minus: vec![0.0; system.state_len()],
        })
    }

    pub(super) fn count(&self) -> usize {
        self.shifted.len()
    }

    /// `df/dp` of `system` (the run's) at `time`, state `y` (`x` then `v`)
    /// and `modes`, added into `out`'s columns `first..first + m` (row-major,
    /// `stride` columns).
    pub(super) fn add_field(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &[f64],
        modes: &[Mode],
        out: &mut [f64],
        (first, stride): (usize, usize),
    ) {
        let size = y.len();
        self.full[..size].copy_from_slice(y);
        for (j, (s, [up, down])) in self.shifted.iter().zip(&mut self.scratches).enumerate() {
            s.plus.rates(time, &self.full, modes, up, &mut self.plus);
            s.minus
                .rates(time, &self.full, modes, down, &mut self.minus);
            for r in 0..size {
                out[r * stride + first + j] += (self.plus[r] - self.minus[r]) / (2.0 * s.delta);
            }
        }
        self.contacts_inside(system, y, modes, out, (first, stride));
    }

    /// The compliant contacts' part of [`Self::add_field`] taken from
    /// inside them. The quotient of the rates compares each shifted
    /// system's force at its own indentation: where a parameter moves a gap
    /// (a clearance) and the contact has just begun or is about to end, one
    /// side is apart, its force clamped, and the quotient errs in proportion
    /// to the step (a linear law with a contact damper had been 0.6 % off at
    /// a relative step of 1e-6). Here that comparison is replaced by the
    /// laws' own quotient at the run's indentation plus the exact slopes
    /// times the indentation's derivative: `d(push F)/dp = Q[push F](delta)
    /// + push (F_delta delta_p + F_rate rate_p)`.
    fn contacts_inside(
        &self,
        system: &Assembly,
        y: &[f64],
        modes: &[Mode],
        out: &mut [f64],
        (first, stride): (usize, usize),
    ) {
        let d = y.len() / 2;
        for (i, (&mode, it)) in modes.iter().zip(&system.interactions).enumerate() {
            let (Mode::Compliant { approach_rate, .. }, InteractionLaw::Compliant { law, damping }) =
                (mode, it.law)
            else {
                continue;
            };
            let indentation = -(it.offset + linalg::dot(&it.h, &y[..d]));
            let rate = -linalg::dot(&it.h, &y[d..]);
            let (_, by_indentation, by_rate) =
                law.force_derivatives(indentation.max(0.0), rate, approach_rate);
            for (j, s) in self.shifted.iter().enumerate() {
                let gaps = [s.plus.gap(i, y), s.minus.gap(i, y)];
                let (gap_by, rate_by) = (
                    (gaps[0].0 - gaps[1].0) / (2.0 * s.delta),
                    (gaps[0].1 - gaps[1].1) / (2.0 * s.delta),
                );
                // d(push F)/dp = Q[push F](run's indentation) + push dF/dp.
                let slope = -(by_indentation * gap_by + (by_rate + damping) * rate_by);
                let mut sides = [0.0; 2];
                for ((side, shifted), (gap, own_rate)) in
                    sides.iter_mut().zip([&s.plus, &s.minus]).zip(gaps)
                {
                    let own = &shifted.interactions[i];
                    let at_run = contact_force(own, mode, indentation, rate);
                    *side = (at_run - contact_force(own, mode, -gap, -own_rate)) / (2.0 * s.delta);
                }
                let (up, down) = (&s.plus.interactions[i].push, &s.minus.interactions[i].push);
                for r in 0..d {
                    out[(d + r) * stride + first + j] +=
                        sides[0] * up[r] - sides[1] * down[r] + slope * it.push[r];
                }
            }
        }
    }

    /// Interaction `i`'s gap and its rate moved by parameter `j` at state
    /// `y`: `(dg/dp, d(g')/dp)` at fixed state.
    pub(super) fn gap_by(&self, j: usize, i: usize, y: &[f64]) -> (f64, f64) {
        let s = &self.shifted[j];
        let (up, down) = (s.plus.gap(i, y), s.minus.gap(i, y));
        (
            (up.0 - down.0) / (2.0 * s.delta),
            (up.1 - down.1) / (2.0 * s.delta),
        )
    }

    /// Interaction `i`'s latched approach rate at an onset at `time` from
    /// the state `before` in `modes`: its derivatives by the parameters,
    /// `c_i W- + shift dg/dp` (`latched` the flow's rows, which hold `c_i`
    /// and the shift), and where the rate latched is the law's floor
    /// ([`OnsetRow::Floor`]) the floor's own change at that state (its
    /// law's, its mass's and the pressing's, between the shifted systems);
    /// zero where none was latched (None: a separation, or no derivative).
    pub(super) fn onset(
        &mut self,
        i: usize,
        (time, before, modes): (f64, &[f64], &[Mode]),
        latched: Option<(&super::Latched, OnsetRow)>,
    ) {
        let (m, size) = (self.count(), before.len());
        if matches!(latched, Some((_, OnsetRow::Floor))) {
            self.full[..size].copy_from_slice(before);
        }
        for j in 0..m {
            self.latched[i * m + j] = match latched {
                None => 0.0,
                Some((l, kind)) => {
                    let along: f64 = (0..size)
                        .map(|k| l.onset_row[k] * self.columns[k * m + j])
                        .sum();
                    let own = if kind == OnsetRow::Floor {
                        self.floor_by(j, i, (time, modes))
                    } else {
                        0.0
                    };
                    along + l.onset_shift * self.gap_by(j, i, before).0 + own
                }
            };
        }
    }

    /// Interaction `i`'s floor's change by parameter `j` at the state in
    /// `self.full`, at `time` in `modes`: between the shifted systems (0
    /// where either has none there).
    fn floor_by(&mut self, j: usize, i: usize, (time, modes): (f64, &[Mode])) -> f64 {
        let s = &self.shifted[j];
        let [up, down] = &mut self.scratches[j];
        let at = (time, &self.full[..], modes);
        match (
            floor_of(&s.plus, i, at, up),
            floor_of(&s.minus, i, at, down),
        ) {
            (Some((plus, _)), Some((minus, _))) => (plus - minus) / (2.0 * s.delta),
            _ => 0.0,
        }
    }

    /// A jump's restitution in a shifted system: its law's there, where the
    /// event gave the law's own; else the event's (0: a pair that stuck).
    pub(super) fn restitution_in(system: &Assembly, other: &Assembly, jump: &Jump) -> f64 {
        let law = |a: &Assembly| match a.interactions[jump.interaction].law {
            InteractionLaw::Rigid { restitution } => Some(restitution),
            InteractionLaw::Compliant { .. } | InteractionLaw::Friction { .. } => None,
        };
        match (law(system), law(other)) {
            (Some(own), Some(shifted)) if own == jump.restitution => shifted,
            _ => jump.restitution,
        }
    }
}

/// The force interaction `it` applies in `mode` at `indentation` (m) and its
/// `rate` (m/s), as the system's rates take it: its law's where indented,
/// else its contact damper's alone where that acts apart.
fn contact_force(it: &Interaction, mode: Mode, indentation: f64, rate: f64) -> f64 {
    let (
        Mode::Compliant {
            approach_rate,
            indented_only,
        },
        InteractionLaw::Compliant { law, damping },
    ) = (mode, it.law)
    else {
        return 0.0;
    };
    if law.acts(indentation, indented_only) {
        law.force_and_elastic(indentation, rate, approach_rate).0 + damping * rate
    } else {
        apart_damping(damping, indented_only) * rate
    }
}
