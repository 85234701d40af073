//! Shell4 element tests: invariants, patch tests, energy consistency, and convergence of a
//! thin cantilever strip to beam/plate theory.

use faer::{Mat, Side};
use jointrom::assembly::{assemble_structure, Structure};
use jointrom::element::{Material, Shell4};
use jointrom::linalg::cholesky::solve_spd;
use jointrom::linalg::eigen::{dense_modes, lowest_modes};
use jointrom::mesh::{Mesh, RigidTie, SheetGrid, ShellElem};

use crate::common::v3::{cross, dot, normalize};

const STEEL: Material = Material::STEEL;
const STEEL_NU0: Material = Material {
    youngs_modulus: 210_000.0,
    poisson_ratio: 0.0,
    density: 7.85e-9,
};

/// Nodes of a distorted quadrilateral rotated into an arbitrary orientation in space.
fn skewed_nodes() -> [[f64; 3]; 4] {
    let plane = [[0.0, 0.0], [6.0, 0.5], [7.0, 5.0], [-0.5, 4.0]];
    let (e1, e2) = rotated_axes();
    let origin = [3.0, -2.0, 1.0];
    plane.map(|[a, b]| [0, 1, 2].map(|k| origin[k] + a * e1[k] + b * e2[k]))
}

fn skewed_element(material: Material) -> Shell4 {
    Shell4::new(skewed_nodes(), 0.5, material).unwrap()
}

fn rotated_axes() -> ([f64; 3], [f64; 3]) {
    let e1 = normalize([0.6, 0.3, -0.74]);
    let tmp = [0.1, 0.9, 0.2];
    let d = dot(tmp, e1);
    let e2 = normalize([tmp[0] - d * e1[0], tmp[1] - d * e1[1], tmp[2] - d * e1[2]]);
    (e1, e2)
}

fn max_abs(m: &Mat<f64>) -> f64 {
    let mut v: f64 = 0.0;
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            v = v.max(m[(i, j)].abs());
        }
    }
    v
}

#[test]
fn stiffness_and_mass_are_symmetric_and_mass_is_positive_definite() {
    let e = skewed_element(STEEL);
    let k = e.stiffness();
    let m = e.mass();
    let (ks, ms) = (max_abs(&k), max_abs(&m));
    for i in 0..24 {
        for j in 0..24 {
            assert!((k[(i, j)] - k[(j, i)]).abs() <= 1e-12 * ks, "K({i},{j})");
            assert!((m[(i, j)] - m[(j, i)]).abs() <= 1e-12 * ms, "M({i},{j})");
        }
    }
    assert!(m.llt(Side::Lower).is_ok(), "M must be positive definite");
    // Total mass of a rigid translation in each direction: ρ t A.
    let area = e.area();
    for d in 0..3 {
        let mut r = [0.0; 24];
        for n in 0..4 {
            r[6 * n + d] = 1.0;
        }
        let mr: f64 = (0..24)
            .map(|i| r[i] * (0..24).map(|j| m[(i, j)] * r[j]).sum::<f64>())
            .sum();
        let expected = STEEL.density * 0.5 * area;
        assert!(
            (mr - expected).abs() <= 1e-12 * expected,
            "{mr} vs {expected}"
        );
    }
}

#[test]
fn free_element_has_exactly_six_rigid_body_modes() {
    let e = skewed_element(STEEL);
    let k = e.stiffness();
    let nodes = skewed_nodes();
    let ks = max_abs(&k);
    let p = [1.0, 2.0, -3.0];
    let mut rigid = Vec::new();
    for d in 0..3 {
        let mut r = vec![0.0; 24];
        for n in 0..4 {
            r[6 * n + d] = 1.0;
        }
        rigid.push(r);
    }
    for d in 0..3 {
        let mut theta = [0.0; 3];
        theta[d] = 1.0;
        let mut r = vec![0.0; 24];
        for n in 0..4 {
            let x = [0, 1, 2].map(|k| nodes[n][k] - p[k]);
            let u = cross(theta, x);
            r[6 * n..6 * n + 3].copy_from_slice(&u);
            r[6 * n + 3..6 * n + 6].copy_from_slice(&theta);
        }
        rigid.push(r);
    }
    for (c, r) in rigid.iter().enumerate() {
        let rn = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        for i in 0..24 {
            let f: f64 = (0..24).map(|j| k[(i, j)] * r[j]).sum();
            assert!(
                f.abs() <= 1e-9 * ks * rn,
                "rigid mode {c}: force {f} at dof {i}"
            );
        }
    }
    let eig = k.self_adjoint_eigenvalues(Side::Lower).unwrap();
    let largest = eig[23];
    let zero = eig.iter().filter(|&&l| l.abs() <= 1e-9 * largest).count();
    assert_eq!(zero, 6, "eigenvalues of K: {eig:?}");
    // The smallest non-zero one is the drilling/bending mode: clearly positive.
    assert!(eig[6] > 1e-9 * largest);
}

#[test]
fn energy_gradient_matches_stiffness_by_finite_differences() {
    let e = skewed_element(STEEL);
    let k = e.stiffness();
    let mut u = [0.0; 24];
    for (i, v) in u.iter_mut().enumerate() {
        *v = ((i as f64) * 0.731).sin() * if i % 6 < 3 { 1e-2 } else { 1e-3 };
    }
    let h = 1e-6;
    for i in 0..24 {
        let mut up = u;
        let mut um = u;
        up[i] += h;
        um[i] -= h;
        let fd = (e.strain_energy(&up) - e.strain_energy(&um)) / (2.0 * h);
        let ku: f64 = (0..24).map(|j| k[(i, j)] * u[j]).sum();
        let scale = (0..24).map(|j| (k[(i, j)] * u[j]).abs()).sum::<f64>();
        assert!(
            (fd - ku).abs() <= 1e-6 * scale,
            "dof {i}: finite difference {fd} vs K u {ku}"
        );
    }
    // Second differences reproduce a column of K.
    for j in [0, 4, 11, 17, 23] {
        for i in [1, 2, 9, 16, 22] {
            let mut e_pp = u;
            let mut e_pm = u;
            let mut e_mp = u;
            let mut e_mm = u;
            let hh = 1e-3;
            e_pp[i] += hh;
            e_pp[j] += hh;
            e_pm[i] += hh;
            e_pm[j] -= hh;
            e_mp[i] -= hh;
            e_mp[j] += hh;
            e_mm[i] -= hh;
            e_mm[j] -= hh;
            let fd = (e.strain_energy(&e_pp) - e.strain_energy(&e_pm) - e.strain_energy(&e_mp)
                + e.strain_energy(&e_mm))
                / (4.0 * hh * hh);
            let kij = k[(i, j)];
            assert!(
                (fd - kij).abs() <= 1e-6 * max_abs(&k),
                "K({i},{j}) = {kij} vs {fd}"
            );
        }
    }
}

/// A 2×2 patch with a displaced interior node (classic patch test), in an arbitrary plane.
/// The eight boundary nodes get the exact field; the interior node must reproduce it.
fn patch_test(field: impl Fn(f64, f64) -> [f64; 6]) {
    let coords = [
        [0.0, 0.0],
        [5.0, 0.0],
        [10.0, 0.0],
        [0.0, 5.0],
        [6.1, 4.2],
        [10.0, 5.0],
        [0.0, 10.0],
        [5.0, 10.0],
        [10.0, 10.0],
    ];
    let elems = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]];
    let (e1, e2) = rotated_axes();
    let n = cross(e1, e2);
    let to3 = |c: [f64; 2]| [0, 1, 2].map(|k| c[0] * e1[k] + c[1] * e2[k]);
    // Assemble the 54×54 global stiffness.
    let mut k = Mat::<f64>::zeros(54, 54);
    for el in elems {
        let s = Shell4::new(el.map(|i| to3(coords[i])), 0.3, STEEL).unwrap();
        let ke = s.stiffness();
        for a in 0..4 {
            for b in 0..4 {
                for p in 0..6 {
                    for q in 0..6 {
                        k[(6 * el[a] + p, 6 * el[b] + q)] += ke[(6 * a + p, 6 * b + q)];
                    }
                }
            }
        }
    }
    // Field in local plane components [u1, u2, w, θ1, θ2, θ3] → global vector components.
    let global = |c: [f64; 2]| {
        let f = field(c[0], c[1]);
        let t = [0, 1, 2].map(|k| f[0] * e1[k] + f[1] * e2[k] + f[2] * n[k]);
        let r = [0, 1, 2].map(|k| f[3] * e1[k] + f[4] * e2[k] + f[5] * n[k]);
        [t[0], t[1], t[2], r[0], r[1], r[2]]
    };
    let mut u = vec![0.0; 54];
    for (i, c) in coords.iter().enumerate() {
        if i != 4 {
            u[6 * i..6 * i + 6].copy_from_slice(&global(*c));
        }
    }
    // Solve K_ii u_i = −K_ib u_b for the interior node (dof 24..30).
    let kii = Mat::from_fn(6, 6, |a, b| k[(24 + a, 24 + b)]);
    let mut rhs = Mat::from_fn(6, 1, |a, _| {
        -(0..54)
            .filter(|j| !(24..30).contains(j))
            .map(|j| k[(24 + a, j)] * u[j])
            .sum::<f64>()
    });
    let llt = kii.llt(Side::Lower).unwrap();
    use faer::linalg::solvers::Solve;
    llt.solve_in_place(rhs.as_mut());
    let exact = global(coords[4]);
    for a in 0..6 {
        let scale = exact.iter().map(|v| v.abs()).fold(0.0, f64::max);
        assert!(
            (rhs[(a, 0)] - exact[a]).abs() <= 1e-9 * scale,
            "interior dof {a}: {} vs exact {}",
            rhs[(a, 0)],
            exact[a]
        );
    }
}

#[test]
fn membrane_patch_test_reproduces_linear_fields() {
    // u1 = 1e-3 (2 + 3x − y), u2 = 1e-3 (−1 + x + 4y); in-plane rotation ω = ½(u2,x − u1,y).
    patch_test(|x, y| {
        let u1 = 1e-3 * (2.0 + 3.0 * x - y);
        let u2 = 1e-3 * (-1.0 + x + 4.0 * y);
        let omega = 0.5 * 1e-3 * (1.0 - (-1.0));
        [u1, u2, 0.0, 0.0, 0.0, omega]
    });
}

#[test]
fn bending_patch_test_reproduces_constant_curvature() {
    // Kirchhoff field w = ½(a x² + b y² + c x y), fibre rotations β = −∇w, θ1 = −β_y, θ2 = β_x.
    let (a, b, c) = (2e-4, -1e-4, 3e-4);
    patch_test(move |x, y| {
        let w = 0.5 * (a * x * x + b * y * y + c * x * y);
        let wx = a * x + 0.5 * c * y;
        let wy = b * y + 0.5 * c * x;
        let (beta_x, beta_y) = (-wx, -wy);
        [0.0, 0.0, w, -beta_y, beta_x, 0.0]
    });
}

/// A clamped strip x ∈ [0, length], z ∈ [0, width] in the x–z plane, the "master" node at the
/// free end's middle (no tie slaves, so it is an ordinary node numbered last).
fn strip(length: f64, width: f64, t: f64, nx: usize, nz: usize, material: Material) -> Mesh {
    assert!(nz % 2 == 0);
    let mut nodes = Vec::new();
    for i in 0..=nx {
        for k in 0..=nz {
            nodes.push([
                length * i as f64 / nx as f64,
                0.0,
                width * k as f64 / nz as f64,
            ]);
        }
    }
    let id = |i: usize, k: usize| i * (nz + 1) + k;
    let mut shells = Vec::new();
    for i in 0..nx {
        for k in 0..nz {
            shells.push(ShellElem {
                nodes: [id(i, k), id(i + 1, k), id(i + 1, k + 1), id(i, k + 1)],
                thickness: t,
                sheet: 0,
            });
        }
    }
    Mesh {
        nodes,
        sheets: vec![SheetGrid {
            name: "strip".into(),
            first_node: 0,
            elements: [nx, nz],
        }],
        shells,
        beams: vec![],
        welds: vec![],
        masses: Vec::new(),
        clamped: (0..=nz).map(|k| id(0, k)).collect(),
        tie: RigidTie {
            master: id(nx, nz / 2),
            slaves: vec![],
        },
        pairs: vec![],
        excluded: vec![],
        material,
        warnings: Vec::new(),
    }
}

/// Mode by dominant motion: returns the frequency of the first mode dominated by the given
/// master DOF (index into the master's 6 DOF).
fn first_mode_with(s: &Structure, count: usize, dof: usize) -> f64 {
    let modes = lowest_modes(&s.stiffness, &s.mass, count).unwrap();
    let m = s.dof_map.master;
    for c in 0..count {
        let col = modes.shapes.col_as_slice(c);
        let amp: Vec<f64> = m.iter().map(|&k| col[k].abs()).collect();
        // Compare translations with translations and rotations with rotations.
        let group = if dof < 3 { 0..3 } else { 3..6 };
        let best = group
            .clone()
            .max_by(|&a, &b| amp[a].total_cmp(&amp[b]))
            .unwrap();
        let others_small = (0..6)
            .filter(|&d| d != dof && (d < 3) == (dof < 3))
            .all(|d| amp[d] < 0.1 * amp[dof]);
        if best == dof && others_small && amp[dof] > 0.0 {
            return modes.frequencies_hz[c];
        }
    }
    panic!("no mode dominated by master dof {dof} among the first {count}");
}

#[test]
fn cantilever_strip_bending_frequencies_converge_to_beam_theory() {
    // ν = 0: plate and beam theory agree (no anticlastic ambiguity).
    let (l, b, t): (f64, f64, f64) = (100.0, 10.0, 0.5);
    let m = STEEL_NU0;
    let ei = m.youngs_modulus * b * t.powi(3) / 12.0;
    let ei_lateral = m.youngs_modulus * t * b.powi(3) / 12.0;
    let rho_a = m.density * b * t;
    let beta1: f64 = 1.875_104_068_711_961;
    let f_theory =
        |ei: f64| beta1 * beta1 / (2.0 * std::f64::consts::PI * l * l) * (ei / rho_a).sqrt();
    let mut errors = Vec::new();
    for nx in [10, 20, 40] {
        let s = assemble_structure(&strip(l, b, t, nx, 2, m)).unwrap();
        let f_out = first_mode_with(&s, 8, 1); // tip uy: out-of-plane bending
        let f_in = first_mode_with(&s, 8, 2); // tip uz: in-plane (lateral) bending
        let e_out = f_out / f_theory(ei) - 1.0;
        let e_in = f_in / f_theory(ei_lateral) - 1.0;
        errors.push((nx, e_out, e_in));
    }
    eprintln!("(nx, out-of-plane error, in-plane error): {errors:?}");
    let (_, e_out, e_in) = errors[errors.len() - 1];
    assert!(e_out.abs() < 0.01, "out-of-plane bending error {e_out}");
    assert!(e_in.abs() < 0.01, "in-plane bending error {e_in}");
    assert!(
        errors[0].1.abs() >= e_out.abs() - 1e-4,
        "refinement must not worsen"
    );
}

#[test]
fn cantilever_strip_torsion_frequency_converges_to_saint_venant_theory() {
    // Long and thin, so the clamp's warping restraint (decay length b/sqrt(48 G/E) ≈ 2.3 mm,
    // ~0.2 % here) and the free-edge boundary layer of width ~t/sqrt(10) (0.6 % of J, not
    // resolved by the mesh) both stay well below the 1 % tolerance.
    let (l, b, t): (f64, f64, f64) = (500.0, 10.0, 0.1);
    let m = STEEL;
    let g = m.shear_modulus();
    // Saint-Venant torsion constant of a thin rectangle (Roark): J = b t³/3 (1 − 0.630 t/b).
    let j = b * t.powi(3) / 3.0 * (1.0 - 0.630 * t / b);
    let ip = m.density * (b * t.powi(3) + t * b.powi(3)) / 12.0;
    let f_theory = 1.0 / (4.0 * l) * (g * j / ip).sqrt();
    let mut errors = Vec::new();
    for (nx, nz) in [(25, 2), (50, 4), (100, 4)] {
        let s = assemble_structure(&strip(l, b, t, nx, nz, m)).unwrap();
        let f = first_mode_with(&s, 12, 3); // tip rx: torsion about x
        errors.push((nx, f / f_theory - 1.0));
    }
    eprintln!("torsion (nx, error): {errors:?}");
    // Measured (DKMQ bending, 2026-11-26): +0.64, +0.69, +0.76 %: converged on the coarsest
    // mesh to within 0.1 %, the last step (x only) resolving the clamp's warping restraint
    // (which the theory leaves out). MITC4 approached from further away.
    let last = errors.last().unwrap().1;
    assert!(errors.iter().all(|e| e.1.abs() < 0.01), "{errors:?}");
    assert!(
        (errors[1].1 - last).abs() < 2e-3,
        "not converged: {errors:?}"
    );
}

#[test]
fn thin_limit_is_free_of_shear_locking() {
    // Tip deflection under an end load, normalised by Euler–Bernoulli, must stay ≈ 1 as t → 0.
    let (l, b): (f64, f64) = (100.0, 10.0);
    let m = STEEL_NU0;
    for t in [1.0f64, 0.1, 0.01, 0.001] {
        let mesh = strip(l, b, t, 10, 2, m);
        let s = assemble_structure(&mesh).unwrap();
        let mut f = vec![0.0; s.dof_map.n];
        // End load P split over the three tip nodes (1/4, 1/2, 1/4): consistent for a line load.
        let p = 1e-3 * t.powi(3);
        let nx = 10;
        for (k, w) in [(0, 0.25), (1, 0.5), (2, 0.25)] {
            let node = nx * 3 + k;
            let dof = s.dof_map.nodes[node][1].as_free().unwrap();
            f[dof] += p * w;
        }
        let u = solve_spd(&s.stiffness, &[f]).unwrap().remove(0);
        let tip = u[s.dof_map.master[1]];
        let ei = m.youngs_modulus * b * t.powi(3) / 12.0;
        let ratio = tip / (p * l.powi(3) / (3.0 * ei));
        eprintln!("t = {t}: deflection / Euler–Bernoulli = {ratio}");
        // Measured (DKMQ, 2026-11-26): 1 + 6.0e-5 (t = 1: the shear deformation), 1 + 6e-7,
        // 1 + 6e-9, 1 + 7e-11 — each edge's deflection is the beam's exact cubic; MITC4's
        // bilinear rotations gave 0.9975 on these 10 elements.
        assert!(
            (ratio - 1.0).abs() < 2e-4,
            "t = {t}: ratio {ratio} (locking if ≪ 1)"
        );
    }
}

#[test]
fn lanczos_matches_dense_eigensolver() {
    let s = assemble_structure(&strip(100.0, 10.0, 0.5, 20, 2, STEEL)).unwrap();
    let a = lowest_modes(&s.stiffness, &s.mass, 12).unwrap();
    let d = dense_modes(&s.stiffness, &s.mass, 12).unwrap();
    for i in 0..12 {
        let rel = (a.eigenvalues[i] - d.eigenvalues[i]).abs() / d.eigenvalues[i];
        assert!(
            rel < 1e-9,
            "mode {i}: {} vs {}",
            a.eigenvalues[i],
            d.eigenvalues[i]
        );
    }
    // M-orthonormality of the Lanczos modes.
    let n = s.stiffness.n;
    let mut mphi = vec![0.0; n];
    for i in 0..12 {
        s.mass.mul_vec(a.shapes.col_as_slice(i), &mut mphi);
        for j in 0..12 {
            let v: f64 = a
                .shapes
                .col_as_slice(j)
                .iter()
                .zip(&mphi)
                .map(|(x, y)| x * y)
                .sum();
            let expected = if i == j { 1.0 } else { 0.0 };
            assert!((v - expected).abs() < 1e-9, "phi_{j}' M phi_{i} = {v}");
        }
    }
}

/// Global DOF of four nodes from a deflection field `u_y = f(x, z)` with Kirchhoff rotations
/// `θ_z = ∂f/∂x`, `θ_x = −∂f/∂z` (the sheets' plane y = const).
fn kirchhoff_dofs(nodes: &[[f64; 3]; 4], f: &dyn Fn(f64, f64) -> [f64; 3]) -> [f64; 24] {
    let mut u = [0.0; 24];
    for (a, p) in nodes.iter().enumerate() {
        let [w, wx, wz] = f(p[0], p[2]);
        u[6 * a + 1] = w;
        u[6 * a + 3] = -wz;
        u[6 * a + 5] = wx;
    }
    u
}

#[test]
fn edge_deflection_reproduces_the_acm_space_on_a_thin_rectangle() {
    // Thin (φ ≈ 1e-8): the blended edge cubics are the 12-term ACM interpolation, exact for
    // every monomial of its space; the bilinear one is not (except for the bilinear ones).
    let nodes = [
        [1.0, 2.0, 1.0],
        [9.0, 2.0, 1.0],
        [9.0, 2.0, 6.0],
        [1.0, 2.0, 6.0],
    ];
    let sh = Shell4::new(nodes, 1e-3, STEEL).unwrap();
    let sign = sh.normal()[1];
    type Field = fn(f64, f64) -> [f64; 3];
    let fields: [Field; 6] = [
        |x, _| [x * x * x, 3.0 * x * x, 0.0],
        |x, z| [x * x * z, 2.0 * x * z, x * x],
        |x, z| [x * x * x * z, 3.0 * x * x * z, x * x * x],
        |_, z| [z * z * z, 0.0, 3.0 * z * z],
        |x, z| [x * z * z * z, z * z * z, 3.0 * x * z * z],
        |x, z| [0.3 + 0.2 * x - 0.1 * z + x * z, 0.2 + z, -0.1 + x],
    ];
    for (k, f) in fields.iter().enumerate() {
        let u = kirchhoff_dofs(&nodes, f);
        let mut bilinear_error = 0.0f64;
        for (r, s) in [(0.3, -0.6), (-0.8, 0.1), (0.0, 0.0), (0.95, 0.7)] {
            let (n, _) = sh.shape(r, s);
            let x: f64 = (0..4).map(|a| n[a] * nodes[a][0]).sum();
            let z: f64 = (0..4).map(|a| n[a] * nodes[a][2]).sum();
            let exact = sign * f(x, z)[0];
            let dot = |row: [f64; 24]| (0..24).map(|d| row[d] * u[d]).sum::<f64>();
            let got = dot(sh.deflection_row(r, s, true));
            assert!(
                (got - exact).abs() < 1e-6 * (1.0 + exact.abs()),
                "field {k} at ({r}, {s}): {got} vs {exact}"
            );
            bilinear_error =
                bilinear_error.max((dot(sh.deflection_row(r, s, false)) - exact).abs());
        }
        if k < 5 {
            assert!(
                bilinear_error > 1e-2,
                "field {k}: bilinear error {bilinear_error}"
            );
        } else {
            assert!(
                bilinear_error < 1e-9,
                "field {k}: bilinear error {bilinear_error}"
            );
        }
    }
}

#[test]
fn edge_deflection_is_the_nodal_deflection_at_the_corners_and_rigid_exact() {
    // At a corner both interpolations give the node's own w; a rigid motion (translation and
    // rotation) is reproduced anywhere on a distorted element, thin or thick.
    for t in [0.5, 5.0] {
        let nodes = skewed_nodes();
        let sh = Shell4::new(nodes, t, STEEL).unwrap();
        let n = sh.normal();
        for (a, (r, s)) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .into_iter()
            .enumerate()
        {
            for edges in [false, true] {
                let row = sh.deflection_row(r, s, edges);
                for d in 0..24 {
                    let want = if d / 6 == a && d % 6 < 3 {
                        n[d % 6]
                    } else {
                        0.0
                    };
                    assert!(
                        (row[d] - want).abs() < 1e-12,
                        "corner {a} dof {d}: {}",
                        row[d]
                    );
                }
            }
        }
        let (c, theta) = ([0.2, -0.4, 0.7], [0.01, -0.03, 0.02]);
        let mut u = [0.0; 24];
        for (a, p) in nodes.iter().enumerate() {
            let disp = [0, 1, 2].map(|k| c[k]);
            let rot = cross(theta, *p);
            for k in 0..3 {
                u[6 * a + k] = disp[k] + rot[k];
                u[6 * a + 3 + k] = theta[k];
            }
        }
        for (r, s) in [(0.3, -0.6), (-0.8, 0.1), (0.0, 0.0)] {
            let (shape, _) = sh.shape(r, s);
            let x = [0, 1, 2].map(|k| (0..4).map(|a| shape[a] * nodes[a][k]).sum::<f64>());
            let rot = cross(theta, x);
            let exact: f64 = (0..3).map(|k| n[k] * (c[k] + rot[k])).sum();
            let got: f64 = (0..24)
                .map(|d| sh.deflection_row(r, s, true)[d] * u[d])
                .sum();
            assert!(
                (got - exact).abs() < 1e-12,
                "t {t} at ({r}, {s}): {got} vs {exact}"
            );
        }
    }
}
