//! The shape topology's schedule: paper 003's Algorithm 1 on a tree of
//! shapes, with `Subdivide` waiting for its smoothing group (Algorithm 4).
//!
//! A derivation alternates two phases until no shape is left to rewrite:
//! 1. every pending shape is rewritten (one applicable rule, chosen with
//!    its probability) until it is terminal, removed, expanded into
//!    children, or waiting at a `Subdivide`;
//! 2. the waiting shapes form their smoothing groups (a named group from
//!    the `smoothingGroup` attribute, with every terminal shape of that
//!    name; or the connected waiting shapes), each group is welded,
//!    subdivided with its protected boundary, and its slices go back to
//!    their shapes by the face tags; then each waiting shape's successor
//!    runs.
//!
//! Phase 1 only ends when every shape is terminal or waiting, which is
//! Algorithm 4's ready check for every group at once. The result does not
//! depend on which pending shape is taken first: a shape's random numbers
//! come from a generator seeded with the run's seed and the shape's place
//! in the tree (not from a shared stream), and everything that is written
//! out walks the tree in order.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use glam::{DAffine3, DMat3, DVec3};

use crate::deadline::Deadline;
use crate::lang::eval::{Env, Interp};
use crate::lang::random::{Rand48, Random};
use crate::lang::value::Value;
use crate::mesh::PolygonSoup;
use crate::syntax::span::Span;

use super::geom::{self, Geometry, Points, Scope, Selector};
use super::grammar::{Axis, CompKind, SizeKind};
use super::host::ShapeHost;
use super::smooth;
use super::{COp, CPart, ShapeGrammar, X};

/// The largest number of shapes a derivation may make (all of them, not
/// only the terminal ones), unless `SUBGRAM_MAX_SHAPES` says otherwise.
pub const MAX_SHAPES: usize = 1_000_000;
pub const MAX_SHAPES_VAR: &str = "SUBGRAM_MAX_SHAPES";

/// The most faces (with edges and points of lower-dimensional shapes) all
/// the shapes of a derivation may hold together, parents included: each
/// shape keeps its own copy of its geometry, so a rule that makes many
/// children of one large mesh would otherwise exhaust memory (about 70
/// bytes a face).
pub const MAX_FACES: usize = 10_000_000;

/// The most faces a smoothing group's subdivision may make (the surface
/// grammar's face limit for `Subdivide`): a few seconds and about 1 GB
/// with the shapes' copies.
pub const MAX_SMOOTH_FACES: usize = 2_000_000;

/// The most face cuts one split may make: a split cuts the shape at its
/// planes one after another, so its work is the shape's faces times its
/// planes.
pub const MAX_SPLIT_WORK: usize = 20_000_000;

/// The most rounds of smoothing (phase 2 of the schedule) a derivation may
/// run: a `Subdivide` whose successor subdivides again without end (`A -->
/// Subdivide(0) { A }`) would otherwise run until the shape limit, each
/// round walking the whole tree.
pub const MAX_ROUNDS: usize = 1000;

/// A shape's place in the derivation.
#[derive(Clone, Debug, PartialEq)]
pub enum State {
    /// Not rewritten yet.
    Pending,
    /// Rewritten into children.
    Expanded,
    /// Terminal: no rule applies, or its rule made no child.
    Leaf,
    /// Removed by `NIL`.
    Removed,
    /// At a `Subdivide`, waiting for its smoothing group.
    Waiting,
}

/// A shape of the tree.
#[derive(Clone, Debug)]
pub struct Node {
    pub symbol: u32,
    pub params: Vec<f64>,
    pub attrs: Vec<Value>,
    /// The `smoothingGroup` attribute.
    pub group: Option<Arc<str>>,
    pub colour: Option<[u8; 3]>,
    pub scope: Scope,
    /// Shared until a shape changes it: a child made by a symbol holds its
    /// parent's geometry without a copy.
    pub geom: Arc<Geometry>,
    /// `u32::MAX` for the axiom's shapes.
    pub parent: u32,
    pub children: Vec<u32>,
    /// The shape's place in the tree, hashed: it seeds its random numbers.
    pub key: u64,
    pub depth: u32,
    pub split: (i64, i64),
    pub comp: (i64, i64),
    pub state: State,
}

/// A waiting shape's `Subdivide`.
struct Wait<'g> {
    node: u32,
    steps: usize,
    scheme: &'g smooth_scheme::Scheme,
    body: &'g [COp],
    frame: Vec<Value>,
    span: Span,
}

pub(crate) mod smooth_scheme {
    /// A subdivision scheme a `Subdivide` names, checked at load.
    #[derive(Debug)]
    pub struct Scheme {
        pub name: String,
        pub grammar: crate::surface::Grammar,
    }
}

/// Why a derivation stopped: the place in the grammar and what happened.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeError {
    pub span: Span,
    pub message: String,
}

impl ShapeError {
    fn at(span: Span, message: impl Into<String>) -> ShapeError {
        ShapeError {
            span,
            message: message.into(),
        }
    }
}

type R<T> = Result<T, ShapeError>;

/// Settings of a derivation.
#[derive(Clone, Debug)]
pub struct ShapeOptions {
    pub seed: u32,
    pub max_shapes: usize,
    /// The most faces, edges and points all shapes hold ([`MAX_FACES`]).
    pub max_faces: usize,
    /// Take pending shapes last-in first-out (the default) or first-in
    /// first-out; the result is the same, which a test checks.
    pub fifo: bool,
    /// Keep each smoothing group's welded and subdivided meshes in its
    /// report (for cross-checks).
    pub keep_meshes: bool,
}

impl Default for ShapeOptions {
    fn default() -> Self {
        ShapeOptions {
            seed: 1,
            max_shapes: MAX_SHAPES,
            max_faces: MAX_FACES,
            fifo: false,
            keep_meshes: false,
        }
    }
}

/// A finished derivation: the tree and the points its shapes share.
#[derive(Debug)]
pub struct ShapeTree {
    pub nodes: Vec<Node>,
    pub roots: Vec<u32>,
    pub points: Points,
    /// The smoothing groups subdivided: (members, faces before, faces
    /// after, protected faces).
    pub groups: Vec<GroupReport>,
}

#[derive(Clone, Debug)]
pub struct GroupReport {
    pub members: usize,
    pub faces_in: usize,
    pub faces_out: usize,
    pub protected_faces: usize,
    pub protected_vertices: usize,
    pub scheme: String,
    pub steps: usize,
    /// The welded group and its subdivision, with `keep_meshes`.
    pub meshes: Option<Box<(PolygonSoup, PolygonSoup)>>,
}

impl ShapeTree {
    /// Every shape in tree order (parents before children, children in the
    /// order they were made).
    pub fn in_order(&self) -> Vec<u32> {
        tree_order(&self.nodes, &self.roots)
    }

    /// The terminal shapes with geometry, in tree order.
    pub fn leaves(&self) -> Vec<u32> {
        self.in_order()
            .into_iter()
            .filter(|&n| self.nodes[n as usize].state == State::Leaf)
            .collect()
    }
}

/// The state a successor's operations act on.
#[derive(Clone, Debug)]
struct Cur {
    scope: Scope,
    geom: Arc<Geometry>,
    group: Option<Arc<str>>,
    colour: Option<[u8; 3]>,
    split: (i64, i64),
    comp: (i64, i64),
}

impl Cur {
    /// The state a shape's successor starts from: the shape as it is.
    fn of(node: &Node) -> Cur {
        Cur {
            scope: node.scope,
            geom: node.geom.clone(),
            group: node.group.clone(),
            colour: node.colour,
            split: node.split,
            comp: node.comp,
        }
    }
}

/// The generators `ran()` and its kin read, seeded from a shape's key.
fn random_of(key: u64) -> Random {
    Random::new(Some((key ^ (key >> 32)) as u32))
}

struct Deriver<'g> {
    g: &'g ShapeGrammar,
    opts: ShapeOptions,
    deadline: &'g Deadline,
    nodes: Vec<Node>,
    roots: Vec<u32>,
    points: Points,
    pending: std::collections::VecDeque<u32>,
    waiting: Vec<Wait<'g>>,
    loose: HashSet<u32>,
    /// For each cut (wall) id, the planes of the later splits of shapes
    /// holding a face of that wall, in the order they ran: the weld refines
    /// the wall's faces on both sides by them, so the two sides match.
    seam_planes: HashMap<u32, Vec<(DVec3, f64)>>,
    next_cut: u32,
    interp: Interp<'static>,
    env: Env,
    groups: Vec<GroupReport>,
    ticks: u32,
    /// The faces, edges and points the shapes hold (see [`MAX_FACES`]).
    held: usize,
}

fn mix(a: u64, b: u64) -> u64 {
    // splitmix64 of a combination: a fixed, well-spread hash of a path.
    let mut z = a ^ b.wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(17);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Derives the grammar's shapes.
pub fn derive(g: &ShapeGrammar, opts: &ShapeOptions, deadline: &Deadline) -> R<ShapeTree> {
    let mut d = Deriver {
        g,
        opts: opts.clone(),
        deadline,
        nodes: Vec::new(),
        roots: Vec::new(),
        points: Points::default(),
        pending: Default::default(),
        waiting: Vec::new(),
        loose: HashSet::new(),
        seam_planes: HashMap::new(),
        next_cut: 1,
        interp: Interp::new(&[]),
        env: Env::new(Vec::new()),
        groups: Vec::new(),
        ticks: 0,
        held: 0,
    };
    // The axiom: its operations act on an empty shape at the origin.
    let mut frame = g.attr_init.clone();
    frame.resize(g.axiom_frame.max(frame.len()), Value::Void);
    let mut cur = Cur {
        scope: Scope::world(),
        geom: Arc::new(Geometry::empty(3)),
        group: None,
        colour: None,
        split: (0, 1),
        comp: (0, 1),
    };
    d.env.random = Random::new(Some(opts.seed));
    let made = d.exec(u32::MAX, &g.axiom, &mut cur, &mut frame, g.attr_base_axiom)?;
    let _ = made;
    let mut rounds = 0;
    loop {
        while let Some(n) = if d.opts.fifo {
            d.pending.pop_front()
        } else {
            d.pending.pop_back()
        } {
            d.rewrite(n)?;
        }
        if d.waiting.is_empty() {
            break;
        }
        rounds += 1;
        let span = d.waiting[0].span;
        if rounds > MAX_ROUNDS {
            return Err(ShapeError::at(
                span,
                format!(
                    "the derivation ran {MAX_ROUNDS} rounds of smoothing; does a \
                     `Subdivide`'s successor subdivide again without end?"
                ),
            ));
        }
        d.deadline.check().map_err(|m| ShapeError::at(span, m))?;
        d.smooth_all()?;
    }
    Ok(ShapeTree {
        nodes: d.nodes,
        roots: d.roots,
        points: d.points,
        groups: d.groups,
    })
}

impl<'g> Deriver<'g> {
    /// A shape's geometry of `old` elements becomes one of `new`: refused
    /// past the face limit.
    fn hold(&mut self, old: usize, new: usize, span: Span) -> R<()> {
        self.held = self.held.saturating_sub(old).saturating_add(new);
        if self.held > self.opts.max_faces {
            return Err(ShapeError::at(
                span,
                format!(
                    "the shapes hold {} faces, edges and points, past the limit of {}: each \
                     shape keeps its own copy of its geometry, so many children of a large \
                     mesh, or too many shapes, hold too much",
                    self.held, self.opts.max_faces
                ),
            ));
        }
        Ok(())
    }

    fn tick(&mut self, span: Span) -> R<()> {
        self.ticks = self.ticks.wrapping_add(1);
        if self.ticks.is_multiple_of(1024) {
            self.deadline.check().map_err(|m| ShapeError::at(span, m))?;
        }
        Ok(())
    }

    fn eval(&mut self, e: &X, frame: &mut [Value], cur: &Cur, depth: u32) -> R<Value> {
        let mut host = ShapeHost::of(&cur.scope);
        host.split = cur.split;
        host.comp = cur.comp;
        host.depth = depth as i64;
        host.faces = cur.geom.face_count() as i64;
        self.interp
            .eval(&e.ex, frame, &mut self.env, &mut host)
            .map_err(|err| ShapeError::at(err.span.unwrap_or(e.span), err.message))
    }

    fn num(&mut self, e: &X, frame: &mut [Value], cur: &Cur, depth: u32) -> R<f64> {
        let v = self.eval(e, frame, cur, depth)?.as_f64();
        if !v.is_finite() {
            return Err(ShapeError::at(
                e.span,
                format!("this is {v}, not a finite number"),
            ));
        }
        Ok(v)
    }

    fn new_node(
        &mut self,
        parent: u32,
        symbol: u32,
        params: Vec<f64>,
        attrs: Vec<Value>,
        cur: &Cur,
        span: Span,
    ) -> R<u32> {
        if self.nodes.len() >= self.opts.max_shapes {
            return Err(ShapeError::at(
                span,
                format!(
                    "the derivation made {} shapes, the limit: does a rule never reach a \
                     terminal shape? (raise it with --max-shapes or {MAX_SHAPES_VAR})",
                    self.opts.max_shapes
                ),
            ));
        }
        let id = self.nodes.len() as u32;
        let (pkey, depth, index) = if parent == u32::MAX {
            (self.opts.seed as u64, 0, self.roots.len())
        } else {
            let p = &self.nodes[parent as usize];
            (p.key, p.depth + 1, p.children.len())
        };
        let key = mix(pkey, index as u64 + 1);
        self.hold(0, cur.geom.elements(), span)?;
        self.nodes.push(Node {
            symbol,
            params,
            attrs,
            group: cur.group.clone(),
            colour: cur.colour,
            scope: cur.scope,
            geom: cur.geom.clone(),
            parent,
            children: Vec::new(),
            key,
            depth,
            split: cur.split,
            comp: cur.comp,
            state: State::Pending,
        });
        if parent == u32::MAX {
            self.roots.push(id);
        } else {
            self.nodes[parent as usize].children.push(id);
        }
        self.pending.push_back(id);
        Ok(id)
    }

    /// Algorithm 1, steps 2 and 3, for one shape.
    fn rewrite(&mut self, n: u32) -> R<()> {
        let g = self.g;
        let sym = self.nodes[n as usize].symbol as usize;
        let rules = &g.by_symbol[sym];
        if rules.is_empty() {
            self.nodes[n as usize].state = State::Leaf;
            return Ok(());
        }
        self.tick(g.rules[rules[0]].span)?;
        let node = &self.nodes[n as usize];
        // The shape's own random numbers.
        let key = node.key;
        self.env.random = random_of(key);
        let mut choose = Rand48::from_state(key & 0xFFFF_FFFF_FFFF);
        let cur = Cur::of(node);
        let depth = node.depth;
        let params: Vec<Value> = node.params.iter().map(|&x| Value::Float(x)).collect();
        let attrs = node.attrs.clone();
        // The applicable rules, in file order, with their probabilities.
        let mut applicable: Vec<(usize, Vec<Value>, Option<f64>)> = Vec::new();
        for &ri in rules {
            let r = &g.rules[ri];
            if r.params != params.len() {
                continue;
            }
            let mut frame = params.clone();
            frame.extend(attrs.iter().cloned());
            frame.resize(r.frame.max(frame.len()), Value::Void);
            if let Some(c) = &r.cond {
                if !self.eval(c, &mut frame, &cur, depth)?.truthy() {
                    continue;
                }
            }
            let p = match &r.prob {
                Some(e) => {
                    let p = self.num(e, &mut frame, &cur, depth)?;
                    if !(0.0..=1.0).contains(&p) {
                        return Err(ShapeError::at(
                            e.span,
                            format!("a rule's probability is between 0 and 1; this is {p}"),
                        ));
                    }
                    Some(p)
                }
                None => None,
            };
            applicable.push((ri, frame, p));
        }
        if applicable.is_empty() {
            self.nodes[n as usize].state = State::Leaf;
            return Ok(());
        }
        let chosen = if applicable.iter().all(|a| a.2.is_none()) {
            0
        } else {
            let sum: f64 = applicable.iter().map(|a| a.2.unwrap_or(0.0)).sum();
            if let Some(a) = applicable.iter().find(|a| a.2.is_none()) {
                let r = &g.rules[a.0];
                return Err(ShapeError::at(
                    r.span,
                    format!(
                        "this rule for `{}` has no probability, but another rule that applies \
                         has one: give every applicable rule a probability",
                        g.symbols[sym]
                    ),
                ));
            }
            if (sum - 1.0).abs() > 1e-9 {
                let r = &g.rules[applicable[0].0];
                return Err(ShapeError::at(
                    r.span,
                    format!(
                        "the probabilities of the {} rules that apply to `{}` sum to {sum}, not 1",
                        applicable.len(),
                        g.symbols[sym]
                    ),
                ));
            }
            let x = choose.next_f64();
            let mut acc = 0.0;
            let mut k = applicable.len() - 1;
            for (i, a) in applicable.iter().enumerate() {
                acc += a.2.unwrap_or(0.0);
                if x < acc {
                    k = i;
                    break;
                }
            }
            k
        };
        let (ri, mut frame, _) = applicable.swap_remove(chosen);
        let r = &g.rules[ri];
        let mut cur = cur;
        let base = params.len();
        self.nodes[n as usize].state = State::Expanded;
        let made = self.exec(n, &r.body, &mut cur, &mut frame, base)?;
        self.finish(n, made, cur, r.span)
    }

    /// After a successor: a shape that made no child and was neither
    /// removed nor left waiting is terminal, with the state the operations
    /// left it in.
    fn finish(&mut self, n: u32, made: Made, cur: Cur, span: Span) -> R<()> {
        if made == Made::Nothing {
            let old = self.nodes[n as usize].geom.elements();
            self.hold(old, cur.geom.elements(), span)?;
        }
        let node = &mut self.nodes[n as usize];
        match made {
            Made::Children => node.state = State::Expanded,
            Made::Removed => node.state = State::Removed,
            Made::Waiting => node.state = State::Waiting,
            Made::Nothing => {
                node.state = State::Leaf;
                node.scope = cur.scope;
                node.geom = cur.geom;
                node.group = cur.group;
                node.colour = cur.colour;
            }
        }
        Ok(())
    }

    /// Runs a successor's operations on `cur` for shape `n` (the axiom's
    /// for `u32::MAX`). `attr_base` is where the attributes start in
    /// `frame`.
    fn exec(
        &mut self,
        n: u32,
        ops: &'g [COp],
        cur: &mut Cur,
        frame: &mut [Value],
        attr_base: usize,
    ) -> R<Made> {
        let depth = if n == u32::MAX {
            0
        } else {
            self.nodes[n as usize].depth
        };
        let mut made = Made::Nothing;
        let mut stack: Vec<(Cur, Vec<Value>)> = Vec::new();
        let nattrs = self.g.attr_names.len();
        for op in ops {
            match op {
                COp::Symbol { symbol, args, span } => {
                    let mut params = Vec::with_capacity(args.len());
                    for a in args {
                        params.push(self.num(a, frame, cur, depth)?);
                    }
                    let attrs = frame[attr_base..attr_base + nattrs].to_vec();
                    self.new_node(n, *symbol, params, attrs, cur, *span)?;
                    made = made.or(Made::Children);
                }
                COp::Nil => return Ok(made.or(Made::Removed)),
                COp::Push => {
                    stack.push((cur.clone(), frame[attr_base..attr_base + nattrs].to_vec()))
                }
                COp::Pop(span) => {
                    let Some((c, a)) = stack.pop() else {
                        return Err(ShapeError::at(
                            *span,
                            "`]` without a `[` before it in this successor",
                        ));
                    };
                    *cur = c;
                    frame[attr_base..attr_base + nattrs].clone_from_slice(&a);
                }
                COp::Translate(v, rel, span) => {
                    let t = relative(self.vec3(v, frame, cur, depth)?, rel, cur.scope.size);
                    let d =
                        cur.scope.axes[0] * t.x + cur.scope.axes[1] * t.y + cur.scope.axes[2] * t.z;
                    if d != DVec3::ZERO {
                        cur.scope.origin += d;
                        far(cur.scope.origin, "the scope's origin", *span)?;
                        cur.geom = Arc::new(self.moved(
                            &cur.geom,
                            &DAffine3::from_translation(d),
                            *span,
                        )?);
                    }
                }
                COp::Rotate(v, span) => {
                    let a = self.vec3(v, frame, cur, depth)?;
                    if a != DVec3::ZERO {
                        let axes = cur.scope.axes;
                        let rot = DMat3::from_axis_angle(axes[0], a.x.to_radians())
                            * DMat3::from_axis_angle(axes[1], a.y.to_radians())
                            * DMat3::from_axis_angle(axes[2], a.z.to_radians());
                        let o = cur.scope.origin;
                        let f = DAffine3::from_translation(o)
                            * DAffine3::from_mat3(rot)
                            * DAffine3::from_translation(-o);
                        cur.scope.axes = [rot * axes[0], rot * axes[1], rot * axes[2]];
                        cur.geom = Arc::new(self.moved(&cur.geom, &f, *span)?);
                    }
                }
                COp::Scale(v, rel, span) => {
                    let s = relative(self.vec3(v, frame, cur, depth)?, rel, cur.scope.size);
                    if s.min_element() < 0.0 {
                        return Err(ShapeError::at(
                            *span,
                            format!("a scope's size is not negative; this asks for {s}"),
                        ));
                    }
                    far(s, "the scope's size", *span)?;
                    let old = cur.scope.size;
                    let ratio = |i: usize| if old[i] > 0.0 { s[i] / old[i] } else { 1.0 };
                    let (rx, ry, rz) = (ratio(0), ratio(1), ratio(2));
                    cur.scope.size = s;
                    if (rx, ry, rz) != (1.0, 1.0, 1.0) && !cur.geom.is_empty() {
                        let ax = cur.scope.axes;
                        let m = DMat3::from_cols(ax[0], ax[1], ax[2]);
                        let o = cur.scope.origin;
                        let f = DAffine3::from_translation(o)
                            * DAffine3::from_mat3(
                                m * DMat3::from_diagonal(DVec3::new(rx, ry, rz)) * m.transpose(),
                            )
                            * DAffine3::from_translation(-o);
                        cur.geom = Arc::new(self.moved(&cur.geom, &f, *span)?);
                    }
                }
                COp::Extrude(h, span) => {
                    let h = self.num(h, frame, cur, depth)?;
                    if h.abs() > geom::MAX_COORD {
                        return Err(ShapeError::at(
                            *span,
                            format!(
                                "this extrudes by {}, beyond the {:e} that shapes stay within",
                                geom::show(h),
                                geom::MAX_COORD
                            ),
                        ));
                    }
                    if cur.geom.dim != 2 {
                        return Err(ShapeError::at(
                            *span,
                            format!(
                                "`extrude` takes a 2D shape (a face or a lot); this one is {}D",
                                cur.geom.dim
                            ),
                        ));
                    }
                    let normal = normal_of(&self.points, &cur.geom);
                    // The scope axis closest to the face's normal grows.
                    let k = (0..3)
                        .max_by(|&a, &b| {
                            cur.scope.axes[a]
                                .dot(normal)
                                .abs()
                                .total_cmp(&cur.scope.axes[b].dot(normal).abs())
                        })
                        .unwrap_or(1);
                    let dir = if cur.scope.axes[k].dot(normal) < 0.0 {
                        -cur.scope.axes[k]
                    } else {
                        cur.scope.axes[k]
                    };
                    cur.geom = Arc::new(
                        geom::extrude(&mut self.points, &cur.geom, dir, h)
                            .map_err(|m| ShapeError::at(*span, m))?,
                    );
                    cur.scope = geom::bounding_scope(&self.points, &cur.geom, cur.scope.axes);
                }
                COp::Insert(kind, span) => {
                    let s = cur.scope;
                    let g = match kind {
                        super::Insert::Box => geom::box_in(&mut self.points, &s),
                        super::Insert::Cylinder(k) => {
                            let k = self.num(k, frame, cur, depth)?;
                            if !(3.0..=1024.0).contains(&k) {
                                return Err(ShapeError::at(*span, format!("a cylinder has 3 to 1024 sides; this asks for {k}")));
                            }
                            geom::cylinder_in(&mut self.points, &s, k as usize)
                        }
                        super::Insert::Sphere(a, b) => {
                            let a = self.num(a, frame, cur, depth)?;
                            let b = self.num(b, frame, cur, depth)?;
                            if !(3.0..=1024.0).contains(&a) || !(2.0..=1024.0).contains(&b) {
                                return Err(ShapeError::at(*span, format!(
                                    "a sphere has 3 to 1024 slices and 2 to 1024 stacks; this asks for {a} and {b}"
                                )));
                            }
                            geom::sphere_in(&mut self.points, &s, a as usize, b as usize)
                        }
                        super::Insert::Mesh(soup) => geom::mesh_in(&mut self.points, &s, soup),
                    }
                    .map_err(|m| ShapeError::at(*span, m))?;
                    cur.geom = Arc::new(g);
                }
                COp::Colour(c) => cur.colour = Some(*c),
                COp::ColourRgb(v) => {
                    let c = self.vec3(v, frame, cur, depth)?;
                    let b = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
                    cur.colour = Some([b(c.x), b(c.y), b(c.z)]);
                }
                COp::Set(slot, e, ty) => {
                    let v = self.eval(e, frame, cur, depth)?.convert(*ty);
                    frame[attr_base + *slot as usize] = v;
                }
                COp::SetGroup(name) => cur.group = name.clone(),
                COp::Lot(w, dd, span) => {
                    let w = self.num(w, frame, cur, depth)?;
                    let dz = self.num(dd, frame, cur, depth)?;
                    if w <= 0.0 || dz <= 0.0 {
                        return Err(ShapeError::at(
                            *span,
                            format!("a lot's sides are positive; this asks for {w} by {dz}"),
                        ));
                    }
                    let o = cur.scope.origin;
                    let (x, z) = (DVec3::X, DVec3::Z);
                    let corners = [o + z * dz, o + x * w + z * dz, o + x * w, o];
                    self.lot(cur, &corners, *span)?;
                }
                COp::Polygon(coords, span) => {
                    let mut c = Vec::with_capacity(coords.len() / 2);
                    for pair in coords.chunks(2) {
                        let x = self.num(&pair[0], frame, cur, depth)?;
                        let z = self.num(&pair[1], frame, cur, depth)?;
                        c.push(cur.scope.origin + DVec3::new(x, 0.0, z));
                    }
                    self.lot(cur, &c, *span)?;
                }
                COp::Split {
                    axis,
                    parts,
                    repeat,
                    parallel,
                    span,
                } => {
                    self.split(
                        n,
                        cur,
                        frame,
                        attr_base,
                        *axis,
                        parts,
                        *repeat,
                        parallel.as_deref(),
                        *span,
                    )?;
                    made = made.or(Made::Children);
                }
                COp::Comp { kind, parts, span } => {
                    self.comp(n, cur, frame, attr_base, *kind, parts, *span)?;
                    made = made.or(Made::Children);
                }
                COp::Subdivide {
                    steps,
                    scheme,
                    body,
                    span,
                } => {
                    if n == u32::MAX {
                        return Err(ShapeError::at(
                            *span,
                            "the axiom cannot subdivide; give its shape a symbol and a rule",
                        ));
                    }
                    let k = self.num(steps, frame, cur, depth)?;
                    if !(0.0..=16.0).contains(&k) || k.fract() != 0.0 {
                        return Err(ShapeError::at(
                            *span,
                            format!("`Subdivide` takes 0 to 16 steps; this asks for {k}"),
                        ));
                    }
                    if cur.geom.dim < 2 || cur.geom.is_empty() {
                        return Err(ShapeError::at(
                            *span,
                            "`Subdivide` smooths faces; this shape has none",
                        ));
                    }
                    let old = self.nodes[n as usize].geom.elements();
                    self.hold(old, cur.geom.elements(), *span)?;
                    let node = &mut self.nodes[n as usize];
                    node.scope = cur.scope;
                    node.geom = cur.geom.clone();
                    node.group = cur.group.clone();
                    node.colour = cur.colour;
                    node.attrs = frame[attr_base..attr_base + nattrs].to_vec();
                    self.waiting.push(Wait {
                        node: n,
                        steps: k as usize,
                        scheme: &self.g.schemes[*scheme],
                        body,
                        frame: frame.to_vec(),
                        span: *span,
                    });
                    return Ok(Made::Waiting);
                }
            }
        }
        if n == u32::MAX && made == Made::Nothing {
            // An axiom without a symbol.
            return Ok(made);
        }
        Ok(made)
    }

    fn vec3(&mut self, v: &[X; 3], frame: &mut [Value], cur: &Cur, depth: u32) -> R<DVec3> {
        Ok(DVec3::new(
            self.num(&v[0], frame, cur, depth)?,
            self.num(&v[1], frame, cur, depth)?,
            self.num(&v[2], frame, cur, depth)?,
        ))
    }

    fn moved(&mut self, g: &Geometry, f: &DAffine3, span: Span) -> R<Geometry> {
        geom::transform(&mut self.points, g, f).map_err(|m| ShapeError::at(span, m))
    }

    /// The current shape becomes a polygon in the ground plane: scope x
    /// along its first edge, y up.
    fn lot(&mut self, cur: &mut Cur, corners: &[DVec3], span: Span) -> R<()> {
        let g = geom::polygon(&mut self.points, corners).map_err(|m| ShapeError::at(span, m))?;
        let n = normal_of(&self.points, &g);
        if n == DVec3::ZERO {
            return Err(ShapeError::at(
                span,
                "a lot's corners enclose no area (they lie on a line, or the outline \
                 crosses itself)",
            ));
        }
        if n.y <= 0.0 {
            return Err(ShapeError::at(
                span,
                "a lot's corners go counter-clockwise seen from above (+y)",
            ));
        }
        let x = (corners[1] - corners[0]).normalize_or_zero();
        let x = if x == DVec3::ZERO { DVec3::X } else { x };
        let y = DVec3::Y;
        let z = x.cross(y);
        cur.geom = Arc::new(g);
        cur.scope = geom::bounding_scope(&self.points, &cur.geom, [x, y, z]);
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    fn split(
        &mut self,
        n: u32,
        cur: &Cur,
        frame: &mut [Value],
        attr_base: usize,
        axis: Axis,
        parts: &'g [CPart],
        repeat: bool,
        parallel: Option<&'g [X]>,
        span: Span,
    ) -> R<()> {
        let depth = if n == u32::MAX {
            0
        } else {
            self.nodes[n as usize].depth
        };
        let a = axis.index();
        let total = cur.scope.size[a];
        let mut sizes = Vec::with_capacity(parts.len());
        for p in parts {
            let s = self.num(&p.size, frame, cur, depth)?;
            if s < 0.0 {
                return Err(ShapeError::at(
                    p.span,
                    format!("a part's size is not negative; this is {s}"),
                ));
            }
            sizes.push((p.kind, s));
        }
        let layout = lay_out(&sizes, total, repeat).map_err(|m| ShapeError::at(span, m))?;
        if layout.len() > self.opts.max_shapes {
            return Err(ShapeError::at(
                span,
                format!(
                "this split makes {} parts, more than the limit of {} shapes ({MAX_SHAPES_VAR})",
                layout.len(), self.opts.max_shapes
            ),
            ));
        }
        let work = cuts_of(&layout, total).saturating_mul(cur.geom.elements());
        if work > MAX_SPLIT_WORK {
            return Err(ShapeError::at(
                span,
                format!(
                    "this split cuts a shape of {} faces at {} planes, one after another: {work} \
                     face cuts, more than the limit of {MAX_SPLIT_WORK}; split a coarser shape, \
                     or into fewer parts",
                    cur.geom.elements(),
                    cuts_of(&layout, total)
                ),
            ));
        }
        let mut flags = Vec::new();
        if let Some(fl) = parallel {
            for f in fl {
                flags.push(self.eval(f, frame, cur, depth)?.truthy());
            }
        }
        // The cut planes: every part's end strictly inside the scope, once.
        // A part of no length gets no geometry; a remainder after the last
        // part is cut off.
        let axis_dir = cur.scope.axes[a];
        let tol = 1e-9 * total.abs().max(1.0);
        let mut cuts: Vec<f64> = Vec::with_capacity(layout.len());
        let mut at = 0.0;
        let mut spans = Vec::with_capacity(layout.len());
        for (_, len) in &layout {
            let (start, end) = (at, at + len);
            spans.push((start, end));
            at = end;
            if end > tol && end < total - tol && cuts.last().is_none_or(|&c| end > c + tol) {
                cuts.push(end);
            }
        }
        let first = self.next_cut;
        self.next_cut += cuts.len() as u32;
        if !cuts.is_empty() {
            let planes: Vec<(DVec3, f64)> = cuts
                .iter()
                .map(|&c| geom::plane_of(cur.scope.origin, axis_dir, c))
                .collect();
            for k in geom::seams_of(&cur.geom) {
                self.seam_planes
                    .entry(k)
                    .or_default()
                    .extend_from_slice(&planes);
            }
        }
        let pieces = geom::split(
            &mut self.points,
            &cur.geom,
            cur.scope.origin,
            axis_dir,
            &cuts,
            first,
        )
        .map_err(|m| ShapeError::at(span, m))?;
        // Piece k lies between cut k - 1 and cut k.
        let piece_of = |start: f64, end: f64| -> Option<usize> {
            if end - start <= tol {
                return None;
            }
            let mid = 0.5 * (start + end);
            Some(cuts.iter().take_while(|&&c| c < mid).count())
        };
        let mut taken: Vec<Option<Geometry>> = pieces.into_iter().map(Some).collect();
        let dim = cur.geom.dim;
        if parallel.is_some() {
            // Soft connectivity: flag i joins parts i and i + 1 (in a
            // repeat, the flags repeat with the pattern). A cut between
            // parts that are not soft-connected is loose.
            for i in 0..layout.len().saturating_sub(1) {
                let soft = if flags.is_empty() {
                    false
                } else {
                    flags[i % flags.len()]
                };
                let end = spans[i].1;
                if let Some(k) = cuts.iter().position(|&c| (c - end).abs() <= tol) {
                    if !soft {
                        self.loose.insert(first + k as u32);
                    }
                }
            }
        }
        let count = layout.len() as i64;
        let mut offset = 0.0;
        for (i, (pi, len)) in layout.iter().enumerate() {
            let (start, end) = spans[i];
            let g = match piece_of(start, end) {
                Some(k) => taken
                    .get_mut(k)
                    .and_then(Option::take)
                    .unwrap_or_else(|| Geometry::empty(dim)),
                None => Geometry::empty(dim),
            };
            let mut scope = cur.scope;
            scope.origin += axis_dir * offset;
            scope.size[a] = *len;
            offset += len;
            let mut c = Cur {
                scope,
                geom: Arc::new(g),
                group: cur.group.clone(),
                colour: cur.colour,
                split: (i as i64, count),
                comp: cur.comp,
            };
            let mut f = frame.to_vec();
            let made = self.exec(n, &parts[*pi].body, &mut c, &mut f, attr_base)?;
            let _ = made;
        }
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    fn comp(
        &mut self,
        n: u32,
        cur: &Cur,
        frame: &mut [Value],
        attr_base: usize,
        kind: CompKind,
        parts: &'g [(Selector, Span, Vec<COp>)],
        span: Span,
    ) -> R<()> {
        let comps: Vec<(Geometry, Scope)> = match kind {
            CompKind::Faces => {
                if cur.geom.dim < 2 {
                    return Err(ShapeError::at(
                        span,
                        format!(
                            "`comp(f)` takes a shape with faces; this one is {}D",
                            cur.geom.dim
                        ),
                    ));
                }
                geom::comp_faces(&self.points, &cur.geom, &cur.scope, Selector::All)
            }
            CompKind::Edges => {
                if cur.geom.dim < 1 {
                    return Err(ShapeError::at(
                        span,
                        "`comp(e)` takes a shape with edges; this one is a point",
                    ));
                }
                geom::comp_edges(&self.points, &cur.geom, &cur.scope)
            }
            CompKind::Vertices => geom::comp_vertices(&self.points, &cur.geom, &cur.scope),
        };
        // Each component's class: a face's by its normal in the scope.
        let classes: Vec<Selector> = comps
            .iter()
            .map(|(_, s)| {
                if kind == CompKind::Faces {
                    let z = s.axes[2];
                    let local = DVec3::new(
                        z.dot(cur.scope.axes[0]),
                        z.dot(cur.scope.axes[1]),
                        z.dot(cur.scope.axes[2]),
                    );
                    Selector::classify(local)
                } else {
                    Selector::All
                }
            })
            .collect();
        // Each component goes to the first part whose selector takes it.
        let mut to: Vec<Vec<usize>> = vec![Vec::new(); parts.len()];
        for (k, &class) in classes.iter().enumerate() {
            if let Some(p) = parts.iter().position(|(sel, _, _)| sel.takes(class)) {
                to[p].push(k);
            }
        }
        // A selector that takes nothing because an earlier part took its
        // components is fine; one the shape has no component for is an
        // error.
        for (p, (sel, at, _)) in parts.iter().enumerate() {
            if to[p].is_empty() && !classes.iter().any(|&c| sel.takes(c)) {
                let what = match kind {
                    CompKind::Faces => "face",
                    CompKind::Edges => "edge",
                    CompKind::Vertices => "vertex",
                };
                let sym = if n == u32::MAX {
                    "the axiom".to_string()
                } else {
                    format!(
                        "`{}`",
                        self.g.symbols[self.nodes[n as usize].symbol as usize]
                    )
                };
                return Err(ShapeError::at(
                    *at,
                    format!(
                        "shape {sym} has no {} {what} left for this selector ({} {what}s in all)",
                        selector_name(*sel),
                        comps.len()
                    ),
                ));
            }
        }
        let mut comps: Vec<Option<(Geometry, Scope)>> = comps.into_iter().map(Some).collect();
        for (p, ks) in to.iter().enumerate() {
            let total = ks.len() as i64;
            for (i, &k) in ks.iter().enumerate() {
                let Some((g, s)) = comps[k].take() else {
                    continue;
                };
                let mut c = Cur {
                    scope: s,
                    geom: Arc::new(g),
                    group: cur.group.clone(),
                    colour: cur.colour,
                    split: cur.split,
                    comp: (i as i64, total),
                };
                let mut f = frame.to_vec();
                self.exec(n, &parts[p].2, &mut c, &mut f, attr_base)?;
            }
        }
        Ok(())
    }

    /// Phase 2: every smoothing group of the waiting shapes, subdivided.
    fn smooth_all(&mut self) -> R<()> {
        let waiting = std::mem::take(&mut self.waiting);
        // Tree order, so that the welded meshes do not depend on the order
        // the shapes were rewritten in.
        let order: HashMap<u32, usize> = {
            let tree = TreeOrder {
                nodes: &self.nodes,
                roots: &self.roots,
            };
            tree.rank()
        };
        let mut waiting = waiting;
        waiting.sort_by_key(|w| order[&w.node]);
        let wait_of: HashMap<u32, usize> = waiting
            .iter()
            .enumerate()
            .map(|(i, w)| (w.node, i))
            .collect();
        // Groups: named ones (with every terminal shape of the name), then
        // connected components of the unnamed waiting shapes.
        let mut groups: Vec<Vec<u32>> = Vec::new();
        let mut named: HashMap<Arc<str>, usize> = HashMap::new();
        let mut unnamed = Vec::new();
        for w in &waiting {
            match &self.nodes[w.node as usize].group {
                Some(name) => {
                    let gi = *named.entry(name.clone()).or_insert_with(|| {
                        groups.push(Vec::new());
                        groups.len() - 1
                    });
                    groups[gi].push(w.node);
                }
                None => unnamed.push(w.node),
            }
        }
        if !named.is_empty() {
            let leaves: Vec<u32> = {
                let tree = TreeOrder {
                    nodes: &self.nodes,
                    roots: &self.roots,
                };
                tree.all()
            };
            for l in leaves {
                let node = &self.nodes[l as usize];
                if node.state == State::Leaf {
                    if let Some(gi) = node.group.as_ref().and_then(|g| named.get(g)) {
                        groups[*gi].push(l);
                    }
                }
            }
            for g in &mut groups {
                g.sort_by_key(|x| order[x]);
            }
        }
        groups.extend(connected(&self.nodes, &unnamed));
        // Everything with geometry that a group may border.
        let live: Vec<u32> = {
            let tree = TreeOrder {
                nodes: &self.nodes,
                roots: &self.roots,
            };
            tree.all()
                .into_iter()
                .filter(|&x| matches!(self.nodes[x as usize].state, State::Leaf | State::Waiting))
                .collect()
        };
        let mut after: Vec<(u32, usize)> = Vec::new();
        for members in groups {
            // Algorithm 4: every member is waiting or terminal (phase 1
            // left nothing pending), and they agree on the subdivision.
            let first = members
                .iter()
                .find_map(|m| wait_of.get(m).copied())
                .expect("a group has a waiting shape");
            let (steps, scheme, span) = (
                waiting[first].steps,
                waiting[first].scheme,
                waiting[first].span,
            );
            for m in &members {
                if let Some(&wi) = wait_of.get(m) {
                    let w = &waiting[wi];
                    if w.steps != steps || w.scheme.name != scheme.name {
                        return Err(ShapeError::at(w.span, format!(
                            "the shapes of a smoothing group are subdivided together, so their \
                             `Subdivide`s agree; this one asks for {} steps of {}, another for {} of {}",
                            w.steps, w.scheme.name, steps, scheme.name
                        )));
                    }
                    after.push((*m, wi));
                }
            }
            self.smooth_group(&members, &live, steps, scheme, span)?;
        }
        // Each waiting shape goes on with its successor.
        after.sort_by_key(|(m, _)| order[m]);
        for (m, wi) in after {
            let w = &waiting[wi];
            let node = &self.nodes[m as usize];
            let mut cur = Cur::of(node);
            let mut frame = w.frame.clone();
            let base = node.params.len();
            // The body's random numbers are the shape's own too, whatever
            // shape was rewritten last.
            self.env.random = random_of(mix(node.key, 0x5EED));
            self.nodes[m as usize].state = State::Expanded;
            let made = self.exec(m, w.body, &mut cur, &mut frame, base)?;
            self.finish(m, made, cur, w.span)?;
        }
        Ok(())
    }

    fn smooth_group(
        &mut self,
        members: &[u32],
        live: &[u32],
        steps: usize,
        scheme: &smooth_scheme::Scheme,
        span: Span,
    ) -> R<()> {
        let inside: HashSet<u32> = members.iter().copied().collect();
        let others: Vec<&Geometry> = live
            .iter()
            .filter(|x| !inside.contains(x))
            .map(|&x| &*self.nodes[x as usize].geom)
            .collect();
        let member_geoms: Vec<Arc<Geometry>> = members
            .iter()
            .map(|&m| self.nodes[m as usize].geom.clone())
            .collect();
        let refs: Vec<&Geometry> = member_geoms.iter().map(|g| &**g).collect();
        let welded = geom::weld(
            &mut self.points,
            &refs,
            &others,
            &self.loose,
            &self.seam_planes,
        )
        .map_err(|m| ShapeError::at(span, m))?;
        let smoothed = smooth::subdivide(
            &scheme.grammar,
            &welded.soup,
            &welded.tags,
            &welded.protected_vertex,
            &welded.protected_face,
            steps,
            self.deadline,
        )
        .map_err(|m| ShapeError::at(span, m))?;
        self.groups.push(GroupReport {
            members: members.len(),
            faces_in: welded.soup.faces.len(),
            faces_out: smoothed.soup.faces.len(),
            protected_faces: welded.protected_face.iter().filter(|&&b| b).count(),
            protected_vertices: welded.protected_vertex.iter().filter(|&&b| b).count(),
            scheme: scheme.name.clone(),
            steps,
            meshes: self
                .opts
                .keep_meshes
                .then(|| Box::new((welded.soup.clone(), smoothed.soup.clone()))),
        });
        // One point per output vertex, the input's where it did not move.
        let mut ids: Vec<Option<u32>> = vec![None; smoothed.soup.positions.len()];
        let mut slices: Vec<Vec<geom::Face>> = vec![Vec::new(); members.len()];
        for (f, face) in smoothed.soup.faces.iter().enumerate() {
            let mut pts = Vec::with_capacity(face.len());
            for &v in face {
                let v = v as usize;
                let id = match ids[v] {
                    Some(id) => id,
                    None => {
                        let id = match smoothed.origin[v] {
                            Some(j) => welded.point_of[j as usize],
                            None => self
                                .points
                                .add(smoothed.soup.positions[v])
                                .map_err(|m| ShapeError::at(span, m))?,
                        };
                        ids[v] = Some(id);
                        id
                    }
                };
                pts.push(id);
            }
            let t = smoothed.tags[f] as usize;
            if let Some(s) = slices.get_mut(t) {
                s.push(geom::Face { pts, seam: 0 });
            }
        }
        for (k, (&m, faces)) in members.iter().zip(slices).enumerate() {
            let _ = k;
            let old = self.nodes[m as usize].geom.elements();
            let new = old - self.nodes[m as usize].geom.faces.len() + faces.len();
            self.hold(old, new, span)?;
            let node = &mut self.nodes[m as usize];
            Arc::make_mut(&mut node.geom).faces = faces;
            node.scope = geom::bounding_scope(&self.points, &node.geom, node.scope.axes);
        }
        Ok(())
    }
}

/// `v` with the coordinates written relative (`'0.5`) taken as fractions of
/// the scope's `size`.
fn relative(v: DVec3, rel: &[bool; 3], size: DVec3) -> DVec3 {
    DVec3::new(
        if rel[0] { v.x * size.x } else { v.x },
        if rel[1] { v.y * size.y } else { v.y },
        if rel[2] { v.z * size.z } else { v.z },
    )
}

/// Refuses a scope's origin, size or an extrusion's height beyond
/// [`geom::MAX_COORD`], where the shapes' arithmetic would overflow.
fn far(v: DVec3, what: &str, span: Span) -> R<()> {
    if !v.is_finite() || v.abs().max_element() > geom::MAX_COORD {
        return Err(ShapeError::at(
            span,
            format!(
                "this makes {what} ({}, {}, {}), beyond the {:e} that shapes stay within",
                geom::show(v.x),
                geom::show(v.y),
                geom::show(v.z),
                geom::MAX_COORD
            ),
        ));
    }
    Ok(())
}

/// The number of planes a split with this layout cuts at (at most): the
/// part ends strictly inside the scope.
fn cuts_of(layout: &[(usize, f64)], total: f64) -> usize {
    let mut at = 0.0;
    let mut n = 0usize;
    for (_, len) in layout {
        at += len;
        if at < total {
            n += 1;
        }
    }
    n
}

/// The direction a 2D shape faces: the sum of its faces' vector areas.
fn normal_of(points: &Points, g: &Geometry) -> DVec3 {
    g.faces
        .iter()
        .fold(DVec3::ZERO, |n, f| n + geom::newell(points, &f.pts))
        .normalize_or_zero()
}

/// What a successor did to its shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Made {
    Nothing,
    Children,
    Removed,
    Waiting,
}

impl Made {
    fn or(self, other: Made) -> Made {
        match (self, other) {
            (Made::Nothing, x) => x,
            (x, Made::Nothing) => x,
            (Made::Children, x) => {
                if x == Made::Removed {
                    Made::Children
                } else {
                    x
                }
            }
            (x, _) => x,
        }
    }
}

pub(crate) fn selector_name(s: Selector) -> &'static str {
    use Selector::*;
    match s {
        Front => "front",
        Back => "back",
        Left => "left",
        Right => "right",
        Top => "top",
        Bottom => "bottom",
        Side => "side",
        Horizontal => "horizontal",
        Vertical => "vertical",
        All => "all",
    }
}

/// The sizes of a split's parts along a scope of length `total`: (part,
/// length) in order. Absolute sizes are kept, relative ones are fractions
/// of `total`, floating ones share what is left in proportion to their
/// sizes. A repeat lays its pattern as many times as fits: with floating
/// parts, round(total / pattern) times (at least once) stretched to fill;
/// without, floor(total / pattern) times, the rest cut off.
pub(crate) fn lay_out(
    sizes: &[(SizeKind, f64)],
    total: f64,
    repeat: bool,
) -> Result<Vec<(usize, f64)>, String> {
    let tol = 1e-9 * total.abs().max(1.0);
    let fixed = |s: &(SizeKind, f64)| match s.0 {
        SizeKind::Absolute => s.1,
        SizeKind::Relative => s.1 * total,
        SizeKind::Floating => 0.0,
    };
    let fixed_sum: f64 = sizes.iter().map(fixed).sum();
    let float_sum: f64 = sizes
        .iter()
        .filter(|s| s.0 == SizeKind::Floating)
        .map(|s| s.1)
        .sum();
    let has_float = sizes.iter().any(|s| s.0 == SizeKind::Floating);
    if !repeat {
        if fixed_sum > total + tol {
            return Err(format!(
                "the split's fixed sizes add up to {fixed_sum}, more than the scope's {total}"
            ));
        }
        let left = (total - fixed_sum).max(0.0);
        return Ok(sizes
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let len = match s.0 {
                    SizeKind::Floating if float_sum > 0.0 => left * s.1 / float_sum,
                    SizeKind::Floating => {
                        left / sizes.iter().filter(|s| s.0 == SizeKind::Floating).count() as f64
                    }
                    _ => fixed(s),
                };
                (i, len)
            })
            .collect());
    }
    let pattern = fixed_sum + float_sum;
    if pattern <= 0.0 {
        return Err("a repeated pattern has a length above zero".into());
    }
    let times = if has_float {
        (total / pattern).round().max(1.0)
    } else {
        ((total + tol) / pattern).floor()
    };
    if times > 1e7 {
        return Err(format!(
            "this repeat would lay its pattern {} times (a pattern of {} in {}); at most 1e7",
            geom::show(times),
            geom::show(pattern),
            geom::show(total)
        ));
    }
    let times = times as usize;
    if has_float && fixed_sum * times as f64 > total + tol {
        return Err(format!(
            "the repeat's fixed sizes add up to {} in {times} repetitions, more than the scope's {total}",
            fixed_sum * times as f64
        ));
    }
    let left = (total - fixed_sum * times as f64).max(0.0) / times as f64;
    let mut out = Vec::with_capacity(times * sizes.len());
    for _ in 0..times {
        for (i, s) in sizes.iter().enumerate() {
            let len = match s.0 {
                SizeKind::Floating => left * s.1 / float_sum,
                _ => fixed(s),
            };
            out.push((i, len));
        }
    }
    Ok(out)
}

/// The connected components (shared points) of `shapes`, in the order of
/// their first member.
fn connected(nodes: &[Node], shapes: &[u32]) -> Vec<Vec<u32>> {
    let mut parent: Vec<usize> = (0..shapes.len()).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    let mut owner: HashMap<u32, usize> = HashMap::new();
    for (i, &s) in shapes.iter().enumerate() {
        for pt in nodes[s as usize].geom.point_ids() {
            match owner.get(&pt) {
                Some(&j) => {
                    let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                    if a != b {
                        parent[a.max(b)] = a.min(b);
                    }
                }
                None => {
                    owner.insert(pt, i);
                }
            }
        }
    }
    let mut out: Vec<Vec<u32>> = Vec::new();
    let mut index: HashMap<usize, usize> = HashMap::new();
    for (i, &s) in shapes.iter().enumerate() {
        let r = find(&mut parent, i);
        let k = *index.entry(r).or_insert_with(|| {
            out.push(Vec::new());
            out.len() - 1
        });
        out[k].push(s);
    }
    out
}

struct TreeOrder<'a> {
    nodes: &'a [Node],
    roots: &'a [u32],
}

/// Every shape in tree order: parents before children, children in the
/// order they were made; with an explicit stack, for trees of any depth.
fn tree_order(nodes: &[Node], roots: &[u32]) -> Vec<u32> {
    let mut out = Vec::with_capacity(nodes.len());
    let mut stack: Vec<u32> = roots.iter().rev().copied().collect();
    while let Some(n) = stack.pop() {
        out.push(n);
        stack.extend(nodes[n as usize].children.iter().rev().copied());
    }
    out
}

impl TreeOrder<'_> {
    fn all(&self) -> Vec<u32> {
        tree_order(self.nodes, self.roots)
    }

    fn rank(&self) -> HashMap<u32, usize> {
        self.all()
            .into_iter()
            .enumerate()
            .map(|(i, n)| (n, i))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grammar(text: &str) -> ShapeGrammar {
        let front = crate::load::front("t.lsys", text.to_string(), &[]).unwrap();
        super::super::from_front(front, None).unwrap_or_else(|e| panic!("{e}"))
    }

    fn obj(g: &ShapeGrammar, fifo: bool, seed: u32) -> String {
        let opts = ShapeOptions {
            seed,
            fifo,
            ..Default::default()
        };
        let never = Deadline::after(std::time::Duration::from_secs(3600));
        let t = derive(g, &opts, &never).unwrap_or_else(|e| panic!("{}", e.message));
        super::super::output::obj(g, &t, "t.mtl").0
    }

    /// Algorithm 1 chooses "a shape" to rewrite: taking the newest first or
    /// the oldest first gives the same model, bit for bit, stochastic
    /// rules and smoothing groups included.
    #[test]
    fn the_order_of_rewriting_does_not_matter() {
        let text = "axiom: lot(20, 12) Lot\n\
             Lot --> extrude(9) Mass\n\
             Mass --> comp(f) { top : Roof | side : Facade | bottom : NIL }\n\
             Facade --> split(y) { ~3 : Floor }*\n\
             Floor --> split(x) { ~2.5 : Tile }*\n\
             1 : Tile ~> extrude(-0.2) Dark : 0.6\n\
             2 : Tile ~> split(x) { ~1 : Wall | ~1 : Lit(ran(1)) } : 0.4\n\
             Roof --> split(x) { ~1 : R | ~1 : R }\n\
             R --> Subdivide(1) { Done(ran(1)) }\n\
             Done(k) --> t(0, k, 0)\n";
        let g = grammar(text);
        for seed in [1, 2, 3] {
            assert_eq!(obj(&g, false, seed), obj(&g, true, seed));
        }
        assert_ne!(obj(&g, false, 1), obj(&g, false, 2));
    }

    fn derive_err(g: &ShapeGrammar, opts: &ShapeOptions) -> ShapeError {
        let never = Deadline::after(std::time::Duration::from_secs(3600));
        match derive(g, opts, &never) {
            Ok(_) => panic!("the derivation succeeded"),
            Err(e) => e,
        }
    }

    /// The text at a span of the grammar.
    fn at(g: &ShapeGrammar, span: Span) -> String {
        let text = &g.sources.get(span.file).text;
        text[span.start as usize..span.end as usize].to_string()
    }

    /// A smoothing group's subdivision stops at its scheme's face limit,
    /// which load sets to at most MAX_SMOOTH_FACES, with the message at
    /// the `Subdivide`. √3 on a box: 12 triangles, then 36, then 108 (3
    /// per triangle a step, by hand), past a limit of 100.
    #[test]
    fn subdivision_stops_at_the_face_limit() {
        let mut g = grammar("axiom: s(1, 1, 1) i(\"box\") A\nA --> Subdivide(2) { B }\n");
        assert_eq!(g.schemes[0].grammar.max_faces, MAX_SMOOTH_FACES);
        g.schemes[0].grammar.max_faces = 100;
        let e = derive_err(&g, &ShapeOptions::default());
        assert!(e.message.contains("past the limit of 100"), "{}", e.message);
        assert_eq!(at(&g, e.span), "Subdivide(2) { B }");
        g.schemes[0].grammar.max_faces = 108;
        obj(&g, false, 1);
    }

    /// The faces all shapes hold together are bounded: a box's 6 faces in
    /// the axiom's shape and each child's copy are 6 each, 18 in all, so a
    /// limit of 17 stops at the third shape, at its symbol, and 18 does not.
    #[test]
    fn held_faces_are_bounded() {
        let g = grammar("axiom: s(1, 1, 1) i(\"box\") A\nA --> B C\n");
        let opts = ShapeOptions {
            max_faces: 17,
            ..Default::default()
        };
        let e = derive_err(&g, &opts);
        assert!(e.message.contains("hold 18 faces"), "{}", e.message);
        assert_eq!(at(&g, e.span), "C");
        let opts = ShapeOptions {
            max_faces: 18,
            ..Default::default()
        };
        let never = Deadline::after(std::time::Duration::from_secs(3600));
        derive(&g, &opts, &never).unwrap_or_else(|e| panic!("{}", e.message));
    }

    #[test]
    fn layout_matches_hand_sums() {
        use SizeKind::*;
        // 10 = 2 + 1 (a tenth) + 7 shared 1 : 3.
        let l = lay_out(
            &[
                (Absolute, 2.0),
                (Floating, 1.0),
                (Floating, 3.0),
                (Relative, 0.1),
            ],
            10.0,
            false,
        )
        .unwrap();
        let lens: Vec<f64> = l.iter().map(|x| x.1).collect();
        assert_eq!(lens, vec![2.0, 1.75, 5.25, 1.0]);
        assert!(lay_out(&[(Absolute, 6.0), (Absolute, 6.0)], 10.0, false).is_err());
        // A repeat of about 2 in 7: round(3.5) = 4 parts of 1.75.
        let l = lay_out(&[(Floating, 2.0)], 7.0, true).unwrap();
        assert_eq!(l.iter().map(|x| x.1).collect::<Vec<_>>(), vec![1.75; 4]);
    }
}
