//! The `tracelab` command: headless renders and image comparison.

mod cli;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    if !args.opens_window() {
        quiet_broken_pipe();
    }
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Output piped into a command that stops reading early (`tracelab compare
/// a.exr b.exr | head -1`) ends the process quietly, as it ends other
/// command-line tools: Rust ignores SIGPIPE, which made the next print
/// panic. The window keeps Rust's default (its display connection's errors
/// are its own to report).
fn quiet_broken_pipe() {
    #[cfg(unix)]
    {
        unsafe extern "C" {
            fn signal(signum: std::ffi::c_int, handler: usize) -> usize;
        }
        // SIGPIPE is 13 and SIG_DFL is 0 on Linux and macOS.
        // SAFETY: restores one signal's default action before any thread
        // of this process starts.
        unsafe {
            signal(13, 0);
        }
    }
}
