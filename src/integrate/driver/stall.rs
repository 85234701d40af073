//! Runs that cannot finish in reasonable time, told from their own statistics.
//!
//! Two configurations make a run crawl without failing: event location whose roots fire every
//! step or two while the model is expensive per step (the full FE model with events on), and a
//! step size that keeps collapsing output interval after output interval (BDF orders 3–5 on
//! the undamped structure's modes, a tight velocity tolerance). Both are detected at every root
//! and every output from the integrator's counters and the run's CPU time, and stop the run as
//! [`RunStatus::Stalled`](super::RunStatus::Stalled) with a message naming the flag to change.
//!
//! ## Thresholds (measured)
//!
//! - **Chatter**: in [`CHATTER_WINDOWS`] windows in a row of at least [`WINDOW_CPU_S`] CPU
//!   seconds each, at least [`CHATTER_ROOTS_PER_STEP`] roots per step *and* less than
//!   [`CHATTER_MIN_PROGRESS`] s of simulated time per CPU second. Healthy reduced runs with
//!   events on chatter just as often (0.36–0.67 roots per step over whole stability-map cells,
//!   0.67 in the friction bar's contact onset) but advance 1.1e-5 s or more per second (the
//!   slowest: that onset, which lasts under 2 s); the full friction bar with events on and
//!   Newton advances 3.6e-7–8.6e-7 s per CPU second while chattering (with functional
//!   iteration about 5.5e-6: those runs end on the wall-clock budget instead).
//! - **Step collapse**: steps per output interval growing at least [`COLLAPSE_GROWTH`]-fold in
//!   each of [`COLLAPSE_INTERVALS`] intervals in a row, to at least [`COLLAPSE_MIN_STEPS`]
//!   steps and [`COLLAPSE_MIN_CPU_S`] CPU seconds in the last one. The full friction bar at max
//!   order 5 and velocity scale 1 takes 135, 582, 2710, 5995 steps in its 4th–7th intervals
//!   (1.1 and 2.5 CPU s for the last two); healthy runs (friction bar and multilayer, full and
//!   reduced, events off and on) never exceed 1.9 s in one interval, and where their steps grow
//!   fourfold twice in a row the interval costs well under a second.
//!
//! ## The clock
//!
//! The thread's CPU clock is a system call (the monotonic clock is read in user space), and a
//! reduced run reaches an output every 10–40 µs of CPU: read at every output it was
//! 1 % of a tolerance model's CPU. The watch reads it only once [`CPU_CLOCK_INTERVAL`] of wall
//! time has passed since its last reading, and otherwise keeps that reading. A thread's CPU
//! time grows no faster than the wall time, so every mark's CPU time lags its true value by
//! less than that interval, and a window's or interval's CPU time is off by less than it:
//! 1 % of the least CPU time either rule acts on.

use std::time::Instant;

use super::thread_cpu_s;
use crate::integrate::mechanical::DEFAULT_VELOCITY_SCALE;
use crate::integrate::problem::OdeStats;

/// Least CPU time of a chatter window, s.
pub const WINDOW_CPU_S: f64 = 1.0;
/// Chattering windows in a row that stop a run.
pub const CHATTER_WINDOWS: usize = 2;
/// Roots per step over a window from which events count as chattering.
pub const CHATTER_ROOTS_PER_STEP: f64 = 0.3;
/// Simulated time per CPU second below which a chattering run stops, s/s.
pub const CHATTER_MIN_PROGRESS: f64 = 3e-6;
/// Growth of the steps per output interval, from one interval to the next, of a collapse.
pub const COLLAPSE_GROWTH: f64 = 2.0;
/// Growing intervals in a row that make a collapse.
pub const COLLAPSE_INTERVALS: usize = 3;
/// Least steps in the last interval of a collapse.
pub const COLLAPSE_MIN_STEPS: u64 = 1000;
/// Least CPU time of the last interval of a collapse, s.
pub const COLLAPSE_MIN_CPU_S: f64 = 1.0;
/// Wall time between two readings of the thread's CPU clock, s (module docs, "The clock").
pub const CPU_CLOCK_INTERVAL: f64 = 0.01;

/// Why a run was stopped before its end ([`RunStatus::Stalled`](super::RunStatus::Stalled)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stall {
    /// Roots every few steps at a crawl: the event handling chatters.
    Chatter,
    /// The step size collapsed interval after interval.
    StepCollapse,
}

impl Stall {
    /// `chatter` or `step_collapse`.
    pub fn name(self) -> &'static str {
        match self {
            Stall::Chatter => "chatter",
            Stall::StepCollapse => "step_collapse",
        }
    }
}

/// The run's counters at one moment.
#[derive(Clone, Copy, Debug)]
struct Mark {
    t: f64,
    steps: u64,
    error_test_failures: u64,
    roots: u64,
    cpu: f64,
}

impl Mark {
    fn now(t: f64, stats: &OdeStats, roots: u64, cpu: f64) -> Mark {
        Mark {
            t,
            steps: stats.steps,
            error_test_failures: stats.error_test_failures,
            roots,
            cpu,
        }
    }
}

/// The thread's CPU clock, read at most once per [`CPU_CLOCK_INTERVAL`] of wall time (module
/// docs, "The clock").
#[derive(Clone, Copy, Debug)]
struct CpuClock {
    /// When it was last read, and what it read (s).
    read_at: Instant,
    cpu: f64,
}

impl CpuClock {
    fn new() -> CpuClock {
        CpuClock {
            read_at: Instant::now(),
            cpu: thread_cpu_s(),
        }
    }

    /// The thread's CPU time, s: read anew if the last reading is [`CPU_CLOCK_INTERVAL`] old
    /// (wall time), else that reading.
    fn now(&mut self) -> f64 {
        let now = Instant::now();
        if now.duration_since(self.read_at).as_secs_f64() >= CPU_CLOCK_INTERVAL {
            *self = CpuClock {
                read_at: now,
                cpu: thread_cpu_s(),
            };
        }
        self.cpu
    }
}

/// Watches one run's statistics for the two stalls.
#[derive(Clone, Debug)]
pub(super) struct StallWatch {
    max_order: usize,
    clock: CpuClock,
    velocity_scale: f64,
    window: Mark,
    /// The marks at the last outputs (at most `COLLAPSE_INTERVALS + 1`).
    outputs: Vec<Mark>,
    /// Chattering windows in a row.
    chattering: usize,
    /// The stall found, if any.
    pub(super) stalled: Option<Stall>,
}

impl StallWatch {
    pub(super) fn new(t0: f64, max_order: usize, velocity_scale: f64) -> StallWatch {
        let clock = CpuClock::new();
        let start = Mark::now(t0, &OdeStats::default(), 0, clock.cpu);
        StallWatch {
            max_order,
            clock,
            velocity_scale,
            window: start,
            outputs: vec![start],
            chattering: 0,
            stalled: None,
        }
    }

    /// At a root: the reason to stop, if the run chatters.
    pub(super) fn at_root(&mut self, t: f64, stats: &OdeStats, roots: u64) -> Option<String> {
        let cpu = self.clock.now();
        self.chatter(Mark::now(t, stats, roots, cpu))
    }

    /// At an output: the reason to stop, if the run chatters or its step collapsed.
    pub(super) fn at_output(&mut self, t: f64, stats: &OdeStats, roots: u64) -> Option<String> {
        let cpu = self.clock.now();
        let now = Mark::now(t, stats, roots, cpu);
        if let Some(reason) = self.chatter(now) {
            return Some(reason);
        }
        self.outputs.push(now);
        if self.outputs.len() > COLLAPSE_INTERVALS + 1 {
            self.outputs.remove(0);
        }
        self.collapse(stats)
    }

    fn chatter(&mut self, now: Mark) -> Option<String> {
        let w = self.window;
        let cpu = now.cpu - w.cpu;
        // NaN (no thread clock) never reaches the window's length: no chatter stop.
        if cpu.is_nan() || cpu < WINDOW_CPU_S {
            return None;
        }
        self.window = now;
        let (steps, roots, dt) = (now.steps - w.steps, now.roots - w.roots, now.t - w.t);
        let per_step = roots as f64 / steps.max(1) as f64;
        let progress = dt / cpu;
        if !(per_step >= CHATTER_ROOTS_PER_STEP && progress < CHATTER_MIN_PROGRESS) {
            self.chattering = 0;
            return None;
        }
        self.chattering += 1;
        if self.chattering < CHATTER_WINDOWS {
            return None;
        }
        self.stalled = Some(Stall::Chatter);
        Some(format!(
            "the events chatter: {roots} roots in {steps} steps while the run advanced only \
             {dt:.3e} s in {cpu:.1} CPU s (less than {CHATTER_MIN_PROGRESS:e} s per CPU second, \
             so the end is hours away): run with `--events off`"
        ))
    }

    fn collapse(&mut self, stats: &OdeStats) -> Option<String> {
        if self.outputs.len() < COLLAPSE_INTERVALS + 1 {
            return None;
        }
        let steps: Vec<u64> = self
            .outputs
            .windows(2)
            .map(|p| p[1].steps - p[0].steps)
            .collect();
        let growing = steps
            .windows(2)
            .all(|p| p[0] > 0 && p[1] as f64 >= COLLAPSE_GROWTH * p[0] as f64);
        let (a, b) = (
            self.outputs[COLLAPSE_INTERVALS - 1],
            self.outputs[COLLAPSE_INTERVALS],
        );
        let last = b.steps - a.steps;
        let cpu = b.cpu - a.cpu;
        if !(growing && last >= COLLAPSE_MIN_STEPS && cpu >= COLLAPSE_MIN_CPU_S) {
            return None;
        }
        self.stalled = Some(Stall::StepCollapse);
        let mut advice = Vec::new();
        if self.max_order > 2 {
            advice.push(
                "`--max-order 2` (BDF orders 3–5 are not stable on the undamped structure's \
                 modes)"
                    .to_string(),
            );
        }
        if self.velocity_scale < DEFAULT_VELOCITY_SCALE {
            advice.push(format!(
                "a larger `--velocity-scale` (the default {DEFAULT_VELOCITY_SCALE:e} 1/s; {} \
                 holds every fast mode to a far tighter displacement tolerance)",
                self.velocity_scale
            ));
        }
        if advice.is_empty() {
            advice.push("a looser `--rtol`/`--atol`, or a reduced model".to_string());
        }
        Some(format!(
            "the step size collapsed: {} steps in the last {COLLAPSE_INTERVALS} output intervals \
             ({} error-test failures and {cpu:.1} CPU s in the last; last step {:.2e} s at \
             order {}), each interval costing at least {COLLAPSE_GROWTH}× the one before: run \
             with {}",
            steps
                .iter()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            b.error_test_failures - a.error_test_failures,
            stats.last_step,
            stats.last_order,
            advice.join(" or ")
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mark(t: f64, steps: u64, roots: u64, cpu: f64) -> Mark {
        Mark {
            t,
            steps,
            error_test_failures: 0,
            roots,
            cpu,
        }
    }

    fn watch() -> StallWatch {
        let start = mark(0.0, 0, 0, 0.0);
        StallWatch {
            max_order: 5,
            clock: CpuClock::new(),
            velocity_scale: 1.0,
            window: start,
            outputs: vec![start],
            chattering: 0,
            stalled: None,
        }
    }

    #[test]
    fn chatter_needs_many_roots_and_a_crawl() {
        // The full model's chatter: 0.67 roots per step, 3e-8 s in a CPU second.
        let mut w = watch();
        assert!(w.chatter(mark(8e-7, 300, 200, 1.1)).is_none());
        assert!(w.chatter(mark(1.6e-6, 600, 400, 2.2)).is_some());
        assert_eq!(w.stalled, Some(Stall::Chatter));
        // One window of chatter between healthy ones does not stop a run.
        let mut w = watch();
        assert!(w.chatter(mark(8e-7, 300, 200, 1.1)).is_none());
        assert!(w.chatter(mark(1e-4, 600, 200, 2.2)).is_none());
        assert!(w.chatter(mark(1e-4 + 8e-7, 900, 400, 3.3)).is_none());
        // A reduced model chattering as often but advancing 1e-5 s per CPU second.
        let mut w = watch();
        assert!(w.chatter(mark(1.1e-5, 30_000, 20_000, 1.1)).is_none());
        // A crawl without roots is not chatter; a short window is not judged.
        let mut w = watch();
        assert!(w.chatter(mark(3e-8, 300, 0, 1.1)).is_none());
        assert!(w.chatter(mark(3.1e-8, 600, 400, 1.5)).is_none());
        assert!(w.stalled.is_none());
    }

    #[test]
    fn the_cpu_clock_is_read_only_after_its_interval() {
        use std::time::Duration;
        // A reading younger than the interval is kept (a reading "from the future" is young).
        let mut clock = CpuClock {
            read_at: Instant::now() + Duration::from_secs(3600),
            cpu: -1.0,
        };
        assert_eq!(clock.now(), -1.0);
        // An old one is replaced by the thread's clock.
        let Some(old) = Instant::now().checked_sub(Duration::from_secs(1)) else {
            return;
        };
        clock.read_at = old;
        let cpu = clock.now();
        assert!(cpu.is_nan() || cpu >= 0.0, "{cpu}");
        assert!(clock.read_at > old);
    }

    #[test]
    fn collapse_needs_growth_steps_and_cost() {
        let run = |intervals: &[(u64, f64)]| {
            let mut w = watch();
            let (mut steps, mut cpu) = (0, 0.0);
            for &(n, c) in intervals {
                steps += n;
                cpu += c;
                w.outputs.push(mark(0.0, steps, 0, cpu));
                if w.outputs.len() > COLLAPSE_INTERVALS + 1 {
                    w.outputs.remove(0);
                }
            }
            w.collapse(&OdeStats::default())
        };
        // The full model at max order 5, velocity scale 1.
        let stop = run(&[(52, 0.1), (135, 0.2), (582, 0.6), (2710, 3.1)]).unwrap();
        assert!(stop.contains("--max-order 2") && stop.contains("--velocity-scale"));
        // The same growth, cheap (a reduced model), or expensive without growth.
        assert!(run(&[(52, 0.0), (135, 0.0), (582, 0.0), (2710, 0.3)]).is_none());
        assert!(run(&[(2400, 1.0), (2000, 1.0), (2500, 2.5), (2463, 2.1)]).is_none());
    }
}
