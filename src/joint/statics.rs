//! Frictionless penalty contact statics, solved exactly by an active-set Newton method.
//!
//! The paper's static computations (Witteveen & Pichler 2014, Sections 4.1.2 and 4.2.2) load the
//! structure at the master node with friction switched off and compare the Euclidean norm of the
//! contact force vector `f_c` (one entry per joint node-pair) between the full and the reduced
//! models. The contact law is the paper's node-to-node penalty model (Section 3): a pair `i` with
//! normal gap `g_i = b_i q < 0` (penetration) carries a spring of stiffness `k_n` (N/mm),
//! a gaping pair (`g_i ≥ 0`) none. The pair contact force is
//!
//! ```text
//! p_i = k_n · min(g_i, 0)        (N; compressive negative)
//! ```
//!
//! and static equilibrium reads `K q + B_nᵀ p = f`, i.e. the contact forces act on the structure
//! as `−B_nᵀ p` (with [`crate::joint`]'s sign convention the pair force pulling the upper node in
//! +y is `−p_i ≥ 0`).
//!
//! ## Why the solution is exact
//!
//! The law is piecewise linear: for a fixed set `A` of active (penetrating) pairs the equilibrium
//! is the linear system
//!
//! ```text
//! (K + k_n Σ_{i∈A} b_iᵀ b_i) q = f .
//! ```
//!
//! The active-set Newton method ([`active_set_newton`]) solves it, recomputes the gaps, takes
//! `A ← {i : g_i < 0}` and repeats until `A` stops changing. At termination the set is
//! self-consistent — every active pair has `g < 0`, every inactive pair `g ≥ 0` — so the last
//! linear solution satisfies the nonlinear equilibrium up to round-off: there is no Newton
//! tolerance. This is semismooth Newton on the convex energy
//! `½ qᵀK q − fᵀq + ½ k_n Σ min(g_i, 0)²`; it normally converges in a few steps, but it is not
//! globally guaranteed to, so visited active sets are remembered and a repeat is reported as an
//! error naming the cycle length, and the number of linear solves is capped.
//!
//! ## Starting set
//!
//! [`ActiveStart::Open`] (the default) starts with no pair active: the first iterate is the
//! linear solution of the undeformed structure, the same reference state the paper's modes use.
//! [`ActiveStart::Closed`] starts with all pairs active (the joint glued in the normal direction).
//!
//! ## Full and reduced models
//!
//! - [`crate::model::contact_static_full`] / [`contact_static_sparse`]: the sparse `K` of the model. The
//!   matrix `K + K_c` changes values but not pattern, so the union pattern of `K` and every
//!   pair's coupling `b_iᵀ b_i` and its symbolic Cholesky factorization (AMD ordering) are built
//!   once; each iteration refills the values and refactors numerically.
//! - [`contact_static_reduced`]: any dense reduced system `K_r = Φᵀ K Φ`, `f_r = Φᵀ f` with the
//!   normal rows `B_n Φ` (see [`crate::joint::JointOperator::reduce`]), dense Cholesky per
//!   iteration. Nothing here depends on how Φ was built.
//!
//! Both refine each solve twice with a double-double residual (see `REFINEMENT_STEPS`), so
//! the result is the solution of the assembled system to nearly working precision despite
//! cond(K) ≈ 1e10, and the full and a Φ = I reduced solution agree to round-off.

use std::collections::HashMap;

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Mat, MatRef, Side};

use crate::error::{Error, JointError};
use crate::joint::{JointOperator, NORMAL};
use crate::linalg::compensated::{Dot2, REFINEMENT_STEPS};
use crate::linalg::sparse::column_pattern;
use crate::linalg::LinalgError;
use crate::linalg::SymCsc;

/// Which pairs are active in the first linear solve.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ActiveStart {
    /// No pair active: the first iterate is the linear (contact-free) solution. Default.
    #[default]
    Open,
    /// Every pair active: the first iterate has the joint closed by the penalty springs.
    Closed,
}

/// Options of the active-set Newton iteration.
///
/// Defaults: `max_iterations = 100`, `start = ActiveStart::Open`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ContactOptions {
    /// Maximum number of linear solves (≥ 1). Exceeding it is an error.
    pub max_iterations: usize,
    /// The starting active set.
    pub start: ActiveStart,
}

impl Default for ContactOptions {
    fn default() -> Self {
        ContactOptions {
            max_iterations: 100,
            start: ActiveStart::Open,
        }
    }
}

/// The converged contact state of `w` pairs.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactState {
    /// Normal gaps `g = B_n q` (mm), negative = penetration.
    pub gaps: Vec<f64>,
    /// Pair contact forces `p = k_n min(g, 0)` (N, compressive negative; zero for open pairs).
    pub forces: Vec<f64>,
    /// Active (penetrating, `g < 0`) pairs.
    pub active: Vec<bool>,
    /// `‖f_c‖₂`, the Euclidean norm of `forces` (N) — the paper's convergence measure.
    pub contact_force_norm: f64,
    /// Number of active pairs.
    pub pairs_in_contact: usize,
    /// Number of linear solves performed (the last one with the converged set).
    pub iterations: usize,
    /// Number of active pairs used in each linear solve, in order.
    pub active_counts: Vec<usize>,
}

/// A full-model contact static solution.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactSolution {
    /// All independent DOF (mm, rad).
    pub displacement: Vec<f64>,
    /// The master node `[ux, uy, uz (mm), rx, ry, rz (rad)]`.
    pub master_displacement: [f64; 6],
    /// Gaps, forces and the active set.
    pub state: ContactState,
}

/// The generic active-set Newton driver for `pairs` contact pairs with penalty `k_n` (N/mm).
///
/// `solve(active, gaps)` must solve the linear system with the springs of the `active` pairs and
/// write all pairs' normal gaps (mm) into `gaps`; it keeps its own solution vector, which on
/// success belongs to the returned (converged) active set, since the last call is made with it.
///
/// Errors: invalid `k_n` or options ([`Error::Joint`]), a failure of `solve`, non-finite gaps,
/// a revisited active set (cycle) or more than `opts.max_iterations` solves
/// ([`Error::LinearAlgebra`]).
pub fn active_set_newton<S>(
    pairs: usize,
    k_n: f64,
    opts: &ContactOptions,
    mut solve: S,
) -> Result<ContactState, Error>
where
    S: FnMut(&[bool], &mut [f64]) -> Result<(), Error>,
{
    if !(k_n.is_finite() && k_n > 0.0) {
        return Err(JointError::NormalStiffness { k_n }.into());
    }
    if opts.max_iterations == 0 {
        return Err(JointError::NoIterations.into());
    }
    let mut active = vec![opts.start == ActiveStart::Closed; pairs];
    let mut gaps = vec![0.0; pairs];
    // Active set → the iteration (1-based) that solved with it.
    let mut visited: HashMap<Vec<bool>, usize> = HashMap::new();
    let mut active_counts = Vec::new();
    for it in 1..=opts.max_iterations {
        visited.insert(active.clone(), it);
        active_counts.push(active.iter().filter(|&&a| a).count());
        solve(&active, &mut gaps)?;
        if let Some(i) = gaps.iter().position(|g| !g.is_finite()) {
            return Err(Error::LinearAlgebra(LinalgError::GapNotFinite {
                context: format!("contact iteration {it}"),
                pair: i,
                value: Some(gaps[i]),
            }));
        }
        let next: Vec<bool> = gaps.iter().map(|&g| g < 0.0).collect();
        if next == active {
            let forces: Vec<f64> = gaps
                .iter()
                .zip(&active)
                .map(|(&g, &a)| if a { k_n * g } else { 0.0 })
                .collect();
            let contact_force_norm = forces.iter().map(|p| p * p).sum::<f64>().sqrt();
            let pairs_in_contact = active.iter().filter(|&&a| a).count();
            return Ok(ContactState {
                gaps,
                forces,
                active,
                contact_force_norm,
                pairs_in_contact,
                iterations: it,
                active_counts,
            });
        }
        if let Some(&first) = visited.get(&next) {
            let len = it + 1 - first;
            return Err(Error::LinearAlgebra(LinalgError::ActiveSetCycle {
                iteration: it,
                in_contact: next.iter().filter(|&&a| a).count(),
                first,
                length: len,
            }));
        }
        active = next;
    }
    let last = active_counts.last().copied().unwrap_or(0);
    Err(Error::LinearAlgebra(LinalgError::ActiveSetNotConverged {
        iterations: opts.max_iterations,
        last,
        pairs,
    }))
}

/// Frictionless penalty contact statics of a sparse system `K q = f − B_nᵀ p` with the normal
/// rows of `joint`. Returns `q` (length n) and the contact state.
pub fn contact_static_sparse(
    k: &SymCsc,
    joint: &JointOperator,
    f: &[f64],
    k_n: f64,
    opts: &ContactOptions,
) -> Result<(Vec<f64>, ContactState), Error> {
    let n = k.n;
    if joint.dofs() != n || f.len() != n {
        return Err(JointError::StaticsSizes {
            n,
            joint_dofs: joint.dofs(),
            load: f.len(),
        }
        .into());
    }
    let pattern = ContactPattern::new(k, joint)?;
    let mut values = vec![0.0; pattern.row_idx.len()];
    let mut rhs = Mat::<f64>::zeros(n, 1);
    let mut q = vec![0.0; n];
    let mut acc = vec![Dot2::default(); n];
    let state = active_set_newton(joint.pairs(), k_n, opts, |active, gaps| {
        pattern.fill_into(k, k_n, active, &mut values);
        let mat = SparseColMatRef::new(pattern.symbolic_matrix.as_ref(), &values);
        let llt = Llt::try_new_with_symbolic(pattern.symbolic_llt.clone(), mat, Side::Lower)
            .map_err(|e| {
                Error::LinearAlgebra(LinalgError::NotPositiveDefinite {
                    what: format!(
                        "K + K_c ({n}×{n}, {} pairs active)",
                        active.iter().filter(|&&a| a).count()
                    ),
                    hint: "",
                    source: Box::new(e),
                })
            })?;
        for i in 0..n {
            rhs[(i, 0)] = f[i];
        }
        llt.solve_in_place(rhs.as_mut());
        for i in 0..n {
            q[i] = rhs[(i, 0)];
        }
        for _ in 0..REFINEMENT_STEPS {
            pattern.residual_into(&values, f, &q, &mut acc, &mut rhs);
            llt.solve_in_place(rhs.as_mut());
            for i in 0..n {
                q[i] += rhs[(i, 0)];
            }
        }
        joint.gaps(&q, gaps);
        Ok(())
    })?;
    Ok((q, state))
}

/// Frictionless penalty contact statics of a dense reduced system
/// `(K_r + k_n Σ_active (B_n Φ)_iᵀ (B_n Φ)_i) η = f_r`.
///
/// `k_red` is `Φᵀ K Φ` (r × r, symmetric positive definite; the lower triangle is read),
/// `b_n_phi` the normal rows of `B Φ` (w × r, one row per pair), `f_red = Φᵀ f` (r), `k_n` the
/// penalty stiffness (N/mm). Returns `η` (r) and the contact state; the physical displacement is
/// `Φ η`. Dense Cholesky per iteration.
pub fn contact_static_reduced(
    k_red: MatRef<'_, f64>,
    b_n_phi: MatRef<'_, f64>,
    f_red: &[f64],
    k_n: f64,
    opts: &ContactOptions,
) -> Result<(Vec<f64>, ContactState), Error> {
    let r = reduced_sizes(k_red, b_n_phi, f_red)?;
    let w = b_n_phi.nrows();
    // Nonzero columns of each pair row (B_n Φ is sparse when Φ selects DOF).
    let support: Vec<Vec<usize>> = (0..w)
        .map(|i| (0..r).filter(|&j| b_n_phi[(i, j)] != 0.0).collect())
        .collect();
    let rhs = Mat::from_fn(r, 1, |i, _| f_red[i]);
    let mut eta = vec![0.0; r];
    let state = active_set_newton(w, k_n, opts, |active, gaps| {
        let mut a = k_red.to_owned();
        for (i, s) in support.iter().enumerate() {
            if active[i] {
                for &cj in s {
                    let bj = k_n * b_n_phi[(i, cj)];
                    for &ci in s {
                        a[(ci, cj)] += b_n_phi[(i, ci)] * bj;
                    }
                }
            }
        }
        let llt = a.llt(Side::Lower).map_err(|e| {
            Error::LinearAlgebra(LinalgError::NotPositiveDefinite {
                what: format!(
                    "reduced K_r + K_c ({r}×{r}, {} pairs active)",
                    active.iter().filter(|&&a| a).count()
                ),
                hint: "",
                source: Box::new(e),
            })
        })?;
        let mut x = llt.solve(&rhs);
        for _ in 0..REFINEMENT_STEPS {
            // x ← x + A⁻¹ (f − A x), the residual in double-double.
            let mut acc: Vec<Dot2> = f_red.iter().map(|&v| Dot2::new(v)).collect();
            for j in 0..r {
                let xj = x[(j, 0)];
                for (i, ai) in acc.iter_mut().enumerate() {
                    ai.add_product(-a[(i, j)], xj);
                }
            }
            let res = Mat::from_fn(r, 1, |i, _| acc[i].value());
            x += llt.solve(&res);
        }
        for j in 0..r {
            eta[j] = x[(j, 0)];
        }
        for (i, g) in gaps.iter_mut().enumerate() {
            *g = support[i].iter().map(|&j| b_n_phi[(i, j)] * eta[j]).sum();
        }
        Ok(())
    })?;
    Ok((eta, state))
}

/// The pattern of `K + K_c` for every possible active set: the union of K's pattern and each
/// pair's `b_iᵀ b_i`, with scatter positions and one symbolic Cholesky factorization.
struct ContactPattern {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Position in the union pattern of each stored entry of K.
    k_pos: Vec<usize>,
    /// Per pair, `(position, b_a b_b)` for every entry of `b_iᵀ b_i`.
    pair_entries: Vec<Vec<(usize, f64)>>,
    symbolic_matrix: SymbolicSparseColMat<usize>,
    symbolic_llt: SymbolicLlt<usize>,
}

impl ContactPattern {
    fn new(k: &SymCsc, joint: &JointOperator) -> Result<ContactPattern, Error> {
        let n = k.n;
        let rows: Vec<Vec<(usize, f64)>> = (0..joint.pairs())
            .map(|i| joint.row(3 * i + NORMAL).collect())
            .collect();
        // Rows each column gains from the pairs' b_iᵀ b_i, beside K's own.
        let mut extra: Vec<Vec<usize>> = vec![Vec::new(); n];
        for row in &rows {
            for &(cj, _) in row {
                extra[cj].extend(row.iter().map(|&(ci, _)| ci));
            }
        }
        let (col_ptr, row_idx) = column_pattern(n, |c, out| {
            out.extend_from_slice(&k.row_idx[k.col_ptr[c]..k.col_ptr[c + 1]]);
            out.extend_from_slice(&extra[c]);
        });
        let pos = |i: usize, j: usize| -> usize {
            let col = &row_idx[col_ptr[j]..col_ptr[j + 1]];
            // Every queried entry was inserted above.
            col_ptr[j] + col.binary_search(&i).expect("entry in union pattern")
        };
        let mut k_pos = Vec::with_capacity(k.row_idx.len());
        for j in 0..n {
            for p in k.col_ptr[j]..k.col_ptr[j + 1] {
                k_pos.push(pos(k.row_idx[p], j));
            }
        }
        let pair_entries = rows
            .iter()
            .map(|row| {
                let mut e = Vec::with_capacity(row.len() * row.len());
                for &(cj, vj) in row {
                    for &(ci, vi) in row {
                        e.push((pos(ci, cj), vi * vj));
                    }
                }
                e
            })
            .collect();
        let symbolic_matrix =
            SymbolicSparseColMat::new_checked(n, n, col_ptr.clone(), None, row_idx.clone());
        let symbolic_llt =
            SymbolicLlt::try_new(symbolic_matrix.as_ref(), Side::Lower).map_err(|e| {
                Error::LinearAlgebra(LinalgError::Symbolic {
                    what: format!("Cholesky of K + K_c ({n}×{n})"),
                    source: Box::new(e),
                })
            })?;
        Ok(ContactPattern {
            col_ptr,
            row_idx,
            k_pos,
            pair_entries,
            symbolic_matrix,
            symbolic_llt,
        })
    }

    /// `r = f − A q` in double-double for the matrix `values` on this pattern (full symmetric
    /// storage); `acc` is scratch of length n.
    fn residual_into(
        &self,
        values: &[f64],
        f: &[f64],
        q: &[f64],
        acc: &mut [Dot2],
        r: &mut Mat<f64>,
    ) {
        for (a, &fi) in acc.iter_mut().zip(f) {
            *a = Dot2::new(fi);
        }
        for (j, &qj) in q.iter().enumerate() {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                acc[self.row_idx[p]].add_product(-values[p], qj);
            }
        }
        for (i, a) in acc.iter().enumerate() {
            r[(i, 0)] = a.value();
        }
    }

    /// `values = K + k_n Σ_active b_iᵀ b_i` on the union pattern.
    fn fill_into(&self, k: &SymCsc, k_n: f64, active: &[bool], values: &mut [f64]) {
        values.fill(0.0);
        for (&p, &v) in self.k_pos.iter().zip(&k.values) {
            values[p] += v;
        }
        for (entries, &a) in self.pair_entries.iter().zip(active) {
            if a {
                for &(p, v) in entries {
                    values[p] += k_n * v;
                }
            }
        }
    }
}

/// Frictionless contact statics of a dense reduced system (as [`contact_static_reduced`]) by
/// semismooth Newton with a backtracking
/// (Armijo) line search on the contact energy
///
/// ```text
/// E(η) = ½ ηᵀ K̃ η − f̃ᵀ η + ½ k_n Σ_i min(b_i η, 0)²     (b_i: row i of B_n Φ)
/// ```
///
/// which is convex and continuously differentiable with `∇E = H_A η − f̃`,
/// `H_A = K̃ + k_n Σ_{i∈A(η)} b_iᵀ b_i`, `A(η) = {i : b_i η < 0}`. The Newton direction
/// `d = H_A⁻¹ f̃ − η` is the undamped active-set step of [`contact_static_reduced`]; it is a descent
/// direction (`∇E·d = −dᵀ H_A d < 0`), and backtracking until
/// `E(η + t d) ≤ E(η) + 10⁻⁴ t ∇E·d` makes the iteration converge from any start, where the
/// undamped one can cycle. It stops exactly as the undamped one: when the full step's active set
/// equals the set it was computed with, the step solves the piecewise linear equilibrium
/// exactly. Starts from η = 0 (all pairs open); at most `20 · opts.max_iterations` steps.
pub fn contact_static_reduced_damped(
    k_red: MatRef<'_, f64>,
    b_n_phi: MatRef<'_, f64>,
    f: &[f64],
    k_n: f64,
    opts: &ContactOptions,
) -> Result<(Vec<f64>, ContactState), Error> {
    let (w, r) = (b_n_phi.nrows(), reduced_sizes(k_red, b_n_phi, f)?);
    let b = b_n_phi;
    let gaps_of = |eta: &[f64]| -> Vec<f64> {
        (0..w)
            .map(|i| (0..r).map(|j| b[(i, j)] * eta[j]).sum())
            .collect()
    };
    let energy = |eta: &[f64]| -> f64 {
        let mut e = 0.0;
        for i in 0..r {
            let ki: f64 = (0..r).map(|j| k_red[(i, j)] * eta[j]).sum();
            e += eta[i] * (0.5 * ki - f[i]);
        }
        e + 0.5 * k_n * gaps_of(eta).iter().map(|g| g.min(0.0).powi(2)).sum::<f64>()
    };
    let max_steps = 20 * opts.max_iterations.max(1);
    let mut eta = vec![0.0; r];
    let mut active_counts = Vec::new();
    for it in 1..=max_steps {
        let active: Vec<bool> = gaps_of(&eta).iter().map(|&g| g < 0.0).collect();
        active_counts.push(active.iter().filter(|&&a| a).count());
        let mut h = k_red.to_owned();
        for i in (0..w).filter(|&i| active[i]) {
            for c in 0..r {
                let bc = k_n * b[(i, c)];
                if bc != 0.0 {
                    for rr in 0..r {
                        h[(rr, c)] += b[(i, rr)] * bc;
                    }
                }
            }
        }
        let llt = h.llt(Side::Lower).map_err(|e| {
            Error::LinearAlgebra(LinalgError::NotPositiveDefinite {
                what: format!("damped reduced contact, step {it}: K̃ + K_c"),
                hint: "",
                source: Box::new(e),
            })
        })?;
        let rhs = Mat::from_fn(r, 1, |i, _| f[i]);
        let x = faer::linalg::solvers::Solve::solve(&llt, &rhs);
        let full: Vec<f64> = (0..r).map(|i| x[(i, 0)]).collect();
        if full.iter().any(|v| !v.is_finite()) {
            return Err(Error::LinearAlgebra(LinalgError::not_finite(format!(
                "damped reduced contact, step {it}: solution"
            ))));
        }
        let gaps = gaps_of(&full);
        let next: Vec<bool> = gaps.iter().map(|&g| g < 0.0).collect();
        if next == active {
            let forces: Vec<f64> = gaps
                .iter()
                .zip(&active)
                .map(|(&g, &a)| if a { k_n * g } else { 0.0 })
                .collect();
            let state = ContactState {
                contact_force_norm: forces.iter().map(|p| p * p).sum::<f64>().sqrt(),
                pairs_in_contact: active.iter().filter(|&&a| a).count(),
                gaps,
                forces,
                active,
                iterations: it,
                active_counts,
            };
            return Ok((full, state));
        }
        // Armijo backtracking along d = full − η; ∇E·d = −dᵀ H_A d.
        let d: Vec<f64> = full.iter().zip(&eta).map(|(a, b)| a - b).collect();
        let mut hd = vec![0.0; r];
        for c in 0..r {
            for rr in 0..r {
                hd[rr] += h[(rr, c)] * d[c];
            }
        }
        let slope = -d.iter().zip(&hd).map(|(a, b)| a * b).sum::<f64>();
        let e0 = energy(&eta);
        let mut t = 1.0;
        loop {
            let trial: Vec<f64> = eta.iter().zip(&d).map(|(e, dd)| e + t * dd).collect();
            if energy(&trial) <= e0 + 1e-4 * t * slope {
                eta = trial;
                break;
            }
            t *= 0.5;
            if t < 1e-12 {
                return Err(Error::LinearAlgebra(LinalgError::LineSearch { step: it }));
            }
        }
    }
    Err(Error::LinearAlgebra(LinalgError::NotConverged {
        what: "damped reduced contact",
        steps: max_steps,
    }))
}

/// r of a reduced contact problem (`K_r` r × r, `B_n Φ` w × r, `f_r` r), or the error naming the
/// sizes that do not fit.
fn reduced_sizes(
    k_red: MatRef<'_, f64>,
    b_n_phi: MatRef<'_, f64>,
    f_red: &[f64],
) -> Result<usize, Error> {
    let r = k_red.nrows();
    if k_red.ncols() != r || b_n_phi.ncols() != r || f_red.len() != r {
        return Err(JointError::ReducedStaticsSizes {
            k_r: (k_red.nrows(), k_red.ncols()),
            b_n_phi: (b_n_phi.nrows(), b_n_phi.ncols()),
            load: f_red.len(),
        }
        .into());
    }
    Ok(r)
}
