//! The `restpose` command line: parse the arguments ([`cli::args`]), run the subcommand, map
//! its outcome to an exit code.

mod cli;

use clap::Parser;
use cli::args::{Cli, Command};
use std::process::ExitCode;

/// mimalloc: the solver's per-iteration vectors and the importer's many small strings are
/// served from thread-local free lists instead of glibc's arenas and fresh pages.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    // A build for extensions this CPU lacks refuses before it meets one (module `cpu`).
    let missing = restpose::cpu::unsupported();
    if !missing.is_empty() {
        eprintln!(
            "error: this CPU lacks {}: {}",
            missing.join(", "),
            restpose::cpu::REMEDY
        );
        return ExitCode::from(cli::exit::INPUT);
    }
    let cli = Cli::parse();
    let out = match &cli.command {
        Command::Analyze(a) => cli::analyze::run(a),
        Command::View(a) => cli::view::run(a),
        Command::Verify(a) => cli::verify::run(a),
        Command::Check(a) => cli::check::run(a),
        Command::Generate(a) => cli::generate::run(a),
    };
    match out {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            // The library's hint for a package directory, as the option that gives it.
            let hint = restpose::geometry::UNKNOWN_PACKAGE_HINT;
            cli::print::note!(
                "error: {}",
                format!("{e:#}").replace(hint, "use --package NAME=DIR")
            );
            ExitCode::from(cli::exit::INPUT)
        }
    }
}
