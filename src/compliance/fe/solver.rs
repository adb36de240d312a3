//! Sparse Cholesky factorisation K_ff = L Lᵀ, block solves and selected solves.
//!
//! A wrapper over faer's supernodal sparse LLᵀ: the symbolic analysis (fill-reducing ordering
//! by approximate minimum degree, elimination tree, supernodes) and the numeric factorisation
//! are done once each. Only the lower triangle of the matrix is read. No regularisation is
//! applied: a pivot ≤ 0 is reported as [`FeError::NotPositiveDefinite`]. With P the ordering
//! (row i of P K Pᵀ is row `fwd[i]` of K) the factor is P K Pᵀ = L Lᵀ, L stored by supernodes:
//! supernode s holds the consecutive columns c₀ … c₁ − 1 of L as one dense block of the rows
//! c₀ … c₁ − 1 (lower triangle L_ss) followed by the rows of its pattern p(s) (L_ps), all
//! pattern rows ≥ c₁.
//!
//! # Block solves ([`SparseCholesky::solve_in_place`])
//! Any number of right-hand-side blocks (n × k, one load case per column) are solved in place by
//! forward and backward substitution over all supernodes.
//!
//! # Selected solves ([`SparseCholesky::solve_selected`])
//! When the loads are non-zero on a few rows only and the displacements are wanted on a few
//! rows only, most of the substitution is work on zeros or on unwanted values:
//!
//! * forward, L y = P f: y is zero on every supernode that is not an ancestor (in the
//!   supernodal elimination tree, parent(s) = the supernode of the first row of p(s)) of a
//!   supernode holding a loaded row, because the update of supernode s only reaches the rows
//!   p(s), which belong to ancestors of s. The forward pass visits the loaded supernodes and
//!   their ancestors, F, in increasing order;
//! * backward, Lᵀ x = y: x on supernode s needs x on p(s) only, i.e. on the ancestors of s.
//!   The backward pass visits the supernodes holding a wanted row and their ancestors, B, in
//!   decreasing order (y = 0 on B ∖ F).
//!
//! Each visit does the same dense operations as the full solve (triangular solve with L_ss,
//! product with L_ps), on the rows of F ∪ B only, stored compactly. The result equals the full
//! solve's on the wanted rows (same operations in the same order on the values that matter,
//! the others being exact zeros); for a load near the wanted rows F and B are a small part of
//! the tree, and the cost falls with them.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltError;
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::perm::PermRef;
use faer::sparse::SparseColMat;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::{Accum, Mat, MatMut, Par, Side};

use super::error::FeError;

/// A numeric sparse Cholesky factor of a symmetric positive definite matrix.
#[derive(Debug)]
pub struct SparseCholesky {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    /// Supernode of each (permuted) column.
    super_of: Vec<usize>,
    /// Parent of each supernode in the supernodal elimination tree (`usize::MAX`: a root).
    parent: Vec<usize>,
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

/// A load case of [`SparseCholesky::solve_selected`]: (row, value) pairs; rows may repeat
/// (the values add).
pub type SparseColumn = Vec<(usize, f64)>;

const NONE: usize = usize::MAX;

impl SparseCholesky {
    /// Factorises the square matrix whose lower triangle (row ≥ column) is stored in `lower`;
    /// entries above the diagonal, if any, are ignored. The ordering is faer's AMD on the
    /// matrix graph.
    pub fn new(lower: &SparseColMat<usize, f64>) -> Result<(Self, FactorTimes), FeError> {
        Self::with_ordering(lower, None)
    }

    /// As [`SparseCholesky::new`] with the elimination order `order` (`order[k]` the row
    /// eliminated k-th, a permutation of 0 … n − 1), or faer's AMD when `None`.
    pub fn with_ordering(
        lower: &SparseColMat<usize, f64>,
        order: Option<&[usize]>,
    ) -> Result<(Self, FactorTimes), FeError> {
        let n = lower.nrows();
        if lower.ncols() != n {
            return Err(FeError::InvalidInput(format!(
                "Cholesky of a non-square {}×{} matrix",
                n,
                lower.ncols()
            )));
        }
        let t0 = std::time::Instant::now();
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let inverse = match order {
            None => None,
            Some(fwd) => {
                if fwd.len() != n {
                    return Err(FeError::InvalidInput(format!(
                        "ordering of {} rows for a matrix of order {n}",
                        fwd.len()
                    )));
                }
                let mut inv = vec![NONE; n];
                for (k, &r) in fwd.iter().enumerate() {
                    if r >= n || inv[r] != NONE {
                        return Err(FeError::InvalidInput(format!(
                            "ordering: row {r} out of range or repeated"
                        )));
                    }
                    inv[r] = k;
                }
                Some(inv)
            }
        };
        let ordering = match (order, &inverse) {
            (Some(fwd), Some(inv)) => SymmetricOrdering::Custom(PermRef::new_checked(fwd, inv, n)),
            _ => SymmetricOrdering::Amd,
        };
        let symbolic = factorize_symbolic_cholesky(lower.symbolic(), Side::Lower, ordering, params)
            .map_err(|e| FeError::Solver(format!("symbolic Cholesky: {e:?}")))?;
        let SymbolicCholeskyRaw::Supernodal(sn) = symbolic.raw() else {
            return Err(FeError::Solver(
                "internal: simplicial factor where supernodal forced".into(),
            ));
        };
        let ns = sn.n_supernodes();
        let mut super_of = vec![NONE; n];
        let mut parent = vec![NONE; ns];
        for s in 0..ns {
            let (b, e) = (sn.supernode_begin()[s], sn.supernode_end()[s]);
            super_of[b..e].fill(s);
        }
        for (s, p) in parent.iter_mut().enumerate() {
            let start = sn.col_ptr_for_row_idx()[s];
            if sn.nnz_per_super()[s] > 0 {
                *p = super_of[sn.row_idx()[start]];
            }
        }
        let t1 = std::time::Instant::now();
        let len = symbolic.len_val();
        let mut values = Vec::new();
        values.try_reserve_exact(len).map_err(|_| {
            FeError::Solver(format!("Cholesky factor of {len} values does not fit in memory"))
        })?;
        values.resize(len, 0.0);
        let mut mem = MemBuffer::try_new(
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
        )
        .map_err(|_| FeError::Solver("Cholesky workspace does not fit in memory".into()))?;
        symbolic
            .factorize_numeric_llt(
                &mut values,
                lower.as_ref(),
                Side::Lower,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|LltError::NonPositivePivot { index }| FeError::NotPositiveDefinite {
                pivot: index,
            })?;
        let t2 = std::time::Instant::now();
        let times =
            FactorTimes { symbolic_s: (t1 - t0).as_secs_f64(), numeric_s: (t2 - t1).as_secs_f64() };
        Ok((Self { symbolic, values, super_of, parent, n }, times))
    }

    /// Order n of the factorised matrix.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Number of stored values of L.
    pub fn factor_len(&self) -> usize {
        self.values.len()
    }

    /// Overwrites the n × k block `rhs` with K⁻¹·rhs. Error: `rhs` has ≠ n rows.
    pub fn solve_in_place(&self, rhs: MatMut<'_, f64>) -> Result<(), FeError> {
        if rhs.nrows() != self.n {
            return Err(FeError::LoadShape { rows: rhs.nrows(), expected: self.n });
        }
        let k = rhs.ncols();
        let mut mem = MemBuffer::try_new(self.symbolic.solve_in_place_scratch::<f64>(k, Par::Seq))
            .map_err(|_| FeError::Solver("solve workspace does not fit in memory".into()))?;
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            faer::Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(&mut mem),
        );
        Ok(())
    }

    /// (K⁻¹·F)[wanted, :] for the n × k load block F whose column c is given sparsely by
    /// `loads[c]` (see the module docs, "Selected solves"): row i of the result is row
    /// `wanted[i]` of the solution. Errors: a row ≥ n.
    pub fn solve_selected(
        &self,
        loads: &[SparseColumn],
        wanted: &[usize],
    ) -> Result<Mat<f64>, FeError> {
        let n = self.n;
        let k = loads.len();
        let bad =
            loads.iter().flatten().map(|&(r, _)| r).chain(wanted.iter().copied()).find(|&r| r >= n);
        if let Some(r) = bad {
            return Err(FeError::InvalidInput(format!("selected solve: row {r} ≥ n = {n}")));
        }
        let SymbolicCholeskyRaw::Supernodal(sn) = self.symbolic.raw() else {
            return Err(FeError::Solver("internal: factor is not supernodal".into()));
        };
        let inv: Option<&[usize]> = self.symbolic.perm().map(|p| p.arrays().1);
        let pos = |r: usize| inv.map_or(r, |v| v[r]);
        let ns = sn.n_supernodes();
        // Ancestor closures: 1 = forward set F, 2 = backward set B.
        let mut mark = vec![0u8; ns];
        let close = |start: usize, bit: u8, mark: &mut [u8]| {
            let mut s = self.super_of[start];
            while s != NONE && mark[s] & bit == 0 {
                mark[s] |= bit;
                s = self.parent[s];
            }
        };
        for &(r, _) in loads.iter().flatten() {
            close(pos(r), 1, &mut mark);
        }
        for &r in wanted {
            close(pos(r), 2, &mut mark);
        }
        // Compact rows: the columns of the visited supernodes, in supernode order.
        let mut slot = vec![NONE; n];
        let mut rows = 0usize;
        for s in (0..ns).filter(|&s| mark[s] != 0) {
            for v in &mut slot[sn.supernode_begin()[s]..sn.supernode_end()[s]] {
                *v = rows;
                rows += 1;
            }
        }
        let mut x = Mat::<f64>::zeros(rows, k);
        for (c, col) in loads.iter().enumerate() {
            for &(r, v) in col {
                x[(slot[pos(r)], c)] += v;
            }
        }
        let l = SupernodalLltRef::new(sn, &self.values);
        let mut tmp = Mat::<f64>::zeros(0, k);
        for s in (0..ns).filter(|&s| mark[s] & 1 != 0) {
            let node = l.supernode(s);
            let size = node.val().ncols();
            let (top, bot) = node.val().split_at_row(size);
            let base = slot[node.start()];
            let mut xs = x.as_mut().subrows_mut(base, size);
            solve_lower_triangular_in_place(top, xs.as_mut(), Par::Seq);
            let pat = node.pattern();
            tmp.resize_with(pat.len(), k, |_, _| 0.0);
            matmul(tmp.as_mut(), Accum::Replace, bot, xs.as_ref(), 1.0, Par::Seq);
            for j in 0..k {
                for (i, &r) in pat.iter().enumerate() {
                    x[(slot[r], j)] -= tmp[(i, j)];
                }
            }
        }
        for s in (0..ns).rev().filter(|&s| mark[s] & 2 != 0) {
            let node = l.supernode(s);
            let size = node.val().ncols();
            let (top, bot) = node.val().split_at_row(size);
            let base = slot[node.start()];
            let pat = node.pattern();
            tmp.resize_with(pat.len(), k, |_, _| 0.0);
            for j in 0..k {
                for (i, &r) in pat.iter().enumerate() {
                    tmp[(i, j)] = x[(slot[r], j)];
                }
            }
            let mut xs = x.as_mut().subrows_mut(base, size);
            matmul(xs.as_mut(), Accum::Add, bot.transpose(), tmp.as_ref(), -1.0, Par::Seq);
            solve_upper_triangular_in_place(top.transpose(), xs.as_mut(), Par::Seq);
        }
        let mut out = Mat::<f64>::zeros(wanted.len(), k);
        for (i, &r) in wanted.iter().enumerate() {
            let si = slot[pos(r)];
            for j in 0..k {
                out[(i, j)] = x[(si, j)];
            }
        }
        Ok(out)
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

    /// 2D Laplacian (5-point) on an m × m grid, lower triangle.
    fn laplacian(m: usize) -> SparseColMat<usize, f64> {
        let n = m * m;
        let mut t = Vec::new();
        for j in 0..m {
            for i in 0..m {
                let k = j * m + i;
                t.push(Triplet::new(k, k, 4.0));
                if i + 1 < m {
                    t.push(Triplet::new(k + 1, k, -1.0));
                }
                if j + 1 < m {
                    t.push(Triplet::new(k + m, k, -1.0));
                }
            }
        }
        SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).expect("matrix")
    }

    #[test]
    fn selected_solves_equal_whole_solves_for_any_ordering() {
        let m = 12;
        let n = m * m;
        let k = laplacian(m);
        let reversed: Vec<usize> = (0..n).rev().collect();
        for order in [None, Some(&reversed[..])] {
            let (chol, _) = SparseCholesky::with_ordering(&k, order).expect("spd");
            let loads = vec![vec![(5, 1.0)], vec![(77, -2.0), (78, 0.5), (77, 1.0)], vec![]];
            let wanted = [0, 5, 77, 140, 143, 5];
            let x = chol.solve_selected(&loads, &wanted).expect("selected");
            let mut b = Mat::<f64>::zeros(n, loads.len());
            for (c, col) in loads.iter().enumerate() {
                for &(r, v) in col {
                    b[(r, c)] += v;
                }
            }
            chol.solve_in_place(b.as_mut()).expect("whole");
            for (i, &r) in wanted.iter().enumerate() {
                for c in 0..loads.len() {
                    assert!((x[(i, c)] - b[(r, c)]).abs() <= 1e-14, "row {r}, case {c}");
                }
            }
            assert!(chol.solve_selected(&loads, &[n]).is_err());
            assert!(chol.solve_selected(&[vec![(n, 1.0)]], &wanted).is_err());
        }
        assert!(SparseCholesky::with_ordering(&k, Some(&[0, 1])).is_err());
        let mut repeated: Vec<usize> = (0..n).collect();
        repeated[1] = 0;
        assert!(SparseCholesky::with_ordering(&k, Some(&repeated)).is_err());
    }
}
