//! Output for people and tools: charts ([`chart`], [`heatmap`]), VTU fields for ParaView
//! ([`vtu`], [`shapes`]) and the main job's report ([`main_job`]).

pub mod chart;
pub mod convergence;
pub mod heatmap;
pub mod main_job;
pub mod shapes;
pub mod stability;
pub mod vtu;
