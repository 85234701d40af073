//! Studies: orchestration of many runs — the static convergence study ([`convergence`]), the
//! stability map ([`stability`]) and parameter sweeps on one reduced model ([`sweep`]).

pub mod convergence;
pub mod main_job;
pub mod stability;
pub mod sweep;
