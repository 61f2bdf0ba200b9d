//! vlab's `shadowpyramid`, built in: the shadow-pyramid light model of
//! Palubicki et al., "Self-organizing tree models for image synthesis"
//! (SIGGRAPH 2009), which open L-systems read to grow towards light.
//!
//! Space `[-S, S] × [0, 2S] × [-S, S]` (S: `grid span:`) is a cube of N³
//! voxels (N: `grid size:`), each holding light in 0..1. Every step the
//! light is reset to 1 (with `light randomness:` and `light vertical
//! bias:` as vlab's documentation describes), then each query whose first
//! value is positive casts a shadow: below its voxel, tier i (i = 0 ..
//! `shadow depth:` − 1) darkens a (2⌊i·spread⌋+1)² square of voxels, each
//! multiplied by 1 − min(1, w·d^−dist) (w: `shadow weight:`, d: `shadow
//! dissipation:`, dist: the voxel's distance in voxels). Then every query
//! is answered with the light at its position, interpolated between the 8
//! voxels around it, and, when it sent four values or more, the light's
//! gradient there (central differences `sample radius:` apart).
//!
//! The facts are those of vlab's `ENVIRO/shadowpyramid` (its `doc.txt`,
//! and its source read for the arithmetic: `float` throughout, the
//! answers printed with `%g`, the random numbers `drand48`'s). An answer
//! goes back with as many values as the query sent: `E1` gets the light,
//! `E2` the light and 0, `EA20` the light, the gradient and zeros.

use std::path::{Path, PathBuf};

use crate::deadline::Deadline;
use crate::lang::cfmt;
use crate::lang::Value;
use crate::model::comm::CommSpec;
use crate::model::ModelError;
use crate::rewrite::environment::{Answer, Environment, EnvironmentStarter, Query};

use super::protocol::{as_received, position_as_read};
use super::spec_file;

/// The largest `grid size:` taken (N³ voxels of 4 bytes: 1.6 GB at 750).
pub const MAX_GRID_SIZE: i64 = 750;

/// shadowpyramid's settings, from its specification file.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub grid_size: usize,
    pub grid_span: f32,
    pub spread: f32,
    pub depth: i32,
    pub weight: f32,
    pub dissipation: f32,
    pub randomness: f32,
    pub vertical_bias: f32,
    pub sample_radius: f32,
    pub verbose: bool,
}

impl Default for Settings {
    /// vlab's defaults.
    fn default() -> Self {
        Settings {
            grid_size: 201,
            grid_span: 200.0,
            spread: 1.0,
            depth: 6,
            weight: 0.58,
            dissipation: 6.9,
            randomness: 0.0,
            vertical_bias: 0.0,
            sample_radius: 1.6,
            verbose: false,
        }
    }
}

const KEYS: &[&str] = &[
    "verbose",
    "grid size",
    "grid span",
    "shadow spread",
    "shadow depth",
    "shadow weight",
    "shadow dissipation",
    "light randomness",
    "light vertical bias",
    "sample radius",
];

impl Settings {
    /// Reads a specification file (`path`, whose text is `text`).
    pub fn read(path: &Path, text: &str) -> Result<Settings, ModelError> {
        let shown = path.display().to_string();
        let mut s = Settings::default();
        for line in spec_file::lines(&shown, text) {
            if !KEYS.contains(&line.key) {
                return Err(line.unknown("shadowpyramid", KEYS));
            }
            if line.key == "verbose" {
                s.verbose = line.on_off()?;
                continue;
            }
            let v = line.number()?;
            let whole = |what: &str, lo: i64, hi: i64| -> Result<i64, ModelError> {
                if v.fract() != 0.0 || v < lo as f64 || v > hi as f64 {
                    return Err(
                        line.bad_value(format!("{what} must be a whole number from {lo} to {hi}"))
                    );
                }
                Ok(v as i64)
            };
            match line.key {
                "grid size" => s.grid_size = whole("the grid size", 2, MAX_GRID_SIZE)? as usize,
                "grid span" => s.grid_span = v as f32,
                "shadow spread" => s.spread = v as f32,
                "shadow depth" => s.depth = whole("the shadow depth", 0, 10_000)? as i32,
                "shadow weight" => s.weight = v as f32,
                "shadow dissipation" => s.dissipation = v as f32,
                "light randomness" => s.randomness = v as f32,
                "light vertical bias" => s.vertical_bias = v as f32,
                _ => s.sample_radius = v as f32,
            }
        }
        if s.grid_span <= 0.0 {
            return Err(ModelError::file(
                shown,
                "shadowpyramid's grid span must be positive",
            ));
        }
        Ok(s)
    }
}

/// C's `drand48`: a 48-bit linear congruential generator, started where
/// the C library starts it.
#[derive(Clone, Debug)]
struct Drand48(u64);

impl Drand48 {
    fn new() -> Drand48 {
        Drand48(0x1234_ABCD_330E)
    }

    fn next(&mut self) -> f64 {
        self.0 = (self.0.wrapping_mul(0x5_DEEC_E66D).wrapping_add(0xB)) & ((1 << 48) - 1);
        self.0 as f64 / (1u64 << 48) as f64
    }
}

/// The light field.
#[derive(Debug)]
struct Light {
    s: Settings,
    n: usize,
    /// World coordinates to voxel indices.
    scale: f32,
    exposure: Vec<f32>,
    random: Drand48,
}

impl Light {
    fn new(s: Settings) -> Light {
        let n = s.grid_size;
        Light {
            scale: (n as f32 - 1.0) / (s.grid_span * 2.0),
            exposure: vec![1.0; n * n * n],
            random: Drand48::new(),
            n,
            s,
        }
    }

    fn at(&self, x: usize, y: usize, z: usize) -> usize {
        (x * self.n + y) * self.n + z
    }

    /// Every voxel back to full light (with the randomness and vertical
    /// bias), the floor and the roof at 1.
    fn reset(&mut self) {
        let n = self.n;
        let (ran, vert) = (self.s.randomness, self.s.vertical_bias);
        for k in 0..n {
            for i in 0..n {
                for j in 1..n.saturating_sub(1) {
                    let r = (ran as f64 * self.random.next()) as f32;
                    let v = (1.0f32 - (ran + vert)) + r + (vert * j as f32) / n as f32;
                    let a = self.at(i, j, k);
                    self.exposure[a] = v;
                }
                let (a, b) = (self.at(i, 0, k), self.at(i, n - 1, k));
                self.exposure[a] = 1.0;
                self.exposure[b] = 1.0;
            }
        }
    }

    fn clamp(v: f32, hi: usize) -> usize {
        // C's float-to-int conversion truncates; then the index is clamped.
        let i = if v.is_nan() { 0 } else { v as i64 };
        i.clamp(0, hi as i64) as usize
    }

    /// The voxel holding `p` (the nearest inside the cube).
    fn voxel(&self, p: [f32; 3]) -> [usize; 3] {
        let half = self.n as f32 / 2.0;
        let hi = self.n - 1;
        [
            Self::clamp(p[0] * self.scale + half, hi),
            Self::clamp(p[1] * self.scale, hi),
            Self::clamp(p[2] * self.scale + half, hi),
        ]
    }

    /// The shadow a query at `p` casts.
    fn shadow(&mut self, p: [f32; 3]) {
        let [x, y, z] = self.voxel(p);
        let (x, y, z) = (x as i64, y as i64, z as i64);
        let n = self.n as i64;
        let mut i = 0.0f32;
        while i < self.s.depth as f32 {
            let m = (i * self.s.spread) as i64 as f32;
            let mut j = -m;
            while j <= m {
                let mut k = -m;
                while k <= m {
                    let dist = (i * i + j * j + k * k).sqrt();
                    let (xb, yb, zb) = (x + j as i64, y - i as i64, z + k as i64);
                    if (0..n).contains(&xb) && (0..n).contains(&yb) && (0..n).contains(&zb) {
                        let s = (self.s.weight * self.s.dissipation.powf(-dist)).min(1.0);
                        let a = self.at(xb as usize, yb as usize, zb as usize);
                        self.exposure[a] = (self.exposure[a] as f64 * (1.0 - s as f64)) as f32;
                    }
                    k += 1.0;
                }
                j += 1.0;
            }
            i += 1.0;
        }
    }

    /// The light at `p`, interpolated between the 8 voxels around it.
    fn light(&self, p: [f32; 3]) -> f32 {
        let hi = self.n - 2;
        let half = (self.n as f32 - 1.0) / 2.0;
        let x = Self::clamp(p[0] * self.scale + half, hi);
        let y = Self::clamp(p[1] * self.scale, hi);
        let z = Self::clamp(p[2] * self.scale + half, hi);
        let frac = |v: f32| v - v.floor();
        let u = frac(p[0] * self.scale);
        let v = frac(p[1] * self.scale);
        let w = frac(p[2] * self.scale);
        let e = |dx: usize, dy: usize, dz: usize| self.exposure[self.at(x + dx, y + dy, z + dz)];
        let mut sum = 0.0f32;
        sum += (1.0 - u) * (1.0 - v) * (1.0 - w) * e(0, 0, 0);
        sum += u * (1.0 - v) * (1.0 - w) * e(1, 0, 0);
        sum += (1.0 - u) * v * (1.0 - w) * e(0, 1, 0);
        sum += u * v * (1.0 - w) * e(1, 1, 0);
        sum += (1.0 - u) * (1.0 - v) * w * e(0, 0, 1);
        sum += u * (1.0 - v) * w * e(1, 0, 1);
        sum += (1.0 - u) * v * w * e(0, 1, 1);
        sum += u * v * w * e(1, 1, 1);
        sum
    }

    /// The light's gradient at `p`: differences `sample radius` apart
    /// along each axis, inside the cube.
    fn gradient(&self, p: [f32; 3]) -> [f32; 3] {
        let span = self.s.grid_span;
        let r = self.s.sample_radius;
        let (lo, hi) = (span * -0.9999f32, span * 0.9999f32);
        let (ylo, yhi) = (0.0001f32, span * 1.9999f32);
        let p = [
            p[0].min(hi).max(lo),
            p[1].min(yhi).max(ylo),
            p[2].min(hi).max(lo),
        ];
        let (xa, xb) = ((p[0] - r).max(lo), (p[0] + r).min(hi));
        let (ya, yb) = ((p[1] - r).max(ylo), (p[1] + r).min(yhi));
        let (za, zb) = ((p[2] - r).max(lo), (p[2] + r).min(hi));
        let mut g = [0.0f32; 3];
        g[0] += self.light([xb, p[1], p[2]]);
        g[0] -= self.light([xa, p[1], p[2]]);
        g[1] += self.light([p[0], yb, p[2]]);
        g[1] -= self.light([p[0], ya, p[2]]);
        g[2] += self.light([p[0], p[1], zb]);
        g[2] -= self.light([p[0], p[1], za]);
        g
    }
}

/// A value as the program prints it (`%g`) and lpfg reads it back.
fn printed(v: f32) -> f64 {
    let text = cfmt::format("%g", &[Value::Float(v as f64)]).unwrap_or_default();
    text.parse::<f32>().map_or(f64::NAN, |v| v as f64)
}

/// Starts the built-in shadowpyramid for each run.
#[derive(Clone, Debug)]
pub struct Starter {
    pub settings: Settings,
    pub spec: CommSpec,
    /// The specification file read, for messages.
    pub file: PathBuf,
}

impl EnvironmentStarter for Starter {
    fn start(&self, _deadline: Option<Deadline>) -> Result<Box<dyn Environment>, String> {
        Ok(Box::new(ShadowPyramid {
            light: Light::new(self.settings.clone()),
            spec: self.spec.clone(),
        }))
    }

    fn following_module(&self) -> bool {
        self.spec.following
    }
}

/// The built-in shadowpyramid, running: its light field and random
/// numbers last from step to step, as the program's do.
#[derive(Debug)]
struct ShadowPyramid {
    light: Light,
    spec: CommSpec,
}

impl Environment for ShadowPyramid {
    fn exchange(&mut self, queries: &[Query]) -> Result<Vec<Answer>, String> {
        self.light.reset();
        let mut kept = Vec::new();
        for q in queries {
            let Some(p) = position_as_read(&self.spec, q.frame.position) else {
                continue;
            };
            if q.values.is_empty() {
                continue;
            }
            if as_received(q.values[0]) > 0.0 {
                self.light.shadow(p);
            }
            kept.push((q, p));
        }
        Ok(kept
            .into_iter()
            .map(|(q, p)| {
                let mut values = vec![0.0; q.values.len()];
                values[0] = printed(self.light.light(p));
                if q.values.len() >= 4 {
                    let g = self.light.gradient(p);
                    for k in 0..3 {
                        values[k + 1] = printed(g[k]);
                    }
                }
                Answer { id: q.id, values }
            })
            .collect())
    }
}
