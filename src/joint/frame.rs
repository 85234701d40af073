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
    /// Distances (mm, ≥ 0) from the lower and the upper node's mid-surface to the contacting
    /// faces, `[t_lower / 2, t_upper / 2]` when the slips are taken at the faces
    /// (`"slip": "faces"`), `[0, 0]` for the paper's mid-surface node-to-node kinematics.
    pub face_offsets: [f64; 2],
}

impl PairFrame {
    /// The frame of the generated sheets: normal +y, t1 = +x, t2 = +z.
    pub const SHEET_AXES: ([f64; 3], [f64; 3], [f64; 3]) =
        ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);

    /// The frame of a pair whose normal points along `direction` (from the lower to the upper
    /// node; need not be unit): t1 is global x projected onto the tangent plane (global z when
    /// the normal is within 45° of x), t2 = t1 × n. A normal within 1e-6 of +y gives
    /// [`PairFrame::SHEET_AXES`] exactly. `None` for a zero or non-finite direction.
    pub fn along(lower: usize, upper: usize, direction: [f64; 3]) -> Option<PairFrame> {
        let len = (direction.iter().map(|d| d * d).sum::<f64>()).sqrt();
        if !(len.is_finite() && len > 0.0) {
            return None;
        }
        let n = direction.map(|d| d / len);
        let (normal, t1, t2) = if (n[1] - 1.0).abs() < 1e-6 {
            Self::SHEET_AXES
        } else {
            let axis = if n[0].abs() < std::f64::consts::FRAC_1_SQRT_2 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 0.0, 1.0]
            };
            let dot: f64 = (0..3).map(|k| axis[k] * n[k]).sum();
            let t: [f64; 3] = std::array::from_fn(|k| axis[k] - dot * n[k]);
            let tl = t.iter().map(|d| d * d).sum::<f64>().sqrt();
            let t1 = t.map(|d| d / tl);
            let t2 = [
                t1[1] * n[2] - t1[2] * n[1],
                t1[2] * n[0] - t1[0] * n[2],
                t1[0] * n[1] - t1[1] * n[0],
            ];
            (n, t1, t2)
        };
        Some(PairFrame {
            lower,
            upper,
            normal,
            t1,
            t2,
            face_offsets: [0.0; 2],
        })
    }

    /// The three directions in row order (normal, t1, t2).
    pub fn directions(&self) -> [[f64; 3]; 3] {
        [self.normal, self.t1, self.t2]
    }

    /// The coefficients of a sheet's rotation `θ` (rad, global axes) in a pair row along
    /// `dir` when the contacting face lies `offset` (mm) from the mid-surface: the face
    /// point of the upper sheet is `x − offset·n`, of the lower `x + offset·n`, so with
    /// `u_face = u + θ × d` the row `dir·(u_face,upper − u_face,lower)` gains
    /// `−offset (n × dir)·θ` from either sheet (zero for the normal row, `n × n = 0`).
    pub fn face_rotation_row(&self, dir: [f64; 3], offset: f64) -> [f64; 3] {
        let n = self.normal;
        let c = [
            n[1] * dir[2] - n[2] * dir[1],
            n[2] * dir[0] - n[0] * dir[2],
            n[0] * dir[1] - n[1] * dir[0],
        ];
        c.map(|v| -offset * v)
    }

    /// The global axis (0 = x, 1 = y, 2 = z) closest to the normal.
    pub(crate) fn normal_axis(&self) -> usize {
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
