//! The README and the user guide as a new user reads them (issue 18's
//! rough edges, issue 40's front door): what their commands write is
//! ignored by git, the `subgram` command is installed before it is used,
//! the command table names every view, the language example draws its
//! closed curve, and the README is a short page that starts with the two
//! commands and needs nothing beside the clone.

use crate::support::root;

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The shell commands of a Markdown text's `sh` blocks, continuation
/// lines joined, comments dropped.
fn commands(readme: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut inside = false;
    let mut pending = String::new();
    for line in readme.lines() {
        if line.starts_with("```") {
            inside = line.trim() == "```sh";
            continue;
        }
        if !inside {
            continue;
        }
        let code = line.split(" #").next().unwrap_or("").trim_end();
        match code.strip_suffix('\\') {
            Some(head) => pending.push_str(head),
            None => {
                pending.push_str(code);
                if !pending.trim().is_empty() {
                    out.push(pending.trim().to_string());
                }
                pending.clear();
            }
        }
    }
    out
}

/// The files a `subgram` command line writes: `-o`, `--figure` and
/// `--details` arguments, and the output of `mesh convert`.
fn outputs(command: &str) -> Vec<String> {
    let words: Vec<&str> = command.split_whitespace().collect();
    let mut out = Vec::new();
    for (k, w) in words.iter().enumerate() {
        if matches!(*w, "-o" | "--output" | "--figure" | "--details") {
            if let Some(f) = words.get(k + 1) {
                out.push(f.to_string());
            }
        }
    }
    if let Some(k) = words.windows(2).position(|w| w == ["mesh", "convert"]) {
        if let Some(f) = words.get(k + 3) {
            out.push(f.to_string());
        }
    }
    // An OBJ output brings its MTL beside it (shape grammars).
    let mtl: Vec<String> = out
        .iter()
        .filter_map(|f| f.strip_suffix(".obj").map(|s| format!("{s}.mtl")))
        .collect();
    out.extend(mtl);
    out
}

/// Whether `.gitignore` ignores the top-level file `name`: a `/NAME`
/// line, or a `/*.EXT` line for its extension.
fn ignored(gitignore: &str, name: &str) -> bool {
    gitignore.lines().map(str::trim).any(|p| {
        p.strip_prefix('/').is_some_and(|p| {
            p == name
                || p.strip_prefix('*')
                    .is_some_and(|ext| ext.starts_with('.') && name.ends_with(ext))
        })
    })
}

#[test]
fn every_file_the_readme_commands_write_at_the_top_level_is_ignored() {
    let gitignore = read(".gitignore");
    let mut pages = vec!["README.md".to_string()];
    pages.extend(crate::guide::chapters());
    let mut cmds = Vec::new();
    for p in &pages {
        cmds.extend(commands(&read(p)).into_iter().map(|c| (p.clone(), c)));
    }
    assert!(cmds.len() > 10, "{cmds:?}");
    let mut seen = 0;
    for (page, c) in cmds
        .iter()
        .filter(|(_, c)| c.contains("subgram ") || c.starts_with("cargo run"))
    {
        for f in outputs(c) {
            if f.contains('/') {
                continue;
            }
            seen += 1;
            assert!(
                ignored(&gitignore, &f),
                "`{f}`, written by `{c}` in {page}, is not in .gitignore"
            );
        }
    }
    assert!(seen > 10, "{seen} outputs");
    // The matcher itself: a pattern for another extension does not match.
    assert!(ignored("/*.png\n", "a.png") && !ignored("/*.png\n", "a.txt"));
}

/// In the README, and in the guide read in its order, the install comes
/// before the first command that runs a bare `subgram`.
#[test]
fn the_readme_says_how_to_get_the_subgram_command_before_using_it() {
    let mut guide = String::new();
    for c in crate::guide::chapters() {
        guide.push_str(&read(&c));
    }
    for (name, text) in [("README.md", read("README.md")), ("the guide", guide)] {
        let install = text
            .find("cargo install --path .")
            .unwrap_or_else(|| panic!("{name} says how to install the command"));
        let first_use = commands(&text)
            .into_iter()
            .find(|c| c.starts_with("subgram "))
            .expect("a bare subgram command");
        let used = text.find(&first_use).unwrap();
        assert!(
            install < used,
            "{name}: `{first_use}` comes before the install"
        );
    }
}

/// The guide's command table (the README's, before issue 40).
#[test]
fn the_command_table_names_every_view() {
    let table = read("docs/guide/src/commands.md");
    let row = table
        .lines()
        .find(|l| l.starts_with("| `subgram render "))
        .expect("the render row");
    for v in ["xy", "xz", "yz"] {
        assert!(row.contains(&format!("`{v}`")), "{v}: {row}");
    }
    for v in ["iso", "front", "back", "left", "right", "top", "bottom"] {
        assert!(subgram::render::mesh::view_direction(v).is_some(), "{v}");
        assert!(row.contains(&format!("`{v}`")), "{v}: {row}");
    }
}

/// The program of the guide's "The language in one example", run as
/// printed: its picture is the closed curve of its points, each segment
/// from a point to the next around the ring, and no segment from the
/// turtle's start at the origin (no derived point is there).
#[test]
fn the_language_example_draws_its_closed_curve_and_nothing_else() {
    let guide = read("docs/guide/src/language.md");
    let at = guide.find("## The language in one example").unwrap();
    let start = at + guide[at..].find("```c\n").unwrap() + 5;
    let end = start + guide[start..].find("```").unwrap();
    let l = crate::support::load_text(&guide[start..end]);
    let mut run = l.run(subgram::DeriveOptions::default()).unwrap();
    let pts = crate::support::points(&l, &crate::support::derive(&l, Default::default()), "P");
    assert_eq!(pts.len(), 3 << 4, "three points, four Chaikin steps");
    let mut segments = Vec::new();
    for e in run.events().unwrap() {
        segments.extend(e.segments().map(|(a, b)| (a.truncate(), b.truncate())));
    }
    assert_eq!(segments.len(), pts.len(), "one segment per point");
    for (k, &(a, b)) in segments.iter().enumerate() {
        let i = (k + pts.len() - 1) % pts.len();
        assert!(
            a.distance(pts[i]) < 1e-6 && b.distance(pts[k]) < 1e-6,
            "segment {k}: {a} {b}"
        );
    }
    assert!(
        pts.iter().all(|p| p.length() > 0.1),
        "no point at the origin"
    );
}

/// The README is a front door (issue 40): at most 250 lines, starting
/// with the two commands, every shell command in it runnable in a clone
/// with nothing beside it, and links into the guide.
#[test]
fn the_readme_is_a_short_front_door_that_starts_with_the_two_commands() {
    let readme = read("README.md");
    let lines = readme.lines().count();
    assert!(
        lines <= 250,
        "README.md has {lines} lines; the guide takes the rest"
    );
    let first = readme.find("```").expect("a code block");
    assert!(
        readme[first..].starts_with(
            "```sh\ncargo run --release -- render lsystems/figures/fig10-kolam.lsys -o kolam.png\ncargo test\n```\n"
        ),
        "the README's first block is not the two commands"
    );
    assert!(
        !readme.contains("../shared"),
        "the README points into ../shared, which a clone does not have"
    );
    let links = readme.matches("](docs/guide/src/").count();
    assert!(links >= 10, "{links} links into the guide");
}

/// Every package the Python scripts of `benches/` import, beyond Python's
/// own library, is in `benches/requirements.txt` (issue 18: they needed
/// numpy, scipy, libigl, pymeshlab, compas_cgal and bpy, and nothing said
/// so).
#[test]
fn every_package_the_bench_scripts_import_is_in_the_requirements() {
    // Import names to the names pip installs.
    const PACKAGES: &[(&str, &str)] = &[
        ("numpy", "numpy"),
        ("scipy", "scipy"),
        ("igl", "libigl"),
        ("pymeshlab", "pymeshlab"),
        ("vtk", "vtk"),
        ("compas", "compas"),
        ("compas_cgal", "compas_cgal"),
        ("PIL", "pillow"),
        ("trimesh", "trimesh"),
        ("bpy", "bpy"),
        ("matplotlib", "matplotlib"),
    ];
    const STANDARD: &[&str] = &[
        "argparse",
        "hashlib",
        "itertools",
        "json",
        "math",
        "os",
        "re",
        "shutil",
        "struct",
        "subprocess",
        "sys",
        "tempfile",
        "time",
        "collections",
        "pathlib",
        "functools",
        "statistics",
        "random",
        "glob",
        "textwrap",
        "io",
        "dataclasses",
        "typing",
        "zlib",
        "warnings",
        "base64",
        "select",
        "csv",
        "platform",
        "urllib",
    ];
    // The project's own Python beside the benches: the browser tests'
    // DevTools driver, which `page_3d.py` borrows.
    const PROJECT: &[(&str, &str)] = &[("serve", "tests/browser/serve.py")];
    for (_, path) in PROJECT {
        assert!(root().join(path).is_file(), "{path} is gone");
    }
    let dir = root().join("benches");
    let req = std::fs::read_to_string(dir.join("requirements.txt")).unwrap();
    let pinned: Vec<&str> = req
        .lines()
        .filter(|l| !l.trim_start().starts_with('#') && !l.trim().is_empty())
        .map(|l| l.split("==").next().unwrap().trim())
        .collect();
    let local: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            e.ok()?
                .file_name()
                .to_str()?
                .strip_suffix(".py")
                .map(String::from)
        })
        .collect();
    let mut checked = 0;
    for name in &local {
        let text = std::fs::read_to_string(dir.join(format!("{name}.py"))).unwrap();
        for line in text.lines().map(str::trim_start) {
            let module = match line.split_whitespace().collect::<Vec<_>>()[..] {
                ["import", m, ..] | ["from", m, "import", ..] => m,
                _ => continue,
            };
            let top = module.split('.').next().unwrap().trim_end_matches(',');
            if STANDARD.contains(&top)
                || local.iter().any(|l| l == top)
                || PROJECT.iter().any(|(m, _)| *m == top)
            {
                continue;
            }
            let package = PACKAGES
                .iter()
                .find(|(m, _)| *m == top)
                .unwrap_or_else(|| panic!("benches/{name}.py imports `{top}`: add it to this test's table and to requirements.txt"))
                .1;
            assert!(
                pinned.contains(&package),
                "benches/{name}.py imports `{top}`; `{package}` is not in benches/requirements.txt"
            );
            checked += 1;
        }
    }
    assert!(checked >= 6, "{checked} imports checked");
}
