//! Small dense symmetric matrices (row-major `n x n` slices): the checks a
//! structure's matrices must pass and the factorisation its kernel uses.
//! Sizes are a few tens of degrees of freedom, so plain loops are best.

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

/// Solves `A x = b` in place (`b` becomes `x`) by Gaussian elimination with
/// complete pivoting (partial beyond 64 unknowns); `A` (row-major, `n x n`)
/// is overwritten. A singular `A` (dependent rows, such as two constraints on
/// the same gap) gives the unknowns of the columns left without a pivot 0: a
/// solution of a consistent system. Partial pivoting alone could move an
/// independent row into a dependent one's place and drop it.
pub fn solve_in_place(a: &mut [f64], b: &mut [f64], n: usize) {
    const MOST: usize = 64;
    if n > MOST {
        return solve_partial(a, b, n);
    }
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
    for k in 0..n {
        x[columns[k]] = b[k];
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

/// `e^A` of a row-major `n x n` matrix by scaling and squaring with the
/// [13/13] Pade approximant (Higham 2005): accurate to a few ulps of its norm.
pub fn expm(a: &[f64], n: usize) -> Vec<f64> {
    // Balance first (Parlett and Reinsch: a diagonal similarity by powers of
    // two, exact in floating point), so that rows and columns of very
    // different sizes (a stiff contact beside a soft structure) do not set
    // the scaling and its round-off: e^A = D e^(D^-1 A D) D^-1.
    let mut b = a.to_vec();
    let mut d = vec![1.0; n];
    for _ in 0..32 {
        let mut changed = false;
        for i in 0..n {
            let (mut column, mut row) = (0.0, 0.0);
            for j in 0..n {
                if j != i {
                    column += b[j * n + i].abs();
                    row += b[i * n + j].abs();
                }
            }
            if column == 0.0 || row == 0.0 {
                continue;
            }
            let mut f = 1.0;
            let total = column + row;
            let (mut c, mut r) = (column, row);
            while c < r / 2.0 {
                c *= 2.0;
                r /= 2.0;
                f *= 2.0;
            }
            while c >= r * 2.0 {
                c /= 2.0;
                r *= 2.0;
                f /= 2.0;
            }
            if (c + r) < 0.95 * total {
                changed = true;
                d[i] *= f;
                for j in 0..n {
                    b[i * n + j] /= f;
                    b[j * n + i] *= f;
                }
            }
        }
        if !changed {
            break;
        }
    }
    let mut e = expm_balanced(&b, n);
    for i in 0..n {
        for j in 0..n {
            e[i * n + j] *= d[i] / d[j];
        }
    }
    e
}

/// [`expm`] without balancing.
fn expm_balanced(a: &[f64], n: usize) -> Vec<f64> {
    const B: [f64; 14] = [
        64764752532480000.0,
        32382376266240000.0,
        7771770303897600.0,
        1187353796428800.0,
        129060195264000.0,
        10559470521600.0,
        670442572800.0,
        33522128640.0,
        1323241920.0,
        40840800.0,
        960960.0,
        16380.0,
        182.0,
        1.0,
    ];
    const THETA_13: f64 = 5.371920351148152;
    let norm = (0..n)
        .map(|c| (0..n).map(|r| a[r * n + c].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let squarings = if norm > THETA_13 {
        (norm / THETA_13).log2().ceil() as i32
    } else {
        0
    };
    let scale = 0.5f64.powi(squarings);
    let a: Vec<f64> = a.iter().map(|v| v * scale).collect();
    let mut a2 = vec![0.0; n * n];
    let mut a4 = vec![0.0; n * n];
    let mut a6 = vec![0.0; n * n];
    matmul(&a, &a, &mut a2, n);
    matmul(&a2, &a2, &mut a4, n);
    matmul(&a4, &a2, &mut a6, n);
    let combine = |w: [f64; 4], out: &mut [f64]| {
        for p in 0..n * n {
            out[p] = w[0] * a6[p] + w[1] * a4[p] + w[2] * a2[p];
        }
        for i in 0..n {
            out[i * n + i] += w[3];
        }
    };
    // U = A [A6 (b13 A6 + b11 A4 + b9 A2) + b7 A6 + b5 A4 + b3 A2 + b1 I]
    let mut inner = vec![0.0; n * n];
    let mut tmp = vec![0.0; n * n];
    combine([B[13], B[11], B[9], 0.0], &mut inner);
    matmul(&a6, &inner, &mut tmp, n);
    combine([B[7], B[5], B[3], B[1]], &mut inner);
    for p in 0..n * n {
        inner[p] += tmp[p];
    }
    let mut u = vec![0.0; n * n];
    matmul(&a, &inner, &mut u, n);
    // V = A6 (b12 A6 + b10 A4 + b8 A2) + b6 A6 + b4 A4 + b2 A2 + b0 I
    combine([B[12], B[10], B[8], 0.0], &mut inner);
    let mut v = vec![0.0; n * n];
    matmul(&a6, &inner, &mut v, n);
    combine([B[6], B[4], B[2], B[0]], &mut inner);
    for p in 0..n * n {
        v[p] += inner[p];
    }
    // (V - U) R = V + U.
    let mut lhs: Vec<f64> = v.iter().zip(&u).map(|(v, u)| v - u).collect();
    let mut r: Vec<f64> = v.iter().zip(&u).map(|(v, u)| v + u).collect();
    solve_matrix_in_place(&mut lhs, &mut r, n);
    for _ in 0..squarings {
        matmul(&r, &r, &mut tmp, n);
        std::mem::swap(&mut r, &mut tmp);
    }
    r
}

/// The eigenvalues of a general real `n x n` matrix (row-major), as
/// `(real, imaginary)` pairs in no particular order: reduction to upper
/// Hessenberg form by stabilised elementary similarity transformations, then
/// the Francis double-shift QR iteration (EISPACK's `elmhes` and `hqr`, as
/// Numerical Recipes gives them, with 1-based indices kept so that the
/// algorithm reads as published). None if an eigenvalue takes more than 30
/// iterations.
pub fn eigenvalues(matrix: &[f64], n: usize) -> Option<Vec<(f64, f64)>> {
    let w = n + 1;
    let mut a = vec![0.0; w * w];
    for i in 1..=n {
        for j in 1..=n {
            a[i * w + j] = matrix[(i - 1) * n + (j - 1)];
        }
    }
    let at = |i: usize, j: usize| i * w + j;
    // elmhes
    for m in 2..n {
        let (mut x, mut i) = (0.0f64, m);
        for j in m..=n {
            if a[at(j, m - 1)].abs() > x.abs() {
                x = a[at(j, m - 1)];
                i = j;
            }
        }
        if i != m {
            for j in (m - 1)..=n {
                a.swap(at(i, j), at(m, j));
            }
            for j in 1..=n {
                a.swap(at(j, i), at(j, m));
            }
        }
        if x != 0.0 {
            for i in (m + 1)..=n {
                let mut y = a[at(i, m - 1)];
                if y != 0.0 {
                    y /= x;
                    a[at(i, m - 1)] = y;
                    for j in m..=n {
                        a[at(i, j)] -= y * a[at(m, j)];
                    }
                    for j in 1..=n {
                        a[at(j, m)] += y * a[at(j, i)];
                    }
                }
            }
        }
    }
    // elmhes leaves its multipliers below the subdiagonal.
    for i in 3..=n {
        for j in 1..(i - 1) {
            a[at(i, j)] = 0.0;
        }
    }
    // hqr
    let sign = |x: f64, y: f64| if y >= 0.0 { x.abs() } else { -x.abs() };
    let mut values = vec![(0.0, 0.0); n + 1];
    let mut anorm = 0.0;
    for i in 1..=n {
        for j in (i.max(2) - 1)..=n {
            anorm += a[at(i, j)].abs();
        }
    }
    let mut nn = n;
    let mut t = 0.0;
    while nn >= 1 {
        let mut its = 0;
        loop {
            let mut l = nn;
            while l >= 2 {
                let mut s = a[at(l - 1, l - 1)].abs() + a[at(l, l)].abs();
                if s == 0.0 {
                    s = anorm;
                }
                if a[at(l, l - 1)].abs() + s == s {
                    a[at(l, l - 1)] = 0.0;
                    break;
                }
                l -= 1;
            }
            let mut x = a[at(nn, nn)];
            if l == nn {
                values[nn] = (x + t, 0.0);
                nn -= 1;
            } else {
                let mut y = a[at(nn - 1, nn - 1)];
                let mut w2 = a[at(nn, nn - 1)] * a[at(nn - 1, nn)];
                if l == nn - 1 {
                    let p = 0.5 * (y - x);
                    let q = p * p + w2;
                    let mut z = q.abs().sqrt();
                    x += t;
                    if q >= 0.0 {
                        z = p + sign(z, p);
                        let low = if z != 0.0 { x - w2 / z } else { x + z };
                        values[nn - 1] = (x + z, 0.0);
                        values[nn] = (low, 0.0);
                    } else {
                        values[nn - 1] = (x + p, -z);
                        values[nn] = (x + p, z);
                    }
                    nn -= 2;
                } else {
                    if its == 30 {
                        return None;
                    }
                    if its == 10 || its == 20 {
                        // Exceptional shift.
                        t += x;
                        for i in 1..=nn {
                            a[at(i, i)] -= x;
                        }
                        let s = a[at(nn, nn - 1)].abs() + a[at(nn - 1, nn - 2)].abs();
                        x = 0.75 * s;
                        y = x;
                        w2 = -0.4375 * s * s;
                    }
                    its += 1;
                    let (mut p, mut q, mut r): (f64, f64, f64);
                    let mut m = nn - 2;
                    loop {
                        let z = a[at(m, m)];
                        let rr = x - z;
                        let ss = y - z;
                        p = (rr * ss - w2) / a[at(m + 1, m)] + a[at(m, m + 1)];
                        q = a[at(m + 1, m + 1)] - z - rr - ss;
                        r = a[at(m + 2, m + 1)];
                        let s = p.abs() + q.abs() + r.abs();
                        p /= s;
                        q /= s;
                        r /= s;
                        if m == l {
                            break;
                        }
                        let u = a[at(m, m - 1)].abs() * (q.abs() + r.abs());
                        let v = p.abs()
                            * (a[at(m - 1, m - 1)].abs() + z.abs() + a[at(m + 1, m + 1)].abs());
                        if u + v == v {
                            break;
                        }
                        m -= 1;
                    }
                    for i in (m + 2)..=nn {
                        a[at(i, i - 2)] = 0.0;
                        if i != m + 2 {
                            a[at(i, i - 3)] = 0.0;
                        }
                    }
                    let mut k = m;
                    while k < nn {
                        if k != m {
                            p = a[at(k, k - 1)];
                            q = a[at(k + 1, k - 1)];
                            r = if k != nn - 1 {
                                a[at(k + 2, k - 1)]
                            } else {
                                0.0
                            };
                            x = p.abs() + q.abs() + r.abs();
                            if x != 0.0 {
                                p /= x;
                                q /= x;
                                r /= x;
                            }
                        }
                        let s = sign((p * p + q * q + r * r).sqrt(), p);
                        if s != 0.0 {
                            if k == m {
                                if l != m {
                                    a[at(k, k - 1)] = -a[at(k, k - 1)];
                                }
                            } else {
                                a[at(k, k - 1)] = -s * x;
                            }
                            p += s;
                            x = p / s;
                            y = q / s;
                            let z = r / s;
                            q /= p;
                            r /= p;
                            for j in k..=nn {
                                p = a[at(k, j)] + q * a[at(k + 1, j)];
                                if k != nn - 1 {
                                    p += r * a[at(k + 2, j)];
                                    a[at(k + 2, j)] -= p * z;
                                }
                                a[at(k + 1, j)] -= p * y;
                                a[at(k, j)] -= p * x;
                            }
                            let last = nn.min(k + 3);
                            for i in l..=last {
                                p = x * a[at(i, k)] + y * a[at(i, k + 1)];
                                if k != nn - 1 {
                                    p += z * a[at(i, k + 2)];
                                    a[at(i, k + 2)] -= p * r;
                                }
                                a[at(i, k + 1)] -= p * q;
                                a[at(i, k)] -= p;
                            }
                        }
                        k += 1;
                    }
                }
            }
            if nn < 2 || l >= nn - 1 {
                break;
            }
        }
    }
    values.remove(0);
    Some(values)
}

/// `x^T A x` for a symmetric row-major matrix.
pub fn quadratic_form(a: &[f64], x: &[f64]) -> f64 {
    let n = x.len();
    (0..n)
        .map(|i| x[i] * (0..n).map(|j| a[i * n + j] * x[j]).sum::<f64>())
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dependent_row_first_keeps_the_independent_one() {
        crate::testing::timeout(60, || {
            // Both walls of a zero-clearance damper (rows h and -h) and a
            // second damper sticking: the forces must hold all three gaps.
            // Partial pivoting swapped the third row into the dependent
            // second's place and dropped it: forces [2.73, 0, 0].
            let w = [11.0, -11.0, 1.0, -11.0, 11.0, -1.0, 1.0, -1.0, 21.0];
            let x = [0.3, 0.0, -0.2];
            let rhs: Vec<f64> = (0..3)
                .map(|r| (0..3).map(|c| w[r * 3 + c] * x[c]).sum())
                .collect();
            let (mut a, mut b) = (w, rhs.clone());
            solve_in_place(&mut a, &mut b, 3);
            for r in 0..3 {
                let got: f64 = (0..3).map(|c| w[r * 3 + c] * b[c]).sum();
                assert!((got - rhs[r]).abs() < 1e-12, "row {r}: {got} vs {}", rhs[r]);
            }
            // A regular system: the solution itself.
            let w = [4.0, 1.0, 0.5, 1.0, 3.0, -1.0, 0.5, -1.0, 2.0];
            let rhs: Vec<f64> = (0..3)
                .map(|r| (0..3).map(|c| w[r * 3 + c] * x[c]).sum())
                .collect();
            let (mut a, mut b) = (w, rhs);
            solve_in_place(&mut a, &mut b, 3);
            for (got, want) in b.iter().zip(x) {
                assert!((got - want).abs() < 1e-14, "{got} vs {want}");
            }
        });
    }

    #[test]
    fn eigenvalues_of_a_known_matrix() {
        crate::testing::timeout(60, || {
            // The second-difference matrix tridiag(-1, 2, -1) of size n has
            // eigenvalues 2 - 2 cos(k pi / (n + 1)), k = 1..n.
            let n = 7;
            let mut a = vec![0.0; n * n];
            for i in 0..n {
                a[i * n + i] = 2.0;
                if i + 1 < n {
                    a[i * n + i + 1] = -1.0;
                    a[(i + 1) * n + i] = -1.0;
                }
            }
            let (values, vectors) = symmetric_eigen(&a, n);
            for (k, v) in values.iter().enumerate() {
                // A v = lambda v for each column.
                for r in 0..n {
                    let av: f64 = (0..n).map(|c| a[r * n + c] * vectors[c * n + k]).sum();
                    assert!((av - v * vectors[r * n + k]).abs() < 1e-13);
                }
                let exact =
                    2.0 - 2.0 * ((k + 1) as f64 * std::f64::consts::PI / (n + 1) as f64).cos();
                assert!((v - exact).abs() < 1e-14, "{v} vs {exact}");
            }
            let l = cholesky(&a, n).expect("positive definite");
            let inverse = inverse_from_cholesky(&l, n);
            // A A^-1 = I.
            for i in 0..n {
                for j in 0..n {
                    let p: f64 = (0..n).map(|k| a[i * n + k] * inverse[k * n + j]).sum();
                    let expected = if i == j { 1.0 } else { 0.0 };
                    assert!((p - expected).abs() < 1e-13);
                }
            }
            // e^A of a rotation generator and of a Jordan block, in closed form.
            let (w, t) = (3.0, 2.5);
            let e = expm(&[0.0, w * t, -w * t, 0.0], 2);
            let (s, c) = (w * t).sin_cos();
            for (got, want) in e.iter().zip([c, s, -s, c]) {
                assert!((got - want).abs() < 1e-14, "{e:?}");
            }
            let e = expm(&[-2.0 * t, t, 0.0, -2.0 * t], 2);
            let d = (-2.0 * t).exp();
            for (got, want) in e.iter().zip([d, t * d, 0.0, d]) {
                assert!((got - want).abs() < 1e-15, "{e:?}");
            }
            // Singular (a free-free chain) and indefinite matrices have no factor.
            assert!(cholesky(&[1.0, -1.0, -1.0, 1.0], 2).is_none());
            assert!(cholesky(&[1.0, 2.0, 2.0, 1.0], 2).is_none());
        });
    }
    #[test]
    fn eigenvalues_of_general_matrices() {
        crate::testing::timeout(60, || {
            let sorted = |mut v: Vec<(f64, f64)>| {
                v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
                v
            };
            let close = |got: &[(f64, f64)], want: &[(f64, f64)], tol: f64| {
                assert_eq!(got.len(), want.len());
                for (g, w) in got.iter().zip(want) {
                    assert!(
                        (g.0 - w.0).abs() < tol && (g.1 - w.1).abs() < tol,
                        "{got:?} vs {want:?}"
                    );
                }
            };
            // A rotation scaled by r: r e^(+-i phi).
            let (r, phi) = (0.9f64, 0.7f64);
            let (c, s) = (r * phi.cos(), r * phi.sin());
            close(
                &sorted(eigenvalues(&[c, -s, s, c], 2).unwrap()),
                &[(c, -s), (c, s)],
                1e-15,
            );
            // The companion matrix of (x - 0.5)(x + 0.3)(x - 1.1)(x^2 - 0.4 x + 0.53):
            // roots 0.5, -0.3, 1.1 and 0.2 +- 0.7 i.
            let roots = [(0.5, 0.0), (-0.3, 0.0), (1.1, 0.0), (0.2, 0.7), (0.2, -0.7)];
            // Coefficients of the monic polynomial, highest first, by expansion.
            let mut poly: Vec<(f64, f64)> = vec![(1.0, 0.0)];
            for &(rr, ri) in &roots {
                let mut next = vec![(0.0, 0.0); poly.len() + 1];
                for (i, &(pr, pi)) in poly.iter().enumerate() {
                    next[i].0 += pr;
                    next[i].1 += pi;
                    next[i + 1].0 -= pr * rr - pi * ri;
                    next[i + 1].1 -= pr * ri + pi * rr;
                }
                poly = next;
            }
            let n = 5;
            let mut companion = vec![0.0; n * n];
            for j in 0..n {
                companion[j] = -poly[j + 1].0;
            }
            for i in 1..n {
                companion[i * n + i - 1] = 1.0;
            }
            close(
                &sorted(eigenvalues(&companion, n).unwrap()),
                &sorted(roots.to_vec()),
                1e-12,
            );
            // Any matrix: the eigenvalues sum to the trace, and (n = 3) their
            // product is the determinant.
            let m = [0.3, -1.2, 2.5, 0.7, 0.1, -0.4, -2.0, 1.5, 0.9];
            let e = eigenvalues(&m, 3).unwrap();
            let trace: f64 = e.iter().map(|v| v.0).sum();
            assert!((trace - (0.3 + 0.1 + 0.9)).abs() < 1e-13);
            assert!(e.iter().map(|v| v.1).sum::<f64>().abs() < 1e-13);
            let det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6])
                + m[2] * (m[3] * m[7] - m[4] * m[6]);
            let (mut pr, mut pi) = (1.0, 0.0);
            for (a, b) in &e {
                (pr, pi) = (pr * a - pi * b, pr * b + pi * a);
            }
            assert!(
                (pr - det).abs() < 1e-12 && pi.abs() < 1e-12,
                "{pr} {pi} vs {det}"
            );
            // Triangular: its diagonal. One by one: itself.
            close(
                &sorted(eigenvalues(&[2.0, 5.0, 7.0, 0.0, -1.0, 3.0, 0.0, 0.0, 0.5], 3).unwrap()),
                &[(-1.0, 0.0), (0.5, 0.0), (2.0, 0.0)],
                1e-14,
            );
            close(&eigenvalues(&[4.2], 1).unwrap(), &[(4.2, 0.0)], 1e-15);
        });
    }
}
