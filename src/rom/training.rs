//! POD training (the paper's Section 5.2 competitor): a full-FE transient run whose displacement
//! snapshots are compressed by POD into the joint part of a Craig–Bampton basis
//! ([`crate::reduction::snapshot_basis`]).

use serde::Serialize;

use crate::error::{Error, RomError};
use crate::integrate::{integrate, TransientOptions};
use crate::model::Model;
use crate::reduction::{snapshot_basis, Basis, BasisOptions};
use crate::system::{FullSystem, Scene};

/// What the training cost and kept.
#[derive(Clone, Debug, Serialize)]
pub struct Training {
    /// End of the training run, s.
    pub end_time: f64,
    /// Snapshots kept.
    pub snapshots: usize,
    /// Wall time of the training run, s.
    pub wall_s: f64,
    /// CPU time of the training run, s.
    pub cpu_s: f64,
    /// Integrator steps of the training run.
    pub steps: u64,
    /// The snapshot POD's energy ratios w(g).
    pub w: Vec<f64>,
}

/// Runs the full model over `[0, train_end]` with `opts` (its end time replaced), keeps about
/// `snapshots` (≥ 2) evenly spaced displacement states and builds the snapshot POD basis with
/// `basis` (g, ν: the Euclidean POD, no weighting).
///
/// # Errors
/// `snapshots < 2`, the full run failing, the basis failing.
pub fn train_snapshot_basis(
    model: &Model,
    opts: &TransientOptions,
    train_end: f64,
    snapshots: usize,
    basis: &BasisOptions,
) -> Result<(Basis, Training), Error> {
    if snapshots < 2 {
        return Err(RomError::Snapshots { snapshots }.into());
    }
    let train_opts = TransientOptions {
        end_time: Some(train_end),
        ..opts.clone()
    };
    let outputs = (train_end / opts.output_step).ceil().max(1.0) as usize + 1;
    let every = (outputs / snapshots).max(1);
    let mut states: Vec<Vec<f64>> = Vec::new();
    let mut k = 0usize;
    let run = integrate(
        FullSystem::new(model)?,
        &Scene::of(model),
        &train_opts,
        |_, q| {
            if k % every == 0 {
                states.push(q.to_vec());
            }
            k += 1;
        },
    )
    .into_result()?;
    let y = faer::Mat::from_fn(model.dofs(), states.len(), |r, c| states[c][r]);
    let basis = snapshot_basis(model, y.as_ref(), None, basis)?;
    let training = Training {
        end_time: train_end,
        snapshots: states.len(),
        wall_s: run.wall_s,
        cpu_s: run.cpu_s,
        steps: run.stats.steps,
        w: basis.w.clone(),
    };
    Ok((basis, training))
}
