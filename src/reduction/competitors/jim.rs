//! Joint Interface Modes (Witteveen & Irschik 2009, reference \[10\] of the paper; the competitor
//! of Witteveen & Pichler 2014, Section 5.3).
//!
//! "The structure is statically condensed to the DOF of the joints. This condensation leads to a
//! reduced mass and stiffness matrix which are used for a subsequent eigenvalue problem. The
//! obtained eigenvectors are used as Joint Interface Modes" (Section 5.3), with the trial vectors
//! "in normal and in-plane directions of the contact surface … computed separately" (Section 5.3,
//! (iii)).
//!
//! ## The joint DOF sets
//!
//! The joint nodes are the distinct nodes of all joint pairs (both sides; in the multilayer sheet
//! a middle-sheet node may belong to two pairs and counts once). The **normal** set `J_n` holds
//! their out-of-plane translations `u_y` (the joint normal, see [`crate::joint`]), the
//! **in-plane** set `J_t` their `u_x` and `u_z`. A set `J` is condensed on its own: the other
//! set's DOF and the joint nodes' rotations are condensed out with the rest of the structure.
//!
//! ## Static (Guyan) condensation with the master node fixed
//!
//! As for the Craig–Bampton fixed-interface modes, the master node's six DOF are held at zero, so
//! the JIM live on the interior DOF `i` (all but the master) and are orthogonal in `K` to the
//! constraint modes `Φ_S` (`K Φ_S` vanishes on the interior rows). Split the interior into the
//! joint set `J` and the rest `o`. The Guyan transformation `T = [I; −K_oo⁻¹ K_oJ]` gives
//! `K* = Tᵀ K_ii T` and `M* = Tᵀ M_ii T` (|J| × |J|), and a JIM is `φ = T v` for an eigenpair
//! `K* v = λ M* v`, λ = ω² (1/s²), lowest first.
//!
//! ## How it is computed: one factorization of `K_ii`
//!
//! Let `E_J` select the set's DOF and `X = K_ii⁻¹ E_J` (the static responses to unit forces on
//! the joint DOF, mm/N; all joint DOF of both sets in one multi-column solve with one sparse
//! Cholesky of `K_ii`, the same matrix Craig–Bampton factors). Its joint rows form the joint
//! flexibility `F = E_Jᵀ K_ii⁻¹ E_J = X_J` (SPD), and since `K_ii X = E_J` has no force on `o`,
//! `T = X F⁻¹` — the Guyan shapes without ever forming `K_oo`. Then
//!
//! ```text
//! K* = F⁻¹,   M* = F⁻¹ G F⁻¹  with  G = Xᵀ M_ii X,
//! K* v = λ M* v   ⇔   G u = μ F u,   u = F⁻¹ v,  μ = 1/λ,   φ = T v = X u .
//! ```
//!
//! The symmetric-definite pencil `(G, F)` is reduced to a standard problem by the dense Cholesky
//! `F = L Lᵀ`: `C = L⁻¹ G L⁻ᵀ`, `C z = μ z`, `u = L⁻ᵀ z` (faer `self_adjoint_eigen`). The
//! lowest modes are the largest μ, the best-determined eigenvalues of `C`. With `zᵀz = 1`:
//! `φᵀ K φ = uᵀ F u = 1` and `φᵀ M φ = uᵀ G u = μ`, so each returned vector is scaled by
//! `1/√μ` to `φᵀMφ = 1`, `φᵀKφ = λ`. In the code λ is the Rayleigh quotient `uᵀFu / uᵀGu`
//! (more accurate than `1/μ` after the back substitution), and each expanded `φ = X u` is
//! normalized on the assembled M: the columns of X (responses to forces at neighbouring joint
//! DOF) are nearly parallel, so `X u` cancels and its M-norm drifts ~1e-10 from `uᵀGu`. JIM of
//! one set are M- and K-orthogonal to each other (eigenvectors of one pencil); the normal and
//! in-plane sets are not mutually orthogonal.
//!
//! Only the lowest modes are resolved: μ below `1e-12 μ_max` (a numerically infinite frequency;
//! the friction bar's in-plane set reaches ~1e5 Hz by its 30th mode) is an error if requested.
//!
//! [`JimSet::Both`] merges the two sets' modes by eigenvalue, ascending. The built-in cases'
//! lowest JIM frequencies and how `Both` mixes the sets are in `docs/validation/static-convergence.md`, section
//! `reduction::competitors::jim`.

use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Mat, Par, Side};

use crate::error::{Error, ReductionError};
use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::symmetric_eigen;
use crate::linalg::LinalgError;
use crate::model::Model;

use crate::reduction::basis::JimSet;
use crate::reduction::pod::apply_sym;

/// Joint Interface Modes with their eigenvalues.
#[derive(Clone, Debug)]
pub struct JointInterfaceModes {
    /// The modes φ (n × count), each `φᵀMφ = 1`, zero on the master DOF; columns ordered by
    /// eigenvalue, ascending.
    pub vectors: Mat<f64>,
    /// `λ = ω²` of the condensed eigenproblem (1/s²), ascending.
    pub eigenvalues: Vec<f64>,
    /// The set each column came from ([`JimSet::Normal`] or [`JimSet::InPlane`]).
    pub sets: Vec<JimSet>,
    /// Size of the normal set `|J_n|` (the number of joint nodes).
    pub normal_dofs: usize,
    /// Size of the in-plane set `|J_t|` (twice the number of joint nodes).
    pub in_plane_dofs: usize,
}

/// The interior (non-master) independent DOF of the joint nodes in the `Normal` or `InPlane`
/// set, node by node in ascending node order: the global axis closest to the node's pair normal
/// (y for generated sheets), or the other two axes (x, z). Errors if a joint node's
/// translation is not an independent interior DOF (clamped, tied or the master node).
pub fn jim_dofs(model: &Model, set: JimSet) -> Result<Vec<usize>, Error> {
    // Per joint node, the global axis closest to its pair's normal (y for generated sheets).
    let mut nodes: Vec<(usize, usize)> = model
        .pairs
        .iter()
        .flat_map(|p| [(p.lower, p.normal_axis()), (p.upper, p.normal_axis())])
        .collect();
    nodes.sort_unstable_by_key(|e| e.0);
    nodes.dedup_by_key(|e| e.0);
    let m = model.dofs().saturating_sub(6);
    let mut out = Vec::with_capacity(nodes.len() * 3);
    for &(node, a) in &nodes {
        let in_plane = [(a + 1) % 3, (a + 2) % 3];
        let in_plane = [in_plane[0].min(in_plane[1]), in_plane[0].max(in_plane[1])];
        let dirs: &[usize] = match set {
            JimSet::Normal => &[a],
            JimSet::InPlane => &in_plane,
            JimSet::Both => &[a, in_plane[0], in_plane[1]],
        };
        let deps = model
            .dof_map
            .nodes
            .get(node)
            .ok_or_else(|| Error::Reduction(ReductionError::UnknownJointNode { node }))?;
        for &d in dirs {
            match deps[d].as_free() {
                Some(i) if i < m => out.push(i),
                _ => {
                    return Err(ReductionError::JimDependentDof {
                        node,
                        axis: ["x", "y", "z"][d],
                    }
                    .into())
                }
            }
        }
    }
    Ok(out)
}

/// The interior size m = n − 6, checking that the master DOF are the last six.
pub(crate) fn interior_size(model: &Model, what: &'static str) -> Result<usize, Error> {
    let n = model.dofs();
    if n <= 6 {
        return Err(ReductionError::NoInteriorDofs {
            method: what,
            dofs: n,
        }
        .into());
    }
    let m = n - 6;
    for (c, &d) in model.master_dofs().iter().enumerate() {
        if d != m + c {
            return Err(ReductionError::MasterNotLast {
                method: what,
                master: c,
                dof: d,
                expected: m + c,
            }
            .into());
        }
    }
    Ok(m)
}

/// Eigenpairs of one set, all |J| of them: `λ` ascending (1/s²) and the coefficients `c_k`
/// (|J| × |J|) with `φ_k = X_s c_k` M-normalized.
fn condensed_modes(
    model: &Model,
    x: &Mat<f64>,
    cols: std::ops::Range<usize>,
    dofs: &[usize],
) -> Result<(Vec<f64>, Mat<f64>), Error> {
    let m = x.nrows();
    let p = dofs.len();
    let xs = x.as_ref().subcols(cols.start, cols.len());
    // Joint flexibility F = X_J (mm/N), symmetrized.
    let f = Mat::from_fn(p, p, |a, b| 0.5 * (xs[(dofs[a], b)] + xs[(dofs[b], a)]));
    let mii = model.mass.leading(m);
    let mx = apply_sym(Some(&mii), xs);
    let g = xs.transpose() * &mx;
    let g = Mat::from_fn(p, p, |a, b| 0.5 * (g[(a, b)] + g[(b, a)]));
    let llt = f.llt(Side::Lower).map_err(|e| {
        Error::LinearAlgebra(LinalgError::NotPositiveDefinite {
            what: format!("Joint Interface Modes: the {p}×{p} joint flexibility"),
            hint: "",
            source: Box::new(e),
        })
    })?;
    let l = llt.L();
    // C = L⁻¹ G L⁻ᵀ: Y = L⁻¹ G, then C = L⁻¹ Yᵀ.
    let mut y = g.clone();
    solve_lower_triangular_in_place(l, y.as_mut(), Par::Seq);
    let mut c = y.transpose().to_owned();
    solve_lower_triangular_in_place(l, c.as_mut(), Par::Seq);
    let c = Mat::from_fn(p, p, |a, b| 0.5 * (c[(a, b)] + c[(b, a)]));
    let evd = symmetric_eigen(c.as_ref(), "Joint Interface Modes").map_err(Error::LinearAlgebra)?;
    let mu = &evd.values;
    let mut u = evd.vectors;
    solve_upper_triangular_in_place(l.transpose(), u.as_mut(), Par::Seq);
    // Ascending λ = descending μ. Only the lowest modes are ever used; μ ≤ 1e-12 μ_max is
    // numerically an infinite frequency (the pencil (G, F) resolves the largest μ to working
    // precision, the smallest not at all) and is reported as λ = ∞, an error if requested.
    let mu_max = if p > 0 { mu[p - 1] } else { 0.0 };
    let mut lambda = Vec::with_capacity(p);
    let mut coef = Mat::<f64>::zeros(p, p);
    for (k, i) in (0..p).rev().enumerate() {
        let mui = mu[i];
        if mui.is_finite() && mui > 1e-12 * mu_max {
            // Normalize by the computed M-norm uᵀGu and take λ as the Rayleigh quotient
            // uᵀFu / uᵀGu (both more accurate than μ after the back substitution).
            let ui = u.col(i);
            let gu = &g * ui;
            let fu = &f * ui;
            let ugu: f64 = (0..p).map(|a| ui[a] * gu[a]).sum();
            let ufu: f64 = (0..p).map(|a| ui[a] * fu[a]).sum();
            if !(ugu > 0.0 && ufu > 0.0) {
                return Err(Error::LinearAlgebra(LinalgError::JimProducts {
                    mode: k,
                    ugu,
                    ufu,
                }));
            }
            lambda.push(ufu / ugu);
            let inv = 1.0 / ugu.sqrt();
            for a in 0..p {
                coef[(a, k)] = ui[a] * inv;
            }
        } else {
            lambda.push(f64::INFINITY);
        }
    }
    Ok((lambda, coef))
}

/// The `count` lowest Joint Interface Modes of `set` with their eigenvalues (see the module
/// docs). Errors if `count` exceeds the size of the set (`|J_n|` for `Normal`, `|J_t|` for
/// `InPlane`, their sum for `Both`), on a singular joint flexibility, or if a requested mode's
/// condensed mass eigenvalue `μ = 1/λ` is below `1e-12 μ_max` (a numerically infinite
/// frequency: the highest modes of a set are not resolved, nor needed).
pub fn joint_interface_modes(
    model: &Model,
    count: usize,
    set: JimSet,
) -> Result<JointInterfaceModes, Error> {
    let m = interior_size(model, "Joint Interface Modes")?;
    let n = model.dofs();
    let normal = jim_dofs(model, JimSet::Normal)?;
    let in_plane = jim_dofs(model, JimSet::InPlane)?;
    let available = match set {
        JimSet::Normal => normal.len(),
        JimSet::InPlane => in_plane.len(),
        JimSet::Both => normal.len() + in_plane.len(),
    };
    if count > available {
        return Err(ReductionError::JimCount {
            count,
            set: set.name(),
            available,
        }
        .into());
    }
    if count == 0 {
        return Ok(JointInterfaceModes {
            vectors: Mat::zeros(n, 0),
            eigenvalues: Vec::new(),
            sets: Vec::new(),
            normal_dofs: normal.len(),
            in_plane_dofs: in_plane.len(),
        });
    }
    let use_normal = set != JimSet::InPlane;
    let use_in_plane = set != JimSet::Normal;
    // Right-hand sides E_J for the needed sets: normal columns first, then in-plane.
    let mut all: Vec<usize> = Vec::new();
    if use_normal {
        all.extend(&normal);
    }
    if use_in_plane {
        all.extend(&in_plane);
    }
    let mut x = Mat::<f64>::zeros(m, all.len());
    for (c, &d) in all.iter().enumerate() {
        x[(d, c)] = 1.0;
    }
    let kii = SparseCholesky::new(&model.stiffness.leading(m))?;
    kii.solve_in_place(&mut x);
    if x.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
        return Err(Error::LinearAlgebra(LinalgError::NotFinite {
            what: "Joint Interface Modes: static responses".to_string(),
            plural: true,
        }));
    }
    let mut parts: Vec<(JimSet, Vec<f64>, Mat<f64>, usize)> = Vec::new();
    let mut start = 0;
    if use_normal {
        let (l, c) = condensed_modes(model, &x, 0..normal.len(), &normal)?;
        parts.push((JimSet::Normal, l, c, 0));
        start = normal.len();
    }
    if use_in_plane {
        let (l, c) = condensed_modes(model, &x, start..start + in_plane.len(), &in_plane)?;
        parts.push((JimSet::InPlane, l, c, start));
    }
    // Merge by eigenvalue ascending (a single set is already sorted).
    let mut picks: Vec<(f64, usize, usize)> = parts
        .iter()
        .enumerate()
        .flat_map(|(s, (_, l, _, _))| l.iter().enumerate().map(move |(k, &v)| (v, s, k)))
        .collect();
    picks.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    picks.truncate(count);
    if let Some(&(_, s, k)) = picks.iter().find(|p| !p.0.is_finite()) {
        return Err(Error::LinearAlgebra(LinalgError::JimInfiniteFrequency {
            mode: k + 1,
            set: parts[s].0.name(),
            count,
        }));
    }
    let mut vectors = Mat::<f64>::zeros(n, count);
    let mut mphi = vec![0.0; n];
    for (c, &(_, s, k)) in picks.iter().enumerate() {
        let (_, _, coef, first) = &parts[s];
        let p = coef.nrows();
        let xs = x.as_ref().subcols(*first, p);
        let phi = xs * coef.col(k);
        let mut full: Vec<f64> = (0..n).map(|r| if r < m { phi[r] } else { 0.0 }).collect();
        // The columns of X (responses to forces at neighbouring joint DOF) are nearly parallel,
        // so X c cancels and its M-norm drifts ~1e-10 from uᵀGu: renormalize on the assembled M.
        model.mass.mul_vec(&full, &mut mphi);
        let norm = full
            .iter()
            .zip(&mphi)
            .map(|(a, b)| a * b)
            .sum::<f64>()
            .sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            return Err(Error::LinearAlgebra(LinalgError::ModeNorm {
                what: format!("Joint Interface Mode {c}"),
                norm,
            }));
        }
        full.iter_mut().for_each(|v| *v /= norm);
        for r in 0..m {
            vectors[(r, c)] = full[r];
        }
    }
    Ok(JointInterfaceModes {
        vectors,
        eigenvalues: picks.iter().map(|p| p.0).collect(),
        sets: picks.iter().map(|p| parts[p.1].0).collect(),
        normal_dofs: normal.len(),
        in_plane_dofs: in_plane.len(),
    })
}

/// The `count` lowest Joint Interface Modes of `set` (n × count, columns ascending in
/// eigenfrequency, each M-normalized, zero on the master DOF): static condensation of K and M
/// onto the joint DOF with the master node fixed, then the condensed eigenproblem, expanded back
/// by the condensation (see the module docs and [`joint_interface_modes`]).
pub fn jim_vectors(model: &Model, count: usize, set: JimSet) -> Result<faer::Mat<f64>, Error> {
    Ok(joint_interface_modes(model, count, set)?.vectors)
}
