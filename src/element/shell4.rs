//! `Shell4`: flat 4-node shell with 6 DOF per node.
//!
//! The element is the superposition of three independent parts in a local frame
//! `(e1, e2, n)` on the element's plane (the shell is flat: a warped quadrilateral is an error):
//!
//! **Membrane** — bilinear plane stress with Wilson's incompatible modes in Taylor's form
//! (QM6): `u = Σ N_i u_i + (1 − r²) a_1 + (1 − s²) a_2` (likewise v); the incompatible
//! derivatives use the Jacobian at the element centre scaled by `det J0 / det J`, so the
//! constant-strain patch test passes on distorted meshes, and in-plane bending of a
//! rectangle is exact. The four internal DOF are condensed statically:
//! `K_m = K_cc − K_ca K_aa⁻¹ K_ac`, with `D_m = E t / (1 − ν²) [1 ν 0; ν 1 0; 0 0 (1−ν)/2]`.
//!
//! **Plate bending** — the Discrete Kirchhoff–Mindlin quadrilateral (DKMQ, Katili 1993), valid
//! from thick to thin plates without shear locking. With the local rotations θ1 (about e1) and
//! θ2 (about e2) the fibre rotations are `β_x = θ2`, `β_y = −θ1`, and each edge k (C: nodes
//! 0 → 1, A: 3 → 2, B: 0 → 3, D: 1 → 2; length L_k, unit tangent t_k) adds a quadratic
//! tangential rotation to the bilinear field:
//!
//! ```text
//! β = Σ_i N_i β_i + Σ_k P_k t_k Δβ_k,   P_k the serendipity mid-side functions (P_A = ½(1 − r²)(1 + s), …)
//! ```
//!
//! Δβ_k is fixed by the edge's own nodal values: the edge's shear strain is constant,
//! `γ_k = (w_j − w_i)/L_k + β̄_s + ⅔ Δβ_k` on average along the edge, and equals the shear force
//! of the quadratic rotation's bending moment, `γ_k = −⅔ φ_k Δβ_k` with
//! `φ_k = 2/(κ(1 − ν)) (t/L_k)²`, so
//!
//! ```text
//! Δβ_k = −3 / (2 L_k (1 + φ_k)) · (w_j − w_i + L_k/2 (β_s,i + β_s,j)),   β_s = β·t_k
//! ```
//!
//! Curvatures `κ = [β_x,x, β_y,y, β_x,y + β_y,x]` of the enriched field, `D_b = E t³ / (12 (1 − ν²))
//! [...]`; transverse shear is the MITC4 field of Bathe & Dvorkin (1985) built from the edges'
//! γ_k — the covariant strains at the mid-edges A, C (γ_r) and B, D (γ_s), each `φ_k/(1 + φ_k)`
//! of MITC4's tying value `½(w_j − w_i + L_k β̄_s)`, interpolated
//! `γ_r = ½(1+s) γ_r^A + ½(1−s) γ_r^C`, `γ_s = ½(1+r) γ_s^D + ½(1−r) γ_s^B`; Cartesian
//! `[γ_xz, γ_yz] = J⁻¹ [γ_r, γ_s]`, `D_s = κ G t` with κ = 5/6. Thin (φ → 0): the
//! Kirchhoff constraint on every edge, the DKQ element (the edge's deflection is the Hermite
//! cubic of its nodal w and β_s); thick (φ ≫ 1): Δβ → 0 and MITC4. Rigid motions and constant
//! curvatures give Δβ_k = 0 (patch test). Why DKMQ rather than MITC4's bending: on the paper's
//! coarse 5 × 12.5 mm shells it converges faster under refinement, and the weld
//! neighbourhoods' sides use the same edge field (`super::weld_patch`), so sheets and welds
//! converge together (measured: docs/validation/welds.md).
//!
//! **Drilling** — the rotation θ3 about the normal has no stiffness of its own in shell theory;
//! a small penalty ties it to the in-plane rotation of the membrane field (Hughes & Brezzi):
//! `U_d = ½ ∫ α G t (θ3 − ω)² dA` with `ω = ½ (v_,x − u_,y)` (compatible part) and
//! α = [`Shell4::DEFAULT_DRILLING_FACTOR`] = 1e-3. It vanishes for rigid-body rotation, so the
//! element keeps exactly six zero-energy modes, and it restrains a weld beam's spin about the
//! sheet normal. With α = 1e-3 its effect on membrane stiffness is below 0.1 %.
//!
//! All parts use 2×2 Gauss quadrature.
//!
//! **Mass** — consistent: `ρ t ∫ N_i N_j dA` for the three translations and the rotary inertia
//! `ρ t³/12 ∫ N_i N_j dA` for θ1 and θ2; the drilling rotation θ3 gets the same rotary inertia
//! (a modelling choice: it keeps M positive definite; its modes lie above 100 kHz here).
//!
//! Units: coordinates and thickness mm, E and G N/mm², ρ t/mm³; stiffness N/mm, N, N·mm/rad;
//! mass t, t·mm².

use faer::Mat;

use super::Material;
use crate::error::{ElementError, Error};

const NODE_R: [f64; 4] = [-1.0, 1.0, 1.0, -1.0];
const NODE_S: [f64; 4] = [-1.0, -1.0, 1.0, 1.0];
const GAUSS: f64 = 0.577_350_269_189_625_8; // 1/sqrt(3)
const GAUSS_POINTS: [(f64, f64); 4] = [
    (-GAUSS, -GAUSS),
    (GAUSS, -GAUSS),
    (GAUSS, GAUSS),
    (-GAUSS, GAUSS),
];

/// Local DOF indices within a node: translations along e1, e2, n, rotations about e1, e2, n.
const U: usize = 0;
const V: usize = 1;
const W: usize = 2;
const T1: usize = 3;
const T2: usize = 4;
const T3: usize = 5;

type Mat24 = [[f64; 24]; 24];

/// A flat 4-node shell element (see the module docs for the formulation).
#[derive(Clone, Debug)]
pub struct Shell4 {
    /// Node coordinates in the local frame, mm.
    local: [[f64; 2]; 4],
    /// Rows e1, e2, n of the local frame (global components).
    frame: [[f64; 3]; 3],
    /// Thickness, mm.
    thickness: f64,
    material: Material,
    /// Drilling penalty factor α (dimensionless).
    drilling_factor: f64,
}

/// One edge's DKMQ terms ([`Shell4::edge_rows`]).
struct EdgeTerms {
    /// Row of the mid-side tangential rotation increment Δβ_k over the 24 local DOF (rad).
    increment: [f64; 24],
    /// φ_k / (1 + φ_k): the edge's shear strain relative to MITC4's tying value.
    factor: f64,
    /// Unit tangent (local e1, e2 components).
    tangent: [f64; 2],
}

/// DKMQ's shear parameter of an edge of length `l` (mm) in a shell of thickness `t` (mm):
/// `φ = 2 / (κ (1 − ν)) (t / l)²` — the ratio of the edge's bending to its shear flexibility.
pub(crate) fn dkmq_phi(t: f64, l: f64, nu: f64) -> f64 {
    2.0 / (Shell4::SHEAR_CORRECTION * (1.0 - nu)) * (t / l).powi(2)
}

/// `(∂P_k/∂r, ∂P_k/∂s)` of the serendipity mid-side functions of the edges C, A, B, D:
/// `P_C = ½(1 − r²)(1 − s)`, `P_A = ½(1 − r²)(1 + s)`, `P_B = ½(1 − r)(1 − s²)`,
/// `P_D = ½(1 + r)(1 − s²)`.
fn edge_bubble_derivatives(r: f64, s: f64) -> [(f64, f64); 4] {
    [
        (-r * (1.0 - s), -0.5 * (1.0 - r * r)),
        (-r * (1.0 + s), 0.5 * (1.0 - r * r)),
        (-0.5 * (1.0 - s * s), -(1.0 - r) * s),
        (0.5 * (1.0 - s * s), -(1.0 + r) * s),
    ]
}

/// The curvature rows `κ = [β_x,x, β_y,y, β_x,y + β_y,x]` over the 24 local DOF at `(r, s)`:
/// the bilinear rotations plus DKMQ's mid-side increments of the four edges (module docs).
fn curvature_rows(sh: &ShapeAt, r: f64, s: f64, edges: &[EdgeTerms; 4]) -> [[f64; 24]; 3] {
    let mut bb = [[0.0; 24]; 3];
    for i in 0..4 {
        // β_x = θ2, β_y = −θ1.
        bb[0][6 * i + T2] = sh.dx[i];
        bb[1][6 * i + T1] = -sh.dy[i];
        bb[2][6 * i + T2] = sh.dy[i];
        bb[2][6 * i + T1] = -sh.dx[i];
    }
    // Mid-side tangential rotation increments: β += Σ_k P_k t_k Δβ_k.
    for (edge, (p_r, p_s)) in edges.iter().zip(edge_bubble_derivatives(r, s)) {
        let px = sh.inv_j[0][0] * p_r + sh.inv_j[0][1] * p_s;
        let py = sh.inv_j[1][0] * p_r + sh.inv_j[1][1] * p_s;
        let [c, sn] = edge.tangent;
        for d in 0..24 {
            let v = edge.increment[d];
            if v != 0.0 {
                bb[0][d] += px * c * v;
                bb[1][d] += py * sn * v;
                bb[2][d] += (py * c + px * sn) * v;
            }
        }
    }
    bb
}

/// Shape functions and their derivatives at one point.
struct ShapeAt {
    n: [f64; 4],
    /// dN/dx, dN/dy (local Cartesian).
    dx: [f64; 4],
    dy: [f64; 4],
    det_j: f64,
    /// Inverse Jacobian, `[dr/dx, ds/dx; dr/dy, ds/dy]` (so `d/dx = inv[0][0] d/dr + inv[0][1] d/ds`).
    inv_j: [[f64; 2]; 2],
}

fn shape_functions(r: f64, s: f64) -> ([f64; 4], [f64; 4], [f64; 4]) {
    let mut n = [0.0; 4];
    let mut dr = [0.0; 4];
    let mut ds = [0.0; 4];
    for i in 0..4 {
        n[i] = 0.25 * (1.0 + r * NODE_R[i]) * (1.0 + s * NODE_S[i]);
        dr[i] = 0.25 * NODE_R[i] * (1.0 + s * NODE_S[i]);
        ds[i] = 0.25 * NODE_S[i] * (1.0 + r * NODE_R[i]);
    }
    (n, dr, ds)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
fn scale(a: [f64; 3], f: f64) -> [f64; 3] {
    [a[0] * f, a[1] * f, a[2] * f]
}

impl Shell4 {
    /// Default drilling penalty factor α in `½ ∫ α G t (θ3 − ω)² dA`.
    pub const DEFAULT_DRILLING_FACTOR: f64 = 1e-3;
    /// Shear correction factor of the transverse shear stiffness.
    pub const SHEAR_CORRECTION: f64 = 5.0 / 6.0;

    /// A shell through the four nodes (mm, counter-clockwise seen from either side), with
    /// thickness `thickness` (mm). Errors: non-finite or coincident coordinates, a warped or
    /// non-convex quadrilateral, non-positive thickness, invalid material.
    pub fn new(nodes: [[f64; 3]; 4], thickness: f64, material: Material) -> Result<Shell4, Error> {
        material.validate()?;
        if !(thickness.is_finite() && thickness > 0.0) {
            return Err(ElementError::Shell4Thickness { thickness }.into());
        }
        if nodes.iter().flatten().any(|c| !c.is_finite()) {
            return Err(ElementError::Shell4NotFinite { nodes }.into());
        }
        let centre = scale(
            [0, 1, 2].map(|k| nodes.iter().map(|p| p[k]).sum::<f64>()),
            0.25,
        );
        let d13 = sub(nodes[2], nodes[0]);
        let d24 = sub(nodes[3], nodes[1]);
        let normal = cross(d13, d24);
        let size = norm(d13).max(norm(d24));
        let area2 = norm(normal);
        if size == 0.0 || area2 <= 1e-12 * size * size {
            return Err(ElementError::Shell4Degenerate { nodes }.into());
        }
        let n = scale(normal, 1.0 / area2);
        for p in &nodes {
            let off = dot(sub(*p, centre), n);
            if off.abs() > 1e-6 * size {
                return Err(ElementError::Shell4Warped {
                    node: *p,
                    offset: off,
                }
                .into());
            }
        }
        let mut e1 = sub(
            [0, 1, 2].map(|k| nodes[1][k] + nodes[2][k]),
            [0, 1, 2].map(|k| nodes[0][k] + nodes[3][k]),
        );
        e1 = sub(e1, scale(n, dot(e1, n)));
        let e1n = norm(e1);
        if e1n <= 1e-12 * size {
            return Err(ElementError::Shell4NoEdge { nodes }.into());
        }
        let e1 = scale(e1, 1.0 / e1n);
        let e2 = cross(n, e1);
        let local = nodes.map(|p| {
            let d = sub(p, centre);
            [dot(d, e1), dot(d, e2)]
        });
        let shell = Shell4 {
            local,
            frame: [e1, e2, n],
            thickness,
            material,
            drilling_factor: Self::DEFAULT_DRILLING_FACTOR,
        };
        for &(r, s) in GAUSS_POINTS.iter().chain(&[(0.0, 0.0)]) {
            if shell.shape_at(r, s).det_j <= 0.0 {
                return Err(ElementError::Shell4NotConvex { nodes }.into());
            }
        }
        Ok(shell)
    }

    /// Unit normal of the element plane (global components).
    pub fn normal(&self) -> [f64; 3] {
        self.frame[2]
    }

    /// Element area, mm².
    pub fn area(&self) -> f64 {
        GAUSS_POINTS
            .iter()
            .map(|&(r, s)| self.shape_at(r, s).det_j)
            .sum()
    }

    fn jacobian(&self, dr: &[f64; 4], ds: &[f64; 4]) -> [[f64; 2]; 2] {
        let mut j = [[0.0; 2]; 2];
        for i in 0..4 {
            j[0][0] += dr[i] * self.local[i][0];
            j[0][1] += dr[i] * self.local[i][1];
            j[1][0] += ds[i] * self.local[i][0];
            j[1][1] += ds[i] * self.local[i][1];
        }
        j
    }

    fn shape_at(&self, r: f64, s: f64) -> ShapeAt {
        let (n, dr, ds) = shape_functions(r, s);
        let j = self.jacobian(&dr, &ds);
        let det_j = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        // J = [x_r y_r; x_s y_s]; [d/dx; d/dy] = J⁻¹ [d/dr; d/ds].
        let inv_j = [
            [j[1][1] / det_j, -j[0][1] / det_j],
            [-j[1][0] / det_j, j[0][0] / det_j],
        ];
        let mut dx = [0.0; 4];
        let mut dy = [0.0; 4];
        for i in 0..4 {
            dx[i] = inv_j[0][0] * dr[i] + inv_j[0][1] * ds[i];
            dy[i] = inv_j[1][0] * dr[i] + inv_j[1][1] * ds[i];
        }
        ShapeAt {
            n,
            dx,
            dy,
            det_j,
            inv_j,
        }
    }

    /// Covariant transverse shear strain rows at a tying point: returns (B_r, B_s), the rows
    /// giving γ_r and γ_s in terms of the 24 local DOF.
    fn covariant_shear_rows(&self, r: f64, s: f64) -> ([f64; 24], [f64; 24]) {
        let (n, dr, ds) = shape_functions(r, s);
        let j = self.jacobian(&dr, &ds);
        let (x_r, y_r, x_s, y_s) = (j[0][0], j[0][1], j[1][0], j[1][1]);
        let mut br = [0.0; 24];
        let mut bs = [0.0; 24];
        for i in 0..4 {
            // γ_r = w_,r + β_x x_,r + β_y y_,r with β_x = θ2, β_y = −θ1.
            br[6 * i + W] = dr[i];
            br[6 * i + T2] = n[i] * x_r;
            br[6 * i + T1] = -n[i] * y_r;
            bs[6 * i + W] = ds[i];
            bs[6 * i + T2] = n[i] * x_s;
            bs[6 * i + T1] = -n[i] * y_s;
        }
        (br, bs)
    }

    /// The four edges' DKMQ terms, in the order C (nodes 0 → 1), A (3 → 2), B (0 → 3),
    /// D (1 → 2) — each along +r or +s, as MITC4's tying points.
    fn edge_rows(&self) -> [EdgeTerms; 4] {
        let nu = self.material.poisson_ratio;
        let t = self.thickness;
        [(0usize, 1usize), (3, 2), (0, 3), (1, 2)].map(|(i, j)| {
            let dx = self.local[j][0] - self.local[i][0];
            let dy = self.local[j][1] - self.local[i][1];
            let l = (dx * dx + dy * dy).sqrt();
            let (c, sn) = (dx / l, dy / l);
            let phi = dkmq_phi(t, l, nu);
            let coef = -1.5 / (l * (1.0 + phi));
            // Δβ_k = coef (w_j − w_i + L/2 (β_s,i + β_s,j)), β_s = c β_x + s β_y = c θ2 − s θ1.
            let mut increment = [0.0; 24];
            increment[6 * j + W] += coef;
            increment[6 * i + W] -= coef;
            for n in [i, j] {
                increment[6 * n + T2] += coef * 0.5 * l * c;
                increment[6 * n + T1] -= coef * 0.5 * l * sn;
            }
            EdgeTerms {
                increment,
                factor: phi / (1.0 + phi),
                tangent: [c, sn],
            }
        })
    }

    fn membrane_d(&self) -> [[f64; 3]; 3] {
        let e = self.material.youngs_modulus;
        let nu = self.material.poisson_ratio;
        let c = e * self.thickness / (1.0 - nu * nu);
        [
            [c, c * nu, 0.0],
            [c * nu, c, 0.0],
            [0.0, 0.0, c * (1.0 - nu) / 2.0],
        ]
    }

    /// The bilinear shape functions `N_a(r, s)` and the area element `det J` (mm² per unit
    /// `dr ds`) at the parametric point `(r, s)` ∈ [−1, 1]².
    pub fn shape(&self, r: f64, s: f64) -> ([f64; 4], f64) {
        let sh = self.shape_at(r, s);
        (sh.n, sh.det_j)
    }

    /// The row (24 values over the global DOF `[ux, uy, uz, rx, ry, rz]` of the four nodes) of
    /// the transverse deflection `w = n·u` (mm, along [`Shell4::normal`]) at the parametric
    /// point `(r, s)`.
    ///
    /// `edges = false`: the bilinear interpolation `Σ N_a w_a` of the nodal deflections.
    /// `edges = true`: the element's own edge deflections blended over the face (a Coons
    /// patch). Along edge k (nodes i → j, length L, arc length σ) DKMQ's tangential rotation
    /// is `β_s(σ) = β_s,i + (β_s,j − β_s,i) σ/L + Δβ_k (4σ/L − 4σ²/L²)` and its shear strain the
    /// constant `γ_k = −⅔ φ_k Δβ_k`, so `w' = γ_k − β_s` integrates to the cubic
    ///
    /// ```text
    /// w_k(σ) = w_i + (γ_k − β_s,i) σ − (β_s,j − β_s,i) σ²/(2L) − Δβ_k (2σ²/L − 4σ³/(3L²))
    /// ```
    ///
    /// which ends at `w_j` by the definition of `Δβ_k` (thin: the Hermite cubic of the nodal
    /// deflections and slopes `−β_s`, the DKQ edge). The face gets
    /// `w = ½(1−s) w_C(r) + ½(1+s) w_A(r) + ½(1−r) w_B(s) + ½(1+r) w_D(s) − Σ N_a w_a`,
    /// which equals each edge's cubic on that edge (so neighbouring faces agree) and, on a
    /// rectangle, is the 12-term Adini–Clough–Melosh interpolation of the nodal deflections and
    /// Kirchhoff slopes.
    pub fn deflection_row(&self, r: f64, s: f64, edges: bool) -> [f64; 24] {
        let (n, _, _) = shape_functions(r, s);
        let mut local = [0.0; 24];
        for a in 0..4 {
            local[6 * a + W] = n[a];
        }
        if edges {
            for v in local.iter_mut() {
                *v = -*v;
            }
            let nu = self.material.poisson_ratio;
            let terms = self.edge_rows();
            // (edge nodes, edge parameter, blend) of C, A, B, D — the order of `edge_rows`.
            let blend = [
                ((0usize, 1usize), r, 0.5 * (1.0 - s)),
                ((3, 2), r, 0.5 * (1.0 + s)),
                ((0, 3), s, 0.5 * (1.0 - r)),
                ((1, 2), s, 0.5 * (1.0 + r)),
            ];
            for (((i, j), tau, b), edge) in blend.into_iter().zip(&terms) {
                let dx = self.local[j][0] - self.local[i][0];
                let dy = self.local[j][1] - self.local[i][1];
                let l = (dx * dx + dy * dy).sqrt();
                let [c, sn] = edge.tangent;
                let phi = dkmq_phi(self.thickness, l, nu);
                let sigma = 0.5 * l * (1.0 + tau);
                // w_k = w_i + σ γ − σ β_i − σ²/(2L) (β_j − β_i) − Δβ (2σ²/L − 4σ³/(3L²)),
                // γ = −⅔ φ Δβ, β = c θ2 − s θ1.
                let q = sigma * sigma / (2.0 * l);
                let dbeta = -(2.0 / 3.0) * phi * sigma
                    - (2.0 * sigma * sigma / l - 4.0 * sigma.powi(3) / (3.0 * l * l));
                local[6 * i + W] += b;
                for (node, coef) in [(i, -sigma + q), (j, -q)] {
                    local[6 * node + T2] += b * coef * c;
                    local[6 * node + T1] -= b * coef * sn;
                }
                for (d, v) in edge.increment.iter().enumerate() {
                    local[d] += b * dbeta * v;
                }
            }
        }
        // Local DOF row → global: a_g[3 blk + c] = Σ_k a_l[3 blk + k] R[k][c].
        let f = &self.frame;
        let mut out = [0.0; 24];
        for blk in 0..8 {
            for c in 0..3 {
                out[3 * blk + c] = (0..3).map(|k| local[3 * blk + k] * f[k][c]).sum();
            }
        }
        out
    }

    /// Stiffness in the local frame (24×24, local DOF order per node u, v, w, θ1, θ2, θ3).
    fn local_stiffness(&self) -> Mat24 {
        let mut k = [[0.0; 24]; 24];
        let t = self.thickness;
        let dm = self.membrane_d();
        let db = {
            let f = t * t / 12.0;
            dm.map(|row| row.map(|v| v * f))
        };
        let g = self.material.shear_modulus();
        let ds = Self::SHEAR_CORRECTION * g * t;
        let dd = self.drilling_factor * g * t;

        // Incompatible-mode derivatives use the centre Jacobian (Taylor's correction).
        let centre = self.shape_at(0.0, 0.0);
        let det0 = centre.det_j;
        let inv0 = centre.inv_j;

        // Tying-point rows for MITC4.
        let (mut ra, _) = self.covariant_shear_rows(0.0, 1.0);
        let (mut rc, _) = self.covariant_shear_rows(0.0, -1.0);
        let (_, mut sb) = self.covariant_shear_rows(-1.0, 0.0);
        let (_, mut sd) = self.covariant_shear_rows(1.0, 0.0);
        // DKMQ: each edge's constant shear strain is φ_k / (1 + φ_k) of MITC4's tying value.
        let edges = self.edge_rows();
        for (row, e) in [(&mut rc, 0), (&mut ra, 1), (&mut sb, 2), (&mut sd, 3)] {
            let f = edges[e].factor;
            row.iter_mut().for_each(|v| *v *= f);
        }

        let mut kcc = [[0.0; 8]; 8]; // membrane compatible, DOF (u_i, v_i) → 2i, 2i+1
        let mut kca = [[0.0; 4]; 8];
        let mut kaa = [[0.0; 4]; 4];

        for &(r, s) in &GAUSS_POINTS {
            let sh = self.shape_at(r, s);
            let w = sh.det_j;

            // Membrane, compatible part: rows ε_x, ε_y, γ_xy over 8 DOF.
            let mut bm = [[0.0; 8]; 3];
            for i in 0..4 {
                bm[0][2 * i] = sh.dx[i];
                bm[1][2 * i + 1] = sh.dy[i];
                bm[2][2 * i] = sh.dy[i];
                bm[2][2 * i + 1] = sh.dx[i];
            }
            // Incompatible part: P1 = 1 − r², P2 = 1 − s²; a = [u1, u2, v1, v2].
            let f = det0 / sh.det_j;
            let p_dr = [-2.0 * r, 0.0];
            let p_ds = [0.0, -2.0 * s];
            let mut ba = [[0.0; 4]; 3];
            for m in 0..2 {
                let px = f * (inv0[0][0] * p_dr[m] + inv0[0][1] * p_ds[m]);
                let py = f * (inv0[1][0] * p_dr[m] + inv0[1][1] * p_ds[m]);
                ba[0][m] = px;
                ba[1][2 + m] = py;
                ba[2][m] = py;
                ba[2][2 + m] = px;
            }
            let dbm = mat3_times(&dm, &bm);
            let dba = mat3_times(&dm, &ba);
            for a in 0..8 {
                for b in 0..8 {
                    kcc[a][b] += w * (0..3).map(|q| bm[q][a] * dbm[q][b]).sum::<f64>();
                }
                for b in 0..4 {
                    kca[a][b] += w * (0..3).map(|q| bm[q][a] * dba[q][b]).sum::<f64>();
                }
            }
            for a in 0..4 {
                for b in 0..4 {
                    kaa[a][b] += w * (0..3).map(|q| ba[q][a] * dba[q][b]).sum::<f64>();
                }
            }

            // Bending: κ rows over 24 DOF.
            let bb = curvature_rows(&sh, r, s, &edges);
            let dbb = mat3_times(&db, &bb);
            add_btdb(&mut k, &bb, &dbb, w);

            // MITC4 transverse shear.
            let mut gr = [0.0; 24];
            let mut gs = [0.0; 24];
            for d in 0..24 {
                gr[d] = 0.5 * (1.0 + s) * ra[d] + 0.5 * (1.0 - s) * rc[d];
                gs[d] = 0.5 * (1.0 + r) * sd[d] + 0.5 * (1.0 - r) * sb[d];
            }
            let mut bsh = [[0.0; 24]; 2];
            for d in 0..24 {
                bsh[0][d] = sh.inv_j[0][0] * gr[d] + sh.inv_j[0][1] * gs[d];
                bsh[1][d] = sh.inv_j[1][0] * gr[d] + sh.inv_j[1][1] * gs[d];
            }
            for a in 0..24 {
                if bsh[0][a] == 0.0 && bsh[1][a] == 0.0 {
                    continue;
                }
                for b in 0..24 {
                    k[a][b] += w * ds * (bsh[0][a] * bsh[0][b] + bsh[1][a] * bsh[1][b]);
                }
            }

            // Drilling: θ3 − ½ (v_,x − u_,y).
            let mut bd = [0.0; 24];
            for i in 0..4 {
                bd[6 * i + T3] = sh.n[i];
                bd[6 * i + V] = -0.5 * sh.dx[i];
                bd[6 * i + U] = 0.5 * sh.dy[i];
            }
            for a in 0..24 {
                if bd[a] == 0.0 {
                    continue;
                }
                for b in 0..24 {
                    k[a][b] += w * dd * bd[a] * bd[b];
                }
            }
        }

        // Condense the incompatible modes: K_m = K_cc − K_ca K_aa⁻¹ K_ac.
        let kaa_inv = invert4(&kaa);
        let mut km = kcc;
        for a in 0..8 {
            for b in 0..8 {
                let mut corr = 0.0;
                for p in 0..4 {
                    for q in 0..4 {
                        corr += kca[a][p] * kaa_inv[p][q] * kca[b][q];
                    }
                }
                km[a][b] -= corr;
            }
        }
        let mdof = |a: usize| 6 * (a / 2) + if a % 2 == 0 { U } else { V };
        for a in 0..8 {
            for b in 0..8 {
                k[mdof(a)][mdof(b)] += km[a][b];
            }
        }
        symmetrize(&mut k);
        k
    }

    /// Mass in the local frame.
    fn local_mass(&self) -> Mat24 {
        let rho = self.material.density;
        let t = self.thickness;
        let mt = rho * t;
        let mr = rho * t * t * t / 12.0;
        let mut m = [[0.0; 24]; 24];
        for &(r, s) in &GAUSS_POINTS {
            let sh = self.shape_at(r, s);
            for i in 0..4 {
                for j in 0..4 {
                    let nn = sh.n[i] * sh.n[j] * sh.det_j;
                    for d in [U, V, W] {
                        m[6 * i + d][6 * j + d] += mt * nn;
                    }
                    for d in [T1, T2, T3] {
                        m[6 * i + d][6 * j + d] += mr * nn;
                    }
                }
            }
        }
        m
    }

    /// Rotates a local 24×24 matrix to global axes: `Tᵀ A T` with `T = diag(R, …, R)`,
    /// R's rows the local frame vectors.
    fn to_global(&self, a: &Mat24) -> Mat<f64> {
        let r = &self.frame;
        // (A T): for each row a, block column j: sum_k A[a][3j+k] R[k][c].
        let mut at = [[0.0; 24]; 24];
        for (a, row) in a.iter().enumerate() {
            for blk in 0..8 {
                for c in 0..3 {
                    at[a][3 * blk + c] = (0..3).map(|k| row[3 * blk + k] * r[k][c]).sum();
                }
            }
        }
        Mat::from_fn(24, 24, |i, j| {
            let blk = i / 3;
            let c = i % 3;
            (0..3).map(|k| r[k][c] * at[3 * blk + k][j]).sum()
        })
    }

    /// Global local-DOF transformation of a global displacement vector: `u_local = T u_global`.
    fn to_local_vector(&self, u: &[f64; 24]) -> [f64; 24] {
        let r = &self.frame;
        let mut out = [0.0; 24];
        for blk in 0..8 {
            for k in 0..3 {
                out[3 * blk + k] = (0..3).map(|c| r[k][c] * u[3 * blk + c]).sum();
            }
        }
        out
    }

    /// 24×24 stiffness in global axes, DOF per node `[ux, uy, uz, rx, ry, rz]`.
    pub fn stiffness(&self) -> Mat<f64> {
        self.to_global(&self.local_stiffness())
    }

    /// 24×24 consistent mass in global axes.
    pub fn mass(&self) -> Mat<f64> {
        self.to_global(&self.local_mass())
    }

    /// Strain energy `½ uᵀ K u` (N·mm) of a global displacement vector, evaluated from the
    /// local stiffness without forming the global matrix (an independent path for tests).
    pub fn strain_energy(&self, u: &[f64; 24]) -> f64 {
        let ul = self.to_local_vector(u);
        let k = self.local_stiffness();
        0.5 * (0..24)
            .map(|a| ul[a] * (0..24).map(|b| k[a][b] * ul[b]).sum::<f64>())
            .sum::<f64>()
    }
}

fn mat3_times<const N: usize>(d: &[[f64; 3]; 3], b: &[[f64; N]; 3]) -> [[f64; N]; 3] {
    let mut out = [[0.0; N]; 3];
    for q in 0..3 {
        for c in 0..N {
            out[q][c] = (0..3).map(|p| d[q][p] * b[p][c]).sum();
        }
    }
    out
}

fn add_btdb(k: &mut Mat24, b: &[[f64; 24]; 3], db: &[[f64; 24]; 3], w: f64) {
    for a in 0..24 {
        if b[0][a] == 0.0 && b[1][a] == 0.0 && b[2][a] == 0.0 {
            continue;
        }
        for c in 0..24 {
            k[a][c] += w * (b[0][a] * db[0][c] + b[1][a] * db[1][c] + b[2][a] * db[2][c]);
        }
    }
}

fn symmetrize(k: &mut Mat24) {
    for a in 0..24 {
        for b in (a + 1)..24 {
            let v = 0.5 * (k[a][b] + k[b][a]);
            k[a][b] = v;
            k[b][a] = v;
        }
    }
}

/// Inverse of a symmetric positive definite 4×4 matrix by Gauss–Jordan elimination.
fn invert4(a: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut m = *a;
    let mut inv = [[0.0; 4]; 4];
    for (i, row) in inv.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for col in 0..4 {
        let p = m[col][col];
        for c in 0..4 {
            m[col][c] /= p;
            inv[col][c] /= p;
        }
        for r in 0..4 {
            if r != col {
                let f = m[r][col];
                for c in 0..4 {
                    m[r][c] -= f * m[col][c];
                    inv[r][c] -= f * inv[col][c];
                }
            }
        }
    }
    inv
}
