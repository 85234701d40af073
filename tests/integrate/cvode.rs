//! The safe CVODE wrapper (`jointrom::integrate::Cvode`) against exact solutions: accuracy for
//! every iteration type, Newton iteration counts of the problem's solver vs CVODE's dense one,
//! stiffness, callback panics and NaN, events, options, statistics and create/drop cycles.

use std::f64::consts::PI;

use jointrom::integrate::problem::{
    CallbackError, Iteration, Method, NewtonLinear, OdeOptions, OdeProblem, OdeStats, Stop,
};
use jointrom::integrate::Cvode;
use jointrom::Error;

/// ω of the test oscillator, rad/s (100 Hz).
pub(super) const OMEGA: f64 = 2.0 * PI * 100.0;

/// `y' = A y` with a dense `A`, and its own Newton solver: Gaussian elimination with partial
/// pivoting of `I − γ A`, factored in `newton_setup` with the γ given there (like CVODE's dense
/// solver, which factors at setup and reuses the factors until the next setup).
#[derive(Clone)]
pub(super) struct Linear {
    n: usize,
    /// Row-major n × n.
    a: Vec<f64>,
    /// Row-major LU factors of I − γ_setup A, and the pivot rows.
    lu: Vec<f64>,
    piv: Vec<usize>,
    /// Solve with the γ passed to `newton_solve` (refactor) instead of the setup's.
    use_current_gamma: bool,
    setup_gamma: f64,
    pub(super) rhs_calls: u64,
    pub(super) setups: u64,
    pub(super) solves: u64,
}

impl Linear {
    pub(super) fn new(n: usize, a: Vec<f64>) -> Self {
        assert_eq!(a.len(), n * n);
        Linear {
            n,
            a,
            lu: vec![0.0; n * n],
            piv: vec![0; n],
            use_current_gamma: false,
            setup_gamma: f64::NAN,
            rhs_calls: 0,
            setups: 0,
            solves: 0,
        }
    }

    /// Undamped oscillator x'' = −ω² x as y = [x, v].
    pub(super) fn oscillator() -> Self {
        Linear::new(2, vec![0.0, 1.0, -OMEGA * OMEGA, 0.0])
    }

    fn factor(&mut self, gamma: f64) -> Result<(), CallbackError> {
        newton_matrix_lu(self.n, &self.a, gamma, &mut self.lu, &mut self.piv)
    }
}

/// Writes the LU factors (partial pivoting, row-major, pivot rows in `piv`) of `I − γ A` into
/// `lu`; a recoverable error if singular.
fn newton_matrix_lu(
    n: usize,
    a: &[f64],
    gamma: f64,
    lu: &mut [f64],
    piv: &mut [usize],
) -> Result<(), CallbackError> {
    for i in 0..n {
        for j in 0..n {
            lu[i * n + j] = f64::from(u8::from(i == j)) - gamma * a[i * n + j];
        }
    }
    for k in 0..n {
        let p = (k..n)
            .max_by(|&i, &j| lu[i * n + k].abs().total_cmp(&lu[j * n + k].abs()))
            .unwrap();
        if lu[p * n + k] == 0.0 {
            return Err(CallbackError::Recoverable("singular Newton matrix".into()));
        }
        piv[k] = p;
        if p != k {
            for j in 0..n {
                lu.swap(k * n + j, p * n + j);
            }
        }
        for i in k + 1..n {
            let l = lu[i * n + k] / lu[k * n + k];
            lu[i * n + k] = l;
            for j in k + 1..n {
                lu[i * n + j] -= l * lu[k * n + j];
            }
        }
    }
    Ok(())
}

/// `z ← (LU)⁻¹ z` with the factors of [`newton_matrix_lu`].
fn lu_solve(n: usize, lu: &[f64], piv: &[usize], z: &mut [f64]) {
    for k in 0..n {
        z.swap(k, piv[k]);
        for i in k + 1..n {
            z[i] -= lu[i * n + k] * z[k];
        }
    }
    for k in (0..n).rev() {
        for j in k + 1..n {
            z[k] -= lu[k * n + j] * z[j];
        }
        z[k] /= lu[k * n + k];
    }
}

impl OdeProblem for Linear {
    fn dim(&self) -> usize {
        self.n
    }

    fn rhs(&mut self, _t: f64, y: &[f64], ydot: &mut [f64]) -> Result<(), CallbackError> {
        self.rhs_calls += 1;
        for (out, row) in ydot.iter_mut().zip(self.a.chunks_exact(self.n)) {
            *out = row.iter().zip(y).map(|(a, y)| a * y).sum();
        }
        Ok(())
    }

    fn has_newton_solver(&self) -> bool {
        true
    }

    fn newton_setup(
        &mut self,
        _t: f64,
        _y: &[f64],
        _fy: &[f64],
        _jok: bool,
        gamma: f64,
    ) -> Result<bool, CallbackError> {
        self.setups += 1;
        self.setup_gamma = gamma;
        self.factor(gamma)?;
        // A is constant: the "Jacobian" is always current.
        Ok(true)
    }

    fn newton_solve(
        &mut self,
        _t: f64,
        _y: &[f64],
        r: &[f64],
        z: &mut [f64],
        gamma: f64,
    ) -> Result<(), CallbackError> {
        self.solves += 1;
        if self.use_current_gamma && gamma != self.setup_gamma {
            self.setup_gamma = gamma;
            self.factor(gamma)?;
        }
        z.copy_from_slice(r);
        lu_solve(self.n, &self.lu, &self.piv, z);
        Ok(())
    }
}

fn bdf(iteration: Iteration) -> OdeOptions {
    OdeOptions {
        iteration,
        ..OdeOptions::default()
    }
}

const DENSE: Iteration = Iteration::Newton {
    linear: NewtonLinear::DenseDq,
};
const PROBLEM: Iteration = Iteration::Newton {
    linear: NewtonLinear::Problem,
};
const FUNCTIONAL: Iteration = Iteration::Functional { anderson: 0 };

/// Runs the oscillator to t = 0.05 s (5 periods) from x = 1, v = 0 and returns the error
/// max(|x − cos ωt|, |v/ω + sin ωt|) and the statistics.
fn oscillator_run(problem: Linear, opts: &OdeOptions) -> (f64, OdeStats, Linear) {
    let mut cvode = Cvode::new(problem, 0.0, &[1.0, 0.0], opts).unwrap();
    let tend = 0.05;
    assert_eq!(cvode.solve_to(tend).unwrap(), Stop::Reached(tend));
    assert_eq!(cvode.t(), tend);
    let y = cvode.y();
    let err = (y[0] - (OMEGA * tend).cos())
        .abs()
        .max((y[1] / OMEGA + (OMEGA * tend).sin()).abs());
    let stats = cvode.stats();
    (err, stats, cvode.into_problem())
}

/// Each iteration type reaches the exact solution to within a tolerance consistent with the
/// paper's rtol = 1e-8, atol = 1e-6 (global error over 5 periods: a few hundred × rtol).
#[test]
fn oscillator_matches_exact_solution_for_every_iteration() {
    let cases = [
        ("BDF Newton DenseDq", bdf(DENSE)),
        ("BDF Newton Problem", bdf(PROBLEM)),
        ("BDF functional", bdf(FUNCTIONAL)),
        (
            "BDF functional Anderson(3)",
            bdf(Iteration::Functional { anderson: 3 }),
        ),
        (
            "Adams functional",
            OdeOptions {
                method: Method::Adams,
                max_order: 12,
                ..bdf(FUNCTIONAL)
            },
        ),
        (
            "Adams Newton DenseDq",
            OdeOptions {
                method: Method::Adams,
                max_order: 12,
                ..bdf(DENSE)
            },
        ),
    ];
    for (name, opts) in cases {
        let (err, s, p) = oscillator_run(Linear::oscillator(), &opts);
        println!(
            "{name}: error {err:.2e}, steps {}, rhs {} (+{} DQ), nonlinear iters {}, conv fails {}, \
             err test fails {}, setups {}, jac/prec evals {}, lin solves {}, order {}, h {:.2e}",
            s.steps,
            s.rhs_evals,
            s.rhs_evals_jac,
            s.nonlinear_iterations,
            s.nonlinear_conv_failures,
            s.error_test_failures,
            s.linear_setups,
            s.jacobian_evals,
            s.linear_solves,
            s.last_order,
            s.last_step
        );
        assert!(err < 1e-5, "{name}: error {err:e} too large for rtol 1e-8");
        assert!(err > 0.0);
        // Every rhs call the problem saw is counted by CVODE, as integrator or DQ evaluation.
        assert_eq!(p.rhs_calls, s.rhs_evals + s.rhs_evals_jac, "{name}");
        check_stats_consistent(name, &s, &opts, &p);
    }
}

/// Relations every run's statistics must satisfy.
fn check_stats_consistent(name: &str, s: &OdeStats, opts: &OdeOptions, p: &Linear) {
    assert!(s.steps > 10, "{name}: {s:?}");
    assert!(s.rhs_evals >= s.steps, "{name}: {s:?}");
    assert!(s.nonlinear_iterations >= s.steps, "{name}: {s:?}");
    assert!(s.last_order >= 1 && s.last_step > 0.0, "{name}: {s:?}");
    assert_eq!(s.root_evals, 0);
    assert_eq!(s.roots_found, 0);
    match opts.iteration {
        Iteration::Functional { .. } => {
            assert_eq!(s.linear_setups, 0, "{name}");
            assert_eq!(s.jacobian_evals, 0, "{name}");
            assert_eq!(s.linear_solves, 0, "{name}");
            assert_eq!(s.rhs_evals_jac, 0, "{name}");
        }
        Iteration::Newton {
            linear: NewtonLinear::DenseDq,
        } => {
            assert!(s.linear_setups >= 1 && s.linear_setups <= s.steps + s.nonlinear_conv_failures);
            assert!(s.jacobian_evals >= 1 && s.jacobian_evals <= s.linear_setups);
            // A dense DQ Jacobian costs n rhs evaluations.
            assert_eq!(s.rhs_evals_jac, 2 * s.jacobian_evals, "{name}");
            assert_eq!(s.linear_solves, s.nonlinear_iterations, "{name}");
        }
        Iteration::Newton {
            linear: NewtonLinear::Problem,
        } => {
            assert_eq!(s.linear_setups, p.setups, "{name}");
            assert_eq!(s.jacobian_evals, p.setups, "{name}: jcur is always true");
            assert_eq!(s.linear_solves, p.solves, "{name}");
            assert_eq!(s.rhs_evals_jac, 0, "{name}");
            // One problem solve per Newton iteration, bar a negligible-residual skip.
            assert!(s.linear_solves <= s.nonlinear_iterations, "{name}: {s:?}");
            assert!(
                s.linear_solves * 10 >= s.nonlinear_iterations * 9,
                "{name}: {s:?}"
            );
        }
    }
}

/// The problem's solver behind CVODE's iterative interface gives Newton iteration counts
/// within 10 % of CVODE's dense direct solver (the point of declaring it iterative with a
/// preconditioner, NOTES.md), both with a setup-time factorization and with one at the
/// current γ.
#[test]
fn problem_solver_newton_iterations_match_dense() {
    let (_, dense, _) = oscillator_run(Linear::oscillator(), &bdf(DENSE));
    for current in [false, true] {
        let mut p = Linear::oscillator();
        p.use_current_gamma = current;
        let (_, own, _) = oscillator_run(p, &bdf(PROBLEM));
        let ratio = own.nonlinear_iterations as f64 / dense.nonlinear_iterations as f64;
        println!(
            "current γ {current}: Newton iterations problem {} / dense {} = {ratio:.3}; steps {} / {}; \
             setups {} / {}",
            own.nonlinear_iterations,
            dense.nonlinear_iterations,
            own.steps,
            dense.steps,
            own.linear_setups,
            dense.linear_setups
        );
        assert!((ratio - 1.0).abs() < 0.10, "ratio {ratio}");
        let steps = own.steps as f64 / dense.steps as f64;
        assert!((steps - 1.0).abs() < 0.10, "steps ratio {steps}");
    }
}

/// Van der Pol `x'' = μ (1 − x²) x' − x` as y = [x, v], stiff for large μ, with its own
/// Newton solver: analytic Jacobian, reused when CVODE allows (`jok`), `I − γJ` refactored at
/// every setup.
struct VanDerPol {
    mu: f64,
    jac: [f64; 4],
    lu: [f64; 4],
    piv: [usize; 2],
    jac_evals: u64,
    setups: u64,
}

impl VanDerPol {
    fn new(mu: f64) -> Self {
        VanDerPol {
            mu,
            jac: [0.0; 4],
            lu: [0.0; 4],
            piv: [0; 2],
            jac_evals: 0,
            setups: 0,
        }
    }
}

impl OdeProblem for VanDerPol {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], ydot: &mut [f64]) -> Result<(), CallbackError> {
        ydot[0] = y[1];
        ydot[1] = self.mu * (1.0 - y[0] * y[0]) * y[1] - y[0];
        Ok(())
    }
    fn has_newton_solver(&self) -> bool {
        true
    }
    fn newton_setup(
        &mut self,
        _t: f64,
        y: &[f64],
        _fy: &[f64],
        jok: bool,
        gamma: f64,
    ) -> Result<bool, CallbackError> {
        self.setups += 1;
        let recompute = !jok;
        if recompute {
            self.jac_evals += 1;
            self.jac = [
                0.0,
                1.0,
                -2.0 * self.mu * y[0] * y[1] - 1.0,
                self.mu * (1.0 - y[0] * y[0]),
            ];
        }
        newton_matrix_lu(2, &self.jac, gamma, &mut self.lu, &mut self.piv)?;
        Ok(recompute)
    }
    fn newton_solve(
        &mut self,
        _t: f64,
        _y: &[f64],
        r: &[f64],
        z: &mut [f64],
        _gamma: f64,
    ) -> Result<(), CallbackError> {
        z.copy_from_slice(r);
        lu_solve(2, &self.lu, &self.piv, z);
        Ok(())
    }
}

/// On a nonlinear stiff problem (Van der Pol, μ = 50, two relaxation cycles) the problem's
/// solver with Jacobian reuse (`jok`) gives step and Newton iteration counts within 10 % of
/// CVODE's dense solver with difference-quotient Jacobians, and the same solution.
#[test]
fn problem_solver_with_jacobian_reuse_matches_dense_on_van_der_pol() {
    let opts = |iteration| OdeOptions {
        rtol: 1e-6,
        atol: 1e-8,
        ..bdf(iteration)
    };
    let tend = 150.0;
    let mut dense = Cvode::new(VanDerPol::new(50.0), 0.0, &[2.0, 0.0], &opts(DENSE)).unwrap();
    dense.solve_to(tend).unwrap();
    let mut own = Cvode::new(VanDerPol::new(50.0), 0.0, &[2.0, 0.0], &opts(PROBLEM)).unwrap();
    own.solve_to(tend).unwrap();
    let (d, o) = (dense.stats(), own.stats());
    println!("Van der Pol dense:   {d:?}");
    println!("Van der Pol problem: {o:?}");
    let p = own.problem();
    assert_eq!(o.jacobian_evals, p.jac_evals);
    assert_eq!(o.linear_setups, p.setups);
    assert!(p.jac_evals < p.setups, "the Jacobian was never reused");
    for (what, a, b) in [
        ("steps", o.steps, d.steps),
        (
            "Newton iterations",
            o.nonlinear_iterations,
            d.nonlinear_iterations,
        ),
    ] {
        let ratio = a as f64 / b as f64;
        assert!(
            (ratio - 1.0).abs() < 0.10,
            "{what}: problem {a} / dense {b} = {ratio}"
        );
    }
    let (yd, yo) = (dense.y(), own.y());
    assert!((yd[0] - yo[0]).abs() < 1e-3, "{yd:?} vs {yo:?}");
}

/// y' = λ (y − cos t) − sin t, y(0) = 1: exact y = cos t; stiff for λ = −1e6.
struct Stiff {
    lambda: f64,
}

impl OdeProblem for Stiff {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, y: &[f64], ydot: &mut [f64]) -> Result<(), CallbackError> {
        ydot[0] = self.lambda * (y[0] - t.cos()) - t.sin();
        Ok(())
    }
}

/// With λ = −1e6 functional iteration's step is bounded by |hλ| ≲ 1 (≥ 1e5 steps for 0.1 s),
/// so with a budget of 20 000 steps it fails with CV_TOO_MUCH_WORK; Newton needs a few
/// hundred steps and is accurate.
#[test]
fn stiff_problem_defeats_functional_iteration() {
    let tend = 0.1;
    let newton = OdeOptions {
        max_steps: 20_000,
        ..bdf(DENSE)
    };
    let mut cv = Cvode::new(Stiff { lambda: -1e6 }, 0.0, &[1.0], &newton).unwrap();
    assert_eq!(cv.solve_to(tend).unwrap(), Stop::Reached(tend));
    assert!((cv.y()[0] - tend.cos()).abs() < 1e-6, "y = {}", cv.y()[0]);
    let sn = cv.stats();
    println!("stiff Newton: {sn:?}");
    assert!(sn.steps < 2_000, "{sn:?}");

    let functional = OdeOptions {
        max_steps: 20_000,
        ..bdf(FUNCTIONAL)
    };
    let mut cv = Cvode::new(Stiff { lambda: -1e6 }, 0.0, &[1.0], &functional).unwrap();
    let err = cv.solve_to(tend).unwrap_err();
    let sf = cv.stats();
    println!("stiff functional: {err}; {sf:?}");
    match &err {
        Error::Sundials {
            function,
            flag,
            time,
        } => {
            assert_eq!(*function, "CVode");
            assert!(flag.to_string().starts_with("CV_TOO_MUCH_WORK"), "{flag}");
            assert!(*time > 0.0 && *time < tend, "{time}");
            assert_eq!(*time, cv.t());
        }
        other => panic!("unexpected error {other:?}"),
    }
    assert!(err.to_string().contains("CV_TOO_MUCH_WORK"));
    assert_eq!(sf.steps, 20_000);
    // The state reached is still accurate: the work, not the accuracy, is the failure.
    assert!((cv.y()[0] - cv.t().cos()).abs() < 1e-6);
    // Mildly stiff (λ = −1e3): functional iteration succeeds but needs many more steps.
    let run = |opts: &OdeOptions| {
        let mut cv = Cvode::new(Stiff { lambda: -1e3 }, 0.0, &[1.0], opts).unwrap();
        cv.solve_to(1.0).unwrap();
        assert!((cv.y()[0] - 1f64.cos()).abs() < 1e-6);
        cv.stats().steps
    };
    let (steps_n, steps_f) = (run(&newton), run(&functional));
    println!("λ = −1e3: Newton {steps_n} steps, functional {steps_f} steps");
    assert!(steps_f > 3 * steps_n, "{steps_f} vs {steps_n}");
}

/// What a test problem does wrong, and when.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Fault {
    /// Panics in the named callback once t > 1e-3.
    PanicRhs,
    PanicNewtonSolve,
    PanicRoots,
    /// NaN in the very first rhs call.
    NanFirstCall,
    /// NaN in the first rhs call with t > 1e-3 only.
    NanOnceLater,
    /// NaN in every rhs call after the 20th.
    NanAlwaysLater,
    /// NaN in every rhs call with t > 1e-3: a wall the steps pile up against.
    NanWall,
    /// Fatal error from the rhs once t > 1e-3.
    FatalRhs,
}

pub(super) struct Faulty {
    inner: Linear,
    fault: Fault,
    calls: u64,
    fired: bool,
}

impl Faulty {
    pub(super) fn new(fault: Fault) -> Self {
        Faulty {
            inner: Linear::oscillator(),
            fault,
            calls: 0,
            fired: false,
        }
    }
}

impl OdeProblem for Faulty {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], ydot: &mut [f64]) -> Result<(), CallbackError> {
        self.calls += 1;
        self.inner.rhs(t, y, ydot)?;
        let late = t > 1e-3;
        match self.fault {
            Fault::PanicRhs if late => panic!("boom in rhs at t = {t}"),
            Fault::NanFirstCall if self.calls == 1 => ydot[1] = f64::NAN,
            Fault::NanOnceLater if late && !self.fired => {
                self.fired = true;
                ydot[0] = f64::INFINITY;
            }
            Fault::NanAlwaysLater if self.calls > 20 => ydot[1] = f64::NAN,
            Fault::NanWall if late => ydot[1] = f64::NAN,
            Fault::FatalRhs if late => {
                return Err(CallbackError::Fatal(format!("model broke at t = {t}")))
            }
            _ => {}
        }
        Ok(())
    }
    fn num_roots(&self) -> usize {
        usize::from(self.fault == Fault::PanicRoots)
    }
    fn roots(&mut self, t: f64, y: &[f64], g: &mut [f64]) -> Result<(), CallbackError> {
        if self.fault == Fault::PanicRoots && t > 1e-3 {
            panic!("boom in roots");
        }
        g[0] = y[0] + 2.0;
        Ok(())
    }
    fn has_newton_solver(&self) -> bool {
        true
    }
    fn newton_setup(
        &mut self,
        t: f64,
        y: &[f64],
        fy: &[f64],
        jok: bool,
        gamma: f64,
    ) -> Result<bool, CallbackError> {
        self.inner.newton_setup(t, y, fy, jok, gamma)
    }
    fn newton_solve(
        &mut self,
        t: f64,
        y: &[f64],
        r: &[f64],
        z: &mut [f64],
        gamma: f64,
    ) -> Result<(), CallbackError> {
        if self.fault == Fault::PanicNewtonSolve && t > 1e-3 {
            panic!("boom in newton_solve");
        }
        self.inner.newton_solve(t, y, r, z, gamma)
    }
}

/// A panic in any callback becomes an `Error::Callback` carrying the panic text; the process
/// continues, the integrator refuses further work until `reinit`, and then works again.
#[test]
fn callback_panics_become_errors() {
    for (fault, callback, text) in [
        (Fault::PanicRhs, "rhs", "boom in rhs"),
        (
            Fault::PanicNewtonSolve,
            "newton_solve",
            "boom in newton_solve",
        ),
        (Fault::PanicRoots, "roots", "boom in roots"),
    ] {
        let mut cv = Cvode::new(Faulty::new(fault), 0.0, &[1.0, 0.0], &bdf(PROBLEM)).unwrap();
        let err = cv.solve_to(0.01).unwrap_err();
        println!("{err}");
        match &err {
            Error::Callback {
                callback: c,
                message,
                time,
                outcome: flag,
            } => {
                assert_eq!(*c, callback);
                assert!(
                    message.contains("panicked") && message.contains(text),
                    "{message}"
                );
                assert!(*time > 1e-3 && *time < 0.01, "{time}");
                assert!(flag.to_string().starts_with("CVode returned CV_"), "{flag}");
            }
            other => panic!("unexpected {other:?}"),
        }
        assert!(cv.t() <= 1e-3 + 1e-4, "t = {}", cv.t());
        // Poisoned: refuses to run.
        let again = cv.solve_to(0.01).unwrap_err();
        assert!(again.to_string().contains("panicked earlier"), "{again}");
        // After reinit (and repairing the problem) it integrates again.
        cv.problem_mut().fault = Fault::NanFirstCall;
        cv.problem_mut().calls = 10;
        let (t, y) = (cv.t(), cv.y().to_vec());
        let exact = [(OMEGA * t).cos(), -OMEGA * (OMEGA * t).sin()];
        assert!(
            (y[0] - exact[0]).abs() < 1e-5,
            "{callback}: y({t}) = {y:?}, exact {exact:?}"
        );
        cv.reinit(t, &y).unwrap();
        assert_eq!(cv.solve_to(0.01).unwrap(), Stop::Reached(0.01));
        let e = (cv.y()[0] - (OMEGA * 0.01).cos()).abs();
        assert!(e < 1e-5, "{callback}: error {e} after reinit at t = {t}");
    }
}

/// NaN/Inf in the rhs: once during a step → CVODE retries with a smaller step and the result
/// is accurate; persistently → an error naming the rhs and the non-finite entry; on the very
/// first call (at t0, where CVODE cannot shrink a step) → CV_FIRST_RHSFUNC_ERR. A fatal error
/// stops at once with its message.
#[test]
fn nan_in_rhs_is_recoverable_once_and_named_when_persistent() {
    for iteration in [DENSE, PROBLEM, FUNCTIONAL] {
        let opts = bdf(iteration);
        let mut cv = Cvode::new(Faulty::new(Fault::NanOnceLater), 0.0, &[1.0, 0.0], &opts).unwrap();
        assert_eq!(cv.solve_to(0.01).unwrap(), Stop::Reached(0.01));
        assert!(cv.problem().fired);
        let err = (cv.y()[0] - (OMEGA * 0.01).cos()).abs();
        assert!(err < 1e-5, "{iteration:?}: error {err}");

        let mut cv =
            Cvode::new(Faulty::new(Fault::NanAlwaysLater), 0.0, &[1.0, 0.0], &opts).unwrap();
        let err = cv.solve_to(0.01).unwrap_err();
        println!("{iteration:?}: {err}");
        match &err {
            Error::Callback {
                callback,
                message,
                outcome: flag,
                ..
            } => {
                assert_eq!(*callback, "rhs");
                assert!(message.contains("ydot[1] = NaN is not finite"), "{message}");
                assert!(flag.to_string().contains("CV_"), "{flag}");
            }
            other => panic!("unexpected {other:?}"),
        }
        assert!(cv.t() < 1e-3, "t = {}", cv.t());

        // NaN beyond a fixed time: the steps pile up against it until the step budget is
        // spent; the error still names the rhs and its message.
        let opts = OdeOptions {
            max_steps: 2_000,
            ..opts
        };
        let mut cv = Cvode::new(Faulty::new(Fault::NanWall), 0.0, &[1.0, 0.0], &opts).unwrap();
        let err = cv.solve_to(0.01).unwrap_err();
        println!("{iteration:?} wall: {err}");
        assert!(
            matches!(&err, Error::Callback { callback: "rhs", message, .. } if message.contains("not finite")),
            "{err}"
        );
        assert!(cv.t() > 9e-4 && cv.t() <= 1e-3, "t = {}", cv.t());
    }

    let mut cv = Cvode::new(
        Faulty::new(Fault::NanFirstCall),
        0.0,
        &[1.0, 0.0],
        &bdf(DENSE),
    )
    .unwrap();
    let err = cv.solve_to(0.01).unwrap_err();
    println!("{err}");
    assert!(
        matches!(&err, Error::Callback { callback: "rhs", outcome: flag, .. } if flag.to_string().contains("CV_FIRST_RHSFUNC_ERR")),
        "{err}"
    );

    let mut cv = Cvode::new(Faulty::new(Fault::FatalRhs), 0.0, &[1.0, 0.0], &bdf(DENSE)).unwrap();
    let err = cv.solve_to(0.01).unwrap_err();
    assert!(
        matches!(&err, Error::Callback { callback: "rhs", message, outcome: flag, .. }
            if message.starts_with("model broke") && flag.to_string().contains("CV_RHSFUNC_FAIL")),
        "{err}"
    );
}

/// A ball dropped from h0 = 10 mm... well, m: h' = v, v' = −g; event g(h) = h.
struct Ball {
    g: f64,
}

impl OdeProblem for Ball {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], ydot: &mut [f64]) -> Result<(), CallbackError> {
        ydot[0] = y[1];
        ydot[1] = -self.g;
        Ok(())
    }
    fn num_roots(&self) -> usize {
        2
    }
    fn roots(&mut self, t: f64, y: &[f64], g: &mut [f64]) -> Result<(), CallbackError> {
        g[0] = y[0];
        // A sign change at a known time, rising.
        g[1] = t - 0.3;
        Ok(())
    }
}

/// Events are located to 1e-8 s: the clock event at 0.3 s, the impact at √(2h0/g), and after
/// a bounce with restitution e (reinit) the second impact at t1 + 2 e v1 / g.
#[test]
fn root_finding_locates_events() {
    let (g, h0, e) = (9.81, 10.0, 0.8);
    for iteration in [DENSE, FUNCTIONAL] {
        let opts = OdeOptions {
            rtol: 1e-10,
            atol: 1e-10,
            ..bdf(iteration)
        };
        let mut cv = Cvode::new(Ball { g }, 0.0, &[h0, 0.0], &opts).unwrap();
        match cv.solve_to(5.0).unwrap() {
            Stop::Root { t, roots } => {
                assert!((t - 0.3).abs() < 1e-8, "{t}");
                assert_eq!(roots, vec![0, 1]);
            }
            other => panic!("{other:?}"),
        }
        let t1 = (2.0 * h0 / g).sqrt();
        match cv.solve_to(5.0).unwrap() {
            Stop::Root { t, roots } => {
                assert!((t - t1).abs() < 1e-8, "{t} vs {t1}");
                assert_eq!(roots, vec![-1, 0]);
                assert!(cv.y()[0].abs() < 1e-8);
            }
            other => panic!("{other:?}"),
        }
        let v1 = cv.y()[1];
        assert!((v1 + g * t1).abs() < 1e-6);
        cv.reinit(t1, &[0.0, -e * v1]).unwrap();
        let t2 = t1 + 2.0 * e * (-v1) / g;
        match cv.solve_to(5.0).unwrap() {
            Stop::Root { t, roots } => {
                assert!((t - t2).abs() < 1e-8, "{t} vs {t2}");
                assert_eq!(roots, vec![-1, 0]);
            }
            other => panic!("{other:?}"),
        }
        let s = cv.stats();
        println!("{iteration:?}: {s:?}");
        assert_eq!(s.roots_found, 3);
        assert!(s.root_evals > s.steps, "{s:?}");
        // Only falling impacts: the rising h after the bounce at t1 is ignored by direction.
        cv.set_root_direction(&[-1, 0]).unwrap();
        assert!(cv.set_root_direction(&[1]).is_err());
    }
}

/// Stability-limit detection is accepted for BDF (statistics report its order reductions) and
/// refused for Adams with an error naming the field; the run stays accurate.
#[test]
fn stab_lim_det_option() {
    let opts = OdeOptions {
        stab_lim_det: true,
        ..bdf(DENSE)
    };
    let (err, s, _) = oscillator_run(Linear::oscillator(), &opts);
    let (_, s0, _) = oscillator_run(Linear::oscillator(), &bdf(DENSE));
    println!(
        "stab lim det: error {err:.2e}, steps {} (without: {}), order reductions {}",
        s.steps, s0.steps, s.stab_lim_order_reductions
    );
    assert!(err < 1e-5);
    assert_eq!(s0.stab_lim_order_reductions, 0);
    let adams = OdeOptions {
        method: Method::Adams,
        stab_lim_det: true,
        ..bdf(DENSE)
    };
    let e = Cvode::new(Linear::oscillator(), 0.0, &[1.0, 0.0], &adams)
        .err()
        .unwrap();
    assert!(e.to_string().contains("stab_lim_det"), "{e}");
}

/// Bad options and states are errors naming the field, never panics.
#[test]
fn invalid_input_is_named() {
    let y0 = [1.0, 0.0];
    let cases: Vec<(OdeOptions, &str)> = vec![
        (
            OdeOptions {
                rtol: -1.0,
                ..bdf(DENSE)
            },
            "rtol",
        ),
        (
            OdeOptions {
                atol: f64::NAN,
                ..bdf(DENSE)
            },
            "atol",
        ),
        (
            OdeOptions {
                max_order: 6,
                ..bdf(DENSE)
            },
            "max_order",
        ),
        (
            OdeOptions {
                max_order: 0,
                ..bdf(DENSE)
            },
            "max_order",
        ),
        (
            OdeOptions {
                max_steps: 0,
                ..bdf(DENSE)
            },
            "max_steps",
        ),
        (
            OdeOptions {
                max_step: -1.0,
                ..bdf(DENSE)
            },
            "max_step",
        ),
        (
            OdeOptions {
                init_step: f64::INFINITY,
                ..bdf(DENSE)
            },
            "init_step",
        ),
    ];
    for (opts, field) in cases {
        let e = Cvode::new(Linear::oscillator(), 0.0, &y0, &opts)
            .err()
            .unwrap();
        assert!(e.to_string().contains(field), "{e}");
    }
    let e = Cvode::new(Stiff { lambda: -1.0 }, 0.0, &[1.0], &bdf(PROBLEM))
        .err()
        .unwrap();
    assert!(e.to_string().contains("has_newton_solver"), "{e}");
    let e = Cvode::new(Linear::oscillator(), 0.0, &[1.0], &bdf(DENSE))
        .err()
        .unwrap();
    assert!(e.to_string().contains("y has 1 entries"), "{e}");
    let e = Cvode::new(Linear::oscillator(), 0.0, &[1.0, f64::NAN], &bdf(DENSE))
        .err()
        .unwrap();
    assert!(e.to_string().contains("y[1]"), "{e}");
    let mut cv = Cvode::new(Linear::oscillator(), 0.0, &y0, &bdf(DENSE)).unwrap();
    assert!(cv.solve_to(f64::NAN).is_err());
    assert!(cv.reinit(0.0, &[1.0]).is_err());
    // CVODE's own refusals come back as Error::Sundials with the flag and CVODE's message.
    cv.solve_to(0.01).unwrap();
    let e = cv.set_stop_time(0.001).unwrap_err();
    println!("{e}");
    assert!(
        matches!(&e, Error::Sundials { function: "CVodeSetStopTime", flag, .. } if flag.to_string().starts_with("CV_ILL_INPUT")),
        "{e}"
    );
}

/// The stop time is hit exactly, then forgotten; `reinit` keeps statistics cumulative.
#[test]
fn stop_time_and_reinit() {
    let mut cv = Cvode::new(Linear::oscillator(), 0.0, &[1.0, 0.0], &bdf(DENSE)).unwrap();
    cv.set_stop_time(0.0123).unwrap();
    assert_eq!(cv.solve_to(0.05).unwrap(), Stop::Reached(0.0123));
    assert!((cv.y()[0] - (OMEGA * 0.0123).cos()).abs() < 1e-5);
    assert_eq!(cv.solve_to(0.02).unwrap(), Stop::Reached(0.02));
    let before = cv.stats();
    let (t, y) = (cv.t(), cv.y().to_vec());
    cv.reinit(t, &y).unwrap();
    let at_reinit = cv.stats();
    assert_eq!(at_reinit.steps, before.steps);
    assert_eq!(at_reinit.jacobian_evals, before.jacobian_evals);
    assert_eq!(at_reinit.nonlinear_iterations, before.nonlinear_iterations);
    assert_eq!(cv.solve_to(0.05).unwrap(), Stop::Reached(0.05));
    let after = cv.stats();
    assert!(after.steps > before.steps && after.jacobian_evals > before.jacobian_evals);
    assert!((cv.y()[0] - (OMEGA * 0.05).cos()).abs() < 1e-5);
    // The problem saw exactly the evaluations counted, across the restart.
    let p = cv.into_problem();
    assert_eq!(p.rhs_calls, after.rhs_evals + after.rhs_evals_jac);
}

/// Many create / integrate / drop cycles of every configuration (the valgrind target: no
/// definite leaks, no invalid accesses), including `into_problem` and failed constructions.
#[test]
fn create_drop_cycles() {
    let configs = [
        bdf(DENSE),
        bdf(PROBLEM),
        bdf(FUNCTIONAL),
        bdf(Iteration::Functional { anderson: 2 }),
    ];
    let mut total_steps = 0;
    for cycle in 0..50 {
        for opts in &configs {
            let mut cv = Cvode::new(Linear::oscillator(), 0.0, &[1.0, 0.0], opts).unwrap();
            cv.solve_to(1e-3).unwrap();
            total_steps += cv.stats().steps;
            if cycle % 2 == 0 {
                let p = cv.into_problem();
                assert!(p.rhs_calls > 0);
            }
        }
        let mut ball = Cvode::new(Ball { g: 9.81 }, 0.0, &[1.0, 0.0], &bdf(DENSE)).unwrap();
        assert!(matches!(ball.solve_to(1.0).unwrap(), Stop::Root { .. }));
        // A failure mid-run, then drop.
        let mut cv = Cvode::new(
            Faulty::new(Fault::PanicRhs),
            0.0,
            &[1.0, 0.0],
            &bdf(PROBLEM),
        )
        .unwrap();
        assert!(cv.solve_to(0.01).is_err());
        // A failed construction (after the context exists).
        assert!(Cvode::new(Stiff { lambda: -1.0 }, 0.0, &[1.0], &bdf(PROBLEM)).is_err());
    }
    assert!(total_steps > 0);
}

/// Two undamped modes, 1 Hz (amplitude 1) and 50 Hz (amplitude 1e-6, near atol): BDF at order
/// 5 is unstable for the fast mode's ±iω when it is not resolved, and stability-limit detection
/// reacts with order reductions (measured at the paper's tolerances: 143 reductions, 8570 steps
/// vs 6105 without — it costs steps here, it does not save them); both runs stay accurate.
#[test]
fn stab_lim_det_reduces_order_on_weak_fast_undamped_mode() {
    let (w1, w2) = (2.0 * PI, 2.0 * PI * 50.0);
    #[rustfmt::skip]
    let a = vec![
        0.0, 1.0, 0.0, 0.0,
        -w1 * w1, 0.0, 0.0, 0.0,
        0.0, 0.0, 0.0, 1.0,
        0.0, 0.0, -w2 * w2, 0.0,
    ];
    let tend = 10.0;
    let mut reductions = [0; 2];
    for (k, stab_lim_det) in [false, true].into_iter().enumerate() {
        let opts = OdeOptions {
            stab_lim_det,
            ..bdf(DENSE)
        };
        let mut cv = Cvode::new(
            Linear::new(4, a.clone()),
            0.0,
            &[1.0, 0.0, 1e-6, 0.0],
            &opts,
        )
        .unwrap();
        assert_eq!(cv.solve_to(tend).unwrap(), Stop::Reached(tend));
        let err = (cv.y()[0] - (w1 * tend).cos()).abs();
        let s = cv.stats();
        println!(
            "stab_lim_det {stab_lim_det}: error {err:.2e}, steps {}, error test failures {}, \
             order reductions {}",
            s.steps, s.error_test_failures, s.stab_lim_order_reductions
        );
        assert!(err < 1e-5, "{err}");
        assert!(cv.y()[2].abs() < 1e-5, "fast mode grew: {}", cv.y()[2]);
        reductions[k] = s.stab_lim_order_reductions;
    }
    assert_eq!(reductions[0], 0);
    assert!(reductions[1] > 0, "no order reduction detected");
}
