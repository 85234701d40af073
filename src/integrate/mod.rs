//! Time integration: the first-order ODE problem, its options and statistics ([`problem`]), the
//! mechanical problem of any [`crate::system::SecondOrderSystem`] with contact and friction
//! ([`mechanical`]), the one driver loop with deadline, observer and a typed [`RunStatus`]
//! ([`driver`]), the same run advanced from outside for co-simulation ([`stepper`]), and SUNDIALS
//! CVODE (or ARKODE's ARKStep as a DIRK method) beneath (`sundials`, crate-private, the crate's
//! only `unsafe`; [`Cvode`], [`Arkode`] and [`Integrator`] re-exported).

pub mod driver;
pub mod mechanical;
pub mod problem;
pub mod stepper;
#[allow(unsafe_code)]
pub(crate) mod sundials;

pub use crate::system::Scene;
pub use driver::{
    integrate, positive_flag, run, thread_cpu_s, Curves, InitialState, Profile, Run, RunChoices,
    RunHook, RunStatus, Stall, Trajectory, TransientOptions,
};
pub use mechanical::{EnergySample, MechanicalOde, ProblemOptions};
pub use stepper::Stepper;
pub use sundials::{Arkode, Cvode, Integrator};
