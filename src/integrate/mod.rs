//! Time integration: the first-order ODE problem, its options and statistics ([`problem`]), the
//! mechanical problem of any [`crate::system::SecondOrderSystem`] with contact and friction
//! ([`mechanical`]), the one driver loop with deadline, observer and a typed [`RunStatus`]
//! ([`driver`]), and SUNDIALS CVODE beneath ([`sundials`], the crate's only `unsafe`).

pub mod driver;
pub mod mechanical;
pub mod problem;
#[allow(unsafe_code)]
pub mod sundials;

pub use crate::system::Scene;
pub use driver::{
    integrate, run, thread_cpu_s, Curves, Profile, Run, RunStatus, Trajectory, TransientOptions,
};
pub use mechanical::{EnergySample, MechanicalOde, ProblemOptions};
