//! The local frame of a joint node pair: normal and two tangents (rows of the joint operator).

/// A node-to-node joint pair with its local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairFrame {
    /// Node on the lower surface (index into `Geometry::nodes` of the model).
    pub lower: usize,
    /// Node on the upper surface, coincident with `lower` (zero initial clearance).
    pub upper: usize,
    /// Unit normal, pointing from the lower to the upper surface.
    pub normal: [f64; 3],
    /// First unit tangent (⊥ normal).
    pub t1: [f64; 3],
    /// Second unit tangent (⊥ normal, ⊥ t1).
    pub t2: [f64; 3],
}

impl PairFrame {
    /// The frame of the generated sheets: normal +y, t1 = +x, t2 = +z.
    pub const SHEET_AXES: ([f64; 3], [f64; 3], [f64; 3]) =
        ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);

    /// The three directions in row order (normal, t1, t2).
    pub fn directions(&self) -> [[f64; 3]; 3] {
        [self.normal, self.t1, self.t2]
    }

    /// The global axis (0 = x, 1 = y, 2 = z) closest to the normal.
    pub fn normal_axis(&self) -> usize {
        let a = self.normal.map(f64::abs);
        if a[1] >= a[0] && a[1] >= a[2] {
            1
        } else if a[0] >= a[2] {
            0
        } else {
            2
        }
    }
}
