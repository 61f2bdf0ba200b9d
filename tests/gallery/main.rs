//! The gallery's pictures (issue 40, item 3): every command of
//! `docs/guide/src/gallery.md` is run again and its picture compared
//! byte for byte with the one in `docs/gallery/`. Run by `.ci/run` as
//! `cargo test --release --test gallery`, not by a plain `cargo test`
//! (53 programs, about 30 s in a debug build); the pictures are the same
//! bytes in debug and release builds.
//!
//! `UPDATE_GUIDE=1 cargo test --test gallery` draws every picture again,
//! writes those that differ, removes pictures no example makes, and
//! rewrites the page.

mod entries;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

use entries::Entry;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs an entry's command from the project root with its outputs in
/// `dir`, and returns its picture's bytes.
fn draw(e: &Entry, dir: &Path, k: usize) -> Result<Vec<u8>, String> {
    let mut args = e.args.clone();
    let outs = entries::outputs(&args);
    for (j, &at) in outs.iter().enumerate() {
        let name = Path::new(&args[at])
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        args[at] = dir
            .join(format!("{k}-{j}-{name}"))
            .to_string_lossy()
            .into_owned();
    }
    let picture = outs
        .iter()
        .map(|&at| args[at].clone())
        .find(|p| p.ends_with(".png"))
        .ok_or_else(|| format!("`{}` writes no picture", entries::command(e)))?;
    let out = Command::new(env!("CARGO_BIN_EXE_subgram"))
        .current_dir(root())
        .args(&args)
        .stdin(std::process::Stdio::null())
        .output()
        .map_err(|err| format!("cannot run subgram: {err}"))?;
    if !out.status.success() {
        return Err(format!(
            "`{}` failed ({}):\n{}",
            entries::command(e),
            out.status,
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    std::fs::read(&picture).map_err(|err| format!("{picture}: {err}"))
}

/// Every picture files under `docs/gallery/`, relative to the root.
fn pictures_on_disk(root: &Path) -> Vec<String> {
    fn walk(dir: &Path, root: &Path, out: &mut Vec<String>) {
        let Ok(rd) = std::fs::read_dir(dir) else {
            return;
        };
        for e in rd {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, root, out);
            } else {
                let rel = p.strip_prefix(root).unwrap();
                let parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                out.push(parts.join("/"));
            }
        }
    }
    let mut out = Vec::new();
    walk(&root.join(entries::PICTURES), root, &mut out);
    out.sort();
    out
}

#[test]
fn every_gallery_picture_is_what_its_command_draws() {
    let root = root();
    let update = entries::updating();
    let all = entries::entries(&root);
    assert!(all.len() >= 50, "{} examples", all.len());
    let page = entries::page(&all);
    let page_path = root.join(entries::PAGE);
    let on_page = std::fs::read_to_string(&page_path).unwrap_or_default();
    let mut problems = Vec::new();
    if on_page != page {
        if update {
            std::fs::write(&page_path, &page).unwrap();
        } else {
            problems.push(format!(
                "{} is stale: it is not the page that the examples make",
                entries::PAGE
            ));
        }
    }

    let dir = tempfile::Builder::new()
        .prefix("subgram-gallery-")
        .tempdir()
        .unwrap();
    // The commands on the machine's cores, each picture compared or
    // written as it comes.
    let next = Mutex::new(0usize);
    let found = Mutex::new(Vec::new());
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| loop {
                let k = {
                    let mut n = next.lock().unwrap();
                    *n += 1;
                    *n - 1
                };
                let Some(e) = all.get(k) else { break };
                let result = draw(e, dir.path(), k).and_then(|bytes| {
                    let path = root.join(&e.picture);
                    let old = std::fs::read(&path).ok();
                    if old.as_deref() == Some(&bytes[..]) {
                        return Ok(());
                    }
                    if update {
                        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
                        std::fs::write(&path, &bytes).unwrap();
                        return Ok(());
                    }
                    Err(match old {
                        None => format!("{} is missing", e.picture),
                        Some(old) => format!(
                            "{} is stale: `{}` draws {} bytes that differ from its {} bytes",
                            e.picture,
                            entries::command(e),
                            bytes.len(),
                            old.len()
                        ),
                    })
                });
                if let Err(m) = result {
                    found.lock().unwrap().push(m);
                }
            });
        }
    });
    problems.extend(found.into_inner().unwrap());

    // No picture that no example makes.
    for p in pictures_on_disk(&root) {
        if !all.iter().any(|e| e.picture == p) {
            if update {
                std::fs::remove_file(root.join(&p)).unwrap();
            } else {
                problems.push(format!("{p} belongs to no example of lsystems/"));
            }
        }
    }
    problems.sort();
    assert!(
        problems.is_empty(),
        "the gallery is stale; run `{}` and look at the pictures that changed:\n{}",
        entries::UPDATE,
        problems.join("\n")
    );
}
