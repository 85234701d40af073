//! Whole models (`jointrom::model`): DOF counts, constraints, modes, users' MatrixMarket models,
//! contact statics, and the CLI's `info`/`modes`/`static` contract.

#[path = "../common/mod.rs"]
mod common;

mod contact_statics;
mod deck;
mod matrices;
mod model;
mod per_area;
mod petsc;
mod sampling;
mod slip;
mod weld_targets;
