//! The preloaded equilibrium and the linearised modes about it, for the full FE model (sparse)
//! and a reduced one (dense).
//!
//! **Equilibrium.** The case's master load times the preload factor S, held constant, with
//! frictionless penalty contact ([`crate::joint::statics`]): `K q + B_nᵀ p_n(B_n q) = S f`. Its
//! slip memory is the tangential relative displacement itself, `s = B_t q`, so the elastic stick
//! stretch `e = B_t q − s` and with it every tangential pair force is zero: the state is an exact
//! equilibrium of the frictional model as well (the one reached by pressing the joint shut
//! without tangential friction and then letting it stick). With S = 0 it is the undeformed
//! state.
//!
//! **Mode k** is the k-th mode of the model linearised about that equilibrium with every closed
//! pair stuck: `(K + Σ_closed [k_n b_n b_nᵀ + k_t (b_t1 b_t1ᵀ + b_t2 b_t2ᵀ)]) ψ = ω² M ψ`, a pair
//! closed when its gap is `≤ 0` (with no preload every pair touches at g = 0 and counts as
//! closed: the joint glued), the `k_t` terms only with friction on. It is the small-amplitude
//! limit of the ring-down wherever the preload keeps the pairs closed; without one the contact
//! is bilinear at every amplitude (half the joint opens each half cycle), so the ring-down runs
//! below this frequency, at an amplitude-independent one. Shapes are scaled to a largest nodal
//! translation of 1 mm of the physical field (`Φψ` for a reduced model), so a modal amplitude
//! is in mm of the largest nodal translation.

use faer::Mat;

use crate::error::Error;
use crate::joint::statics::ContactOptions;
use crate::linalg::sparse::column_pattern;
use crate::linalg::{dense_modes, lowest_modes, SymCsc};
use crate::model::{contact_static_full, Model};
use crate::rom::statics::{reduced_contact_static_restarting, scaled_load};
use crate::system::{ReducedSystem, SecondOrderSystem};

/// The preloaded equilibrium a ring-down starts from and returns to.
#[derive(Clone, Debug, PartialEq)]
pub struct Equilibrium {
    /// Coordinates (n or r).
    pub q: Vec<f64>,
    /// Slip memory `s = B_t q` (2 per pair), mm.
    pub slip: Vec<f64>,
    /// Pairs closed (gap ≤ 0).
    pub closed: Vec<bool>,
    /// The constant master load `[Fx, Fy, Fz (N), Mx, My, Mz (N·mm)]`.
    pub load: [f64; 6],
    /// The master node's displacement `[ux, uy, uz (mm), rx, ry, rz (rad)]`.
    pub master: [f64; 6],
}

impl Equilibrium {
    /// The equilibrium at `q` of `sys` under `load` (the pair gaps and slips from `B q`).
    pub fn at<S: SecondOrderSystem>(sys: &S, q: Vec<f64>, load: [f64; 6]) -> Equilibrium {
        let w = sys.pairs();
        let mut u = vec![0.0; 3 * w];
        sys.joint_apply_into(&q, &mut u);
        Equilibrium {
            slip: (0..w).flat_map(|k| [u[3 * k + 1], u[3 * k + 2]]).collect(),
            closed: (0..w).map(|k| u[3 * k] <= 0.0).collect(),
            master: sys.master_displacement(&q),
            load,
            q,
        }
    }
}

/// One linearised mode in a model's coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearMode {
    /// Mode number k (1 = lowest).
    pub number: usize,
    /// Linearised frequency, Hz.
    pub frequency_hz: f64,
    /// Shape ψ (n or r), scaled to a largest nodal translation of 1 mm.
    pub shape: Vec<f64>,
    /// `M ψ`.
    pub mass_shape: Vec<f64>,
    /// `ψᵀ M ψ`, t.
    pub modal_mass: f64,
    /// The master node's displacement in ψ `[ux, uy, uz (mm), rx, ry, rz (rad)]`.
    pub master: [f64; 6],
}

/// The equilibrium of the full model under `scale` × the case's master load.
///
/// # Errors
/// A non-finite scale, a contact solve that fails.
pub fn full_equilibrium(model: &Model, scale: f64) -> Result<Equilibrium, Error> {
    let load = scaled_load(model, scale)?;
    let q = if scale == 0.0 {
        vec![0.0; model.dofs()]
    } else {
        contact_static_full(model, load, &ContactOptions::default())?.displacement
    };
    let sys = crate::system::FullSystem::new(model)?;
    Ok(Equilibrium::at(&sys, q, load))
}

/// The equilibrium of the reduced model `rom` of `model` under `scale` × the master load.
///
/// # Errors
/// A non-finite scale, a contact solve that fails.
pub fn reduced_equilibrium(
    model: &Model,
    rom: &ReducedSystem,
    scale: f64,
) -> Result<Equilibrium, Error> {
    let load = scaled_load(model, scale)?;
    let q = if scale == 0.0 {
        vec![0.0; rom.dim()]
    } else {
        reduced_contact_static_restarting(model, rom, scale, &ContactOptions::default())?
            .0
            .eta
    };
    Ok(Equilibrium::at(rom, q, load))
}

/// The pair stiffnesses of the linearisation: `(row of B, stiffness)` for each closed pair's
/// normal row (k_n) and, with friction, its tangential rows (k_t).
fn stuck_rows(model: &Model, eq: &Equilibrium, friction: bool) -> Vec<(usize, f64)> {
    let c = &model.contact;
    let mut out = Vec::new();
    for (k, _) in eq.closed.iter().enumerate().filter(|(_, &c)| c) {
        out.push((3 * k, c.normal_stiffness));
        if friction {
            out.push((3 * k + 1, c.stick_stiffness));
            out.push((3 * k + 2, c.stick_stiffness));
        }
    }
    out
}

/// `K + Σ k_i b_i b_iᵀ` over `rows` of the model's joint operator, sparse: the pattern of K
/// joined with each row's `b bᵀ` ([`column_pattern`]), then the values added in place.
fn stiffened(model: &Model, rows: &[(usize, f64)]) -> SymCsc {
    let k = &model.stiffness;
    let n = k.n;
    let b: Vec<(f64, Vec<(usize, f64)>)> = rows
        .iter()
        .map(|&(r, kr)| (kr, model.joint.row(r).collect()))
        .collect();
    // Per column j, the rows of b that touch it.
    let mut touching: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, (_, row)) in b.iter().enumerate() {
        for &(j, _) in row {
            touching[j].push(i);
        }
    }
    let (col_ptr, row_idx) = column_pattern(n, |j, out| {
        out.extend_from_slice(&k.row_idx[k.col_ptr[j]..k.col_ptr[j + 1]]);
        for &i in &touching[j] {
            out.extend(b[i].1.iter().map(|e| e.0));
        }
    });
    let mut a = SymCsc {
        n,
        values: vec![0.0; row_idx.len()],
        col_ptr,
        row_idx,
    };
    let add = |a: &mut SymCsc, i: usize, j: usize, v: f64| {
        let rows = &a.row_idx[a.col_ptr[j]..a.col_ptr[j + 1]];
        if let Ok(p) = rows.binary_search(&i) {
            a.values[a.col_ptr[j] + p] += v;
        }
    };
    for j in 0..n {
        for p in k.col_ptr[j]..k.col_ptr[j + 1] {
            add(&mut a, k.row_idx[p], j, k.values[p]);
        }
    }
    for (kr, row) in &b {
        for &(j, bj) in row {
            for &(i, bi) in row {
                add(&mut a, i, j, kr * bi * bj);
            }
        }
    }
    a
}

/// A dense symmetric matrix as [`SymCsc`] (every entry stored).
fn dense_sym(a: &Mat<f64>) -> SymCsc {
    let n = a.nrows();
    SymCsc {
        n,
        col_ptr: (0..=n).map(|j| j * n).collect(),
        row_idx: (0..n * n).map(|p| p % n).collect(),
        values: (0..n * n)
            .map(|p| 0.5 * (a[(p % n, p / n)] + a[(p / n, p % n)]))
            .collect(),
    }
}

/// The largest absolute entry of `field` over the DOF `dofs`.
fn largest(field: &[f64], dofs: &[usize]) -> f64 {
    dofs.iter().map(|&d| field[d].abs()).fold(0.0, f64::max)
}

/// The lowest `count` linearised modes of the full model about `eq` (module docs).
///
/// # Errors
/// `count` beyond the model's DOF, a failing eigensolve.
pub fn full_modes(
    model: &Model,
    eq: &Equilibrium,
    count: usize,
    friction: bool,
) -> Result<Vec<LinearMode>, Error> {
    let k = stiffened(model, &stuck_rows(model, eq, friction));
    let modes = lowest_modes(&k, &model.mass, count)?;
    let trans = model.translation_dofs();
    let master = model.master_dofs();
    Ok((0..count)
        .map(|c| {
            let raw: Vec<f64> = modes.shapes.col(c).iter().copied().collect();
            let scale = 1.0 / largest(&raw, &trans);
            let shape: Vec<f64> = raw.iter().map(|v| v * scale).collect();
            let mut mass_shape = vec![0.0; shape.len()];
            model.mass.mul_vec(&shape, &mut mass_shape);
            LinearMode {
                number: c + 1,
                frequency_hz: modes.frequencies_hz[c],
                modal_mass: dot(&shape, &mass_shape),
                master: master.map(|d| shape[d]),
                mass_shape,
                shape,
            }
        })
        .collect())
}

/// The lowest `count` linearised modes of the reduced model `rom` (with its basis Φ) about
/// `eq` (module docs), dense.
///
/// # Errors
/// `count` beyond r, a reduced model without its basis, a failing eigensolve.
pub fn reduced_modes(
    model: &Model,
    rom: &ReducedSystem,
    eq: &Equilibrium,
    count: usize,
    friction: bool,
) -> Result<Vec<LinearMode>, Error> {
    let phi = rom
        .phi
        .as_ref()
        .ok_or_else(|| crate::error::RomError::Unsupported {
            command: "backbone".into(),
            model: "a reduced model without its basis".into(),
            takes: "a reduced basis or --tolerance (the mode shape is normalised on Φψ)",
        })?;
    let r = rom.dim();
    let mut k = rom.k().clone();
    let b = rom.b_phi();
    for (row, kr) in stuck_rows(model, eq, friction) {
        for j in 0..r {
            let bj = kr * b[(row, j)];
            for i in 0..r {
                k[(i, j)] += b[(row, i)] * bj;
            }
        }
    }
    let modes = dense_modes(&dense_sym(&k), &dense_sym(rom.m()), count)?;
    let trans = model.translation_dofs();
    let mut out = Vec::with_capacity(count);
    for c in 0..count {
        let raw: Vec<f64> = modes.shapes.col(c).iter().copied().collect();
        let field: Vec<f64> = (0..phi.nrows())
            .map(|i| (0..r).map(|j| phi[(i, j)] * raw[j]).sum())
            .collect();
        let scale = 1.0 / largest(&field, &trans);
        let shape: Vec<f64> = raw.iter().map(|v| v * scale).collect();
        let mut mass_shape = vec![0.0; r];
        rom.mul_m_into(&shape, &mut mass_shape);
        out.push(LinearMode {
            number: c + 1,
            frequency_hz: modes.frequencies_hz[c],
            modal_mass: dot(&shape, &mass_shape),
            master: rom.master_displacement(&shape),
            mass_shape,
            shape,
        });
    }
    Ok(out)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sparse `K + Σ k b bᵀ` equals the dense sum entry by entry, its pattern sorted.
    #[test]
    fn stiffened_equals_the_dense_sum() {
        let model = Model::from_case_name("friction_bar").unwrap();
        let rows: Vec<(usize, f64)> = [
            (0, 2.0),
            (1, 3.0),
            (2, 5.0),
            (3 * 7, 7.0),
            (3 * 7 + 2, 11.0),
        ]
        .into_iter()
        .collect();
        let a = stiffened(&model, &rows);
        let mut dense = model.stiffness.to_dense();
        for &(r, kr) in &rows {
            let b: Vec<(usize, f64)> = model.joint.row(r).collect();
            for &(j, bj) in &b {
                for &(i, bi) in &b {
                    dense[(i, j)] += kr * bi * bj;
                }
            }
        }
        let got = a.to_dense();
        let scale = model.stiffness.inf_norm();
        for j in 0..a.n {
            let col = &a.row_idx[a.col_ptr[j]..a.col_ptr[j + 1]];
            assert!(col.windows(2).all(|w| w[0] < w[1]), "column {j} unsorted");
            for i in 0..a.n {
                assert!(
                    (got[(i, j)] - dense[(i, j)]).abs() <= 1e-14 * scale,
                    "({i}, {j}): {} vs {}",
                    got[(i, j)],
                    dense[(i, j)]
                );
            }
        }
        assert!(a.row_idx.len() > model.stiffness.row_idx.len());
    }
}
