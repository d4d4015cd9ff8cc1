//! The matrix exponential by scaling and squaring with Pade approximants.

use super::{matmul, solve_matrix_in_place};

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
