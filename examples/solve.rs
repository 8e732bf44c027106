//! The README's library example: load a URDF, solve for the rest pose, build the result JSON.
//!
//! `cargo run --example solve` (from the repository root, where `robots/` is).

fn main() -> Result<(), restpose::Error> {
    let loaded = restpose::urdf::load_file("robots/pendulum.urdf", &Default::default())?;
    let (state, report) = restpose::solve(&loaded.model, &Default::default())?;
    let result = restpose::export::json::AnalysisResult::new(&loaded.model, &state, &report);
    assert!(result.converged);
    Ok(())
}
