//! Small dense matrices (row-major `n x n` slices): the checks a
//! structure's matrices must pass and the factorisation its kernel uses.
//! Sizes are a few tens of degrees of freedom, so plain loops are best.
//!
//! Here the products and the Cholesky factor; in `solve` the linear
//! systems (Gaussian elimination), in `symmetric` the symmetric
//! eigenproblem (Jacobi), in `eigen` a general matrix's eigenvalues
//! (Hessenberg QR), in `expm` the matrix exponential.

mod eigen;
mod expm;
mod solve;
mod sparse;
mod symmetric;
#[cfg(test)]
mod tests;

pub use eigen::eigenvalues;
pub use expm::{expm, Expm};
pub(crate) use solve::solve_pivoted;
pub use solve::{solve_in_place, solve_matrix_in_place};
pub use sparse::SparseRows;
pub use symmetric::{symmetric_eigen, symmetric_eigenvalues};

/// The largest absolute entry.
pub fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// The first pair `(i, j)`, `i < j`, whose entries differ by more than a
/// relative 1e-12 of the largest entry; None when symmetric.
pub fn asymmetry(a: &[f64], n: usize) -> Option<(usize, usize)> {
    let tolerance = 1e-12 * max_abs(a);
    for i in 0..n {
        for j in i + 1..n {
            if (a[i * n + j] - a[j * n + i]).abs() > tolerance {
                return Some((i, j));
            }
        }
    }
    None
}

/// Cholesky factor `L` (row-major, lower) of a symmetric positive definite
/// matrix; None when a pivot is not positive beyond round-off.
pub fn cholesky(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let scale = max_abs(a);
    let mut l = vec![0.0; n * n];
    for j in 0..n {
        let mut diagonal = a[j * n + j];
        for k in 0..j {
            diagonal -= l[j * n + k] * l[j * n + k];
        }
        if diagonal.is_nan() || diagonal <= 1e-14 * scale {
            return None;
        }
        let root = diagonal.sqrt();
        l[j * n + j] = root;
        for i in j + 1..n {
            let mut sum = a[i * n + j];
            for k in 0..j {
                sum -= l[i * n + k] * l[j * n + k];
            }
            l[i * n + j] = sum / root;
        }
    }
    Some(l)
}

/// The inverse of a symmetric positive definite matrix from its Cholesky
/// factor, by solving `L L^T x = e_k` for each column.
pub fn inverse_from_cholesky(l: &[f64], n: usize) -> Vec<f64> {
    let mut inverse = vec![0.0; n * n];
    let mut column = vec![0.0; n];
    for k in 0..n {
        column.iter_mut().for_each(|c| *c = 0.0);
        column[k] = 1.0;
        // Forward: L y = e_k.
        for i in 0..n {
            let mut sum = column[i];
            for j in 0..i {
                sum -= l[i * n + j] * column[j];
            }
            column[i] = sum / l[i * n + i];
        }
        // Backward: L^T x = y.
        for i in (0..n).rev() {
            let mut sum = column[i];
            for j in i + 1..n {
                sum -= l[j * n + i] * column[j];
            }
            column[i] = sum / l[i * n + i];
        }
        for i in 0..n {
            inverse[i * n + k] = column[i];
        }
    }
    inverse
}

/// The inverse of a lower-triangular matrix (row-major), lower-triangular.
pub fn inverse_lower(l: &[f64], n: usize) -> Vec<f64> {
    let mut inverse = vec![0.0; n * n];
    for k in 0..n {
        inverse[k * n + k] = 1.0 / l[k * n + k];
        for i in k + 1..n {
            let sum: f64 = (k..i).map(|j| l[i * n + j] * inverse[j * n + k]).sum();
            inverse[i * n + k] = -sum / l[i * n + i];
        }
    }
    inverse
}

/// `y = A x` for a row-major `rows x x.len()` matrix.
#[inline]
pub fn multiply(a: &[f64], x: &[f64], y: &mut [f64]) {
    let n = x.len();
    for (row, out) in y.iter_mut().enumerate() {
        *out = a[row * n..(row + 1) * n]
            .iter()
            .zip(x)
            .map(|(a, x)| a * x)
            .sum();
    }
}

/// `a . b`.
#[inline(always)]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// `C = A B` for row-major `n x n` matrices.
pub fn matmul(a: &[f64], b: &[f64], c: &mut [f64], n: usize) {
    for i in 0..n {
        for j in 0..n {
            c[i * n + j] = 0.0;
        }
        for k in 0..n {
            let aik = a[i * n + k];
            if aik == 0.0 {
                continue;
            }
            for j in 0..n {
                c[i * n + j] += aik * b[k * n + j];
            }
        }
    }
}

/// `C = A B` for row-major `A` (`n x n`) and `B`, `C` (`n x m`).
pub fn matmul_rect(a: &[f64], b: &[f64], c: &mut [f64], n: usize, m: usize) {
    for i in 0..n {
        let row = &mut c[i * m..(i + 1) * m];
        row.iter_mut().for_each(|v| *v = 0.0);
        for k in 0..n {
            let aik = a[i * n + k];
            if aik == 0.0 {
                continue;
            }
            for (value, b) in row.iter_mut().zip(&b[k * m..(k + 1) * m]) {
                *value += aik * b;
            }
        }
    }
}

/// `x^T A x` for a symmetric row-major matrix.
pub fn quadratic_form(a: &[f64], x: &[f64]) -> f64 {
    let n = x.len();
    (0..n)
        .map(|i| x[i] * (0..n).map(|j| a[i * n + j] * x[j]).sum::<f64>())
        .sum()
}
