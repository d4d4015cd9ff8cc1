//! Compliant contact laws.
//!
//! A law gives the force `F(delta, delta', delta'_minus)` pushing the bodies
//! apart for an indentation `delta > 0`. The force never pulls the bodies
//! together: it is clamped at zero. The contact damper `c1` is not part of the
//! law; it is a linear damper on the relative velocity that acts only while in
//! contact, exactly as in the founding paper's equations of motion.

use crate::error::{finite, non_negative, positive, within, Error, Result};

/// A contact law, generic so that the integration kernels monomorphise over it.
///
/// The laws below are the kernels' building blocks: their methods run in the
/// inner loops on the kernels' own (finite) state and check nothing. Build
/// them through a validated [`Contact`] ([`Contact::visit`]); the checked way
/// to evaluate a law is [`Contact::law_force`].
pub trait ContactLaw: Copy + Send + Sync {
    /// Whether the force depends on the rate latched at the onset (kernels
    /// that need it only for such laws may skip keeping it).
    const USES_APPROACH_RATE: bool = true;
    /// Force in N (>= 0) at indentation `indentation` > 0 (m), indentation
    /// rate `rate` (m/s, > 0 while approaching) and the rate latched at the
    /// onset of this contact `approach_rate` (m/s).
    fn force(&self, indentation: f64, rate: f64, approach_rate: f64) -> f64;
    /// The conservative (elastic) part of the force, N.
    fn elastic_force(&self, indentation: f64) -> f64;
    /// `(force, elastic_force)` together (one square root for the Hertz laws).
    #[inline(always)]
    fn force_and_elastic(&self, indentation: f64, rate: f64, approach_rate: f64) -> (f64, f64) {
        (
            self.force(indentation, rate, approach_rate),
            self.elastic_force(indentation),
        )
    }
    /// Elastic energy stored at `indentation`, J.
    fn potential(&self, indentation: f64) -> f64;
    /// `(F, dF/d delta, dF/d delta')` for Newton iterations (zero slopes where
    /// the force is clamped).
    fn force_derivatives(&self, indentation: f64, rate: f64, approach_rate: f64)
        -> (f64, f64, f64);
}

/// Hertz: `F = k delta^(3/2)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hertz {
    /// K_hz, N/m^1.5.
    pub stiffness: f64,
}

impl ContactLaw for Hertz {
    const USES_APPROACH_RATE: bool = false;
    #[inline(always)]
    fn force(&self, indentation: f64, _rate: f64, _approach_rate: f64) -> f64 {
        self.elastic_force(indentation)
    }
    #[inline(always)]
    fn force_and_elastic(&self, indentation: f64, _rate: f64, _approach_rate: f64) -> (f64, f64) {
        let f = self.elastic_force(indentation);
        (f, f)
    }
    #[inline(always)]
    fn elastic_force(&self, indentation: f64) -> f64 {
        self.stiffness * indentation * indentation.sqrt()
    }
    fn potential(&self, indentation: f64) -> f64 {
        0.4 * self.stiffness * indentation * indentation * indentation.sqrt()
    }
    fn force_derivatives(
        &self,
        indentation: f64,
        _rate: f64,
        _approach_rate: f64,
    ) -> (f64, f64, f64) {
        let root = indentation.sqrt();
        (
            self.stiffness * indentation * root,
            1.5 * self.stiffness * root,
            0.0,
        )
    }
}

/// Hertz with hysteretic damping of the Lankarani-Nikravesh form:
/// `F = k delta^(3/2) (1 + alpha delta' / delta'_minus)`.
///
/// "hyster-hertz" sets `alpha = (3/4)(1 - e^2)` (the founding paper's law,
/// whose rebound is not `e`); "hertz-damped" solves `alpha` from the exact
/// relation `alpha (1 + e) = ln((1 + alpha) / (1 - alpha e))`, so that two
/// bodies alone separate at exactly `e` times their approach speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HysterHertz {
    /// K_hz, N/m^1.5.
    pub stiffness: f64,
    /// `alpha`, dimensionless.
    pub hysteresis: f64,
}

impl HysterHertz {
    /// The founding paper's law: `alpha = (3/4)(1 - e^2)`, for `stiffness` > 0
    /// (N/m^1.5) and `restitution` in (0, 1].
    pub fn new(stiffness: f64, restitution: f64) -> Result<Self> {
        Ok(Self::paper(
            positive("stiffness", stiffness)?,
            checked_restitution(restitution)?,
        ))
    }

    /// The law whose rebound is exactly `restitution` in (0, 1] (see
    /// [`exact_hysteresis`]), for `stiffness` > 0 (N/m^1.5).
    pub fn exact(stiffness: f64, restitution: f64) -> Result<Self> {
        Ok(Self::rebounding_at(
            positive("stiffness", stiffness)?,
            checked_restitution(restitution)?,
        ))
    }

    /// [`HysterHertz::new`] for inputs already checked.
    pub(crate) fn paper(stiffness: f64, restitution: f64) -> Self {
        Self {
            stiffness,
            hysteresis: paper_hysteresis(restitution),
        }
    }

    /// [`HysterHertz::exact`] for inputs already checked.
    pub(crate) fn rebounding_at(stiffness: f64, restitution: f64) -> Self {
        Self {
            stiffness,
            hysteresis: hysteresis_for(restitution),
        }
    }
}

/// The founding paper's `alpha = (3/4)(1 - e^2)`.
fn paper_hysteresis(restitution: f64) -> f64 {
    0.75 * (1.0 - restitution * restitution)
}

/// A coefficient of restitution: in (0, 1].
fn checked_restitution(restitution: f64) -> Result<f64> {
    within("restitution", restitution, 0.0, 1.0, true, "in (0, 1]")
}

/// The `alpha` for which a law `F = K delta^n (1 + alpha delta'/delta'_minus)`
/// acting alone between two bodies gives the rebound/approach speed ratio
/// `restitution` in (0, 1]: the root of
/// `alpha (1 + e) - ln((1 + alpha)/(1 - alpha e)) = 0` in `(0, 1/e)`
/// (0 for `e = 1`).
pub fn exact_hysteresis(restitution: f64) -> Result<f64> {
    Ok(hysteresis_for(checked_restitution(restitution)?))
}

/// [`exact_hysteresis`] for a restitution already checked.
fn hysteresis_for(restitution: f64) -> f64 {
    let e = restitution;
    if e >= 1.0 {
        return 0.0;
    }
    if e > NEAR_ELASTIC {
        // The root is below 0.2: the relation's series, divided by alpha^2.
        return bisect(0.0, 0.5, |a| relation_series(a, e) > 0.0);
    }
    // f > 0 on (0, root) (f ~ alpha^2 (1 - e^2)/2 near 0) and f -> -inf at 1/e;
    // log1p keeps f's sign right for small alpha.
    let f = |a: f64| a * (1.0 + e) - ((a).ln_1p() - (-a * e).ln_1p());
    bisect(0.0, 1.0 / e, |a| f(a) > 0.0)
}

/// Above this restitution the relation is summed as its series
/// ([`relation_series`]): its closed form is a difference of terms of order
/// `alpha` whose value is of order `alpha^3 (1 - e)`, and near e = 1 its sign
/// was round-off (a hertz-damped law at e = 1 - 1e-9 rebounded at 1 - 3e-13).
const NEAR_ELASTIC: f64 = 0.9;

/// The relation `alpha (1 + e) - ln((1 + alpha)/(1 - alpha e))` over
/// `alpha^2`, as its series `sum over n >= 2 of alpha^(n-2) ((-1)^n - e^n) / n`
/// (for `alpha` in [0, 1/2] and `e` in [1/2, 1): each term below `2^-(n-2)`),
/// with `1 - e^n` summed as `(1 - e)(1 + e + ... + e^(n-1))`, free of
/// cancellation near `e = 1`.
fn relation_series(alpha: f64, e: f64) -> f64 {
    let delta = 1.0 - e; // exact for e in [1/2, 1]
    let (mut sum, mut power) = (0.0, 1.0);
    // 1 + e + ... + e^(n-1) and e^n, for n = 2.
    let (mut geometric, mut e_n) = (1.0 + e, e * e);
    for n in 2..64 {
        let c = if n % 2 == 0 {
            delta * geometric
        } else {
            -(1.0 + e_n)
        };
        sum += power * c / f64::from(n);
        power *= alpha;
        geometric += e_n;
        e_n *= e;
    }
    sum
}

/// The point of `(lo, hi)` where `above` turns from true to false, to the
/// last bit.
fn bisect(mut lo: f64, mut hi: f64, above: impl Fn(f64) -> bool) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if above(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The rebound/approach speed ratio that the law with hysteresis `alpha`
/// (finite, >= 0) gives two bodies alone: the root of the same relation in `e`.
pub fn rebound_ratio(hysteresis: f64) -> Result<f64> {
    Ok(ratio_for(non_negative("hysteresis", hysteresis)?))
}

/// [`rebound_ratio`] for a hysteresis already checked.
fn ratio_for(hysteresis: f64) -> f64 {
    let a = hysteresis;
    if a <= 0.0 {
        return 1.0;
    }
    if a < NEAR_ELASTIC_HYSTERESIS {
        // The ratio is above 0.9: the relation's series (see hysteresis_for).
        return bisect(0.5, 1.0, |e| relation_series(a, e) > 0.0);
    }
    let f = |e: f64| a * (1.0 + e) - (a.ln_1p() - (-a * e).ln_1p());
    bisect(0.0, (1.0_f64).min(1.0 / a), |e| f(e) > 0.0)
}

/// Below this hysteresis the rebound ratio is above 0.9 (the hysteresis of
/// [`NEAR_ELASTIC`] is about 0.15), where the relation is summed as its
/// series.
const NEAR_ELASTIC_HYSTERESIS: f64 = 0.1;

/// Below this approach rate (m/s) a contact is a graze and the damping term,
/// which divides by the approach rate, is left out.
const GRAZING_RATE: f64 = 1e-12;

impl HysterHertz {
    /// The approach rate (m/s) below which a contact's damping is taken from
    /// the pressing instead: the speed `sqrt(2 a delta_s)` that the pressing
    /// `a` (m/s^2, > 0 presses the bodies together) gives over the static
    /// indentation `delta_s = (m a / K)^(2/3)` of the effective mass `m`
    /// (kg). The law's damping `alpha delta' / delta'_minus` is fitted to an
    /// indentation made by the approach; where the pressing makes it (a body
    /// set down at rest, or landing slower than this), the indentation rate
    /// is the pressing's and dividing by a slower approach makes the damping
    /// grow without bound (a creep over hundreds of thousands of steps).
    /// With this rate latched, a body resting on the contact oscillates
    /// about `delta_s` with a damping ratio `alpha / (2 sqrt 3)` of its
    /// linearised motion and settles there. 0 when nothing presses.
    pub fn resting_approach_rate(&self, effective_mass: f64, pressing: f64) -> f64 {
        let static_indentation = hertz_static_indentation(self.stiffness, effective_mass, pressing);
        let rate = (2.0 * pressing.max(0.0) * static_indentation).sqrt();
        if rate.is_finite() {
            rate
        } else {
            0.0
        }
    }
}

impl ContactLaw for HysterHertz {
    #[inline(always)]
    fn force(&self, indentation: f64, rate: f64, approach_rate: f64) -> f64 {
        self.force_and_elastic(indentation, rate, approach_rate).0
    }
    #[inline(always)]
    fn force_and_elastic(&self, indentation: f64, rate: f64, approach_rate: f64) -> (f64, f64) {
        let elastic = self.elastic_force(indentation);
        if approach_rate > GRAZING_RATE {
            (
                // The factor on the rate first: the division is off the
                // path from the rate (the state) to the force.
                (elastic * (1.0 + (self.hysteresis / approach_rate) * rate)).max(0.0),
                elastic,
            )
        } else {
            (elastic, elastic)
        }
    }
    #[inline(always)]
    fn elastic_force(&self, indentation: f64) -> f64 {
        self.stiffness * indentation * indentation.sqrt()
    }
    fn potential(&self, indentation: f64) -> f64 {
        0.4 * self.stiffness * indentation * indentation * indentation.sqrt()
    }
    fn force_derivatives(
        &self,
        indentation: f64,
        rate: f64,
        approach_rate: f64,
    ) -> (f64, f64, f64) {
        let root = indentation.sqrt();
        let elastic = self.stiffness * indentation * root;
        let elastic_slope = 1.5 * self.stiffness * root;
        if approach_rate <= GRAZING_RATE {
            return (elastic, elastic_slope, 0.0);
        }
        let factor = 1.0 + (self.hysteresis / approach_rate) * rate;
        if factor <= 0.0 {
            return (0.0, 0.0, 0.0);
        }
        (
            elastic * factor,
            elastic_slope * factor,
            elastic * self.hysteresis / approach_rate,
        )
    }
}

/// Linear spring: `F = k delta`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Linear {
    /// k1, N/m.
    pub stiffness: f64,
}

impl ContactLaw for Linear {
    const USES_APPROACH_RATE: bool = false;
    #[inline(always)]
    fn force(&self, indentation: f64, _rate: f64, _approach_rate: f64) -> f64 {
        self.stiffness * indentation
    }
    #[inline(always)]
    fn elastic_force(&self, indentation: f64) -> f64 {
        self.stiffness * indentation
    }
    fn potential(&self, indentation: f64) -> f64 {
        0.5 * self.stiffness * indentation * indentation
    }
    fn force_derivatives(
        &self,
        indentation: f64,
        _rate: f64,
        _approach_rate: f64,
    ) -> (f64, f64, f64) {
        (self.stiffness * indentation, self.stiffness, 0.0)
    }
}

/// The named contact laws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LawKind {
    Hertz,
    HysterHertz,
    HertzDamped,
    Linear,
}

impl LawKind {
    pub const NAMES: &'static str = "\"hertz\", \"hyster-hertz\", \"hertz-damped\", \"linear\"";

    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "hertz" => Ok(Self::Hertz),
            "hyster-hertz" => Ok(Self::HysterHertz),
            "hertz-damped" => Ok(Self::HertzDamped),
            "linear" => Ok(Self::Linear),
            _ => Err(Error::UnknownChoice {
                field: "law",
                allowed: Self::NAMES,
                value: name.to_string(),
            }),
        }
    }

    /// Whether the law takes a coefficient of restitution.
    pub fn uses_restitution(self) -> bool {
        matches!(self, Self::HysterHertz | Self::HertzDamped)
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Hertz => "hertz",
            Self::HysterHertz => "hyster-hertz",
            Self::HertzDamped => "hertz-damped",
            Self::Linear => "linear",
        }
    }
}

/// A validated contact description: law, its stiffness, restitution (used by
/// "hyster-hertz" only) and the contact damper `c1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    pub law: LawKind,
    /// K_hz in N/m^1.5 for the Hertz laws, k1 in N/m for "linear".
    pub stiffness: f64,
    /// e in (0, 1] for the damped Hertz laws; 1 for the others.
    pub restitution: f64,
    /// c1, N s/m, acting on the relative velocity only while in contact.
    pub damping: f64,
}

impl Contact {
    /// `restitution` must be given for "hyster-hertz" and only for it.
    pub fn new(
        law: LawKind,
        stiffness: f64,
        restitution: Option<f64>,
        damping: f64,
    ) -> Result<Self> {
        let stiffness = positive("stiffness", stiffness)?;
        let damping = non_negative("damping", damping)?;
        let restitution = match (law.uses_restitution(), restitution) {
            (true, Some(e)) => checked_restitution(e)?,
            (true, None) => {
                return Err(Error::Inconsistent(format!(
                    "restitution is required for law {:?} (a number in (0, 1])",
                    law.name()
                )))
            }
            (false, Some(_)) => {
                return Err(Error::Inconsistent(format!(
                "restitution applies only to laws \"hyster-hertz\" and \"hertz-damped\", not {:?}",
                law.name()
            )))
            }
            (false, None) => 1.0,
        };
        Ok(Self {
            law,
            stiffness,
            restitution,
            damping,
        })
    }

    /// The same law through [`Contact::new`]'s checks: a literal's fields
    /// (they are public) in their ranges, a restitution only where the law
    /// takes one.
    pub fn checked(&self) -> Result<Self> {
        let restitution = self.law.uses_restitution().then_some(self.restitution);
        Self::new(self.law, self.stiffness, restitution, self.damping)
    }

    /// The rebound/approach speed ratio two bodies alone get from the law
    /// (without the contact damper): `e` for "hertz-damped", more than `e`
    /// for "hyster-hertz" and never below 0.66296.
    pub fn effective_restitution(&self) -> f64 {
        match self.law {
            LawKind::HysterHertz => ratio_for(paper_hysteresis(self.restitution)),
            _ => self.restitution,
        }
    }

    /// The law's force (N, clamped at zero), without the contact damper, at
    /// `indentation` (m; none at or below 0), indentation `rate` (m/s, > 0
    /// while approaching) and the rate latched at the onset `approach_rate`
    /// (m/s), all finite.
    pub fn law_force(&self, indentation: f64, rate: f64, approach_rate: f64) -> Result<f64> {
        struct Force(f64, f64, f64);
        impl LawVisitor for Force {
            type Output = f64;
            fn visit<L: ContactLaw>(self, law: L) -> f64 {
                if self.0 > 0.0 {
                    law.force(self.0, self.1, self.2)
                } else {
                    0.0
                }
            }
        }
        let indentation = finite("indentation", indentation)?;
        let rate = finite("rate", rate)?;
        let approach_rate = finite("approach_rate", approach_rate)?;
        let force = self.visit(Force(indentation, rate, approach_rate));
        if force.is_finite() {
            Ok(force)
        } else {
            Err(Error::Inconsistent(format!(
                "the {} force at indentation {indentation} m is out of floating-point range: \
                 the indentation or rate is far beyond any contact",
                self.law.name()
            )))
        }
    }

    /// Call `visitor` with the concrete law: the one place where the named
    /// laws become types, so that kernels monomorphise over them.
    pub fn visit<V: LawVisitor>(&self, visitor: V) -> V::Output {
        let k = self.stiffness;
        match self.law {
            LawKind::Hertz => visitor.visit(Hertz { stiffness: k }),
            LawKind::HysterHertz => visitor.visit(HysterHertz::paper(k, self.restitution)),
            LawKind::HertzDamped => visitor.visit(HysterHertz::rebounding_at(k, self.restitution)),
            LawKind::Linear => visitor.visit(Linear { stiffness: k }),
        }
    }
}

/// Any of the laws, chosen at run time: for systems whose pairs each have
/// their own law (one branch per evaluation, which the predictor learns).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AnyLaw {
    Hertz(Hertz),
    HysterHertz(HysterHertz),
    Linear(Linear),
}

impl Contact {
    /// The law as a run-time choice (see [`AnyLaw`]).
    pub fn any_law(&self) -> AnyLaw {
        let k = self.stiffness;
        match self.law {
            LawKind::Hertz => AnyLaw::Hertz(Hertz { stiffness: k }),
            LawKind::HysterHertz => AnyLaw::HysterHertz(HysterHertz::paper(k, self.restitution)),
            LawKind::HertzDamped => {
                AnyLaw::HysterHertz(HysterHertz::rebounding_at(k, self.restitution))
            }
            LawKind::Linear => AnyLaw::Linear(Linear { stiffness: k }),
        }
    }
}

/// A Hertz law's indentation `(m a / K)^(2/3)` (m) under the load of the
/// effective mass `m` (kg) pressed at `a` (m/s^2, > 0 pressing); 0 when
/// nothing presses.
fn hertz_static_indentation(stiffness: f64, effective_mass: f64, pressing: f64) -> f64 {
    let load = effective_mass * pressing;
    if load > 0.0 && load.is_finite() {
        (load / stiffness).powf(2.0 / 3.0)
    } else {
        0.0
    }
}

impl AnyLaw {
    /// Whether the law acts on a pair at `indentation` (m) in its contact
    /// mode: where the pair is indented, and the linear law also on its own
    /// straight line past the wall while the mode is the contact (stepping
    /// by events, not `indented_only`). A step located onto the separation
    /// evaluates its last stages about the wall, some a hair past it: there
    /// the clamped force's kink had cost a high-order method its order
    /// (`dop853`'s rebound off by up to 30 times `rtol`). The straight line
    /// is the same field, smooth, up to the separation the event ends it
    /// at. The Hertz laws' power 1.5 has no such extension.
    #[inline(always)]
    pub fn acts(&self, indentation: f64, indented_only: bool) -> bool {
        indentation > 0.0 || (!indented_only && matches!(self, AnyLaw::Linear(_)))
    }

    /// The force's derivative by the approach rate latched at the onset
    /// (N per m/s) at `indentation` (m), its `rate` (m/s) and
    /// that `approach_rate` (m/s): `-K delta^1.5 alpha delta' / v0^2` for the
    /// hysteretic laws while their factor is positive, else 0.
    pub fn force_by_approach_rate(&self, indentation: f64, rate: f64, approach_rate: f64) -> f64 {
        match self {
            AnyLaw::HysterHertz(law) if indentation > 0.0 && approach_rate > GRAZING_RATE => {
                let ratio = law.hysteresis / approach_rate;
                if 1.0 + ratio * rate <= 0.0 {
                    return 0.0;
                }
                -law.elastic_force(indentation) * ratio * rate / approach_rate
            }
            _ => 0.0,
        }
    }

    /// The indentation (m) at which the law's elastic force holds the
    /// effective mass `effective_mass` (kg) pressed at `pressing` (m/s^2, > 0
    /// pressing the bodies together); 0 when nothing presses. The scale of a
    /// contact at rest: a landing that would rise less than its round-off is
    /// no impact.
    pub fn static_indentation(&self, effective_mass: f64, pressing: f64) -> f64 {
        match self {
            AnyLaw::Hertz(Hertz { stiffness })
            | AnyLaw::HysterHertz(HysterHertz { stiffness, .. }) => {
                hertz_static_indentation(*stiffness, effective_mass, pressing)
            }
            AnyLaw::Linear(Linear { stiffness }) => {
                let load = effective_mass * pressing;
                if load > 0.0 && load.is_finite() {
                    load / stiffness
                } else {
                    0.0
                }
            }
        }
    }

    /// How long (s) the law's elastic force holds two free bodies of
    /// effective mass `effective_mass` (kg) that meet at `approach` (m/s):
    /// `pi sqrt(m / k)` for the linear law, `2.9433 delta_max / approach`
    /// for a Hertz law (Goldsmith's, `delta_max = (5 m v^2 / 4 k)^(2/5)`);
    /// infinite for bodies that do not approach. A damped law's contact is
    /// of the same scale: what a fixed step has to resolve.
    pub fn impact_duration(&self, effective_mass: f64, approach: f64) -> f64 {
        if approach.is_nan() || approach <= 0.0 {
            return f64::INFINITY;
        }
        match self {
            AnyLaw::Hertz(Hertz { stiffness })
            | AnyLaw::HysterHertz(HysterHertz { stiffness, .. }) => {
                use crate::model::closed_forms::HERTZ_DURATION_CONSTANT;
                // The deepest indentation over the approach, (5 m v^2 / 4 k)^0.4
                // / v, with no square to underflow: a pair set touching at rest
                // (3e-162 m/s) had lasted 0 s and been refused as too short.
                let scale = (5.0 * effective_mass / (4.0 * stiffness)).powf(0.4);
                HERTZ_DURATION_CONSTANT * scale * approach.powf(-0.2)
            }
            AnyLaw::Linear(Linear { stiffness }) => {
                std::f64::consts::PI * (effective_mass / stiffness).sqrt()
            }
        }
    }

    /// The rate latched at the onset of a contact that approaches at
    /// `approach` (m/s) with `pressing` (m/s^2, > 0 pressing the bodies
    /// together) on the effective mass `effective_mass` (kg): the approach,
    /// or for a law whose damping divides by it, at least
    /// [`HysterHertz::resting_approach_rate`].
    pub fn latched_approach_rate(&self, approach: f64, effective_mass: f64, pressing: f64) -> f64 {
        match self {
            AnyLaw::HysterHertz(law) => {
                approach.max(law.resting_approach_rate(effective_mass, pressing))
            }
            _ => approach,
        }
    }
}

macro_rules! delegate {
    ($self:ident, $law:ident => $call:expr) => {
        match $self {
            AnyLaw::Hertz($law) => $call,
            AnyLaw::HysterHertz($law) => $call,
            AnyLaw::Linear($law) => $call,
        }
    };
}

impl ContactLaw for AnyLaw {
    #[inline(always)]
    fn force(&self, indentation: f64, rate: f64, approach_rate: f64) -> f64 {
        delegate!(self, law => law.force(indentation, rate, approach_rate))
    }
    #[inline(always)]
    fn elastic_force(&self, indentation: f64) -> f64 {
        delegate!(self, law => law.elastic_force(indentation))
    }
    #[inline(always)]
    fn force_and_elastic(&self, indentation: f64, rate: f64, approach_rate: f64) -> (f64, f64) {
        delegate!(self, law => law.force_and_elastic(indentation, rate, approach_rate))
    }
    fn potential(&self, indentation: f64) -> f64 {
        delegate!(self, law => law.potential(indentation))
    }
    fn force_derivatives(
        &self,
        indentation: f64,
        rate: f64,
        approach_rate: f64,
    ) -> (f64, f64, f64) {
        delegate!(self, law => law.force_derivatives(indentation, rate, approach_rate))
    }
}

/// Something to do with a concrete contact law (see [`Contact::visit`]).
pub trait LawVisitor {
    type Output;
    fn visit<L: ContactLaw>(self, law: L) -> Self::Output;
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    const NON_FINITE: [f64; 3] = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY];

    /// The field an invalid-parameter error names (panics on anything else).
    pub(crate) fn field<T: std::fmt::Debug>(result: Result<T>) -> &'static str {
        match result {
            Err(Error::InvalidParameter { field, .. }) => field,
            other => panic!("expected an invalid parameter, got {other:?}"),
        }
    }

    /// Near e = 1 the hysteresis follows the relation's expansion,
    /// `alpha = 3 (1 - e^2) / (2 (1 + e^3))` to first order in `1 - e` (from
    /// `alpha^2 (1 - e^2)/2 - alpha^3 (1 + e^3)/3 + O(alpha^4) = 0`), and the
    /// rebound ratio of that hysteresis is e again. Summed in closed form, the
    /// relation's sign was round-off there: e = 1 - 1e-9 gave a law that
    /// rebounded at 1 - 3e-13.
    #[test]
    fn near_elastic_hysteresis_follows_the_relations_expansion() {
        crate::testing::timeout(10, || {
            for gap in [1e-4, 1e-6, 1e-8, 1e-9, 1e-12, 1e-15] {
                let e = 1.0 - gap;
                let delta = 1.0 - e; // (exact)
                let alpha = exact_hysteresis(e).unwrap();
                let first = 3.0 * (1.0 - e * e) / (2.0 * (1.0 + e * e * e));
                // The next order is alpha's own size (about 1.5 delta) relative.
                assert!(
                    (alpha / first - 1.0).abs() < 3.0 * delta,
                    "{delta}: {alpha} vs {first}"
                );
                let back = rebound_ratio(alpha).unwrap();
                // To the doubles' spacing near 1.
                assert!(
                    ((1.0 - back) - delta).abs() < 4.0 * f64::EPSILON,
                    "{delta}: {back}"
                );
            }
            // Either side of the switch to the series, one relation.
            let (below, above) = (
                exact_hysteresis(0.9).unwrap(),
                exact_hysteresis(0.9 + 1e-12),
            );
            assert!((below - above.unwrap()).abs() < 1e-10);
        });
    }

    #[test]
    fn law_force_refuses_non_finite_arguments() {
        crate::testing::timeout(60, || {
            let contact = Contact::new(LawKind::HertzDamped, 3000.0, Some(0.5), 0.01).unwrap();
            for bad in NON_FINITE {
                assert_eq!(field(contact.law_force(bad, 0.0, 1.0)), "indentation");
                assert_eq!(field(contact.law_force(1e-3, bad, 1.0)), "rate");
                assert_eq!(field(contact.law_force(1e-3, 0.0, bad)), "approach_rate");
            }
            // A force beyond floating point is an error, not inf.
            let err = contact.law_force(1e300, 0.0, 1.0).unwrap_err();
            assert!(
                err.to_string().contains("out of floating-point range"),
                "{err}"
            );
            // Finite arguments still give the law: 3000 (1e-4)^1.5 N with no rate.
            let force = contact.law_force(1e-4, 0.0, 1.0).unwrap();
            assert!((force - 3000.0 * 1e-6).abs() < 1e-18, "{force}");
        });
    }

    #[test]
    fn a_resting_contact_takes_its_damping_from_the_pressing() {
        crate::testing::timeout(10, || {
            // 0.2 kg under 9.81 m/s^2 on K = 1e7 N/m^1.5: delta_s = (m g /
            // K)^(2/3), and the rate latched is sqrt(2 g delta_s).
            let law = HysterHertz::exact(1e7, 0.5).unwrap();
            let static_indentation = (0.2_f64 * 9.81 / 1e7).powf(2.0 / 3.0);
            let floor = (2.0 * 9.81 * static_indentation).sqrt();
            let rate = law.resting_approach_rate(0.2, 9.81);
            assert!((rate - floor).abs() <= 1e-15 * floor, "{rate} vs {floor}");
            let any = AnyLaw::HysterHertz(law);
            assert_eq!(any.latched_approach_rate(1e-65, 0.2, 9.81), rate);
            // An impact faster than it keeps its own approach; nothing
            // pressing, or a law without damping, latches the approach.
            assert_eq!(any.latched_approach_rate(2.0, 0.2, 9.81), 2.0);
            assert_eq!(any.latched_approach_rate(1e-65, 0.2, -9.81), 1e-65);
            let elastic = AnyLaw::Hertz(Hertz { stiffness: 1e7 });
            assert_eq!(elastic.latched_approach_rate(1e-65, 0.2, 9.81), 1e-65);
        });
    }

    #[test]
    fn helpers_refuse_values_outside_their_range() {
        crate::testing::timeout(60, || {
            for bad in NON_FINITE.into_iter().chain([0.0, 1.5, -0.5]) {
                assert_eq!(field(exact_hysteresis(bad)), "restitution");
                assert_eq!(field(HysterHertz::new(1.0, bad)), "restitution");
                assert_eq!(field(HysterHertz::exact(1.0, bad)), "restitution");
                assert_eq!(field(HysterHertz::new(-bad.abs(), 0.5)), "stiffness");
            }
            for bad in NON_FINITE.into_iter().chain([-1e-3]) {
                assert_eq!(field(rebound_ratio(bad)), "hysteresis");
            }
            // The checked helpers agree with the relation they solve:
            // alpha (1 + e) = ln((1 + alpha) / (1 - alpha e)).
            let alpha = exact_hysteresis(0.5).unwrap();
            let residual = alpha * 1.5 - ((1.0 + alpha) / (1.0 - 0.5 * alpha)).ln();
            assert!(residual.abs() < 1e-14, "{residual}");
            assert!((rebound_ratio(alpha).unwrap() - 0.5).abs() < 1e-14);
        });
    }
}
