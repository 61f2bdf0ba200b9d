//! The layers read one way (issue 41; ARCHITECTURE.md, "Layers"): no
//! module's code names a module above it. The order is the one
//! ARCHITECTURE.md gives; a module not in it fails the test until it is
//! placed. Unit tests (a `tests.rs` file, or what follows `#[cfg(test)]`
//! in a file) may load whole programs through the crate's front door and
//! are not checked.

use std::collections::HashMap;
use std::path::Path;

use crate::support::root;

/// Each top-level module of `src/` and its layer, from the bottom.
const LAYERS: &[&[&str]] = &[
    &["deadline", "limits", "huge", "colour", "testing"],
    &["files"],
    &["syntax"],
    &["lang"],
    &["model"],
    &["rewrite"],
    &["production", "enviro"],
    &["mesh"],
    &["surface"],
    &["vv", "shape"],
    &["scene3"],
    &["draw"],
    &["render"],
    &["error"],
    &["curve", "output", "export", "infer"],
    &["system"],
    &["load"],
    &["reverse", "analyze"],
    &["command", "serve"],
    &["lib", "main", "cli"],
];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

/// The names `lib.rs` re-exports at the crate's root, and the module each
/// comes from (`crate::load_str` is `load`'s).
fn root_names(lib: &str) -> HashMap<String, String> {
    let mut names = HashMap::new();
    for item in lib.split(';') {
        let item = item.trim();
        let Some(rest) = item.rfind("pub use ").map(|i| &item[i + 8..]) else {
            continue;
        };
        let module = rest.split("::").next().unwrap_or("").trim().to_string();
        let tail = rest.rsplit("::").next().unwrap_or("");
        let inside = rest.find('{').map(|i| &rest[i + 1..]).unwrap_or(tail);
        for name in inside.split([',', '{', '}']).map(str::trim) {
            if !name.is_empty() {
                names.insert(name.to_string(), module.clone());
            }
        }
    }
    names
}

fn files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The modules a line of code names through `crate::`.
fn named(line: &str, root: &HashMap<String, String>) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = line;
    while let Some(i) = rest.find("crate::") {
        rest = &rest[i + 7..];
        let group = rest.starts_with('{');
        let text = if group {
            &rest[1..rest.find('}').unwrap_or(rest.len())]
        } else {
            rest
        };
        for part in text.split(',') {
            let name: String = part
                .trim()
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() {
                out.push(root.get(&name).cloned().unwrap_or(name));
            }
            if !group {
                break;
            }
        }
    }
    out
}

#[test]
fn no_module_names_a_layer_above_its_own() {
    let src = root().join("src");
    let root_names = root_names(&std::fs::read_to_string(src.join("lib.rs")).unwrap());
    let mut all = Vec::new();
    files(&src, &mut all);
    all.sort();
    let mut upward = Vec::new();
    for path in &all {
        let rel = path.strip_prefix(&src).unwrap();
        let top = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy()
            .trim_end_matches(".rs")
            .to_string();
        let Some(own) = layer_of(&top) else {
            panic!("src/{top} is in no layer: place it in LAYERS and in ARCHITECTURE.md");
        };
        if rel.file_name().is_some_and(|f| f == "tests.rs") {
            continue;
        }
        let text = std::fs::read_to_string(path).unwrap();
        for (k, line) in text.lines().enumerate() {
            if line.starts_with("#[cfg(test)]") {
                break;
            }
            let code = line.trim_start();
            if code.starts_with("//") {
                continue;
            }
            for m in named(line, &root_names) {
                if let Some(theirs) = layer_of(&m) {
                    if theirs > own {
                        upward.push(format!("src/{}:{}: {top} names {m}", rel.display(), k + 1));
                    }
                }
            }
        }
    }
    assert!(upward.is_empty(), "upward names:\n{}", upward.join("\n"));
}

/// The check finds what it looks for: a line of `lang` naming the loader,
/// and a name the crate's root re-exports.
#[test]
fn the_layer_check_sees_upward_names() {
    let root_names = root_names("pub use load::{\n    load, load_str,\n};\npub use error::Error;");
    assert_eq!(
        named("let c = crate::load_str(\"t\", s, &[]);", &root_names),
        ["load"]
    );
    assert_eq!(
        named("use crate::{Error, lang::Value};", &root_names),
        ["error", "lang"]
    );
    assert!(layer_of("load") > layer_of("lang"));
}
