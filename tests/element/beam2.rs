//! Invariants and closed-form checks of the `Beam2` Timoshenko beam (spot weld element).

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use jointrom::element::{Beam2, ElementError, Material};
use jointrom::Error;
use rand::rngs::StdRng;
use std::f64::consts::PI;

use crate::common;
use crate::common::v3::{add, cross, dot, norm, scale, sub};

const STEEL: Material = Material::STEEL;

/// Spot weld: 0.5 mm long, 5 mm thick (Φ ≈ 220).
const WELD: (f64, f64) = (0.5, 5.0);
/// Slender beam: 200 mm long, 5 mm thick (Φ ≈ 1.4e-3).
const SLENDER: (f64, f64) = (200.0, 5.0);
/// In between: 10 mm long, 5 mm thick (Φ ≈ 0.55).
const MEDIUM: (f64, f64) = (10.0, 5.0);

/// Random 3-vectors from a seeded generator (the same on every run).
trait RandomV3 {
    /// Each component uniform in [-1, 1).
    fn vec3(&mut self) -> [f64; 3];
    /// A random unit vector.
    fn unit(&mut self) -> [f64; 3];
}

impl RandomV3 for StdRng {
    fn vec3(&mut self) -> [f64; 3] {
        [
            common::uniform(self),
            common::uniform(self),
            common::uniform(self),
        ]
    }

    fn unit(&mut self) -> [f64; 3] {
        loop {
            let v = self.vec3();
            let n = norm(v);
            if n > 0.1 && n <= 1.0 {
                return scale(v, 1.0 / n);
            }
        }
    }
}

/// A unit vector perpendicular to `e`, otherwise arbitrary.
fn perpendicular(e: [f64; 3], rng: &mut StdRng) -> [f64; 3] {
    loop {
        let v = rng.unit();
        let p = sub(v, scale(e, dot(v, e)));
        if norm(p) > 0.3 {
            return scale(p, 1.0 / norm(p));
        }
    }
}

/// Directions to test: the global axes (both signs), diagonals and random ones.
fn directions(rng: &mut StdRng) -> Vec<[f64; 3]> {
    let s = 1.0 / 3f64.sqrt();
    let mut d = vec![
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, -1.0],
        [s, s, s],
        [-s, s, -s],
        [1e-9, 1.0, 0.0], // nearly along an axis: frame choice must stay robust
    ];
    for _ in 0..8 {
        d.push(rng.unit());
    }
    d.into_iter().map(|v| scale(v, 1.0 / norm(v))).collect()
}

/// A beam of the given (length, diameter) along `e` from an arbitrary start point.
fn beam_along(e: [f64; 3], (length, diameter): (f64, f64), rng: &mut StdRng) -> (Beam2, [f64; 3]) {
    let a = scale(rng.vec3(), 100.0);
    let b = add(a, scale(e, length));
    (Beam2::circular(a, b, diameter, STEEL).unwrap(), a)
}

fn frobenius(m: &Mat<f64>) -> f64 {
    m.norm_l2()
}

fn mat_vec(m: &Mat<f64>, v: &[f64; 12]) -> [f64; 12] {
    let mut out = [0.0; 12];
    for (i, o) in out.iter_mut().enumerate() {
        *o = (0..12).map(|j| m[(i, j)] * v[j]).sum();
    }
    out
}

fn quad(m: &Mat<f64>, v: &[f64; 12]) -> f64 {
    let mv = mat_vec(m, v);
    (0..12).map(|i| v[i] * mv[i]).sum()
}

/// Rigid motion u = t + θ × (x − p), rotation DOF = θ, at nodes `a`, `b`.
fn rigid(t: [f64; 3], theta: [f64; 3], p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> [f64; 12] {
    let mut r = [0.0; 12];
    for (n, x) in [a, b].into_iter().enumerate() {
        let u = add(t, cross(theta, sub(x, p)));
        r[6 * n..6 * n + 3].copy_from_slice(&u);
        r[6 * n + 3..6 * n + 6].copy_from_slice(&theta);
    }
    r
}

fn section(d: f64) -> (f64, f64, f64, f64) {
    let nu = STEEL.poisson_ratio;
    let area = PI * d * d / 4.0;
    let i = PI * d.powi(4) / 64.0;
    let kappa = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu);
    (area, i, 2.0 * i, kappa)
}

fn assert_close(what: &str, computed: f64, expected: f64, rtol: f64) {
    let err = (computed - expected).abs() / expected.abs();
    assert!(
        err <= rtol,
        "{what}: computed {computed:e}, expected {expected:e}, relative error {err:e} > {rtol:e}"
    );
}

#[test]
fn stiffness_and_mass_are_symmetric() {
    let mut rng = common::rng(1);
    for e in directions(&mut rng) {
        for shape in [WELD, MEDIUM, SLENDER] {
            let (beam, _) = beam_along(e, shape, &mut rng);
            for (name, m) in [("K", beam.stiffness()), ("M", beam.mass())] {
                let scale = frobenius(&m);
                for i in 0..12 {
                    for j in 0..12 {
                        assert!(
                            (m[(i, j)] - m[(j, i)]).abs() <= 1e-15 * scale,
                            "{name} not symmetric at ({i}, {j}) for e = {e:?}, shape {shape:?}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn mass_is_positive_definite() {
    let mut rng = common::rng(2);
    for e in directions(&mut rng) {
        for shape in [WELD, MEDIUM, SLENDER] {
            let (beam, _) = beam_along(e, shape, &mut rng);
            let m = beam.mass();
            assert!(
                m.llt(Side::Lower).is_ok(),
                "M not positive definite, e = {e:?}"
            );
            let eig = m.self_adjoint_eigenvalues(Side::Lower).unwrap();
            assert!(eig[0] > 0.0, "M eigenvalues {eig:?}, e = {e:?}");
        }
    }
}

#[test]
fn six_rigid_body_modes_give_zero_force() {
    let mut rng = common::rng(3);
    for e in directions(&mut rng) {
        for shape in [WELD, MEDIUM, SLENDER] {
            let (beam, a) = beam_along(e, shape, &mut rng);
            let b = add(a, scale(e, shape.0));
            let k = beam.stiffness();
            let knorm = frobenius(&k);
            let p = scale(rng.vec3(), 50.0); // arbitrary centre of rotation
            let zero = [0.0; 3];
            let mut modes = Vec::new();
            for i in 0..3 {
                let mut unit = [0.0; 3];
                unit[i] = 1.0;
                modes.push(rigid(unit, zero, p, a, b));
                modes.push(rigid(zero, unit, p, a, b));
            }
            // And an arbitrary combination.
            modes.push(rigid(rng.vec3(), rng.vec3(), p, a, b));
            for r in &modes {
                let f = mat_vec(&k, r);
                let rel = common::norm(&f) / (knorm * common::norm(r));
                assert!(
                    rel <= 1e-9,
                    "|K r| / (|K| |r|) = {rel:e} for rigid mode {r:?}, e = {e:?}, shape {shape:?}"
                );
            }
        }
    }
}

#[test]
fn stiffness_has_rank_six() {
    let mut rng = common::rng(4);
    for e in directions(&mut rng) {
        for shape in [WELD, MEDIUM, SLENDER] {
            let (beam, _) = beam_along(e, shape, &mut rng);
            let eig = beam
                .stiffness()
                .self_adjoint_eigenvalues(Side::Lower)
                .unwrap();
            let max = eig[11];
            for (i, &l) in eig.iter().enumerate() {
                if i < 6 {
                    assert!(
                        l.abs() <= 1e-12 * max,
                        "eigenvalue {i} = {l:e} should be ~0 (max {max:e}), e = {e:?}, shape {shape:?}"
                    );
                } else {
                    // For these shapes the elastic eigenvalues are ≥ 0.2·max (mixed N/mm and
                    // N·mm/rad units); round-off puts the rigid ones at ~1e-16·max.
                    assert!(
                        l >= 1e-3 * max,
                        "eigenvalue {i} = {l:e} should be clearly > 0 (max {max:e}), e = {e:?}, shape {shape:?}"
                    );
                }
            }
        }
    }
}

/// Tip displacement and rotation of a cantilever clamped at node a, loaded at node b by force
/// `f` and moment `m` (global axes).
fn cantilever(beam: &Beam2, f: [f64; 3], m: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let k = beam.stiffness();
    let kbb = Mat::<f64>::from_fn(6, 6, |i, j| k[(6 + i, 6 + j)]);
    let rhs = Mat::<f64>::from_fn(6, 1, |i, _| if i < 3 { f[i] } else { m[i - 3] });
    let x = kbb
        .llt(Side::Lower)
        .expect("K_bb positive definite")
        .solve(&rhs);
    (
        [x[(0, 0)], x[(1, 0)], x[(2, 0)]],
        [x[(3, 0)], x[(4, 0)], x[(5, 0)]],
    )
}

fn assert_vec_close(what: &str, computed: [f64; 3], expected: [f64; 3], scale: f64, rtol: f64) {
    let err = norm(sub(computed, expected)) / scale;
    assert!(
        err <= rtol,
        "{what}: computed {computed:?}, expected {expected:?}, relative error {err:e} > {rtol:e}"
    );
}

#[test]
fn cantilever_matches_timoshenko_closed_form() {
    let mut rng = common::rng(5);
    let ee = STEEL.youngs_modulus;
    let g = STEEL.shear_modulus();
    let rtol = 1e-10;
    for e in directions(&mut rng) {
        for shape in [WELD, MEDIUM, SLENDER] {
            let (l, d) = shape;
            let (area, i, j, kappa) = section(d);
            let (beam, _) = beam_along(e, shape, &mut rng);
            let n = perpendicular(e, &mut rng);
            let zero = [0.0; 3];
            let ctx = format!("e = {e:?}, n = {n:?}, L = {l}, d = {d}");

            // Transverse tip force P along n: bending + shear deflection, rotation about e × n.
            let p = 100.0;
            let delta = p * l.powi(3) / (3.0 * ee * i) + p * l / (kappa * g * area);
            let phi = p * l * l / (2.0 * ee * i);
            let (u, th) = cantilever(&beam, scale(n, p), zero);
            assert_close(&format!("tip deflection, {ctx}"), dot(u, n), delta, rtol);
            assert_vec_close(
                &format!("tip force: u, {ctx}"),
                u,
                scale(n, delta),
                delta,
                rtol,
            );
            assert_vec_close(
                &format!("tip force: rotation, {ctx}"),
                th,
                scale(cross(e, n), phi),
                phi,
                rtol,
            );

            // Tip moment M about n (pure bending, no shear): rotation ML/(EI) about n,
            // deflection ML²/(2EI) along n × e.
            let mm = 1000.0;
            let rot = mm * l / (ee * i);
            let defl = mm * l * l / (2.0 * ee * i);
            let (u, th) = cantilever(&beam, zero, scale(n, mm));
            assert_vec_close(
                &format!("tip moment: rotation, {ctx}"),
                th,
                scale(n, rot),
                rot,
                rtol,
            );
            assert_vec_close(
                &format!("tip moment: deflection, {ctx}"),
                u,
                scale(cross(n, e), defl),
                defl,
                rtol,
            );

            // Axial force: EA/L.
            let (u, th) = cantilever(&beam, scale(e, p), zero);
            let stretch = p * l / (ee * area);
            assert_close(
                &format!("axial stiffness, {ctx}"),
                p / dot(u, e),
                ee * area / l,
                rtol,
            );
            assert_vec_close(
                &format!("axial: u, {ctx}"),
                u,
                scale(e, stretch),
                stretch,
                rtol,
            );
            assert!(
                norm(th) <= rtol * stretch / l,
                "axial load rotates the tip, {ctx}"
            );

            // Torque: GJ/L.
            let (u, th) = cantilever(&beam, zero, scale(e, mm));
            let twist = mm * l / (g * j);
            assert_close(
                &format!("torsional stiffness, {ctx}"),
                mm / dot(th, e),
                g * j / l,
                rtol,
            );
            assert_vec_close(
                &format!("torsion: rotation, {ctx}"),
                th,
                scale(e, twist),
                twist,
                rtol,
            );
            assert!(norm(u) <= rtol * twist * l, "torque moves the tip, {ctx}");
        }
    }
}

#[test]
fn weld_is_shear_dominated() {
    // Φ = 12EI/(κGAL²) ≈ 220 for the weld, i.e. the transverse flexibility is
    // Φ/(Φ + 4) ≈ 98 % shear.
    let (l, d) = WELD;
    let (area, i, _, kappa) = section(d);
    let phi = 12.0 * STEEL.youngs_modulus * i / (kappa * STEEL.shear_modulus() * area * l * l);
    assert!((150.0..300.0).contains(&phi), "Φ = {phi}");
    let beam = Beam2::circular([0.0; 3], [0.0, 0.0, l], d, STEEL).unwrap();
    let (u, _) = cantilever(&beam, [1.0, 0.0, 0.0], [0.0; 3]);
    let shear = l / (kappa * STEEL.shear_modulus() * area);
    assert_close(
        "weld tip deflection is mostly shear",
        u[0],
        shear * (1.0 + 4.0 / phi),
        1e-10,
    );
}

#[test]
fn lumped_mass_totals() {
    let mut rng = common::rng(6);
    let rho = STEEL.density;
    for e in directions(&mut rng) {
        for shape in [WELD, MEDIUM, SLENDER] {
            let (l, d) = shape;
            let (area, i, j, _) = section(d);
            let (beam, a) = beam_along(e, shape, &mut rng);
            let b = add(a, scale(e, l));
            let m = beam.mass();
            let zero = [0.0; 3];
            let ctx = format!("e = {e:?}, L = {l}, d = {d}");
            let total = rho * area * l;
            for k in 0..3 {
                let mut t = [0.0; 3];
                t[k] = 1.0;
                let r = rigid(t, zero, zero, a, b);
                assert_close(
                    &format!("translation {k}, {ctx}"),
                    quad(&m, &r),
                    total,
                    1e-12,
                );
            }
            let t = rng.unit();
            assert_close(
                &format!("translation {t:?}, {ctx}"),
                quad(&m, &rigid(t, zero, zero, a, b)),
                total,
                1e-12,
            );
            // Rotation about the beam axis: exact polar inertia ρJL.
            let r = rigid(zero, e, a, a, b);
            assert_close(
                &format!("axial spin, {ctx}"),
                quad(&m, &r),
                rho * j * l,
                1e-12,
            );
            // Rotation about a transverse axis through the midpoint: lumped gives
            // ρ(IL + AL³/4) (exact: ρ(IL + AL³/12)), as documented.
            let n = perpendicular(e, &mut rng);
            let mid = add(a, scale(e, l / 2.0));
            let r = rigid(zero, n, mid, a, b);
            let expected = rho * (i * l + area * l.powi(3) / 4.0);
            assert_close(
                &format!("transverse spin, {ctx}"),
                quad(&m, &r),
                expected,
                1e-12,
            );
        }
    }
}

/// Global matrices must rotate with the beam, whatever local y', z' the element picks.
#[test]
fn matrices_are_objective() {
    let mut rng = common::rng(7);
    for shape in [WELD, MEDIUM] {
        for _ in 0..20 {
            let e = rng.unit();
            let (beam, a) = beam_along(e, shape, &mut rng);
            let b = add(a, scale(e, shape.0));
            // Random rotation Q (Gram-Schmidt on random vectors, det +1).
            let q0 = rng.unit();
            let q1 = perpendicular(q0, &mut rng);
            let q2 = cross(q0, q1);
            let q = [q0, q1, q2]; // rows: Q maps x to (q0·x, q1·x, q2·x)
            let apply = |x: [f64; 3]| [dot(q[0], x), dot(q[1], x), dot(q[2], x)];
            let rotated = Beam2::circular(apply(a), apply(b), shape.1, STEEL).unwrap();
            for (name, m1, m2) in [
                ("K", beam.stiffness(), rotated.stiffness()),
                ("M", beam.mass(), rotated.mass()),
            ] {
                // m2 must equal T m1 Tᵀ with T = diag(Q, Q, Q, Q).
                let t =
                    Mat::<f64>::from_fn(
                        12,
                        12,
                        |i, j| {
                            if i / 3 == j / 3 {
                                q[i % 3][j % 3]
                            } else {
                                0.0
                            }
                        },
                    );
                let expected = &t * &m1 * t.transpose();
                let err = frobenius(&(&m2 - &expected)) / frobenius(&m1);
                assert!(
                    err <= 1e-12,
                    "{name} not objective: error {err:e}, e = {e:?}"
                );
            }
        }
    }
}

/// Swapping the nodes gives the same element with the node blocks swapped.
#[test]
fn node_order_does_not_matter() {
    let mut rng = common::rng(8);
    for _ in 0..10 {
        let e = rng.unit();
        let (beam, a) = beam_along(e, MEDIUM, &mut rng);
        let b = add(a, scale(e, MEDIUM.0));
        let swapped = Beam2::circular(b, a, MEDIUM.1, STEEL).unwrap();
        for (name, m1, m2) in [
            ("K", beam.stiffness(), swapped.stiffness()),
            ("M", beam.mass(), swapped.mass()),
        ] {
            let p = |i: usize| (i + 6) % 12;
            let err = (0..12)
                .flat_map(|i| (0..12).map(move |j| (i, j)))
                .map(|(i, j)| (m1[(i, j)] - m2[(p(i), p(j))]).abs())
                .fold(0.0, f64::max);
            assert!(err <= 1e-12 * frobenius(&m1), "{name}: {err:e}");
        }
    }
}

fn element_error(result: Result<Beam2, Error>) -> (ElementError, String) {
    match result {
        Err(Error::Element(e)) => {
            let msg = e.to_string();
            (e, msg)
        }
        Err(other) => panic!("expected Error::Element, got {other:?}"),
        Ok(_) => panic!("expected an error, got a beam"),
    }
}

#[test]
fn bad_input_is_an_element_error() {
    let a = [1.0, 2.0, 3.0];
    let b = [1.0, 2.0, 3.5];
    for end in [a, [f64::NAN, 2.0, 3.0], [f64::INFINITY, 2.0, 3.0]] {
        let (e, msg) = element_error(Beam2::circular(a, end, 5.0, STEEL));
        assert!(matches!(e, ElementError::Beam2Length { .. }), "{e:?}");
        assert!(msg.contains("length"), "{msg}");
    }
    for d in [0.0, -5.0, f64::NAN, f64::INFINITY] {
        let (e, msg) = element_error(Beam2::circular(a, b, d, STEEL));
        assert!(matches!(e, ElementError::Beam2Diameter { .. }), "{e:?}");
        assert!(msg.contains("diameter"), "d = {d}: {msg}");
    }
    for material in [
        Material {
            youngs_modulus: -1.0,
            ..STEEL
        },
        Material {
            poisson_ratio: 0.5,
            ..STEEL
        },
        Material {
            poisson_ratio: f64::NAN,
            ..STEEL
        },
        Material {
            density: 0.0,
            ..STEEL
        },
    ] {
        let (e, msg) = element_error(Beam2::circular(a, b, 5.0, material));
        assert!(
            matches!(&e, ElementError::Beam2Material { source, .. }
                if matches!(**source, ElementError::Material { .. })),
            "{e:?}"
        );
        assert!(msg.contains("material"), "{material:?}: {msg}");
    }
    // Finite but absurd sizes whose matrices overflow.
    for (a, b, d) in [(a, b, 1e100), ([0.0; 3], [1e-310, 0.0, 0.0], 5.0)] {
        let (e, msg) = element_error(Beam2::circular(a, b, d, STEEL));
        assert!(
            matches!(e, ElementError::Beam2NotRepresentable { .. }),
            "{e:?}"
        );
        assert!(msg.contains("not representable"), "{msg}");
    }
    // Very short is fine as long as it is representable.
    let k = Beam2::circular([0.0; 3], [1e-120, 0.0, 0.0], 5.0, STEEL)
        .unwrap()
        .stiffness();
    assert!((0..12).all(|i| (0..12).all(|j| k[(i, j)].is_finite())));
}
