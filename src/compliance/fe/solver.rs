//! Sparse Cholesky factorisation K_ff = L Lᵀ and block solves.
//!
//! A thin wrapper over faer's sparse LLᵀ: the symbolic analysis (fill-reducing ordering,
//! elimination tree, supernodes) and the numeric factorisation are done once each; any number
//! of right-hand-side blocks (n × k, one load case per column) are then solved in place by
//! forward and backward substitution. Only the lower triangle of the matrix is read. No
//! regularisation is applied: a pivot ≤ 0 is reported as [`FeError::NotPositiveDefinite`].

use faer::MatMut;
use faer::Side;
use faer::linalg::solvers::Solve;
use faer::sparse::SparseColMat;
use faer::sparse::linalg::LltError;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};

use super::error::FeError;

/// A numeric sparse Cholesky factor of a symmetric positive definite matrix.
#[derive(Debug, Clone)]
pub struct SparseCholesky {
    llt: Llt<usize, f64>,
    n: usize,
}

/// Wall-clock times of the two factorisation phases, s.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FactorTimes {
    /// Symbolic analysis (ordering, elimination tree, supernode structure), s.
    pub symbolic_s: f64,
    /// Numeric factorisation, s.
    pub numeric_s: f64,
}

impl SparseCholesky {
    /// Factorises the square matrix whose lower triangle (row ≥ column) is stored in `lower`;
    /// entries above the diagonal, if any, are ignored.
    pub fn new(lower: &SparseColMat<usize, f64>) -> Result<(Self, FactorTimes), FeError> {
        let n = lower.nrows();
        if lower.ncols() != n {
            return Err(FeError::InvalidInput(format!(
                "Cholesky of a non-square {}×{} matrix",
                n,
                lower.ncols()
            )));
        }
        let t0 = std::time::Instant::now();
        let symbolic = SymbolicLlt::try_new(lower.symbolic(), Side::Lower)
            .map_err(|e| FeError::Solver(format!("symbolic Cholesky: {e:?}")))?;
        let t1 = std::time::Instant::now();
        let llt = Llt::try_new_with_symbolic(symbolic, lower.as_ref(), Side::Lower).map_err(
            |e| match e {
                LltError::Numeric(
                    faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index },
                ) => FeError::NotPositiveDefinite { pivot: index },
                LltError::Generic(g) => FeError::Solver(format!("numeric Cholesky: {g:?}")),
            },
        )?;
        let t2 = std::time::Instant::now();
        let times =
            FactorTimes { symbolic_s: (t1 - t0).as_secs_f64(), numeric_s: (t2 - t1).as_secs_f64() };
        Ok((Self { llt, n }, times))
    }

    /// Order n of the factorised matrix.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Overwrites the n × k block `rhs` with K⁻¹·rhs. Error: `rhs` has ≠ n rows.
    pub fn solve_in_place(&self, rhs: MatMut<'_, f64>) -> Result<(), FeError> {
        if rhs.nrows() != self.n {
            return Err(FeError::LoadShape { rows: rhs.nrows(), expected: self.n });
        }
        self.llt.solve_in_place(rhs);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;
    use faer::sparse::Triplet;

    #[test]
    fn solves_a_tridiagonal_system_and_rejects_an_indefinite_one() {
        // Lower triangle of tridiag(-1, 2, -1), n = 5.
        let n = 5;
        let mut t = Vec::new();
        for i in 0..n {
            t.push(Triplet::new(i, i, 2.0));
            if i + 1 < n {
                t.push(Triplet::new(i + 1, i, -1.0));
            }
        }
        let k = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).expect("matrix");
        let (chol, _) = SparseCholesky::new(&k).expect("spd");
        // x = (1..=5) → b = K x.
        let x: Vec<f64> = (1..=n).map(|i| i as f64).collect();
        let mut b = Mat::<f64>::zeros(n, 2);
        for i in 0..n {
            let mut v = 2.0 * x[i];
            if i > 0 {
                v -= x[i - 1];
            }
            if i + 1 < n {
                v -= x[i + 1];
            }
            b[(i, 0)] = v;
            b[(i, 1)] = -2.0 * v;
        }
        chol.solve_in_place(b.as_mut()).expect("solve");
        for i in 0..n {
            assert!((b[(i, 0)] - x[i]).abs() < 1e-12);
            assert!((b[(i, 1)] + 2.0 * x[i]).abs() < 1e-12);
        }
        assert!(chol.solve_in_place(Mat::<f64>::zeros(4, 1).as_mut()).is_err());
        t[0] = Triplet::new(0, 0, -2.0);
        let bad = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).expect("matrix");
        assert!(matches!(SparseCholesky::new(&bad), Err(FeError::NotPositiveDefinite { .. })));
    }
}
