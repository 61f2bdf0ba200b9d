//! Every file in `lsystems/` is a test input: its output through the
//! command line is compared with a golden file in `tests/data/lsystems/`
//! (same path, another extension) by [`crate::golden`]. These are
//! regression checks: the golden files were written by subgram itself (see
//! `tests/data/lsystems/README.md`); the independent checks of the same
//! files (subdivision matrices, published masks, known counts) are in
//! `curves`, `surface`, `surface_quad` and `corpus`.
//!
//! * a curve L-system (every `.lsys` outside `surfaces/`): the word after
//!   the file's own derivation length, `subgram derive FILE --format json`,
//!   as `NAME.json`, one module per line;
//! * a surface grammar (`surfaces/*.lsys`): `subgram subdivide --grammar
//!   FILE` on the file's own base mesh as `NAME.obj` in a canonical form
//!   ([`canonical_obj`]), and the counts, levels and valences that
//!   `subgram derive FILE` prints as `NAME.txt`; the grammars with boundary
//!   rules also run on `meshes/grid.obj`, as `NAME-on-grid.obj`, and
//!   those with crease rules on a mesh with creases, as
//!   `NAME-creased.obj`;
//! * a vv program (`vv/*.lsys`): as a surface grammar; those with boundary
//!   rules also run on `meshes/pentagon-patch.obj`, as `NAME-on-patch.obj`;
//! * a base mesh (`meshes/*.obj`, `meshes/*.ply`): `subgram mesh info
//!   FILE` as `NAME.txt`; a `meshes/*.creases` file is read with the mesh
//!   beside it;
//! * an open L-system (`open/NAME/`, a model folder): the word of its
//!   `lsystem.l`, derived with the environment its `.e` file names, as
//!   `open/NAME/lsystem.json`; the folder's other files are read with it;
//! * a shape grammar (`shapes/*.lsys`): the OBJ file `subgram subdivide
//!   --grammar FILE -o NAME.obj` writes (one group per terminal shape, in
//!   tree order) as `NAME.obj`, and the shape tree `subgram derive FILE`
//!   prints as `NAME.txt`.
//!
//! Regenerate with `UPDATE_GOLDEN=1 cargo test --test it lsystems::`.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::golden::{self, Kind};
use crate::support::{root, scratch};

/// The folders of `lsystems/`, each checked by its own test below.
const FOLDERS: &[&str] = &[
    "abop", "curves", "figures", "lplusc", "meshes", "open", "paper", "reverse", "shapes",
    "surfaces", "vv",
];

/// Surface grammars with boundary rules, run on the open grid as well.
const ON_GRID: &[&str] = &["c4", "catmull-clark", "four-eight", "loop", "sqrt3"];

/// Surface grammars with crease rules, also run on a mesh with creases,
/// as `NAME-creased.obj`.
const ON_CREASES: &[(&str, &str)] = &[
    ("catmull-clark", "lsystems/meshes/creased-cube.ply"),
    ("loop", "lsystems/meshes/creased-octahedron.obj"),
];

/// vv programs with boundary rules, run on the open triangle patch as well.
const ON_PATCH: &[&str] = &[
    "butterfly",
    "doo-sabin",
    "loop",
    "modified-butterfly",
    "peters-reif",
    "sqrt3",
];

/// The golden files of `lsystems/REL`, with how each is compared; `None`
/// for a file no rule covers.
fn goldens(rel: &Path) -> Option<Vec<(PathBuf, Kind)>> {
    let base = Path::new("tests/data/lsystems").join(rel);
    let stem = rel.file_stem()?.to_str()?;
    let folder = rel.parent()?.to_str()?;
    let with = |suffix: &str| base.with_file_name(format!("{stem}{suffix}"));
    let ext = rel.extension().and_then(|e| e.to_str()).unwrap_or("");
    if folder.starts_with("open/") {
        // A model folder: its program's word (derived with the model's
        // environment); its other files are read with it.
        return Some(match ext {
            "l" => vec![(with(".json"), Kind::Numeric)],
            _ => vec![],
        });
    }
    match (folder, ext) {
        ("meshes", "obj" | "ply" | "off") => Some(vec![(with(".txt"), Kind::Exact)]),
        // The sharpness of the mesh beside it: read with it.
        ("meshes", "creases") => Some(vec![]),
        ("shapes", "lsys") => Some(vec![
            (with(".obj"), Kind::Numeric),
            (with(".txt"), Kind::Numeric),
        ]),
        ("surfaces" | "vv", "lsys") => {
            let mut v = vec![(with(".obj"), Kind::Numeric), (with(".txt"), Kind::Exact)];
            if folder == "surfaces" && ON_GRID.contains(&stem) {
                v.push((with("-on-grid.obj"), Kind::Numeric));
            }
            if folder == "surfaces" && ON_CREASES.iter().any(|(g, _)| *g == stem) {
                v.push((with("-creased.obj"), Kind::Numeric));
            }
            if folder == "vv" && ON_PATCH.contains(&stem) {
                v.push((with("-on-patch.obj"), Kind::Numeric));
            }
            Some(v)
        }
        (_, "lsys") => Some(vec![(with(".json"), Kind::Numeric)]),
        _ => None,
    }
}

fn subgram(args: &[&str]) -> Result<Vec<u8>, String> {
    let o = Command::new(env!("CARGO_BIN_EXE_subgram"))
        .current_dir(root())
        .args(args)
        .output()
        .map_err(|e| format!("the binary does not run: {e}"))?;
    if !o.status.success() {
        return Err(format!(
            "`subgram {}` failed ({}):\n{}",
            args.join(" "),
            o.status,
            String::from_utf8_lossy(&o.stderr)
        ));
    }
    Ok(o.stdout)
}

/// An OBJ text without its numbering: vertices sorted by their rounded
/// positions, each face rotated to start at its smallest new index (its
/// orientation kept), faces sorted. Two runs that make the same surface
/// with the elements numbered differently give the same text.
pub fn canonical_obj(text: &str) -> String {
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut faces: Vec<Vec<usize>> = Vec::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let p: Vec<f64> = words.map(|w| golden::round(w.parse().unwrap())).collect();
                positions.push([p[0], p[1], p[2]]);
            }
            Some("f") => faces.push(
                words
                    .map(|w| w.split('/').next().unwrap().parse::<usize>().unwrap() - 1)
                    .collect(),
            ),
            _ => {}
        }
    }
    let mut order: Vec<usize> = (0..positions.len()).collect();
    order.sort_by(|&a, &b| {
        positions[a]
            .partial_cmp(&positions[b])
            .expect("no NaN in a mesh")
    });
    let mut new_index = vec![0; positions.len()];
    for (new, &old) in order.iter().enumerate() {
        new_index[old] = new;
    }
    let mut faces: Vec<Vec<usize>> = faces
        .into_iter()
        .map(|f| {
            let f: Vec<usize> = f.iter().map(|&i| new_index[i]).collect();
            let start = (0..f.len()).min_by_key(|&k| f[k]).unwrap();
            (0..f.len()).map(|k| f[(start + k) % f.len()]).collect()
        })
        .collect();
    faces.sort();
    let mut out = format!(
        "# {} vertices, {} faces; canonical order (tests/it/lsystems.rs)\n",
        positions.len(),
        faces.len()
    );
    for &i in &order {
        let [x, y, z] = positions[i];
        out += &format!("v {x:?} {y:?} {z:?}\n");
    }
    for f in faces {
        out += "f";
        for i in f {
            out += &format!(" {}", i + 1);
        }
        out += "\n";
    }
    out
}

/// The outputs of `lsystems/REL` in the order of [`goldens`].
fn outputs(rel: &Path) -> Result<Vec<Vec<u8>>, String> {
    let file = Path::new("lsystems").join(rel);
    let f = file.to_str().unwrap();
    let folder = rel.parent().and_then(Path::to_str).unwrap_or("");
    if folder == "meshes" {
        return Ok(vec![subgram(&["mesh", "info", f])?]);
    }
    if folder == "shapes" {
        let stem = rel.file_stem().unwrap().to_str().unwrap();
        let tmp = scratch("shapes");
        let dir = tmp.path();
        let out = dir.join(format!("{stem}.obj"));
        let o = out.to_str().unwrap();
        subgram(&["subdivide", "--grammar", f, "-o", o])?;
        let obj = std::fs::read(&out).map_err(|e| format!("{o}: {e}"))?;
        return Ok(vec![obj, subgram(&["derive", f])?]);
    }
    if folder != "surfaces" && folder != "vv" {
        let json: serde_json::Value =
            serde_json::from_slice(&subgram(&["derive", f, "--format", "json"])?)
                .map_err(|e| format!("{f}: the JSON word does not parse: {e}"))?;
        return Ok(vec![golden::json_lines(&json).into_bytes()]);
    }
    let stem = rel.file_stem().unwrap().to_str().unwrap();
    let tmp = scratch("lsystems");
    let dir = tmp.path();
    let subdivide = |mesh: Option<&str>, out: &str| -> Result<Vec<u8>, String> {
        let out = dir.join(out);
        let o = out.to_str().unwrap();
        let mut args = vec!["subdivide"];
        args.extend(mesh);
        args.extend(["--grammar", f, "-o", o]);
        subgram(&args)?;
        let text = std::fs::read_to_string(&out).map_err(|e| format!("{o}: {e}"))?;
        Ok(canonical_obj(&text).into_bytes())
    };
    let mut v = vec![
        subdivide(None, &format!("{stem}.obj"))?,
        subgram(&["derive", f])?,
    ];
    if folder == "surfaces" && ON_GRID.contains(&stem) {
        v.push(subdivide(
            Some("lsystems/meshes/grid.obj"),
            &format!("{stem}-on-grid.obj"),
        )?);
    }
    if folder == "vv" && ON_PATCH.contains(&stem) {
        v.push(subdivide(
            Some("lsystems/meshes/pentagon-patch.obj"),
            &format!("{stem}-on-patch.obj"),
        )?);
    }
    if let Some((_, mesh)) = ON_CREASES
        .iter()
        .find(|(g, _)| folder == "surfaces" && *g == stem)
    {
        v.push(subdivide(Some(mesh), &format!("{stem}-creased.obj"))?);
    }
    Ok(v)
}

/// The files of `dir`, recursively, relative to `dir`, sorted.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    fn walk(base: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                out.push(p.strip_prefix(base).unwrap().to_path_buf());
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

fn check_folder(folder: &str) {
    let files = files_under(&root().join("lsystems").join(folder));
    assert!(!files.is_empty(), "lsystems/{folder} is empty");
    let mut failures = Vec::new();
    for f in files {
        let rel = Path::new(folder).join(&f);
        let Some(goldens) = goldens(&rel) else {
            failures.push(format!("lsystems/{}: no golden rule", rel.display()));
            continue;
        };
        if goldens.is_empty() {
            // An input read with another file (a `.creases` file).
            continue;
        }
        match outputs(&rel) {
            Ok(outs) => {
                for ((path, kind), out) in goldens.iter().zip(outs) {
                    failures.extend(golden::compare(path, &out, *kind).err());
                }
            }
            Err(e) => failures.push(e),
        }
    }
    golden::assert_all(failures);
}

#[test]
fn abop() {
    check_folder("abop");
}

#[test]
fn curves() {
    check_folder("curves");
}

#[test]
fn figures() {
    check_folder("figures");
}

#[test]
fn lplusc() {
    check_folder("lplusc");
}

#[test]
fn meshes() {
    check_folder("meshes");
}

#[test]
fn paper() {
    check_folder("paper");
}

#[test]
fn open() {
    check_folder("open");
}

#[test]
fn reverse() {
    check_folder("reverse");
}

#[test]
fn shapes() {
    check_folder("shapes");
}

#[test]
fn surfaces() {
    check_folder("surfaces");
}

#[test]
fn vv() {
    check_folder("vv");
}

/// No file of `lsystems/` escapes the tests above, and no golden file is
/// left over from a file that is gone.
#[test]
fn every_lsystems_file_is_a_test_input() {
    let mut folders: Vec<String> = std::fs::read_dir(root().join("lsystems"))
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            assert!(
                e.path().is_dir(),
                "{}: files in lsystems/ itself are not checked; put it in a folder",
                e.path().display()
            );
            e.file_name().into_string().unwrap()
        })
        .collect();
    folders.sort();
    assert_eq!(folders, FOLDERS, "a folder of lsystems/ has no test here");
    let mut expected: Vec<PathBuf> = vec![PathBuf::from("tests/data/lsystems/README.md")];
    for rel in files_under(&root().join("lsystems")) {
        let g =
            goldens(&rel).unwrap_or_else(|| panic!("lsystems/{}: no golden rule", rel.display()));
        expected.extend(g.into_iter().map(|(p, _)| p));
    }
    let data = Path::new("tests/data/lsystems");
    for f in files_under(&root().join(data)) {
        let p = data.join(&f);
        assert!(
            expected.contains(&p),
            "{}: a golden file without its lsystems/ source",
            p.display()
        );
    }
}

/// The canonical form does not depend on the numbering, and keeps each
/// face's orientation.
#[test]
fn canonical_obj_forgets_the_numbering_only() {
    let a = "v 1 0 0\nv 0 0 0\nv 0 1 0\nf 1 3 2\n";
    let b = "v 0 1 0\nv 0 0 0\nv 1 0 0\nf 2 3 1\n";
    assert_eq!(canonical_obj(a), canonical_obj(b));
    let flipped = "v 0 1 0\nv 0 0 0\nv 1 0 0\nf 2 1 3\n";
    assert_ne!(canonical_obj(a), canonical_obj(flipped));
    assert!(canonical_obj(a).ends_with("v 0.0 0.0 0.0\nv 0.0 1.0 0.0\nv 1.0 0.0 0.0\nf 1 3 2\n"));
}
