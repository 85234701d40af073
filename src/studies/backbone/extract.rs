//! Cycle-by-cycle extraction of frequency, amplitude and damping from a free decay.
//!
//! Input: the modal coordinate `a(t)` (mm, sampled at the run's outputs), the master's
//! displacement along the mode's master direction `m(t)` (mm) and the dissipated energy `D(t)`
//! (N·mm, integrated by the integrator with the motion).
//!
//! 1. **Turning points.** The decay starts at rest, so t = 0 is the first one. Later ones are
//!    the samples where the discrete slope of `a` changes sign, refined by the parabola through
//!    the sample and its two neighbours (time and value). They must alternate (maximum,
//!    minimum, …) and lie at least a quarter of the linearised period apart; a wiggle that
//!    breaks either rule (another mode riding on the motion) is dropped, keeping the more
//!    extreme of two same-kind points.
//! 2. **Cycles**, one per turning point k with two successors (so consecutive cycles overlap by
//!    half a cycle): period `T = t_{k+2} − t_k`, frequency `1/T`, amplitude the mean of the two
//!    half peak-to-peak swings `Ā = (|a_k − a_{k+1}| + |a_{k+1} − a_{k+2}|)/4` (insensitive to
//!    a drift of the centre, which slip causes), the master's amplitude the same of `m` (`m` at
//!    the turning times of `a` by the parabola through the nearest three samples).
//! 3. **Damping** from energy, not from the envelope: `ΔD = D(t_{k+2}) − D(t_k)` (linear
//!    interpolation of the sampled `D`, which is flat at the turning points where the slip
//!    rate vanishes with the velocity) and the equivalent viscous damping ratio of a cycle of
//!    that amplitude, `ζ = ΔD / (4π E)`, `E = ½ m_k ω² Ā²` (`m_k = ψᵀMψ`, `ω = 2π/T`). For a
//!    linear oscillator with light viscous damping this is its ζ; for a Jenkins element it is
//!    Masing's `4 F_s (Ā − c) / (2π k_sec Ā²)`. An amplitude decrement `ln(A_k/A_{k+2})/2π`
//!    would need the decay to be resolved over a cycle: at ζ = 1e-4 the two amplitudes differ
//!    in the fourth digit, whereas `D` is integrated to the integrator's tolerance.
//!
//! Resolution: a turning point from a parabola through samples `h` apart is off by
//! `O(h³ a''')` in time, so with 64 samples per cycle a period is resolved to ~1e-5 relative
//! (the flatness tests measure it); a cycle's frequency and damping are averages over that
//! cycle, in which the amplitude decays by `e^{−2πζ}`.

use serde::Serialize;

/// One extracted cycle of a decay.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Cycle {
    /// Index of the cycle in its decay (0: the one starting at t = 0; consecutive cycles
    /// overlap by half a cycle).
    pub cycle: usize,
    /// Start and end of the cycle, s.
    pub t_start: f64,
    pub t_end: f64,
    /// Modal amplitude Ā, mm (the mode shape is normalised to a largest nodal translation of
    /// 1 mm, so this is the largest nodal translation of the modal part of the motion).
    pub modal_amplitude: f64,
    /// The master's displacement amplitude along the mode's master direction, mm (`None`
    /// where the mode does not move the master).
    pub master_amplitude: Option<f64>,
    /// Frequency 1/T, Hz.
    pub frequency_hz: f64,
    /// Equivalent viscous damping ratio ΔD / (4π E), dimensionless.
    pub damping_ratio: f64,
    /// Energy dissipated over the cycle, N·mm.
    pub dissipated: f64,
}

/// A sampled decay: output times (s), modal coordinate (mm), master displacement along the
/// mode's direction (mm; empty when the mode does not move the master) and dissipated energy
/// (N·mm), all of one length.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Samples {
    pub t: Vec<f64>,
    pub modal: Vec<f64>,
    pub master: Vec<f64>,
    pub dissipated: Vec<f64>,
}

/// A turning point: time (s), value of `a` (mm), and whether it is a maximum.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Turn {
    t: f64,
    a: f64,
    max: bool,
}

/// The vertex of the parabola through `(t0, y0), (t1, y1), (t2, y2)` (equally spaced; falls back
/// to the middle sample when the points are collinear).
fn vertex(t: [f64; 3], y: [f64; 3]) -> (f64, f64) {
    let h = 0.5 * (t[2] - t[0]);
    let d1 = 0.5 * (y[2] - y[0]);
    let d2 = y[2] - 2.0 * y[1] + y[0];
    if d2 == 0.0 || !d2.is_finite() {
        return (t[1], y[1]);
    }
    let x = (-d1 / d2).clamp(-1.0, 1.0);
    (t[1] + x * h, y[1] + 0.5 * d1 * x)
}

/// The turning points of `a` sampled at `t` (module docs, step 1); `min_gap` is the shortest
/// accepted distance between two (s).
fn turns(t: &[f64], a: &[f64], min_gap: f64) -> Vec<Turn> {
    let mut out = vec![Turn {
        t: t[0],
        a: a[0],
        max: a.len() < 2 || a[1] <= a[0],
    }];
    for i in 1..a.len().saturating_sub(1) {
        let (l, r) = (a[i] - a[i - 1], a[i + 1] - a[i]);
        let max = l > 0.0 && r <= 0.0;
        let min = l < 0.0 && r >= 0.0;
        if !(max || min) {
            continue;
        }
        let (tv, av) = vertex([t[i - 1], t[i], t[i + 1]], [a[i - 1], a[i], a[i + 1]]);
        let turn = Turn { t: tv, a: av, max };
        let last = out.last().copied().unwrap_or(turn);
        if last.max == max {
            // Two of a kind: keep the more extreme one (the other was a wiggle).
            let better = if max { av > last.a } else { av < last.a };
            if better && out.len() > 1 {
                *out.last_mut().expect("non-empty") = turn;
            }
        } else if tv - last.t >= min_gap {
            out.push(turn);
        }
    }
    out
}

/// `y` at time `x` by linear interpolation of the samples `(t, y)` (clamped at the ends).
fn interp(t: &[f64], y: &[f64], x: f64) -> f64 {
    let i = t.partition_point(|&ti| ti <= x);
    if i == 0 {
        return y[0];
    }
    if i >= t.len() {
        return y[t.len() - 1];
    }
    let w = (x - t[i - 1]) / (t[i] - t[i - 1]);
    y[i - 1] + w * (y[i] - y[i - 1])
}

/// `y` at time `x` by the parabola through the three samples nearest to it (a turning point
/// of a smooth curve, where linear interpolation is off by `O(h²)`).
fn interp_quadratic(t: &[f64], y: &[f64], x: f64) -> f64 {
    if t.len() < 3 {
        return interp(t, y, x);
    }
    let i = t.partition_point(|&ti| ti <= x).clamp(1, t.len() - 2);
    let (t0, t1, t2) = (t[i - 1], t[i], t[i + 1]);
    let l0 = (x - t1) * (x - t2) / ((t0 - t1) * (t0 - t2));
    let l1 = (x - t0) * (x - t2) / ((t1 - t0) * (t1 - t2));
    let l2 = (x - t0) * (x - t1) / ((t2 - t0) * (t2 - t1));
    l0 * y[i - 1] + l1 * y[i] + l2 * y[i + 1]
}

/// The cycles of a decay (module docs). `period` is the linearised period (s; turning points
/// closer than a quarter of it are wiggles), `modal_mass` = ψᵀMψ (t).
pub fn cycles(s: &Samples, period: f64, modal_mass: f64) -> Vec<Cycle> {
    if s.t.len() < 3 {
        return Vec::new();
    }
    let tp = turns(&s.t, &s.modal, 0.25 * period);
    let master_at = |x: f64| (!s.master.is_empty()).then(|| interp_quadratic(&s.t, &s.master, x));
    let mut out = Vec::new();
    for k in 0..tp.len().saturating_sub(2) {
        let (p0, p1, p2) = (tp[k], tp[k + 1], tp[k + 2]);
        let period = p2.t - p0.t;
        let amp = 0.25 * ((p0.a - p1.a).abs() + (p1.a - p2.a).abs());
        let master = match (master_at(p0.t), master_at(p1.t), master_at(p2.t)) {
            (Some(m0), Some(m1), Some(m2)) => Some(0.25 * ((m0 - m1).abs() + (m1 - m2).abs())),
            _ => None,
        };
        let dd = interp(&s.t, &s.dissipated, p2.t) - interp(&s.t, &s.dissipated, p0.t);
        let omega = 2.0 * std::f64::consts::PI / period;
        let energy = 0.5 * modal_mass * omega * omega * amp * amp;
        out.push(Cycle {
            cycle: k,
            t_start: p0.t,
            t_end: p2.t,
            modal_amplitude: amp,
            master_amplitude: master,
            frequency_hz: 1.0 / period,
            damping_ratio: dd / (4.0 * std::f64::consts::PI * energy),
            dissipated: dd,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A damped cosine sampled 64 times per period, with its exact dissipation.
    fn decay(f: f64, zeta: f64, cycles: f64) -> Samples {
        let w = 2.0 * std::f64::consts::PI * f;
        let wd = w * (1.0 - zeta * zeta).sqrt();
        let h = 1.0 / (64.0 * f);
        let n = (cycles / f / h) as usize;
        let mut s = Samples::default();
        for i in 0..=n {
            let t = i as f64 * h;
            let e = (-zeta * w * t).exp();
            let a = e * ((wd * t).cos() + zeta * w / wd * (wd * t).sin());
            s.t.push(t);
            s.modal.push(a);
            s.master.push(0.5 * a);
            s.dissipated.push(0.0);
        }
        // D(t) = E(0) − E(t) with unit modal mass: E = ½ (v² + ω² a²).
        for i in 0..s.t.len() {
            let t = s.t[i];
            let e = (-zeta * w * t).exp();
            let v = -e * w * w / wd * (wd * t).sin();
            let a = s.modal[i];
            s.dissipated[i] = 0.5 * w * w - 0.5 * (v * v + w * w * a * a);
        }
        s
    }

    #[test]
    fn a_damped_cosine_gives_its_frequency_and_damping() {
        let (f, zeta) = (40.0, 0.01);
        let c = cycles(&decay(f, zeta, 4.2), 1.0 / f, 1.0);
        assert!(c.len() >= 6, "{} cycles", c.len());
        let fd = f * (1.0f64 - zeta * zeta).sqrt();
        for x in &c {
            assert!((x.frequency_hz / fd - 1.0).abs() < 1e-5, "{x:?}");
            assert!((x.damping_ratio / zeta - 1.0).abs() < 0.02, "{x:?}");
            let m = x.master_amplitude.unwrap();
            assert!((m / x.modal_amplitude - 0.5).abs() < 1e-5, "{m} {x:?}");
        }
        assert!(
            (c[0].modal_amplitude - (-zeta * 2.0 * std::f64::consts::PI * 0.5).exp()).abs() < 0.02
        );
    }

    #[test]
    fn too_short_a_decay_has_no_cycle() {
        assert!(cycles(&decay(40.0, 0.0, 0.6), 1.0 / 40.0, 1.0).is_empty());
    }
}
