//! Contact stiffness per area: a contact law given as a pressure per penetration (κ_n, κ_t,
//! N/mm³) becomes per-pair springs `k_i = κ·A_i` with `A_i` the pair's tributary area
//! ([`crate::mesh::tributary`]), so the joint's stiffness `κ·A_joint` does not change when the
//! mesh is refined.
//!
//! # Per-pair stiffness as weighted pair kinematics
//!
//! The pair law ([`crate::joint::law`]) is homogeneous of degree one in the kinematics and the
//! slip memory at fixed `k_t/k_n`: scaling `(g, u_t, s)` of a pair by `w > 0` scales its forces
//! by `w`, leaves its branch (open, stick, slip: the signs and the cone `|e| ≤ μ|p_n|/k_t`)
//! unchanged and its dissipation `p_t·ṡ` by `w²`. So with the rows of pair i in B weighted by
//!
//! ```text
//! w_i = √(A_i / Ā) ,      Ā = (1/w) Σ_i A_i  (the mean tributary area),
//! ```
//!
//! and the scalar law `k_n = κ_n Ā`, `k_t = κ_t Ā`, the force the pair returns to the structure
//! is `w_i · k_n · (w_i g_i) = κ_n A_i g_i` — exactly the per-area law — and every operator
//! built from `B`, `k_n` and `k_t` (contact statics `K + k_n Σ b_iᵀb_i`, the TVD's `∂K/∂q`, the
//! joint flexibility and the error estimate's pair-space statics, the reduced `BΦ` of a ROM
//! file and the FMU) carries the per-pair stiffness without a per-pair branch anywhere: the
//! per-pair default (no weights) runs the very same instructions as before. The weighted pair
//! quantities are the physical ones times `w_i` (gaps, slips, slip memory; forces divided by
//! `w_i`), so [`ContactMeasures`] converts back before reporting; the dissipated and stored
//! pair energies are invariant. The weights are ≈ 1 (the areas of a regular grid differ only at
//! its edges, ½ and ¼), so tolerances on the weighted gaps keep their meaning.
//!
//! `‖f_c‖` of a per-area model is the Euclidean norm of the weighted forces,
//! `√(Σ_i P_i² Ā/A_i) = √Ā · ‖p‖_{L²}` on a regular grid interior, with `P_i` the physical pair
//! forces and `p` the pressure: like the paper's norm it depends on the mesh through Ā, which is
//! why [`ContactMeasures`] reports the resultant, the contact area and the peak pressure.

use super::Model;
use crate::case::Case;
use crate::error::{Error, ModelError};
use crate::mesh::tributary::{tributary_areas, Uncovered};

/// Relative tolerance of the check that the tributary areas cover the joints' overlap.
pub const COVER_TOLERANCE: f64 = 1e-9;

impl Model {
    /// The tributary areas of the pairs from the model's mesh (`None` without a mesh).
    pub(crate) fn mesh_tributary(
        &self,
    ) -> Option<Result<crate::mesh::tributary::Tributary, Uncovered>> {
        let mesh = self.mesh()?;
        let held: Vec<usize> = mesh
            .clamped
            .iter()
            .chain(&mesh.tie.slaves)
            .copied()
            .collect();
        Some(tributary_areas(
            &mesh.nodes,
            &mesh.shells,
            &mesh.pairs,
            &mesh.excluded,
            &held,
        ))
    }

    /// Fills [`Model::pair_areas`] from the mesh where every pair has an area (the per-pair
    /// law needs none, so a pair without one only leaves the area outputs out).
    pub(crate) fn set_mesh_areas(&mut self) {
        if let Some(Ok(t)) = self.mesh_tributary() {
            self.pair_areas = Some(t.areas);
        }
    }

    fn per_area_error(&self, field: &str, reason: String) -> Error {
        ModelError::PerArea {
            model: self.source.clone(),
            field: field.to_string(),
            reason,
        }
        .into()
    }

    /// Resolves the contact law per area `[κ_n, κ_t]` (N/mm³) on the pairs' areas (module
    /// docs): weights B's pair rows and sets `k_n = κ_n Ā`, `k_t = κ_t Ā`. `field` names the
    /// field or flag that asked for it in errors: a non-positive κ, a pair without tributary
    /// area (a node on no face of the joint surface), a model without areas.
    pub fn apply_contact_per_area(&mut self, kappa: [f64; 2], field: &str) -> Result<(), Error> {
        for (name, k) in ["normal", "stick"].iter().zip(kappa) {
            if !(k.is_finite() && k > 0.0) {
                return Err(self.per_area_error(
                    field,
                    format!("the {name} stiffness per area must be positive (finite and > 0), got {k} N/mm³"),
                ));
            }
        }
        let areas = match (self.mesh_tributary(), &self.pair_areas) {
            (Some(Err(u)), _) => {
                let [x, y, z] = self.geometry.nodes[u.node];
                return Err(self.per_area_error(
                    field,
                    format!(
                        "pair {} (lower node {} at ({x}, {y}, {z}) mm) has no tributary area: its \
                         node is on no face of the joint surface (a quadrilateral whose four \
                         corners are all joint nodes), so a stiffness per area cannot be given to it",
                        u.pair, self.geometry.node_ids[u.node]
                    ),
                ));
            }
            (Some(Ok(t)), _) => t.areas,
            (None, Some(a)) => a.clone(),
            (None, None) => {
                return Err(self.per_area_error(
                    field,
                    "the model has no pair areas: give each pair's `area` (mm²) in the matrix \
                     map"
                    .into(),
                ))
            }
        };
        self.resolve_per_area(kappa, areas, field)
    }

    /// Resolves `[κ_n, κ_t]` (N/mm³, checked here) on the given areas of the model's pairs
    /// (mm², one per pair, unweighted rows): weights B's rows and sets the law (module docs).
    pub(crate) fn resolve_per_area(
        &mut self,
        kappa: [f64; 2],
        areas: Vec<f64>,
        field: &str,
    ) -> Result<(), Error> {
        for (name, k) in ["normal", "stick"].iter().zip(kappa) {
            if !(k.is_finite() && k > 0.0) {
                return Err(self.per_area_error(
                    field,
                    format!("the {name} stiffness per area must be positive (finite and > 0), got {k} N/mm³"),
                ));
            }
        }
        let mean = areas.iter().sum::<f64>() / areas.len() as f64;
        let weights: Vec<f64> = areas.iter().map(|a| (a / mean).sqrt()).collect();
        self.joint.weight_pairs(&weights);
        self.contact.normal_stiffness = kappa[0] * mean;
        self.contact.stick_stiffness = kappa[1] * mean;
        self.contact.normal_stiffness_per_area = Some(kappa[0]);
        self.contact.stick_stiffness_per_area = Some(kappa[1]);
        self.pair_areas = Some(areas);
        self.pair_weights = Some(weights);
        Ok(())
    }

    /// A case's per-area law `kappa`: checks that the pairs' faces cover the joints' summed
    /// overlap `overlap` (mm², [`joints_overlap`]; the shares of the pairs left out by welds and supports
    /// included) and
    /// resolves it.
    pub(crate) fn apply_case_per_area(
        &mut self,
        kappa: [f64; 2],
        overlap: f64,
    ) -> Result<(), Error> {
        let field = "contact.normal_stiffness_per_area";
        if let Some(Ok(t)) = self.mesh_tributary() {
            if (t.total - overlap).abs() > COVER_TOLERANCE * overlap {
                return Err(self.per_area_error(
                    field,
                    format!(
                        "the pairs' faces cover {:.6} mm² of the joints' {overlap:.6} mm² overlap: \
                         explicit `points` leave part of a joint without pairs, where a \
                         stiffness per area has no pair to act on",
                        t.total
                    ),
                ));
            }
        }
        self.apply_contact_per_area(kappa, field)
    }
}

/// The summed (x, z) overlap of the case's joints, mm² (the joints are validated: the sheets
/// exist and overlap).
pub fn joints_overlap(case: &Case) -> f64 {
    let sheet = |name: &str| case.sheets.iter().find(|s| s.name == name);
    case.joints
        .iter()
        .filter_map(|j| {
            let (a, b) = (sheet(&j.lower)?, sheet(&j.upper)?);
            let dx = a.x[1].min(b.x[1]) - a.x[0].max(b.x[0]);
            let dz = a.z[1].min(b.z[1]) - a.z[0].max(b.z[0]);
            Some(dx.max(0.0) * dz.max(0.0))
        })
        .sum()
}

/// Mesh-independent measures of a joint's contact state (beside the paper's `‖f_c‖`).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ContactMeasures {
    /// Resultant `Σ|P_i|` of the physical normal pair forces, N.
    pub contact_resultant: f64,
    /// Area of the closed pairs `Σ_{g_i<0} A_i`, mm² (`None` without pair areas).
    pub contact_area: Option<f64>,
    /// Largest pressure `max |P_i|/A_i`, N/mm² (`None` without pair areas).
    pub peak_pressure: Option<f64>,
    /// Largest penetration `max(−g_i)`, mm.
    pub max_penetration: Option<f64>,
    /// The largest penetration over the thinner sheet's thickness at that pair (`None`
    /// without a mesh).
    pub max_penetration_per_thickness: Option<f64>,
}

impl ContactMeasures {
    /// The measures as one line of text, `digits` significant decimals: "resultant … N, contact
    /// area …, peak pressure …, largest penetration … (… of the sheet thickness)" (– where a
    /// measure is not defined).
    pub fn describe(&self, digits: usize) -> String {
        let opt = |v: Option<f64>, unit: &str| {
            v.map_or("–".to_string(), |v| format!("{v:.digits$} {unit}"))
        };
        format!(
            "resultant {:.digits$} N, contact area {}, peak pressure {}, largest penetration {} \
             ({} of the sheet thickness)",
            self.contact_resultant,
            opt(self.contact_area, "mm²"),
            opt(self.peak_pressure, "N/mm²"),
            opt(self.max_penetration, "mm"),
            self.max_penetration_per_thickness
                .map_or("–".to_string(), |v| format!(
                    "{v:.prec$e}",
                    prec = digits.min(6) / 2
                )),
        )
    }
}

impl Model {
    /// The pair weight `w_i` (1 for the per-pair law).
    #[inline]
    pub fn pair_weight(&self, i: usize) -> f64 {
        self.pair_weights.as_ref().map_or(1.0, |w| w[i])
    }

    /// The measures of a contact state given by the model's (weighted) normal pair forces
    /// `forces` (N, compressive negative) and normal gaps `gaps` (mm; empty if unknown).
    pub fn contact_measures(&self, forces: &[f64], gaps: &[f64]) -> ContactMeasures {
        let mut m = ContactMeasures::default();
        let (mut area, mut peak) = (0.0, 0.0f64);
        for (i, &p) in forces.iter().enumerate() {
            let force = (self.pair_weight(i) * p).abs();
            m.contact_resultant += force;
            if let Some(a) = &self.pair_areas {
                if p != 0.0 {
                    area += a[i];
                    peak = peak.max(force / a[i]);
                }
            }
        }
        if self.pair_areas.is_some() {
            m.contact_area = Some(area);
            m.peak_pressure = Some(peak);
        }
        let mut deepest: Option<(f64, usize)> = None;
        for (i, &g) in gaps.iter().enumerate() {
            let g = g / self.pair_weight(i);
            if g < 0.0 && deepest.is_none_or(|(d, _)| -g > d) {
                deepest = Some((-g, i));
            }
        }
        m.max_penetration = Some(deepest.map_or(0.0, |d| d.0));
        if let (Some((d, i)), Some(t)) = (deepest, self.pair_thickness()) {
            m.max_penetration_per_thickness = Some(d / t[i]);
        }
        if gaps.is_empty() {
            m.max_penetration = None;
        }
        m
    }

    /// Per pair, the thinner of the two sheets' thicknesses at its nodes (mm), from the shells
    /// of the mesh (`None` without a mesh).
    pub fn pair_thickness(&self) -> Option<Vec<f64>> {
        let mesh = self.mesh()?;
        let mut t = vec![f64::INFINITY; mesh.nodes.len()];
        for s in &mesh.shells {
            for &n in &s.nodes {
                t[n] = t[n].min(s.thickness);
            }
        }
        Some(
            self.pairs
                .iter()
                .map(|p| t[p.lower].min(t[p.upper]))
                .collect(),
        )
    }
}
