//! The run defaults of each kind of model, declared once: the two-mass impact
//! damper (a 0.1 scenario, the two-mass `simulate`) runs the founding paper's
//! lagged Newmark in its fixed steps; any other system (a 0.2 scenario, a
//! `vibroimpact.System`) runs RK4 with its steps cut at every event. The
//! difference is deliberate: the paper's default is the paper's method.

use super::table::method;
use crate::error::Result;

/// The kind of model a run is of, as far as its defaults go.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelKind {
    /// The two-mass impact damper of the founding paper.
    TwoMass,
    /// Any system of a structure with dampers, stops and excitations.
    System,
}

/// What a run of a model kind takes where its settings leave a choice out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunDefaults {
    /// The kind's name, as the binding exports it.
    pub name: &'static str,
    pub method: &'static str,
    /// The methods that step in fixed steps unless told otherwise; every
    /// other method steps by events.
    pub fixed_by_default: &'static [&'static str],
    /// How a fixed-step run times its contacts unless told otherwise.
    pub contact_timing: &'static str,
}

/// The two-mass impact damper's: the paper's Newmark and RK4 in the paper's
/// fixed steps, the paper's Newmark by default.
pub const TWO_MASS: RunDefaults = RunDefaults {
    name: "two-mass",
    method: "newmark",
    fixed_by_default: &["newmark", "rk4"],
    contact_timing: "located",
};

/// Any other system's: RK4, every method stepping by events.
pub const SYSTEM: RunDefaults = RunDefaults {
    name: "system",
    method: "rk4",
    fixed_by_default: &[],
    contact_timing: "located",
};

/// Every kind's defaults, in the order the binding exports them.
pub const RUN_DEFAULTS: [RunDefaults; 2] = [TWO_MASS, SYSTEM];

impl ModelKind {
    /// The kind's defaults.
    pub fn defaults(self) -> &'static RunDefaults {
        match self {
            Self::TwoMass => &TWO_MASS,
            Self::System => &SYSTEM,
        }
    }
}

impl RunDefaults {
    /// The stepping ("fixed" or "events") of `method` where none is given;
    /// an unknown method refused with the registry's names.
    pub fn stepping(&self, method_name: &str) -> Result<&'static str> {
        let spec = method(method_name)?;
        Ok(if self.fixed_by_default.contains(&spec.name) {
            "fixed"
        } else {
            "events"
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::registry::METHOD_SPECS;

    #[test]
    fn each_kind_s_defaults_are_methods_and_steppings_of_the_table() {
        crate::testing::timeout(10, || {
            for defaults in RUN_DEFAULTS {
                assert!(method(defaults.method).is_ok(), "{defaults:?}");
                for name in defaults.fixed_by_default {
                    let spec = method(name).unwrap();
                    assert!(spec.steppings.contains(&"fixed"), "{name}");
                }
            }
            // The paper's defaults: its Newmark, its two methods in fixed
            // steps; every other system's: RK4, by events.
            assert_eq!(ModelKind::TwoMass.defaults().method, "newmark");
            assert_eq!(ModelKind::System.defaults().method, "rk4");
            for spec in METHOD_SPECS {
                let two_mass = TWO_MASS.stepping(spec.name).unwrap();
                let paper = matches!(spec.name, "newmark" | "rk4");
                assert_eq!(two_mass, if paper { "fixed" } else { "events" });
                assert_eq!(SYSTEM.stepping(spec.name).unwrap(), "events");
            }
            assert!(TWO_MASS.stepping("euler").is_err());
        });
    }
}
