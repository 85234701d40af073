//! The final basis `Φ = [Φ_S Φ_V Φ̃_T]` (Algorithm 2, output): its M-orthonormalization, the
//! rotation to the reduced eigenbasis, and the options and result types of
//! [`super::build_basis`].

use faer::{Mat, MatRef};

use super::pod::DEFAULT_THRESHOLD;
use super::tvd::TvdOptions;
use crate::error::{Error, ReductionError};
use crate::linalg::compensated::product_sums;
use crate::linalg::sparse::{sym_mul_mat, sym_mul_vec_into, SymCsc};
use crate::linalg::symmetric_eigen;
use crate::linalg::LinalgError;
use crate::model::Model;

/// Default relative drop tolerance of [`final_basis`].
pub const DEFAULT_DROP_TOL: f64 = 1e-8;

/// Concatenates `parts` (each n × r_k) and M-orthonormalizes the columns in order by modified
/// Gram–Schmidt in the M inner product, run twice per column ("twice is enough"). A column
/// whose M-norm after orthogonalization is `≤ drop_tol ·` its M-norm before is linearly
/// dependent on the earlier ones (to that tolerance) and is dropped. Returns `(Φ, dropped)`
/// with `Φᵀ M Φ = I`; the span of the earlier columns is kept exactly, so `Φ_S` and `Φ_V`
/// stay in the basis when they come first.
///
/// The updates `v − a q` are accumulated in double-double and rounded once per entry, so the
/// rounding noise left in a column is `eps` of the *orthogonalized* column, not of the original:
/// for stiff local vectors nearly in the span of earlier ones (the multilayer's alldof constraint
/// modes), plain arithmetic leaves noise `eps ‖v‖` whose strain energy, relative to the small
/// remainder, was large enough to perturb the reduced contact forces by ~5e-7.
pub fn final_basis(
    parts: &[MatRef<'_, f64>],
    m: &SymCsc,
    drop_tol: f64,
) -> Result<(Mat<f64>, usize), Error> {
    orthonormalize(parts, m, drop_tol, None)
}

/// The columns that [`final_basis`] of `[phi, extra]` appends to an M-orthonormal `phi`
/// (n × r, `ΦᵀMΦ = I`): `extra` (n × m) M-orthonormalized against Φ and among themselves, with
/// Φ taken as it is instead of orthonormalized again. Φ's part is removed in blocks —
/// `W ← W − Φ (MΦ)ᵀ W`, twice ("twice is enough") — and the remainders go through
/// [`final_basis`]'s modified Gram–Schmidt among themselves, a column dropped when its M-norm
/// is `≤ drop_tol ·` its M-norm before the projection. Returns `(Ψ, dropped)`.
///
/// For columns that are not nearly in Φ's span (smooth, global vectors such as the
/// fixed-interface modes beyond a basis) the block projection in plain arithmetic is accurate:
/// its rounding noise, `eps ‖v‖`, is far below the remainder. The compensated updates of
/// [`final_basis`] are for stiff local vectors nearly in the span of earlier ones.
pub fn orthonormal_beyond(
    phi: MatRef<'_, f64>,
    extra: MatRef<'_, f64>,
    m: &SymCsc,
    drop_tol: f64,
) -> Result<(Mat<f64>, usize), Error> {
    let n = m.n;
    if let Some(p) = [phi, extra].iter().find(|p| p.nrows() != n) {
        return Err(ReductionError::PartRows { rows: p.nrows(), n }.into());
    }
    let m_extra = sym_mul_mat(m, extra);
    let norm0: Vec<f64> = (0..extra.ncols())
        .map(|j| {
            let v = extra.col(j).iter().zip(m_extra.col(j).iter());
            v.map(|(a, b)| a * b).sum::<f64>().max(0.0).sqrt()
        })
        .collect();
    let m_phi = sym_mul_mat(m, phi);
    let mut w = extra.to_owned();
    for _ in 0..2 {
        let c = m_phi.transpose() * &w;
        w -= phi * &c;
    }
    orthonormalize(&[w.as_ref()], m, drop_tol, Some(&norm0))
}

/// [`final_basis`], each column's M-norm before its orthogonalization taken from `norm0` when
/// given (one per column of `parts`, in order).
fn orthonormalize(
    parts: &[MatRef<'_, f64>],
    m: &SymCsc,
    drop_tol: f64,
    norm0: Option<&[f64]>,
) -> Result<(Mat<f64>, usize), Error> {
    let mut gs = Orthonormalizer::new(m, drop_tol);
    let mut column = 0;
    for part in parts {
        if part.nrows() != m.n {
            return Err(ReductionError::PartRows {
                rows: part.nrows(),
                n: m.n,
            }
            .into());
        }
        for c in 0..part.ncols() {
            let v: Vec<f64> = part.col(c).iter().copied().collect();
            gs.push_with_norm(v, norm0.map(|given| given[column]))?;
            column += 1;
        }
    }
    let dropped = gs.dropped();
    Ok((gs.into_basis(), dropped))
}

/// The modified Gram–Schmidt of [`final_basis`], one column at a time, resumable: the state
/// after the first k columns does not depend on the ones after, so a caller whose next basis
/// starts with the same columns as its last one ([`Orthonormalizer::truncate`] to their count)
/// orthonormalizes only the new ones — the same bits as [`final_basis`] of all of them.
#[derive(Clone, Debug)]
pub struct Orthonormalizer<'m> {
    m: &'m SymCsc,
    drop_tol: f64,
    /// The accepted columns' M-products and the columns.
    mq: Vec<Vec<f64>>,
    q: Vec<Vec<f64>>,
    /// Per column pushed, the accepted columns after it.
    accepted_after: Vec<usize>,
}

impl<'m> Orthonormalizer<'m> {
    /// No columns yet; `drop_tol` as in [`final_basis`].
    pub fn new(m: &'m SymCsc, drop_tol: f64) -> Orthonormalizer<'m> {
        Orthonormalizer {
            m,
            drop_tol,
            mq: Vec::new(),
            q: Vec::new(),
            accepted_after: Vec::new(),
        }
    }

    /// Columns pushed so far (accepted or dropped).
    pub fn pushed(&self) -> usize {
        self.accepted_after.len()
    }

    /// Columns dropped so far (linearly dependent on earlier ones, or zero).
    pub fn dropped(&self) -> usize {
        self.pushed() - self.q.len()
    }

    /// Forgets every column pushed after the first `pushed`.
    pub fn truncate(&mut self, pushed: usize) {
        if pushed >= self.pushed() {
            return;
        }
        self.accepted_after.truncate(pushed);
        let keep = self.accepted_after.last().copied().unwrap_or(0);
        for v in [&mut self.mq, &mut self.q] {
            v.truncate(keep);
        }
    }

    /// The accepted columns (n × accepted), `Φᵀ M Φ = I`.
    pub fn basis(&self) -> Mat<f64> {
        Mat::from_fn(self.m.n, self.q.len(), |r, c| self.q[c][r])
    }

    /// [`Orthonormalizer::basis`], releasing each column's working copies as it is placed.
    pub fn into_basis(mut self) -> Mat<f64> {
        let mut out = Mat::<f64>::zeros(self.m.n, self.q.len());
        for c in (0..self.q.len()).rev() {
            self.mq.pop();
            let Some(q) = self.q.pop() else { break };
            for (r, a) in q.iter().enumerate() {
                out[(r, c)] = *a;
            }
        }
        out
    }

    /// Orthogonalizes `v` (n values) against the accepted columns and accepts it unless it is
    /// dependent on them ([`final_basis`]).
    ///
    /// # Errors
    /// [`ReductionError::PartRows`] for a column of the wrong length,
    /// [`ReductionError::NotFinite`] for one that is not finite.
    pub fn push(&mut self, v: Vec<f64>) -> Result<(), Error> {
        self.push_with_norm(v, None)
    }

    /// [`Orthonormalizer::push`], the column's M-norm before its orthogonalization (the scale
    /// of the drop test) `norm0` when given.
    fn push_with_norm(&mut self, mut v: Vec<f64>, norm0: Option<f64>) -> Result<(), Error> {
        let n = self.m.n;
        if v.len() != n {
            return Err(ReductionError::PartRows { rows: v.len(), n }.into());
        }
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let mut mv = vec![0.0; n];
        let norm0 = match norm0 {
            Some(given) => given,
            None => {
                sym_mul_vec_into(self.m, &v, &mut mv);
                dot(&v, &mv).max(0.0).sqrt()
            }
        };
        if !norm0.is_finite() {
            return Err(ReductionError::NotFinite {
                what: "basis column is",
            }
            .into());
        }
        if norm0 == 0.0 {
            self.accepted_after.push(self.q.len());
            return Ok(());
        }
        let mut hi = vec![0.0; n];
        let mut lo = vec![0.0; n];
        for _ in 0..2 {
            // v ← v − Σ_k (q_kᵀ M v) q_k, each entry accumulated in double-double (`hi + lo`,
            // the arithmetic of `Dot2`) and rounded once (see [`final_basis`]).
            hi.copy_from_slice(&v);
            lo.fill(0.0);
            for (mqk, qk) in self.mq.iter().zip(&self.q) {
                let a = -dot(mqk, &v);
                product_sums(&mut hi, &mut lo, a, qk);
                // Modified Gram–Schmidt: the next coefficient sees this update.
                for ((x, h), l) in v.iter_mut().zip(&hi).zip(&lo) {
                    *x = h + l;
                }
            }
        }
        sym_mul_vec_into(self.m, &v, &mut mv);
        let norm = dot(&v, &mv).max(0.0).sqrt();
        if norm > self.drop_tol * norm0 {
            v.iter_mut().for_each(|x| *x /= norm);
            mv.iter_mut().for_each(|x| *x /= norm);
            self.q.push(v);
            self.mq.push(mv);
        }
        self.accepted_after.push(self.q.len());
        Ok(())
    }
}

/// Which joint DOF the Joint Interface Modes are condensed to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum JimSet {
    /// The out-of-plane (y) translations of the joint nodes: the normal (gap) direction.
    Normal,
    /// The in-plane (x and z) translations of the joint nodes: the slip directions.
    InPlane,
    /// Both sets, condensed separately, their modes merged by eigenfrequency ascending. Default.
    #[default]
    Both,
}

impl JimSet {
    /// `"normal"`, `"in-plane"` or `"both"`.
    pub fn name(self) -> &'static str {
        match self {
            JimSet::Normal => "normal",
            JimSet::InPlane => "in-plane",
            JimSet::Both => "both",
        }
    }
}

/// Options of [`super::build_basis`]. Defaults: `nu = 10` (the paper), `g = None` (chosen by
/// `threshold`), `threshold =` [`DEFAULT_THRESHOLD`] (0.999), `tvd =` [`TvdOptions::default`]
/// (tol 1e-6, zero gaps active, no tangential stiffness), `drop_tol =` [`DEFAULT_DROP_TOL`],
/// `jim_set =` [`JimSet::Both`], `modal = true`. Construct with `..Default::default()`: fields
/// may be added.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BasisOptions {
    /// Fixed-interface normal modes ν.
    pub nu: usize,
    /// Number of joint modes g; `None`: the smallest g with `w(g) ≥ threshold`.
    pub g: Option<usize>,
    /// Energy threshold for choosing g (eq. 26).
    pub threshold: f64,
    /// TVD options (zero-gap rule, tangential stiffness).
    pub tvd: TvdOptions,
    /// Relative drop tolerance of the final M-orthonormalization.
    pub drop_tol: f64,
    /// The joint DOF set of [`super::BasisKind::Jim`].
    pub jim_set: JimSet,
    /// Rotate the M-orthonormal basis to the reduced eigenbasis (see [`modal_rotation`]).
    pub modal: bool,
}

impl Default for BasisOptions {
    fn default() -> Self {
        BasisOptions {
            nu: 10,
            g: None,
            threshold: DEFAULT_THRESHOLD,
            tvd: TvdOptions::default(),
            drop_tol: DEFAULT_DROP_TOL,
            jim_set: JimSet::Both,
            modal: true,
        }
    }
}

/// A built basis and how it was chosen.
#[derive(Clone, Debug)]
pub struct Basis {
    /// M-orthonormal basis (n × r), `Φᵀ M Φ = I`.
    pub phi: Mat<f64>,
    /// The POD energy ratio `w[g − 1] = w(g)` of the TVD (the K-weighted one for `Modes` and
    /// `Jim`; empty for `Modes` and `Jim` with an explicit g, where no TVD are computed, and for
    /// `AllDof`; the snapshot POD's for [`super::snapshot_basis`]).
    pub w: Vec<f64>,
    /// Number of joint modes g used (for `Modes`: extra fixed-interface modes; for `Jim`: Joint
    /// Interface Modes; for `AllDof`: the number of pairs; for snapshots: POMs).
    pub g: usize,
    /// TVD candidates `2 (v + s)²` and kept nonzero columns.
    pub tvd_total: usize,
    /// Kept (nonzero) TVD columns.
    pub tvd_nonzero: usize,
    /// Directions dropped by the final M-orthonormalization.
    pub dropped: usize,
    /// With `modal`: the reduced eigenvalues `ω² = diag(ΦᵀKΦ)` (1/s²), ascending, one per
    /// column; empty otherwise.
    pub eigenvalues: Vec<f64>,
}

/// Rotates an M-orthonormal basis Φ (n × r) to the eigenbasis of the reduced problem:
/// `K̃ V = V Λ` with `K̃ = ΦᵀKΦ` (formed with compensated products), `Φ' = Φ V`, so that
/// `Φ'ᵀMΦ' = I` and `Φ'ᵀKΦ' = Λ = diag(ω²)` (1/s², ascending). The span is unchanged (V is
/// orthogonal), but the column order no longer separates `Φ_S`, `Φ_V` and the joint modes.
///
/// Why: a Cholesky solve is accurate relative to the diagonal scaling of its matrix, and the
/// M-orthonormal Gram–Schmidt basis has a `K̃` (cond ≈ 1e9–1e10 with stiff joint vectors) that
/// no diagonal scaling repairs, so rounding `K̃` to double alone perturbs the reduced solution by
/// cond·eps. The contact gaps of the multilayer sheet are ~1e-6 of its displacement, which made
/// the all-joint-DOF basis miss the full ‖f_c‖ by 1.4e-7 on the Gram–Schmidt basis and by 2e-10
/// on the rotated one (measured, `tests/reduction/competitors.rs`). The diagonal `K̃` is also the natural
/// form for the time integration (its largest ω bounds the reduced model's stiffness).
pub fn modal_rotation(model: &Model, phi: Mat<f64>) -> Result<(Mat<f64>, Vec<f64>), Error> {
    if phi.nrows() != model.dofs() {
        return Err(ReductionError::Rows {
            what: "basis has",
            rows: phi.nrows(),
            dofs: model.dofs(),
        }
        .into());
    }
    if phi.ncols() == 0 {
        return Ok((phi, Vec::new()));
    }
    let k = crate::linalg::compensated::compensated_gram(&model.stiffness, phi.as_ref());
    let evd =
        symmetric_eigen(k.as_ref(), "reduced eigenproblem ΦᵀKΦ").map_err(Error::LinearAlgebra)?;
    let lambda = evd.values;
    if let Some(l) = lambda.iter().find(|l| !(l.is_finite() && **l > 0.0)) {
        return Err(Error::LinearAlgebra(LinalgError::ReducedStiffness {
            eigenvalue: *l,
        }));
    }
    Ok((&phi * &evd.vectors, lambda))
}
