//! The eigenvalues of a general real matrix (Floquet multipliers).

/// The eigenvalues of a general real `n x n` matrix (row-major), as
/// `(real, imaginary)` pairs in no particular order: reduction to upper
/// Hessenberg form by stabilised elementary similarity transformations, then
/// the Francis double-shift QR iteration (EISPACK's `elmhes` and `hqr`, as
/// Numerical Recipes gives them, with 1-based indices kept so that the
/// algorithm reads as published). None if an eigenvalue takes more than 30
/// iterations.
pub fn eigenvalues(matrix: &[f64], n: usize) -> Option<Vec<(f64, f64)>> {
    let mut a = hessenberg(matrix, n);
    let mut values = hqr(&mut a, n)?;
    values.remove(0);
    Some(values)
}

/// `matrix` (row-major `n x n`) copied into a 1-based `(n + 1) x (n + 1)`
/// array and reduced to upper Hessenberg form (`elmhes`), its multipliers
/// below the subdiagonal cleared.
fn hessenberg(matrix: &[f64], n: usize) -> Vec<f64> {
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
    a
}

/// `|x|` with the sign of `y` (Fortran's `SIGN`).
fn sign(x: f64, y: f64) -> f64 {
    if y >= 0.0 {
        x.abs()
    } else {
        -x.abs()
    }
}

/// The eigenvalues of the 1-based upper Hessenberg `a` (`hqr`), at 1..=n of
/// the result (0 unused); None if one takes more than 30 iterations.
fn hqr(a: &mut [f64], n: usize) -> Option<Vec<(f64, f64)>> {
    let w = n + 1;
    let at = |i: usize, j: usize| i * w + j;
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
                    francis_step(a, n, (l, nn), (x, y, w2));
                }
            }
            if nn < 2 || l >= nn - 1 {
                break;
            }
        }
    }
    Some(values)
}

/// One Francis double-shift QR step of `hqr` on the active block `l..=nn`
/// of the 1-based Hessenberg `a`, with the shifts' `x`, `y` and `w2`: look
/// for two consecutive small subdiagonal elements, then chase the bulge.
fn francis_step(a: &mut [f64], n: usize, (l, nn): (usize, usize), (x, y, w2): (f64, f64, f64)) {
    let w = n + 1;
    let at = |i: usize, j: usize| i * w + j;
    let (mut x, mut y) = (x, y);
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
        let v = p.abs() * (a[at(m - 1, m - 1)].abs() + z.abs() + a[at(m + 1, m + 1)].abs());
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
