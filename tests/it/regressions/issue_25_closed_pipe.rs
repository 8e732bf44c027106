//! Issue 25, item 9: with its standard error closed
//! (`restpose verify F --pose P 2>&1 >/dev/null | head -c 0`), restpose panicked in
//! `eprintln!` ("failed printing to stderr") and exited 101 whenever it printed a warning
//! (7 runs in 8). Every line to standard error now ignores a closed pipe, as standard output
//! already did: the command's own exit code.

use std::process::{Command, Stdio};

#[test]
fn a_closed_standard_error_or_output_is_a_quiet_exit() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/robots/four_bar_spatial.urdf");
    // A pose of one joint of three: verify warns about the two it keeps at their initial
    // values (on standard error), then reports (on standard output).
    for closed in ["stderr", "stdout", "both"] {
        for _ in 0..8 {
            let mut cmd = Command::new(env!("CARGO_BIN_EXE_restpose"));
            cmd.args(["verify", file, "--joint", "crank_joint=0.3"]);
            cmd.stdout(Stdio::piped()).stderr(Stdio::piped());
            let mut child = cmd.spawn().unwrap();
            // Both pipes' read ends are dropped at once, before the child has read the file.
            if closed != "stdout" {
                drop(child.stderr.take());
            }
            if closed != "stderr" {
                drop(child.stdout.take());
            }
            let status = child.wait().unwrap();
            assert_ne!(status.code(), Some(101), "closed {closed}: a panic");
            // The pose is 0.3 rad off the rest pose: not a rest pose (4), whatever was closed.
            assert_eq!(status.code(), Some(4), "closed {closed}");
        }
    }
}
