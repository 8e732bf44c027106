//! Value parsers for numeric options (clap `value_parser`): clap prefixes their messages with
//! the option's name, and a rejected value is a usage error (exit code 2).

/// Largest `--load-steps`: each step is a full solve from the previous rest pose, and 1,000
/// equal steps of a load are already finer than any solve needs.
pub(crate) const MAX_LOAD_STEPS: usize = 1000;

/// Largest `generate --size`: a million links is about 0.3 GB of URDF text.
pub(crate) const MAX_GENERATE_SIZE: usize = 1_000_000;

fn number(s: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .map_err(|_| format!("`{s}` is not a number"))
}

/// A finite number.
pub(crate) fn finite(s: &str) -> Result<f64, String> {
    let x = number(s)?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("{s} is not finite"))
    }
}

/// A finite number greater than zero.
pub(crate) fn positive(s: &str) -> Result<f64, String> {
    let x = finite(s)?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err(format!("{s}: must be greater than zero"))
    }
}

fn bounded(s: &str, min: usize, max: usize) -> Result<usize, String> {
    let n = s
        .trim()
        .parse::<usize>()
        .map_err(|_| format!("`{s}` is not a whole number"))?;
    if (min..=max).contains(&n) {
        Ok(n)
    } else {
        Err(format!("{n} is out of range: from {min} to {max}"))
    }
}

/// A number of load steps, `0..=MAX_LOAD_STEPS`.
pub(crate) fn load_steps(s: &str) -> Result<usize, String> {
    bounded(s, 0, MAX_LOAD_STEPS)
}

/// A generated mechanism's size, `1..=MAX_GENERATE_SIZE`.
pub(crate) fn generate_size(s: &str) -> Result<usize, String> {
    bounded(s, 1, MAX_GENERATE_SIZE)
}

/// A `--servo` value: `all=K`, `JOINT=K` or `JOINT=K@REF` (K > 0 and finite, REF finite).
pub(crate) fn servo(s: &str) -> anyhow::Result<restpose::urdf::ServoRequest> {
    let usage = || format!("--servo {s}: expected all=K, JOINT=K or JOINT=K@REF");
    let (joint, rest) = s.rsplit_once('=').ok_or_else(|| anyhow::anyhow!(usage()))?;
    let (k, reference) = match rest.split_once('@') {
        Some((k, r)) => (
            k,
            Some(finite(r).map_err(|e| anyhow::anyhow!("{}: {e}", usage()))?),
        ),
        None => (rest, None),
    };
    let stiffness = positive(k).map_err(|e| anyhow::anyhow!("--servo {s}: stiffness {e}"))?;
    if joint.is_empty() {
        anyhow::bail!(usage());
    }
    Ok(restpose::urdf::ServoRequest {
        joint: (joint != "all").then(|| joint.to_string()),
        stiffness,
        reference,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_checked() {
        assert_eq!(positive("1e-9"), Ok(1e-9));
        for bad in ["0", "-1e-9", "nan", "inf", "-inf", "x", ""] {
            assert!(positive(bad).is_err(), "{bad}");
        }
        assert_eq!(finite("-9.81"), Ok(-9.81));
        assert!(finite("NaN").is_err() && finite("1e400").is_err());
        assert_eq!(load_steps("1000"), Ok(1000));
        assert!(load_steps("1001").is_err() && load_steps("-1").is_err());
        assert!(generate_size("0").is_err());
    }
}
