//! What several commands' arguments share: the `--timeout`, `--size`,
//! `--background` and `--max-input-size` value parsers, and `--format`.

use std::time::Duration;

use clap::ValueEnum;

/// `--timeout SECONDS`: the time limit, none for 0.
#[derive(Clone, Copy)]
pub(super) struct Timeout(pub(super) Option<Duration>);

impl std::fmt::Display for Timeout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0.map_or(0.0, |d| d.as_secs_f64()))
    }
}

/// `--timeout SECONDS`: a number of seconds, 0 for no limit.
pub(super) fn parse_timeout(s: &str) -> Result<Timeout, String> {
    let secs: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number of seconds"))?;
    match Duration::try_from_secs_f64(secs) {
        Ok(d) if d.is_zero() => Ok(Timeout(None)),
        Ok(d) => Ok(Timeout(Some(d))),
        Err(_) => Err(format!(
            "`{s}` is not a time limit: give a number of seconds, or 0 for no limit"
        )),
    }
}

/// `1048576`, `512K`, `64M`, `2G` (powers of 1024).
pub(super) fn parse_byte_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (digits, unit) = match t.find(|c: char| !c.is_ascii_digit()) {
        Some(i) => t.split_at(i),
        None => (t, ""),
    };
    let shift = match unit.to_ascii_uppercase().as_str() {
        "" | "B" => 0,
        "K" | "KB" | "KIB" => 10,
        "M" | "MB" | "MIB" => 20,
        "G" | "GB" | "GIB" => 30,
        _ => {
            return Err(format!(
                "`{s}` is not a size: write bytes, or a number with K, M or G"
            ))
        }
    };
    let n: u64 = digits
        .parse()
        .map_err(|_| format!("`{s}` is not a size: write bytes, or a number with K, M or G"))?;
    n.checked_mul(1 << shift)
        .filter(|&b| b <= u32::MAX as u64)
        .ok_or_else(|| format!("`{s}` is more than the largest input size, 4G"))
}

pub(super) fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}` is not WIDTHxHEIGHT, e.g. 800x600"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("`{w}` is not a width in pixels"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("`{h}` is not a height in pixels"))?;
    if w == 0 || h == 0 || w > 20_000 || h > 20_000 {
        return Err("each side must be 1 to 20000 pixels".into());
    }
    Ok((w, h))
}

pub(super) fn parse_color(s: &str) -> Result<subgram::render::Rgba, String> {
    subgram::render::Rgba::parse(s)
        .ok_or_else(|| format!("`{s}` is not a colour: use white, black, none or #rrggbb"))
}

#[derive(Clone, Copy, ValueEnum)]
pub(super) enum Format {
    Text,
    Json,
}

/// The options of open L-systems (a model folder with a `.e` file),
/// shared by the commands that derive.
#[derive(clap::Args, Clone, Debug)]
pub(super) struct EnvCli {
    /// Open L-systems: set the values an environmental program leaves out
    /// of an EA20's answer to zero (lpfg's -cleanEA20).
    #[arg(long)]
    clean_ea20: bool,
    /// Open L-systems: start the .e file's program as a process even
    /// where subgram has it built in (honda81, shadowpyramid).
    #[arg(long)]
    env_process: bool,
    /// Open L-systems: stop a run whose environmental program has not
    /// answered a step after this many seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = 30.0, value_parser = parse_env_timeout)]
    env_timeout: f64,
}

fn parse_env_timeout(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 86_400.0 => Ok(v),
        _ => Err(format!(
            "`{s}` is not a number of seconds above 0 and at most 86400"
        )),
    }
}

impl EnvCli {
    pub(super) fn options(&self) -> subgram::enviro::Options {
        subgram::enviro::Options {
            external: self.env_process,
            answer_timeout: std::time::Duration::from_secs_f64(self.env_timeout),
            clean_ea20: self.clean_ea20,
        }
    }
}
