//! The Newton solve of the mechanical problem (module docs of [`super`], *The Newton solve*): the
//! pairs' linearization, the γ-dependent per-pair blocks `K_c`, and the elimination of `b`, `c`
//! that leaves one symmetric positive definite system in `a`.

use super::{dot, MechanicalOde, PairLin};
use crate::integrate::problem::CallbackError;
use crate::joint::law::PairState;
use crate::system::{JointRows, SecondOrderSystem};

impl<S: SecondOrderSystem> MechanicalOde<S> {
    /// The pair tangents at the kinematics in `u` and the slip memory in `s_phys` (loaded by
    /// the caller), with each pair's branch.
    pub(super) fn linearize(&mut self) {
        let mut slipping = 0;
        for i in 0..self.live.len() {
            let k = self.live[i];
            let state = self.linearize_pair(k);
            if self.law.friction && state == PairState::Slip {
                slipping += 1;
            }
            self.branch[k] = state;
        }
        self.slipping_at_setup = slipping;
        self.have_lin = true;
    }

    /// Pair k's tangent at its kinematics into `lin[k]` (γ-dependent parts left to
    /// [`MechanicalOde::apply_gamma_pair`]); returns its branch there.
    pub(super) fn linearize_pair(&mut self, k: usize) -> PairState {
        let (uk, sk) = self.pair_kinematics(k);
        let tg = self.law.tangent(uk, sk);
        self.lin[k] = PairLin {
            sdot_u: tg.sdot_u,
            sdot_g: tg.sdot_g,
            pt_u: tg.pt_u,
            pn_g: tg.pn_g,
            diss_u: tg.diss_u,
            diss_g: tg.diss_g,
            ..PairLin::default()
        };
        self.law.state(uk, sk)
    }

    /// Pair k's kinematics `[g, u_t1, u_t2]` in `u` and slip memory in `s_phys` (zero with
    /// friction off), mm.
    #[inline(always)]
    pub(super) fn pair_kinematics(&self, k: usize) -> ([f64; 3], [f64; 2]) {
        let uk = [self.u[3 * k], self.u[3 * k + 1], self.u[3 * k + 2]];
        let sk = if self.law.friction {
            [self.s_phys[2 * k], self.s_phys[2 * k + 1]]
        } else {
            [0.0; 2]
        };
        (uk, sk)
    }

    /// Builds K_c and the per-pair data for γ from the stored linearization.
    pub(super) fn apply_gamma(&mut self, gamma: f64) {
        for i in 0..self.live.len() {
            self.apply_gamma_pair(self.live[i], gamma);
        }
        self.lin_gamma = gamma;
    }

    /// [`MechanicalOde::apply_gamma`] of pair k.
    pub(super) fn apply_gamma_pair(&mut self, k: usize, gamma: f64) {
        let l = &mut self.lin[k];
        let a = [
            [1.0 + gamma * l.sdot_u[0][0], gamma * l.sdot_u[0][1]],
            [gamma * l.sdot_u[1][0], 1.0 + gamma * l.sdot_u[1][1]],
        ];
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        l.inv = [
            [a[1][1] / det, -a[0][1] / det],
            [-a[1][0] / det, a[0][0] / det],
        ];
        let te = matmul2(&l.pt_u, &l.inv);
        let off = 0.5 * (te[0][1] + te[1][0]);
        l.t_eff = [[te[0][0], off], [off, te[1][1]]];
        let b = &mut self.kc[9 * k..9 * k + 9];
        b.fill(0.0);
        b[0] = l.pn_g;
        b[4] = l.t_eff[0][0];
        b[5] = l.t_eff[0][1];
        b[7] = l.t_eff[1][0];
        b[8] = l.t_eff[1][1];
    }

    /// The Newton setup ([`crate::integrate::problem::OdeProblem::newton_setup`]): re-linearizes
    /// at `y` unless CVODE allows the stored Jacobian (`jok`) and there is one, then factors the
    /// Newton matrix at `gamma`. Returns whether the Jacobian data were recomputed.
    pub(super) fn setup_newton(
        &mut self,
        t: f64,
        y: &[f64],
        fy: &[f64],
        jok: bool,
        gamma: f64,
    ) -> Result<bool, CallbackError> {
        let n = self.n;
        let moved = self.rebuild_screen(t, y, fy, gamma);
        let jcur = !(jok && self.have_lin) || moved;
        if jcur {
            self.apply_live(&y[..n]);
            self.load_slip(y);
            self.linearize();
        }
        self.apply_gamma(gamma);
        self.sys
            .newton_factor(gamma, &self.kc)
            .map_err(|e| CallbackError::Recoverable(e.to_string()))?;
        Ok(jcur)
    }

    /// The Newton solve ([`crate::integrate::problem::OdeProblem::newton_solve`]): `z` with
    /// `(I − γJ) z = r` at `(t, y)`, after an active-set refresh if one is due.
    pub(super) fn solve_newton(
        &mut self,
        t: f64,
        y: &[f64],
        r: &[f64],
        z: &mut [f64],
        gamma: f64,
    ) -> Result<(), CallbackError> {
        if !self.have_lin {
            return Err(CallbackError::Fatal(
                "newton_solve called before newton_setup".into(),
            ));
        }
        if let Some(margin) = self.refresh {
            self.refresh_if_switched(y, gamma, margin)?;
        }
        // CVODE re-runs the setup only when γ has changed by more than ~30 %; between setups
        // the current γ is used in the elimination (so `a − γ b = r_q` holds exactly) with the
        // factorization and `(I + γ D_s)⁻¹` of the setup's γ.
        let g = gamma;
        let n = self.n;
        let ns = self.ns();
        let fr = self.law.friction;
        let (rq, rest) = r.split_at(n);
        let (rv, rest) = rest.split_at(n);
        let (rs, rest) = rest.split_at(ns);
        // Residuals and corrections of s, W, D in physical units (mm, N·mm) inside.
        let ss = self.s_scale;
        // rhs_a = M (r_q + γ r_v) + γ² Bᵀ [0; T_eff r_s]
        for ((o, a), b) in self.tmp2.iter_mut().zip(rq).zip(rv) {
            *o = a + g * b;
        }
        self.sys.mul_m_into(&self.tmp2, &mut self.tmp);
        if fr {
            // With the stretch states `(I + γD_s) c = r_e + B_t a − B_t r_q − γ φ_g B_n a`
            // (module docs, *The slip memory as elastic stretch*): the known part is
            // `r_e − B_t r_q`, and it enters with the opposite sign (∂p_t/∂e = +T).
            let sign = if self.stretch {
                self.live_apply_ub(rq);
                -1.0
            } else {
                1.0
            };
            for &k in &self.live {
                let l = &self.lin[k];
                let known = if self.stretch {
                    [
                        ss * rs[2 * k] - self.ub[3 * k + 1],
                        ss * rs[2 * k + 1] - self.ub[3 * k + 2],
                    ]
                } else {
                    [ss * rs[2 * k], ss * rs[2 * k + 1]]
                };
                let x = mul2(&l.inv, known);
                let h = mul2(&l.pt_u, x);
                self.p[3 * k] = 0.0;
                self.p[3 * k + 1] = sign * g * g * h[0];
                self.p[3 * k + 2] = sign * g * g * h[1];
            }
            let mut tmp = std::mem::take(&mut self.tmp);
            self.transpose_add_live(&mut tmp);
            self.tmp = tmp;
        }
        let (za, zrest) = z.split_at_mut(n);
        za.copy_from_slice(&self.tmp);
        self.sys.newton_solve_in_place(za);
        let (zb, zrest) = zrest.split_at_mut(n);
        for ((b, a), q) in zb.iter_mut().zip(za.iter()).zip(rq) {
            *b = (a - q) / g;
        }
        let (zs, ze) = zrest.split_at_mut(ns);
        let mut zd = self.e_scale * rest[1];
        if fr {
            // Untracked pairs: frozen memory, zero Jacobian rows (`c = r_s`).
            zs.copy_from_slice(rs);
            self.apply_for_corrections(za);
            if self.stretch {
                self.stretch_corrections(rs, zs, g, &mut zd);
            } else {
                self.slip_corrections(rs, zs, g, &mut zd);
            }
        }
        self.load_at(t);
        ze[0] = rest[0] + g * dot(&self.f, zb) / self.e_scale;
        ze[1] = zd / self.e_scale;
        // Checked by the CVODE trampoline, as the right-hand side.
        Ok(())
    }

    /// `u = B a` for the slip states' corrections ([`MechanicalOde::slip_corrections`]): the
    /// tangential rows and the normal rows of the sliding pairs only — the normal row enters
    /// through `∂ṡ/∂g` and `∂d/∂g`, zero on the open and stuck branches (their entries are set
    /// to 0). With screening, on the live pairs; without it, where the system offers it, for
    /// every pair; with the stretch states, all rows of the live pairs. The same values.
    fn apply_for_corrections(&mut self, a: &[f64]) {
        if self.screen.is_some() && !self.stretch {
            for &k in &self.live {
                if self.branch[k] == PairState::Slip {
                    let u = self.sys.joint_pair(a, k);
                    self.u[3 * k..3 * k + 3].copy_from_slice(&u);
                } else {
                    let [t1, t2] = self.sys.joint_pair_tangential(a, k);
                    self.u[3 * k..3 * k + 3].copy_from_slice(&[0.0, t1, t2]);
                }
            }
            return;
        }
        if self.rows_selectable() {
            let mut rows = std::mem::take(&mut self.rows);
            rows.clear();
            for k in 0..self.w {
                if self.branch[k] == PairState::Slip {
                    rows.push(3 * k);
                } else {
                    self.u[3 * k] = 0.0;
                }
            }
            let done = self.sys.joint_apply_rows_into(
                a,
                Some(JointRows::Tangential),
                &rows,
                &mut self.rows_scratch,
                &mut self.u,
            );
            self.rows = rows;
            if done {
                return;
            }
        }
        self.apply_live(a);
    }

    /// The slip states' corrections of a Newton solve, given `u = B a` on the live pairs:
    /// `c = (I + γD_s)⁻¹ (r_s + γ D_s B_t a + γ φ_g B_n a)` (mm, written to `zs` in state
    /// units) and the dissipation's `γ ∇D'·[a; c]` added to `zd` (N·mm).
    fn slip_corrections(&self, rs: &[f64], zs: &mut [f64], g: f64, zd: &mut f64) {
        let ss = self.s_scale;
        for &k in &self.live {
            let l = &self.lin[k];
            let ba = [self.u[3 * k], self.u[3 * k + 1], self.u[3 * k + 2]];
            let du = mul2(&l.sdot_u, [ba[1], ba[2]]);
            let rhs = [
                ss * rs[2 * k] + g * (du[0] + l.sdot_g[0] * ba[0]),
                ss * rs[2 * k + 1] + g * (du[1] + l.sdot_g[1] * ba[0]),
            ];
            let c = mul2(&l.inv, rhs);
            zs[2 * k] = c[0] / ss;
            zs[2 * k + 1] = c[1] / ss;
            *zd += g
                * (l.diss_u[0] * (ba[1] - c[0]) + l.diss_u[1] * (ba[2] - c[1]) + l.diss_g * ba[0]);
        }
    }
}

impl<S: SecondOrderSystem> MechanicalOde<S> {
    /// `ub = B x` on the live pairs.
    fn live_apply_ub(&mut self, x: &[f64]) {
        if self.screen.is_some() {
            self.sys.joint_apply_pairs_into(x, &self.live, &mut self.ub);
        } else {
            self.sys.joint_apply_into(x, &mut self.ub);
        }
    }

    /// The stretch states' corrections of a Newton solve, given `u = B a` and
    /// `ub = B r_q` on the live pairs: `c = (I + γD_s)⁻¹ (r_e + B_t a − B_t r_q − γ φ_g B_n a)`
    /// (mm, written to `zs` in state units) and the dissipation's `γ (∂d/∂e · c + ∂d/∂g B_n a)`
    /// added to `zd` (N·mm).
    fn stretch_corrections(&self, rs: &[f64], zs: &mut [f64], g: f64, zd: &mut f64) {
        let ss = self.s_scale;
        for &k in &self.live {
            let l = &self.lin[k];
            let ba = [self.u[3 * k], self.u[3 * k + 1], self.u[3 * k + 2]];
            let rhs = [
                ss * rs[2 * k] + ba[1] - self.ub[3 * k + 1] - g * l.sdot_g[0] * ba[0],
                ss * rs[2 * k + 1] + ba[2] - self.ub[3 * k + 2] - g * l.sdot_g[1] * ba[0],
            ];
            let c = mul2(&l.inv, rhs);
            zs[2 * k] = c[0] / ss;
            zs[2 * k + 1] = c[1] / ss;
            *zd += g * (l.diss_u[0] * c[0] + l.diss_u[1] * c[1] + l.diss_g * ba[0]);
        }
    }
}

fn mul2(a: &[[f64; 2]; 2], x: [f64; 2]) -> [f64; 2] {
    [
        a[0][0] * x[0] + a[0][1] * x[1],
        a[1][0] * x[0] + a[1][1] * x[1],
    ]
}

fn matmul2(a: &[[f64; 2]; 2], b: &[[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let mut c = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            c[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j];
        }
    }
    c
}
