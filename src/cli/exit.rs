//! Exit codes (documented in docs/cli.md; 2 is clap's usage error).

/// Invalid input or another error (file, option, assembly).
pub(crate) const INPUT: u8 = 1;
/// Bad command-line usage (clap's code), e.g. two outputs to standard output.
pub(crate) const USAGE: u8 = 2;
/// The solve did not converge.
pub(crate) const NOT_CONVERGED: u8 = 3;
/// `verify`: the pose is not a rest pose.
pub(crate) const NOT_BALANCED: u8 = 4;
