//! The final basis `Φ = [Φ_S Φ_V Φ̃_T]` (Algorithm 2, output), its M-orthonormalization and the
//! one-call builder [`build_basis`].

use faer::{Mat, MatRef, Side};

use crate::assembly::SymCsc;
use crate::error::Error;
use crate::model::Model;

use super::alldof::{alldof_vectors, split, two_product_sums};
use super::craig_bampton::craig_bampton;
use super::jim::{jim_vectors, JimSet};
use super::pod::{pod_tvd, DEFAULT_THRESHOLD};
use super::tvd::{trial_vector_derivatives, TvdOptions};
use crate::statics::sym_mul_vec_into;

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
    let n = m.n;
    if let Some(p) = parts.iter().find(|p| p.nrows() != n) {
        return Err(Error::Invalid(format!(
            "basis part has {} rows, the mass matrix is {n}×{n}",
            p.nrows()
        )));
    }
    let mut q: Vec<Vec<f64>> = Vec::new();
    let mut mq: Vec<Vec<f64>> = Vec::new();
    // Veltkamp splits of the accepted columns, for the compensated updates.
    let mut q_hi: Vec<Vec<f64>> = Vec::new();
    let mut q_lo: Vec<Vec<f64>> = Vec::new();
    let mut dropped = 0;
    let mut mv = vec![0.0; n];
    let mut hi = vec![0.0; n];
    let mut lo = vec![0.0; n];
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    for part in parts {
        for c in 0..part.ncols() {
            let mut v: Vec<f64> = part.col(c).iter().copied().collect();
            sym_mul_vec_into(m, &v, &mut mv);
            let norm0 = dot(&v, &mv).max(0.0).sqrt();
            if !norm0.is_finite() {
                return Err(Error::Invalid("basis column is not finite".into()));
            }
            if norm0 == 0.0 {
                dropped += 1;
                continue;
            }
            for _ in 0..2 {
                // v ← v − Σ_k (q_kᵀ M v) q_k, each entry accumulated in double-double (`hi + lo`,
                // the arithmetic of `Dot2`) and rounded once (see the doc comment).
                hi.copy_from_slice(&v);
                lo.fill(0.0);
                for ((mqk, qh), ql) in mq.iter().zip(&q_hi).zip(&q_lo) {
                    let a = -dot(mqk, &v);
                    let (ah, al) = split(a);
                    two_product_sums(&mut hi, &mut lo, a, ah, al, qh, ql);
                    // Modified Gram–Schmidt: the next coefficient sees this update.
                    for ((x, h), l) in v.iter_mut().zip(&hi).zip(&lo) {
                        *x = h + l;
                    }
                }
            }
            sym_mul_vec_into(m, &v, &mut mv);
            let norm = dot(&v, &mv).max(0.0).sqrt();
            if norm <= drop_tol * norm0 {
                dropped += 1;
                continue;
            }
            v.iter_mut().for_each(|x| *x /= norm);
            mv.iter_mut().for_each(|x| *x /= norm);
            let (h, l): (Vec<f64>, Vec<f64>) = v.iter().map(|&x| split(x)).unzip();
            q_hi.push(h);
            q_lo.push(l);
            q.push(v);
            mq.push(mv.clone());
        }
    }
    Ok((Mat::from_fn(n, q.len(), |r, c| q[c][r]), dropped))
}

/// Which enrichment of the Craig–Bampton basis [`build_basis`] uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BasisKind {
    /// TVD joint modes from the K-weighted POD (eqs. 24–25; the paper's choice).
    Tvd,
    /// TVD joint modes from the plain (Euclidean) POD (eqs. 20–22).
    TvdPlain,
    /// No joint modes: Craig–Bampton with ν + g fixed-interface modes instead (the paper's
    /// comparison, Figure 7).
    Modes,
    /// Craig–Bampton plus the g lowest Joint Interface Modes (Witteveen & Irschik 2009; the
    /// paper's Section 5.3 and Figure 19), of the set [`BasisOptions::jim_set`]; see
    /// [`super::jim`].
    Jim,
    /// Craig–Bampton plus the static constraint modes of every joint pair's relative normal DOF
    /// (all joint DOF kept, the paper's Section 5.1); g is ignored and reported as the number of
    /// pairs; see [`super::alldof`].
    AllDof,
}

impl BasisKind {
    /// Every kind, in the order of [`BasisKind::NAMES`].
    pub const ALL: [BasisKind; 5] = [
        BasisKind::Tvd,
        BasisKind::TvdPlain,
        BasisKind::Modes,
        BasisKind::Jim,
        BasisKind::AllDof,
    ];

    /// The accepted names: `tvd`, `tvd-plain`, `modes`, `jim`, `alldof`.
    pub const NAMES: [&'static str; 5] = ["tvd", "tvd-plain", "modes", "jim", "alldof"];

    /// The kind's name (as accepted by [`BasisKind::from_name`] and the CLI's `--basis`).
    pub fn name(self) -> &'static str {
        match self {
            BasisKind::Tvd => "tvd",
            BasisKind::TvdPlain => "tvd-plain",
            BasisKind::Modes => "modes",
            BasisKind::Jim => "jim",
            BasisKind::AllDof => "alldof",
        }
    }

    /// Parses a name of [`BasisKind::NAMES`] (exact, lower case); anything else is an
    /// [`Error::Invalid`] listing the accepted names.
    pub fn from_name(name: &str) -> Result<BasisKind, Error> {
        BasisKind::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| {
                Error::Invalid(format!(
                    "unknown basis `{name}`: expected one of {}",
                    BasisKind::NAMES.join(", ")
                ))
            })
    }
}

/// Options of [`build_basis`]. Defaults: `nu = 10` (the paper), `g = None` (chosen by
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
    /// The joint DOF set of [`BasisKind::Jim`].
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

/// Builds `Φ = [Φ_S Φ_V Φ̃_T]` (Algorithm 2) for a model: Craig–Bampton with ν modes, TVD of
/// all 6 + ν vectors, POD (weighted for `Tvd`, plain for `TvdPlain`), the first g POMs,
/// M-orthonormalization ([`final_basis`]) and, with `opts.modal` (default), the rotation to the
/// reduced eigenbasis ([`modal_rotation`]). The competitors replace `Φ̃_T`:
///
/// - `Modes`: Craig–Bampton with ν + g fixed-interface modes;
/// - `Jim`: the g lowest Joint Interface Modes of `opts.jim_set` ([`jim_vectors`]);
/// - `AllDof`: the constraint modes of all pairs' normal DOF ([`alldof_vectors`]), g = w.
///
/// For `Modes` and `Jim` with `g = None` the TVD and their K-weighted POD are still computed, to
/// choose g exactly as `Tvd` would (the smallest g with `w(g) ≥ opts.threshold`), so the
/// competitors are compared at the same number of added vectors; `Basis::w` is then that POD's.
pub fn build_basis(model: &Model, kind: BasisKind, opts: &BasisOptions) -> Result<Basis, Error> {
    let need_tvd = match kind {
        BasisKind::Tvd | BasisKind::TvdPlain => true,
        BasisKind::Modes | BasisKind::Jim => opts.g.is_none(),
        BasisKind::AllDof => false,
    };
    let cb = craig_bampton(model, opts.nu)?;
    let (w, g, tvd_total, tvd_nonzero, joint_modes) = if need_tvd {
        let tvd = trial_vector_derivatives(model, cb.as_ref(), &opts.tvd)?;
        let p = pod_tvd(model, &tvd, kind != BasisKind::TvdPlain)?;
        let g = opts
            .g
            .unwrap_or_else(|| p.choose_g(opts.threshold))
            .min(p.lambda.len());
        let jm = p.leading(g).to_owned();
        (p.w, g, tvd.total, tvd.nonzero(), jm)
    } else {
        (
            Vec::new(),
            opts.g.unwrap_or(0),
            0,
            0,
            Mat::zeros(model.dofs(), 0),
        )
    };
    let (phi, dropped, g) = match kind {
        BasisKind::Modes => {
            let cbg = craig_bampton(model, opts.nu + g)?;
            let (phi, dropped) = final_basis(&[cbg.as_ref()], &model.mass, opts.drop_tol)?;
            (phi, dropped, g)
        }
        BasisKind::Jim => {
            let jim = jim_vectors(model, g, opts.jim_set)?;
            let (phi, dropped) =
                final_basis(&[cb.as_ref(), jim.as_ref()], &model.mass, opts.drop_tol)?;
            (phi, dropped, g)
        }
        BasisKind::AllDof => {
            let psi = alldof_vectors(model)?;
            let (phi, dropped) =
                final_basis(&[cb.as_ref(), psi.as_ref()], &model.mass, opts.drop_tol)?;
            (phi, dropped, psi.ncols())
        }
        BasisKind::Tvd | BasisKind::TvdPlain => {
            let (phi, dropped) = final_basis(
                &[cb.as_ref(), joint_modes.as_ref()],
                &model.mass,
                opts.drop_tol,
            )?;
            (phi, dropped, g)
        }
    };
    let (phi, eigenvalues) = if opts.modal {
        modal_rotation(model, phi)?
    } else {
        (phi, Vec::new())
    };
    Ok(Basis {
        phi,
        w,
        g,
        tvd_total,
        tvd_nonzero,
        dropped,
        eigenvalues,
    })
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
/// on the rotated one (measured, `tests/competitors.rs`). The diagonal `K̃` is also the natural
/// form for the time integration (its largest ω bounds the reduced model's stiffness).
pub fn modal_rotation(model: &Model, phi: Mat<f64>) -> Result<(Mat<f64>, Vec<f64>), Error> {
    if phi.nrows() != model.dofs() {
        return Err(Error::Invalid(format!(
            "basis has {} rows, the model {} DOF",
            phi.nrows(),
            model.dofs()
        )));
    }
    if phi.ncols() == 0 {
        return Ok((phi, Vec::new()));
    }
    let k = super::compensated_gram(&model.stiffness, phi.as_ref());
    let evd = k
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| Error::LinearAlgebra(format!("reduced eigenproblem: {e:?}")))?;
    let lambda: Vec<f64> = evd.S().column_vector().iter().copied().collect();
    if let Some(l) = lambda.iter().find(|l| !(l.is_finite() && **l > 0.0)) {
        return Err(Error::LinearAlgebra(format!(
            "reduced stiffness ΦᵀKΦ is not positive definite (eigenvalue {l:e})"
        )));
    }
    Ok((&phi * evd.U(), lambda))
}
