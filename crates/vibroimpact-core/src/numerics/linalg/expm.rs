//! The matrix exponential by scaling and squaring with Pade approximants.

use super::{matmul, solve_matrix_in_place};

/// `e^A` of a row-major `n x n` matrix by scaling and squaring with the
/// [13/13] Pade approximant (Higham 2005): accurate to a few ulps of its norm.
pub fn expm(a: &[f64], n: usize) -> Vec<f64> {
    let mut out = vec![0.0; n * n];
    Expm::new(n).compute(a, 1.0, &mut out);
    out
}

/// [`expm`]'s work space for `n x n` matrices, made once: a caller taking
/// many exponentials (the tangent flow, one per stretch between events)
/// allocates nothing per call.
#[derive(Debug, Clone)]
pub struct Expm {
    n: usize,
    /// The balanced matrix and its diagonal similarity.
    b: Vec<f64>,
    d: Vec<f64>,
    a2: Vec<f64>,
    a4: Vec<f64>,
    a6: Vec<f64>,
    inner: Vec<f64>,
    tmp: Vec<f64>,
    u: Vec<f64>,
    v: Vec<f64>,
}

impl Expm {
    pub fn new(n: usize) -> Self {
        let square = vec![0.0; n * n];
        Self {
            n,
            b: square.clone(),
            d: vec![1.0; n],
            a2: square.clone(),
            a4: square.clone(),
            a6: square.clone(),
            inner: square.clone(),
            tmp: square.clone(),
            u: square.clone(),
            v: square,
        }
    }

    /// `e^(scale A)` into `out` (row-major `n x n`).
    pub fn compute(&mut self, a: &[f64], scale: f64, out: &mut [f64]) {
        let n = self.n;
        // Balance first (Parlett and Reinsch: a diagonal similarity by powers of
        // two, exact in floating point), so that rows and columns of very
        // different sizes (a stiff contact beside a soft structure) do not set
        // the scaling and its round-off: e^A = D e^(D^-1 A D) D^-1.
        for (b, a) in self.b.iter_mut().zip(a) {
            *b = a * scale;
        }
        self.d.iter_mut().for_each(|d| *d = 1.0);
        let b = &mut self.b;
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
                    self.d[i] *= f;
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
        self.balanced(out);
        for i in 0..n {
            for j in 0..n {
                out[i * n + j] *= self.d[i] / self.d[j];
            }
        }
    }

    /// `e^B` of the balanced matrix `self.b` into `out`, without balancing.
    fn balanced(&mut self, out: &mut [f64]) {
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
        let n = self.n;
        let norm = (0..n)
            .map(|c| (0..n).map(|r| self.b[r * n + c].abs()).sum::<f64>())
            .fold(0.0, f64::max);
        let squarings = if norm > THETA_13 {
            (norm / THETA_13).log2().ceil() as i32
        } else {
            0
        };
        let scale = 0.5f64.powi(squarings);
        self.b.iter_mut().for_each(|v| *v *= scale);
        let a = &self.b;
        matmul(a, a, &mut self.a2, n);
        matmul(&self.a2, &self.a2, &mut self.a4, n);
        matmul(&self.a4, &self.a2, &mut self.a6, n);
        let (a2, a4, a6) = (&self.a2, &self.a4, &self.a6);
        let combine = |w: [f64; 4], out: &mut [f64]| {
            for p in 0..n * n {
                out[p] = w[0] * a6[p] + w[1] * a4[p] + w[2] * a2[p];
            }
            for i in 0..n {
                out[i * n + i] += w[3];
            }
        };
        // U = A [A6 (b13 A6 + b11 A4 + b9 A2) + b7 A6 + b5 A4 + b3 A2 + b1 I]
        combine([B[13], B[11], B[9], 0.0], &mut self.inner);
        matmul(a6, &self.inner, &mut self.tmp, n);
        combine([B[7], B[5], B[3], B[1]], &mut self.inner);
        for p in 0..n * n {
            self.inner[p] += self.tmp[p];
        }
        matmul(a, &self.inner, &mut self.u, n);
        // V = A6 (b12 A6 + b10 A4 + b8 A2) + b6 A6 + b4 A4 + b2 A2 + b0 I
        combine([B[12], B[10], B[8], 0.0], &mut self.inner);
        matmul(a6, &self.inner, &mut self.v, n);
        combine([B[6], B[4], B[2], B[0]], &mut self.inner);
        for p in 0..n * n {
            self.v[p] += self.inner[p];
        }
        // (V - U) R = V + U, R into `out`.
        for (((t, o), v), u) in self
            .tmp
            .iter_mut()
            .zip(out.iter_mut())
            .zip(&self.v)
            .zip(&self.u)
        {
            *t = v - u;
            *o = v + u;
        }
        solve_matrix_in_place(&mut self.tmp, out, n);
        for _ in 0..squarings {
            matmul(out, out, &mut self.tmp, n);
            out.copy_from_slice(&self.tmp);
        }
    }
}
