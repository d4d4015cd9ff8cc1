//! Linear systems by Gaussian elimination: a few rows with full pivoting
//! (dependent constraints kept apart), or partial pivoting for many.

use super::max_abs;

/// Solves `A x = b` in place (`b` becomes `x`) by Gaussian elimination with
/// complete pivoting (partial beyond 64 unknowns); `A` (row-major, `n x n`)
/// is overwritten. A singular `A` (dependent rows, such as two constraints on
/// the same gap) gives the unknowns of the columns left without a pivot 0: a
/// solution of a consistent system. Partial pivoting alone could move an
/// independent row into a dependent one's place and drop it.
pub fn solve_in_place(a: &mut [f64], b: &mut [f64], n: usize) {
    if n > 64 {
        return solve_partial(a, b, n);
    }
    solve_pivoted::<64>(a, b, n);
}

/// [`solve_in_place`]'s complete pivoting for `n <= MOST` unknowns, its
/// stack arrays `MOST` long: inlined, a caller with few unknowns known at
/// compile time (a fixed-size path) makes the same operations, the same
/// bits, without a call or arrays of 64.
#[inline(always)]
pub(crate) fn solve_pivoted<const MOST: usize>(a: &mut [f64], b: &mut [f64], n: usize) {
    let tiny = 1e-13 * max_abs(&a[..n * n]);
    // Column k of the reduced system is column `columns[k]` of A's.
    let mut columns = [0usize; MOST];
    for (k, c) in columns[..n].iter_mut().enumerate() {
        *c = k;
    }
    let mut rank = n;
    for k in 0..n {
        let (mut row, mut col, mut best) = (k, k, 0.0f64);
        for r in k..n {
            for c in k..n {
                let value = a[r * n + c].abs();
                if value > best {
                    (row, col, best) = (r, c, value);
                }
            }
        }
        if best <= tiny {
            rank = k;
            break;
        }
        if row != k {
            for c in 0..n {
                a.swap(k * n + c, row * n + c);
            }
            b.swap(k, row);
        }
        if col != k {
            for r in 0..n {
                a.swap(r * n + k, r * n + col);
            }
            columns.swap(k, col);
        }
        let diagonal = a[k * n + k];
        for r in k + 1..n {
            let factor = a[r * n + k] / diagonal;
            if factor != 0.0 {
                for c in k..n {
                    a[r * n + c] -= factor * a[k * n + c];
                }
                b[r] -= factor * b[k];
            }
        }
    }
    for k in (0..n).rev() {
        if k >= rank {
            b[k] = 0.0;
            continue;
        }
        let sum: f64 = (k + 1..rank).map(|c| a[k * n + c] * b[c]).sum();
        b[k] = (b[k] - sum) / a[k * n + k];
    }
    // Back to A's column order: unknown k of the reduced system is A's
    // `columns[k]`.
    let mut x = [0.0f64; MOST];
    if MOST <= 8 {
        // A few unknowns (a fixed-size caller's): each gathered by a
        // comparison, not scattered to an index (stores a wide load would
        // wait on), the same values.
        for (c, slot) in x[..n].iter_mut().enumerate() {
            for (&column, &value) in columns[..n].iter().zip(&b[..n]) {
                if column == c {
                    *slot = value;
                }
            }
        }
    } else {
        for k in 0..n {
            x[columns[k]] = b[k];
        }
    }
    b[..n].copy_from_slice(&x[..n]);
}

/// [`solve_in_place`] by partial pivoting, for systems too large for its
/// stack arrays.
fn solve_partial(a: &mut [f64], b: &mut [f64], n: usize) {
    let scale = max_abs(a);
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))
            .unwrap_or(col);
        let diagonal = a[pivot * n + col];
        if diagonal.abs() <= 1e-13 * scale {
            continue;
        }
        if pivot != col {
            for c in 0..n {
                a.swap(col * n + c, pivot * n + c);
            }
            b.swap(col, pivot);
        }
        for row in col + 1..n {
            let factor = a[row * n + col] / diagonal;
            for c in col..n {
                a[row * n + c] -= factor * a[col * n + c];
            }
            b[row] -= factor * b[col];
        }
    }
    for row in (0..n).rev() {
        let diagonal = a[row * n + row];
        if diagonal.abs() <= 1e-13 * scale {
            b[row] = 0.0;
            continue;
        }
        let sum: f64 = (row + 1..n).map(|c| a[row * n + c] * b[c]).sum();
        b[row] = (b[row] - sum) / diagonal;
    }
}

/// Solves `A X = B` for row-major `n x n` matrices in place (`b` becomes `X`)
/// by Gaussian elimination with partial pivoting; `a` is overwritten.
pub fn solve_matrix_in_place(a: &mut [f64], b: &mut [f64], n: usize) {
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))
            .unwrap_or(col);
        if pivot != col {
            for c in 0..n {
                a.swap(col * n + c, pivot * n + c);
                b.swap(col * n + c, pivot * n + c);
            }
        }
        let diagonal = a[col * n + col];
        for row in col + 1..n {
            let factor = a[row * n + col] / diagonal;
            if factor == 0.0 {
                continue;
            }
            for c in col..n {
                a[row * n + c] -= factor * a[col * n + c];
            }
            for c in 0..n {
                b[row * n + c] -= factor * b[col * n + c];
            }
        }
    }
    for row in (0..n).rev() {
        let diagonal = a[row * n + row];
        for c in 0..n {
            let sum: f64 = (row + 1..n).map(|k| a[row * n + k] * b[k * n + c]).sum();
            b[row * n + c] = (b[row * n + c] - sum) / diagonal;
        }
    }
}
