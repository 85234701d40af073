//! The joint pair law: penalty contact and isotropic Coulomb friction with elastic stick, its slip
//! memory as ODE state, and its derivatives — safe Rust on slices, no allocation.
//!
//! Per pair (rows of [`crate::joint::JointOperator`]: normal, t1 = x, t2 = z) the kinematics are
//! the normal gap `g` (mm, negative = penetration) and the tangential relative displacement
//! `u_t ∈ R²` (mm). The paper's node-to-node model (Witteveen & Pichler 2014, Section 3 and
//! eq. 6: the pseudoforce `f_NL`) with the sign convention of [`crate::joint::statics`]:
//!
//! ```text
//! p_n = k_n · min(g, 0)                          (N, compressive negative)
//! e   = u_t − s                                  (elastic part; s ∈ R² the slip memory, mm)
//! c   = μ |p_n| / k_t                            (radius of the stick region in e, mm)
//! p_t = k_t e                  if |e| ≤ c        (stick)
//!     = k_t c · e/|e|          if |e| > c        (slip: force on the cone |p_t| = μ|p_n|)
//! p   = 0                      if g ≥ 0          (open: no force)
//! ```
//!
//! The forces return to the structure as `−Bᵀ p` (`M q̈ + K q = f − Bᵀ p`).
//!
//! ## Slip memory as ODE state: the viscoplastic return form
//!
//! A CVODE right-hand side must be a pure function of `(t, y)`, so `s` is integrated from a rate
//! law. The consistency form of rate-independent plasticity (`ṡ = λ e/|e|` with `λ` from
//! `d|p_t|/dt = 0`) makes implicit steps that cross onto the cone unsolvable (measured: the step
//! size collapses to round-off; `docs/theory/contact-friction.md`, section `joint::law`). Instead `s`
//! relaxes back to the cone (Perzyna-type regularisation):
//!
//! ```text
//! ṡ = (|e| − c)₊ · e/|e| / τ ,     τ = 1e-6 s by default ([`DEFAULT_TAU`])
//! ```
//!
//! while the force is capped exactly at `μ|p_n|`. In steady sliding at tangential speed `V` the
//! state lags outside the cone by `|e| − c ≈ τ V` (1e-5 mm at 10 mm/s), which changes nothing in
//! the force (it is capped) and only delays the stick→slip transition by ~τ. The dissipation per
//! cycle of the exact Coulomb loop `4 μ p_n (A − c)` is reproduced closely for τ = 1e-6 s
//! (`tests/integrate/friction.rs` checks 1 %; measured errors in `docs/theory/contact-friction.md`, section
//! `joint::law`). The price is a stiff eigenvalue `−1/τ` per sliding or open pair: fine for BDF
//! with Newton (the structured solve of [`crate::integrate::mechanical`] treats it exactly),
//! prohibitive for functional iteration (step ≲ τ) whenever friction is on.
//!
//! When a pair is open, `c = 0` and the memory relaxes to `s = u_t` with time constant τ: a pair
//! that closes again starts without elastic tangential stretch.
//!
//! Dissipation rate `d = p_t · ṡ = k_t c (|e| − c)₊ / τ ≥ 0` (N·mm/s); the tangential stored
//! energy is `½ k_t min(|e|, c)²` ([`PairLaw::stored_energy`]); the power balance
//! `p · (ġ, u̇_t) = dψ/dt + d` holds up to `k_t c · d(|e| − c)/dt`: the capped law has no exact
//! potential, and the mismatch is of the order of the lag `τ V` above (or `τ ċ` when the normal
//! force falls while sliding). The balance is checked in [`crate::integrate::mechanical`]; how
//! closely it closes on the friction bar ROM is in `docs/theory/contact-friction.md`, section `joint::law`.

/// Default relaxation time τ of the slip memory, s.
pub const DEFAULT_TAU: f64 = 1e-6;

/// Parameters of the pair law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairLaw {
    /// Normal penalty stiffness k_n, N/mm.
    pub k_n: f64,
    /// Whether friction (tangential forces and slip memory) is on.
    pub friction: bool,
    /// Coulomb coefficient μ, dimensionless.
    pub mu: f64,
    /// Tangential (stick) stiffness k_t, N/mm.
    pub k_t: f64,
    /// Relaxation time τ of the slip memory, s.
    pub tau: f64,
}

/// Which branch of the law a pair is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PairState {
    /// `g ≥ 0`: no force.
    Open,
    /// Closed, `|e| ≤ c` (or friction off).
    Stick,
    /// Closed, `|e| > c`: sliding on the friction cone.
    Slip,
}

/// The law evaluated at one pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairResponse {
    /// Forces `[p_n, p_t1, p_t2]`, N.
    pub p: [f64; 3],
    /// Slip rate `ṡ`, mm/s (zero with friction off).
    pub s_rate: [f64; 2],
    /// Dissipation rate `p_t · ṡ`, N·mm/s.
    pub dissipation: f64,
    /// Branch.
    pub state: PairState,
}

/// Exact derivatives of the pair law at one state (`u = (g, u_t)`; `∂/∂s = −∂/∂u_t`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairTangent {
    /// `∂p_n/∂g` (k_n when closed), N/mm.
    pub pn_g: f64,
    /// `∂p_t/∂u_t` (2×2, row-major, symmetric), N/mm.
    pub pt_u: [[f64; 2]; 2],
    /// `∂p_t/∂g` (−μ k_n e/|e| when sliding), N/mm — the non-symmetric coupling.
    pub pt_g: [f64; 2],
    /// `∂ṡ/∂u_t` (2×2, symmetric), 1/s.
    pub sdot_u: [[f64; 2]; 2],
    /// `∂ṡ/∂g`, 1/s.
    pub sdot_g: [f64; 2],
    /// `∂d/∂u_t`, N/s.
    pub diss_u: [f64; 2],
    /// `∂d/∂g`, N/s.
    pub diss_g: f64,
}

impl PairLaw {
    /// Stick radius `c = μ|p_n|/k_t` (mm) at gap `g`.
    #[inline]
    fn radius(&self, g: f64) -> f64 {
        if g < 0.0 {
            self.mu * self.k_n * (-g) / self.k_t
        } else {
            0.0
        }
    }

    /// The branch [`PairLaw::eval`] takes at `(u, s)`, without the forces (no square root).
    #[inline]
    pub fn state(&self, u: [f64; 3], s: [f64; 2]) -> PairState {
        if u[0] >= 0.0 {
            return PairState::Open;
        }
        if !self.friction {
            return PairState::Stick;
        }
        let (e1, e2) = (u[1] - s[0], u[2] - s[1]);
        let c = self.radius(u[0]);
        if e1 * e1 + e2 * e2 <= c * c {
            PairState::Stick
        } else {
            PairState::Slip
        }
    }

    /// `|e| − c`, mm: how far the elastic slip `e = u_t − s` lies outside (> 0) or inside the
    /// stick radius `c = μ k_n (−g)₊ / k_t`.
    #[inline]
    pub(crate) fn cone_distance(&self, u: [f64; 3], s: [f64; 2]) -> f64 {
        (u[1] - s[0]).hypot(u[2] - s[1]) - self.radius(u[0])
    }

    /// Evaluates the law at kinematics `u = [g, u_t1, u_t2]` (mm) and memory `s` (mm; ignored
    /// with friction off).
    #[inline]
    pub fn eval(&self, u: [f64; 3], s: [f64; 2]) -> PairResponse {
        let g = u[0];
        let pn = self.k_n * g.min(0.0);
        if !self.friction {
            return PairResponse {
                p: [pn, 0.0, 0.0],
                s_rate: [0.0; 2],
                dissipation: 0.0,
                state: if g < 0.0 {
                    PairState::Stick
                } else {
                    PairState::Open
                },
            };
        }
        let e = [u[1] - s[0], u[2] - s[1]];
        if g >= 0.0 {
            return PairResponse {
                p: [0.0; 3],
                s_rate: [e[0] / self.tau, e[1] / self.tau],
                dissipation: 0.0,
                state: PairState::Open,
            };
        }
        // |e| only for closed pairs: `hypot` is ~5 % of a reduced run, most pairs are open.
        let r = e[0].hypot(e[1]);
        let c = self.radius(g);
        if r <= c {
            return PairResponse {
                p: [pn, self.k_t * e[0], self.k_t * e[1]],
                s_rate: [0.0; 2],
                dissipation: 0.0,
                state: PairState::Stick,
            };
        }
        let n = [e[0] / r, e[1] / r];
        let f = self.k_t * c;
        let rate = (r - c) / self.tau;
        PairResponse {
            p: [pn, f * n[0], f * n[1]],
            s_rate: [rate * n[0], rate * n[1]],
            dissipation: f * rate,
            state: PairState::Slip,
        }
    }

    /// Exact derivatives of [`PairLaw::eval`] (one-sided at the switches: the branch of `eval`).
    pub fn tangent(&self, u: [f64; 3], s: [f64; 2]) -> PairTangent {
        let g = u[0];
        let mut t = PairTangent::default();
        if g < 0.0 {
            t.pn_g = self.k_n;
        }
        if !self.friction {
            return t;
        }
        let inv_tau = 1.0 / self.tau;
        if g >= 0.0 {
            t.sdot_u = [[inv_tau, 0.0], [0.0, inv_tau]];
            return t;
        }
        let e = [u[1] - s[0], u[2] - s[1]];
        let r = e[0].hypot(e[1]);
        let c = self.radius(g);
        if r <= c {
            t.pt_u = [[self.k_t, 0.0], [0.0, self.k_t]];
            return t;
        }
        let n = [e[0] / r, e[1] / r];
        let dc_dg = -self.mu * self.k_n / self.k_t;
        let alpha = self.k_t * c / r;
        let rho = (r - c) / r;
        for i in 0..2 {
            for j in 0..2 {
                let nn = n[i] * n[j];
                let perp = if i == j { 1.0 } else { 0.0 } - nn;
                t.pt_u[i][j] = alpha * perp;
                t.sdot_u[i][j] = inv_tau * (nn + rho * perp);
            }
            t.pt_g[i] = self.k_t * dc_dg * n[i];
            t.sdot_g[i] = -inv_tau * dc_dg * n[i];
            t.diss_u[i] = self.k_t * c * inv_tau * n[i];
        }
        t.diss_g = self.k_t * inv_tau * (r - 2.0 * c) * dc_dg;
        t
    }

    /// Stick/slip switch function `μ|p_n| − k_t|e|` (N): positive while sticking.
    #[inline]
    pub fn switch(&self, u: [f64; 3], s: [f64; 2]) -> f64 {
        let e = [u[1] - s[0], u[2] - s[1]];
        self.k_t * (self.radius(u[0]) - e[0].hypot(e[1]))
    }

    /// Stored (penalty) energy `½ k_n min(g, 0)² + ½ k_t min(|e|, c)²`, N·mm.
    #[inline]
    pub fn stored_energy(&self, u: [f64; 3], s: [f64; 2]) -> f64 {
        let gn = u[0].min(0.0);
        let mut w = 0.5 * self.k_n * gn * gn;
        if self.friction && u[0] < 0.0 {
            let r = (u[1] - s[0]).hypot(u[2] - s[1]).min(self.radius(u[0]));
            w += 0.5 * self.k_t * r * r;
        }
        w
    }
}

/// Totals of [`evaluate_pairs`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairTotals {
    /// Σ dissipation rate, N·mm/s.
    pub dissipation: f64,
    /// Pairs sliding.
    pub slipping: usize,
    /// Pairs closed (g < 0).
    pub closed: usize,
}

/// Evaluates the law for all pairs: `u` the joint kinematics `B q` (3 per pair), `s` the slip
/// memory (2 per pair; may be empty with friction off), writes the forces `p` (3 per pair) and,
/// with friction on, the slip rates `s_rate` (2 per pair).
pub fn evaluate_pairs(
    law: &PairLaw,
    u: &[f64],
    s: &[f64],
    p: &mut [f64],
    s_rate: &mut [f64],
) -> PairTotals {
    evaluate_iter(law, 0..u.len() / 3, u, s, p, s_rate)
}

/// [`evaluate_pairs`] on the listed pairs only (ascending; the other pairs' entries of `p` and
/// `s_rate` are left as they are): the screened right-hand side of
/// [`crate::integrate::mechanical`].
pub fn evaluate_listed_pairs(
    law: &PairLaw,
    pairs: &[usize],
    u: &[f64],
    s: &[f64],
    p: &mut [f64],
    s_rate: &mut [f64],
) -> PairTotals {
    evaluate_iter(law, pairs.iter().copied(), u, s, p, s_rate)
}

fn evaluate_iter(
    law: &PairLaw,
    pairs: impl Iterator<Item = usize>,
    u: &[f64],
    s: &[f64],
    p: &mut [f64],
    s_rate: &mut [f64],
) -> PairTotals {
    let mut tot = PairTotals::default();
    for k in pairs {
        let sk = if law.friction {
            [s[2 * k], s[2 * k + 1]]
        } else {
            [0.0; 2]
        };
        let r = law.eval([u[3 * k], u[3 * k + 1], u[3 * k + 2]], sk);
        p[3 * k..3 * k + 3].copy_from_slice(&r.p);
        if law.friction {
            s_rate[2 * k..2 * k + 2].copy_from_slice(&r.s_rate);
        }
        tot.dissipation += r.dissipation;
        match r.state {
            PairState::Slip => {
                tot.slipping += 1;
                tot.closed += 1;
            }
            PairState::Stick if u[3 * k] < 0.0 => tot.closed += 1,
            _ => {}
        }
    }
    tot
}
