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
}
