//! Case files (`jointrom::case`, `jointrom::mesh`): the built-in scenes, loading files by path
//! and name, one test per validation rule.

#[path = "../common/mod.rs"]
mod common;

mod case_builtins;
mod case_files;
mod case_validation;
