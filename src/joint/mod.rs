//! The joint: node pairs with their local frames ([`frame`]), the operator `B` that maps
//! structural DOF to pair gaps and slips and its reduction `BΦ` ([`operator`]), the penalty
//! contact and viscoplastic Coulomb friction law ([`law`]), and the frictionless contact
//! statics by an active-set Newton iteration ([`statics`]).

pub mod frame;
pub mod law;
pub mod operator;
pub mod statics;

pub use frame::PairFrame;
pub use operator::{JointOperator, NORMAL, T1, T2};
