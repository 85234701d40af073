//! The active-set refresh (module docs of [`super`], *Active-set refresh*): inside a Newton
//! iteration, re-linearize and update or refactor the Newton matrix when a pair has crossed its
//! switch since the last linearization.

use super::MechanicalOde;
use crate::integrate::problem::CallbackError;
use crate::joint::law::PairState;
use crate::system::SecondOrderSystem;

impl<S: SecondOrderSystem> MechanicalOde<S> {
    /// Active-set refresh: if a pair's branch at the iterate `y` differs from the one of the
    /// stored linearization, re-linearizes there and refactors with `gamma`.
    pub(super) fn refresh_if_switched(
        &mut self,
        y: &[f64],
        gamma: f64,
        margin: f64,
    ) -> Result<(), CallbackError> {
        let slip_margin = margin * self.s_scale;
        let (n, ns) = (self.n, self.ns());
        if y[..n] == self.rhs_q[..] && y[2 * n..2 * n + ns] == self.rhs_s[..] {
            self.u.copy_from_slice(&self.rhs_u);
        } else {
            self.apply_live(&y[..n]);
        }
        self.load_slip(y);
        // The pairs on another branch than linearized (`changed`); a refresh when one of them
        // is past its switch by more than the margin.
        self.changed.clear();
        let mut switched = false;
        for i in 0..self.live.len() {
            let k = self.live[i];
            let (uk, sk) = self.pair_kinematics(k);
            let (now, then) = (self.law.state(uk, sk), self.branch[k]);
            if now == then {
                continue;
            }
            self.changed.push(k);
            switched |= if (now == PairState::Open) != (then == PairState::Open) {
                uk[0].abs() > margin
            } else {
                self.law.cone_distance(uk, sk).abs() > slip_margin
            };
        }
        if !switched {
            return Ok(());
        }
        self.refreshes += 1;
        self.refresh_pairs += self.changed.len() as u64;
        if self.update_changed() {
            self.low_rank_refreshes += 1;
            return Ok(());
        }
        self.linearize();
        self.apply_gamma(gamma);
        self.sys
            .newton_factor(gamma, &self.kc)
            .map_err(|e| CallbackError::Recoverable(e.to_string()))
    }

    /// Re-linearizes the pairs in `changed` (those on another branch than linearized) at `u`,
    /// `s_phys` and the factored γ, and asks the system to change its factor by their blocks
    /// alone ([`SecondOrderSystem::newton_update`]). `false` if it did not: the caller then
    /// re-linearizes every pair and refactors at the current γ. The other pairs keep their
    /// linearization; the ones on a branch whose tangent is constant (open, stick) are then
    /// exactly as a full re-linearization would make them, the sliding ones as at the last
    /// linearization (as between setups).
    fn update_changed(&mut self) -> bool {
        for i in 0..self.changed.len() {
            let k = self.changed[i];
            let state = self.linearize_pair(k);
            let friction = self.law.friction;
            let slip = |s: PairState| usize::from(friction && s == PairState::Slip);
            self.slipping_at_setup = self.slipping_at_setup + slip(state) - slip(self.branch[k]);
            self.branch[k] = state;
            self.apply_gamma_pair(k, self.lin_gamma);
        }
        self.sys.newton_update(&self.kc, &self.changed)
    }

    /// Active-set refreshes so far ([`ProblemOptions::refresh`](super::ProblemOptions::refresh)).
    pub fn refreshes(&self) -> u64 {
        self.refreshes
    }

    /// Of the [`MechanicalOde::refreshes`], those done by a low-rank update of the factor
    /// ([`SecondOrderSystem::newton_update`]) instead of a refactorization.
    pub(crate) fn low_rank_refreshes(&self) -> u64 {
        self.low_rank_refreshes
    }

    /// Pairs that had switched branch at a refresh, summed over the refreshes.
    pub(crate) fn refresh_pairs(&self) -> u64 {
        self.refresh_pairs
    }
}
