//! Tributary areas of joint pairs: the share of the joint surface each node-to-node pair
//! stands for, so that a contact law given per area (a pressure per penetration κ, N/mm³) becomes
//! the pair springs `k_i = κ·A_i` (N/mm).
//!
//! # The rule: the consistent nodal area
//!
//! The joint surface is the set of the lower side's quadrilateral faces whose four corners are
//! all joint nodes — lower nodes of pairs, of coincident pairs left out because an area weld
//! fuses them or a support holds them, or clamped or tied nodes (a deck has no pair there) —
//! with at least one corner a pair's or a left-out pair's. Each face `e` gives
//! its corner `a` the integral of the corner's bilinear shape function,
//!
//! ```text
//! A_a^e = ∫_e N_a dA ,        A_i = Σ_{e ∋ i} A_i^e ,        Σ_i A_i = A_joint ,
//! ```
//!
//! evaluated with 2×2 Gauss points on the face's own (possibly distorted) geometry. It is the
//! nodal force of a unit uniform pressure, so a penetration field that is uniform over the joint
//! gives exactly the uniform pressure κ·g on any mesh (the patch test of a penalty surface
//! law), and `κ·A_i` is the row sum of the consistent penalty matrix `κ ∫ N_i N_j dA` — the
//! lumped (diagonal) form that keeps the pairs independent, as the node-to-node law needs, with
//! positive entries for bilinear faces. On a rectangular face `A_a^e` is a quarter of the face,
//! so on a regular grid the rule and "a quarter of each adjacent face" agree; on a distorted
//! face the integral puts more of the area at the corners with the larger angle, where the
//! quarter rule does not see the shape.
//!
//! The shares of the left-out corners belong to the weld (its nugget carries the load there) or
//! the support; they are returned as [`Tributary::excluded`], so `Σ A_i + excluded = A_joint`.

use super::{JointPair, ShellElem};

/// Tributary areas of the pairs.
#[derive(Clone, Debug, PartialEq)]
pub struct Tributary {
    /// `A_i` per pair, mm² (in the order of the pairs given).
    pub areas: Vec<f64>,
    /// Area of the joint surface that falls to left-out (fused, clamped, tied) pairs, mm².
    pub excluded: f64,
    /// Area of the joint surface (all its faces), mm².
    pub total: f64,
}

/// Why a pair has no tributary area.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Uncovered {
    /// Index of the pair.
    pub pair: usize,
    /// Its lower node.
    pub node: usize,
}

/// The tributary areas of `pairs` on the faces `shells` (nodes at `nodes`, mm), with
/// `excluded` the coincident pairs left out of the joint (fused, clamped, tied) and `held` the
/// clamped and tied nodes; `Err` names the first pair on no face of the
/// joint surface (module docs). A lower node shared by several pairs splits its area evenly.
pub fn tributary_areas(
    nodes: &[[f64; 3]],
    shells: &[ShellElem],
    pairs: &[JointPair],
    excluded: &[JointPair],
    held: &[usize],
) -> Result<Tributary, Uncovered> {
    // Per node: how many pairs have it as lower node, whether a left-out pair does, whether a
    // support holds it.
    let mut count = vec![0u32; nodes.len()];
    let mut left_out = vec![false; nodes.len()];
    let mut support = vec![false; nodes.len()];
    for p in pairs {
        count[p.lower] += 1;
    }
    for p in excluded {
        left_out[p.lower] = true;
    }
    for &n in held {
        support[n] = true;
    }
    let coincident = |n: usize| count[n] > 0 || left_out[n];
    let mut node_area = vec![0.0; nodes.len()];
    let (mut total, mut excluded_area) = (0.0, 0.0);
    for shell in shells {
        if !on_joint_surface(shell.nodes, coincident, |n| support[n]) {
            continue;
        }
        let shares = corner_areas(shell.nodes.map(|n| nodes[n]));
        for (&n, a) in shell.nodes.iter().zip(shares) {
            total += a;
            if count[n] > 0 {
                node_area[n] += a;
            } else {
                excluded_area += a;
            }
        }
    }
    let mut areas = Vec::with_capacity(pairs.len());
    for (i, p) in pairs.iter().enumerate() {
        let a = node_area[p.lower] / f64::from(count[p.lower]);
        if a.is_nan() || a <= 0.0 {
            return Err(Uncovered {
                pair: i,
                node: p.lower,
            });
        }
        areas.push(a);
    }
    Ok(Tributary {
        areas,
        excluded: excluded_area,
        total,
    })
}

/// Whether a face with `corners` is on the joint surface (module docs): every corner a joint
/// node (a pair's or a left-out pair's lower node) or held by a support, and one at least a
/// joint node. The one rule of the pairs' tributary areas and of the contact points inside the
/// faces ([`crate::model::sampling`]), so that their areas add up alike.
pub fn on_joint_surface(
    corners: [usize; 4],
    joint: impl Fn(usize) -> bool,
    held: impl Fn(usize) -> bool,
) -> bool {
    corners.iter().all(|&n| joint(n) || held(n)) && corners.iter().any(|&n| joint(n))
}

/// `∫ N_a dA` of the four corners of a bilinear face (corners in cyclic order), mm²: 2×2 Gauss
/// points, the area element `|x_ξ × x_η|` of the face's own geometry.
pub fn corner_areas(x: [[f64; 3]; 4]) -> [f64; 4] {
    const XI: [f64; 4] = [-1.0, 1.0, 1.0, -1.0];
    const ETA: [f64; 4] = [-1.0, -1.0, 1.0, 1.0];
    let g = 1.0 / 3f64.sqrt();
    let mut out = [0.0; 4];
    for (xi, eta) in [(-g, -g), (g, -g), (g, g), (-g, g)] {
        let (mut dxi, mut deta) = ([0.0; 3], [0.0; 3]);
        for a in 0..4 {
            let (dn_dxi, dn_deta) = (
                0.25 * XI[a] * (1.0 + ETA[a] * eta),
                0.25 * ETA[a] * (1.0 + XI[a] * xi),
            );
            for c in 0..3 {
                dxi[c] += dn_dxi * x[a][c];
                deta[c] += dn_deta * x[a][c];
            }
        }
        let cross = [
            dxi[1] * deta[2] - dxi[2] * deta[1],
            dxi[2] * deta[0] - dxi[0] * deta[2],
            dxi[0] * deta[1] - dxi[1] * deta[0],
        ];
        let da = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
        for a in 0..4 {
            out[a] += 0.25 * (1.0 + XI[a] * xi) * (1.0 + ETA[a] * eta) * da;
        }
    }
    out
}
