//! `jointrom` command line: a thin layer over the library. The subcommands are defined in
//! [`cli`], each one runs in its own module of [`commands`].

mod args;
mod cli;
mod commands;
mod common;
mod summary;

use std::process::ExitCode;
use std::sync::LazyLock;

use clap::Parser;

use cli::Cli;

fn main() -> ExitCode {
    LazyLock::force(&common::COMMAND_START);
    quiet_broken_pipe();
    // Bit-identical results for any number of threads: faer's parallel kernels split their
    // sums by the thread count, so the dense linear algebra runs sequentially (the offline
    // stage of the built-in scenes takes well under a second either way); parallel work is
    // done over independent runs (sweeps), whose results do not depend on the split.
    faer::set_global_parallelism(faer::Par::Seq);
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let args: Vec<String> = std::env::args_os()
                .map(|s| s.to_string_lossy().into_owned())
                .collect();
            match cli::legacy_value_error(&e, &args) {
                Some(err) => return fail(&err),
                None => e.exit(),
            }
        }
    };
    // Every output a failing command created is removed again: a failed export or report
    // leaves no partial files.
    jointrom::files::journal_start();
    match cli.load_options() {
        Ok(opts) => common::set_load_options(opts),
        Err(e) => return fail(&e),
    }
    match cli.command.run() {
        Ok(()) => {
            jointrom::files::journal_commit();
            ExitCode::SUCCESS
        }
        Err(e) => {
            let removed = jointrom::files::journal_rollback();
            if removed > 0 {
                eprintln!("jointrom: removed {removed} partial output(s) of the failed command");
            }
            fail(&e)
        }
    }
}

/// A closed standard output (`jointrom info X | head -0`) ends the process quietly with status
/// 141, as SIGPIPE would end a C program, instead of a panic in `println!` (Rust ignores
/// SIGPIPE, so the write fails with EPIPE and `println!` panics on it).
fn quiet_broken_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let text = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if text.starts_with("failed printing to stdout") && text.contains("Broken pipe") {
            std::process::exit(141);
        }
        default(info);
    }));
}

fn fail(e: &jointrom::Error) -> ExitCode {
    eprintln!("jointrom: error: {e}");
    // Errors from inside the numerics name no file; say which inputs they came from.
    if matches!(
        e,
        jointrom::Error::LinearAlgebra(_)
            | jointrom::Error::Sundials { .. }
            | jointrom::Error::Callback { .. }
    ) {
        for input in common::inputs() {
            eprintln!("jointrom:   in {}", jointrom::files::printable(&input));
        }
    }
    ExitCode::FAILURE
}
