//! A stand-in environmental program for the tests of subgram's external
//! environment (tests/it/enviro_external.rs): the slave's side of lpfg's
//! protocol, written from the protocol's description and sharing no code
//! with subgram (it is the peer those tests check subgram against).
//!
//! ```text
//! stand_in_env -k KEY -ext EXT -e FILE.e MODE [pid-file PATH]
//! ```
//!
//! It opens the SysV semaphore set under KEY, sets semaphore 1 to 0, and
//! then, for each step: waits for semaphore 0, reads `.to_fieldEXT`
//! (`ID E(v,…)` and one turtle line per field the `.e` file sends, then
//! `Control: F`; F & 8 asks it to exit), writes `.from_fieldEXT` (`ID
//! E(v,…)` lines, then `Control: 5`) and raises semaphore 1.
//!
//! MODE chooses the answers:
//!
//! * `echo-position`: each module gets as many values as it sent, value k
//!   being the turtle position's component k;
//! * `sum`: one value, the sum of those sent plus the step's number (the
//!   first exchange is step 1);
//! * failures: `crash` (exits with status 3 once it has read the first
//!   queries), `silent` (never answers), `unknown-module` (answers module
//!   999999), `wrong-count` (two values for every module), `garbage`
//!   (`hello`), `no-control` (answers without the `Control:` line).
//!
//! `pid-file PATH` writes its process id to PATH first (outside the model
//! folder), so that a test can see it is gone afterwards.
//!
//! `cargo build --example stand_in_env`; Linux only (SysV semaphores).

#[cfg(target_os = "linux")]
fn main() {
    if let Err(e) = imp::run() {
        eprintln!("stand_in_env: {e}");
        std::process::exit(2);
    }
}

#[cfg(not(target_os = "linux"))]
fn main() {
    eprintln!("stand_in_env: SysV semaphores are used on Linux only");
    std::process::exit(2);
}

#[cfg(target_os = "linux")]
mod imp {
    use std::time::Duration;

    struct Args {
        key: libc::key_t,
        ext: String,
        e_file: String,
        mode: String,
        pid_file: Option<String>,
    }

    fn args() -> Result<Args, String> {
        let mut it = std::env::args().skip(1);
        let (mut key, mut ext, mut e_file) = (None, None, None);
        let mut rest = Vec::new();
        while let Some(a) = it.next() {
            let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
            match a.as_str() {
                "-k" => {
                    let v = value("-k")?;
                    key = Some(
                        v.parse::<libc::key_t>()
                            .map_err(|e| format!("-k {v}: {e}"))?,
                    );
                }
                "-ext" => ext = Some(value("-ext")?),
                "-e" => e_file = Some(value("-e")?),
                _ => rest.push(a),
            }
        }
        let mut rest = rest.into_iter();
        let mode = rest
            .next()
            .ok_or("no mode (echo-position, sum, crash, …)")?;
        let mut pid_file = None;
        while let Some(a) = rest.next() {
            match a.as_str() {
                "pid-file" => pid_file = Some(rest.next().ok_or("pid-file needs a path")?),
                _ => return Err(format!("unknown argument `{a}`")),
            }
        }
        Ok(Args {
            key: key.ok_or("no -k KEY")?,
            ext: ext.ok_or("no -ext EXT")?,
            e_file: e_file.ok_or("no -e FILE")?,
            mode,
            pid_file,
        })
    }

    /// How many turtle lines follow each module's line: the position
    /// always (sent by default), and the heading, left and up vectors
    /// where the `.e` file asks for them.
    fn turtle_lines(e_text: &str) -> usize {
        let mut n = 1;
        for line in e_text.lines() {
            let label = line.split(':').next().unwrap_or("").trim();
            if matches!(label, "turtle heading" | "turtle left" | "turtle up") {
                n += 1;
            }
        }
        n
    }

    struct Module {
        id: String,
        values: Vec<f64>,
        position: [f64; 3],
    }

    /// One block from the master: the modules and the `Control:` flag.
    fn parse(text: &str, per_module: usize) -> Result<(Vec<Module>, i64), String> {
        let mut lines = text.lines();
        let mut out = Vec::new();
        while let Some(line) = lines.next() {
            let line = line.trim();
            if let Some(rest) = line.strip_prefix("Control:") {
                let flag = rest
                    .split_whitespace()
                    .next()
                    .and_then(|w| w.parse().ok())
                    .ok_or(format!("bad control line `{line}`"))?;
                return Ok((out, flag));
            }
            let (id, rest) = line
                .split_once(' ')
                .ok_or(format!("bad module line `{line}`"))?;
            let inner = rest
                .strip_prefix("E(")
                .and_then(|r| r.split_once(')'))
                .map(|(v, _)| v)
                .ok_or(format!("bad module line `{line}`"))?;
            let values = inner
                .split(',')
                .map(|v| v.trim().parse::<f64>().map_err(|e| format!("`{v}`: {e}")))
                .collect::<Result<Vec<_>, _>>()?;
            let pos_line = lines.next().ok_or(format!("no position after `{line}`"))?;
            // The position's format is the .e file's: its last three
            // words are the numbers.
            let nums: Vec<f64> = pos_line
                .split_whitespace()
                .filter_map(|w| w.parse().ok())
                .collect();
            if nums.len() < 3 {
                return Err(format!("bad position line `{pos_line}`"));
            }
            let k = nums.len() - 3;
            let position = [nums[k], nums[k + 1], nums[k + 2]];
            for _ in 1..per_module {
                lines.next().ok_or("a turtle line is missing")?;
            }
            out.push(Module {
                id: id.to_string(),
                values,
                position,
            });
        }
        Err("no `Control:` line".into())
    }

    fn sem_op(id: libc::c_int, n: u16, op: i16) -> Result<(), String> {
        let mut b = libc::sembuf {
            sem_num: n,
            sem_op: op,
            sem_flg: 0,
        };
        loop {
            // SAFETY: one valid sembuf.
            if unsafe { libc::semop(id, &mut b, 1) } == 0 {
                return Ok(());
            }
            let e = std::io::Error::last_os_error();
            if e.kind() != std::io::ErrorKind::Interrupted {
                return Err(format!("semop({n}, {op}): {e}"));
            }
        }
    }

    fn list(values: impl Iterator<Item = f64>) -> String {
        values.map(|v| v.to_string()).collect::<Vec<_>>().join(",")
    }

    pub fn run() -> Result<(), String> {
        let a = args()?;
        if let Some(p) = &a.pid_file {
            std::fs::write(p, std::process::id().to_string()).map_err(|e| format!("{p}: {e}"))?;
        }
        let e_text =
            std::fs::read_to_string(&a.e_file).map_err(|e| format!("{}: {e}", a.e_file))?;
        let per_module = turtle_lines(&e_text);
        // SAFETY: plain system calls with integer arguments.
        let id = unsafe { libc::semget(a.key, 2, 0o600) };
        if id < 0 {
            return Err(format!(
                "no semaphore set {}: {}",
                a.key,
                std::io::Error::last_os_error()
            ));
        }
        // SAFETY: SETVAL of one semaphore of the set to 0.
        if unsafe { libc::semctl(id, 1, libc::SETVAL, 0 as libc::c_int) } < 0 {
            return Err(format!("SETVAL: {}", std::io::Error::last_os_error()));
        }
        let to = format!(".to_field{}", a.ext);
        let from = format!(".from_field{}", a.ext);
        let mut step = 0u64;
        loop {
            sem_op(id, 0, -1)?;
            let text = std::fs::read_to_string(&to).map_err(|e| format!("{to}: {e}"))?;
            let (modules, flag) = parse(&text, per_module)?;
            if flag & 8 != 0 {
                sem_op(id, 1, 1)?;
                return Ok(());
            }
            step += 1;
            let mut out = String::new();
            for m in &modules {
                let values = match a.mode.as_str() {
                    "echo-position" => list(m.position.iter().copied().take(m.values.len())),
                    "sum" => list(std::iter::once(m.values.iter().sum::<f64>() + step as f64)),
                    "wrong-count" => list([1.0, 2.0].into_iter()),
                    "unknown-module" | "crash" | "silent" | "garbage" | "no-control" => {
                        list(m.values.iter().copied())
                    }
                    other => return Err(format!("unknown mode `{other}`")),
                };
                let id = match a.mode.as_str() {
                    "unknown-module" => "999999",
                    _ => m.id.as_str(),
                };
                out.push_str(&format!("{id} E({values})\n"));
            }
            match a.mode.as_str() {
                "crash" => std::process::exit(3),
                "silent" => loop {
                    std::thread::sleep(Duration::from_secs(3600));
                },
                "garbage" => out = "hello\n".into(),
                _ => {}
            }
            if a.mode != "no-control" {
                out.push_str("Control: 5\n");
            }
            std::fs::write(&from, out).map_err(|e| format!("{from}: {e}"))?;
            sem_op(id, 1, 1)?;
        }
    }
}
