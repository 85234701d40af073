//! [`build_basis`]: the one entry point that builds a basis of any [`BasisKind`] — the paper's
//! TVD (Algorithm 2) and the competitors of its Section 5 — from the core steps and the
//! competitors' builders.

use faer::Mat;

use super::basis::{final_basis, modal_rotation, Basis, BasisOptions};
use super::competitors::{alldof_vectors, jim_vectors};
use super::craig_bampton::craig_bampton;
use super::pod::{pod_tvd_leading, pod_tvd_ratios, Pod};
use super::tvd::{trial_vector_derivatives_factored, TvdOptions};
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
        // The TVD in factor form and only the g POMs the basis takes: no n × p block but the
        // flexibility Z, which is dropped before the basis is orthonormalized.
        let tvd = trial_vector_derivatives_factored(model, cb.as_ref(), &tvd_opts)?;
        if other_pod {
            other_w = Some(pod_tvd_ratios(model, &tvd, kind == BasisKind::TvdPlain)?);
        }
        // One rule for every command: a g beyond the POD's modes is an error, never clamped.
        let choose = |p: &Pod| -> Result<usize, Error> {
            let available = p.lambda.len();
            match opts.g {
                Some(g) if g > available => Err(ReductionError::PodModes {
                    g,
                    available,
                    model: crate::files::printable(&model.name).to_string(),
                }
                .into()),
                Some(g) => Ok(g),
                None => Ok(p.choose_g(opts.threshold).min(available)),
            }
        };
        let p = pod_tvd_leading(model, &tvd, kind != BasisKind::TvdPlain, &choose)?;
        let (total, nonzero) = (tvd.total, tvd.nonzero());
        drop(tvd);
        let g = p.poms.ncols();
        (p.w, g, total, nonzero, p.poms)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reduction::{pod_tvd, trial_vector_derivatives};

    /// The basis from the TVD's factor form and the leading POMs alone
    /// ([`trial_vector_derivatives_factored`], [`pod_tvd_leading`]) is the basis from the formed
    /// TVD `Z C` and all POMs (the route before): the same w(g) and g bit for bit, the POMs and
    /// the final basis to 1e-10, uncompressed (ν = 10) and compressed (multilayer, Φ_S alone),
    /// both PODs.
    #[test]
    fn factor_form_gives_the_basis_of_the_formed_tvd() {
        for (name, nu) in [
            ("friction_bar", 10),
            ("multilayer_sheet", 10),
            ("multilayer_sheet", 0),
        ] {
            let model = Model::from_case_name(name).unwrap();
            let cb = craig_bampton(&model, nu).unwrap();
            let opts = TvdOptions::default();
            let formed = trial_vector_derivatives(&model, cb.as_ref(), &opts).unwrap();
            let factored = trial_vector_derivatives_factored(&model, cb.as_ref(), &opts).unwrap();
            assert_eq!(factored.vectors.ncols(), 0, "{name}: Z C is not formed");
            assert_eq!(factored.nonzero(), formed.nonzero());
            let y = factored.formed_vectors();
            assert!(
                y.as_ref() == formed.vectors.as_ref(),
                "{name}: Z C formed on demand"
            );
            for kind in [BasisKind::Tvd, BasisKind::TvdPlain] {
                let weighted = kind == BasisKind::Tvd;
                let all = pod_tvd(&model, &formed, weighted).unwrap();
                let g = all.choose_g(0.999);
                let lead = pod_tvd_leading(&model, &factored, weighted, &|_| Ok(g)).unwrap();
                assert_eq!(lead.poms.ncols(), g);
                let bits = |w: &[f64]| w.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&lead.w), bits(&all.w), "{name} {kind:?}");
                let dev = max_dev(all.leading(g), lead.poms.as_ref());
                assert!(dev <= 1e-10, "{name} ν = {nu} {kind:?}: POMs {dev:e}");
                // The whole basis, against the one from the formed TVD and all POMs.
                let opts = BasisOptions {
                    nu,
                    ..BasisOptions::default()
                };
                let basis = build_basis(&model, kind, &opts).unwrap();
                assert_eq!(basis.g, g);
                let (want, _) =
                    final_basis(&[cb.as_ref(), all.leading(g)], &model.mass, opts.drop_tol)
                        .unwrap();
                let (want, _) = modal_rotation(&model, want).unwrap();
                let dev = max_dev(want.as_ref(), basis.phi.as_ref());
                assert!(dev <= 1e-10, "{name} ν = {nu} {kind:?}: basis {dev:e}");
            }
        }
    }

    /// The largest difference of two matrices' columns relative to the column's largest entry,
    /// up to each column's sign.
    fn max_dev(a: faer::MatRef<'_, f64>, b: faer::MatRef<'_, f64>) -> f64 {
        assert_eq!(a.shape(), b.shape());
        (0..a.ncols())
            .map(|c| {
                let scale = a.col(c).iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let dot: f64 = a
                    .col(c)
                    .iter()
                    .zip(b.col(c).iter())
                    .map(|(x, y)| x * y)
                    .sum();
                let s = dot.signum();
                let dev = a
                    .col(c)
                    .iter()
                    .zip(b.col(c).iter())
                    .fold(0.0f64, |m, (x, y)| m.max((x - s * y).abs()));
                dev / scale
            })
            .fold(0.0, f64::max)
    }
}
