//! Output for people and tools: a backbone's table, CSV and charts ([`backbone`]), charts ([`chart`], [`heatmap`]), VTU fields for ParaView
//! ([`vtu`], [`shapes`]), CSV curves ([`curves`]), the convergence study's and the stability
//! map's outputs ([`convergence`], [`stability`]), the main job's report ([`main_job`]) and the
//! reduced model as an FMI 2.0 co-simulation FMU ([`fmu`]).

pub mod backbone;
pub mod chart;
pub mod convergence;
pub mod curves;
pub mod fmu;
pub mod heatmap;
pub mod html;
pub mod info;
pub mod main_job;
pub mod shapes;
pub mod stability;
pub mod vtu;
