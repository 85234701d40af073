//! [`build_basis`]: the one entry point that builds a basis of any [`BasisKind`] — the paper's
//! TVD (Algorithm 2) and the competitors of its Section 5 — from the core steps and the
//! competitors' builders.

use faer::Mat;

use super::basis::{final_basis, modal_rotation, Basis, BasisOptions};
use super::competitors::{alldof_vectors, jim_vectors};
use super::craig_bampton::craig_bampton;
use super::pod::{pod_tvd, pod_tvd_ratios};
use super::tvd::{trial_vector_derivatives, TvdOptions};
use crate::error::{Error, ReductionError};
use crate::model::Model;

/// Which enrichment of the Craig–Bampton basis [`build_basis`] uses. The one table of the basis
/// names: [`BasisKind::NAMES`], the CLI's `--basis`/`--model` values (a clap value enum) and the
/// names in every output.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BasisKind {
    /// TVD joint modes from the K-weighted POD (eqs. 24–25; the paper's choice).
    #[value(name = "tvd")]
    Tvd,
    /// TVD joint modes from the plain (Euclidean) POD (eqs. 20–22).
    #[value(name = "tvd-plain")]
    TvdPlain,
    /// Secant TVD (`(K + ∂K)⁻¹ ∂K φ_i`, [`super::tvd`], "The secant TVD") with the K-weighted
    /// POD: Algorithm 2 with line 19 replaced; opt-in.
    #[value(name = "tvd-secant")]
    TvdSecant,
    /// No joint modes: Craig–Bampton with ν + g fixed-interface modes instead (the paper's
    /// comparison, Figure 7).
    #[value(name = "modes")]
    Modes,
    /// Craig–Bampton plus the g lowest Joint Interface Modes (Witteveen & Irschik 2009; the
    /// paper's Section 5.3 and Figure 19), of the set [`BasisOptions::jim_set`]; see
    /// [`super::competitors::jim`].
    #[value(name = "jim")]
    Jim,
    /// Craig–Bampton plus the static constraint modes of every joint pair's relative normal DOF
    /// (all joint DOF kept, the paper's Section 5.1); g is ignored and reported as the number of
    /// pairs; see [`super::competitors::alldof`].
    #[value(name = "alldof")]
    AllDof,
}

impl BasisKind {
    /// Every kind, in the order of [`BasisKind::NAMES`].
    pub const ALL: [BasisKind; 6] = [
        BasisKind::Tvd,
        BasisKind::TvdPlain,
        BasisKind::TvdSecant,
        BasisKind::Modes,
        BasisKind::Jim,
        BasisKind::AllDof,
    ];

    /// The accepted names: `tvd`, `tvd-plain`, `tvd-secant`, `modes`, `jim`, `alldof`.
    pub const NAMES: [&'static str; 6] =
        ["tvd", "tvd-plain", "tvd-secant", "modes", "jim", "alldof"];

    /// The kind's name (as accepted by [`BasisKind::from_name`] and the CLI's `--basis`).
    pub fn name(self) -> &'static str {
        match self {
            BasisKind::Tvd => "tvd",
            BasisKind::TvdPlain => "tvd-plain",
            BasisKind::TvdSecant => "tvd-secant",
            BasisKind::Modes => "modes",
            BasisKind::Jim => "jim",
            BasisKind::AllDof => "alldof",
        }
    }

    /// Parses a name of [`BasisKind::NAMES`] (exact, lower case); anything else is a
    /// [`ReductionError::UnknownBasis`] listing the accepted names.
    pub fn from_name(name: &str) -> Result<BasisKind, ReductionError> {
        BasisKind::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| ReductionError::UnknownBasis {
                name: name.to_string(),
                valid: &BasisKind::NAMES,
            })
    }
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
    Ok(build(model, kind, opts, false)?.0)
}

/// [`build_basis`] of a TVD kind (`Tvd` or `TvdPlain`) together with the energy ratios w(g) of
/// the other POD of the same TVD (plain for `Tvd`, K-weighted for `TvdPlain`): one
/// Craig–Bampton and one TVD for both curves (what `jointrom basis` prints). Errors for the
/// other kinds.
pub fn build_tvd_basis_both_pods(
    model: &Model,
    kind: BasisKind,
    opts: &BasisOptions,
) -> Result<(Basis, Vec<f64>), Error> {
    if !matches!(kind, BasisKind::Tvd | BasisKind::TvdPlain) {
        return Err(ReductionError::NoTvdPod { kind: kind.name() }.into());
    }
    let (basis, other) = build(model, kind, opts, true)?;
    Ok((basis, other.unwrap_or_default()))
}

/// [`build_basis`], and with `other_pod` the other POD's w(g) of the TVD (when computed).
fn build(
    model: &Model,
    kind: BasisKind,
    opts: &BasisOptions,
    other_pod: bool,
) -> Result<(Basis, Option<Vec<f64>>), Error> {
    let need_tvd = match kind {
        BasisKind::Tvd | BasisKind::TvdPlain | BasisKind::TvdSecant => true,
        BasisKind::Modes | BasisKind::Jim => opts.g.is_none(),
        BasisKind::AllDof => false,
    };
    let cb = craig_bampton(model, opts.nu)?;
    let mut other_w = None;
    let (w, g, tvd_total, tvd_nonzero, joint_modes) = if need_tvd {
        let tvd_opts = TvdOptions {
            secant: opts.tvd.secant || kind == BasisKind::TvdSecant,
            ..opts.tvd
        };
        let tvd = trial_vector_derivatives(model, cb.as_ref(), &tvd_opts)?;
        let p = pod_tvd(model, &tvd, kind != BasisKind::TvdPlain)?;
        if other_pod {
            other_w = Some(pod_tvd_ratios(model, &tvd, kind == BasisKind::TvdPlain)?);
        }
        // One rule for every command: a g beyond the POD's modes is an error, never clamped.
        let available = p.lambda.len();
        let g = match opts.g {
            Some(g) if g > available => {
                return Err(ReductionError::PodModes {
                    g,
                    available,
                    model: crate::files::printable(&model.name).to_string(),
                }
                .into())
            }
            Some(g) => g,
            None => p.choose_g(opts.threshold).min(available),
        };
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
        BasisKind::Tvd | BasisKind::TvdPlain | BasisKind::TvdSecant => {
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
    let basis = Basis {
        phi,
        w,
        g,
        tvd_total,
        tvd_nonzero,
        dropped,
        eigenvalues,
    };
    Ok((basis, other_w))
}
