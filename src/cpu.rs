//! The instruction-set extensions this build was compiled for, checked against the CPU it
//! runs on.
//!
//! Builds from this repository target **x86-64-v3** on x86-64 (`.cargo/config.toml`:
//! `-C target-cpu=x86-64-v3`: AVX, AVX2, FMA, BMI1/2, F16C, LZCNT and the SSE levels below;
//! Intel Haswell (2013) and AMD Excavator (2015) or later). The compiler then vectorizes the
//! solver's fixed-size block loops four doubles wide: 4 – 5 % less CPU on a 1,000-link chain,
//! the ladder and the rope, every answer bit for bit the baseline build's (Rust never fuses
//! `a * b + c` into an FMA, so the rounding of each operation is the same; BENCHMARKS.md).
//! Built for the baseline instead (`RUSTFLAGS="-C target-cpu=x86-64"`), nothing here is
//! required and [`unsupported`] is always empty.
//!
//! A binary built for extensions the CPU lacks would die on the first such instruction
//! (`SIGILL`); the command line and the Python module call [`unsupported`] first and refuse
//! with [`REMEDY`] instead. The check is a few `cfg!` constants and calls into the standard
//! library's feature detection (compiled for the baseline): best effort, since the compiler
//! may still use an extension in the check's own few instructions.

/// The message for a CPU that lacks what this build needs: the remedy, after the missing list.
pub const REMEDY: &str = "this restpose was built for a newer CPU (the repository's \
     .cargo/config.toml targets x86-64-v3, unless RUSTFLAGS named another); rebuild it for \
     this CPU with RUSTFLAGS=\"-C target-cpu=native\" (or \"-C target-cpu=x86-64\" for any \
     x86-64), e.g. `RUSTFLAGS=\"-C target-cpu=native\" cargo install --path .`";

/// Each extension the detection knows, in the order of the x86-64 levels: its name, whether
/// this build was compiled for it, whether this CPU has it.
#[cfg(target_arch = "x86_64")]
fn extensions() -> Vec<(&'static str, bool, bool)> {
    macro_rules! each {
        ($($f:tt),*) => {
            vec![$(($f, cfg!(target_feature = $f), std::arch::is_x86_feature_detected!($f))),*]
        };
    }
    each!(
        "sse3", "ssse3", "sse4.1", "sse4.2", "popcnt", "avx", "avx2", "fma", "bmi1", "bmi2",
        "f16c", "lzcnt"
    )
}

/// No extension is known on other architectures.
#[cfg(not(target_arch = "x86_64"))]
fn extensions() -> Vec<(&'static str, bool, bool)> {
    Vec::new()
}

/// The extensions this build was compiled for (of those the detection knows), in the order
/// of the x86-64 levels; empty on other architectures or a baseline build.
pub fn required() -> Vec<&'static str> {
    extensions()
        .into_iter()
        .filter(|e| e.1)
        .map(|e| e.0)
        .collect()
}

/// The extensions of [`required`] that this CPU lacks (empty: the build runs here).
pub fn unsupported() -> Vec<&'static str> {
    extensions()
        .into_iter()
        .filter(|e| e.1 && !e.2)
        .map(|e| e.0)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The list follows the build's own target features: with the repository's configuration
    /// on x86-64 it names AVX2 and FMA, and a baseline build names neither.
    #[test]
    fn required_follows_the_build() {
        let r = required();
        assert_eq!(r.contains(&"avx2"), cfg!(target_feature = "avx2"));
        assert_eq!(r.contains(&"fma"), cfg!(target_feature = "fma"));
        #[cfg(not(target_arch = "x86_64"))]
        assert!(r.is_empty());
    }

    /// The machine that runs the tests runs this build (else the tests could not run), and
    /// the detection agrees with it extension by extension.
    #[test]
    fn this_machine_is_supported() {
        assert_eq!(unsupported(), Vec::<&str>::new());
        for (f, compiled, detected) in extensions() {
            assert!(!compiled || detected, "{f} compiled for but not detected");
        }
    }
}
