//! Time integration (`jointrom::integrate`): the CVODE wrapper, the friction law, the mechanical
//! ODE on full and reduced systems, runs against the stored full-FE reference.

#[path = "../common/mod.rs"]
mod common;

mod arkode;
mod cvode;
mod friction;
mod method;
mod refresh;
mod screen;
mod stepper;
mod system;
mod transient_reference;
mod weights;
