//! Loading a model by name or path: a user's matrix map (detected by its `schema`), a case file or
//! a built-in case.

use super::Model;
use crate::case::Case;
use crate::error::Error;

impl Model {
    /// Loads a model: a user's matrix map (a JSON file with `"schema": "jointrom-matrices"`,
    /// see [`crate::model::matrices`]), a case file or a built-in case name.
    pub fn from_case_name(arg: &str) -> Result<Model, Error> {
        if let Some(map) = super::matrices::map_file(arg)? {
            return super::matrices::load(&map);
        }
        Model::from_case(Case::load(arg)?)
    }
}
