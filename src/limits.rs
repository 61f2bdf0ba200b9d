//! Limits the environment may set (`SUBGRAM_MAX_VALENCE=5000`, …).

/// The whole number the environment variable `name` holds, or `default`
/// where it is not set; an error names the variable, `what` it must hold
/// ("a whole number", "a whole number of bytes") and what it held.
pub(crate) fn from_env(name: &str, default: u64, what: &str) -> Result<u64, String> {
    match std::env::var(name) {
        Err(std::env::VarError::NotPresent) => Ok(default),
        Ok(v) => v
            .trim()
            .parse::<u64>()
            .map_err(|_| format!("{name} must be {what}, found `{v}`")),
        Err(std::env::VarError::NotUnicode(v)) => Err(format!(
            "{name} must be {what}, found `{}`",
            v.to_string_lossy()
        )),
    }
}
