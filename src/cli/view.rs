//! `restpose view`: solve, write a recording next to the input, open it in `rerun`.

use super::analyze;
use super::args::AnalyzeArgs;

/// Runs `view`: the exit code of the solve.
pub(crate) fn run(a: &AnalyzeArgs) -> anyhow::Result<u8> {
    let rrd = a
        .rrd
        .clone()
        .unwrap_or_else(|| a.file.with_extension("rrd"));
    let mut args = AnalyzeArgs {
        rrd: Some(rrd.clone()),
        ..a.clone()
    };
    args.quiet = true;
    let code = analyze::run(&args)?;
    super::print::note!("wrote {}", rrd.display());
    match std::process::Command::new("rerun").arg(&rrd).spawn() {
        Ok(_) => super::print::note!("opened it in the rerun viewer"),
        Err(_) => super::print::note!(
            "the `rerun` viewer is not on the PATH: `pip install rerun-sdk==0.36.3`, then `rerun {}`",
            rrd.display()
        ),
    }
    Ok(code)
}
