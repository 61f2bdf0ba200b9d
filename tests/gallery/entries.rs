//! The gallery of `lsystems/` (issue 40, item 3): one entry for every
//! `.lsys` file, the command that draws its picture in `docs/gallery/`,
//! and the guide's page `docs/guide/src/gallery.md` made from them.
//!
//! Shared by two test targets: `tests/it/guide.rs` checks, in every
//! `cargo test`, that the page is what these entries make and that every
//! file has its entry; `tests/gallery` (run by `.ci/run`) runs every
//! command again and compares the pictures byte for byte.
//! `UPDATE_GUIDE=1 cargo test --test gallery` rewrites the pictures and
//! the page.

use std::path::{Path, PathBuf};

/// The page, relative to the project root.
pub const PAGE: &str = "docs/guide/src/gallery.md";
/// The pictures' folder, relative to the project root.
pub const PICTURES: &str = "docs/gallery";
/// How large a plain picture is.
pub const SIZE: &str = "400x400";
/// The command that rewrites the pictures and the page.
pub const UPDATE: &str = "UPDATE_GUIDE=1 cargo test --test gallery";

/// One example of `lsystems/` in the gallery.
pub struct Entry {
    /// The program, relative to `lsystems/` (`abop/bush.lsys`).
    pub file: String,
    /// The picture, relative to the project root
    /// (`docs/gallery/abop/bush.png`).
    pub picture: String,
    /// The arguments of `subgram`, as the page prints them (run from the
    /// project root).
    pub args: Vec<String>,
    /// The file's own first sentence.
    pub caption: String,
    /// Why the command is not the plain `render … --size 400x400`.
    pub note: Option<&'static str>,
}

/// Examples drawn with other options than the plain render: the file,
/// the options (in place of `--size 400x400`) and why.
const OPTIONS: &[(&str, &[&str], &str)] = &[
    (
        "figures/fig01-chaikin-square.lsys",
        &["--each"],
        "Every step side by side (`--each`), as the paper's figure shows them.",
    ),
    (
        "figures/fig07-four-point-steps.lsys",
        &["--each"],
        "Every step side by side (`--each`), as the file's comment asks.",
    ),
    (
        "vv/tissue.lsys",
        &["--size", SIZE, "--view", "top"],
        "Seen from above (`--view top`): the sheet grows in a plane.",
    ),
];

/// Reverse-subdivision schemes: `render` would draw only the axiom's
/// small example, so the gallery runs `subgram reverse` with the scheme on
/// the traced horse of the tutorial and shows its figure (the input, the
/// coarse polygon and its reconstruction). The file, the extra options,
/// and why.
const REVERSE: &[(&str, &[&str], &str)] = &[
    (
        "reverse/chaikin.lsys",
        &[],
        "A reverse-subdivision scheme, run by `subgram reverse` (its own axiom is \
         only a unit square to reverse once): four levels of the horse traced from \
         `tests/data/horse.png`, with the input, the coarse polygon and the \
         reconstruction in one figure (800×800, `--figure` has no size option).",
    ),
    (
        "reverse/chaikin-open.lsys",
        &["--open"],
        "A reverse-subdivision scheme for open curves, run by `subgram reverse \
         --open` on the same traced horse, taken as an open curve (its end points \
         stay): the input, the coarse polygon and the reconstruction (800×800).",
    ),
];

/// The folders in the order the page shows them, each with its heading
/// and a line about it; a folder not listed here comes after them, in
/// the order of its name.
const FOLDERS: &[(&str, &str, &str)] = &[
    (
        "figures",
        "Figures of paper 002",
        "The figures of *L-system description of subdivision curves*.",
    ),
    (
        "curves",
        "Productions of paper 002",
        "Every production of paper 002, each in its own file.",
    ),
    (
        "paper",
        "Program 1 as printed",
        "Program 1 of paper 002 as printed there and as Velho prints it in paper 000.",
    ),
    (
        "abop",
        "The Algorithmic Beauty of Plants",
        "Textbook systems with the single-character turtle (`angle:`).",
    ),
    (
        "lplusc",
        "L+C",
        "An L+C program with C functions and tables.",
    ),
    (
        "open",
        "Open L-systems",
        "Model folders whose `.e` file names an environmental program (built in): \
         growth that stops at collisions, and crowns shaped by their own shade.",
    ),
    (
        "surfaces",
        "Surface grammars",
        "Stellar subdivision grammars (paper 000, paper 004), each on the base mesh \
         it names.",
    ),
    (
        "vv",
        "Vertex-vertex programs",
        "The programs of paper 001 and a growing tissue.",
    ),
    (
        "shapes",
        "Shape grammars",
        "CGA-style shape grammars with paper 003's `Subdivide`.",
    ),
    (
        "reverse",
        "Reverse subdivision",
        "The schemes of `subgram reverse`.",
    ),
];

/// Every `.lsys` file under `lsystems/`, and every model folder (a folder
/// with an `lsystem.l`: the open L-systems of `lsystems/open/`), relative
/// to it, `/`-separated, sorted.
pub fn examples(root: &Path) -> Vec<String> {
    fn walk(dir: &Path, base: &Path, out: &mut Vec<String>) {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for p in entries {
            if p.is_dir() && !p.join("lsystem.l").is_file() {
                walk(&p, base, out);
            } else if p.is_dir() || p.extension().is_some_and(|e| e == "lsys") {
                let rel = p.strip_prefix(base).unwrap();
                let parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                out.push(parts.join("/"));
            }
        }
    }
    let base = root.join("lsystems");
    let mut out = Vec::new();
    walk(&base, &base, &mut out);
    out.sort();
    out
}

/// Captions for the files that have no leading comment.
const CAPTIONS: &[(&str, &str)] = &[
    (
        "paper/000-program1.lsys",
        "Program 1 of paper 002 as Velho prints it in paper 000 (with `vl`).",
    ),
    (
        "paper/002-program1.lsys",
        "Program 1 of paper 002 as printed there: it reads `0.25*v1` where `vl` is \
         meant, and runs that way.",
    ),
];

/// The first sentence of a file's leading `//` comment (cut at its first
/// `: ` when it is longer than 220 characters), or a line that says there
/// is none.
pub fn caption(text: &str) -> String {
    let mut words = String::new();
    for line in text.lines() {
        let Some(c) = line.trim_start().strip_prefix("//") else {
            break;
        };
        let c = c.trim();
        if c.is_empty() {
            break;
        }
        if !words.is_empty() {
            words.push(' ');
        }
        words.push_str(c);
    }
    if words.is_empty() {
        return "(The file has no leading comment.)".to_string();
    }
    // The end of the first sentence: a `.` before a space or the end, not
    // after an abbreviation such as "Fig." or "Figs.".
    let chars: Vec<char> = words.chars().collect();
    let mut end = chars.len();
    for (i, &ch) in chars.iter().enumerate() {
        if ch != '.' || !(i + 1 == chars.len() || chars[i + 1] == ' ') {
            continue;
        }
        let before: String = chars[..i].iter().collect();
        let word = before.rsplit(' ').next().unwrap_or("");
        let word = word.trim_start_matches(|c: char| !c.is_alphanumeric());
        if matches!(word, "Fig" | "Figs" | "e.g" | "i.e" | "cf" | "vs") {
            continue;
        }
        end = i;
        break;
    }
    let mut s: String = chars[..end].iter().collect();
    if s.chars().count() > 220 {
        if let Some(at) = s.find(": ") {
            s.truncate(at);
        }
    }
    let mut s = s.trim_end_matches(':').to_string();
    s.push('.');
    s
}

/// The entries, one per file of [`examples`], in the page's order.
pub fn entries(root: &Path) -> Vec<Entry> {
    let mut files = examples(root);
    files.sort_by_key(|f| {
        let folder = f.split('/').next().unwrap().to_string();
        let rank = FOLDERS
            .iter()
            .position(|(name, _, _)| *name == folder)
            .unwrap_or(FOLDERS.len());
        (rank, f.clone())
    });
    files
        .into_iter()
        .map(|file| {
            let path = root.join("lsystems").join(&file);
            let path = match path.is_dir() {
                true => path.join("lsystem.l"),
                false => path,
            };
            let text = std::fs::read_to_string(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let stem = file.strip_suffix(".lsys").unwrap_or(&file);
            let picture = format!("{PICTURES}/{stem}.png");
            let program = format!("lsystems/{file}");
            let owned = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
            let (args, note) =
                if let Some((_, extra, why)) = REVERSE.iter().find(|(f, _, _)| *f == file) {
                    let coarse = format!("{}-coarse.csv", stem.replace('/', "-"));
                    let mut a = owned(&["reverse", "tests/data/horse.png", "-n", "4"]);
                    a.extend(owned(extra));
                    a.extend([
                        "--scheme".to_string(),
                        program,
                        "-o".to_string(),
                        coarse,
                        "--figure".to_string(),
                        picture.clone(),
                    ]);
                    (a, Some(*why))
                } else {
                    let (opts, note) = match OPTIONS.iter().find(|(f, _, _)| *f == file) {
                        Some((_, o, why)) => (owned(o), Some(*why)),
                        None => (owned(&["--size", SIZE]), None),
                    };
                    let mut a = vec!["render".to_string(), program];
                    a.extend(opts);
                    a.extend(["-o".to_string(), picture.clone()]);
                    (a, note)
                };
            let caption = match CAPTIONS.iter().find(|(f, _)| *f == file) {
                Some((_, c)) => c.to_string(),
                None => caption(&text),
            };
            Entry {
                caption,
                file,
                picture,
                args,
                note,
            }
        })
        .collect()
}

/// The positions in `args` of the files a command writes: the values of
/// `-o` and `--figure`.
pub fn outputs(args: &[String]) -> Vec<usize> {
    (1..args.len())
        .filter(|&k| matches!(args[k - 1].as_str(), "-o" | "--figure"))
        .collect()
}

/// The command line as the page prints it.
pub fn command(e: &Entry) -> String {
    format!("subgram {}", e.args.join(" "))
}

/// The page.
pub fn page(entries: &[Entry]) -> String {
    let mut s = String::new();
    s.push_str(
        "# Gallery\n\
         \n\
         <!-- Generated by tests/gallery/entries.rs: do not edit; run\n\
         \x20    UPDATE_GUIDE=1 cargo test --test gallery -->\n\
         \n\
         Every program in `lsystems/`, drawn by the command under it. Run the\n\
         commands from the root of a clone, after `cargo install --path .` (or\n\
         with `cargo run --release --` in place of `subgram`).\n\
         \n",
    );
    s.push_str(&format!(
        "`{UPDATE}` draws every picture again and rewrites this page.\n\
         `cargo test --release --test gallery` (a step of `.ci/run`) runs every\n\
         command and fails when a picture differs from the one here, or when this\n\
         page is not what the examples make; `cargo test` checks that every file\n\
         of `lsystems/` has its entry.\n"
    ));
    let mut folder = String::new();
    for e in entries {
        let f = e.file.split('/').next().unwrap();
        if f != folder {
            folder = f.to_string();
            let (title, line) = FOLDERS
                .iter()
                .find(|(name, _, _)| *name == f)
                .map(|(_, t, l)| (t.to_string(), l.to_string()))
                .unwrap_or_else(|| (format!("`{f}/`"), String::new()));
            s.push_str(&format!("\n## {title}\n\n"));
            if !line.is_empty() {
                s.push_str(&format!("{line} In `lsystems/{f}/`.\n"));
            } else {
                s.push_str(&format!("In `lsystems/{f}/`.\n"));
            }
        }
        s.push_str(&format!(
            "\n### {}\n\n[`lsystems/{}`](../../../lsystems/{}): {}\n",
            e.file, e.file, e.file, e.caption
        ));
        if let Some(n) = e.note {
            s.push_str(&format!("{n}\n"));
        }
        s.push_str(&format!(
            "\n![{}](../../../{})\n\n```sh\n{}\n```\n",
            e.file,
            e.picture,
            command(e)
        ));
    }
    s
}

/// Whether the run asks to rewrite the generated files.
pub fn updating() -> bool {
    std::env::var_os("UPDATE_GUIDE").is_some_and(|v| !v.is_empty() && v != "0")
}
