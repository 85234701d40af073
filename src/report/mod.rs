//! Output for people and tools: charts ([`chart`], [`heatmap`]), VTU fields for ParaView
//! ([`vtu`], [`shapes`]), CSV curves ([`curves`]), the convergence study's and the stability
//! map's outputs ([`convergence`], [`stability`]) and the main job's report ([`main_job`]).

pub mod chart;
pub mod convergence;
pub mod curves;
pub mod heatmap;
pub mod html;
pub mod main_job;
pub mod shapes;
pub mod stability;
pub mod vtu;
