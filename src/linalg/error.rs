//! The linear-algebra error: a failed factorization, solve or eigen decomposition, a numerical
//! check that failed (a non-finite result, a backward error over its bound, an iteration that
//! did not converge), or a request the matrices cannot serve. faer's own error is kept as the
//! source where faer gives one. The layers above report their numerical failures with it too
//! (contact iterations, bases), naming the matrix or quantity in `what`.

use std::error::Error as StdError;

use faer::linalg::evd::EvdError;
use faer::linalg::svd::SvdError;

/// faer's error of a failed factorization (dense or sparse Cholesky, LU, symbolic analysis, a
/// rank update); messages show its `Debug` text.
pub type FaerError = Box<dyn StdError + Send + Sync + 'static>;

/// A failed factorization, solve or eigen decomposition, or a failed numerical check.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LinalgError {
    // ---- requests the matrices cannot serve (shown as `invalid request: ...`) ----
    /// `count` modes asked of a model with `dofs` DOF (need 1 ≤ count ≤ dofs).
    #[error("cannot compute {count} modes of a model with {dofs} DOF (need 1 ≤ count ≤ {dofs})")]
    ModeCount { count: usize, dofs: usize },
    /// `operation` needs two matrices of the same sparsity pattern.
    #[error("{operation} needs two matrices with the same sparsity pattern")]
    PatternMismatch { operation: &'static str },

    // ---- factorizations ----
    /// faer's Cholesky found `what` (named with its size and context) not positive definite;
    /// `hint` says what that usually means (may be empty).
    #[error("{what} is not positive definite{hint}: {source:?}")]
    NotPositiveDefinite {
        what: String,
        hint: &'static str,
        #[source]
        source: FaerError,
    },
    /// A check found `what` not positive definite (no faer error); `hint` says how (may be
    /// empty).
    #[error("{what} is not positive definite{hint}")]
    Indefinite { what: String, hint: &'static str },
    /// faer's Cholesky of a reduced model's `matrix` (`r` × `r`) failed.
    #[error("{matrix} ({r}×{r}) not positive definite: {source:?}")]
    ReducedNotPositiveDefinite {
        matrix: &'static str,
        r: usize,
        #[source]
        source: FaerError,
    },
    /// The symbolic analysis of `what` (e.g. `Cholesky (40×40)`, `LU of K − Ω²M`) failed.
    #[error("symbolic {what}: {source:?}")]
    Symbolic {
        what: String,
        #[source]
        source: FaerError,
    },
    /// A numeric factorization or rank update (`step`, e.g. `Cholesky downdate removing 2 of 9
    /// indices`, `LU of K − Ω²M for base vector 3 (...)`) failed in faer.
    #[error("{step}: {source:?}")]
    Factorization {
        step: String,
        #[source]
        source: FaerError,
    },
    /// The Cholesky factor of the pair-space contact matrix `I + k_n F_AA` of `pairs` active
    /// pairs could not be updated (`source`).
    #[error("pair-space contact matrix I + k_n F_AA ({pairs} pairs) is not positive definite")]
    ContactMatrix {
        pairs: usize,
        #[source]
        source: Box<LinalgError>,
    },

    // ---- eigenproblems and decompositions ----
    /// The symmetric eigensolver of `what` (an `n` × `n` matrix) did not converge.
    #[error("{what}: the {n}×{n} eigensolver failed: {error:?}")]
    EigenNotConverged {
        what: String,
        n: usize,
        error: EvdError,
    },
    /// The SVD of `what` (e.g. `POD: SVD of the TVD coefficients`) did not converge.
    #[error("{what}: {error:?}")]
    SvdNotConverged { what: &'static str, error: SvdError },
    /// `what` is `rows` × `cols`, not square.
    #[error("{what}: the matrix is {rows}×{cols}, not square")]
    NotSquare {
        what: String,
        rows: usize,
        cols: usize,
    },
    /// `what` (an `n` × `n` matrix) has a NaN or infinite entry.
    #[error("{what}: the {n}×{n} matrix has a non-finite entry")]
    NonFiniteEntry { what: String, n: usize },
    /// The sparse eigenproblem needs K positive definite; its factorization failed (`source`).
    #[error(
        "eigenproblem: K must be positive definite (is the structure supported?): linear \
         algebra: {source}"
    )]
    EigenStiffness {
        #[source]
        source: Box<LinalgError>,
    },
    /// The Rayleigh quotient `value` of the start vector under `L⁻¹ M L⁻ᵀ` is not positive.
    #[error(
        "eigenproblem: Rayleigh quotient {value:e} of L⁻¹ M L⁻ᵀ is not positive (M not positive \
         definite?)"
    )]
    RayleighQuotient { value: f64 },
    /// Krylov–Schur converged `converged` of `count` modes in `restarts` restarts.
    #[error("Krylov–Schur converged {converged} of {count} modes in {restarts} restarts")]
    KrylovSchurIncomplete {
        converged: usize,
        count: usize,
        restarts: usize,
    },
    /// The refined `count` modes kept a relative residual `residual` over `bound`.
    #[error(
        "Krylov–Schur: {count} modes not converged (relative residual {residual:.2e} > {bound:e})"
    )]
    KrylovSchurNotConverged {
        count: usize,
        residual: f64,
        bound: f64,
    },
    /// A Ritz value `value` (μ = 1/ω²) that is not positive.
    #[error("non-positive Ritz value μ = 1/ω² = {value:e}: K or M is not positive definite")]
    RitzValue { value: f64 },
    /// Mode `mode` (1-based, `frequency_hz`) has the normwise backward error `backward` > 1e-10.
    #[error("mode {mode} ({frequency_hz:.4} Hz) has backward error {backward:.2e} > 1e-10")]
    ModeBackwardError {
        mode: usize,
        frequency_hz: f64,
        backward: f64,
    },
    /// `what` (a mode) has the M-norm `norm` (zero or not finite).
    #[error("{what} has M-norm {norm:e}")]
    ModeNorm { what: String, norm: f64 },
    /// The largest eigenvalue `value` of `what` is zero, negative or not finite; `hint` says
    /// why that happens (may be empty).
    #[error("{what} is {value:e}{hint}")]
    NotPositive {
        what: &'static str,
        value: f64,
        hint: &'static str,
    },
    /// An eigenvalue `value` of `what` that is not positive.
    #[error("{what}: eigenvalue {value:e} is not positive")]
    EigenvalueNotPositive { what: &'static str, value: f64 },
    /// The reduced stiffness `ΦᵀKΦ` has the eigenvalue `eigenvalue` ≤ 0 (or not finite).
    #[error("reduced stiffness ΦᵀKΦ is not positive definite (eigenvalue {eigenvalue:e})")]
    ReducedStiffness { eigenvalue: f64 },

    // ---- solves and results ----
    /// `what` has a NaN or infinite entry (`plural`: `what` names several, "are").
    #[error("{what} {} not finite", if *plural { "are" } else { "is" })]
    NotFinite { what: String, plural: bool },
    /// The static solve's normwise backward error `backward` exceeds 1e-10.
    #[error(
        "static solve backward error {backward:.3e} exceeds 1e-10 (singular or ill-conditioned \
         stiffness)"
    )]
    StaticBackwardError { backward: f64 },
    /// The `(i, j)` entry is missing from a prepared sparsity pattern (`what`).
    #[error("entry ({i}, {j}) missing from the {what}")]
    MissingEntry {
        i: usize,
        j: usize,
        what: &'static str,
    },
    /// A failure at time `time` (s) of a run: `source`.
    #[error("error estimate at t = {time:e} s: {source}")]
    EstimateAt {
        time: f64,
        #[source]
        source: Box<LinalgError>,
    },

    // ---- bases of the reduction ----
    /// TVD column `column` (`index`: `TvdIndex { i, k, j }`) has the strain energy `energy`.
    #[error(
        "TVD column {column} (TvdIndex {{ i: {}, k: {}, j: {} }}) has strain energy {energy:e}; K \
         is not positive definite",
        index.0, index.1, index.2
    )]
    TvdStrainEnergy {
        column: usize,
        index: (usize, i8, usize),
        energy: f64,
    },
    /// The `(K − Ω²M)` solve for base vector `mode` has the backward error `backward` > 1e-10.
    #[error(
        "TVD with inertia: (K − Ω²M) solve for base vector {mode} (Ω² = {omega2:e}) has backward \
         error {backward:.2e} > 1e-10 (Ω² is (nearly) a free-interface eigenvalue)"
    )]
    TvdBackwardError {
        mode: usize,
        omega2: f64,
        backward: f64,
    },
    /// Joint Interface Mode `mode` has the non-positive products `uᵀGu`, `uᵀFu`.
    #[error("Joint Interface Modes: mode {mode} has uᵀGu = {ugu:e}, uᵀFu = {ufu:e}")]
    JimProducts { mode: usize, ugu: f64, ufu: f64 },
    /// Joint Interface Mode `mode` (1-based) of the `set` set has an infinite frequency.
    #[error(
        "Joint Interface Mode {mode} of the {set} set has a numerically infinite frequency \
         (condensed mass eigenvalue ≤ 1e-12 of the largest): request fewer than {count}"
    )]
    JimInfiniteFrequency {
        mode: usize,
        set: &'static str,
        count: usize,
    },

    // ---- contact iterations ----
    /// `context` (an iteration) computed a non-finite gap `value` for pair `pair`.
    #[error("{context}: gap of pair {pair} is not finite{}", value_suffix(*value))]
    GapNotFinite {
        context: String,
        pair: usize,
        value: Option<f64>,
    },
    /// The contact active-set Newton's active set after `iteration` (`in_contact` pairs)
    /// repeats that of `first`.
    #[error(
        "contact active-set Newton cycles: the active set after iteration {iteration} \
         ({in_contact} pairs in contact) repeats that of iteration {first} (cycle of length \
         {length})"
    )]
    ActiveSetCycle {
        iteration: usize,
        in_contact: usize,
        first: usize,
        length: usize,
    },
    /// The contact active-set Newton took `iterations` solves without converging.
    #[error(
        "contact active-set Newton did not converge in {iterations} iterations (last active \
         set: {last} of {pairs} pairs)"
    )]
    ActiveSetNotConverged {
        iterations: usize,
        last: usize,
        pairs: usize,
    },
    /// The damped reduced contact's line search found no decrease at `step`.
    #[error(
        "damped reduced contact, step {step}: line search failed (no decrease of the contact \
         energy along the Newton direction)"
    )]
    LineSearch { step: usize },
    /// `what` (an iteration) did not converge in `steps` steps.
    #[error("{what} did not converge in {steps} steps")]
    NotConverged { what: &'static str, steps: usize },
    /// The pair-space contact's projected Gauss–Seidel did not converge in its 100 000 sweeps.
    #[error("pair-space contact: projected Gauss–Seidel did not converge in 100 000 sweeps")]
    GaussSeidelNotConverged,
    /// Reduced contact statics failed (`first`), and then its damped variant (`second`).
    #[error("reduced contact statics failed: {first}; then, damped: {second}")]
    ContactFallback {
        first: Box<crate::Error>,
        #[source]
        second: Box<crate::Error>,
    },
}

impl LinalgError {
    /// Whether this is a request the matrices cannot serve (a mode count out of range,
    /// mismatched patterns) rather than a numerical failure.
    pub fn is_request(&self) -> bool {
        matches!(
            self,
            LinalgError::ModeCount { .. } | LinalgError::PatternMismatch { .. }
        )
    }

    /// [`LinalgError::NotFinite`] of one `what`.
    pub fn not_finite(what: impl Into<String>) -> LinalgError {
        LinalgError::NotFinite {
            what: what.into(),
            plural: false,
        }
    }
}

fn value_suffix(value: Option<f64>) -> String {
    value.map(|v| format!(" ({v})")).unwrap_or_default()
}
