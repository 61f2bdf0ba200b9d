//! Reverse subdivision of contours (paper 002, section 7): a scheme file's
//! group 1 runs through the rewriting engine to halve a contour, its group
//! 2 (the forward scheme) reconstructs and measures. Details between levels
//! make the representation lossless, in the spirit of Bartels and
//! Samavati's multiresolution curves.
//!
//! **Layer.** It uses `curve`, `deadline`, `draw`, `error`, `files`, `lang`,
//! `load`, `rewrite`; it is used by `command`. Nothing here names a layer
//! above (see ARCHITECTURE.md, "Layers").

pub mod details;
mod image;
pub mod input;
pub mod metric;
pub mod trace;

use glam::DVec2;
use serde::{Deserialize, Serialize};

use crate::curve::Curve;
use crate::error::Error;
use crate::lang::Value;
use crate::rewrite::Word;
use crate::{Derivation, DeriveOptions};

pub use details::{DetailsFile, Place};
pub use input::{Contour, InputError};

/// The scheme files built into the binary (also in `lsystems/reverse/`).
pub const CLOSED_SCHEME: &str = include_str!("../../lsystems/reverse/chaikin.lsys");
pub const OPEN_SCHEME: &str = include_str!("../../lsystems/reverse/chaikin-open.lsys");

/// A reverse scheme: group 1 reverses one level, group 2 subdivides one.
pub struct Scheme {
    pub loaded: Curve,
    /// "builtin:chaikin", "builtin:chaikin-open" or a file path.
    pub name: String,
    pub closed: bool,
    /// Every run of the scheme stops with an error once this passes.
    pub deadline: Option<crate::Deadline>,
}

impl Scheme {
    /// The built-in reverse Chaikin scheme, for closed or open contours.
    pub fn builtin(closed: bool) -> Scheme {
        let (name, text) = if closed {
            ("builtin:chaikin", CLOSED_SCHEME)
        } else {
            ("builtin:chaikin-open", OPEN_SCHEME)
        };
        // Reverse subdivision is precision work: its schemes compute in
        // double whatever their `V2f` says.
        let loaded = crate::load_str_with(name, text, &[], crate::Precision::Double)
            .expect("the built-in schemes are valid");
        Scheme {
            loaded,
            name: name.to_string(),
            closed,
            deadline: None,
        }
    }

    /// A scheme file: module `P(V2f)`, group 1 reverse, group 2 forward.
    /// Open schemes work between endmarkers `#`.
    pub fn from_file(path: &std::path::Path, closed: bool) -> Result<Scheme, Error> {
        let loaded = crate::load_file_with(path, &[], crate::Precision::Double)?;
        let p = loaded.program.alphabet.lookup("P");
        let ok = p.is_some_and(|s| {
            matches!(&loaded.program.alphabet.get(s).sig,
                crate::lang::modules::Signature::Fixed(t) if t.len() == 1 && t[0].dim() == 2 && t[0].is_vector())
        });
        if !ok {
            return Err(Error::Failed(format!(
                "the scheme {} must declare `module P(V2f);` for the contour's points",
                path.display()
            )));
        }
        Ok(Scheme {
            loaded,
            name: path.display().to_string(),
            closed,
            deadline: None,
        })
    }

    fn word(&self, pts: &[DVec2]) -> Word {
        let a = &self.loaded.program.alphabet;
        let p = a.lookup("P").expect("checked");
        let hash = a.builtin("#");
        let mut w = Word::new();
        if !self.closed {
            w.push(hash, &[]);
        }
        for q in pts {
            w.push(p, &[Value::V2(*q)]);
        }
        if !self.closed {
            w.push(hash, &[]);
        }
        w
    }

    fn points(&self, w: &Word) -> Vec<DVec2> {
        let p = self.loaded.program.alphabet.lookup("P").expect("checked");
        (0..w.len())
            .filter(|&i| w.sym(i) == p)
            .map(|i| {
                let d = w.data(i);
                DVec2::new(d[0], d[1])
            })
            .collect()
    }

    /// Runs `steps` steps of `group` from the given points.
    fn run(
        &self,
        pts: &[DVec2],
        group: i64,
        steps: u64,
        phase: usize,
    ) -> Result<Vec<DVec2>, Error> {
        let opts = DeriveOptions::default()
            .with_steps(steps)
            .with_phase(phase)
            .with_deadline(self.deadline);
        let l = &self.loaded;
        let fail = |e| l.error(e);
        let mut d = Derivation::new(&l.program, opts).map_err(fail)?;
        d.word = self.word(pts);
        d.ring = self.closed;
        while d.has_next() {
            d.env.next_group = group;
            d.next_step().map_err(fail)?;
        }
        Ok(self.points(&d.word))
    }

    /// One reverse step (group 1) with the partition starting at `phase`.
    /// A step that leaves no points is an error about the scheme.
    pub fn reverse_step(&self, pts: &[DVec2], phase: usize) -> Result<Vec<DVec2>, Error> {
        let out = self.run(pts, 1, 1, phase)?;
        self.produced(pts, &out, "group 1 (the reverse step)")?;
        Ok(out)
    }

    /// `steps` forward steps (group 2). Steps that leave no points are an
    /// error about the scheme.
    pub fn forward(&self, pts: &[DVec2], steps: usize) -> Result<Vec<DVec2>, Error> {
        if steps == 0 {
            return Ok(pts.to_vec());
        }
        let out = self.run(pts, 2, steps as u64, 0)?;
        self.produced(pts, &out, "group 2 (the forward scheme)")?;
        Ok(out)
    }

    /// Points out of points, all finite.
    fn produced(&self, from: &[DVec2], out: &[DVec2], group: &str) -> Result<(), Error> {
        if out.is_empty() && !from.is_empty() {
            return Err(Error::file(
                &self.name,
                format!(
                    "the scheme's {group} turned {} points into none: it must produce `P` modules",
                    from.len()
                ),
            ));
        }
        if let Some(p) = out.iter().find(|p| !p.is_finite()) {
            return Err(Error::file(
                &self.name,
                format!(
                    "the scheme's {group} produced the point ({}, {}), which is not finite",
                    p.x, p.y
                ),
            ));
        }
        Ok(())
    }

    /// The fewest points a level needs for one more reverse step.
    pub fn min_points(&self) -> usize {
        6
    }
}

/// Which partition of a level into pairs to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Try both at every step and keep the better reconstruction.
    Auto,
    Fixed(usize),
}

/// Settings of `reverse`.
#[derive(Clone, Debug)]
pub struct ReverseOptions {
    pub steps: usize,
    pub phase: Phase,
    /// Keep the detail vectors that make the representation lossless.
    pub details: bool,
}

/// What happened at one step.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StepReport {
    pub step: usize,
    /// Points before the step (after dropping one from an odd level).
    pub fine: usize,
    pub coarse: usize,
    pub phase: usize,
    /// An odd level lost its flattest point first.
    pub dropped: bool,
}

/// The detail of one level: what turns the forward subdivision of the
/// coarser level back into this level exactly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LevelDetails {
    /// The subdivided coarse level, rotated left by `shift`, lines up with
    /// this level (closed contours only; 0 for open ones).
    pub shift: usize,
    /// This level minus the aligned subdivision, one vector per point.
    pub details: Vec<[f64; 2]>,
    /// The point an odd level lost before the step: its index and position.
    pub dropped: Option<(usize, [f64; 2])>,
}

/// The details file: the levels from the coarsest to the input.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Details {
    pub format: String,
    pub version: u32,
    pub scheme: String,
    pub closed: bool,
    pub coarse_points: usize,
    pub levels: Vec<LevelDetails>,
}

pub const DETAILS_FORMAT: &str = "subgram-details";

/// The result of `reverse`.
#[derive(Clone, Debug)]
pub struct Reversal {
    pub coarse: Vec<DVec2>,
    pub steps: Vec<StepReport>,
    pub details: Option<Details>,
}

/// The index of the point nearest the chord of its neighbours: removing it
/// changes the contour least. End points of open contours are kept.
fn flattest(pts: &[DVec2], closed: bool) -> usize {
    let n = pts.len();
    let range = if closed { 0..n } else { 1..n - 1 };
    range
        .min_by(|&a, &b| {
            let dev = |i: usize| {
                let (l, r) = (pts[(i + n - 1) % n], pts[(i + 1) % n]);
                metric_point_segment(pts[i], l, r)
            };
            dev(a).total_cmp(&dev(b))
        })
        .unwrap_or(0)
}

fn metric_point_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    metric::point_segment(p, a, b)
}

/// What a distance measurement is for, to say in its messages.
#[derive(Clone, Copy)]
enum Measured {
    Phase,
    Report,
}

/// [`metric::distance`], with its budget's message.
fn measure(
    points: &[DVec2],
    line: &[DVec2],
    closed: bool,
    what: Measured,
) -> Result<metric::Error, Error> {
    metric::distance(points, line, closed).map_err(|e| {
        let (doing, instead) = match what {
            Measured::Phase => (
                "choosing the phase (--phase auto)",
                "--phase 0 or --phase 1 chooses without measuring",
            ),
            Measured::Report => (
                "measuring the reconstruction error (--report, --figure)",
                "without --report and --figure nothing is measured",
            ),
        };
        Error::Failed(format!(
            "{doing}: {e}; the reconstruction is far from most of the input (is it noise, or does the scheme draw something else?); {instead}"
        ))
    })
}

/// Reverses `input` by `opts.steps` levels.
pub fn reverse(scheme: &Scheme, input: &Contour, opts: &ReverseOptions) -> Result<Reversal, Error> {
    let mut level = input.points.clone();
    let mut steps = Vec::new();
    let mut levels = Vec::new();
    for step in 1..=opts.steps {
        let even = level.len() - level.len() % 2;
        if even < scheme.min_points() {
            return Err(Error::Failed(format!(
                "after {} step(s) the contour has {} points; step {step} needs at least {}: ask for fewer steps",
                step - 1,
                level.len(),
                scheme.min_points()
            )));
        }
        let mut dropped = None;
        if level.len() % 2 == 1 {
            let i = flattest(&level, scheme.closed);
            let p = level.remove(i);
            dropped = Some((i, [p.x, p.y]));
        }
        let candidates: Vec<usize> = match (opts.phase, scheme.closed) {
            (_, false) => vec![0],
            (Phase::Fixed(p), true) => vec![p % 2],
            (Phase::Auto, true) => vec![0, 1],
        };
        let mut best: Option<(f64, usize, Vec<DVec2>)> = None;
        for ph in candidates {
            let coarse = scheme.reverse_step(&level, ph)?;
            // A reverse step leaves fewer points, and enough for a shape:
            // so a run has at most log2(n) steps whatever the scheme.
            let least = if scheme.closed { 3 } else { 2 };
            if coarse.len() < least || coarse.len() >= level.len() {
                return Err(Error::file(
                    &scheme.name,
                    format!(
                        "at step {step}, the scheme's group 1 (the reverse step) turned {} points into {}: a reverse step must leave fewer points than it is given, and at least {least} for a coarse {}",
                        level.len(),
                        coarse.len(),
                        if scheme.closed { "polygon" } else { "polyline" }
                    ),
                ));
            }
            let score = if best.is_none() && opts.phase != Phase::Auto {
                0.0
            } else {
                // Reconstruct all the way to the input and compare.
                let rec = scheme.forward(&coarse, step)?;
                measure(&input.points, &rec, scheme.closed, Measured::Phase)?.rms
            };
            if best.as_ref().is_none_or(|(s, _, _)| score < *s) {
                best = Some((score, ph, coarse));
            }
        }
        let (_, ph, coarse) = best.expect("one candidate at least");
        if opts.details {
            let sub = scheme.forward(&coarse, 1)?;
            if sub.len() != level.len() {
                return Err(Error::Failed(format!(
                    "the scheme's forward group turns {} points into {}, not the {} of the finer level, so details cannot be kept",
                    coarse.len(),
                    sub.len(),
                    level.len()
                )));
            }
            let shift = if scheme.closed {
                (0..level.len())
                    .min_by(|&a, &b| {
                        sub[0]
                            .distance(level[a])
                            .total_cmp(&sub[0].distance(level[b]))
                    })
                    .unwrap_or(0)
            } else {
                0
            };
            let n = level.len();
            let mut details = Vec::with_capacity(n);
            for i in 0..n {
                let d = level[(i + shift) % n] - sub[i];
                if !d.is_finite() {
                    return Err(Error::Failed(format!(
                        "at step {step}, the detail of point {} overflows ({:?} minus {:?}): the contour's coordinates are too large to keep details",
                        (i + shift) % n,
                        level[(i + shift) % n].to_array(),
                        sub[i].to_array()
                    )));
                }
                details.push([d.x, d.y]);
            }
            levels.push(LevelDetails {
                shift,
                details,
                dropped,
            });
        }
        steps.push(StepReport {
            step,
            fine: level.len(),
            coarse: coarse.len(),
            phase: ph,
            dropped: dropped.is_some(),
        });
        level = coarse;
    }
    let details = opts.details.then(|| {
        levels.reverse();
        Details {
            format: DETAILS_FORMAT.to_string(),
            version: 1,
            scheme: scheme.name.clone(),
            closed: scheme.closed,
            coarse_points: level.len(),
            levels,
        }
    });
    Ok(Reversal {
        coarse: level,
        steps,
        details,
    })
}

/// Restores the contour from a coarse level and details, up to `upto`
/// levels (all when `None`).
pub fn reconstruct(
    scheme: &Scheme,
    coarse: &[DVec2],
    details: &Details,
    upto: Option<usize>,
) -> Result<Vec<DVec2>, Error> {
    restore(scheme, coarse, details, upto, |place, message| {
        Error::Failed(match place {
            Place::Details(k) | Place::Shift(k) | Place::Dropped(k) => {
                format!("level {}: {message}", k + 1)
            }
            Place::Detail(k, i) => format!("level {}, detail {i}: {message}", k + 1),
            _ => message,
        })
    })
}

/// [`reconstruct`] from a details file: errors about the details point at
/// their place in the file.
pub fn reconstruct_file(
    scheme: &Scheme,
    coarse: &[DVec2],
    file: &DetailsFile,
    upto: Option<usize>,
) -> Result<Vec<DVec2>, Error> {
    restore(scheme, coarse, &file.details, upto, |place, message| {
        file.error(place, message)
    })
}

fn restore(
    scheme: &Scheme,
    coarse: &[DVec2],
    details: &Details,
    upto: Option<usize>,
    at: impl Fn(Place, String) -> Error,
) -> Result<Vec<DVec2>, Error> {
    if details.format != DETAILS_FORMAT || details.version != 1 {
        return Err(at(
            Place::Format,
            format!(
                "not a subgram details file (format `{}` version {})",
                details.format, details.version
            ),
        ));
    }
    if coarse.len() != details.coarse_points {
        return Err(at(
            Place::CoarsePoints,
            format!(
                "the details belong to a coarse contour of {} points, but this one has {}",
                details.coarse_points,
                coarse.len()
            ),
        ));
    }
    let k = upto.unwrap_or(details.levels.len());
    if k > details.levels.len() {
        return Err(at(
            Place::Levels,
            format!(
                "level {k} was asked for, but the details have {} levels",
                details.levels.len()
            ),
        ));
    }
    let mut level = coarse.to_vec();
    for (li, l) in details.levels[..k].iter().enumerate() {
        let sub = scheme.forward(&level, 1)?;
        if sub.len() != l.details.len() {
            return Err(at(
                Place::Details(li),
                format!(
                    "the subdivision of the level below has {} points but these details have {}",
                    sub.len(),
                    l.details.len()
                ),
            ));
        }
        let n = sub.len();
        if l.shift >= n {
            return Err(at(
                Place::Shift(li),
                format!("the shift {} is not below the level's {n} points", l.shift),
            ));
        }
        let mut fine = vec![DVec2::ZERO; n];
        for i in 0..n {
            let p = sub[i] + DVec2::from(l.details[i]);
            if !p.is_finite() {
                return Err(at(
                    Place::Detail(li, i),
                    format!(
                        "this detail overflows: added to the subdivided point {:?} it gives {:?}, and a restored point must be finite",
                        sub[i].to_array(),
                        p.to_array()
                    ),
                ));
            }
            fine[(i + l.shift) % n] = p;
        }
        if let Some((i, p)) = l.dropped {
            if i > fine.len() {
                return Err(at(
                    Place::Dropped(li),
                    format!(
                        "the dropped point's index {i} is beyond the level's {} points",
                        fine.len()
                    ),
                ));
            }
            let p = DVec2::from(p);
            if !p.is_finite() {
                return Err(at(
                    Place::Dropped(li),
                    "the dropped point is not finite".into(),
                ));
            }
            fine.insert(i, p);
        }
        level = fine;
    }
    Ok(level)
}

/// Keeps `count` points of `pts` evenly spaced by index (naive decimation).
pub fn decimate(pts: &[DVec2], count: usize, closed: bool) -> Vec<DVec2> {
    let n = pts.len();
    if count >= n {
        return pts.to_vec();
    }
    if closed {
        (0..count).map(|k| pts[k * n / count]).collect()
    } else {
        (0..count)
            .map(|k| pts[(k * (n - 1) + (count - 1) / 2) / (count - 1).max(1)])
            .collect()
    }
}

/// Reconstruction errors of reverse subdivision and of naive decimation.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub input_points: usize,
    pub closed: bool,
    pub source: String,
    pub scheme: String,
    pub steps: Vec<StepReport>,
    pub coarse_points: usize,
    /// Forward scheme applied STEPS times to the coarse polygon, measured
    /// against the input polyline.
    pub reverse: metric::Error,
    /// The same for the input decimated to the same number of points.
    pub decimation: metric::Error,
}

/// Measures a reversal.
/// Errors too large to represent (coordinates near `f64::MAX`) are refused.
pub fn report(scheme: &Scheme, input: &Contour, r: &Reversal) -> Result<Report, Error> {
    let steps = r.steps.len();
    let rec = scheme.forward(&r.coarse, steps)?;
    let dec = decimate(&input.points, r.coarse.len(), scheme.closed);
    let dec_rec = scheme.forward(&dec, steps)?;
    let reverse = measure(&input.points, &rec, scheme.closed, Measured::Report)?;
    let decimation = measure(&input.points, &dec_rec, scheme.closed, Measured::Report)?;
    if !reverse.is_finite() || !decimation.is_finite() {
        return Err(Error::Failed(format!(
            "the reconstruction error cannot be measured: a distance is beyond the range of floating-point numbers (reverse subdivision: max {}, naive decimation: max {}); the contour's coordinates are too large",
            reverse.max, decimation.max
        )));
    }
    Ok(Report {
        input_points: input.points.len(),
        closed: scheme.closed,
        source: input.source.clone(),
        scheme: scheme.name.clone(),
        steps: r.steps.clone(),
        coarse_points: r.coarse.len(),
        reverse,
        decimation,
    })
}

/// The report as the binary prints it: point counts per step, then the
/// reconstruction errors of reverse subdivision and of naive decimation.
impl std::fmt::Display for Report {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let r = self;
        writeln!(
            f,
            "input: {} points, {} ({})\nscheme: {}",
            r.input_points,
            if r.closed { "closed" } else { "open" },
            r.source,
            r.scheme
        )?;
        for st in &r.steps {
            writeln!(
                f,
                "step {}: {} -> {} points, phase {}{}",
                st.step,
                st.fine,
                st.coarse,
                st.phase,
                if st.dropped {
                    " (odd: the flattest point was dropped first)"
                } else {
                    ""
                }
            )?;
        }
        // Six decimals, or six significant digits for huge figures.
        let num = |v: f64| {
            if v.abs() < 1e12 {
                format!("{v:.6}")
            } else {
                format!("{v:.6e}")
            }
        };
        let e = |m: &metric::Error| {
            format!(
                "max {}  mean {}  rms {}",
                num(m.max),
                num(m.mean),
                num(m.rms)
            )
        };
        writeln!(
            f,
            "reconstruction error, {} points subdivided {} times, against the input:\n  reverse subdivision  {}\n  naive decimation     {}",
            r.coarse_points,
            r.steps.len(),
            e(&r.reverse),
            e(&r.decimation)
        )?;
        if r.reverse.rms > 0.0 {
            write!(
                f,
                "  decimation's rms error is {:.2} times reverse subdivision's",
                r.decimation.rms / r.reverse.rms
            )?;
        }
        Ok(())
    }
}

/// Writes points as `x y` lines (`.txt`, `.xy`, anything else), `x,y` CSV
/// with a header (`.csv`), or an SVG polygon/polyline (`.svg`, y flipped
/// back to SVG's downward axis).
pub fn format_points(pts: &[DVec2], closed: bool, path: &std::path::Path) -> String {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "csv" => {
            let mut s = String::from("x,y\n");
            for p in pts {
                s.push_str(&format!("{:?},{:?}\n", p.x, p.y));
            }
            s
        }
        "svg" => {
            let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
            for p in pts {
                let q = DVec2::new(p.x, -p.y);
                lo = lo.min(q);
                hi = hi.max(q);
            }
            let size = hi - lo;
            let pad = size.max_element() * 0.02;
            let coords: Vec<String> = pts
                .iter()
                .map(|p| format!("{:?},{:?}", p.x, -p.y))
                .collect();
            format!(
                "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"{:?} {:?} {:?} {:?}\">\n<{} points=\"{}\" fill=\"none\" stroke=\"black\" vector-effect=\"non-scaling-stroke\"/>\n</svg>\n",
                lo.x - pad,
                lo.y - pad,
                size.x + 2.0 * pad,
                size.y + 2.0 * pad,
                if closed { "polygon" } else { "polyline" },
                coords.join(" ")
            )
        }
        _ => {
            let mut s = String::new();
            for p in pts {
                s.push_str(&format!("{:?} {:?}\n", p.x, p.y));
            }
            s
        }
    }
}

/// The picture of a reversal: the input thin and grey, the coarse polygon
/// with its points, the reconstruction in colour.
pub fn figure_events(
    input: &Contour,
    coarse: &[DVec2],
    reconstruction: &[DVec2],
) -> Vec<crate::draw::Event> {
    use crate::draw::{Event, Pen};
    let v3 = |p: DVec2| glam::DVec3::new(p.x, p.y, 0.0);
    let mut ev = Vec::new();
    let poly = |pts: &[DVec2], closed: bool, pen: Pen, ev: &mut Vec<Event>| {
        let mut points: Vec<glam::DVec3> = pts.iter().map(|p| v3(*p)).collect();
        if closed {
            points.extend(points.first().copied());
        }
        if points.len() >= 2 {
            ev.push(Event::Path { points, pen });
        }
    };
    poly(
        &input.points,
        input.closed,
        Pen {
            color: 9,
            width: 1.0,
        },
        &mut ev,
    );
    poly(
        coarse,
        input.closed,
        Pen {
            color: 0,
            width: 1.0,
        },
        &mut ev,
    );
    poly(
        reconstruction,
        input.closed,
        Pen {
            color: 2,
            width: 1.5,
        },
        &mut ev,
    );
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in &input.points {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let r = (hi - lo).max_element() * 0.004;
    for p in coarse {
        ev.push(Event::Disc {
            c: v3(*p),
            r,
            color: 3,
        });
    }
    ev
}
