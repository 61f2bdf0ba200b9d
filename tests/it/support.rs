//! Shared helpers: loading files, reading points out of words, figures,
//! and the subdivision matrices that serve as oracles. The `shared` test
//! target (tests/shared) includes this file too.

use std::path::PathBuf;

use glam::{DVec2, DVec3};
use subgram::mesh::PolygonSoup;
use subgram::render::{RenderOptions, Scene};
use subgram::Value;
use subgram::{Curve as Loaded, DeriveOptions, Derived, FigureOptions};

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh, empty scratch folder in the system's temp dir, named
/// `subgram-NAME-` and a random tail. The folder and all in it are removed
/// when the returned `TempDir` is dropped, even when the test panics: bind
/// it to a variable that lives as long as the test (or a program the test
/// runs, or a watcher it starts) uses the folder, and do not `keep()` it.
pub fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("subgram-{name}-"))
        .tempdir()
        .unwrap_or_else(|e| panic!("cannot create a scratch folder for {name}: {e}"))
}

/// `lsystems/NAME` inside the project.
pub fn lsys(name: &str) -> PathBuf {
    root().join("lsystems").join(name)
}

pub fn load(path: &PathBuf) -> Loaded {
    match subgram::load_file(path, &[]) {
        Ok(l) => l,
        Err(e) => panic!("{} does not load:\n{}", path.display(), e),
    }
}

pub fn load_text(text: &str) -> Loaded {
    match subgram::load_str("test.lsys", text, &[]) {
        Ok(l) => l,
        Err(e) => panic!("the test program does not load:\n{e}"),
    }
}

pub fn derive(l: &Loaded, opts: DeriveOptions) -> Derived {
    match subgram::derive(&l.program, opts) {
        Ok(d) => d,
        Err(e) => panic!("derivation failed:\n{}", l.error(e)),
    }
}

/// The figure of the file at `path`.
pub fn figure(path: &PathBuf, opts: FigureOptions) -> Scene {
    let l = load(path);
    l.figure(&opts).unwrap_or_else(|e| panic!("{e}"))
}

/// Figure options for a `w` × `h` picture.
pub fn sized(w: u32, h: u32) -> FigureOptions {
    FigureOptions {
        render: RenderOptions {
            width: w,
            height: h,
            ..RenderOptions::default()
        },
        ..FigureOptions::default()
    }
}

/// Segments (`L` commands), circles and polygons in an SVG document.
pub fn svg_counts(doc: &str) -> (usize, usize, usize) {
    let mut segments = 0;
    for part in doc.split(" d=\"").skip(1) {
        let d = &part[..part.find('"').unwrap()];
        segments += d.matches('L').count();
    }
    (
        segments,
        doc.matches("<circle").count(),
        doc.matches("<polygon").count(),
    )
}

/// The word as text, for compact assertions.
pub fn text(l: &Loaded, d: &Derived) -> String {
    subgram::output::word_text(&d.word, &l.program.alphabet, &l.program.structs)
}

/// The V2 parameters of all modules named `name`, in word order.
pub fn points(l: &Loaded, d: &Derived, name: &str) -> Vec<DVec2> {
    d.word
        .modules(&l.program.alphabet, &l.program.structs)
        .filter(|(s, _)| l.program.alphabet.name(*s) == name)
        .filter_map(|(_, ps)| match ps.first() {
            Some(Value::V2(v)) => Some(*v),
            _ => None,
        })
        .collect()
}

pub fn count(l: &Loaded, d: &Derived, name: &str) -> usize {
    d.word
        .syms()
        .iter()
        .filter(|s| l.program.alphabet.name(**s) == name)
        .count()
}

/// A dense matrix of rows of weights.
pub type Matrix = Vec<Vec<f64>>;

pub fn apply(m: &Matrix, pts: &[DVec2]) -> Vec<DVec2> {
    m.iter()
        .map(|row| {
            assert_eq!(row.len(), pts.len(), "matrix and polygon disagree");
            row.iter().zip(pts).map(|(w, p)| *w * *p).sum()
        })
        .collect()
}

/// Closed Chaikin, matrix (8) of paper 002: old point i gives rows 2i, 2i+1.
pub fn chaikin_closed(n: usize) -> Matrix {
    let mut m = vec![vec![0.0; n]; 2 * n];
    for i in 0..n {
        m[2 * i][(i + n - 1) % n] += 0.25;
        m[2 * i][i] += 0.75;
        m[2 * i + 1][i] += 0.75;
        m[2 * i + 1][(i + 1) % n] += 0.25;
    }
    m
}

/// Closed cubic B-spline, matrix (21): a vertex row 1/8 3/4 1/8 and an edge row 1/2 1/2.
pub fn cubic_closed(n: usize) -> Matrix {
    let mut m = vec![vec![0.0; n]; 2 * n];
    for i in 0..n {
        m[2 * i][(i + n - 1) % n] += 0.125;
        m[2 * i][i] += 0.75;
        m[2 * i][(i + 1) % n] += 0.125;
        m[2 * i + 1][i] += 0.5;
        m[2 * i + 1][(i + 1) % n] += 0.5;
    }
    m
}

/// Closed four-point, matrix (24): a copy, then -1/16 9/16 9/16 -1/16.
pub fn four_point_closed(n: usize) -> Matrix {
    let mut m = vec![vec![0.0; n]; 2 * n];
    for i in 0..n {
        m[2 * i][i] = 1.0;
        m[2 * i + 1][(i + n - 1) % n] += -1.0 / 16.0;
        m[2 * i + 1][i] += 9.0 / 16.0;
        m[2 * i + 1][(i + 1) % n] += 9.0 / 16.0;
        m[2 * i + 1][(i + 2) % n] += -1.0 / 16.0;
    }
    m
}

/// Open Chaikin, matrix (27): the end points stay, the end segments get
/// their midpoint, every inner segment gets the 3/4-1/4 pair.
pub fn chaikin_open(n: usize) -> Matrix {
    let mut m = Vec::new();
    let row = |pairs: &[(usize, f64)]| {
        let mut r = vec![0.0; n];
        for &(i, w) in pairs {
            r[i] += w;
        }
        r
    };
    m.push(row(&[(0, 1.0)]));
    m.push(row(&[(0, 0.5), (1, 0.5)]));
    for i in 1..n - 2 {
        m.push(row(&[(i, 0.75), (i + 1, 0.25)]));
        m.push(row(&[(i, 0.25), (i + 1, 0.75)]));
    }
    m.push(row(&[(n - 2, 0.5), (n - 1, 0.5)]));
    m.push(row(&[(n - 1, 1.0)]));
    m
}

/// Reverse Chaikin of a closed curve, matrix (37): n rows, 2n columns,
/// row j is -1/4 3/4 3/4 -1/4 centred on the pair (2j, 2j+1).
pub fn reverse_chaikin_closed(n2: usize) -> Matrix {
    let n = n2 / 2;
    let mut m = vec![vec![0.0; n2]; n];
    for (j, r) in m.iter_mut().enumerate() {
        r[(2 * j + n2 - 1) % n2] += -0.25;
        r[2 * j] += 0.75;
        r[2 * j + 1] += 0.75;
        r[(2 * j + 2) % n2] += -0.25;
    }
    m
}

/// Applies `m(len)` `steps` times.
pub fn iterate(pts: &[DVec2], steps: usize, m: impl Fn(usize) -> Matrix) -> Vec<DVec2> {
    let mut p = pts.to_vec();
    for _ in 0..steps {
        p = apply(&m(p.len()), &p);
    }
    p
}

/// Asserts `got` equals `want` up to a cyclic shift (rings have no start).
pub fn assert_cyclic_eq(got: &[DVec2], want: &[DVec2], eps: f64) {
    assert_eq!(got.len(), want.len(), "point counts differ");
    let n = got.len();
    let shift = (0..n).find(|s| (0..n).all(|i| got[(i + s) % n].abs_diff_eq(want[i], eps)));
    assert!(
        shift.is_some(),
        "no cyclic shift matches\n got: {got:?}\nwant: {want:?}"
    );
}

pub fn assert_points_eq(got: &[DVec2], want: &[DVec2], eps: f64) {
    assert_eq!(got.len(), want.len(), "point counts differ");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(g.abs_diff_eq(*w, eps), "point {i}: got {g}, want {w}");
    }
}

/// The axiom of a program written as `P(V2f(x, y)) ...`.
pub fn axiom_of(pts: &[DVec2]) -> String {
    pts.iter()
        .map(|p| format!("P(V2f({:?}, {:?}))", p.x, p.y))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The hexagon the `lsystems/curves` files use.
pub fn hexagon() -> Vec<DVec2> {
    [(0., 0.), (1., 3.), (4., 4.), (7., 3.), (6., 0.), (3., -1.)]
        .iter()
        .map(|&(x, y)| DVec2::new(x, y))
        .collect()
}

/// The open polygon of `lsystems/curves/open-*.lsys`.
pub fn open_polygon() -> Vec<DVec2> {
    [(0., 0.), (1., 3.), (4., 4.), (7., 3.), (8., 0.), (11., 1.)]
        .iter()
        .map(|&(x, y)| DVec2::new(x, y))
        .collect()
}

pub struct Rng(pub u64);

impl Rng {
    pub fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The soup with every position moved at random, so that masks cannot hide.
pub fn jitter(mut s: PolygonSoup, seed: u64) -> PolygonSoup {
    let mut r = Rng(seed);
    for p in &mut s.positions {
        *p += DVec3::new(r.unit(), r.unit(), r.unit()) * 0.3 - 0.15;
    }
    s
}

/// The word a program's text derives.
pub fn run(src: &str) -> String {
    let l = load_text(src);
    let d = derive(&l, DeriveOptions::default());
    text(&l, &d)
}

/// The error a program's derivation stops with, rendered.
pub fn run_error(src: &str) -> String {
    let l = load_text(src);
    match subgram::derive(&l.program, DeriveOptions::default()) {
        Ok(d) => panic!("expected an error, derived {}", text(&l, &d)),
        Err(e) => l.error(e).to_string(),
    }
}

/// The diagnostics of a program's text that does not load.
pub fn load_error(src: &str) -> String {
    match subgram::load_str("test.lsys", src, &[]) {
        Ok(_) => panic!("expected the program to be refused"),
        Err(e) => e.to_string(),
    }
}

/// The valences a test measures: every one it names (`all`) in an
/// optimised build, and `quick` in a debug build, where one valence of a
/// two-step grammar takes seconds. `.ci/run` runs these tests in release
/// too (`cargo test --release --test it -- analyze:: surface_c4::`), so
/// every valence named here is checked there.
pub fn valences(all: &[usize], quick: &[usize]) -> Vec<usize> {
    if cfg!(debug_assertions) {
        quick.to_vec()
    } else {
        all.to_vec()
    }
}

/// The `subgram` binary run with `args` in the folder `dir`.
pub fn subgram_in(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}
