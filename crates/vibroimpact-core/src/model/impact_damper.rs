//! The impact damper: a main mass on a spring and damper carrying an
//! enclosure in which a loose impact mass moves with a clearance on each side.
//! A preset of the general system ([`ImpactDamper::spec`]): an oscillator
//! with one damper of equal clearances at its coordinate, run by the general
//! kernel like any other.

use crate::error::{finite, non_negative, positive, Error, Result};
use crate::model::assembly::{initial_state, Assembly, Damper, PairLaw, SystemSpec};
use crate::model::contact::Contact;
use crate::model::structure::Structure;

/// Parameters of the two-mass impact damper (SI units).
///
/// The main structure (one mode: `main_mass` M, `stiffness` K, `damping` C,
/// displacement `w`) carries an enclosure; the impact mass `impact_mass` m
/// (displacement `y`) moves freely while `|y - w| < clearance`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactDamper {
    /// M, kg (> 0).
    pub main_mass: f64,
    /// K, N/m (>= 0).
    pub stiffness: f64,
    /// C, N s/m (>= 0).
    pub damping: f64,
    /// m, kg (> 0).
    pub impact_mass: f64,
    /// d, m (>= 0), on each side of the impact mass.
    pub clearance: f64,
}

impl ImpactDamper {
    /// Validated constructor: every field must be finite, masses positive,
    /// stiffness, damping and clearance non-negative.
    pub fn new(
        main_mass: f64,
        stiffness: f64,
        damping: f64,
        impact_mass: f64,
        clearance: f64,
    ) -> Result<Self> {
        Ok(Self {
            main_mass: positive("main_mass", main_mass)?,
            stiffness: non_negative("stiffness", stiffness)?,
            damping: non_negative("damping", damping)?,
            impact_mass: positive("impact_mass", impact_mass)?,
            clearance: non_negative("clearance", clearance)?,
        })
    }

    /// Effective mass of the colliding pair, `m M / (m + M)`, kg.
    pub fn effective_mass(&self) -> f64 {
        self.main_mass * self.impact_mass / (self.main_mass + self.impact_mass)
    }

    /// The same system as a general one, as a 0.2 scenario writes it: a
    /// `[structure] kind = "oscillator"` of mass M, stiffness K and damping
    /// C, and one `[[damper]]` of mass m at its coordinate (point 0) with
    /// both clearances d and `contact`'s law and contact damper c1. Unforced,
    /// no gravity.
    pub fn spec(&self, contact: &Contact) -> Result<SystemSpec> {
        let damper = Damper {
            mass: self.impact_mass,
            at: 0.0,
            lower_clearance: self.clearance,
            upper_clearance: self.clearance,
            law: PairLaw::Compliant(*contact),
        };
        let structure = Structure::oscillator(self.main_mass, self.stiffness, self.damping)?;
        Ok(SystemSpec::of(structure, vec![damper]))
    }

    /// [`Self::spec`], assembled for the kernel.
    pub fn assembly(&self, contact: &Contact) -> Result<Assembly> {
        Assembly::new(&self.spec(contact)?)
    }
}

/// Displacements (m) and velocities (m/s) of both masses.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct State {
    /// w, m.
    pub main_displacement: f64,
    /// w', m/s.
    pub main_velocity: f64,
    /// y, m.
    pub impact_displacement: f64,
    /// y', m/s.
    pub impact_velocity: f64,
}

impl State {
    /// Validated constructor: all four values must be finite.
    pub fn new(
        main_displacement: f64,
        main_velocity: f64,
        impact_displacement: f64,
        impact_velocity: f64,
    ) -> Result<Self> {
        Ok(Self {
            main_displacement: finite("main_displacement", main_displacement)?,
            main_velocity: finite("main_velocity", main_velocity)?,
            impact_displacement: finite("impact_displacement", impact_displacement)?,
            impact_velocity: finite("impact_velocity", impact_velocity)?,
        })
    }

    /// Relative displacement `y - w`, m.
    #[inline(always)]
    pub fn relative_displacement(&self) -> f64 {
        self.impact_displacement - self.main_displacement
    }

    /// Relative velocity `y' - w'`, m/s.
    #[inline(always)]
    pub fn relative_velocity(&self) -> f64 {
        self.impact_velocity - self.main_velocity
    }

    /// Refuses a start with the impact mass inside a wall beyond round-off
    /// (`|y - w| > d`), naming by how much and what is allowed.
    pub fn check_apart(&self, clearance: f64) -> Result<()> {
        let u = self.relative_displacement();
        let indentation = u.abs() - clearance;
        let round_off = 4.0
            * f64::EPSILON
            * (self.main_displacement.abs() + self.impact_displacement.abs() + clearance);
        if indentation > round_off {
            return Err(Error::Inconsistent(format!(
                "the initial state starts the impact mass {indentation:.6e} m inside the wall: \
                 |impact_displacement - main_displacement| = {:e} m is more than the clearance {:e} m; \
                 start with |impact_displacement - main_displacement| <= clearance (at the wall at most)",
                u.abs(),
                clearance
            )));
        }
        Ok(())
    }

    /// The state vector of the preset's assembly ([`ImpactDamper::assembly`]):
    /// the main mass is the structure's coordinate, the impact mass the
    /// damper's (both relative to the fixed base, as here). A start with the
    /// bodies interpenetrating is refused.
    pub fn vector(&self, system: &Assembly) -> Result<Vec<f64>> {
        initial_state(
            system,
            &[self.main_displacement],
            &[self.main_velocity],
            &[self.impact_displacement],
            &[self.impact_velocity],
        )
    }

    /// The state a run of the preset ended in, from its `x` then `v`
    /// (`[w, y, w', y']`).
    pub fn of_vector(final_state: &[f64]) -> Self {
        Self {
            main_displacement: final_state[0],
            impact_displacement: final_state[1],
            main_velocity: final_state[2],
            impact_velocity: final_state[3],
        }
    }

    #[inline(always)]
    pub(crate) fn is_finite(&self) -> bool {
        (self.main_displacement
            + self.main_velocity
            + self.impact_displacement
            + self.impact_velocity)
            .is_finite()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::events::{ContactTiming, RunOptions, Stepping, SystemSolution};
    use crate::methods::registry::{AnyStepper, Options};
    use crate::model::closed_forms::linear_contact_duration;
    use crate::model::contact::LawKind;

    fn options(dt: Option<f64>, t_end: f64) -> RunOptions {
        RunOptions {
            dt,
            t_end,
            every: 1,
            keep_history: true,
            max_steps: 10_000_000,
            max_rows: 10_000_000,
            energy_tolerance: 0.05,
            reduce: Default::default(),
        }
    }

    fn run(
        system: &Assembly,
        y0: &[f64],
        (method, stepping): (&str, Stepping),
        dt: Option<f64>,
        t_end: f64,
    ) -> SystemSolution {
        let mut stepper = AnyStepper::new(
            system,
            method,
            &Options {
                rtol: 1e-12,
                atol: 1e-15,
                ..Options::default()
            },
        )
        .unwrap();
        stepper
            .integrate_stepped(system, y0, &options(dt, t_end), stepping, &mut || false)
            .unwrap()
    }

    #[test]
    fn the_preset_is_the_oscillator_with_one_damper_of_a_0_2_scenario() {
        crate::testing::timeout(30, || {
            let damper = ImpactDamper::new(1.0, 1.0, 0.01, 0.25, 0.01).unwrap();
            let contact = Contact::new(LawKind::Hertz, 3000.0, None, 0.01).unwrap();
            // As a 0.2 scenario writes it: [structure] kind = "oscillator" and
            // one [[damper]] at = 0 with lower = upper clearance.
            let written = SystemSpec {
                structure: Structure::oscillator(1.0, 1.0, 0.01).unwrap(),
                dampers: vec![Damper {
                    mass: 0.25,
                    at: 0.0,
                    lower_clearance: 0.01,
                    upper_clearance: 0.01,
                    law: PairLaw::Compliant(contact),
                }],
                collisions: vec![],
                frictions: vec![],
                stops: vec![],
                gravity: 0.0,
                excitations: vec![],
                points: vec![],
                moments: vec![],
            };
            let preset = damper.assembly(&contact).unwrap();
            let general = Assembly::new(&written).unwrap();
            assert_eq!(preset, general);
            let start = State::new(0.0, 0.0, 0.01, 0.1).unwrap();
            // [initial] structure_displacement = [w], ... damper_velocity = [y'].
            let y0 = initial_state(&general, &[0.0], &[0.0], &[0.01], &[0.1]).unwrap();
            assert_eq!(start.vector(&preset).unwrap(), y0);
            let fixed = |contact_timing| Stepping::Fixed { contact_timing };
            for (method, dt) in [
                (("rk4", Stepping::Events), Some(1e-5)),
                (("dop853", Stepping::Events), None),
                (("rk4", fixed(ContactTiming::Located)), Some(1e-5)),
                (("newmark", fixed(ContactTiming::StepCount)), Some(1e-5)),
            ] {
                let (a, b) = (
                    run(&preset, &y0, method, dt, 0.3),
                    run(&general, &y0, method, dt, 0.3),
                );
                assert_eq!(a, b, "{method:?}");
                assert!(!a.contacts.is_empty(), "{method:?}");
            }
        });
    }

    #[test]
    fn the_preset_s_state_maps_each_mass_to_its_coordinate() {
        crate::testing::timeout(30, || {
            // Two free bodies (K = C = 0) meeting on a linear spring without
            // damper: momentum m y' + M w' is conserved, the contact lasts
            // pi sqrt(m_eff / k1) and the speeds swap as an elastic collision's.
            let damper = ImpactDamper::new(1.0, 0.0, 0.0, 0.25, 0.01).unwrap();
            let contact = Contact::new(LawKind::Linear, 1e4, None, 0.0).unwrap();
            let system = damper.assembly(&contact).unwrap();
            let start = State::new(0.0, -0.02, 0.01, 0.1).unwrap();
            // Apart again after 0.014 s, at the other wall after 0.18 s.
            let sol = run(
                &system,
                &start.vector(&system).unwrap(),
                ("dop853", Stepping::Events),
                None,
                0.1,
            );
            let end = State::of_vector(&sol.final_state);
            let momentum = |s: &State| s.main_velocity + 0.25 * s.impact_velocity;
            assert!((momentum(&end) - momentum(&start)).abs() < 1e-12);
            let c = sol.contacts[0];
            assert_eq!(sol.contacts.len(), 1);
            assert!((c.onset - 0.0).abs() < 1e-12, "{c:?}");
            assert!((c.approach_speed - 0.12).abs() < 1e-12, "{c:?}");
            assert!((c.rebound_speed - 0.12).abs() < 1e-9, "{c:?}");
            let duration = linear_contact_duration(0.25, 1.0, 1e4, 0.0).unwrap();
            assert!(
                (c.duration / duration - 1.0).abs() < 1e-9,
                "{c:?} {duration}"
            );
            // Elastic: the relative velocity reversed, the centre of mass unmoved in speed.
            assert!((end.relative_velocity() + 0.12).abs() < 1e-9, "{end:?}");
        });
    }
}
