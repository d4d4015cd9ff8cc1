//! The flow of each configuration (which pairs stick, which linear contacts
//! touch), made when first met: normal modes where the damping is
//! classical, else the matrix exponential.

use super::flow::ExactFlow;
use super::matrix_flow::MatrixFlow;
use super::modal::Configuration;
use super::oscillator::Oscillator;
use crate::error::{Error, Result};
use crate::model::assembly::{Assembly, InteractionLaw, LinearParts, Mode};
use crate::model::contact::AnyLaw;

/// Steps per fastest period: the event kernel's cubic check of a gap between
/// step ends is then within a few 1e-3 of the gap's swing.
pub(super) const STEPS_PER_PERIOD: f64 = 8.0;

/// What each interaction does in a configuration.
pub(super) const OPEN: u8 = 0;
pub(super) const STICKING: u8 = 1;
pub(super) const TOUCHING: u8 = 2;
/// A friction element sliding up (its row's rate > 0), down, or stuck.
pub(super) const SLIDING_UP: u8 = 3;
pub(super) const SLIDING_DOWN: u8 = 4;
pub(super) const STUCK: u8 = 5;

/// Whether `m` is the configuration of `modes` (a stuck friction element's
/// place too: its constraint's offset).
#[inline(always)]
pub(super) fn fits(m: &Modes, modes: &[Mode]) -> bool {
    m.key
        .iter()
        .zip(modes)
        .all(|(s, mode)| *s == state_of(mode))
        && (m.offsets.is_empty()
            || m.offsets.iter().zip(modes).all(|(kept, mode)| match mode {
                Mode::Stuck {
                    offset,
                    shadowed: false,
                } => kept.to_bits() == offset.to_bits(),
                _ => true,
            }))
}

#[inline(always)]
pub(super) fn state_of(mode: &Mode) -> u8 {
    match mode {
        // A shadowed stuck element: the rigid pair's constraint holds it.
        Mode::Open | Mode::Stuck { shadowed: true, .. } => OPEN,
        Mode::Sticking => STICKING,
        Mode::Compliant { .. } => TOUCHING,
        Mode::Sliding { direction } if *direction > 0.0 => SLIDING_UP,
        Mode::Sliding { .. } => SLIDING_DOWN,
        Mode::Stuck { .. } => STUCK,
    }
}

/// Each stuck friction element's offset (NaN for the other interactions),
/// or nothing where none is stuck.
fn offsets_of(modes: &[Mode]) -> Vec<f64> {
    if !modes.iter().any(|m| state_of(m) == STUCK) {
        return Vec::new();
    }
    modes
        .iter()
        .map(|m| match m {
            Mode::Stuck {
                offset,
                shadowed: false,
            } => *offset,
            _ => f64::NAN,
        })
        .collect()
}

/// The flow of one configuration (which pairs stick, which linear contacts
/// touch): its normal modes when its damping is classical, else the matrix
/// exponential (`matrix`, and no modes).
#[derive(Debug, Clone)]
pub(super) struct Modes {
    pub(super) key: Vec<u8>,
    /// Each stuck friction element's offset (see [`offsets_of`]).
    pub(super) offsets: Vec<f64>,
    pub(super) configuration: Configuration,
    pub(super) oscillators: Vec<Oscillator>,
    pub(super) matrix: Option<MatrixFlow>,
    /// Whether a contact touches (its losses are the contact's, not viscous).
    pub(super) touching: bool,
    /// Whether the energies may come from the closed form over a stretch of
    /// steps ([`ExactFlow::step_energies`]): one harmonic at most, no mode
    /// near an undamped resonance.
    pub(super) closed_form: bool,
    /// See [`near_resonance`].
    pub(super) from_rest: Vec<bool>,
    /// An eighth of the configuration's fastest period (s).
    pub(super) step: f64,
}

/// The largest `(w2 + omega^2) / |w2 - omega^2 + i c omega|` of a forced mode
/// for which its energies come from the closed form: that form divides the
/// ends' terms, of the size of the particular response `Z`, by the
/// denominator of `Z` again, so its round-off is `eps` of `(w2 + omega^2)
/// |Z|^2`, the square of this ratio times the forcing's own energy scale
/// `|P|^2 / (w2 + omega^2)`. Near an undamped resonance `Z` dwarfs the motion
/// (which grows from rest, or stays small against a stop), and the closed
/// form's input work drowned it (1 Hz, 1e-5 off, undamped: 7e-4 J where
/// the truth was 8e-9 J): the Gauss-Legendre powers on the flow take its
/// place, and the motion the response from rest ([`from_rest`]).
pub(super) const CLOSED_FORM_AMPLIFICATION: f64 = 100.0;

/// Which harmonic `k` forces which mode `j` near its undamped resonance, at
/// `k * modes + j` (empty where none does): a forced mode whose amplification
/// passes [`CLOSED_FORM_AMPLIFICATION`] (an underdamped one: `c omega` is then
/// small against `w2 + omega^2`). Their energies come from the powers on the
/// flow, not the closed form, and their motion from the response from rest
/// ([`from_rest`]), not the particular response.
pub(super) fn near_resonance(
    configuration: &Configuration,
    oscillators: &[Oscillator],
) -> Vec<bool> {
    let r = configuration.modes;
    let mut near = vec![false; configuration.harmonics.len() * r];
    for (k, harmonic) in configuration.harmonics.iter().enumerate() {
        let w2 = harmonic.omega * harmonic.omega;
        for (j, (o, &(pr, pi))) in oscillators.iter().zip(&harmonic.force).enumerate() {
            let (dr, di) = (o.w2 - w2, o.c * harmonic.omega);
            near[k * r + j] = (pr != 0.0 || pi != 0.0)
                && o.disc < 0.0
                && o.w2 + w2 > CLOSED_FORM_AMPLIFICATION * dr.hypot(di);
        }
    }
    if !near.contains(&true) {
        near.clear();
    }
    near
}

impl ExactFlow {
    pub(super) fn modes_of(
        parts: &LinearParts,
        system: &Assembly,
        key: &[u8],
        offsets: &[f64],
    ) -> Result<Modes> {
        let chosen = |state: u8| {
            system
                .interactions
                .iter()
                .zip(key)
                .filter(move |(_, s)| **s == state)
                .map(|(it, _)| it)
        };
        let mut constraints: Vec<(&[f64], f64)> = chosen(STICKING)
            .map(|it| (it.h.as_slice(), it.offset))
            .collect();
        // A stuck friction element holds its row where it stuck.
        for (i, (it, state)) in system.interactions.iter().zip(key).enumerate() {
            if *state == STUCK {
                constraints.push((it.h.as_slice(), offsets[i]));
            }
        }
        // A touching linear contact pushes with k delta + c delta', delta =
        // -(h.x + offset): stiffness k h h^T and damping c h h^T on top, and
        // the load -k offset h.
        let mut parts = parts.clone();
        let dim = system.dim;
        for it in chosen(TOUCHING) {
            if let InteractionLaw::Compliant {
                law: AnyLaw::Linear(law),
                damping,
            } = it.law
            {
                for i in 0..dim {
                    parts.constant[i] -= law.stiffness * it.offset * it.h[i];
                    for j in 0..dim {
                        parts.stiffness[i * dim + j] += law.stiffness * it.h[i] * it.h[j];
                        parts.damping[i * dim + j] += damping * it.h[i] * it.h[j];
                    }
                }
            }
        }
        // A sliding one pushes with its kinetic force against the sliding.
        for (direction, state) in [(1.0, SLIDING_UP), (-1.0, SLIDING_DOWN)] {
            for it in chosen(state) {
                if let InteractionLaw::Friction { kinetic_force, .. } = it.law {
                    for i in 0..dim {
                        parts.constant[i] -= direction * kinetic_force * it.h[i];
                    }
                }
            }
        }
        let mut names: Vec<String> = chosen(STICKING)
            .map(|it| format!("{} sticking", system.pairs[it.pair]))
            .collect();
        names.extend(chosen(TOUCHING).map(|it| format!("{} in contact", system.pairs[it.pair])));
        let what = if names.is_empty() {
            "the system".to_string()
        } else {
            format!("the system with {}", names.join(" and "))
        };
        names.extend(chosen(STUCK).map(|it| format!("{} stuck", system.pairs[it.pair])));
        // Sliding friction's loss is a contact's: taken from the rates.
        let touching = key
            .iter()
            .any(|s| [TOUCHING, SLIDING_UP, SLIDING_DOWN].contains(s));
        let step = |fastest: f64| std::f64::consts::TAU / (STEPS_PER_PERIOD * fastest);
        match Configuration::classical(&parts, &constraints, &what)? {
            Some(configuration) => {
                let oscillators: Vec<Oscillator> = (0..configuration.modes)
                    .map(|j| {
                        Oscillator::new(
                            configuration.stiffness[j],
                            configuration.damping[j],
                            configuration.constant[j],
                        )
                    })
                    .collect();
                let fastest = oscillators
                    .iter()
                    .map(|o| o.w2.sqrt().max(o.c))
                    .chain(configuration.harmonics.iter().map(|h| h.omega))
                    .fold(0.0f64, f64::max);
                let from_rest = near_resonance(&configuration, &oscillators);
                Ok(Modes {
                    key: key.to_vec(),
                    offsets: offsets.to_vec(),
                    closed_form: configuration.harmonics.len() <= 1 && from_rest.is_empty(),
                    from_rest,
                    configuration,
                    oscillators,
                    matrix: None,
                    touching,
                    step: step(fastest),
                })
            }
            None => {
                let flow = MatrixFlow::new(&parts, &constraints, &what)?;
                Ok(Modes {
                    key: key.to_vec(),
                    offsets: offsets.to_vec(),
                    configuration: Configuration::empty(),
                    oscillators: Vec::new(),
                    step: step(flow.fastest),
                    matrix: Some(flow),
                    touching,
                    closed_form: false,
                    from_rest: Vec::new(),
                })
            }
        }
    }

    /// The modes for the sticking interactions of `modes`, made when first met.
    #[inline(always)]
    pub(super) fn select(&mut self, system: &Assembly, modes: &[Mode]) -> Result<usize> {
        // The modes of the last call, most often.
        if fits(&self.modes[self.selected], modes) {
            return Ok(self.selected);
        }
        self.select_other(system, modes)
    }

    #[cold]
    #[inline(never)]
    pub(super) fn select_other(&mut self, system: &Assembly, modes: &[Mode]) -> Result<usize> {
        self.selected = match self.modes.iter().position(|m| fits(m, modes)) {
            Some(index) => index,
            None => {
                let key: Vec<u8> = modes.iter().map(state_of).collect();
                let offsets = offsets_of(modes);
                let made = Self::modes_of(&self.parts, system, &key, &offsets)?;
                // A stuck friction element's place changes at each sticking:
                // its configuration takes the place of the last one's.
                let stale = (!offsets.is_empty())
                    .then(|| self.modes.iter().position(|m| m.key == key))
                    .flatten();
                match stale {
                    Some(index) => {
                        self.modes[index] = made;
                        // The flow begun there was the old configuration's.
                        self.begun = None;
                        index
                    }
                    None => {
                        check_room(self.modes.len(), system.dim)?;
                        self.modes.push(made);
                        self.modes.len() - 1
                    }
                }
            }
        };
        Ok(self.selected)
    }
}

/// The most memory the configurations met may hold, bytes.
const MAX_CONFIGURATION_BYTES: u64 = crate::kernel::memory::MAX_RECORD_BYTES / 2;

/// Refuse a configuration past the `count` met for a system of `dim`
/// coordinates where they would pass [`MAX_CONFIGURATION_BYTES`] (each
/// counted as eight dense matrices of the state's size): pairs that stick
/// in ever new combinations (twenty plastic dampers on a cantilever) had
/// grown a run past 2 GiB, history off.
fn check_room(count: usize, dim: usize) -> Result<()> {
    let each = 8 * 8 * (2 * dim as u64).pow(2);
    if (count as u64 + 1) * each <= MAX_CONFIGURATION_BYTES {
        return Ok(());
    }
    Err(Error::Inconsistent(format!(
        "the exact flow met {count} configurations of sticking pairs and touching linear \
         contacts, about {} MiB, the most it keeps ({} MiB): its pairs stick in ever new \
         combinations; use method = \"dop853\"",
        (count as u64 * each) >> 20,
        MAX_CONFIGURATION_BYTES >> 20
    )))
}
