//! `Beam2`: the two-node, shear-flexible (Timoshenko) 3D beam used for spot welds.
//!
//! Units: lengths mm, forces N, moments N·mm, masses t; E and G in N/mm², ρ in t/mm³.
//!
//! # Why Timoshenko
//!
//! A spot weld is modelled as a beam of length L ≈ 0.5 mm and diameter d = 5 mm. For such a stubby beam the shear flexibility dominates the
//! bending flexibility by far: with ν = 0.3 the shear parameter below is
//! Φ = 12EI/(κGAL²) = 3(1 + ν)d²/(2κL²) ≈ 220, so a Bernoulli–Euler beam would be ≈ 220 times
//! too stiff transversely.
//!
//! # Local frame
//!
//! x' points from node a to node b, e = (b − a)/L, L = |b − a|. The section is a solid circle,
//! so y' and z' may be any right-handed orthonormal pair perpendicular to x'. They are built
//! from the global axis along which e has its *smallest* component (never nearly parallel to
//! e): y' = normalize(g − (g·e)e), z' = x' × y'. Because I_y = I_z and Φ_y = Φ_z, the global
//! matrices do not depend on that choice (up to round-off).
//!
//! The rotation R has the rows x', y', z' (local = R · global), and with
//! T = diag(R, R, R, R) the global matrices are K = Tᵀ K' T and M = Tᵀ M' T.
//!
//! # Section (solid circle of diameter d)
//!
//! ```text
//! A = π d²/4,   I_y = I_z = I = π d⁴/64,   J = π d⁴/32   (torsion constant = polar moment)
//! κ = 6(1 + ν)/(7 + 6ν)                    (Cowper 1966, solid circle; 0.886 for ν = 0.3)
//! G = E/(2(1 + ν))
//! Φ_y = 12 E I_z/(κ G A L²),   Φ_z = 12 E I_y/(κ G A L²)
//! ```
//!
//! Φ_y belongs to bending in the x'y' plane (deflection v, rotation θz), Φ_z to bending in the
//! x'z' plane (deflection w, rotation θy), as in Przemieniecki (1968), *Theory of Matrix
//! Structural Analysis*, ch. 5 (shear-deformable beam element).
//!
//! # Local stiffness K'
//!
//! Local DOF order per node `[u, v, w, θx, θy, θz]`, node a then b. Axial and torsion:
//!
//! ```text
//! K'[u_a,u_a] = K'[u_b,u_b] = −K'[u_a,u_b] = EA/L
//! K'[θx_a,θx_a] = K'[θx_b,θx_b] = −K'[θx_a,θx_b] = GJ/L
//! ```
//!
//! Bending in x'y', DOF (v_a, θz_a, v_b, θz_b):
//!
//! ```text
//!       E I_z        ⎡  12     6L           −12     6L         ⎤
//! ─────────────────  ⎢  6L    (4+Φ_y)L²     −6L    (2−Φ_y)L²   ⎥
//!  (1 + Φ_y) L³      ⎢ −12    −6L            12    −6L         ⎥
//!                    ⎣  6L    (2−Φ_y)L²     −6L    (4+Φ_y)L²   ⎦
//! ```
//!
//! Bending in x'z', DOF (w_a, θy_a, w_b, θy_b): the same with I_y, Φ_z and every ±6L entry of
//! opposite sign (θy = −dw/dx' where θz = +dv/dx').
//!
//! This matrix is exact for a Timoshenko beam loaded at its ends: a cantilever with tip load P
//! deflects PL³/(3EI) + PL/(κGA) = PL³(4 + Φ)/(12EI) and its tip rotates PL²/(2EI).
//! Its null space is exactly the six rigid-body motions.
//!
//! # Mass M' (lumped)
//!
//! ```text
//! at each node, local:  diag(ρAL/2, ρAL/2, ρAL/2,  ρJL/2, ρI_yL/2, ρI_zL/2)
//! in global axes:       translational block (ρAL/2)·1,
//!                       rotary block (ρL/2)·[ I·(1 − e eᵀ) + J·e eᵀ ]
//! ```
//!
//! A lumped mass is used instead of the consistent Timoshenko mass because
//! - a weld's volume AL ≈ 10 mm³ is small against the sheet volume around it, so how the
//!   weld's own mass is distributed has no measurable effect on the structure's modes;
//! - it is diagonal in local axes and positive definite for every L and d, and simple to get
//!   right (the consistent Timoshenko mass has many Φ-dependent coefficients);
//! - it gives the exact total mass ρAL for each rigid translation and the exact polar inertia
//!   ρJL about the beam axis. About a transverse axis through the midpoint it gives
//!   ρ(IL + AL³/4) instead of ρ(IL + AL³/12): 2.6 % too much for the weld (L = 0.5, d = 5),
//!   but up to 3 times too much for a slender beam, which is why this mass is meant for welds
//!   (L ≲ d), not for slender beams in dynamics.

use faer::Mat;

use super::Material;
use crate::error::{ElementError, Error};

/// Number of DOF of the element (2 nodes × 6).
const NDOF: usize = 12;

/// A two-node 3D Timoshenko beam with a solid circular section (spot weld).
///
/// The formulas (section, κ, Φ, local K' and M', frame) and units are derived in the module
/// documentation of `src/element/beam2.rs`.
#[derive(Clone, Debug)]
pub struct Beam2 {
    /// Length L, mm.
    length: f64,
    /// Rows: local axes x', y', z' in global coordinates (local = R · global).
    rotation: [[f64; 3]; 3],
    /// Cross-section area A, mm².
    area: f64,
    /// Second moments of area about y' and z', mm⁴.
    inertia_y: f64,
    inertia_z: f64,
    /// Torsion constant J, mm⁴.
    torsion: f64,
    /// Shear correction factor κ (Cowper).
    shear_factor: f64,
    material: Material,
}

impl Beam2 {
    /// Circular solid section of diameter `diameter` (mm) between nodes at `a`, `b` (mm).
    ///
    /// Errors ([`Error::Element`]) if the length |b − a| or the diameter is zero, negative or
    /// not finite, or if `material` fails [`Material::validate`].
    pub fn circular(
        a: [f64; 3],
        b: [f64; 3],
        diameter: f64,
        material: Material,
    ) -> Result<Beam2, Error> {
        let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let length = norm(d);
        if !(length.is_finite() && length > 0.0) {
            return Err(ElementError::Beam2Length { length, a, b }.into());
        }
        if !(diameter.is_finite() && diameter > 0.0) {
            return Err(ElementError::Beam2Diameter { diameter, a, b }.into());
        }
        material.validate().map_err(|e| match e {
            Error::Element(source) => Error::Element(ElementError::Beam2Material {
                a,
                b,
                source: Box::new(source),
            }),
            other => other,
        })?;

        let nu = material.poisson_ratio;
        let area = std::f64::consts::PI * diameter * diameter / 4.0;
        let inertia = std::f64::consts::PI * diameter.powi(4) / 64.0;
        let beam = Beam2 {
            length,
            rotation: frame([d[0] / length, d[1] / length, d[2] / length]),
            area,
            inertia_y: inertia,
            inertia_z: inertia,
            torsion: 2.0 * inertia,
            shear_factor: 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu),
            material,
        };

        // Extreme but finite inputs (L = 1e-310 mm, d = 1e100 mm, ...) overflow.
        let k = beam.local_stiffness();
        let m = beam.local_mass();
        if k.iter().chain(m.iter()).flatten().any(|x| !x.is_finite()) {
            return Err(ElementError::Beam2NotRepresentable {
                length,
                diameter,
                a,
                b,
            }
            .into());
        }
        Ok(beam)
    }

    /// 12×12 stiffness in global axes, DOF per node [ux, uy, uz, rx, ry, rz], node a then b.
    /// N/mm, N, N·mm/rad.
    pub fn stiffness(&self) -> Mat<f64> {
        self.to_global(&self.local_stiffness())
    }

    /// 12×12 mass in global axes (same DOF order), t, t·mm, t·mm².
    pub fn mass(&self) -> Mat<f64> {
        self.to_global(&self.local_mass())
    }

    /// (Φ_y L², Φ_z L²) = 12 E I_(z,y) / (κ G A), mm²: the shear parameters times L², which
    /// stay finite and well scaled as L → 0.
    fn shear_lengths_squared(&self) -> (f64, f64) {
        let e = self.material.youngs_modulus;
        let kga = self.shear_factor * self.material.shear_modulus() * self.area;
        (
            12.0 * e * self.inertia_z / kga,
            12.0 * e * self.inertia_y / kga,
        )
    }

    /// K' in local axes (Przemieniecki, shear-flexible).
    fn local_stiffness(&self) -> [[f64; NDOF]; NDOF] {
        let e = self.material.youngs_modulus;
        let g = self.material.shear_modulus();
        let l = self.length;
        let (s2_y, s2_z) = self.shear_lengths_squared();
        let mut k = [[0.0; NDOF]; NDOF];

        let axial = e * self.area / l;
        let torsion = g * self.torsion / l;
        for (i, s) in [(0, axial), (3, torsion)] {
            k[i][i] = s;
            k[i + 6][i + 6] = s;
            k[i][i + 6] = -s;
            k[i + 6][i] = -s;
        }
        // x'y' plane: v (1, 7) with θz (5, 11), θz = +dv/dx'.
        bending(&mut k, [1, 5, 7, 11], 1.0, e * self.inertia_z, s2_y, l);
        // x'z' plane: w (2, 8) with θy (4, 10), θy = −dw/dx'.
        bending(&mut k, [2, 4, 8, 10], -1.0, e * self.inertia_y, s2_z, l);
        k
    }

    /// M' in local axes, lumped (see the module documentation).
    fn local_mass(&self) -> [[f64; NDOF]; NDOF] {
        let half = self.material.density * self.length / 2.0;
        let node = [
            half * self.area,
            half * self.area,
            half * self.area,
            half * self.torsion,
            half * self.inertia_y,
            half * self.inertia_z,
        ];
        let mut m = [[0.0; NDOF]; NDOF];
        for (i, &v) in node.iter().enumerate() {
            m[i][i] = v;
            m[i + 6][i + 6] = v;
        }
        m
    }

    /// Tᵀ · local · T with T = diag(R, R, R, R), as a symmetric `Mat`.
    fn to_global(&self, local: &[[f64; NDOF]; NDOF]) -> Mat<f64> {
        let r = &self.rotation;
        let mut out = Mat::<f64>::zeros(NDOF, NDOF);
        for bi in 0..4 {
            for bj in 0..4 {
                // Block (bi, bj): Rᵀ · local_block · R.
                let mut kr = [[0.0; 3]; 3];
                for (p, row) in kr.iter_mut().enumerate() {
                    for (q, v) in row.iter_mut().enumerate() {
                        *v = (0..3)
                            .map(|s| local[3 * bi + p][3 * bj + s] * r[s][q])
                            .sum();
                    }
                }
                for p in 0..3 {
                    for q in 0..3 {
                        out[(3 * bi + p, 3 * bj + q)] = (0..3).map(|s| r[s][p] * kr[s][q]).sum();
                    }
                }
            }
        }
        // Remove the round-off asymmetry of the products so that K and M are symmetric to the
        // last bit (the local matrices are exactly symmetric; a unit test checks that).
        for i in 0..NDOF {
            for j in 0..i {
                let v = 0.5 * (out[(i, j)] + out[(j, i)]);
                out[(i, j)] = v;
                out[(j, i)] = v;
            }
        }
        out
    }
}

/// Adds the Timoshenko bending block of one plane to `k`.
///
/// `dof` = (translation a, rotation a, translation b, rotation b); `sign` = +1 when the rotation
/// is +d(translation)/dx' (x'y' plane), −1 when it is −d(translation)/dx' (x'z' plane);
/// `s2` = ΦL² = 12EI/(κGA). With (1 + Φ)L³ = (L² + s2)L the entries of the module-level matrix
/// are evaluated without forming Φ, so a short beam does not lose precision or overflow.
fn bending(k: &mut [[f64; NDOF]; NDOF], dof: [usize; 4], sign: f64, ei: f64, s2: f64, l: f64) {
    let l2 = l * l;
    let c = ei / ((l2 + s2) * l); // EI / ((1 + Φ) L³)
    let t = 12.0 * c;
    let tr = sign * 6.0 * l * c;
    let near = (4.0 * l2 + s2) * c; // (4 + Φ) L² c
    let far = (2.0 * l2 - s2) * c; // (2 − Φ) L² c
    let block = [
        [t, tr, -t, tr],
        [tr, near, -tr, far],
        [-t, -tr, t, -tr],
        [tr, far, -tr, near],
    ];
    for (i, row) in block.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            k[dof[i]][dof[j]] = v;
        }
    }
}

/// Euclidean norm without underflow or overflow of the squares; NaN if any component is NaN.
fn norm(v: [f64; 3]) -> f64 {
    if v.iter().any(|x| x.is_nan()) {
        return f64::NAN;
    }
    let m = v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if m == 0.0 || m.is_infinite() {
        return m;
    }
    let [x, y, z] = v.map(|x| x / m);
    m * (x * x + y * y + z * z).sqrt()
}

/// Orthonormal right-handed local frame (rows x', y', z') with x' = `e` (a unit vector).
fn frame(e: [f64; 3]) -> [[f64; 3]; 3] {
    // The global axis along which e has its smallest component is at least 54.7° from e.
    let mut k = 0;
    for i in 1..3 {
        if e[i].abs() < e[k].abs() {
            k = i;
        }
    }
    let mut g = [0.0; 3];
    g[k] = 1.0;
    let ge = e[k];
    let y = [g[0] - ge * e[0], g[1] - ge * e[1], g[2] - ge * e[2]];
    let ny = norm(y);
    let y = [y[0] / ny, y[1] / ny, y[2] / ny];
    let z = [
        e[1] * y[2] - e[2] * y[1],
        e[2] * y[0] - e[0] * y[2],
        e[0] * y[1] - e[1] * y[0],
    ];
    [e, y, z]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `to_global` symmetrizes its result, so asymmetry of the local matrices must be caught
    /// here, before it is hidden.
    #[test]
    fn local_matrices_are_exactly_symmetric() {
        for (l, d) in [(0.5, 5.0), (10.0, 5.0), (200.0, 5.0)] {
            let beam =
                Beam2::circular([1.0, 2.0, 3.0], [1.0, 2.0 + l, 3.0], d, Material::STEEL).unwrap();
            for (name, m) in [("K'", beam.local_stiffness()), ("M'", beam.local_mass())] {
                for (i, row) in m.iter().enumerate() {
                    for (j, &v) in row.iter().enumerate() {
                        assert_eq!(v, m[j][i], "{name} at ({i}, {j}), L = {l}");
                    }
                }
            }
        }
    }

    #[test]
    fn frame_is_orthonormal_and_right_handed() {
        let s = 1.0 / 3f64.sqrt();
        for e in [
            [1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [s, -s, s],
            [0.6, 0.8, 0.0],
            [1e-12, (1.0f64 - 1e-24).sqrt(), 0.0],
        ] {
            let r = frame(e);
            for i in 0..3 {
                for j in 0..3 {
                    let dot: f64 = (0..3).map(|k| r[i][k] * r[j][k]).sum();
                    let expected = if i == j { 1.0 } else { 0.0 };
                    assert!(
                        (dot - expected).abs() < 1e-14,
                        "e = {e:?}: R Rᵀ[{i}][{j}] = {dot}"
                    );
                }
            }
            let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
                - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
                + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
            assert!((det - 1.0).abs() < 1e-14, "e = {e:?}: det R = {det}");
            assert_eq!(r[0], e);
        }
    }
}
