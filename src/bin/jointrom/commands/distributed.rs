//! `jointrom distributed`: the Craig–Bampton eigen solve and the TVD multi-right-hand-side
//! solve on PETSc/SLEPc (+ MUMPS) under `mpirun`, compared with the native path
//! (`jointrom::reduction::distributed`, `docs/distributed.md`). Opt-in: needs `slepc-dev` and
//! `openmpi-bin` and the program built by `scripts/dist.sh build`.

use std::path::{Path, PathBuf};
use std::process::Command;

use clap::Args;
use serde_json::json;

use jointrom::error::{FlagError, ReductionError};
use jointrom::reduction::distributed::{self, Comparison, NativeReference};
use jointrom::Error;

use crate::common::print_json;

/// Where `scripts/dist.sh build` puts the PETSc program.
const DEFAULT_PROGRAM: &str = "target/distributed/jointrom_slepc";

/// The environment variable naming the PETSc program (else [`DEFAULT_PROGRAM`]).
const PROGRAM_VAR: &str = "JOINTROM_SLEPC";

#[derive(Args)]
pub struct DistributedArgs {
    /// Case file, matrix map or built-in name.
    case: String,
    /// Fixed-interface modes ν (as `jointrom basis --nu`).
    #[arg(long, default_value_t = 10)]
    nu: usize,
    /// MPI rank counts to run, comma-separated (each one `mpirun -n R`).
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    ranks: Vec<usize>,
    /// The PETSc program (default: $JOINTROM_SLEPC, else target/distributed/jointrom_slepc,
    /// built by `scripts/dist.sh build`).
    #[arg(long)]
    program: Option<PathBuf>,
    /// The MPI launcher.
    #[arg(long, default_value = "mpirun")]
    mpirun: String,
    /// SLEPc's convergence tolerance (relative residual of each pair).
    #[arg(long, default_value_t = 1e-12)]
    tol: f64,
    /// Keep the job folder here (PETSc binary K_ii, M_ii, K, R and each run's results);
    /// default: a temporary folder, removed afterwards.
    #[arg(long)]
    keep: Option<PathBuf>,
    /// One JSON document on stdout.
    #[arg(long)]
    json: bool,
}

fn program(a: &DistributedArgs) -> Result<PathBuf, Error> {
    let p = a
        .program
        .clone()
        .or_else(|| std::env::var_os(PROGRAM_VAR).map(PathBuf::from))
        .unwrap_or_else(|| PathBuf::from(DEFAULT_PROGRAM));
    if !p.is_file() {
        return Err(ReductionError::DistributedProgram {
            program: p,
            var: PROGRAM_VAR,
        }
        .into());
    }
    Ok(p)
}

/// Runs `mpirun -n ranks PROGRAM -dir JOB -out OUT -nev ν -tol TOL`.
fn run_ranks(a: &DistributedArgs, prog: &Path, job: &Path, ranks: usize) -> Result<(), Error> {
    let out = distributed::output_dir(job, ranks);
    jointrom::files::create_dir(&out)?;
    let output = Command::new(&a.mpirun)
        .arg("-n")
        .arg(ranks.to_string())
        .arg("--oversubscribe")
        .arg(prog)
        .arg("-dir")
        .arg(job)
        .arg("-out")
        .arg(&out)
        .arg("-nev")
        .arg(a.nu.to_string())
        .arg("-tol")
        .arg(format!("{:e}", a.tol))
        // Open MPI refuses root without these; one BLAS thread per rank.
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMP_NUM_THREADS", "1")
        .env("OPENBLAS_NUM_THREADS", "1")
        .output()
        .map_err(|e| Error::Io {
            file: PathBuf::from(&a.mpirun),
            source: e,
        })?;
    if !output.status.success() {
        let err = String::from_utf8_lossy(&output.stderr);
        let tail: Vec<&str> = err
            .lines()
            .filter(|l| !l.contains("Configure options"))
            .take(12)
            .collect();
        return Err(ReductionError::DistributedFailed {
            mpirun: a.mpirun.clone(),
            ranks,
            program: prog.to_path_buf(),
            status: output.status.to_string(),
            stderr: jointrom::files::printable(&tail.join("\n")).to_string(),
        }
        .into());
    }
    Ok(())
}

pub fn run(a: DistributedArgs) -> Result<(), Error> {
    if a.ranks.is_empty() || a.ranks.contains(&0) {
        return Err(FlagError::Ranks.into());
    }
    if !(a.tol > 0.0 && a.tol < 1.0) {
        return Err(FlagError::Value {
            flag: "tol",
            value: a.tol.to_string(),
            need: "must lie in (0, 1)",
        }
        .into());
    }
    let prog = program(&a)?;
    let model = crate::common::load_model(&a.case)?;
    let temp;
    let job = match &a.keep {
        Some(dir) => dir.clone(),
        None => {
            temp = tempfile::tempdir().map_err(|e| {
                jointrom::files::write_err(&std::env::temp_dir(), "create folder", e)
            })?;
            temp.path().join("job")
        }
    };
    let native = distributed::prepare(&model, a.nu, &job)?;
    let mut runs = Vec::new();
    for &r in &a.ranks {
        run_ranks(&a, &prog, &job, r)?;
        runs.push(distributed::compare(
            &model,
            &native,
            &distributed::output_dir(&job, r),
        )?);
    }
    if a.json {
        print_json(&json!({
            "case": model.name,
            "dofs": model.dofs(),
            "interior_dofs": model.dofs() - 6,
            "joint_pairs": model.pair_count(),
            "nu": a.nu,
            "rhs_columns": native.rhs.ncols(),
            "native_seconds": native.seconds,
            "native_solve_backward": native.solve_backward,
            "runs": runs,
        }));
    } else {
        print_table(&model.name, model.dofs(), &native, &runs);
    }
    Ok(())
}

fn print_table(name: &str, n: usize, native: &NativeReference, runs: &[Comparison]) {
    let nu = native.modes.eigenvalues.len();
    let s = &native.seconds;
    println!(
        "{}: {n} DOF, ν = {nu} fixed-interface modes, {} TVD right-hand sides",
        jointrom::files::printable(name),
        native.rhs.ncols()
    );
    println!(
        "| path | freq. rel. diff | span sin θ | mode backward | Z rel. diff | Z backward | \
         eigen s | factor K s | solve s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    println!(
        "| native (faer) | | | | | {:.1e} | {:.2} | {:.2} | {:.2} |",
        native.solve_backward, s.eigen, s.factor, s.solve
    );
    for c in runs {
        let t = &c.petsc.seconds;
        println!(
            "| PETSc/SLEPc, {} rank{} | {:.1e} | {:.1e} | {:.1e} | {:.1e} | {:.1e} | {:.2} | {:.2} | {:.2} |",
            c.ranks,
            if c.ranks == 1 { "" } else { "s" },
            c.frequency_rel_diff,
            c.span_sine,
            c.mode_backward,
            c.solve_rel_diff,
            c.solve_backward,
            t.eigen,
            t.factor,
            t.solve
        );
    }
    println!(
        "native: TVD base and right-hand sides {:.2} s, job export {:.2} s; PETSc eigen = \
         MUMPS factor of K_ii + Krylov–Schur, loads and writes not included",
        s.rhs, s.export
    );
}
