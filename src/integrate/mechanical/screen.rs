//! Pair screening (module docs of [`super`], *Pair screening*): the tracked set of pairs whose
//! kinematics, forces, slip memory and Newton blocks a step evaluates, a bound that proves every
//! other pair open, and the slip-memory offsets that let a pair join the set between steps
//! without a jump in the state's derivative.

use super::MechanicalOde;
use crate::joint::law::PairState;
use crate::system::SecondOrderSystem;

/// The screening horizon in multiples of γ (`h ≈ 1.5 γ` at BDF order 2): about 40 steps. The
/// set is built for the pairs that may close within it and rebuilt at a setup after half of it
/// (CVODE sets up at least every 20 steps).
const HORIZON_GAMMAS: f64 = 60.0;

/// The state of the screening of one run.
pub(super) struct PairScreen {
    /// `‖B_{n,z}‖₂` per pair z: the Euclidean norm of its normal row of the joint operator in
    /// the system's coordinates (mm per unit coordinate).
    row_norm: Vec<f64>,
    /// Whether pair z is tracked.
    is_tracked: Vec<bool>,
    /// The time `t_ref` (s), coordinates `q_ref` and velocities `v_ref` at the last build.
    t_ref: f64,
    q_ref: Vec<f64>,
    v_ref: Vec<f64>,
    /// The horizon of the last build, s.
    horizon: f64,
    /// Normal gaps `g_ref` (mm) and their rates `ġ_ref = B_n v_ref` (mm/s) of every pair at the
    /// last build.
    gaps: Vec<f64>,
    rates: Vec<f64>,
    /// The gaps' accelerations `B_n v̇` at the last build (mm/s², scratch of the prediction).
    accels: Vec<f64>,
    /// The untracked pairs, ascending.
    untracked: Vec<usize>,
    /// Whether the set must be rebuilt at the next setup (never built, or a late entry).
    stale: bool,
    /// The pairs whose membership changed at the last build (scratch, capacity w).
    moved: Vec<usize>,
    /// The slip-memory rates of the untracked pairs (2w, state units per s): each pair's rate
    /// when it left the set, held constant while it is untracked.
    frozen_rate: Vec<f64>,
    /// Statistics.
    pub(super) stats: ScreenStats,
}

/// Counters of the screening, for the run's statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct ScreenStats {
    /// Builds of the tracked set (each three products of the normal rows over all pairs: gaps,
    /// rates, accelerations).
    pub builds: u64,
    /// Pairs that joined the tracked set, summed.
    pub entries: u64,
    /// Pairs dropped from it.
    pub exits: u64,
    /// Untracked pairs whose gap a right-hand side computed exactly (their bound was not
    /// positive), summed.
    pub exact_checks: u64,
    /// Untracked pairs found closed by a right-hand side (late entries; also counted in
    /// `entries`).
    pub violations: u64,
    /// Tracked pairs summed over the builds (mean = this / builds).
    pub tracked_sum: u64,
    /// The most pairs tracked at once.
    pub tracked_max: u64,
}

impl PairScreen {
    /// Whether pair `z` is tracked.
    pub(super) fn tracks(&self, z: usize) -> bool {
        self.is_tracked[z]
    }

    /// A screen of w pairs with the normal-row norms `row_norm`, tracking every pair until its
    /// first build.
    pub(super) fn new(row_norm: Vec<f64>, n: usize) -> PairScreen {
        let w = row_norm.len();
        PairScreen {
            row_norm,
            is_tracked: vec![true; w],
            t_ref: 0.0,
            q_ref: vec![0.0; n],
            v_ref: vec![0.0; n],
            horizon: 0.0,
            gaps: vec![0.0; w],
            rates: vec![0.0; w],
            accels: vec![0.0; w],
            untracked: Vec::with_capacity(w),
            stale: true,
            moved: Vec::with_capacity(w),
            frozen_rate: vec![0.0; 2 * w],
            stats: ScreenStats::default(),
        }
    }

    /// Writes the frozen slip rates of every pair into `out` (2w; the tracked pairs' entries
    /// are then overwritten by the caller).
    pub(super) fn frozen_rates_into(&self, out: &mut [f64]) {
        out.copy_from_slice(&self.frozen_rate[..out.len()]);
    }

    /// `‖q − q_ref − v_ref (t − t_ref)‖`: how far the motion has left the straight line of the
    /// last build (units of q).
    fn drift(&self, t: f64, q: &[f64]) -> f64 {
        let tau = t - self.t_ref;
        q.iter()
            .zip(&self.q_ref)
            .zip(&self.v_ref)
            .map(|((x, x0), v0)| {
                let d = x - x0 - v0 * tau;
                d * d
            })
            .sum::<f64>()
            .sqrt()
    }

    /// The lower bound of pair z's gap at time t for a drift `drift`:
    /// `g_ref + ġ_ref (t − t_ref) − ‖B_{n,z}‖ drift` (mm).
    fn gap_bound(&self, z: usize, t: f64, drift: f64) -> f64 {
        self.gaps[z] + self.rates[z] * (t - self.t_ref) - self.row_norm[z] * drift
    }
}

impl<S: SecondOrderSystem> MechanicalOde<S> {
    /// Adds the screening's counters to a run's statistics.
    pub fn add_screen_stats(&self, stats: &mut crate::integrate::problem::OdeStats) {
        if let Some(sc) = &self.screen {
            stats.screen_builds = sc.stats.builds;
            stats.screen_tracked_sum = sc.stats.tracked_sum;
            stats.screen_tracked_max = sc.stats.tracked_max;
            stats.screen_violations = sc.stats.violations;
            stats.screen_entries = sc.stats.entries;
            stats.screen_exact_checks = sc.stats.exact_checks;
            stats.screen_exits = sc.stats.exits;
        }
    }

    /// Proves every untracked pair open at `(t, y)`: with `Δ = q − q_ref − v_ref (t − t_ref)`,
    /// `g_z(q) = g_ref + ġ_ref (t − t_ref) + B_{n,z} Δ ≥ g_ref + ġ_ref (t − t_ref) − ‖B_{n,z}‖ ‖Δ‖`
    /// (one scalar test per pair); the pairs whose bound is not positive are checked exactly,
    /// and one found closed joins the set at once (a late entry, with the memory offset of any
    /// entry): no contact is missed, whatever the prediction of the last build.
    pub(super) fn check_untracked(&mut self, t: f64, y: &[f64]) {
        let q = &y[..self.n];
        let Some(sc) = self.screen.as_mut() else {
            return;
        };
        let drift = sc.drift(t, q);
        sc.moved.clear();
        for i in 0..sc.untracked.len() {
            let z = sc.untracked[i];
            // Round-off of the gap products: relative 1e-12 of the bound's terms.
            let slack = 1e-12 * (sc.gaps[z].abs() + sc.row_norm[z] * (drift + 1.0));
            if sc.gap_bound(z, t, drift) > slack {
                continue;
            }
            sc.stats.exact_checks += 1;
            if self.sys.joint_normal_gap(q, z) < 0.0 {
                sc.moved.push(z);
            }
        }
        if sc.moved.is_empty() {
            return;
        }
        sc.stats.violations += sc.moved.len() as u64;
        sc.stats.entries += sc.moved.len() as u64;
        for &z in &sc.moved {
            sc.is_tracked[z] = true;
        }
        let tracked = &sc.is_tracked;
        sc.untracked.retain(|&z| !tracked[z]);
        sc.stale = true;
        self.sync_live(y);
    }

    /// Rebuilds the tracked set at `(t, y)` with the right-hand side `fy` there, if half the
    /// last horizon has passed (or the set is stale). With `H = 60 γ` (≈ 40 steps) and
    /// `reach_z(H)` the least gap over `[0, H]` of the quadratic prediction
    /// `g_z + ġ_z τ + ½ g̈_z τ²` (`g̈ = B_n v̇` from `fy`),
    /// pair z joins if `reach_z(H) ≤ 0` (it may close within H) and leaves if
    /// `reach_z(2H) > 0`. A leaving pair's slip memory keeps its current rate (from `fy`); a
    /// joining pair's memory offset is set so that the law gives that same rate
    /// (module docs, *Pair screening*): the state's derivative is continuous either way.
    /// Returns whether the set changed (the caller then re-linearizes).
    pub(super) fn rebuild_screen(&mut self, t: f64, y: &[f64], fy: &[f64], gamma: f64) -> bool {
        let n = self.n;
        let (q, v) = (&y[..n], &y[n..2 * n]);
        let Some(sc) = self.screen.as_mut() else {
            return false;
        };
        if !sc.stale && (t - sc.t_ref).abs() <= 0.5 * sc.horizon {
            return false;
        }
        let horizon = HORIZON_GAMMAS * gamma.abs();
        self.sys.joint_normal_apply_into(q, &mut sc.gaps);
        self.sys.joint_normal_apply_into(v, &mut sc.rates);
        sc.t_ref = t;
        sc.q_ref.copy_from_slice(q);
        sc.v_ref.copy_from_slice(v);
        sc.horizon = horizon;
        sc.stale = false;
        sc.stats.builds += 1;
        sc.untracked.clear();
        sc.moved.clear();
        // The quadratic prediction of each gap over [0, h], its minimum; the right-hand sides'
        // exact bound catches what it leaves out.
        self.sys
            .joint_normal_apply_into(&fy[n..2 * n], &mut sc.accels);
        let reach = |sc: &PairScreen, z: usize, h: f64| {
            let (g, r, a) = (sc.gaps[z], sc.rates[z], sc.accels[z]);
            let end = g + r * h + 0.5 * a * h * h;
            let mut low = g.min(end);
            if a > 0.0 && r < 0.0 && -r / a < h {
                low = low.min(g - 0.5 * r * r / a);
            }
            low
        };
        let ns = if self.law.friction { 2 } else { 0 };
        let mut tracked = 0;
        for z in 0..self.w {
            let keep = reach(sc, z, horizon) <= 0.0
                || (sc.is_tracked[z] && reach(sc, z, 2.0 * horizon) <= 0.0);
            if keep != sc.is_tracked[z] {
                sc.moved.push(z);
                sc.is_tracked[z] = keep;
                if keep {
                    sc.stats.entries += 1;
                } else {
                    sc.stats.exits += 1;
                    for i in 2 * z..2 * z + ns {
                        sc.frozen_rate[i] = fy[2 * n + i];
                    }
                }
            }
            if keep {
                tracked += 1;
            } else {
                sc.untracked.push(z);
            }
        }
        sc.stats.tracked_sum += tracked;
        sc.stats.tracked_max = sc.stats.tracked_max.max(tracked);
        let changed = !sc.moved.is_empty();
        if changed {
            self.sync_live(y);
        }
        changed
    }

    /// Rebuilds the live list from `is_tracked`; the pairs in `moved` that joined get their
    /// slip-memory offset, and all of them an open linearization and zero blocks.
    fn sync_live(&mut self, y: &[f64]) {
        let Some(sc) = self.screen.as_ref() else {
            return;
        };
        let n = self.n;
        self.live.clear();
        self.live.extend((0..self.w).filter(|&z| sc.is_tracked[z]));
        for &z in &sc.moved {
            self.kc[9 * z..9 * z + 9].fill(0.0);
            self.lin[z] = super::PairLin::default();
            self.branch[z] = PairState::Open;
            self.p[3 * z..3 * z + 3].fill(0.0);
            if self.stretch && sc.is_tracked[z] {
                // e = τ (u̇_t − ė_frozen): the open pair's law `ė = u̇_t − e/τ` then gives the
                // frozen rate.
                let ud = self.sys.joint_pair(&y[n..2 * n], z);
                for (i, vt) in [(2 * z, ud[1]), (2 * z + 1, ud[2])] {
                    let rate = self.s_scale * sc.frozen_rate[i];
                    self.offset[i] = self.law.tau * (vt - rate) - self.s_scale * y[2 * n + i];
                }
            } else if self.law.friction && sc.is_tracked[z] {
                // s = u_t − τ ṡ_frozen: the open pair's law `ṡ = (u_t − s)/τ` then gives the
                // frozen rate.
                let u = self.sys.joint_pair(&y[..n], z);
                for (i, ut) in [(2 * z, u[1]), (2 * z + 1, u[2])] {
                    let rate = self.s_scale * sc.frozen_rate[i];
                    self.offset[i] = ut - self.law.tau * rate - self.s_scale * y[2 * n + i];
                }
            }
        }
    }
}
