//! Output (`jointrom::report`): the main job's quick report and VTU files.

#[path = "../common/mod.rs"]
mod common;

mod report;
mod vtu;
