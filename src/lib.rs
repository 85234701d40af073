//! # jointrom
//!
//! Transient dynamics of jointed sheet structures (leaf springs, spot-welded panels, lap joints)
//! with contact and friction in the joints, by model order reduction with trial vector
//! derivatives (Witteveen & Pichler 2014, `shared/paper`).
//!
//! The folders of the crate are the pipeline (see `ARCHITECTURE.md`: each uses only the ones
//! above it):
//!
//! 1. [`linalg`]: symmetric sparse storage, the SPD Cholesky, compensated arithmetic, eigen;
//! 2. [`case`]: a JSON case file (units mm, N, t, s) is parsed and its fields validated;
//! 3. [`mesh`]: the sheets, weld beams, clamps, rigid ties and joint pairs are generated (and the
//!    geometry validated);
//! 4. [`element`]: `Shell4` and `Beam2` element matrices;
//! 5. [`assembly`]: sparse global K and M on the independent DOF (clamp and rigid tie
//!    eliminated);
//! 6. [`joint`]: pair frames, the joint operator B, the contact and friction law, contact statics;
//! 7. [`model`]: the [`Model`] (from a case or a user's matrices), its modes and statics;
//! 8. [`system`]: the second-order-system boundary, full and reduced;
//! 9. [`reduction`]: Craig–Bampton, trial vector derivatives, POD, the basis Φ and competitors;
//! 10. [`integrate`]: the mechanical ODE and the one CVODE driver loop;
//! 11. [`rom`]: the reduced model's home — the model choice ([`rom::ModelSpec`]), the
//!     tolerance-chosen model, every reduced run with its error estimate, the reduced-model file;
//! 12. [`studies`]: convergence study, stability map, sweeps, backbones, the main job;
//! 13. [`report`]: charts, heat maps, VTU, the main job's report.
//!
//! ```no_run
//! let model = jointrom::Model::from_case_name("friction_bar")?;
//! assert_eq!(model.dofs(), 906);
//! let modes = model.modes(10, jointrom::Interface::Fixed)?;
//! println!("10th fixed-interface mode: {:.1} Hz", modes.frequencies_hz[9]);
//!
//! // A 1 % reduced model, its run and its error estimate.
//! use jointrom::rom::{run_model, ModelSpec, RunSettings};
//! let spec = ModelSpec::Tolerance { tolerance: 1e-2, nu: 10, on: None };
//! let opts = jointrom::integrate::TransientOptions::default();
//! let out = run_model(&model, &spec, &opts, &RunSettings::default())?;
//! println!("r = {}, estimate {:?}", out.basis_size, out.estimate);
//! # Ok::<(), jointrom::Error>(())
//! ```

// Index loops mirror the element and matrix formulas (B_ij, K_ab) more clearly than iterator
// chains; clippy's style lint against them is switched off for the numerical code.
#![allow(clippy::needless_range_loop)]
// All FFI `unsafe` lives in `sundials`.
#![deny(unsafe_code)]

pub mod linalg;

pub mod case;

pub mod mesh;

pub mod element;

pub mod assembly;

pub mod joint;

pub mod model;

pub mod system;

pub mod reduction;

pub mod integrate;

pub mod rom;

pub mod studies;

pub mod report;

pub mod error;

pub mod files;

pub use error::Error;
pub use model::{Interface, Model};
