//! The condensation against the direct dense formula on a small neighbourhood.

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};

use super::*;
use crate::case::{Case, LocalMesh};
use crate::mesh::Mesh;

/// Two 60 × 60 plates of unequal thickness, 6 × 6 shells each, one weld off the nodes with its
/// neighbourhood re-meshed at `size` mm.
fn mesh(size: f64) -> Mesh {
    let text = r#"{
        "name": "plates",
        "material": {"youngs_modulus": 210000.0, "poisson_ratio": 0.3, "density": 7.85e-9},
        "sheets": [
            {"name": "A", "x": [0.0, 60.0], "z": [0.0, 60.0], "y": 0.0, "thickness": 0.8, "elements": [6, 6]},
            {"name": "B", "x": [0.0, 60.0], "z": [0.0, 60.0], "y": 0.65, "thickness": 0.5, "elements": [6, 6]}
        ],
        "clamps": [{"x": 0.0, "sheets": ["A"]}],
        "rigid_tie": {"x": 60.0, "sheets": ["B"], "master": [60.0, 0.65, 30.0]},
        "welds": [{"x": 31.25, "z": 27.5, "sheets": ["A", "B"], "diameter": 5.0}],
        "joints": [],
        "contact": {"normal_stiffness": 1.0e4, "friction_coefficient": 0.25, "stick_stiffness": 1.0e4},
        "load": {"master": {"fy": -0.1}, "ramp": {"shape": "half_cosine", "duration": 0.05}},
        "end_time": 0.1
    }"#;
    let mut case = Case::from_json_str(text, "plates.json").unwrap();
    case.welds[0].local_mesh = LocalMesh::Size(size);
    Mesh::from_case(&case).unwrap()
}

/// `Aᵀ F A` for the dense fine matrix `f` and the constraint `a` (per fine DOF, its terms on the
/// condensed DOF `[retained; internal]`).
fn project(f: &Mat<f64>, a: &[Vec<(usize, f64)>], n: usize) -> Mat<f64> {
    let mut fa = Mat::<f64>::zeros(f.nrows(), n);
    for (row, terms) in a.iter().enumerate() {
        for &(col, c) in terms {
            for i in 0..f.nrows() {
                fa[(i, col)] += c * f[(i, row)];
            }
        }
    }
    let mut out = Mat::<f64>::zeros(n, n);
    for (row, terms) in a.iter().enumerate() {
        for &(col, c) in terms {
            for j in 0..n {
                out[(col, j)] += c * fa[(row, j)];
            }
        }
    }
    out
}

/// max |a − b| / max |b|.
fn relative(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
    let (mut diff, mut scale) = (0.0f64, 0.0f64);
    for j in 0..b.ncols() {
        for i in 0..b.nrows() {
            diff = diff.max((a[(i, j)] - b[(i, j)]).abs());
            scale = scale.max(b[(i, j)].abs());
        }
    }
    diff / scale
}

#[test]
fn condensation_equals_the_dense_formula() {
    let mesh = mesh(2.0);
    let weld = &mesh.welds[0];
    let patch = weld.patch.as_ref().expect("a re-meshed neighbourhood");
    let material = Material::STEEL;
    let got = condense(weld, patch, material, Par::Seq).unwrap();

    // The dense reference: K_f, M_f on every small-shell DOF, A from the roles.
    let (retained, roles, internal) = patch_roles(patch, material);
    let (nr, ni, nf) = (6 * retained.len(), 6 * internal, 6 * roles.len());
    let (mut kf, mut mf) = (Mat::<f64>::zeros(nf, nf), Mat::<f64>::zeros(nf, nf));
    for_each_element(patch, material, 0, true, |nodes, ke, me| {
        for (p, &a) in nodes.iter().enumerate() {
            for (q, &b) in nodes.iter().enumerate() {
                for c in 0..6 {
                    for d in 0..6 {
                        kf[(6 * a + c, 6 * b + d)] += ke[(6 * p + c, 6 * q + d)];
                        if let Some(me) = me {
                            mf[(6 * a + c, 6 * b + d)] += me[(6 * p + c, 6 * q + d)];
                        }
                    }
                }
            }
        }
    })
    .unwrap();
    let a: Vec<Vec<(usize, f64)>> = (0..nf)
        .map(|f| match roles[f / 6] {
            Role::Internal(i) => vec![(nr + 6 * i + f % 6, 1.0)],
            role => {
                let (t, n) = retained_terms(role, f % 6);
                t[..n].to_vec()
            }
        })
        .collect();
    let (kh, mh) = (project(&kf, &a, nr + ni), project(&mf, &a, nr + ni));
    let kii = kh.as_ref().submatrix(nr, nr, ni, ni).to_owned();
    let kir = kh.as_ref().submatrix(nr, 0, ni, nr).to_owned();
    let x = -kii.llt(Side::Lower).unwrap().solve(&kir);
    let mut t = Mat::<f64>::zeros(nr + ni, nr);
    for r in 0..nr {
        t[(r, r)] = 1.0;
    }
    t.as_mut().submatrix_mut(nr, 0, ni, nr).copy_from(&x);
    let (k_ref, m_ref) = (t.transpose() * &kh * &t, t.transpose() * &mh * &t);
    assert!(
        ni > 10 * nr,
        "a neighbourhood worth condensing ({ni} internal DOF)"
    );
    let (ek, em) = (
        relative(&got.stiffness, &k_ref),
        relative(&got.mass, &m_ref),
    );
    assert!(
        ek < 1e-10 && em < 1e-10,
        "stiffness {ek:.2e}, mass {em:.2e}"
    );
}
