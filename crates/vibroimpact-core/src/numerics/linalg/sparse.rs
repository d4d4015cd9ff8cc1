//! A matrix's rows by their non-zero entries: the transforms and the
//! interactions' rows of a system with many loose masses (ten particles in a
//! column: each pair's row touches two of eleven coordinates, each free
//! mass's mode one) are mostly zeros, and a product over the zeros is most
//! of an event's arithmetic.

/// The non-zero entries of a row-major matrix, row by row, each row's in
/// the order of its columns: a product over a row sums the same non-zero
/// terms in the same order as the dense one, the zeros' terms left out (a
/// zero term changes a non-zero sum by nothing).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SparseRows {
    /// Where each row's entries start in `columns` and `values`, and one
    /// past the last row's.
    starts: Vec<usize>,
    columns: Vec<usize>,
    values: Vec<f64>,
}

impl SparseRows {
    /// The rows of the `rows x columns` row-major `dense`.
    pub fn new(dense: &[f64], rows: usize, columns: usize) -> Self {
        let mut sparse = Self {
            starts: Vec::with_capacity(rows + 1),
            ..Self::default()
        };
        sparse.starts.push(0);
        for row in dense[..rows * columns]
            .chunks_exact(columns.max(1))
            .take(rows)
        {
            for (c, &v) in row.iter().enumerate() {
                if v != 0.0 {
                    sparse.columns.push(c);
                    sparse.values.push(v);
                }
            }
            sparse.starts.push(sparse.columns.len());
        }
        sparse.starts.resize(rows + 1, sparse.columns.len());
        sparse
    }

    /// Row `i`'s columns and values.
    #[inline(always)]
    pub fn row(&self, i: usize) -> (&[usize], &[f64]) {
        let (a, b) = (self.starts[i], self.starts[i + 1]);
        (&self.columns[a..b], &self.values[a..b])
    }

    /// The entries kept, of all rows.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether no entry is non-zero.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each row's products equal the dense ones, with the zeros left out.
    #[test]
    fn rows_hold_the_non_zero_entries_in_order() {
        crate::testing::timeout(5, || {
            let dense = [1.5, 0.0, -2.0, 0.0, 0.0, 0.0, 0.0, 3.0, 0.25];
            let sparse = SparseRows::new(&dense, 3, 3);
            assert_eq!(sparse.len(), 4);
            assert_eq!(sparse.row(0), (&[0usize, 2][..], &[1.5, -2.0][..]));
            assert_eq!(sparse.row(1), (&[][..], &[][..]));
            assert_eq!(sparse.row(2), (&[1usize, 2][..], &[3.0, 0.25][..]));
            let x = [0.3, -7.0, 1.1];
            for i in 0..3 {
                let dense_sum: f64 = (0..3).map(|c| dense[3 * i + c] * x[c]).sum();
                let (columns, values) = sparse.row(i);
                let sparse_sum: f64 = columns.iter().zip(values).map(|(c, v)| v * x[*c]).sum();
                assert_eq!(dense_sum, sparse_sum);
            }
            let none = SparseRows::new(&[], 0, 4);
            assert!(none.is_empty());
        });
    }
}
