//! The command line: argument definitions ([`args`]), one module per subcommand, and the
//! human-readable printing ([`print`]). Each subcommand returns its exit code ([`exit`]);
//! errors become exit code 1 in `main`.

pub(crate) mod analyze;
pub(crate) mod args;
pub(crate) mod check;
pub(crate) mod confirm;
pub(crate) mod exit;
pub(crate) mod formats;
pub(crate) mod generate;
pub(crate) mod json_out;
pub(crate) mod parse;
pub(crate) mod print;
pub(crate) mod progress;
pub(crate) mod report;
pub(crate) mod values;
pub(crate) mod verify;
pub(crate) mod view;
pub(crate) mod written;
