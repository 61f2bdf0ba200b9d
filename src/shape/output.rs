//! What a shape derivation writes: the shape tree (text or JSON), an OBJ
//! file with one group per terminal shape and its material, and the
//! polygons of a picture with their colours. Everything walks the tree in
//! order, so the bytes do not depend on the order shapes were rewritten in.

use std::collections::HashMap;
use std::fmt::Write as _;

use crate::colour::Rgba;
use crate::mesh::PolygonSoup;

use super::geom::Geometry;
use super::run::{Node, ShapeTree, State};
use super::ShapeGrammar;

/// A terminal shape's colour: its own, or one of the palette's by symbol.
pub fn colour_of(node: &Node) -> [u8; 3] {
    match node.colour {
        Some(c) => c,
        None => {
            let Rgba(r, g, b, _) = crate::colour::palette(node.symbol as i64 + 1);
            [r, g, b]
        }
    }
}

fn state_name(s: &State) -> &'static str {
    match s {
        State::Pending => "pending",
        State::Expanded => "expanded",
        State::Leaf => "terminal",
        State::Removed => "removed",
        State::Waiting => "waiting",
    }
}

fn num(x: f64) -> String {
    format!("{}", unsigned_zero(x))
}

/// `x`, with -0 as 0: written with `{}`, the shortest text that reads back
/// as the same double.
fn unsigned_zero(x: f64) -> f64 {
    if x == 0.0 {
        0.0
    } else {
        x
    }
}

/// The deepest level [`tree_text`] indents; a deeper shape's line starts
/// with its level in brackets instead, so that a line stays short whatever
/// the depth (a chain of a million shapes is a million short lines).
pub const MAX_INDENT: usize = 32;

/// The tree as indented text: one line per shape.
pub fn tree_text(g: &ShapeGrammar, t: &ShapeTree) -> String {
    let mut out = String::new();
    let mut stack: Vec<(u32, usize)> = t.roots.iter().rev().map(|&r| (r, 0)).collect();
    while let Some((n, depth)) = stack.pop() {
        let node = &t.nodes[n as usize];
        let _ = write!(out, "{:indent$}", "", indent = 2 * depth.min(MAX_INDENT));
        if depth > MAX_INDENT {
            let _ = write!(out, "[{depth}] ");
        }
        out.push_str(&g.symbols[node.symbol as usize]);
        if !node.params.is_empty() {
            let p: Vec<String> = node.params.iter().map(|&x| num(x)).collect();
            let _ = write!(out, "({})", p.join(", "));
        }
        let s = &node.scope;
        let _ = writeln!(
            out,
            "  {}D {} faces, scope at ({}, {}, {}) size ({}, {}, {}), {}",
            node.geom.dim,
            node.geom.face_count(),
            num(s.origin.x),
            num(s.origin.y),
            num(s.origin.z),
            num(s.size.x),
            num(s.size.y),
            num(s.size.z),
            state_name(&node.state)
        );
        stack.extend(node.children.iter().rev().map(|&c| (c, depth + 1)));
    }
    out
}

/// The tree as JSON text: an array of root shapes, each an object with its
/// symbol, parameters, scope (origin, axes, size), dimension, face count,
/// the number of vertices it shares with its parent (the paper's
/// connectivity map), state and children, one shape per line. Written with
/// an explicit stack, so a tree as deep as the shape limit allows is
/// written without recursion.
pub fn tree_json(g: &ShapeGrammar, t: &ShapeTree) -> String {
    let mut out = String::from("[");
    // (node, index among its siblings) to open, or None to close a shape.
    let mut stack: Vec<Option<(u32, usize)>> = t
        .roots
        .iter()
        .enumerate()
        .rev()
        .map(|(i, &r)| Some((r, i)))
        .collect();
    let f = |x: f64| serde_json::Value::from(unsigned_zero(x)).to_string();
    let v3 = |v: glam::DVec3| format!("[{}, {}, {}]", f(v.x), f(v.y), f(v.z));
    // Closing brackets in a row, so that a deep tree's run of them is
    // broken into short lines.
    let mut closing = 0usize;
    while let Some(item) = stack.pop() {
        let Some((n, i)) = item else {
            if closing > 0 && closing.is_multiple_of(32) {
                out.push('\n');
            }
            out.push_str("]}");
            closing += 1;
            continue;
        };
        closing = 0;
        if i > 0 {
            out.push(',');
        }
        out.push('\n');
        let node = &t.nodes[n as usize];
        let s = &node.scope;
        let params: Vec<String> = node.params.iter().map(|&x| f(x)).collect();
        let shared = if node.parent == u32::MAX {
            0
        } else {
            shared(t, n, node.parent).len()
        };
        let _ = write!(
            out,
            "{{\"symbol\": {}, \"params\": [{}], \"scope\": {{\"origin\": {}, \"x\": {}, \
             \"y\": {}, \"z\": {}, \"size\": {}}}, \"dim\": {}, \"faces\": {}, \
             \"shared_with_parent\": {}, \"state\": \"{}\", \"children\": [",
            serde_json::Value::from(g.symbols[node.symbol as usize].as_str()),
            params.join(", "),
            v3(s.origin),
            v3(s.axes[0]),
            v3(s.axes[1]),
            v3(s.axes[2]),
            v3(s.size),
            node.geom.dim,
            node.geom.face_count(),
            shared,
            state_name(&node.state)
        );
        stack.push(None);
        stack.extend(
            node.children
                .iter()
                .enumerate()
                .rev()
                .map(|(k, &c)| Some((c, k))),
        );
    }
    out.push_str("\n]");
    out
}

/// The material name of a colour.
fn material(c: [u8; 3]) -> String {
    format!("c{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// An OBJ file of the terminal shapes, one group each (`g Symbol_k`, k
/// counting the shapes of that symbol from 1) with `usemtl` of its colour,
/// and the MTL file that defines the colours; `mtl_name` is the MTL file's
/// name as the OBJ refers to it.
pub fn obj(g: &ShapeGrammar, t: &ShapeTree, mtl_name: &str) -> (String, String) {
    let leaves = t.leaves();
    // Each point's OBJ number (from 1; 0: not written), by point id.
    let mut index: Vec<u32> = vec![0; t.points.pos.len()];
    let mut order: Vec<u32> = Vec::new();
    for &l in &leaves {
        for p in t.nodes[l as usize].geom.point_ids() {
            if let Some(slot) = index.get_mut(p as usize) {
                if *slot == 0 {
                    order.push(p);
                    *slot = order.len() as u32;
                }
            }
        }
    }
    let mut out = String::with_capacity(order.len() * 40 + leaves.len() * 64);
    let _ = writeln!(
        out,
        "# subgram shape grammar: {} terminal shapes",
        leaves.len()
    );
    let _ = writeln!(out, "mtllib {mtl_name}");
    for &p in &order {
        let v = t.points.pos[p as usize];
        let z = unsigned_zero;
        let _ = writeln!(out, "v {} {} {}", z(v.x), z(v.y), z(v.z));
    }
    let mut count: HashMap<u32, usize> = HashMap::new();
    let mut colours: Vec<[u8; 3]> = Vec::new();
    for &l in &leaves {
        let node = &t.nodes[l as usize];
        let k = count.entry(node.symbol).or_insert(0);
        *k += 1;
        let c = colour_of(node);
        if !colours.contains(&c) {
            colours.push(c);
        }
        let _ = writeln!(out, "g {}_{}", g.symbols[node.symbol as usize], k);
        let _ = writeln!(out, "usemtl {}", material(c));
        write_geometry(&mut out, &node.geom, &index);
    }
    let mut mtl = String::new();
    let _ = writeln!(mtl, "# subgram shape grammar colours");
    for c in colours {
        let _ = writeln!(
            mtl,
            "newmtl {}\nKd {} {} {}\n",
            material(c),
            num(c[0] as f64 / 255.0),
            num(c[1] as f64 / 255.0),
            num(c[2] as f64 / 255.0)
        );
    }
    (out, mtl)
}

fn write_geometry(out: &mut String, geom: &Geometry, index: &[u32]) {
    let at = |p: u32| index.get(p as usize).copied().unwrap_or(0);
    for f in &geom.faces {
        out.push('f');
        for &p in &f.pts {
            let _ = write!(out, " {}", at(p));
        }
        out.push('\n');
    }
    for e in &geom.edges {
        let _ = writeln!(out, "l {} {}", at(e[0]), at(e[1]));
    }
    for &v in &geom.verts {
        let _ = writeln!(out, "p {}", at(v));
    }
}

/// The faces of the terminal shapes as one soup, with each face's colour
/// (for pictures, PLY and OFF).
pub fn soup(t: &ShapeTree) -> (PolygonSoup, Vec<Rgba>) {
    let mut soup = PolygonSoup::default();
    let mut colours = Vec::new();
    // Each point's soup vertex, by point id (u32::MAX: none yet).
    let mut index: Vec<u32> = vec![u32::MAX; t.points.pos.len()];
    for l in t.leaves() {
        let node = &t.nodes[l as usize];
        let c = colour_of(node);
        for f in &node.geom.faces {
            let face = f
                .pts
                .iter()
                .map(|&p| {
                    let slot = &mut index[p as usize];
                    if *slot == u32::MAX {
                        soup.positions.push(t.points.pos[p as usize]);
                        *slot = soup.positions.len() as u32 - 1;
                    }
                    *slot
                })
                .collect::<Vec<u32>>();
            soup.faces.push(face);
            colours.push(Rgba(c[0], c[1], c[2], 255));
        }
    }
    (soup, colours)
}

/// One line per smoothing group subdivided.
pub fn groups_text(t: &ShapeTree) -> String {
    let mut out = String::new();
    for (k, g) in t.groups.iter().enumerate() {
        let _ = writeln!(
            out,
            "smoothing group {}: {} shapes, {} x {}, {} -> {} faces, {} protected faces, {} protected vertices",
            k + 1,
            g.members,
            g.scheme,
            g.steps,
            g.faces_in,
            g.faces_out,
            g.protected_faces,
            g.protected_vertices
        );
    }
    out
}

/// Counts for a run's summary.
pub fn counts(t: &ShapeTree) -> (usize, usize, usize) {
    let leaves = t.leaves();
    let faces = leaves
        .iter()
        .map(|&l| t.nodes[l as usize].geom.face_count())
        .sum();
    (t.nodes.len(), leaves.len(), faces)
}

/// The points that shape `a` shares with shape `b` (the paper's
/// connectivity map between them), in `a`'s order.
pub fn shared(t: &ShapeTree, a: u32, b: u32) -> Vec<u32> {
    let other: std::collections::HashSet<u32> = t.nodes[b as usize].geom.point_ids().collect();
    let mut seen = std::collections::HashSet::new();
    t.nodes[a as usize]
        .geom
        .point_ids()
        .filter(|p| other.contains(p) && seen.insert(*p))
        .collect()
}
