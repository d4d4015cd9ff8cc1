//! Compile-time sizes for the 0.2 kernel's hot loops. A small system's
//! right-hand side, Runge-Kutta stages and gaps loop over a handful of
//! coordinates: with the sizes as constants the compiler unrolls the loops
//! and drops the bounds checks, which is most of the work at these sizes.

/// Evaluates `$body` with `$n` (structure coordinates) and `$k` (dampers)
/// bound to the system's sizes: as constants for the small sizes (each arm
/// is then compiled on its own, the body being `#[inline(always)]`), as
/// variables otherwise. The same arithmetic in every arm: results do not
/// depend on which one runs.
macro_rules! by_size {
    ($system:expr, |$n:ident, $k:ident| $body:expr) => {
        match ($system.n, $system.k) {
            (1, 0) => {
                let ($n, $k) = (1usize, 0usize);
                $body
            }
            (1, 1) => {
                let ($n, $k) = (1usize, 1usize);
                $body
            }
            (1, 2) => {
                let ($n, $k) = (1usize, 2usize);
                $body
            }
            (2, 0) => {
                let ($n, $k) = (2usize, 0usize);
                $body
            }
            (2, 1) => {
                let ($n, $k) = (2usize, 1usize);
                $body
            }
            (2, 2) => {
                let ($n, $k) = (2usize, 2usize);
                $body
            }
            (3, 0) => {
                let ($n, $k) = (3usize, 0usize);
                $body
            }
            (3, 1) => {
                let ($n, $k) = (3usize, 1usize);
                $body
            }
            (3, 2) => {
                let ($n, $k) = (3usize, 2usize);
                $body
            }
            (4, 0) => {
                let ($n, $k) = (4usize, 0usize);
                $body
            }
            (4, 1) => {
                let ($n, $k) = (4usize, 1usize);
                $body
            }
            (4, 2) => {
                let ($n, $k) = (4usize, 2usize);
                $body
            }
            ($n, $k) => $body,
        }
    };
}
pub(crate) use by_size;
