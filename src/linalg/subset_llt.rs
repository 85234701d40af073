//! The Cholesky factor of a principal submatrix `S_AA` of a symmetric positive definite matrix
//! `S` that is never formed, kept up to date as the index set A changes by a few indices.
//!
//! The pair-space contact problem of the error estimate solves `(I + k_n F_AA) g_A = ĝ_A` for
//! an active set A that changes a little from one output time to the next; on a refined mesh
//! A holds thousands of pairs, and a fresh factorization per output (|A|³/3 flops, 9 Gflop at
//! 3 000 pairs) is the whole cost. The factor of the new set follows from the old one:
//!
//! - **Removing** a set D of positions: with `S = L Lᵀ`, the kept principal submatrix is
//!   `S_KK = L_K Lᵀ_K` (`L_K` the kept rows of L). Splitting `L_K` into its kept columns `L'`
//!   (lower triangular: rows and columns of a triangular matrix removed alike) and its D columns
//!   `W` gives `S_KK = L' L'ᵀ + W Wᵀ`, a rank-|D| update of `L'` (faer's
//!   `rank_r_update_clobber`, stable for a positive update). Rows of W above the first removed
//!   position are zero, so only the trailing block is updated.
//! - **Appending** a set N of indices at the end: `X = L⁻¹ S_{A,N}` (one triangular solve with
//!   |N| right-hand sides), `L_NN = chol(S_NN − Xᵀ X)`, and the factor of `[A, N]` is
//!   `[[L, 0], [Xᵀ, L_NN]]`.
//!
//! The order of the indices in the factor is its own (appended at the end), not sorted. A change
//! larger than [`REFACTOR_FRACTION`] of the set refactors from scratch.

use faer::linalg::cholesky::llt::update::rank_r_update_clobber;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Mat, MatMut, Par, Side};

use crate::linalg::LinalgError;

/// A change of more than this fraction of the set's size (removed plus added indices)
/// refactors from scratch instead of updating.
pub const REFACTOR_FRACTION: f64 = 0.25;

/// The Cholesky factor `L` (`S_AA = L Lᵀ`) of a principal submatrix of an implicit SPD matrix
/// (module docs).
#[derive(Clone, Debug)]
pub struct SubsetLlt {
    /// The indices of A in the factor's order.
    order: Vec<usize>,
    /// The lower-triangular factor (|A| × |A|; the strict upper triangle is zero).
    l: Mat<f64>,
}

impl Default for SubsetLlt {
    fn default() -> SubsetLlt {
        SubsetLlt::new()
    }
}

impl SubsetLlt {
    /// An empty factor (A = ∅).
    pub fn new() -> SubsetLlt {
        SubsetLlt {
            order: Vec::new(),
            l: Mat::zeros(0, 0),
        }
    }

    /// The indices of A in the factor's order (the order of [`SubsetLlt::solve_in_place`]).
    pub fn order(&self) -> &[usize] {
        &self.order
    }

    /// Makes this the factor of `S_AA` for the index set `set` (any order, no repeats), with
    /// `entry(i, j) = S_ij` for indices i, j of the whole matrix. Reuses the current factor by
    /// removing and appending indices (module docs) unless the change is large.
    ///
    /// # Errors
    /// `S_AA` (or a Schur complement on the way) is not positive definite; the factor is then
    /// empty.
    pub fn update(
        &mut self,
        set: &[usize],
        entry: impl Fn(usize, usize) -> f64,
    ) -> Result<(), LinalgError> {
        let size = set.iter().copied().max().map_or(0, |m| m + 1);
        let upto = size.max(self.order.iter().copied().max().map_or(0, |m| m + 1));
        let mut wanted = vec![false; upto];
        for &i in set {
            wanted[i] = true;
        }
        let mut held = vec![false; upto];
        for &i in &self.order {
            held[i] = true;
        }
        let removed: Vec<usize> = (0..self.order.len())
            .filter(|&p| !wanted[self.order[p]])
            .collect();
        let added: Vec<usize> = set.iter().copied().filter(|&i| !held[i]).collect();
        if removed.is_empty() && added.is_empty() {
            return Ok(());
        }
        let change = (removed.len() + added.len()) as f64;
        let result = if self.order.is_empty() || change > REFACTOR_FRACTION * set.len() as f64 {
            self.refactor(set, &entry)
        } else {
            self.remove(&removed)
                .and_then(|()| self.append(&added, &entry))
        };
        if result.is_err() {
            *self = SubsetLlt::new();
        }
        result
    }

    /// Solves `S_AA x = b` in place, `b` and `x` in the factor's order ([`SubsetLlt::order`]).
    pub fn solve_in_place(&self, b: &mut [f64]) {
        let n = self.order.len();
        let mut rhs = MatMut::from_column_major_slice_mut(&mut b[..n], n, 1);
        solve_lower_triangular_in_place(self.l.as_ref(), rhs.as_mut(), Par::Seq);
        solve_upper_triangular_in_place(self.l.as_ref().transpose(), rhs, Par::Seq);
    }

    /// A fresh factorization of `S_AA`.
    fn refactor(
        &mut self,
        set: &[usize],
        entry: &impl Fn(usize, usize) -> f64,
    ) -> Result<(), LinalgError> {
        let n = set.len();
        let s = Mat::from_fn(n, n, |i, j| entry(set[i], set[j]));
        let llt = s.llt(Side::Lower).map_err(|e| LinalgError::Factorization {
            step: format!("Cholesky of a {n}×{n} principal submatrix"),
            source: Box::new(e),
        })?;
        self.l = llt.L().to_owned();
        self.order = set.to_vec();
        Ok(())
    }

    /// Removes the positions `removed` (ascending) by one rank-|D| update (module docs).
    fn remove(&mut self, removed: &[usize]) -> Result<(), LinalgError> {
        let Some(&first) = removed.first() else {
            return Ok(());
        };
        let n = self.order.len();
        let mut gone = vec![false; n];
        for &p in removed {
            gone[p] = true;
        }
        let keep: Vec<usize> = (0..n).filter(|&p| !gone[p]).collect();
        let m = keep.len();
        // W: the removed columns at the kept rows; zero above row `first` (of the kept rows,
        // `first` of them precede the first removed position).
        let mut w = Mat::from_fn(m - first, removed.len(), |i, d| {
            self.l[(keep[first + i], removed[d])]
        });
        // L': the kept rows and columns moved up and left in place (module docs, "Removing").
        // Every source position is at or below and right of its destination, and the
        // destinations are written in ascending order, so no source is overwritten before it
        // is read. The first `first` columns keep their position; only their rows move.
        let l = &mut self.l;
        for (jj, &j) in keep.iter().enumerate() {
            let from = if jj < first { first } else { jj };
            for (ii, &i) in keep.iter().enumerate().skip(from) {
                l[(ii, jj)] = l[(i, j)];
            }
        }
        l.truncate(m, m);
        let mut alpha = Mat::<f64>::from_fn(removed.len(), 1, |_, _| 1.0);
        rank_r_update_clobber(
            l.as_mut().submatrix_mut(first, first, m - first, m - first),
            w.as_mut(),
            alpha.as_mut().col_mut(0).as_diagonal_mut(),
        )
        .map_err(|e| LinalgError::Factorization {
            step: format!(
                "Cholesky downdate removing {} of {n} indices",
                removed.len()
            ),
            source: Box::new(e),
        })?;
        self.order = keep.iter().map(|&p| self.order[p]).collect();
        Ok(())
    }

    /// Appends the indices `added` at the end of the factor (module docs).
    fn append(
        &mut self,
        added: &[usize],
        entry: &impl Fn(usize, usize) -> f64,
    ) -> Result<(), LinalgError> {
        if added.is_empty() {
            return Ok(());
        }
        let (n, a) = (self.order.len(), added.len());
        let mut x = Mat::from_fn(n, a, |i, j| entry(self.order[i], added[j]));
        solve_lower_triangular_in_place(self.l.as_ref(), x.as_mut(), Par::Seq);
        let s_nn = Mat::from_fn(a, a, |i, j| entry(added[i], added[j]));
        let schur = &s_nn - x.transpose() * &x;
        let llt = schur
            .llt(Side::Lower)
            .map_err(|e| LinalgError::Factorization {
                step: format!("Cholesky of the Schur complement appending {a} to {n} indices"),
                source: Box::new(e),
            })?;
        let l22 = llt.L();
        let mut l = Mat::<f64>::zeros(n + a, n + a);
        l.as_mut().submatrix_mut(0, 0, n, n).copy_from(&self.l);
        l.as_mut()
            .submatrix_mut(n, 0, a, n)
            .copy_from(x.transpose());
        l.as_mut().submatrix_mut(n, n, a, a).copy_from(l22);
        self.l = l;
        self.order.extend_from_slice(added);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An SPD matrix on 40 indices: diagonally dominant with smooth couplings.
    fn entry(i: usize, j: usize) -> f64 {
        let d = (i as f64 - j as f64).abs();
        let base = 1.0 / (1.0 + d) + 0.1 * ((i * 7 + j * 7) % 5) as f64 / 5.0;
        if i == j {
            base + 50.0
        } else {
            base
        }
    }

    fn solve_direct(set: &[usize], b: &[f64]) -> Vec<f64> {
        let n = set.len();
        let s = Mat::from_fn(n, n, |i, j| entry(set[i], set[j]));
        let rhs = Mat::from_fn(n, 1, |i, _| b[i]);
        let x = s.llt(Side::Lower).unwrap().solve(&rhs);
        (0..n).map(|i| x[(i, 0)]).collect()
    }

    use faer::linalg::solvers::Solve;

    /// A sequence of sets (small changes: updates; large: refactors) solves as a fresh
    /// factorization of each set does, to round-off.
    #[test]
    fn updated_factor_solves_like_a_fresh_one() {
        let sets: Vec<Vec<usize>> = vec![
            (0..20).collect(),
            (0..20).filter(|i| i % 7 != 3).collect(),
            (0..20).filter(|i| i % 7 != 3).chain([25, 31]).collect(),
            (1..20).chain([25, 31, 33]).collect(),
            vec![2, 5, 39],
            (0..40).collect(),
            (0..40).filter(|i| *i != 0 && *i != 39).collect(),
        ];
        let mut f = SubsetLlt::new();
        for set in &sets {
            f.update(set, entry).unwrap();
            let mut held = f.order().to_vec();
            held.sort_unstable();
            let mut want = set.clone();
            want.sort_unstable();
            assert_eq!(held, want);
            let b: Vec<f64> = f.order().iter().map(|&i| (i as f64).sin()).collect();
            let mut x = b.clone();
            f.solve_in_place(&mut x);
            let direct = solve_direct(f.order(), &b);
            for (a, d) in x.iter().zip(&direct) {
                assert!((a - d).abs() <= 1e-13 * (1.0 + d.abs()), "{a} vs {d}");
            }
        }
    }

    /// A set that is not positive definite is an error, and leaves an empty factor.
    #[test]
    fn indefinite_subset_is_an_error() {
        let mut f = SubsetLlt::new();
        let bad = |i: usize, j: usize| if i == j { -1.0 } else { 0.0 };
        assert!(f.update(&[1, 2], bad).is_err());
        assert!(f.order().is_empty());
    }
}
