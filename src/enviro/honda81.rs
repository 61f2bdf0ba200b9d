//! vlab's `honda81`, built in: the density field of Honda (1981) that
//! open L-systems use to stop colliding branches.
//!
//! Its parameter file (`density.spec` in vlab's models) has the lines
//! `radius: R`, `3d case: on|off` and `verbose: on|off`. Each step, every
//! query `E(vigor[, index])` is answered 0 (stop) when another query of the
//! same index with a vigor at least its own lies within the radius, and 1
//! (grow) otherwise. Distances are taken in x, y and z with `3d case: on`,
//! else in x and z; the index is the second value cut to an integer (0
//! without one).
//!
//! The answers are vlab's to the bit: the program reads the position that
//! lpfg prints with the `.e` file's format back into `float`s, and works
//! in `float` (the squared radius and the squared distances too), which is
//! what this port does (see `honda81.c` of vlab's ENVIRO, whose facts are
//! described in `../shared/tools/lpfg/README.md`).

use std::path::{Path, PathBuf};

use crate::deadline::Deadline;
use crate::model::comm::CommSpec;
use crate::model::ModelError;
use crate::rewrite::environment::{Answer, Environment, EnvironmentStarter, Query};

use super::protocol::{as_received, position_as_read};
use super::spec_file;

/// honda81's settings, from its parameter file.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// The radius, squared in `float` as honda81 squares it.
    pub radius2: f32,
    /// `3d case: on`.
    pub three_d: bool,
    pub verbose: bool,
}

impl Settings {
    /// honda81's defaults: radius 0, the 2D case (x and z).
    pub fn new(radius: f32, three_d: bool) -> Settings {
        Settings {
            radius2: radius * radius,
            three_d,
            verbose: false,
        }
    }

    /// Reads a parameter file (`path`, whose text is `text`).
    pub fn read(path: &Path, text: &str) -> Result<Settings, ModelError> {
        let shown = path.display().to_string();
        let mut s = Settings::new(0.0, false);
        for line in spec_file::lines(&shown, text) {
            match line.key {
                "radius" => {
                    let r = line.number()? as f32;
                    if !r.is_finite() {
                        return Err(line.bad_value("the radius must be finite".into()));
                    }
                    s.radius2 = r * r;
                }
                "3d case" => s.three_d = line.on_off()?,
                "verbose" => s.verbose = line.on_off()?,
                _ => return Err(line.unknown("honda81", &["radius", "3d case", "verbose"])),
            }
        }
        Ok(s)
    }
}

/// One query as honda81 holds it.
#[derive(Clone, Copy, Debug)]
struct Item {
    /// (x, y, z), or (x, z) in the 2D case.
    at: [f32; 3],
    vigor: f32,
    index: i32,
    id: u64,
}

/// honda81's answers to one step's queries: 0 or 1 each.
pub fn answer(settings: &Settings, spec: &CommSpec, queries: &[Query]) -> Vec<Answer> {
    let items: Vec<Item> = queries
        .iter()
        .filter_map(|q| item(settings, spec, q))
        .collect();
    let dims = if settings.three_d { 3 } else { 2 };
    let blocked = |i: usize, j: usize| -> bool {
        let (a, b) = (&items[i], &items[j]);
        if i == j || a.index != b.index || a.vigor > b.vigor {
            return false;
        }
        let mut d2 = 0.0f32;
        for k in 0..dims {
            let d = a.at[k] - b.at[k];
            d2 += d * d;
        }
        d2 <= settings.radius2
    };
    let grow: Vec<bool> = match Grid::new(&items, settings.radius2, dims) {
        Some(grid) => (0..items.len())
            .map(|i| !grid.near(&items[i]).any(|j| blocked(i, j)))
            .collect(),
        None => (0..items.len())
            .map(|i| !(0..items.len()).any(|j| blocked(i, j)))
            .collect(),
    };
    items
        .iter()
        .zip(grow)
        .map(|(it, g)| Answer {
            id: it.id,
            values: vec![if g { 1.0 } else { 0.0 }],
        })
        .collect()
}

/// The query as honda81 reads it from lpfg's text: the position line
/// printed with the `.e` file's format and read back as three `float`s
/// after the text before its first conversion. `None` where honda81 gets
/// no position or no value (it answers nothing then).
fn item(settings: &Settings, spec: &CommSpec, q: &Query) -> Option<Item> {
    let p = position_as_read(spec, q.frame.position)?;
    let vigor = as_received(*q.values.first()?);
    let index = q.values.get(1).map_or(0, |v| as_received(*v) as i32);
    let at = if settings.three_d {
        p
    } else {
        [p[0], p[2], 0.0]
    };
    Some(Item {
        at,
        vigor,
        index,
        id: q.id,
    })
}

/// Queries bucketed by cells one radius wide, so that each query is
/// compared with its neighbours only; the comparison itself is the exact
/// one. `None` when a plain double loop is as good (few queries, a zero or
/// non-finite radius, positions too far out for cells).
struct Grid {
    cells: std::collections::HashMap<[i64; 3], Vec<usize>, CellHash>,
    size: f64,
    dims: usize,
}

impl Grid {
    fn new(items: &[Item], radius2: f32, dims: usize) -> Option<Grid> {
        let size = (radius2 as f64).sqrt();
        if items.len() < 512 || size.is_nan() || size <= 0.0 || !size.is_finite() {
            return None;
        }
        let mut cells: std::collections::HashMap<[i64; 3], Vec<usize>, CellHash> =
            Default::default();
        for (i, it) in items.iter().enumerate() {
            cells
                .entry(Self::cell(it, size, dims)?)
                .or_default()
                .push(i);
        }
        Some(Grid { cells, size, dims })
    }

    fn cell(it: &Item, size: f64, dims: usize) -> Option<[i64; 3]> {
        let mut c = [0i64; 3];
        for (c, x) in c.iter_mut().zip(&it.at).take(dims) {
            let v = (*x as f64 / size).floor();
            if v.is_nan() || v.abs() >= 1e15 {
                return None;
            }
            *c = v as i64;
        }
        Some(c)
    }

    /// The queries in the cells around `it`'s (its own included).
    fn near<'a>(&'a self, it: &Item) -> impl Iterator<Item = usize> + 'a {
        let c = Self::cell(it, self.size, self.dims).unwrap_or_default();
        let span = |k: usize| if k < self.dims { -1..=1 } else { 0..=0 };
        let mut keys = Vec::with_capacity(27);
        for dx in span(0) {
            for dy in span(1) {
                for dz in span(2) {
                    keys.push([c[0] + dx, c[1] + dy, c[2] + dz]);
                }
            }
        }
        keys.into_iter()
            .filter_map(|k| self.cells.get(&k))
            .flatten()
            .copied()
    }
}

/// A fast hash of cell coordinates (no defence against chosen keys is
/// needed: the keys are the model's own positions, and a bad spread only
/// costs time).
#[derive(Clone, Copy, Default)]
struct CellHash;

impl std::hash::BuildHasher for CellHash {
    type Hasher = CellHasher;
    fn build_hasher(&self) -> CellHasher {
        CellHasher(0)
    }
}

/// Multiply-rotate mixing, one word at a time.
struct CellHasher(u64);

impl std::hash::Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for c in bytes.chunks(8) {
            let mut w = [0u8; 8];
            w[..c.len()].copy_from_slice(c);
            self.write_u64(u64::from_le_bytes(w));
        }
    }
    fn write_i64(&mut self, v: i64) {
        self.write_u64(v as u64);
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

/// Starts the built-in honda81 for each run.
#[derive(Clone, Debug)]
pub struct Starter {
    pub settings: Settings,
    pub spec: CommSpec,
    /// The parameter file read, for messages.
    pub file: PathBuf,
}

impl EnvironmentStarter for Starter {
    fn start(&self, _deadline: Option<Deadline>) -> Result<Box<dyn Environment>, String> {
        Ok(Box::new(Honda81 {
            settings: self.settings.clone(),
            spec: self.spec.clone(),
        }))
    }

    fn following_module(&self) -> bool {
        self.spec.following
    }
}

/// The built-in honda81, running.
#[derive(Debug)]
struct Honda81 {
    settings: Settings,
    spec: CommSpec,
}

impl Environment for Honda81 {
    fn exchange(&mut self, queries: &[Query]) -> Result<Vec<Answer>, String> {
        Ok(answer(&self.settings, &self.spec, queries))
    }
}
