//! Studies: orchestration of many runs — backbones from free decays ([`backbone`]), the static
//! convergence study ([`convergence`]), the stability map ([`stability`]), parameter sweeps on
//! one reduced model ([`sweep`]) and the main job ([`main_job`]). One reduced model and its run
//! live in [`crate::rom`].

pub mod backbone;
pub mod convergence;
pub mod main_job;
pub mod stability;
pub mod sweep;
