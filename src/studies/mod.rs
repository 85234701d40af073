//! Studies: orchestration of many runs — the static convergence study ([`convergence`]), the
//! stability map ([`stability`]), parameter sweeps on one reduced model ([`sweep`]), POD training
//! on a full run ([`training`]), the main job ([`main_job`]) and the errors of a run against
//! stored reference curves ([`mod@reference`]).

pub mod convergence;
pub mod main_job;
pub mod reference;
pub mod stability;
pub mod sweep;
pub mod tolerance;
pub mod training;
