//! Loading a model by name or path: a user's matrix map (detected by its `schema`), a NASTRAN
//! deck (by extension or content), a case file or a built-in case.

use super::Model;
use crate::case::Case;
use crate::error::Error;

impl Model {
    /// Loads a model: a user's matrix map (a JSON file with `"schema": "jointrom-matrices"`,
    /// see [`crate::model::matrices`]), a NASTRAN deck (`.bdf`, `.dat`, `.nas`, or by content:
    /// [`crate::case::nastran::is_deck`]), a case file or a built-in case name.
    pub fn from_case_name(arg: &str) -> Result<Model, Error> {
        if let Some(map) = super::matrices::map_file(arg)? {
            return super::matrices::load(&map);
        }
        if crate::case::nastran::is_deck(arg) {
            return Model::from_deck(std::path::Path::new(arg));
        }
        Model::from_case(Case::load(arg)?)
    }

    /// [`Model::from_case_name`] with the options a file does not carry (`opts`): for a deck
    /// the rule of its area welds' neighbourhoods, and for any model the contact law per area
    /// `[κ_n, κ_t]` (N/mm³) on the pairs' tributary areas in place of the stiffnesses the file
    /// gives (a deck's PGAP, a case's or a map's contact block; `crate::model::per_area`; the
    /// file's friction coefficient stays), and for a case the contact points inside its joint's
    /// faces. Errors name the flags (`--contact-per-area`, `--contact-sampling`).
    pub fn from_case_name_with(arg: &str, opts: &LoadOptions) -> Result<Model, Error> {
        let field = "--contact-per-area";
        let is_map = super::matrices::map_file(arg)?.is_some();
        let is_deck = !is_map && crate::case::nastran::is_deck(arg);
        if opts.contact_sampling.is_some() && (is_map || is_deck) {
            return Err(crate::error::ModelError::PerArea {
                model: arg.to_string(),
                field: "--contact-sampling".into(),
                reason: "contact points inside the joint's faces are given for case files only \
                         (a deck's CGAPs and a map's pairs are node pairs)"
                    .into(),
            }
            .into());
        }
        let Some(kappa) = opts.contact_per_area else {
            return if is_deck {
                Model::from_deck_with(std::path::Path::new(arg), opts.deck_local_mesh)
            } else if let Some(sampling) = opts.contact_sampling {
                let mut case = Case::load(arg)?;
                if case.contact.per_area().is_none() {
                    return Err(crate::error::ModelError::PerArea {
                        model: case.source.clone(),
                        field: "--contact-sampling".into(),
                        reason: "contact points need the contact stiffnesses per area: the \
                                 case gives them per pair (add --contact-per-area KN,KT)"
                            .into(),
                    }
                    .into());
                }
                case.contact.sampling = Some(sampling);
                Model::from_case(case)
            } else {
                Model::from_case_name(arg)
            };
        };
        if is_map || is_deck {
            let mut model = if is_deck {
                Model::from_deck_with(std::path::Path::new(arg), opts.deck_local_mesh)?
            } else {
                Model::from_case_name(arg)?
            };
            if model.pair_weights.is_some() {
                return Err(crate::error::ModelError::PerArea {
                    model: model.source.clone(),
                    field: field.to_string(),
                    reason: "the map already gives its contact law per area".into(),
                }
                .into());
            }
            model.apply_contact_per_area(kappa, field)?;
            return Ok(model);
        }
        let mut case = Case::load(arg)?;
        case.contact.normal_stiffness = f64::NAN;
        case.contact.stick_stiffness = f64::NAN;
        case.contact.normal_stiffness_per_area = Some(kappa[0]);
        case.contact.stick_stiffness_per_area = Some(kappa[1]);
        if opts.contact_sampling.is_some() {
            case.contact.sampling = opts.contact_sampling;
        }
        Model::from_case(case)
    }
}

/// What loading a model may be told beside its file (the CLI's `--contact-per-area`,
/// `--deck-local-mesh`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LoadOptions {
    /// The contact law per area `[κ_n, κ_t]`, N/mm³, in place of the file's stiffnesses.
    pub contact_per_area: Option<[f64; 2]>,
    /// How a deck's area welds re-mesh their neighbourhood (default `auto`, a case file's
    /// rule; `off`: the nugget on the deck's own shells; a size in mm).
    pub deck_local_mesh: crate::case::LocalMesh,
    /// Contact points inside a case's joint faces (`crate::model::sampling`), in place of the
    /// case's `contact.sampling`; needs the law per area.
    pub contact_sampling: Option<crate::case::ContactSampling>,
}
