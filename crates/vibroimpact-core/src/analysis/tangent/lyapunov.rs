//! Lyapunov exponents through impacts (Benettin's method): the tangent map
//! carried through every event by its saltation matrix, its columns
//! re-orthonormalised (QR by modified Gram-Schmidt) after each factor, the
//! logarithms of the stretches summed. The exponents are those sums over
//! the time averaged (1/s); their convergence is the standard error of the
//! estimates over consecutive blocks of the run.

use super::{Grazing, Tangent};
use crate::error::Result;
use crate::model::assembly::Assembly;

/// Re-orthonormalise the columns of the row-major `size x size` `matrix`
/// (twice-applied modified Gram-Schmidt: orthogonal to round-off even when
/// the columns are nearly parallel), adding the logarithm of each column's
/// stretch to `logs`. A column collapsed to zero (a pair that stuck: its
/// direction is lost) adds minus infinity. The rows `extra` (each `size`
/// long: the latched rates' derivatives, [`super::latched`]) take the same
/// column operations, so that they stay derivatives along the same columns
/// (`L R^-1`).
pub(super) fn orthonormalise(matrix: &mut [f64], size: usize, logs: &mut [f64], extra: &mut [f64]) {
    if extra.is_empty() {
        gram_schmidt::<false>(matrix, size, logs, extra);
    } else {
        gram_schmidt::<true>(matrix, size, logs, extra);
    }
}

/// [`orthonormalise`], the rows `extra` taken where `EXTRA` (compiled out
/// otherwise: the QR after each event is a rigid spectrum's inner loop).
fn gram_schmidt<const EXTRA: bool>(
    matrix: &mut [f64],
    size: usize,
    logs: &mut [f64],
    extra: &mut [f64],
) {
    let rows = extra.len() / size;
    for j in 0..size {
        for _ in 0..2 {
            for k in 0..j {
                let r: f64 = (0..size)
                    .map(|i| matrix[i * size + k] * matrix[i * size + j])
                    .sum();
                for i in 0..size {
                    matrix[i * size + j] -= r * matrix[i * size + k];
                }
                if EXTRA {
                    for i in 0..rows {
                        extra[i * size + j] -= r * extra[i * size + k];
                    }
                }
            }
        }
        let norm = (0..size)
            .map(|i| matrix[i * size + j] * matrix[i * size + j])
            .sum::<f64>()
            .sqrt();
        logs[j] += norm.ln();
        if norm > 0.0 {
            for i in 0..size {
                matrix[i * size + j] /= norm;
            }
            if EXTRA {
                for i in 0..rows {
                    extra[i * size + j] /= norm;
                }
            }
        }
    }
}

/// The Lyapunov spectrum of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct LyapunovSpectrum {
    /// 1/s, in descending order (minus infinity: a direction lost where a
    /// pair stuck).
    pub exponents: Vec<f64>,
    /// Each exponent's standard error over the blocks, 1/s (NaN for one
    /// block, or an exponent infinite in any block).
    pub standard_error: Vec<f64>,
    /// The estimates after each block (1/s, row-major `blocks x 2 dim`, each
    /// row in the order of `exponents`): the spectrum's convergence.
    pub running: Vec<f64>,
    /// The time averaged over, s.
    pub time: f64,
    /// Events whose impulses acted, or where a compliant contact began, over
    /// that time.
    pub impacts: u64,
    pub grazings: Vec<Grazing>,
}

/// One block's run: from a start state, with the flow told of its events, to
/// its end state.
pub type BlockRun<'r> = dyn FnMut(&[f64], &mut Tangent<'_>) -> Result<Vec<f64>> + 'r;

/// The spectrum of `system` from `y0` over `blocks` runs of `block_time` s
/// each, each from the last one's end: `run` integrates one block from its
/// start state (the system's full state, [`Assembly::state_len`] values)
/// with the flow told of its events and returns its end state as the next
/// block's start (the same length).
pub fn lyapunov_blocks(
    system: &Assembly,
    y0: &[f64],
    block_time: f64,
    blocks: usize,
    run: &mut BlockRun<'_>,
) -> Result<LyapunovSpectrum> {
    let mut flow = Tangent::orthonormal(system)?;
    let size = 2 * system.dim;
    let mut estimates: Vec<Vec<f64>> = Vec::with_capacity(blocks);
    let mut sums: Vec<Vec<f64>> = Vec::with_capacity(blocks);
    let mut y = y0.to_vec();
    for b in 0..blocks {
        let before = flow.logs().to_vec();
        y = run(&y, &mut flow)?;
        let block: Vec<f64> = flow
            .logs()
            .iter()
            .zip(&before)
            .map(|(after, before)| (after - before) / block_time)
            .collect();
        estimates.push(block);
        let elapsed = block_time * (b + 1) as f64;
        sums.push(flow.logs().iter().map(|l| l / elapsed).collect());
    }
    let time = block_time * blocks as f64;
    let exponents: Vec<f64> = flow.logs().iter().map(|l| l / time).collect();
    let standard_error: Vec<f64> = (0..size)
        .map(|j| {
            if blocks < 2 {
                return f64::NAN;
            }
            let mean = estimates.iter().map(|b| b[j]).sum::<f64>() / blocks as f64;
            let var =
                estimates.iter().map(|b| (b[j] - mean).powi(2)).sum::<f64>() / (blocks - 1) as f64;
            (var / blocks as f64).sqrt()
        })
        .collect();
    let mut order: Vec<usize> = (0..size).collect();
    order.sort_by(|&a, &b| exponents[b].total_cmp(&exponents[a]));
    Ok(LyapunovSpectrum {
        exponents: order.iter().map(|&j| exponents[j]).collect(),
        standard_error: order.iter().map(|&j| standard_error[j]).collect(),
        running: sums
            .iter()
            .flat_map(|row| order.iter().map(move |&j| row[j]))
            .collect(),
        time,
        impacts: flow.impacts(),
        grazings: flow.grazings().to_vec(),
    })
}
