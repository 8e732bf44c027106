//! Fuzz target: any bytes as a URDF file must load or fail with an error, and what loads must
//! solve or fail with an error; never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(loaded) = restpose::urdf::load_str(&text, "fuzz.urdf", &Default::default()) {
        if loaded.model.coordinate_count() <= 7 * 40 {
            let options = restpose::Options { max_iterations: 10, load_steps: 1, ..Default::default() };
            let _ = restpose::solve(&loaded.model, &options);
        }
    }
});
