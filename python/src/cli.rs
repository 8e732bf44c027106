//! The `restpose` command line inside the extension: the binary's own modules (`src/cli/` of
//! the library crate, compiled here as they are in the binary), dispatched as `src/main.rs`
//! does. The wheel's `restpose` script calls [`run_cli`] with its arguments, so the command
//! installed by `pip` is the same program as `cargo install restpose`.

#[path = "../../src/cli/mod.rs"]
mod commands;

use clap::Parser;
use commands::args::{Cli, Command};
use pyo3::prelude::*;
use std::io::Write;

/// Runs the `restpose` command line on `argv` (program name first) and returns its exit code;
/// the process is not exited.
#[pyfunction]
pub(crate) fn run_cli(py: Python<'_>, argv: Vec<String>) -> i32 {
    py.detach(|| {
        let cli = match Cli::try_parse_from(argv) {
            Ok(cli) => cli,
            Err(e) => {
                let _ = e.print();
                return e.exit_code();
            }
        };
        let out = match &cli.command {
            Command::Analyze(a) => commands::analyze::run(a),
            Command::View(a) => commands::view::run(a),
            Command::Verify(a) => commands::verify::run(a),
            Command::Check(a) => commands::check::run(a),
            Command::Generate(a) => commands::generate::run(a),
        };
        let code = match out {
            Ok(code) => i32::from(code),
            Err(e) => {
                eprintln!("error: {e:#}");
                i32::from(commands::exit::INPUT)
            }
        };
        let _ = std::io::stdout().flush();
        code
    })
}
