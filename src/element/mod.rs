//! Finite elements, named by node count.
//!
//! Every element returns its stiffness and mass in **global** axes, with 6 DOF per node in the
//! order `[ux, uy, uz, rx, ry, rz]` (mm and rad), nodes in the order given to the constructor.
//! Matrices are dense `faer::Mat<f64>` (24×24 for [`Shell4`], 12×12 for [`Beam2`]); units are
//! N/mm, N, N·mm/rad for stiffness and t, t·mm, t·mm² for mass.

mod beam2;
mod shell4;

pub use beam2::Beam2;
pub use shell4::Shell4;

use crate::error::Error;

/// Linear elastic isotropic material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Young's modulus E, N/mm².
    pub youngs_modulus: f64,
    /// Poisson's ratio ν, dimensionless.
    pub poisson_ratio: f64,
    /// Mass density ρ, t/mm³.
    pub density: f64,
}

impl Material {
    /// Structural steel as used in the paper: E = 210000 N/mm², ν = 0.3, ρ = 7.85e-9 t/mm³.
    pub const STEEL: Material = Material {
        youngs_modulus: 210_000.0,
        poisson_ratio: 0.3,
        density: 7.85e-9,
    };

    /// Shear modulus G = E / (2 (1 + ν)), N/mm².
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }

    /// Checks E > 0, -1 < ν < 0.5, ρ > 0.
    pub fn validate(&self) -> Result<(), Error> {
        let ok = self.youngs_modulus.is_finite()
            && self.youngs_modulus > 0.0
            && self.poisson_ratio > -1.0
            && self.poisson_ratio < 0.5
            && self.density.is_finite()
            && self.density > 0.0;
        if ok {
            Ok(())
        } else {
            Err(Error::Element(format!(
                "invalid material: E = {} N/mm², nu = {}, rho = {} t/mm³ (need E > 0, -1 < nu < 0.5, rho > 0)",
                self.youngs_modulus, self.poisson_ratio, self.density
            )))
        }
    }
}
