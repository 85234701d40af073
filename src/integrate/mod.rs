//! Time integration: the first-order ODE problem and its options ([`problem`]), the mechanical
//! problem of any [`crate::system::SecondOrderSystem`] with contact and friction
//! ([`mechanical`]), and SUNDIALS CVODE beneath ([`sundials`], the crate's only `unsafe`).

pub mod mechanical;
pub mod problem;
#[allow(unsafe_code)]
pub mod sundials;
