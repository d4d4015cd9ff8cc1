//! The structure of a 0.2 system: generalised coordinates `q` with mass,
//! stiffness and damping matrices (`M q'' + C q' + K q = f`), the points where
//! dampers, stops and forces attach (each a row `h` with the point's
//! displacement `h . q`), and the influence vector `r` of a rigid base motion
//! (the structure's coordinates move by `r` per metre of base displacement).
//!
//! Kinds: one mass on a spring and damper; any symmetric matrices; and a
//! cantilever in its modal coordinates, whose points are its mode shapes at a
//! position along the beam (so a tip force enters each mode with the tip
//! value of its shape, 2 in magnitude, by construction).

use crate::error::{non_negative, positive, within, Error, Result};
use crate::model::beam::CantileverShape;
use crate::numerics::linalg;

/// Most degrees of freedom a structure may have: its matrices are dense and
/// every step multiplies them, so a larger model belongs in modal coordinates.
pub const MAX_DOFS: usize = 200;

#[derive(Debug, Clone, PartialEq)]
enum Points {
    /// A point is a coordinate index.
    Indices,
    /// A point is a position along a cantilever (m from the clamp); its row
    /// is the mode shapes there.
    Beam {
        length: f64,
        shapes: Vec<CantileverShape>,
    },
}

/// The inputs a structure was made from: kept so that a study can make it
/// again with one of them changed, the same bit for bit as a scenario
/// written with that value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Recipe {
    Oscillator {
        mass: f64,
        stiffness: f64,
        damping: f64,
    },
    /// Matrices given as they are (not remade).
    Matrices,
    Cantilever {
        length: f64,
        youngs_modulus: f64,
        second_moment: f64,
        mass_per_length: f64,
        modes: u32,
        damping_ratio: f64,
    },
}

impl Recipe {
    /// The `kind` of the scenario's `[structure]`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Oscillator { .. } => "oscillator",
            Self::Matrices => "matrices",
            Self::Cantilever { .. } => "cantilever",
        }
    }

    /// The keys a study can set (see [`Recipe::input`]), for error messages.
    pub fn keys(&self) -> &'static str {
        match self {
            Self::Oscillator { .. } => "mass, stiffness, damping",
            Self::Matrices => "",
            Self::Cantilever { .. } => {
                "length, youngs_modulus, second_moment, mass_per_length, damping_ratio"
            }
        }
    }

    /// The input named `key` (one of [`Recipe::keys`]), to set.
    pub fn input(&mut self, key: &str) -> Option<&mut f64> {
        match (self, key) {
            (Self::Oscillator { mass, .. }, "mass") => Some(mass),
            (Self::Oscillator { stiffness, .. }, "stiffness") => Some(stiffness),
            (Self::Oscillator { damping, .. }, "damping") => Some(damping),
            (Self::Cantilever { length, .. }, "length") => Some(length),
            (Self::Cantilever { youngs_modulus, .. }, "youngs_modulus") => Some(youngs_modulus),
            (Self::Cantilever { second_moment, .. }, "second_moment") => Some(second_moment),
            (
                Self::Cantilever {
                    mass_per_length, ..
                },
                "mass_per_length",
            ) => Some(mass_per_length),
            (Self::Cantilever { damping_ratio, .. }, "damping_ratio") => Some(damping_ratio),
            _ => None,
        }
    }

    /// The structure (validated as its constructor validates it).
    pub fn build(&self) -> Result<Structure> {
        match *self {
            Self::Oscillator {
                mass,
                stiffness,
                damping,
            } => Structure::oscillator(mass, stiffness, damping),
            Self::Matrices => Err(Error::Inconsistent(
                "a structure of kind \"matrices\" is not made from inputs a study can vary".into(),
            )),
            Self::Cantilever {
                length,
                youngs_modulus,
                second_moment,
                mass_per_length,
                modes,
                damping_ratio,
            } => Structure::cantilever(
                length,
                youngs_modulus,
                second_moment,
                mass_per_length,
                modes,
                damping_ratio,
            ),
        }
    }
}

/// A linear structure (SI units: kg, N/m, N s/m), validated.
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    dofs: usize,
    /// Row-major `dofs x dofs`.
    mass: Vec<f64>,
    stiffness: Vec<f64>,
    damping: Vec<f64>,
    influence: Vec<f64>,
    points: Points,
    recipe: Recipe,
}

impl Structure {
    /// One mass (kg) on a spring (N/m) and a damper (N s/m).
    pub fn oscillator(mass: f64, stiffness: f64, damping: f64) -> Result<Self> {
        Ok(Self {
            dofs: 1,
            mass: vec![positive("mass", mass)?],
            stiffness: vec![non_negative("stiffness", stiffness)?],
            damping: vec![non_negative("damping", damping)?],
            influence: vec![1.0],
            points: Points::Indices,
            recipe: Recipe::Oscillator {
                mass,
                stiffness,
                damping,
            },
        })
    }

    /// Any `n x n` matrices, given as rows: `mass` symmetric positive
    /// definite, `stiffness` and `damping` symmetric positive semi-definite
    /// (kg, N/m, N s/m). Every coordinate moves with the base (`r = 1`).
    pub fn matrices(
        mass: &[Vec<f64>],
        stiffness: &[Vec<f64>],
        damping: &[Vec<f64>],
    ) -> Result<Self> {
        let n = mass.len();
        if n == 0 || n > MAX_DOFS {
            return Err(Error::Inconsistent(format!(
                "structure.mass must be an n x n matrix with 1 <= n <= {MAX_DOFS}, got {n} rows"
            )));
        }
        let mass = square("mass", mass, n)?;
        let stiffness = square("stiffness", stiffness, n)?;
        let damping = square("damping", damping, n)?;
        if linalg::cholesky(&mass, n).is_none() {
            return Err(Error::Inconsistent(why_not_positive_definite(&mass, n)));
        }
        for (key, matrix) in [("stiffness", &stiffness), ("damping", &damping)] {
            let values = linalg::symmetric_eigenvalues(matrix, n);
            let lowest = values[0];
            if lowest < -1e-12 * linalg::max_abs(&values) {
                return Err(Error::Inconsistent(format!(
                    "structure.{key} must be positive semi-definite (no mode that gains energy): \
                     its lowest eigenvalue is {lowest:.6e}"
                )));
            }
        }
        Ok(Self {
            dofs: n,
            mass,
            stiffness,
            damping,
            influence: vec![1.0; n],
            points: Points::Indices,
            recipe: Recipe::Matrices,
        })
    }

    /// An Euler-Bernoulli cantilever (`length` m, `youngs_modulus` Pa,
    /// `second_moment` m^4, `mass_per_length` kg/m) in the coordinates of its
    /// first `modes` modes, each with the modal `damping_ratio`. With the
    /// shapes normalised to `int_0^L phi_i^2 dx = L` (so `|phi_i(L)| = 2`):
    /// `M = rho A L I`, `K_ii = (b_i L)^4 E I / L^3`, `C_ii = 2 zeta omega_i
    /// M_ii`, `omega_i = (b_i L)^2 sqrt(E I / (rho A L^4))`, and a base motion
    /// enters mode `i` with `r_i = (1/L) int_0^L phi_i dx = 2 sigma_i / (b_i L)`.
    pub fn cantilever(
        length: f64,
        youngs_modulus: f64,
        second_moment: f64,
        mass_per_length: f64,
        modes: u32,
        damping_ratio: f64,
    ) -> Result<Self> {
        let length = positive("length", length)?;
        let flexural =
            positive("youngs_modulus", youngs_modulus)? * positive("second_moment", second_moment)?;
        let mass_per_length = positive("mass_per_length", mass_per_length)?;
        let zeta = within("damping_ratio", damping_ratio, 0.0, 1.0, false, "in [0, 1]")?;
        let n = modes as usize;
        if n == 0 || n > MAX_DOFS {
            return Err(Error::Inconsistent(format!(
                "structure.modes must be a whole number in [1, {MAX_DOFS}], got {modes}"
            )));
        }
        let shapes = (1..=modes)
            .map(CantileverShape::new)
            .collect::<Result<Vec<_>>>()?;
        let modal_mass = mass_per_length * length;
        let mut mass = vec![0.0; n * n];
        let mut stiffness = vec![0.0; n * n];
        let mut damping = vec![0.0; n * n];
        let mut influence = vec![0.0; n];
        for (i, shape) in shapes.iter().enumerate() {
            let b = shape.beta_l;
            let k = b.powi(4) * flexural / length.powi(3);
            let omega = (k / modal_mass).sqrt();
            mass[i * n + i] = modal_mass;
            stiffness[i * n + i] = k;
            damping[i * n + i] = 2.0 * zeta * omega * modal_mass;
            // sigma = (sinh b - sin b) / (cosh b + cos b), from e^-b (no overflow).
            let e = (-b).exp();
            let sigma = (1.0 - e * (2.0 * b.sin() + e)) / (1.0 + e * (2.0 * b.cos() + e));
            influence[i] = 2.0 * sigma / b;
        }
        Ok(Self {
            dofs: n,
            mass,
            stiffness,
            damping,
            influence,
            points: Points::Beam { length, shapes },
            recipe: Recipe::Cantilever {
                length,
                youngs_modulus,
                second_moment,
                mass_per_length,
                modes,
                damping_ratio,
            },
        })
    }

    /// Undamped natural angular frequencies (rad/s), ascending: the square
    /// roots of the eigenvalues of `L^-1 K L^-T`, with `M = L L^T`.
    pub fn natural_frequencies(&self) -> Vec<f64> {
        let n = self.dofs;
        let l = linalg::cholesky(&self.mass, n).expect("checked positive definite");
        let inverse = linalg::inverse_lower(&l, n);
        // B = L^-1 K, then A = B L^-T.
        let mut b = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                b[i * n + j] = (0..=i)
                    .map(|p| inverse[i * n + p] * self.stiffness[p * n + j])
                    .sum();
            }
        }
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = (0..=j).map(|q| b[i * n + q] * inverse[j * n + q]).sum();
            }
        }
        linalg::symmetric_eigenvalues(&a, n)
            .into_iter()
            .map(|v| v.max(0.0).sqrt())
            .collect()
    }

    /// The inputs it was made from.
    pub fn recipe(&self) -> Recipe {
        self.recipe
    }

    /// Number of generalised coordinates.
    pub fn dofs(&self) -> usize {
        self.dofs
    }

    /// Mass matrix, row-major, kg.
    pub fn mass(&self) -> &[f64] {
        &self.mass
    }

    /// Stiffness matrix, row-major, N/m.
    pub fn stiffness(&self) -> &[f64] {
        &self.stiffness
    }

    /// Damping matrix, row-major, N s/m.
    pub fn damping(&self) -> &[f64] {
        &self.damping
    }

    /// Influence vector of a rigid base displacement.
    pub fn influence(&self) -> &[f64] {
        &self.influence
    }

    /// The row `h` of the point `at` (a coordinate index for the oscillator
    /// and matrices), whose displacement is `h . q`, m. `key` names the input
    /// in the error (for example `"damper 1 at"`).
    pub fn point(&self, key: &str, at: f64) -> Result<Vec<f64>> {
        match self.points {
            Points::Indices => {
                let index = at as usize;
                if !(at.is_finite() && at >= 0.0 && at.fract() == 0.0 && index < self.dofs) {
                    return Err(Error::Inconsistent(format!(
                        "{key} must be a coordinate index, a whole number in [0, {}], got {at}",
                        self.dofs - 1
                    )));
                }
                let mut row = vec![0.0; self.dofs];
                row[index] = 1.0;
                Ok(row)
            }
            Points::Beam { length, ref shapes } => {
                let xi = beam_position(key, at, length)?;
                shapes.iter().map(|s| s.value(xi)).collect()
            }
        }
    }

    /// The row of the bending moment at `at` (m from a cantilever's clamp),
    /// whose value is `row . q`, N m: `E I w''(x) = E I sum_i phi_i''(x) q_i`.
    /// Only a cantilever bends; `key` names the input in the error.
    pub fn moment_row(&self, key: &str, at: f64) -> Result<Vec<f64>> {
        let (
            Points::Beam { length, ref shapes },
            Recipe::Cantilever {
                youngs_modulus,
                second_moment,
                ..
            },
        ) = (&self.points, self.recipe)
        else {
            return Err(Error::Inconsistent(format!(
                "{key}: only a cantilever has bending moments (structure.kind = \"cantilever\")"
            )));
        };
        let xi = beam_position(key, at, *length)?;
        let stiffness = youngs_modulus * second_moment / (length * length);
        shapes
            .iter()
            .map(|s| Ok(stiffness * s.derivatives(xi)?[2]))
            .collect()
    }

    /// Kinetic plus strain energy at displacements `q` (m) and velocities
    /// `v` (m/s), J.
    pub fn energy(&self, q: &[f64], v: &[f64]) -> f64 {
        0.5 * (linalg::quadratic_form(&self.mass, v) + linalg::quadratic_form(&self.stiffness, q))
    }
}

/// Why a mass matrix has no Cholesky factor (see [`linalg::cholesky`]): a coordinate
/// without mass, coordinates that are dependent (a mode without mass: the matrix
/// scaled to a unit diagonal has an eigenvalue of round-off or below), or masses
/// further apart than the factor's 1e14 (a diagonal `[1e308, 1e-308]`: each
/// positive, but the smaller is round-off of the larger in double precision).
fn why_not_positive_definite(mass: &[f64], n: usize) -> String {
    let head = "structure.mass must be positive definite (every mode needs mass)";
    let diagonal: Vec<f64> = (0..n).map(|i| mass[i * n + i]).collect();
    if let Some(i) = diagonal.iter().position(|&m| m <= 0.0) {
        return format!("{head}: entry [{i}][{i}] is {} kg", diagonal[i]);
    }
    // D^-1/2 M D^-1/2: a unit diagonal, whatever the units of each coordinate.
    let roots: Vec<f64> = diagonal.iter().map(|m| m.sqrt()).collect();
    let scaled: Vec<f64> = (0..n * n)
        .map(|k| mass[k] / roots[k / n] / roots[k % n])
        .collect();
    let lowest = linalg::symmetric_eigenvalues(&scaled, n)[0];
    if lowest.is_nan() || lowest <= 1e-12 {
        return format!(
            "{head}: scaled to a unit diagonal, its lowest eigenvalue is {lowest:.4} (zero or \
             below: a combination of the coordinates without mass)"
        );
    }
    let smallest = diagonal.iter().copied().fold(f64::INFINITY, f64::min);
    let largest = diagonal.iter().copied().fold(0.0, f64::max);
    format!(
        "structure.mass: its lightest mode (about {} kg) is below 1e-14 of its largest \
         mass ({largest} kg), beyond what double precision resolves (the masses span \
         {smallest} to {largest} kg): give the coordinates units of like size",
        lowest * smallest
    )
}

/// A square, finite, symmetric matrix from its rows, row-major.
fn square(key: &str, rows: &[Vec<f64>], n: usize) -> Result<Vec<f64>> {
    if rows.len() != n || rows.iter().any(|row| row.len() != n) {
        let shape: Vec<usize> = rows.iter().map(Vec::len).collect();
        let like = if key == "mass" {
            String::new()
        } else {
            " like structure.mass".into()
        };
        return Err(Error::Inconsistent(format!(
            "structure.{key} must be {n} x {n}{like} (an array of {n} rows of {n} numbers), \
             got rows of lengths {shape:?}"
        )));
    }
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    if let Some(at) = flat.iter().position(|v| !v.is_finite()) {
        return Err(Error::Inconsistent(format!(
            "structure.{key} must be finite: entry [{}][{}] is {}",
            at / n,
            at % n,
            flat[at]
        )));
    }
    if let Some((i, j)) = linalg::asymmetry(&flat, n) {
        return Err(Error::Inconsistent(format!(
            "structure.{key} must be symmetric: entry [{i}][{j}] = {} but [{j}][{i}] = {}",
            flat[i * n + j],
            flat[j * n + i]
        )));
    }
    Ok(flat)
}

/// `at` (m from the clamp, named `key` in the error) as a fraction of a
/// beam's `length`: a point's and a bending moment's position alike.
fn beam_position(key: &str, at: f64, length: f64) -> Result<f64> {
    if !(at.is_finite() && (0.0..=length).contains(&at)) {
        return Err(Error::Inconsistent(format!(
            "{key} must be a position along the beam in [0, {length}] m, got {at}"
        )));
    }
    Ok(at / length)
}
