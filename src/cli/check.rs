//! `restpose check`: load and validate a file without solving; print the model as understood.

use super::args::{CheckArgs, Format};
use super::exit;
use super::{json_out, print};
use restpose::export::summary::ModelSummary;
use restpose::urdf::load_file;

/// Runs `check`: exit 0, or 1 if the initial guess does not assemble.
pub(crate) fn run(a: &CheckArgs) -> anyhow::Result<u8> {
    let loaded = load_file(&a.file, &a.input.options()?).map_err(|e| a.input.explain(e))?;
    let stdout_json = print::is_stdout(a.json.as_ref());
    let text = matches!(a.format, Format::Text) && !stdout_json;
    let check = restpose::verify::check(&loaded.model);
    let s = ModelSummary::of_model(&loaded).with_check(&check);
    // About 100 bytes a line, a line per body and joint: reserved once (capacity never
    // written costs no page), not regrown by copies.
    let mut listing = Vec::with_capacity(if text {
        4096 + 128 * (s.bodies.len() + s.joints.len())
    } else {
        0
    });
    if text {
        print::model_listing(&s, &mut listing);
    }
    if let Some(path) = &a.json {
        json_out::write(path, |w| json_out::pretty(w, &s))?;
    }
    match a.format {
        Format::Json if !stdout_json => {
            json_out::write(std::path::Path::new("-"), |w| json_out::pretty(w, &s))?
        }
        Format::Text if !stdout_json => print::model_with_listing(&s, &listing),
        _ => {}
    }
    // The JSON carries the warnings; the text form gives them on standard error.
    if let Format::Text = a.format {
        for w in &s.warnings {
            print::warning(w);
        }
        if a.verbose {
            for i in &s.ignored {
                super::print::note!("ignored: {}:{i}", a.file.display());
            }
        }
    }
    // Exit 1 always comes with an `error:` line on standard error (whatever the format).
    let code = match &s.assembly_error {
        Some(e) => {
            let file = a.file.display().to_string();
            if e.starts_with(&file) {
                super::print::note!("error: {e}");
            } else {
                super::print::note!("error: {file}: {e}");
            }
            exit::INPUT
        }
        None => 0,
    };
    // The process ends next: its memory goes back whole, without freeing each of a large
    // model's names and listings one by one (3 % of `check` at 10,000 links).
    std::mem::forget((loaded, s, listing));
    Ok(code)
}
