//! Trial vector derivatives for joint contact (Algorithm 2, lines 3–20; eqs. 12–19, 27–28).
//!
//! # The derivatives (paper Section 2.4–2.5)
//! A trial vector φ_i of the base changes with the state `q` because the joint stiffness does.
//! Its derivative with respect to the scaling `q_j` of trial vector φ_j is a new trial vector.
//!
//! - **Vibration mode** φ_i with `(K − Ω_i² M) φ_i = 0`. Differentiating the eigenproblem
//!   (eq. 12, M constant) gives eq. (13),
//!   `(K − Ω_i² M) ∂φ_i/∂q_j + (∂K/∂q_j − ∂Ω_i²/∂q_j M) φ_i = 0`, and premultiplying by φ_iᵀ
//!   the eigenvalue sensitivity (eq. 14) `∂Ω_i²/∂q_j = φ_iᵀ (∂K/∂q_j) φ_i / φ_iᵀ M φ_i` (the
//!   paper writes it for M-normalized modes). Substituted back, eq. (15):
//!   `φ_{i,j} = (K − Ω_i² M)⁻¹ (∂K/∂q_j − ∂Ω_i²/∂q_j M) φ_i`
//!   (the paper drops the overall sign of eq. 13, immaterial for a trial vector).
//! - Neglecting inertia (eq. 16), and for **static shapes** such as the constraint modes
//!   (eqs. 17–18, exactly): `φ_{i,j} = K⁻¹ (∂K/∂q_j) φ_i`, the static response to the
//!   pseudoforce `f_{i,j} = (∂K/∂q_j) φ_i` (eq. 19).
//!
//! Contact makes `∂K/∂q` one-sided, so each φ_j is differentiated for both signs `k = ±1`
//! (eqs. 27–28): `∂K/∂q_{k,j} = Σ_{z active under k φ_j} k_n b_{n,z}ᵀ b_{n,z}` (optionally
//! `+ k_t (b_{t1,z}ᵀ b_{t1,z} + b_{t2,z}ᵀ b_{t2,z})`), with b the rows of the joint operator B.
//! Hence `f_{i,k,j} = Bᵀ p_{i,k,j}`, p the `3w` pair forces `k_n (B φ_i)_r` on the active rows.
//!
//! # Which K, M and Ω
//! K and M are the full model's (master node free, as for eq. 16 in Algorithm 2). A base column
//! that is exactly zero on the six master DOF is a fixed-interface vibration mode: with
//! [`TvdOptions::inertia`] its `Ω_i² = φ_iᵀ K φ_i / φ_iᵀ M φ_i` (Rayleigh quotient — exact for
//! a Craig–Bampton mode, because `(K − Ω_i² M) φ_i` vanishes on the interior rows and φ_i on the
//! master rows) and eq. (15) is used; every other column (the constraint modes Φ_S) has `Ω = 0`
//! and eq. (16)/(18). `K − Ω_i² M` is indefinite (Ω_i² lies above the lowest free-interface
//! eigenvalues) and nonsingular unless Ω_i² is also an eigenvalue of the free-master problem;
//! it is factored by sparse LU with partial pivoting (faer), one factorization per mode
//! (symbolic analysis shared), and the solve's backward error is checked (≤ 1e-10).
//!
//! # How (one factorization, few right-hand sides)
//! Every pseudoforce lies in `span(B_uᵀ)`, B_u the m joint rows that receive stiffness (the w
//! normal rows, or all 3w with `k_t`). So instead of 2(v+s)² = 512 solves, the m "joint
//! flexibility" columns `Z = K⁻¹ B_uᵀ` are solved once (one sparse Cholesky) and each TVD is
//! `φ_{i,k,j} = Z p_u` (a dense product, the same vector to round-off). Its strain energy is
//! `φᵀ K φ = p_uᵀ B_u K⁻¹ B_uᵀ p_u = p_uᵀ G p_u` with the m × m joint flexibility
//! `G = B_u Z`, so the K-normalization (Algorithm 2, line 20) needs no n-sized product. For
//! eq. (15) the 2(v+s) right-hand sides `f − ∂Ω_i²/∂q M φ_i` of each mode are solved directly
//! with its LU factors (combining flexibility columns of the indefinite operator would cancel
//! catastrophically when Ω_i² lies near a free-interface eigenvalue), and `φᵀ K φ` is formed
//! with K.
//!
//! # Factor form
//! The static TVD are kept as `Y = Z C` ([`Tvd::factor`], [`TvdFactor`]): Z solved and refined
//! once with a double-double residual (so `B_u Z = Zᵀ K Z` to working precision), `G = B_u Z`, C the
//! K-normalized coefficients. [`super::pod_tvd`] computes the K-weighted POD as the SVD of
//! `D^½ Vᵀ C` (`G = V D Vᵀ`) instead of the eigenproblem of `Yᵀ K Y`, which squares the
//! condition number: the directions carrying the last per cent of the contact force have POD
//! eigenvalues below the Gram route's round-off (measured in `docs/validation/static-convergence.md`, section
//! `reduction::tvd`).
//!
//! The product `Z C` itself is needed by nothing downstream of the factors: the POMs are
//! `Z (C w_i)/σ_i`, formed for the g a basis takes. [`trial_vector_derivatives_factored`]
//! therefore leaves it unformed — at 10⁶ DOF an n × 512 block (4 GB) that never exists.
//!
//! # The secant TVD (opt-in, [`TvdOptions::secant`])
//! A tangent TVD `K⁻¹ (∂K/∂q_{k,j}) φ_i` weighs pair z by the gap the linear base opens there,
//! `k_n (B_n φ_i)_z`: the first-order change of φ_i when the penalty of the active set A is
//! switched on. Where the penalty is stiff against the sheet (`k_n G_zz ≫ 1` on the pair-space
//! flexibility `G = B_n K⁻¹ B_nᵀ`), the first order overshoots by orders of magnitude, and pairs
//! that the welds hold nearly shut get tiny weights and enter only the last POD modes although
//! they carry load. The exact change of the shape when that contact stiffness is switched on is
//! the secant `φ_{i,k,j} = (K + ∂K/∂q_{k,j})⁻¹ (∂K/∂q_{k,j}) φ_i` — what a finite-difference
//! evaluation of `∂φ_i/∂q_j` returns for a penalty law (the paper's Section 2.3). With
//! `∂K = k_n B_Aᵀ B_A` the Woodbury identity keeps the factor form:
//!
//! ```text
//! φ_{i,k,j} = Z c,   c_A = (I/k_n + G_AA)⁻¹ (B_n φ_i)_A,   c = 0 off A,   Z = K⁻¹ B_nᵀ
//! ```
//!
//! one small dense SPD solve of size |A| per active set (normal rows only; the tangential and
//! inertia variants have no secant form here). Everything downstream — K-normalization, the
//! POD, w(g) — is the tangent TVD's, on these coefficients. G needs the flexibility of every
//! normal row (n × w solves) once, also where the compression below applies.
//!
//! # Compressed flexibility (many pairs)
//! Z has one column per joint row: n × m, dense. A refined 10⁵-DOF friction bar has m ≈ 6 000
//! pairs, so Z alone would be 5 GB and m solves, while the p ≤ 2(v+s)² = 512 TVD only need the
//! range of C. When `p < m`, C is factored first, `C = Q R` (thin QR, Q m × p orthonormal,
//! R p × p), and the factor form is kept on that range:
//! `Y = Z C = (K⁻¹ B_uᵀ Q) R = Z_Q R`, `Yᵀ K Y = Rᵀ (Qᵀ G Q) R = Rᵀ G_Q R` with
//! `G_Q = Qᵀ B_u Z_Q` (p × p). The same algebra with `Z → Z_Q`, `G → G_Q`, `C → R`: p refined
//! solves instead of m, memory n·p instead of n·m, and [`super::pod_tvd`] unchanged (its "m" is
//! then p). `B_uᵀ Q` is formed from the sparse rows of B. With `p ≥ m` (the built-in scenes:
//! 54 and 86 pairs) nothing is compressed and the arithmetic is the one above.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{Mat, MatRef};

use crate::error::{Error, ReductionError};
use crate::joint::{JointOperator, NORMAL, T1, T2};
use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::sparse::{sym_mul_mat, sym_mul_vec_into};
use crate::linalg::LinalgError;
use crate::linalg::SymCsc;
use crate::model::Model;

use crate::linalg::compensated::solve_refined_steps_owned;

/// Options of [`trial_vector_derivatives`]. Defaults: `tol = 1e-8`, `zero_gap_active = true`,
/// `tangential = false`, `inertia = false`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TvdOptions {
    /// Relative zero of a gap and of a pseudoforce, relative to the trial vector's displacement
    /// scale `s_j` (its largest translation, [`displacement_scales`]): under φ_j a pair gap with
    /// `|g_z| ≤ tol · s_j` counts as exactly zero ([`active_pairs`]), and a pseudoforce column of
    /// φ_i with `‖p‖∞ ≤ tol · k · s_i` is dropped ([`Tvd::negligible_columns`]). The default
    /// 1e-8 lies in the empty band between the round-off of the built-in cases' base vectors
    /// (≤ 5.7e-10 s_j) and their smallest physical gaps (≥ 5.8e-6 s_j); measured in
    /// [`active_pairs`].
    pub tol: f64,
    /// Whether an exactly-zero gap (in the sense of `tol`) is active. `true` is the paper's
    /// rule `g ≤ 0` (Algorithm 2, line 9); `false` makes only penetrating pairs (`g < 0`) active.
    pub zero_gap_active: bool,
    /// Add the stick stiffness `k_t` on the two tangential rows of active pairs too (Algorithm 2,
    /// line 10 adds `k_n` and `k_t`). `false`: normal stiffness `k_n` only.
    pub tangential: bool,
    /// Include the inertia term of eq. (15) for the fixed-interface vibration modes: solve
    /// `(K − Ω_i² M) φ_{i,k,j} = ∂K/∂q_{k,j} φ_i` with φ_i's own eigenvalue Ω_i² (rad/s)².
    /// `false` (default): the static eq. (16) for every vector, the paper's Algorithm 2.
    pub inertia: bool,
    /// The secant TVD of the module docs instead of the tangent ones (normal rows, static only).
    pub secant: bool,
}

impl Default for TvdOptions {
    fn default() -> Self {
        TvdOptions {
            tol: 1e-8,
            zero_gap_active: true,
            tangential: false,
            inertia: false,
            secant: false,
        }
    }
}

/// Which derivative a TVD column is: `φ_{i,k·j}` = response to `∂K/∂q_{k,j} φ_i` (0-based
/// indices into the base, `k = ±1`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TvdIndex {
    /// The differentiated trial vector φ_i.
    pub i: usize,
    /// Sign of the scaling of φ_j, ±1.
    pub k: i8,
    /// The trial vector φ_j whose scaling sets the active pairs.
    pub j: usize,
}

/// The trial vector derivatives of a base.
#[derive(Clone, Debug)]
pub struct Tvd {
    /// K-normalized TVD (n × p), `φᵀ K φ = 1` for each column; n × 0 when only the factor
    /// form is kept ([`trial_vector_derivatives_factored`], [`Tvd::formed_vectors`]).
    pub vectors: Mat<f64>,
    /// Which `(i, k, j)` each column is.
    pub index: Vec<TvdIndex>,
    /// `sqrt(φᵀKφ)` of each column before normalization (N^½·mm^½ per unit of the base).
    pub k_norms: Vec<f64>,
    /// All candidates, `2 (v + s)²`.
    pub total: usize,
    /// Candidates whose pseudoforce is exactly zero (no active pair, or φ_i exactly zero on all
    /// active rows); dropped.
    pub zero_columns: usize,
    /// Candidates whose pseudoforce is nonzero but zero in the sense of [`TvdOptions::tol`]:
    /// `‖p‖∞ ≤ tol · k · s_i` (k = k_n, or `max(k_n, k_t)` with [`TvdOptions::tangential`]; s_i
    /// φ_i's largest translation, [`displacement_scales`]), i.e. φ_i's joint displacement on
    /// every active row is round-off; dropped too. On the multilayer sheet these are the 96
    /// columns of its in-plane constraint modes (i = ux, uz, ry), whose gaps are ≤ 1e-13 s_i: kept,
    /// they were K-normalized round-off carrying 96/512 of the POD's energy.
    pub negligible_columns: usize,
    /// For each base vector j, the active pairs for `k = −1` and `k = +1`.
    pub active: Vec<[Vec<bool>; 2]>,
    /// For each base vector i, the `Ω_i²` ((rad/s)²) of the operator `K − Ω_i² M` its
    /// derivatives were solved with: 0 for the static eq. (16)/(18) (all vectors unless
    /// [`TvdOptions::inertia`]; constraint modes always).
    pub omega2: Vec<f64>,
    /// The factor form `vectors = Z C` of the static TVD (module docs, "Factor form"); `None`
    /// when some column was solved with eq. (15) ([`TvdOptions::inertia`]) or there are no
    /// columns. [`super::pod_tvd`] uses it for the POD without squaring.
    pub factor: Option<TvdFactor>,
}

/// The factor form of static TVD: `vectors = flexibility · coefficients` (to round-off; the
/// product is how the vectors are formed).
#[derive(Clone, Debug)]
pub struct TvdFactor {
    /// The joint flexibility columns `Z = K⁻¹ B_uᵀ` (n × m, mm/N), m the joint rows that receive
    /// stiffness (one per pair, or three with [`TvdOptions::tangential`]); or, with fewer TVD p
    /// than joint rows, the compressed `Z_Q = K⁻¹ B_uᵀ Q` (n × p, module docs, "Compressed
    /// flexibility"); solved with one double-double residual refinement.
    pub flexibility: Mat<f64>,
    /// `G = B_u Z = B_u K⁻¹ B_uᵀ` (m × m, mm/N), or `G_Q = Qᵀ B_u Z_Q` (p × p) when compressed;
    /// symmetrized: `Zᵀ K Z` to the solve's residual.
    pub joint_flexibility: Mat<f64>,
    /// The K-normalized pseudoforce coefficients C (m × p, N per unit of the base over the
    /// column's K-norm), or R of `C = Q R` (p × p) when compressed: `vectors = Z C`,
    /// `cᵀ G c = 1` per column.
    pub coefficients: Mat<f64>,
}

impl Tvd {
    /// Number of kept (nonzero) columns p.
    pub fn nonzero(&self) -> usize {
        self.index.len()
    }

    /// The K-normalized TVD (n × p): [`Tvd::vectors`] where formed, else the product
    /// `Z C` of the factor form ([`trial_vector_derivatives_factored`]).
    pub fn formed_vectors(&self) -> Mat<f64> {
        match &self.factor {
            Some(f) if self.vectors.ncols() != self.nonzero() => &f.flexibility * &f.coefficients,
            _ => self.vectors.clone(),
        }
    }
}

/// The active pairs under the scaled trial vector `k · φ_j`, given its normal gaps `g = B_n φ_j`
/// (w values, mm per unit of the base) and its displacement scale `scale = s_j`, the largest
/// translation of φ_j (mm per unit of the base; [`displacement_scales`]).
///
/// A gap is "zero" when `|g_z| ≤ tol · s_j`; a zero gap is active iff `zero_gap_active`.
/// Otherwise pair z is active iff `k g_z < 0` (penetration). A vector that opens no gap (all
/// gaps zero, e.g. an in-plane constraint mode, whose gaps are round-off) has all pairs active
/// for both signs if `zero_gap_active` (the paper's `g ≤ 0`), none otherwise — whatever the
/// signs of its round-off.
///
/// # Why the displacement scale
/// A gap is a difference of translations, `g_z = b_z φ_j = n · (u_upper − u_lower)` (a row of
/// B has unit-normal weights on the two nodes' translations; a rigid follower node adds the
/// master's rotation times its offset in mm). Its computed value carries the error of those
/// translations, `|δg_z| ≤ ‖b_z‖₁ max|δu|`, and φ_j is computed to an error relative to its
/// own size: `max|δu| ≲ c ε s_j` for the constraint modes (backward-stable solve with K), the
/// eigen-solver's residual for the modes. So round-off in a gap is a fraction of s_j, whatever
/// the gaps are, and `tol · s_j` is a round-off bound for every vector. Relative to the largest
/// gap instead (an earlier rule), a vector that opens no gap compares round-off with
/// round-off: its active sets were the signs of round-off, and multiplying the multilayer
/// sheet's K and M entrywise by `1 ± 1e-15` moved its reduced `‖f_c‖` by 2.5e-2 … 1.1e-1
/// (`tests/reduction/roundoff.rs`). Translations only:
/// gaps are in mm, rotations in rad (on the built-in cases the largest entry of every base
/// vector is a translation anyway).
///
/// # Why `tol = 1e-8`
/// Measured on the built-in cases (Craig–Bampton, ν = 10; `tests/reduction/reduction.rs`,
/// `tvd_zero_gap_rule_counts`): with the welds' re-meshed neighbourhoods (the default since
/// the default weld model) the round-off gaps are ≤ 5.7e-10 s_j (friction bar: its centre-line pairs under the
/// vectors antisymmetric in z — the condensed neighbourhoods carry the round-off of their
/// 60 k-DOF solve; multilayer ≤ 5.5e-11 s_j, every gap of its in-plane constraint modes ux, uz,
/// ry), the physical ones ≥ 3.4e-5 s_j (friction bar) and ≥ 5.8e-6 s_j (multilayer), and no gap
/// lies in between: 1e-8 is more than a decade from either side. With `"local_mesh": "off"`
/// (the RBE3 weld on the sheets' own shells) the band is 2e-11 … 1.1e-7 s_j (the multilayer's
/// welded sheets move nearly together), and 1e-8 is again a decade inside it; 1e-9, the value
/// before the re-meshed neighbourhoods, is within 2× of the friction bar's round-off now.
pub fn active_pairs(gaps: &[f64], scale: f64, k: f64, opts: &TvdOptions) -> Vec<bool> {
    let zero = opts.tol * scale;
    gaps.iter()
        .map(|&g| {
            if g.abs() <= zero {
                opts.zero_gap_active
            } else {
                k * g < 0.0
            }
        })
        .collect()
}

/// The displacement scale of each base vector, `s_j = max |φ_j|` over the model's translation
/// DOF ([`Model::translation_dofs`]; mm per unit of the base): the reference of the zero gaps
/// and negligible pseudoforces ([`active_pairs`], [`TvdOptions::tol`]).
pub fn displacement_scales(model: &Model, base: MatRef<'_, f64>) -> Vec<f64> {
    let dofs = model.translation_dofs();
    (0..base.ncols())
        .map(|j| dofs.iter().fold(0.0f64, |a, &d| a.max(base[(d, j)].abs())))
        .collect()
}

/// Trial vector derivatives of `base` (Algorithm 2): for each trial vector φ_j and sign
/// `k = ±1` the active pairs of `k φ_j` ([`active_pairs`]) define
/// `∂K/∂q_{k,j} = Σ_active k_n b_nᵀ b_n (+ k_t (b_t1ᵀ b_t1 + b_t2ᵀ b_t2))`, and for every φ_i the
/// pseudoforce `f_{i,k,j} = ∂K/∂q_{k,j} φ_i` (eq. 19) is formed through the joint operator,
/// `Bᵀ (D_{k,j} B φ_i)`, never as a dense n × n matrix. One sparse Cholesky of the full `K`
/// (master free, the paper's K) serves all kept right-hand sides: `K φ_{i,k,j} = f_{i,k,j}`
/// (eqs. 16/18), through the joint flexibility columns `K⁻¹ B_uᵀ` (module docs). With
/// [`TvdOptions::inertia`] the fixed-interface modes use eq. (15) instead. Columns are ordered
/// j, then k = −1, +1, then i; zero and negligible pseudoforces are dropped and counted; each
/// kept column is normalized w.r.t. K (Algorithm 2, line 20).
pub fn trial_vector_derivatives(
    model: &Model,
    base: MatRef<'_, f64>,
    opts: &TvdOptions,
) -> Result<Tvd, Error> {
    derivatives(model, base, opts, true)
}

/// [`trial_vector_derivatives`] that keeps the static TVD in their factor form only: where
/// [`Tvd::factor`] is set, [`Tvd::vectors`] is left empty (n × 0) instead of the n × p product
/// `Z C` — one dense n × p block less (4 GB for the 509 TVD of a 10⁶-DOF model). Everything
/// [`super::build_basis`] needs — the POD, its POMs `Z (C w_i)/σ_i`, w(g) — comes from the
/// factors ([`super::pod_tvd`]); [`Tvd::formed_vectors`] forms the product when wanted. With
/// eq. (15) columns ([`TvdOptions::inertia`]) there is no factor form and the vectors are formed
/// as by [`trial_vector_derivatives`].
pub fn trial_vector_derivatives_factored(
    model: &Model,
    base: MatRef<'_, f64>,
    opts: &TvdOptions,
) -> Result<Tvd, Error> {
    derivatives(model, base, opts, false)
}

/// [`trial_vector_derivatives`]; with `form_static` false the static columns' product `Z C`
/// is not formed when the factor form stands for all columns.
fn derivatives(
    model: &Model,
    base: MatRef<'_, f64>,
    opts: &TvdOptions,
    form_static: bool,
) -> Result<Tvd, Error> {
    let n = model.dofs();
    if base.nrows() != n {
        return Err(ReductionError::Rows {
            what: "TVD base has",
            rows: base.nrows(),
            dofs: n,
        }
        .into());
    }
    if !(opts.tol >= 0.0 && opts.tol < 1.0) {
        return Err(ReductionError::TvdTolerance { tol: opts.tol }.into());
    }
    if opts.secant && (opts.tangential || opts.inertia) {
        return Err(ReductionError::SecantOptions.into());
    }
    let run = TvdRun::new(model, base, opts);
    let nb = base.ncols();
    let total = 2 * nb * nb;
    let mut cand = run.candidates(opts);
    if opts.secant {
        run.secant_coefficients(&mut cand)?;
    }
    let cols = cand.index.len();
    let omega2 = if opts.inertia {
        mode_eigenvalues(model, base)?
    } else {
        vec![0.0; nb]
    };

    let mut x = if cols > 0 && omega2.iter().all(|&o| o == 0.0) {
        Mat::<f64>::zeros(0, 0) // replaced by the static product below
    } else {
        Mat::<f64>::zeros(n, cols)
    };
    let mut k_norms = vec![0.0; cols];
    let mut factor = None;
    // Static columns (Ω_i = 0): Z = K⁻¹ B_uᵀ, φᵀKφ = p_uᵀ G p_u with G = B_u Z.
    let static_cols: Vec<usize> = (0..cols)
        .filter(|&c| omega2[cand.index[c].i] == 0.0)
        .collect();
    if !static_cols.is_empty() {
        let all_static = static_cols.len() == cols;
        let (xs, static_factor) = run.static_columns(
            &cand,
            &static_cols,
            &mut k_norms,
            form_static || !all_static,
        )?;
        if all_static {
            // All columns static (the default): the product is the whole TVD matrix.
            x = xs;
            factor = Some(static_factor);
        } else {
            for (a, &c) in static_cols.iter().enumerate() {
                x.col_mut(c).copy_from(xs.col(a));
            }
        }
    }
    run.inertia_columns(&cand, &omega2, &mut x, &mut k_norms)?;
    Ok(Tvd {
        vectors: x,
        index: cand.index,
        k_norms,
        total,
        zero_columns: cand.zero_columns,
        negligible_columns: cand.negligible_columns,
        active: cand.active,
        omega2,
        factor,
    })
}

/// The block of right-hand sides that the static TVD solve with the full `K` (eqs. 16/18, no
/// inertia): `B_uᵀ Q` (n × p, N per unit of the base) with `C = Q R` when the p kept TVD are
/// fewer than the m joint rows that receive stiffness, else `B_uᵀ` (n × m) — module docs,
/// "Compressed flexibility". `K⁻¹` of this block is [`TvdFactor::flexibility`]. The
/// distributed path ([`super::distributed`]) solves it on PETSc and compares.
pub fn static_right_hand_sides(
    model: &Model,
    base: MatRef<'_, f64>,
    opts: &TvdOptions,
) -> Result<Mat<f64>, Error> {
    let n = model.dofs();
    if base.nrows() != n {
        return Err(ReductionError::Rows {
            what: "TVD base has",
            rows: base.nrows(),
            dofs: n,
        }
        .into());
    }
    let run = TvdRun::new(model, base, opts);
    let cand = run.candidates(opts);
    let cols: Vec<usize> = (0..cand.index.len()).collect();
    Ok(run.static_rhs(&cand, &cols).2)
}

/// One [`trial_vector_derivatives`] run: the model, the base, its joint displacements and the
/// joint rows that receive stiffness.
struct TvdRun<'a> {
    model: &'a Model,
    base: MatRef<'a, f64>,
    /// `B φ` of every base vector (3w × nb).
    bphi: Mat<f64>,
    /// The displacement scale of every base vector ([`displacement_scales`]).
    scales: Vec<f64>,
    /// The joint rows that receive stiffness, B_u (m of them): each pair's normal row, or all
    /// three with [`TvdOptions::tangential`].
    used: Vec<usize>,
}

/// The kept candidates of a [`TvdRun`] and the counts of the dropped ones.
struct Candidates {
    /// Pseudoforces p_u of the kept candidates (m × cols, column-major).
    coef: Vec<f64>,
    /// Which `(i, k, j)` each kept column is.
    index: Vec<TvdIndex>,
    /// For each base vector j, the active pairs for `k = −1` and `k = +1`.
    active: Vec<[Vec<bool>; 2]>,
    zero_columns: usize,
    negligible_columns: usize,
}

impl Candidates {
    /// The pseudoforce p_u of kept column `c` (m values).
    fn col(&self, c: usize, m: usize) -> &[f64] {
        &self.coef[c * m..(c + 1) * m]
    }
}

impl<'a> TvdRun<'a> {
    fn new(model: &'a Model, base: MatRef<'a, f64>, opts: &TvdOptions) -> Self {
        let joint = &model.joint;
        let w = joint.pairs();
        let bphi = joint.reduce(base); // 3w × nb
        let per_pair: &[usize] = if opts.tangential {
            &[NORMAL, T1, T2]
        } else {
            &[NORMAL]
        };
        let used: Vec<usize> = (0..w)
            .flat_map(|z| per_pair.iter().map(move |&r| 3 * z + r))
            .collect();
        TvdRun {
            model,
            base,
            bphi,
            scales: displacement_scales(model, base),
            used,
        }
    }

    /// The pseudoforces `p_u = D_{k,j} B_u φ_i` of all `2 nb²` candidates, columns ordered j,
    /// then k = −1, +1, then i; zero and negligible ones dropped and counted.
    fn candidates(&self, opts: &TvdOptions) -> Candidates {
        let (bphi, used, scales) = (&self.bphi, &self.used, &self.scales);
        let w = self.model.joint.pairs();
        let kn = self.model.contact.normal_stiffness;
        let kt = self.model.contact.stick_stiffness;
        let nb = self.base.ncols();
        let stiff = |r: usize| if r % 3 == NORMAL { kn } else { kt };
        let max_stiff = if opts.tangential { kn.max(kt) } else { kn };

        let mut out = Candidates {
            coef: Vec::new(),
            index: Vec::new(),
            active: Vec::with_capacity(nb),
            zero_columns: 0,
            negligible_columns: 0,
        };
        let mut p = vec![0.0; used.len()];
        for j in 0..nb {
            let gaps: Vec<f64> = (0..w).map(|z| bphi[(3 * z + NORMAL, j)]).collect();
            let act = [
                active_pairs(&gaps, scales[j], -1.0, opts),
                active_pairs(&gaps, scales[j], 1.0, opts),
            ];
            for (ki, k) in [-1i8, 1].into_iter().enumerate() {
                for i in 0..nb {
                    for (pa, &r) in p.iter_mut().zip(used) {
                        *pa = if act[ki][r / 3] {
                            stiff(r) * bphi[(r, i)]
                        } else {
                            0.0
                        };
                    }
                    let pmax = p.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                    if pmax == 0.0 {
                        out.zero_columns += 1;
                        continue;
                    }
                    // Every active entry of φ_i is a zero in the sense of `active_pairs`.
                    if pmax <= opts.tol * max_stiff * scales[i] {
                        out.negligible_columns += 1;
                        continue;
                    }
                    out.coef.extend_from_slice(&p);
                    out.index.push(TvdIndex { i, k, j });
                }
            }
            out.active.push(act);
        }
        out
    }

    /// Replaces the tangent pseudoforces `k_n (B_n φ_i)_A` of every kept candidate by the secant
    /// coefficients `(I/k_n + G_AA)⁻¹ (B_n φ_i)_A` (module docs, "The secant TVD"), with
    /// `G = B_n K⁻¹ B_nᵀ` solved once; one Cholesky per active set.
    fn secant_coefficients(&self, cand: &mut Candidates) -> Result<(), Error> {
        let (model, used) = (self.model, &self.used);
        let m = used.len();
        let kn = model.contact.normal_stiffness;
        let bt = joint_rows_transposed(&model.joint, used, None, model.dofs());
        let chol = SparseCholesky::new(&model.stiffness)?;
        let z = solve_refined_steps_owned(&model.stiffness, &chol, bt, 1);
        let g = symmetric(&rows_times(&model.joint, used, z.as_ref()));
        let mut c = 0;
        while c < cand.index.len() {
            let TvdIndex { k, j, .. } = cand.index[c];
            let end = (c..cand.index.len())
                .find(|&e| cand.index[e].j != j || cand.index[e].k != k)
                .unwrap_or(cand.index.len());
            let act = &cand.active[j][usize::from(k > 0)];
            let a: Vec<usize> = (0..m).filter(|&r| act[used[r] / 3]).collect();
            let ma = Mat::from_fn(a.len(), a.len(), |x, y| {
                g[(a[x], a[y])] + if x == y { 1.0 / kn } else { 0.0 }
            });
            let llt = ma.llt(faer::Side::Lower).map_err(|e| {
                Error::LinearAlgebra(LinalgError::NotPositiveDefinite {
                    what: format!("secant TVD: I/k_n + G_AA of {} pairs", a.len()),
                    hint: "",
                    source: Box::new(e),
                })
            })?;
            let rhs = Mat::from_fn(a.len(), end - c, |x, y| cand.col(c + y, m)[a[x]] / kn);
            let sol = llt.solve(&rhs);
            for y in 0..end - c {
                let col = &mut cand.coef[(c + y) * m..(c + y + 1) * m];
                col.iter_mut().for_each(|v| *v = 0.0);
                for (x, &r) in a.iter().enumerate() {
                    col[r] = sol[(x, y)];
                }
            }
            c = end;
        }
        Ok(())
    }

    /// The right-hand sides of the static columns `static_cols`: `(Q, R, B_uᵀ Q)` with
    /// `C = Q R` when there are fewer columns p than joint rows m (module docs, "Compressed
    /// flexibility"), else `(None, C, B_uᵀ)`; C the pseudoforce coefficients (m × p).
    fn static_rhs(
        &self,
        cand: &Candidates,
        static_cols: &[usize],
    ) -> (Option<Mat<f64>>, Mat<f64>, Mat<f64>) {
        let used = &self.used;
        let m = used.len();
        let pc = Mat::from_fn(m, static_cols.len(), |r, c| cand.col(static_cols[c], m)[r]);
        // C = Q R (thin QR, Q m × p orthonormal) when that makes fewer right-hand sides.
        let (q, coef) = if pc.ncols() < m {
            let qr = pc.qr();
            (Some(qr.compute_thin_Q()), qr.thin_R().to_owned())
        } else {
            (None, pc)
        };
        let bt = joint_rows_transposed(&self.model.joint, used, q.as_ref(), self.model.dofs());
        (q, coef, bt)
    }

    /// The static columns `static_cols` (eqs. 16/18) through one Cholesky of K: their
    /// K-normalized vectors `Z C` (n × static_cols.len(); n × 0 unless `form`) and the factor
    /// form Z, G, C; the K-norms go to `k_norms`. With fewer columns p than joint rows m, the
    /// flexibility is solved on the range of C only (module docs, "Compressed flexibility").
    /// The factorization is dropped before the product is formed.
    fn static_columns(
        &self,
        cand: &Candidates,
        static_cols: &[usize],
        k_norms: &mut [f64],
        form: bool,
    ) -> Result<(Mat<f64>, TvdFactor), Error> {
        let (model, used) = (self.model, &self.used);
        let (q, coef, bt) = self.static_rhs(cand, static_cols);
        let chol = SparseCholesky::new(&model.stiffness)?;
        let z = solve_refined_steps_owned(&model.stiffness, &chol, bt, 1);
        drop(chol);
        let bz = rows_times(&model.joint, used, z.as_ref());
        let g = symmetric(&match &q {
            Some(q) => q.transpose() * &bz,
            None => bz,
        });
        let scaled = normalize(&g, coef, static_cols, &cand.index, k_norms)?;
        let xs = if form {
            &z * &scaled
        } else {
            Mat::zeros(model.dofs(), 0)
        };
        let factor = TvdFactor {
            flexibility: z,
            joint_flexibility: g,
            coefficients: scaled,
        };
        Ok((xs, factor))
    }

    /// Eq. (15) per vibration mode (`omega2[i] ≠ 0`): `(K − Ω_i² M) φ = f − ∂Ω_i²/∂q M φ_i`,
    /// sparse LU; the K-normalized columns go to `x`, their K-norms to `k_norms`.
    fn inertia_columns(
        &self,
        cand: &Candidates,
        omega2: &[f64],
        x: &mut Mat<f64>,
        k_norms: &mut [f64],
    ) -> Result<(), Error> {
        let model = self.model;
        let cols = cand.index.len();
        let mut lu_symbolic: Option<SymbolicLu<usize>> = None;
        for (i, &om2) in omega2.iter().enumerate() {
            if om2 == 0.0 {
                continue;
            }
            let mode_cols: Vec<usize> = (0..cols).filter(|&c| cand.index[c].i == i).collect();
            if mode_cols.is_empty() {
                continue;
            }
            let rhs = self.mode_rhs(cand, i, &mode_cols);
            let mut z = shifted_solve(model, om2, &rhs, &mut lu_symbolic, i)?;
            let kz = sym_mul_mat(&model.stiffness, z.as_ref());
            scale_to_unit_energy(&mut z, &kz, &mode_cols, &cand.index, k_norms)?;
            for (a, &c) in mode_cols.iter().enumerate() {
                x.col_mut(c).copy_from(z.col(a));
            }
        }
        Ok(())
    }

    /// The right-hand sides `f − ∂Ω²/∂q M φ_i` of mode i's columns `mode_cols` (n × len), to be
    /// solved directly (`Z_i = (K − Ω²M)⁻¹ B_uᵀ` would be dominated by the near-resonant
    /// direction and cancel in the combinations).
    fn mode_rhs(&self, cand: &Candidates, i: usize, mode_cols: &[usize]) -> Mat<f64> {
        let (model, used) = (self.model, &self.used);
        let n = model.dofs();
        let m = used.len();
        let phi: Vec<f64> = self.base.col(i).iter().copied().collect();
        let mut mphi = vec![0.0; n];
        sym_mul_vec_into(&model.mass, &phi, &mut mphi);
        let phi_m_phi: f64 = phi.iter().zip(&mphi).map(|(a, b)| a * b).sum();
        let mut rhs = Mat::<f64>::zeros(n, mode_cols.len());
        let mut full = vec![0.0; 3 * model.joint.pairs()];
        for (a, &c) in mode_cols.iter().enumerate() {
            let pu = cand.col(c, m);
            full.iter_mut().for_each(|v| *v = 0.0);
            for (&u, v) in used.iter().zip(pu) {
                full[u] = *v;
            }
            let mut f = vec![0.0; n];
            model.joint.apply_transpose_add(&full, &mut f);
            let phi_f: f64 = used
                .iter()
                .zip(pu)
                .map(|(&u, v)| self.bphi[(u, i)] * v)
                .sum();
            let dom2 = phi_f / phi_m_phi;
            for r in 0..n {
                rhs[(r, a)] = f[r] - dom2 * mphi[r];
            }
        }
        rhs
    }
}

/// `Ω_i²` of each base column for eq. (15): the Rayleigh quotient of the columns that vanish
/// on the master DOF (fixed-interface modes), 0 for the others.
fn mode_eigenvalues(model: &Model, base: MatRef<'_, f64>) -> Result<Vec<f64>, Error> {
    let n = model.dofs();
    let master = model.master_dofs();
    let mut kv = vec![0.0; n];
    let mut mv = vec![0.0; n];
    (0..base.ncols())
        .map(|i| {
            if master.iter().any(|&d| base[(d, i)] != 0.0) {
                return Ok(0.0);
            }
            let v: Vec<f64> = base.col(i).iter().copied().collect();
            sym_mul_vec_into(&model.stiffness, &v, &mut kv);
            sym_mul_vec_into(&model.mass, &v, &mut mv);
            let vk: f64 = v.iter().zip(&kv).map(|(a, b)| a * b).sum();
            let vm: f64 = v.iter().zip(&mv).map(|(a, b)| a * b).sum();
            let om2 = vk / vm;
            if !(om2.is_finite() && om2 > 0.0) {
                return Err(ReductionError::TvdRayleighQuotient {
                    vector: i,
                    omega2: om2,
                }
                .into());
            }
            Ok(om2)
        })
        .collect()
}

/// `B_uᵀ Q` (n × Q.ncols()) for a dense Q (m × r), or `B_uᵀ` (n × m, column a the joint row
/// `used[a]`) without Q; formed row by row from the sparse joint operator.
fn joint_rows_transposed(
    joint: &JointOperator,
    used: &[usize],
    q: Option<&Mat<f64>>,
    n: usize,
) -> Mat<f64> {
    let Some(q) = q else {
        let mut out = Mat::<f64>::zeros(n, used.len());
        for (a, &r) in used.iter().enumerate() {
            for (c, v) in joint.row(r) {
                out[(c, a)] += v;
            }
        }
        return out;
    };
    let mut out = Mat::<f64>::zeros(n, q.ncols());
    for b in 0..q.ncols() {
        let col = out
            .col_mut(b)
            .try_as_col_major_mut()
            .expect("Mat columns are contiguous");
        let col = col.as_slice_mut();
        for (a, &r) in used.iter().enumerate() {
            let s = q[(a, b)];
            for (c, v) in joint.row(r) {
                col[c] += v * s;
            }
        }
    }
    out
}

/// `B_u Z` (m × Z.ncols()).
fn rows_times(joint: &JointOperator, used: &[usize], z: MatRef<'_, f64>) -> Mat<f64> {
    Mat::from_fn(used.len(), z.ncols(), |a, b| {
        joint.row(used[a]).map(|(c, v)| v * z[(c, b)]).sum()
    })
}

fn symmetric(g: &Mat<f64>) -> Mat<f64> {
    Mat::from_fn(g.nrows(), g.ncols(), |a, b| 0.5 * (g[(a, b)] + g[(b, a)]))
}

/// Scales each coefficient column q to unit energy `qᵀ G q` (= φᵀKφ of `φ = Z q`), storing
/// `sqrt(qᵀ G q)` in `k_norms[cols[c]]`.
fn normalize(
    g: &Mat<f64>,
    mut q: Mat<f64>,
    cols: &[usize],
    index: &[TvdIndex],
    k_norms: &mut [f64],
) -> Result<Mat<f64>, Error> {
    let gq = g * &q;
    scale_to_unit_energy(&mut q, &gq, cols, index, k_norms)?;
    Ok(q)
}

/// Scales each column `a` of `q` by `sqrt(q_aᵀ (Aq)_a)` (its energy; `aq = A q`), storing the
/// factor in `k_norms[cols[a]]`; a non-positive energy means A is not positive definite.
fn scale_to_unit_energy(
    q: &mut Mat<f64>,
    aq: &Mat<f64>,
    cols: &[usize],
    index: &[TvdIndex],
    k_norms: &mut [f64],
) -> Result<(), Error> {
    for (a, &c) in cols.iter().enumerate() {
        let e: f64 = q
            .col(a)
            .iter()
            .zip(aq.col(a).iter())
            .map(|(x, y)| x * y)
            .sum();
        if !(e.is_finite() && e > 0.0) {
            return Err(Error::LinearAlgebra(LinalgError::TvdStrainEnergy {
                column: c,
                index: (index[c].i, index[c].k, index[c].j),
                energy: e,
            }));
        }
        let s = e.sqrt();
        q.col_mut(a).iter_mut().for_each(|v| *v /= s);
        k_norms[c] = s;
    }
    Ok(())
}

/// Solves `(K − Ω² M) Z = rhs` by sparse LU (symbolic analysis shared through `symbolic`) and
/// checks the normwise backward error.
fn shifted_solve(
    model: &Model,
    om2: f64,
    rhs: &Mat<f64>,
    symbolic: &mut Option<SymbolicLu<usize>>,
    mode: usize,
) -> Result<Mat<f64>, Error> {
    let k = &model.stiffness;
    let mass = &model.mass;
    let a = shifted(k, mass, om2);
    let faer_a = SparseColMat::new(
        SymbolicSparseColMat::new_checked(a.n, a.n, a.col_ptr.clone(), None, a.row_idx.clone()),
        a.values.clone(),
    );
    let sym = match symbolic {
        Some(s) => s.clone(),
        None => {
            let s = SymbolicLu::try_new(faer_a.symbolic()).map_err(|e| {
                Error::LinearAlgebra(LinalgError::Symbolic {
                    what: "LU of K − Ω²M".to_string(),
                    source: Box::new(e),
                })
            })?;
            *symbolic = Some(s.clone());
            s
        }
    };
    let lu = Lu::try_new_with_symbolic(sym, faer_a.as_ref()).map_err(|e| {
        Error::LinearAlgebra(LinalgError::Factorization {
            step: format!("LU of K − Ω²M for base vector {mode} (Ω² = {om2:e})"),
            source: Box::new(e),
        })
    })?;
    let mut z = rhs.clone();
    lu.solve_in_place(z.as_mut());
    let az = sym_mul_mat(&a, z.as_ref());
    let a_norm = a.inf_norm();
    let mut worst = 0.0f64;
    for c in 0..z.ncols() {
        let res = (0..a.n).fold(0.0f64, |m, r| m.max((az[(r, c)] - rhs[(r, c)]).abs()));
        let zn = z.col(c).iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let bn = rhs.col(c).iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let backward = res / (a_norm * zn + bn).max(f64::MIN_POSITIVE);
        worst = if backward.is_nan() {
            f64::INFINITY
        } else {
            worst.max(backward)
        };
    }
    if worst > 1e-10 {
        return Err(Error::LinearAlgebra(LinalgError::TvdBackwardError {
            mode,
            omega2: om2,
            backward: worst,
        }));
    }
    Ok(z)
}

/// `K − s M` on the union of both patterns (both triangles stored, rows sorted).
fn shifted(k: &SymCsc, m: &SymCsc, s: f64) -> SymCsc {
    let n = k.n;
    let mut col_ptr = Vec::with_capacity(n + 1);
    col_ptr.push(0);
    let mut row_idx = Vec::with_capacity(k.row_idx.len());
    let mut values = Vec::with_capacity(k.values.len());
    for j in 0..n {
        let (mut a, ae) = (k.col_ptr[j], k.col_ptr[j + 1]);
        let (mut b, be) = (m.col_ptr[j], m.col_ptr[j + 1]);
        while a < ae || b < be {
            let ra = if a < ae { k.row_idx[a] } else { usize::MAX };
            let rb = if b < be { m.row_idx[b] } else { usize::MAX };
            if ra == rb {
                row_idx.push(ra);
                values.push(k.values[a] - s * m.values[b]);
                a += 1;
                b += 1;
            } else if ra < rb {
                row_idx.push(ra);
                values.push(k.values[a]);
                a += 1;
            } else {
                row_idx.push(rb);
                values.push(-s * m.values[b]);
                b += 1;
            }
        }
        col_ptr.push(row_idx.len());
    }
    SymCsc {
        n,
        col_ptr,
        row_idx,
        values,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reduction::{craig_bampton, pod};

    fn col(m: MatRef<'_, f64>, c: usize) -> Vec<f64> {
        m.col(c).iter().copied().collect()
    }

    fn mul(a: &SymCsc, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; x.len()];
        a.mul_vec(x, &mut y);
        y
    }

    fn inf(x: &[f64]) -> f64 {
        x.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    /// The pseudoforce `f_{i,k,j} = Bᵀ D_{k,j} B φ_i` (eq. 19), formed independently.
    fn pseudoforce(model: &Model, base: MatRef<'_, f64>, tvd: &Tvd, c: usize) -> Vec<f64> {
        let TvdIndex { i, k, j } = tvd.index[c];
        let act = &tvd.active[j][if k < 0 { 0 } else { 1 }];
        let mut b = vec![0.0; model.joint.rows()];
        model.joint.apply(&col(base, i), &mut b);
        let kn = model.contact.normal_stiffness;
        let p: Vec<f64> = (0..b.len())
            .map(|r| {
                if r % 3 == NORMAL && act[r / 3] {
                    kn * b[r]
                } else {
                    0.0
                }
            })
            .collect();
        let mut f = vec![0.0; model.dofs()];
        model.joint.apply_transpose_add(&p, &mut f);
        f
    }

    /// `inertia = false` is eq. (16): each column solves `K φ = f` (checked against a direct
    /// sparse solve of the independently formed pseudoforce) and is K-normalized.
    #[test]
    fn static_tvd_solves_eq16() {
        let model = Model::from_case_name("friction_bar").unwrap();
        let base = craig_bampton(&model, 10).unwrap();
        let tvd = trial_vector_derivatives(&model, base.as_ref(), &TvdOptions::default()).unwrap();
        assert!(tvd.omega2.iter().all(|&o| o == 0.0));
        // More TVD (496) than pairs (54): the uncompressed factor form.
        let f = tvd.factor.as_ref().unwrap();
        assert_eq!(f.flexibility.ncols(), model.joint.pairs());
        check_static_columns(&model, base.as_ref(), &tvd, &[0, 17, 100, 255, 400]);
    }

    /// Fewer TVD than pairs (multilayer sheet, 86 pairs, base Φ_S alone: ≤ 72 TVD): the
    /// compressed factor form `Z_Q = K⁻¹ B_uᵀ Q` (module docs) gives the TVD of eq. (16) and the
    /// K-weighted POD of the vectors themselves.
    #[test]
    fn compressed_factor_solves_eq16() {
        let model = Model::from_case_name("multilayer_sheet").unwrap();
        let base = craig_bampton(&model, 0).unwrap();
        let tvd = trial_vector_derivatives(&model, base.as_ref(), &TvdOptions::default()).unwrap();
        let p = tvd.nonzero();
        let f = tvd.factor.as_ref().unwrap();
        assert!(
            p < model.joint.pairs(),
            "{p} TVD, {} pairs",
            model.joint.pairs()
        );
        assert_eq!(f.flexibility.shape(), (model.dofs(), p));
        assert_eq!(f.coefficients.shape(), (p, p));
        check_static_columns(&model, base.as_ref(), &tvd, &[0, p / 3, p / 2]);
        let fast = crate::reduction::pod_tvd(&model, &tvd, true).unwrap();
        let gram = pod(tvd.vectors.as_ref(), Some(&model.stiffness)).unwrap();
        let lmax = gram.lambda[0];
        for (i, l) in gram
            .lambda
            .iter()
            .enumerate()
            .filter(|(_, l)| **l > 1e-6 * lmax)
        {
            let rel = (fast.lambda[i] - l).abs() / l;
            assert!(rel < 1e-6, "λ_{i}: {} vs {l}", fast.lambda[i]);
        }
        assert!(fast.choose_g(0.999) == gram.choose_g(0.999));
    }

    /// The secant TVD solve `(K + ∂K_{k,j}) φ = ∂K_{k,j} φ_i` directly (a dense Cholesky of
    /// `K + k_n Σ_{z∈A} b_zᵀ b_z` formed from the sparse K and the joint rows), before their
    /// K-normalization.
    #[test]
    fn secant_tvd_solve_the_switched_on_contact() {
        let model = Model::from_case_name("friction_bar").unwrap();
        let base = craig_bampton(&model, 10).unwrap();
        let opts = TvdOptions {
            secant: true,
            ..TvdOptions::default()
        };
        let tvd = trial_vector_derivatives(&model, base.as_ref(), &opts).unwrap();
        let (n, kn) = (model.dofs(), model.contact.normal_stiffness);
        let k = &model.stiffness;
        for c in [0, 17, 100, 255, tvd.nonzero() - 1] {
            let TvdIndex { k: sign, j, .. } = tvd.index[c];
            let act = &tvd.active[j][usize::from(sign > 0)];
            let mut a = Mat::<f64>::zeros(n, n);
            for col in 0..n {
                for p in k.col_ptr[col]..k.col_ptr[col + 1] {
                    a[(k.row_idx[p], col)] += k.values[p];
                }
            }
            for z in (0..model.joint.pairs()).filter(|&z| act[z]) {
                let row: Vec<(usize, f64)> = model.joint.row(3 * z + NORMAL).collect();
                for &(x, vx) in &row {
                    for &(y, vy) in &row {
                        a[(x, y)] += kn * vx * vy;
                    }
                }
            }
            let f = pseudoforce(&model, base.as_ref(), &tvd, c);
            let rhs = Mat::from_fn(n, 1, |r, _| f[r]);
            let x = a.llt(faer::Side::Lower).unwrap().solve(&rhs);
            let x = col(x.as_ref(), 0);
            let s = tvd.k_norms[c];
            let v = col(tvd.vectors.as_ref(), c);
            let dev = x
                .iter()
                .zip(&v)
                .fold(0.0f64, |m, (a, b)| m.max((a - s * b).abs()));
            assert!(
                dev <= 1e-7 * inf(&x),
                "column {c}: {dev:e} vs {:e}",
                inf(&x)
            );
        }
        let both = TvdOptions {
            tangential: true,
            ..opts
        };
        assert!(trial_vector_derivatives(&model, base.as_ref(), &both).is_err());
    }

    /// Columns `cols` (and the last) of a static TVD solve `K φ = f` with the independently
    /// formed pseudoforce (a direct sparse solve) and have `φᵀKφ = 1`.
    fn check_static_columns(model: &Model, base: MatRef<'_, f64>, tvd: &Tvd, cols: &[usize]) {
        let chol = SparseCholesky::new(&model.stiffness).unwrap();
        for &c in cols.iter().chain([tvd.nonzero() - 1].iter()) {
            let f = pseudoforce(model, base, tvd, c);
            let mut x = Mat::from_fn(f.len(), 1, |r, _| f[r]);
            chol.solve_in_place(&mut x);
            let x = col(x.as_ref(), 0);
            let s = tvd.k_norms[c];
            let v = col(tvd.vectors.as_ref(), c);
            let dev = x
                .iter()
                .zip(&v)
                .fold(0.0f64, |m, (a, b)| m.max((a - s * b).abs()));
            assert!(
                dev <= 1e-8 * inf(&x),
                "column {c}: {dev:e} vs {:e}",
                inf(&x)
            );
            let e: f64 = v
                .iter()
                .zip(mul(&model.stiffness, &v))
                .map(|(a, b)| a * b)
                .sum();
            assert!((e - 1.0).abs() < 1e-8, "column {c}: φᵀKφ = {e}");
        }
    }

    /// `inertia = true`: the fixed-interface modes get `Ω² =` their eigenvalue, the constraint
    /// modes 0; every column satisfies eq. (15),
    /// `(K − Ω_i² M) φ s = f − (φ_iᵀ f / φ_iᵀ M φ_i) M φ_i`, with `s` its K-norm; constraint-mode
    /// columns equal the static ones.
    #[test]
    fn inertia_tvd_satisfies_eq15() {
        for name in ["friction_bar", "multilayer_sheet"] {
            inertia_case(name);
        }
    }

    fn inertia_case(name: &str) {
        let model = Model::from_case_name(name).unwrap();
        let base = craig_bampton(&model, 10).unwrap();
        let opts = TvdOptions {
            inertia: true,
            ..TvdOptions::default()
        };
        let tvd = trial_vector_derivatives(&model, base.as_ref(), &opts).unwrap();
        let plain =
            trial_vector_derivatives(&model, base.as_ref(), &TvdOptions::default()).unwrap();
        assert_eq!(tvd.index, plain.index);
        let modes = model.modes(10, crate::model::Interface::Fixed).unwrap();
        for v in 0..10 {
            let (a, b) = (tvd.omega2[6 + v], modes.eigenvalues[v]);
            assert!((a - b).abs() < 1e-8 * b, "mode {v}: Ω² {a} vs {b}");
        }
        assert!(tvd.omega2[..6].iter().all(|&o| o == 0.0));
        let (k_norm, m_norm) = (model.stiffness.inf_norm(), model.mass.inf_norm());
        let mut checked = 0;
        for c in (0..tvd.nonzero()).step_by(37) {
            let i = tvd.index[c].i;
            let om2 = tvd.omega2[i];
            let phi = col(base.as_ref(), i);
            let mphi = mul(&model.mass, &phi);
            let f = pseudoforce(&model, base.as_ref(), &tvd, c);
            let dom2 = if om2 == 0.0 {
                0.0
            } else {
                phi.iter().zip(&f).map(|(a, b)| a * b).sum::<f64>()
                    / phi.iter().zip(&mphi).map(|(a, b)| a * b).sum::<f64>()
            };
            let rhs: Vec<f64> = f.iter().zip(&mphi).map(|(a, b)| a - dom2 * b).collect();
            let s = tvd.k_norms[c];
            let x: Vec<f64> = col(tvd.vectors.as_ref(), c).iter().map(|v| v * s).collect();
            let kx = mul(&model.stiffness, &x);
            let mx = mul(&model.mass, &x);
            let res: Vec<f64> = (0..x.len()).map(|r| kx[r] - om2 * mx[r] - rhs[r]).collect();
            // Normwise backward error.
            let scale = (k_norm + om2 * m_norm) * inf(&x) + inf(&rhs);
            let backward = inf(&res) / scale;
            assert!(
                backward <= 1e-12,
                "column {c} (Ω² {om2}): backward error {backward:e}"
            );
            if om2 == 0.0 {
                let v = col(plain.vectors.as_ref(), c);
                let u = col(tvd.vectors.as_ref(), c);
                let dev = u
                    .iter()
                    .zip(&v)
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                assert!(dev <= 1e-12 * inf(&v), "column {c}: {dev:e}");
            } else {
                checked += 1;
            }
        }
        assert!(checked > 5);
        // Report w(g) of both variants (K-weighted POD) for the record.
        let wi = pod(tvd.vectors.as_ref(), Some(&model.stiffness)).unwrap();
        let ws = pod(plain.vectors.as_ref(), Some(&model.stiffness)).unwrap();
        println!(
            "{name} w(g), eq. (15): g(0.999) = {}, w[..30] = {:?}",
            wi.choose_g(0.999),
            &wi.w[..30]
        );
        println!(
            "{name} w(g), eq. (16): g(0.999) = {}, w[..30] = {:?}",
            ws.choose_g(0.999),
            &ws.w[..30]
        );
    }
}
