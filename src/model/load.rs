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

    /// [`Model::from_case_name`] with, for `contact_per_area = Some([κ_n, κ_t])` (N/mm³), the
    /// contact law per area on the model's tributary areas in place of the stiffnesses the file
    /// gives (a deck's PGAP, a case's or a map's contact block; `crate::model::per_area`); the
    /// file's friction coefficient stays. Errors name `field` (the flag).
    pub fn from_case_name_with(
        arg: &str,
        contact_per_area: Option<[f64; 2]>,
        field: &str,
    ) -> Result<Model, Error> {
        let Some(kappa) = contact_per_area else {
            return Model::from_case_name(arg);
        };
        let is_map = super::matrices::map_file(arg)?.is_some();
        if is_map || crate::case::nastran::is_deck(arg) {
            let mut model = Model::from_case_name(arg)?;
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
        Model::from_case(case)
    }
}
