//! The co-simulation slave in safe Rust: the FMI 2.0 state machine, the variables' values, and
//! the reduced model stepped by [`jointrom::integrate::Stepper`]. The FFI layer ([`crate::ffi`])
//! only converts C arguments, catches panics and reports errors; every rule of the standard
//! that can be checked is checked here, and a broken rule is an `Err` with a message naming the
//! function, the variable or the value.
//!
//! ## States (FMI 2.0, section 4.2.4)
//!
//! ```text
//! Instantiated ──EnterInitializationMode──► Initialization ──ExitInitializationMode──► StepComplete
//!      ▲                                                                                 │  ▲  DoStep
//!      └──────────────── Reset (from any state) ─────────────── Terminate ◄──────────────┘──┘
//!                                                                  ▼
//! any error ──► Error  (only Get*, Reset and FreeInstance are then allowed)  Terminated
//! ```
//!
//! An `fmi2Error` means "the simulation cannot be continued with this instance" (FMI 2.0.4,
//! section 2.1.3), so every error — a wrong argument, a call in the wrong state, an integrator
//! failure — puts the instance into `Error`; the importer may read values, reset or free it.
//!
//! ## Time
//!
//! The model starts from rest at `fmi2SetupExperiment`'s `startTime` (0 if it is not called);
//! the reduced model's own load history is a function of absolute time. `fmi2DoStep(t, h)`
//! needs `t` to be the end of the previous step (to a relative 1e-9 of `max(|t|, h)`, round-off
//! of an importer's clock) and integrates to `t + h`; with a defined stop time it refuses to step
//! beyond it. A defined `tolerance` becomes CVODE's relative tolerance (the model description's
//! default experiment gives `jointrom transient`'s 1e-8).
//!
//! ## Parameters
//!
//! `mu`, `k_n`, `k_t` are `fixed`: set in `Instantiated` or `Initialization`, used when the
//! integrator is built at `fmi2ExitInitializationMode`. `load_scale` is `tunable` and the
//! inputs `continuous`: their values at a `fmi2DoStep` hold over that step
//! ([`jointrom::integrate::Stepper::set_load`], which restarts CVODE only when they changed).

use std::path::Path;

use jointrom::case::ContactSpec;
use jointrom::integrate::{EnergySample, Stepper, TransientOptions};
use jointrom::report::fmu::{guid, variable, vr, Causality, Variability, ROM_RESOURCE, VARIABLES};
use jointrom::rom::file::RomFile;
use jointrom::system::ReducedSystem;

/// A state of the FMI 2.0 co-simulation state machine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// After `fmi2Instantiate` or `fmi2Reset`.
    Instantiated,
    /// Between `fmi2EnterInitializationMode` and `fmi2ExitInitializationMode`.
    Initialization,
    /// Initialized; steps may be taken.
    StepComplete,
    /// After `fmi2Terminate`.
    Terminated,
    /// After any `fmi2Error`.
    Error,
}

impl Phase {
    fn name(self) -> &'static str {
        match self {
            Phase::Instantiated => "Instantiated",
            Phase::Initialization => "InitializationMode",
            Phase::StepComplete => "StepComplete",
            Phase::Terminated => "Terminated",
            Phase::Error => "Error",
        }
    }
}

/// Number of variables (value references `0..COUNT`).
const COUNT: usize = vr::COUNT as usize;

/// Relative tolerance on `currentCommunicationPoint` against the slave's time.
const TIME_TOLERANCE: f64 = 1e-9;

/// One FMU instance's model and state (see the module docs).
pub struct Slave {
    rom: RomFile,
    phase: Phase,
    /// The value of every variable, by value reference (outputs: at the current time).
    values: [f64; COUNT],
    start_time: f64,
    stop_time: Option<f64>,
    tolerance: Option<f64>,
    stepper: Option<Stepper<ReducedSystem>>,
}

/// A slave's result: `Err` carries the message for the logger.
pub type Outcome<T> = Result<T, String>;

impl Slave {
    /// Reads the reduced model from the resources folder `resources` and checks that it is the
    /// one the model description's GUID `fmu_guid` was made for.
    pub fn new(resources: &Path, fmu_guid: &str) -> Outcome<Slave> {
        // faer's dense kernels (the reduced model's checks at reading) run on the calling
        // thread: no rayon pool is started inside the importer's process (its threads would
        // outlive the instance). The setting is this binary's own copy of faer's.
        faer::set_global_parallelism(faer::Par::Seq);
        let path = resources.join(Path::new(ROM_RESOURCE).file_name().unwrap_or_default());
        let bytes = jointrom::files::read_bytes(&path)
            .map_err(|e| format!("cannot read the reduced model {}: {e}", path.display()))?;
        let expected = guid(&bytes);
        if expected != fmu_guid {
            return Err(format!(
                "{} does not belong to this FMU: its GUID would be {expected}, the model \
                 description's is {fmu_guid} (the file was changed or damaged)",
                path.display()
            ));
        }
        let text = String::from_utf8(bytes)
            .map_err(|_| format!("{} is not UTF-8 text", path.display()))?;
        let rom = RomFile::parse(&text, &path).map_err(|e| e.to_string())?;
        let mut slave = Slave {
            rom,
            phase: Phase::Instantiated,
            values: [0.0; COUNT],
            start_time: 0.0,
            stop_time: None,
            tolerance: None,
            stepper: None,
        };
        slave.reset_values();
        Ok(slave)
    }

    /// The reduced model's case name and dimension, for the log.
    pub fn describe(&self) -> String {
        format!(
            "reduced model of {} (r = {}, {} pairs)",
            self.rom.case, self.rom.dimension, self.rom.pairs
        )
    }

    /// The current state.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// Puts the instance into the error state (after any failed call).
    pub fn fail(&mut self) {
        self.phase = Phase::Error;
    }

    /// Start values everywhere, outputs at rest (0).
    fn reset_values(&mut self) {
        for v in &VARIABLES {
            self.values[v.vr as usize] = v.start_value(&self.rom).unwrap_or(0.0);
        }
    }

    /// `Ok` if the instance is in one of `allowed`, else the message for `function`.
    fn expect(&self, function: &str, allowed: &[Phase]) -> Outcome<()> {
        if allowed.contains(&self.phase) {
            Ok(())
        } else {
            let names: Vec<&str> = allowed.iter().map(|p| p.name()).collect();
            Err(format!(
                "{function} is not allowed in state {} (only in {})",
                self.phase.name(),
                names.join(", ")
            ))
        }
    }

    /// `fmi2SetupExperiment`.
    pub fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    ) -> Outcome<()> {
        self.expect("fmi2SetupExperiment", &[Phase::Instantiated])?;
        if let Some(tol) = tolerance {
            if !(tol.is_finite() && tol > 0.0 && tol < 1.0) {
                return Err(format!(
                    "fmi2SetupExperiment: tolerance must be in (0, 1), got {tol}"
                ));
            }
        }
        if !start.is_finite() {
            return Err(format!(
                "fmi2SetupExperiment: startTime must be finite, got {start} s"
            ));
        }
        if let Some(stop) = stop {
            if !(stop.is_finite() && stop > start) {
                return Err(format!(
                    "fmi2SetupExperiment: stopTime must be finite and after startTime {start} s, \
                     got {stop} s"
                ));
            }
        }
        self.tolerance = tolerance;
        self.start_time = start;
        self.stop_time = stop;
        Ok(())
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization(&mut self) -> Outcome<()> {
        self.expect("fmi2EnterInitializationMode", &[Phase::Instantiated])?;
        self.phase = Phase::Initialization;
        Ok(())
    }

    /// `fmi2ExitInitializationMode`: builds the integrator with the parameters set so far.
    pub fn exit_initialization(&mut self) -> Outcome<()> {
        self.expect("fmi2ExitInitializationMode", &[Phase::Initialization])?;
        let v = &self.values;
        let contact = ContactSpec {
            normal_stiffness: v[vr::K_N as usize],
            friction_coefficient: v[vr::MU as usize],
            stick_stiffness: v[vr::K_T as usize],
            // A per-area model's k_n, k_t are those of a pair of mean tributary area (its
            // joint operator carries each pair's share): the per-area values stay for reports.
            ..self.rom.contact
        };
        // The options of `jointrom transient`, with the exported τ and the importer's rtol.
        let mut opts = TransientOptions::default();
        opts.problem.tau = self.rom.friction_relaxation_time;
        if let Some(tol) = self.tolerance {
            opts.ode.rtol = tol;
        }
        let system = self
            .rom
            .system()
            .map_err(|e| format!("fmi2ExitInitializationMode: the reduced model: {e}"))?;
        let stepper = Stepper::new(system, self.start_time, &contact, &opts.ode, &opts.problem)
            .map_err(|e| format!("fmi2ExitInitializationMode: the integrator: {e}"))?;
        self.store_outputs(&stepper.sample().clone());
        self.stepper = Some(stepper);
        self.phase = Phase::StepComplete;
        Ok(())
    }

    /// `fmi2Terminate`.
    pub fn terminate(&mut self) -> Outcome<()> {
        self.expect("fmi2Terminate", &[Phase::StepComplete])?;
        self.phase = Phase::Terminated;
        Ok(())
    }

    /// `fmi2Reset`: back to `Instantiated` with the start values; the integrator is freed.
    pub fn reset(&mut self) {
        self.stepper = None;
        self.start_time = 0.0;
        self.stop_time = None;
        self.tolerance = None;
        self.reset_values();
        self.phase = Phase::Instantiated;
    }

    /// `fmi2GetReal`: `out[i]` = the value of `vrs[i]`.
    pub fn get_real(&self, vrs: &[u32], out: &mut [f64]) -> Outcome<()> {
        self.expect(
            "fmi2GetReal",
            &[
                Phase::Initialization,
                Phase::StepComplete,
                Phase::Terminated,
                Phase::Error,
            ],
        )?;
        if let Some(bad) = vrs.iter().find(|&&r| variable(r).is_none()) {
            return Err(format!(
                "fmi2GetReal: no Real variable has value reference {bad} (0..{})",
                vr::COUNT
            ));
        }
        for (o, &r) in out.iter_mut().zip(vrs) {
            *o = self.values[r as usize];
        }
        Ok(())
    }

    /// `fmi2SetReal`: checks every value first, then sets them all (or none).
    pub fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> Outcome<()> {
        self.expect(
            "fmi2SetReal",
            &[
                Phase::Instantiated,
                Phase::Initialization,
                Phase::StepComplete,
            ],
        )?;
        let before_init = self.phase != Phase::StepComplete;
        for (&r, &x) in vrs.iter().zip(values) {
            let v = variable(r).ok_or_else(|| {
                format!(
                    "fmi2SetReal: no Real variable has value reference {r} (0..{})",
                    vr::COUNT
                )
            })?;
            let name = v.name;
            if v.causality == Causality::Output {
                return Err(format!(
                    "fmi2SetReal: {name} is an output and cannot be set"
                ));
            }
            if v.variability == Variability::Fixed && !before_init {
                return Err(format!(
                    "fmi2SetReal: {name} is a fixed parameter: set it before \
                     fmi2ExitInitializationMode"
                ));
            }
            if !x.is_finite() {
                return Err(format!("fmi2SetReal: {name} = {x} is not finite"));
            }
            let ok = match r {
                vr::MU => x >= 0.0,
                vr::K_N | vr::K_T => x > 0.0,
                _ => true,
            };
            if !ok {
                let rule = if r == vr::MU { ">= 0" } else { "> 0 N/mm" };
                return Err(format!("fmi2SetReal: {name} must be {rule}, got {x}"));
            }
        }
        for (&r, &x) in vrs.iter().zip(values) {
            self.values[r as usize] = x;
        }
        Ok(())
    }

    /// `fmi2DoStep(t, h)`: integrates from `t` (the end of the last step) to `t + h`.
    pub fn do_step(&mut self, t: f64, h: f64) -> Outcome<()> {
        self.expect("fmi2DoStep", &[Phase::StepComplete])?;
        if !(h.is_finite() && h > 0.0) {
            return Err(format!(
                "fmi2DoStep: communicationStepSize must be finite and positive, got {h} s"
            ));
        }
        let stepper = self
            .stepper
            .as_mut()
            .ok_or("fmi2DoStep: no integrator (internal error)")?;
        let now = stepper.t();
        if !(t.is_finite() && (t - now).abs() <= TIME_TOLERANCE * now.abs().max(h)) {
            return Err(format!(
                "fmi2DoStep: currentCommunicationPoint {t} s is not the FMU's time {now} s (a step \
                 must start where the last one ended)"
            ));
        }
        let t_next = t + h;
        if let Some(stop) = self.stop_time {
            if t_next > stop + TIME_TOLERANCE * stop.abs().max(h) {
                return Err(format!(
                    "fmi2DoStep: the step to {t_next} s goes past the stopTime {stop} s given to \
                     fmi2SetupExperiment"
                ));
            }
        }
        let v = &self.values;
        let mut master = [0.0; 6];
        master.copy_from_slice(&v[vr::MASTER_FX as usize..=vr::MASTER_MZ as usize]);
        stepper
            .set_load(v[vr::LOAD_SCALE as usize], master)
            .map_err(|e| format!("fmi2DoStep: {e}"))?;
        let sample = *stepper
            .advance(t_next)
            .map_err(|e| format!("fmi2DoStep from {t} s to {t_next} s: {e}"))?;
        self.store_outputs(&sample);
        Ok(())
    }

    /// The outputs of `s` into the values.
    fn store_outputs(&mut self, s: &EnergySample) {
        let i0 = vr::MASTER_UX as usize;
        self.values[i0..i0 + 6].copy_from_slice(&s.master);
        self.values[vr::CONTACT_FORCE_NORM as usize] = s.contact_force_norm;
        self.values[vr::FRICTION_FORCE_NORM as usize] = s.friction_force_norm;
    }

    /// The time of the last completed step, s (`fmi2LastSuccessfulTime`).
    pub fn last_successful_time(&self) -> f64 {
        self.stepper.as_ref().map_or(self.start_time, |s| s.t())
    }

    /// Integrator statistics for the log: steps, restarts after input changes.
    pub fn statistics(&self) -> Option<String> {
        self.stepper.as_ref().map(|s| {
            let st = s.stats();
            let (restarts, events) = s.restarts();
            format!(
                "t = {} s: {} CVODE steps, {} right-hand sides, {} Newton iterations, {} \
                 restarts after input changes, {events} events",
                s.t(),
                st.steps,
                st.rhs_evals,
                st.nonlinear_iterations,
                restarts
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A one-coordinate reduced model (`rom.json` text): a 1 t mass on a 10⁴ N/mm spring whose
    /// coordinate is the master's u_y and the one pair's gap; the master load −1 N along y
    /// (half-cosine ramp over 10 ms) closes the pair.
    fn tiny_rom() -> String {
        let zero = [0.0];
        serde_json::json!({
            "schema": "jointrom-rom", "version": 1, "case": "tiny",
            "basis": {"kind": "modes", "g": 0, "nu": 1, "threshold": 0.999, "w": []},
            "dimension": 1, "pairs": 1,
            "mass": [[1.0]], "stiffness": [[1e4]],
            "joint_operator": [[1.0], zero, zero],
            "master_rows": [zero, [1.0], zero, zero, zero, zero],
            "reduced_loads": [zero, [1.0], zero, zero, zero, zero],
            "master_load": {"fy": -1.0},
            "load_ramp": {"shape": "half_cosine", "duration": 0.01},
            "contact": {"normal_stiffness": 1e4, "friction_coefficient": 0.25,
                        "stick_stiffness": 1e4},
            "friction_relaxation_time": 1e-6, "coordinate_size": [1.0], "end_time": 0.05
        })
        .to_string()
    }

    /// A resources folder `name` holding `text` as rom.json; the folder and the GUID.
    fn resources(name: &str, text: &str) -> (std::path::PathBuf, String) {
        let dir =
            std::env::temp_dir().join(format!("jointrom_fmu_slave_{}_{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("rom.json"), text).unwrap();
        (dir, guid(text.as_bytes()))
    }

    fn slave(name: &str) -> Slave {
        let (dir, g) = resources(name, &tiny_rom());
        Slave::new(&dir, &g).unwrap()
    }

    #[test]
    fn a_run_follows_the_state_machine() {
        let mut s = slave("run");
        assert!(s
            .get_real(&[vr::MASTER_UY], &mut [0.0])
            .unwrap_err()
            .contains("Instantiated"));
        s.setup_experiment(None, 0.0, Some(0.02)).unwrap();
        s.set_real(&[vr::MU, vr::MASTER_FY], &[0.3, 0.0]).unwrap();
        s.enter_initialization().unwrap();
        s.exit_initialization().unwrap();
        assert_eq!(s.phase(), Phase::StepComplete);
        let mut out = [f64::NAN; 3];
        let outs = [vr::MU, vr::MASTER_UY, vr::CONTACT_FORCE_NORM];
        s.get_real(&outs, &mut out).unwrap();
        assert_eq!(out, [0.3, 0.0, 0.0], "at rest");
        for k in 0..20 {
            s.do_step(k as f64 * 1e-3, 1e-3).unwrap();
        }
        s.get_real(&outs, &mut out).unwrap();
        assert!(out[1] < 0.0 && out[2] > 0.0, "pushed into contact: {out:?}");
        assert!((s.last_successful_time() - 0.02).abs() < 1e-15);
        assert!(s.statistics().unwrap().contains("CVODE steps"));
        let e = s.do_step(0.02, 1e-3).unwrap_err();
        assert!(e.contains("past the stopTime"), "{e}");
        s.terminate().unwrap();
        assert!(s.do_step(0.02, 1e-3).unwrap_err().contains("Terminated"));
        s.reset();
        assert_eq!(s.phase(), Phase::Instantiated);
        assert_eq!(s.values[vr::MU as usize], 0.25, "start values back");
    }

    #[test]
    fn bad_arguments_are_refused_with_their_names() {
        let mut s = slave("args");
        for (tol, start, stop, what) in [
            (Some(0.0), 0.0, None, "tolerance"),
            (Some(f64::NAN), 0.0, None, "tolerance"),
            (None, f64::INFINITY, None, "startTime"),
            (None, 1.0, Some(0.5), "stopTime"),
        ] {
            let e = s.setup_experiment(tol, start, stop).unwrap_err();
            assert!(e.contains(what), "{e}");
        }
        // All or nothing.
        let e = s
            .set_real(&[vr::LOAD_SCALE, vr::K_T], &[2.0, 0.0])
            .unwrap_err();
        assert!(e.contains("k_t must be > 0"), "{e}");
        assert_eq!(s.values[vr::LOAD_SCALE as usize], 1.0);
        let e = s.set_real(&[vr::COUNT], &[1.0]).unwrap_err();
        assert!(e.contains("value reference 18"), "{e}");
        s.enter_initialization().unwrap();
        s.exit_initialization().unwrap();
        assert!(s
            .set_real(&[vr::K_N], &[1.0])
            .unwrap_err()
            .contains("fixed parameter"));
        s.set_real(&[vr::LOAD_SCALE], &[0.5]).unwrap();
        let e = s.do_step(1.0, 1e-3).unwrap_err();
        assert!(e.contains("is not the FMU's time 0 s"), "{e}");
        assert!(s
            .do_step(0.0, -1e-3)
            .unwrap_err()
            .contains("communicationStepSize"));
    }

    #[test]
    fn a_foreign_or_damaged_reduced_model_is_refused() {
        let (dir, g) = resources("foreign", &tiny_rom());
        let e = Slave::new(&dir, "{not-the-guid}").err().unwrap();
        assert!(
            e.contains("does not belong to this FMU") && e.contains(&g),
            "{e}"
        );
        let bad = tiny_rom().replace("\"dimension\":1", "\"dimension\":2");
        assert_ne!(bad, tiny_rom());
        let (dir, g) = resources("damaged", &bad);
        let e = Slave::new(&dir, &g).err().unwrap();
        assert!(e.contains("rom.json") && e.contains("mass"), "{e}");
        let e = Slave::new(Path::new("/nonexistent/resources"), &g)
            .err()
            .unwrap();
        assert!(e.contains("cannot read the reduced model"), "{e}");
    }
}
