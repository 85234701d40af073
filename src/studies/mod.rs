//! Studies: orchestration of many runs — the static convergence study ([`convergence`]), the
//! stability map ([`stability`]), parameter sweeps on one reduced model ([`sweep`]), POD training
//! on a full run ([`training`]) and the main job ([`main_job`]).

pub mod convergence;
pub mod main_job;
pub mod stability;
pub mod sweep;
pub mod tolerance;
pub mod training;
