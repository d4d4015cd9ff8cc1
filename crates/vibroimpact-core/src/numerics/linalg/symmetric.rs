//! The symmetric eigenproblem by cyclic Jacobi rotations.

use super::max_abs;

/// Eigenvalues of a symmetric matrix by cyclic Jacobi rotations, ascending.
/// Accurate to round-off relative to the largest eigenvalue.
pub fn symmetric_eigenvalues(a: &[f64], n: usize) -> Vec<f64> {
    symmetric_eigen(a, n).0
}

/// Eigenvalues (ascending) and orthonormal eigenvectors (the columns of a
/// row-major `n x n` matrix, in the same order) of a symmetric matrix, by
/// cyclic Jacobi rotations: accurate to round-off relative to the largest
/// eigenvalue, and exactly orthonormal to round-off even for repeated ones.
pub fn symmetric_eigen(a: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut m = a.to_vec();
    let mut vectors = vec![0.0; n * n];
    for i in 0..n {
        vectors[i * n + i] = 1.0;
    }
    let scale = max_abs(a);
    for _sweep in 0..100 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| m[i * n + j] * m[i * n + j])
            .sum();
        if off.sqrt() <= 1e-15 * scale || scale == 0.0 {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = m[p * n + q];
                if apq == 0.0 {
                    continue;
                }
                let (app, aqq) = (m[p * n + p], m[q * n + q]);
                // The rotation that zeroes (p, q) (Golub and Van Loan, 8.5.2).
                let theta = (aqq - app) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for block in [&mut m, &mut vectors] {
                    for k in 0..n {
                        let (akp, akq) = (block[k * n + p], block[k * n + q]);
                        block[k * n + p] = c * akp - s * akq;
                        block[k * n + q] = s * akp + c * akq;
                    }
                }
                for k in 0..n {
                    let (apk, aqk) = (m[p * n + k], m[q * n + k]);
                    m[p * n + k] = c * apk - s * aqk;
                    m[q * n + k] = s * apk + c * aqk;
                }
            }
        }
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| m[i * n + i].total_cmp(&m[j * n + j]));
    let values = order.iter().map(|&i| m[i * n + i]).collect();
    let mut sorted = vec![0.0; n * n];
    for (c, &i) in order.iter().enumerate() {
        for r in 0..n {
            sorted[r * n + c] = vectors[r * n + i];
        }
    }
    (values, sorted)
}
