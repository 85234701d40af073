//! Trial vector derivatives for joint contact (Algorithm 2, lines 3–20; eqs. 16, 18, 19, 27–28).

use faer::{Mat, MatRef};

use crate::error::Error;
use crate::joint::{NORMAL, T1, T2};
use crate::model::Model;
use crate::statics::SparseCholesky;

/// Options of [`trial_vector_derivatives`]. Defaults: `tol = 1e-6`, `zero_gap_active = true`,
/// `tangential = false`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TvdOptions {
    /// Relative zero of a gap: under trial vector φ_j a pair gap with
    /// `|g_z| ≤ tol · max_pairs |g|` counts as exactly zero (eigen-solver noise is ~1e-8–1e-7
    /// of a mode's size, NOTES). Also the relative zero of a pseudoforce column (see
    /// [`Tvd::negligible_columns`]).
    pub tol: f64,
    /// Whether an exactly-zero gap (in the sense of `tol`) is active. `true` is the paper's
    /// rule `g ≤ 0` (Algorithm 2, line 9); `false` makes only penetrating pairs (`g < 0`) active.
    pub zero_gap_active: bool,
    /// Add the stick stiffness `k_t` on the two tangential rows of active pairs too (Algorithm 2,
    /// line 10 adds `k_n` and `k_t`). `false`: normal stiffness `k_n` only.
    pub tangential: bool,
}

impl Default for TvdOptions {
    fn default() -> Self {
        TvdOptions {
            tol: 1e-6,
            zero_gap_active: true,
            tangential: false,
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
    /// K-normalized TVD (n × p), `φᵀ K φ = 1` for each column.
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
    /// Candidates whose pseudoforce is nonzero but below `tol` relative to φ_i's own joint scale
    /// (`‖f‖∞ ≤ tol · k_n · max_rows |B φ_i|`): round-off, dropped too.
    pub negligible_columns: usize,
    /// For each base vector j, the active pairs for `k = −1` and `k = +1`.
    pub active: Vec<[Vec<bool>; 2]>,
}

impl Tvd {
    /// Number of kept (nonzero) columns p.
    pub fn nonzero(&self) -> usize {
        self.vectors.ncols()
    }
}

/// The active pairs under the scaled trial vector `k · φ_j`, given its normal gaps `g = B_n φ_j`
/// (w values).
///
/// A gap is "zero" when `|g_z| ≤ tol · max_z |g_z|`; a zero gap is active iff
/// `zero_gap_active`. Otherwise pair z is active iff `k g_z < 0` (penetration). When all gaps are
/// exactly zero (`max |g| = 0`, e.g. an in-plane constraint mode) every gap is zero and the same
/// rule applies: all pairs are active for both signs if `zero_gap_active`, none otherwise.
///
/// What "zero" catches on the built-in cases (Craig–Bampton, ν = 10, `tol = 1e-6`): in the
/// friction bar 136 of 16 × 54 gaps, 126 of them ≤ 1e-10 relative — the centre-line pairs under
/// the vectors antisymmetric in z (symmetry zeros) — and the rest the weld pairs' true but tiny
/// gaps (~1e-7 relative, the welds are very stiff); in the multilayer sheet 52 of 16 × 92, most
/// in the 1e-8–1e-6 band. No base vector has all gaps exactly zero on either case, and the rule
/// changes no column count (every candidate keeps some active penetrating pair); it changes the
/// K-weighted `g(0.999)` of the friction bar from 12 (`true`) to 13 (`false`).
pub fn active_pairs(gaps: &[f64], k: f64, opts: &TvdOptions) -> Vec<bool> {
    let scale = gaps.iter().fold(0.0f64, |a, g| a.max(g.abs()));
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

/// Trial vector derivatives of `base` (Algorithm 2): for each trial vector φ_j and sign
/// `k = ±1` the active pairs of `k φ_j` ([`active_pairs`]) define
/// `∂K/∂q_{k,j} = Σ_active k_n b_nᵀ b_n (+ k_t (b_t1ᵀ b_t1 + b_t2ᵀ b_t2))`, and for every φ_i the
/// pseudoforce `f_{i,k,j} = ∂K/∂q_{k,j} φ_i` (eq. 19) is formed through the joint operator,
/// `Bᵀ (D_{k,j} B φ_i)`, never as a dense n × n matrix. One sparse Cholesky of the full `K`
/// (master free, the paper's K) solves all kept right-hand sides: `K φ_{i,k,j} = f_{i,k,j}`
/// (eqs. 16/18, inertia terms of eq. 15 neglected). Columns are ordered j, then k = −1, +1, then
/// i; zero pseudoforces are dropped and counted; each kept column is normalized w.r.t. K
/// (Algorithm 2, line 20).
pub fn trial_vector_derivatives(
    model: &Model,
    base: MatRef<'_, f64>,
    opts: &TvdOptions,
) -> Result<Tvd, Error> {
    let n = model.dofs();
    if base.nrows() != n {
        return Err(Error::Invalid(format!(
            "TVD base has {} rows, the model {n} DOF",
            base.nrows()
        )));
    }
    if !(opts.tol >= 0.0 && opts.tol < 1.0) {
        return Err(Error::Invalid(format!(
            "TVD zero tolerance must be in [0, 1), got {}",
            opts.tol
        )));
    }
    let joint = &model.joint;
    let w = joint.pairs();
    let kn = model.case.contact.normal_stiffness;
    let kt = model.case.contact.stick_stiffness;
    let nb = base.ncols();
    let bphi = joint.reduce(base); // 3w × nb
                                   // Joint scale of each φ_i over the rows that receive stiffness.
    let rows_used: &[usize] = if opts.tangential {
        &[NORMAL, T1, T2]
    } else {
        &[NORMAL]
    };
    let joint_scale: Vec<f64> = (0..nb)
        .map(|i| {
            (0..w)
                .flat_map(|z| rows_used.iter().map(move |&r| 3 * z + r))
                .fold(0.0f64, |a, r| a.max(bphi[(r, i)].abs()))
        })
        .collect();
    let max_stiff = if opts.tangential { kn.max(kt) } else { kn };

    let total = 2 * nb * nb;
    let mut forces: Vec<Vec<f64>> = Vec::new();
    let mut index = Vec::new();
    let mut active_all = Vec::with_capacity(nb);
    let mut zero_columns = 0;
    let mut negligible_columns = 0;
    let mut p = vec![0.0; 3 * w];
    for j in 0..nb {
        let gaps: Vec<f64> = (0..w).map(|z| bphi[(3 * z + NORMAL, j)]).collect();
        let act = [
            active_pairs(&gaps, -1.0, opts),
            active_pairs(&gaps, 1.0, opts),
        ];
        for (ki, k) in [-1i8, 1].into_iter().enumerate() {
            for i in 0..nb {
                p.iter_mut().for_each(|v| *v = 0.0);
                for z in (0..w).filter(|&z| act[ki][z]) {
                    p[3 * z + NORMAL] = kn * bphi[(3 * z + NORMAL, i)];
                    if opts.tangential {
                        p[3 * z + T1] = kt * bphi[(3 * z + T1, i)];
                        p[3 * z + T2] = kt * bphi[(3 * z + T2, i)];
                    }
                }
                let pmax = p.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                if pmax == 0.0 {
                    zero_columns += 1;
                    continue;
                }
                if pmax <= opts.tol * max_stiff * joint_scale[i] {
                    negligible_columns += 1;
                    continue;
                }
                let mut f = vec![0.0; n];
                joint.apply_transpose_add(&p, &mut f);
                forces.push(f);
                index.push(TvdIndex { i, k, j });
            }
        }
        active_all.push(act);
    }

    let cols = forces.len();
    let mut x = Mat::from_fn(n, cols, |r, c| forces[c][r]);
    if cols > 0 {
        let chol = SparseCholesky::new(&model.stiffness)?;
        chol.solve_in_place(&mut x);
    }
    let mut k_norms = Vec::with_capacity(cols);
    let mut kx = vec![0.0; n];
    for c in 0..cols {
        let xc: Vec<f64> = x.col(c).iter().copied().collect();
        model.stiffness.mul_vec(&xc, &mut kx);
        let e: f64 = xc.iter().zip(&kx).map(|(a, b)| a * b).sum();
        if !(e.is_finite() && e > 0.0) {
            return Err(Error::LinearAlgebra(format!(
                "TVD column {c} ({:?}) has strain energy {e:e}; K is not positive definite",
                index[c]
            )));
        }
        let s = e.sqrt();
        for r in 0..n {
            x[(r, c)] /= s;
        }
        k_norms.push(s);
    }
    Ok(Tvd {
        vectors: x,
        index,
        k_norms,
        total,
        zero_columns,
        negligible_columns,
        active: active_all,
    })
}
