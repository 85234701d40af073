//! The model choice, parsed once: [`ModelSpec`] says which model a command builds — the full FE
//! model, a reduced basis of a [`BasisKind`] with g enrichment vectors and ν fixed-interface
//! modes, the POD of a full-FE training run, the tolerance-chosen model, or a reduced model read
//! from a file — and [`ModelFlags`] is the one group of command-line flags that names it
//! (`--model`, `--basis`, `--g`, `--nu`, `--tolerance`), flattened into every command that builds
//! a model, so each flag means the same everywhere and is checked in one place.

use std::path::PathBuf;

use crate::error::{Error, RomError};
use crate::reduction::{BasisKind, Quantities, Quantity};

/// Which model to build and run.
#[derive(Clone, Debug, PartialEq)]
pub enum ModelSpec {
    /// The full FE model.
    Full,
    /// Craig–Bampton (ν fixed-interface modes) enriched by a basis of `kind` with `g` vectors;
    /// `g = None` takes the a-priori rule (the smallest g with w(g) ≥ 0.999).
    Basis {
        /// The enrichment.
        kind: BasisKind,
        /// Added vectors (None: the a-priori w(g) rule).
        g: Option<usize>,
        /// Fixed-interface modes ν.
        nu: usize,
    },
    /// The POD of the displacement snapshots of a full-FE training run over `[0, train_end]`
    /// (paper Section 5.2), added to Craig–Bampton.
    Pod {
        /// POD modes kept (None: the a-priori w(g) rule).
        g: Option<usize>,
        /// Fixed-interface modes ν.
        nu: usize,
        /// End of the training run, s (None: the run's end time).
        train_end: Option<f64>,
        /// About this many snapshots are kept from the training run.
        snapshots: usize,
    },
    /// The smallest Craig–Bampton + pair-attachment-mode model whose estimated error meets the
    /// tolerance ([`super::tolerance`]).
    Tolerance {
        /// The relative L2 error it is built for, in (0, 1).
        tolerance: f64,
        /// Fixed-interface modes ν to start from.
        nu: usize,
        /// The quantities the tolerance holds for (`--tolerance-on`); `None`: all that the
        /// run produces (‖f_R‖ and D need friction).
        on: Option<Quantities>,
    },
    /// A reduced model written by `jointrom export` (schema `jointrom-rom`).
    File(PathBuf),
}

/// The default number of fixed-interface modes ν.
pub const DEFAULT_NU: usize = 10;

/// The default number of snapshots kept from a POD training run.
pub const DEFAULT_SNAPSHOTS: usize = 200;

impl ModelSpec {
    /// The name the outputs use for the model: `full`, the basis kind, `pod`, `adaptive` (the
    /// tolerance-chosen model) or `file:PATH`.
    pub fn name(&self) -> String {
        match self {
            ModelSpec::Full => "full".into(),
            ModelSpec::Basis { kind, .. } => kind.name().into(),
            ModelSpec::Pod { .. } => "pod".into(),
            ModelSpec::Tolerance { .. } => "adaptive".into(),
            ModelSpec::File(p) => format!("file:{}", p.display()),
        }
    }

    /// Whether the model is reduced (everything but [`ModelSpec::Full`]).
    pub fn is_reduced(&self) -> bool {
        !matches!(self, ModelSpec::Full)
    }
}

/// A `--model` name: `full`, a [`BasisKind`] name, `pod`, `adaptive` or `file:PATH`.
enum ModelName {
    Full,
    Basis(BasisKind),
    Pod,
    Adaptive,
    File(PathBuf),
}

impl ModelName {
    fn parse(name: &str) -> Result<ModelName, Error> {
        Ok(match name {
            "full" => ModelName::Full,
            "pod" => ModelName::Pod,
            "adaptive" => ModelName::Adaptive,
            _ if name.starts_with("file:") => {
                ModelName::File(PathBuf::from(&name["file:".len()..]))
            }
            _ => ModelName::Basis(
                BasisKind::from_name(name).map_err(|source| RomError::ModelName { source })?,
            ),
        })
    }
}

/// The model-choice flags every model-building command shares (flatten this group into the
/// command's arguments) and the one place they are checked ([`ModelFlags::spec`]).
#[derive(Clone, Debug, Default, clap::Args)]
pub struct ModelFlags {
    /// The model: full (the FE model), a reduced basis (tvd, tvd-plain, tvd-secant, modes, jim, alldof), pod
    /// (POD of the displacement snapshots of a full-FE training run, paper Section 5.2),
    /// file:PATH (a reduced model written by `jointrom export`), or adaptive (Craig–Bampton
    /// plus the attachment modes of the pairs the error estimate selects: give --tolerance).
    /// Default: the command's (see its help), adaptive with --tolerance.
    #[arg(long)]
    pub model: Option<String>,
    /// A reduced basis kind: the same as `--model KIND`.
    #[arg(long, value_enum)]
    pub basis: Option<BasisKind>,
    /// Enrichment vectors g of the basis (joint modes; extra modes for `modes`); default: the
    /// smallest g with w(g) >= 0.999. Larger than available is an error.
    #[arg(long)]
    pub g: Option<usize>,
    /// Fixed-interface modes ν of the basis.
    #[arg(long, default_value_t = DEFAULT_NU)]
    pub nu: usize,
    /// Build the smallest reduced model whose estimated relative L2 error of |f_c| is at most
    /// TOL (in (0, 1); e.g. 1e-2): `--model adaptive`, the default with this flag.
    #[arg(long, allow_negative_numbers = true)]
    pub tolerance: Option<f64>,
    /// What --tolerance holds for: a comma-separated list of fc (|f_c|(t)), fr (|f_R|(t)), uy
    /// (the master's u_y(t)) and dissipation (the joint's dissipated energy D(t): over the run
    /// and at its end). Default: all four (fc and uy with friction off).
    #[arg(long, value_name = "LIST")]
    pub tolerance_on: Option<String>,
}

/// The quantities of a `--tolerance-on` list (module docs of [`ModelFlags`]).
///
/// # Errors
/// An empty list or an unknown name, naming `--tolerance-on`.
pub fn parse_tolerance_on(list: &str) -> Result<Quantities, Error> {
    let mut found = Vec::new();
    for name in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
        found.push(
            Quantity::from_name(name).ok_or_else(|| RomError::ToleranceOnName {
                name: crate::files::printable(name).to_string(),
            })?,
        );
    }
    if found.is_empty() {
        return Err(RomError::ToleranceOnEmpty.into());
    }
    Ok(Quantities::of(&found))
}

impl ModelFlags {
    /// The flags of a basis `kind` with ν = [`DEFAULT_NU`] (for library callers).
    pub fn basis(kind: BasisKind) -> ModelFlags {
        ModelFlags {
            basis: Some(kind),
            nu: DEFAULT_NU,
            ..ModelFlags::default()
        }
    }

    /// [`ModelFlags::spec`] with the commands' default: the paper's a-priori TVD basis with
    /// the flags' ν.
    ///
    /// # Errors
    /// As [`ModelFlags::spec`].
    pub fn spec_or_tvd(&self) -> Result<ModelSpec, Error> {
        self.spec(ModelSpec::Basis {
            kind: BasisKind::Tvd,
            g: None,
            nu: self.nu,
        })
    }

    /// The model the flags name; `default` when they name none (and give no `--tolerance`).
    /// POD models get [`DEFAULT_SNAPSHOTS`] and the run's end time for training: set them on
    /// the returned spec.
    ///
    /// # Errors
    /// An unknown `--model` name, `--model` and `--basis` both given, `--tolerance` outside
    /// (0, 1) or beside another model or `--g`, `--model adaptive` without a tolerance, `--g`
    /// on the full model or a file — each naming the flags.
    pub fn spec(&self, default: ModelSpec) -> Result<ModelSpec, Error> {
        let name = match (&self.model, self.basis) {
            (Some(_), Some(_)) => return Err(RomError::ModelAndBasis.into()),
            (Some(m), None) => Some(ModelName::parse(m)?),
            (None, Some(kind)) => Some(ModelName::Basis(kind)),
            (None, None) => None,
        };
        let nu = self.nu;
        let on = match (&self.tolerance_on, self.tolerance) {
            (Some(_), None) => return Err(RomError::ToleranceOnWithout.into()),
            (Some(list), Some(_)) => Some(parse_tolerance_on(list)?),
            (None, _) => None,
        };
        if let Some(tolerance) = self.tolerance {
            let named = match (&self.model, self.basis) {
                (Some(m), _) => Some(format!("--model {m}")),
                (None, Some(kind)) => Some(format!("--basis {}", kind.name())),
                _ => None,
            };
            return match name {
                None | Some(ModelName::Adaptive) => {
                    if self.g.is_some() {
                        return Err(RomError::ToleranceAndG.into());
                    }
                    super::tolerance::check_tolerance(tolerance)?;
                    Ok(ModelSpec::Tolerance { tolerance, nu, on })
                }
                Some(_) => Err(RomError::ToleranceModel {
                    model: named.unwrap_or_default(),
                }
                .into()),
            };
        }
        let g = self.g;
        Ok(match name {
            None => match default {
                ModelSpec::Full if g.is_some() => return Err(RomError::GWithoutBasis.into()),
                ModelSpec::Basis { kind, .. } => ModelSpec::Basis { kind, g, nu },
                other => other,
            },
            Some(ModelName::Full) => {
                if g.is_some() {
                    return Err(RomError::GOnFull.into());
                }
                ModelSpec::Full
            }
            Some(ModelName::Basis(kind)) => ModelSpec::Basis { kind, g, nu },
            Some(ModelName::Pod) => ModelSpec::Pod {
                g,
                nu,
                train_end: None,
                snapshots: DEFAULT_SNAPSHOTS,
            },
            Some(ModelName::Adaptive) => return Err(RomError::AdaptiveWithoutTolerance.into()),
            Some(ModelName::File(path)) => {
                if g.is_some() {
                    return Err(RomError::FileSizing.into());
                }
                ModelSpec::File(path)
            }
        })
    }
}

/// An error for a command that cannot use the model `spec` names: `command` is the command's
/// name, `what` says what it takes instead.
pub fn unsupported(command: &str, spec: &ModelSpec, what: &'static str) -> Error {
    RomError::Unsupported {
        command: command.to_string(),
        model: spec.name(),
        takes: what,
    }
    .into()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flags(model: Option<&str>, g: Option<usize>, tolerance: Option<f64>) -> ModelFlags {
        ModelFlags {
            model: model.map(str::to_string),
            basis: None,
            g,
            nu: DEFAULT_NU,
            tolerance,
            tolerance_on: None,
        }
    }

    #[test]
    fn names_parse_into_specs() {
        let tvd = ModelSpec::Basis {
            kind: BasisKind::Tvd,
            g: None,
            nu: 10,
        };
        assert_eq!(flags(None, None, None).spec(tvd.clone()).unwrap(), tvd);
        assert_eq!(
            flags(Some("full"), None, None).spec(tvd.clone()).unwrap(),
            ModelSpec::Full
        );
        assert_eq!(
            flags(Some("jim"), Some(4), None).spec(tvd.clone()).unwrap(),
            ModelSpec::Basis {
                kind: BasisKind::Jim,
                g: Some(4),
                nu: 10
            }
        );
        assert_eq!(
            flags(None, None, Some(0.01)).spec(tvd.clone()).unwrap(),
            ModelSpec::Tolerance {
                tolerance: 0.01,
                nu: 10,
                on: None
            }
        );
        assert_eq!(
            flags(Some("file:a.json"), None, None)
                .spec(tvd.clone())
                .unwrap(),
            ModelSpec::File(PathBuf::from("a.json"))
        );
        for name in BasisKind::NAMES {
            let spec = flags(Some(name), None, None).spec(tvd.clone()).unwrap();
            assert_eq!(spec.name(), name);
        }
    }

    #[test]
    fn conflicts_are_errors_naming_the_flags() {
        let tvd = ModelSpec::Basis {
            kind: BasisKind::Tvd,
            g: None,
            nu: 10,
        };
        let err = |f: ModelFlags| f.spec(tvd.clone()).unwrap_err().to_string();
        assert!(err(flags(Some("nonsense"), None, None)).contains("--model"));
        assert!(err(flags(Some("adaptive"), None, None)).contains("--tolerance"));
        assert!(err(flags(None, Some(3), Some(0.01))).contains("--g"));
        assert!(err(flags(Some("tvd"), None, Some(0.01))).contains("--model tvd"));
        assert!(err(flags(Some("full"), Some(3), None)).contains("--g"));
        assert!(err(flags(None, None, Some(2.0))).contains("(0, 1)"));
        let both = ModelFlags {
            basis: Some(BasisKind::Jim),
            ..flags(Some("tvd"), None, None)
        };
        assert!(err(both).contains("--basis"));
        let on = |list: &str, tol: Option<f64>| ModelFlags {
            tolerance_on: Some(list.to_string()),
            ..flags(None, None, tol)
        };
        assert!(
            err(on("fc,bogus", Some(0.01))).contains("--tolerance-on: unknown quantity `bogus`")
        );
        assert!(err(on(" , ", Some(0.01))).contains("--tolerance-on: the list is empty"));
        assert!(err(on("fc", None)).contains("--tolerance-on"));
        assert_eq!(
            on("fr, dissipation", Some(0.01)).spec(tvd.clone()).unwrap(),
            ModelSpec::Tolerance {
                tolerance: 0.01,
                nu: 10,
                on: Some(Quantities::of(&[
                    Quantity::FrictionForce,
                    Quantity::Dissipation
                ]))
            }
        );
        assert!(flags(None, Some(2), None)
            .spec(ModelSpec::Full)
            .unwrap_err()
            .to_string()
            .contains("--g needs --basis"));
    }
}
