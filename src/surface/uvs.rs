//! Texture coordinates (face-varying data) through a grammar's run.
//!
//! The coordinates of a mesh's face corners make a mesh of their own, the
//! UV layout: the same faces, with a vertex for each value at each mesh
//! vertex, so that the layout is the mesh cut open along its seams. The
//! grammar runs on the layout as it runs on the mesh, with the layout's
//! points `(u, v, 0)`: a seam is a boundary there, and the grammar's
//! boundary rules are what OpenSubdiv does at a face-varying boundary (its
//! crease rule over the values on either side, and the midpoint on the
//! seam's edges). OpenSubdiv's face-varying linear interpolation choices
//! ([`FvarLinear`]) sharpen some of the layout's vertices before the run,
//! as its `FVarLevel` decides which values are corners, or (`All`) every
//! vertex and edge before every step, which makes the grammar's crease
//! rules a linear interpolation. The mesh carries its sharpness over to
//! the layout, so a crease is a crease in the texture too.
//!
//! Both runs give every vertex an origin key (see
//! [`Mesh::track_origins`]); a face of the result is found in the
//! layout's result by its corners' keys, so each of its corners gets the
//! layout's point there. Where the grammar makes a different topology at
//! a boundary than inside (√3, the dual schemes, adaptive refinement) the
//! two results do not correspond, and that is an error, not a guess.

use std::collections::HashMap;

use glam::{DVec2, DVec3};

use crate::mesh::halfedge::mix64;
use crate::mesh::{FaceUvs, Mesh, PolygonSoup, SoupSharpness, VertexId};

use super::run::{Grammar, GrammarRun, RunError};

/// OpenSubdiv's face-varying linear interpolation choices
/// (`Sdc::Options::FVarLinearInterpolation`), from the smoothest: which
/// texture coordinates are interpolated linearly instead of by the
/// scheme's smooth rules. Blender's "UV Smooth" names them the other way
/// round (its default, "Keep Boundaries", is [`FvarLinear::Boundaries`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FvarLinear {
    /// Smooth everywhere the mesh is smooth; seams are boundaries with the
    /// boundary rules (Blender: "All").
    None,
    /// Corners (a value in a single face) stay where they are (Blender:
    /// "Keep Corners").
    CornersOnly,
    /// And every value where three or more regions meet (Blender: "Keep
    /// Corners, Junctions").
    CornersPlus1,
    /// And darts (a seam ending inside the mesh) and both values where one
    /// is a corner (Blender: "Keep Corners, Junctions, Concave").
    CornersPlus2,
    /// Linear along every seam and boundary (Blender's default, "Keep
    /// Boundaries").
    #[default]
    Boundaries,
    /// Linear everywhere (Blender: "None").
    All,
}

impl FvarLinear {
    /// The names `--fvar-linear` takes, in order.
    pub const NAMES: [&'static str; 6] = [
        "none",
        "corners-only",
        "corners-plus1",
        "corners-plus2",
        "boundaries",
        "all",
    ];

    const ALL: [FvarLinear; 6] = [
        FvarLinear::None,
        FvarLinear::CornersOnly,
        FvarLinear::CornersPlus1,
        FvarLinear::CornersPlus2,
        FvarLinear::Boundaries,
        FvarLinear::All,
    ];

    /// The choice `name` (one of [`FvarLinear::NAMES`]).
    pub fn from_name(name: &str) -> Option<FvarLinear> {
        let k = Self::NAMES.iter().position(|&n| n == name)?;
        Some(Self::ALL[k])
    }

    /// Its name in [`FvarLinear::NAMES`].
    pub fn name(self) -> &'static str {
        Self::NAMES[Self::ALL.iter().position(|&m| m == self).unwrap_or(0)]
    }

    fn linear_boundaries(self) -> bool {
        matches!(self, FvarLinear::Boundaries | FvarLinear::All)
    }

    fn corners_sharp(self) -> bool {
        self != FvarLinear::None
    }

    fn junctions_sharp(self) -> bool {
        matches!(self, FvarLinear::CornersPlus1 | FvarLinear::CornersPlus2)
    }

    fn darts_sharp(self) -> bool {
        self == FvarLinear::CornersPlus2 || self.linear_boundaries()
    }
}

/// A mesh's UV layout, ready for the grammar: the layout as a mesh, and
/// the mesh vertex of each of its vertices.
pub struct UvLayout {
    pub mesh: Mesh,
    /// The mesh vertex each layout vertex is a value at.
    pub vertex_of: Vec<VertexId>,
    pub mode: FvarLinear,
}

impl UvLayout {
    /// The layout of `uvs`, the texture coordinates of `soup`'s corners,
    /// where `mesh` is the mesh built from `soup` (its sharpness carried
    /// over), with the vertices `mode` makes linear sharpened.
    pub fn new(
        soup: &PolygonSoup,
        uvs: &FaceUvs,
        mesh: &Mesh,
        mode: FvarLinear,
    ) -> Result<UvLayout, String> {
        // A layout vertex for each (mesh vertex, value) pair, or one for
        // each fan of faces around the vertex that hold the value where
        // the fans are separate (a bow-tie would not be a manifold
        // layout); such a value is kept a corner below, as OpenSubdiv
        // keeps a non-manifold value.
        let corner_of = fans_of_values(soup, uvs);
        let mut index: HashMap<u32, u32> = HashMap::new();
        let mut groups: HashMap<(u32, u32), u32> = HashMap::new();
        let mut value_of: Vec<(u32, u32)> = Vec::new();
        let mut vertex_of: Vec<VertexId> = Vec::new();
        let mut positions: Vec<DVec3> = Vec::new();
        let mut faces = crate::mesh::Faces::with_capacity(soup.faces.len(), uvs.corners.len());
        let mut corner = 0;
        let mut face = Vec::new();
        for f in soup.faces.iter() {
            face.clear();
            for &v in f {
                let t = uvs.corners[corner];
                let root = corner_of[corner];
                corner += 1;
                let id = *index.entry(root).or_insert_with(|| {
                    let uv = uvs.values[t as usize];
                    vertex_of.push(VertexId(v));
                    positions.push(DVec3::new(uv.x, uv.y, 0.0));
                    *groups.entry((v, t)).or_insert(0) += 1;
                    value_of.push((v, t));
                    positions.len() as u32 - 1
                });
                face.push(id);
            }
            faces.push(&face);
        }
        // Built over the mesh's own points (a layout may have faces of no
        // area, which a mesh of points refuses), then moved to the values.
        let layout = PolygonSoup {
            positions: vertex_of.iter().map(|v| mesh.position(*v)).collect(),
            faces,
            face_lines: soup.face_lines.clone(),
            vertex_lines: Vec::new(),
        };
        let mut uv_mesh = Mesh::from_soup(&layout).map_err(|e| {
            let at = e.line.map_or(String::new(), |l| format!(" (line {l})"));
            format!(
                "the texture coordinates do not make a layout the grammar can run on{at}: {}",
                e.message
            )
        })?;
        for (u, p) in positions.iter().enumerate() {
            uv_mesh.set_position(VertexId(u as u32), *p);
        }
        // The mesh's sharpness, edge by edge and vertex by vertex.
        if mesh.has_sharpness_flag() {
            for e in uv_mesh.edges().collect::<Vec<_>>() {
                let (a, b) = uv_mesh.edge_vertices(e);
                let (p, q) = (vertex_of[a.index()], vertex_of[b.index()]);
                if let Some(h) = mesh.find_halfedge(p, q) {
                    let s = mesh.edge_sharpness(h.edge());
                    if s > 0.0 {
                        uv_mesh.set_edge_sharpness(e, s).map_err(|e| e.message)?;
                    }
                }
            }
            for (u, v) in vertex_of.iter().enumerate() {
                let s = mesh.vertex_sharpness(*v);
                if s > 0.0 {
                    uv_mesh
                        .set_vertex_sharpness(VertexId(u as u32), s)
                        .map_err(|e| e.message)?;
                }
            }
        }
        // A value in separate fans at one vertex is a corner in each
        // (OpenSubdiv's non-manifold value).
        for (u, key) in value_of.iter().enumerate() {
            if groups[key] > 1 {
                uv_mesh
                    .set_vertex_sharpness(VertexId(u as u32), f64::INFINITY)
                    .map_err(|e| e.message)?;
            }
        }
        let mut out = UvLayout {
            mesh: uv_mesh,
            vertex_of,
            mode,
        };
        out.sharpen(soup, &layout, mesh);
        Ok(out)
    }

    /// Sharpens the values that `mode` makes corners, as OpenSubdiv's
    /// face-varying level decides at each mesh vertex whose values do not
    /// match its topology (a seam at it, or a boundary the mode treats
    /// alike): every value where boundaries are linear; values where three
    /// or more regions meet (`CornersPlus1` and on); a dart's; a value in
    /// one face (a corner) unless the mode is `None`; both values where
    /// one of two is a corner (`CornersPlus2`) or where either region
    /// holds an infinitely sharp edge.
    fn sharpen(&mut self, soup: &PolygonSoup, layout: &PolygonSoup, mesh: &Mesh) {
        let mode = self.mode;
        if mode == FvarLinear::None {
            return;
        }
        let m = &self.mesh;
        let mut mesh_faces = vec![0u32; soup.positions.len()];
        for &v in soup.faces.indices() {
            mesh_faces[v as usize] += 1;
        }
        let mut value_faces = vec![0u32; layout.positions.len()];
        for &u in layout.faces.indices() {
            value_faces[u as usize] += 1;
        }
        let mut values: Vec<Vec<VertexId>> = vec![Vec::new(); soup.positions.len()];
        for (u, v) in self.vertex_of.iter().enumerate() {
            values[v.index()].push(VertexId(u as u32));
        }
        // A region with an infinitely sharp edge inside it.
        let inf_inside = |u: VertexId| {
            m.outgoing_halfedges(u).any(|h| {
                let e = h.edge();
                !m.is_boundary_edge(e) && !m.is_block_edge(e) && m.edge_sharpness(e).is_infinite()
            })
        };
        let mut sharp = Vec::new();
        for (p, vals) in values.iter().enumerate() {
            let pv = VertexId(p as u32);
            if vals.is_empty() {
                continue;
            }
            let boundary = mesh.is_boundary_vertex(pv);
            let seam = vals.len() > 1 || (!boundary && m.is_boundary_vertex(vals[0]));
            let mismatch = seam
                || (boundary && mode.linear_boundaries())
                || (boundary && mesh_faces[p] == 1 && mode.corners_sharp());
            if !mismatch {
                continue;
            }
            let mut all = mode.linear_boundaries()
                || mesh.vertex_sharpness(pv).is_infinite()
                || (mode.junctions_sharp() && vals.len() > 2)
                || (mode.darts_sharp() && vals.len() == 1 && !boundary);
            if !all && mode.junctions_sharp() && vals.len() == 2 {
                all = vals.iter().any(|&u| inf_inside(u));
                if mode == FvarLinear::CornersPlus2 {
                    all |= vals.iter().any(|&u| value_faces[u.index()] == 1);
                }
            }
            for &u in vals {
                if all || inf_inside(u) || (value_faces[u.index()] == 1 && mode.corners_sharp()) {
                    sharp.push(u);
                }
            }
        }
        for u in sharp {
            self.mesh
                .set_vertex_sharpness(u, f64::INFINITY)
                .expect("a layout vertex");
        }
    }

    /// Runs `steps` steps of `g` on the layout (after its `init:` rules),
    /// with origin keys from the mesh vertices' (see [`base_key`]); under
    /// [`FvarLinear::All`] every vertex and edge is made sharp before
    /// each step.
    pub fn run(
        &mut self,
        g: &Grammar,
        steps: usize,
        deadline: Option<crate::Deadline>,
    ) -> Result<(), RunError> {
        let of = &self.vertex_of;
        self.mesh.track_origins(|u| base_key(of[u.index()]));
        let linear = self.mode == FvarLinear::All;
        let mut run: GrammarRun = {
            let _scope = deadline.map(|d| crate::deadline::scope(Some(d)));
            g.start(&mut self.mesh)?
        };
        run.set_deadline(deadline);
        for _ in 0..steps {
            if linear {
                run.sharpen_everything();
            }
            run.steps(1, |_| {})?;
        }
        Ok(())
    }
}

/// For each corner of `soup`, a representative corner of its fan: the
/// corners at the same vertex with the same value joined across the edges
/// whose two faces agree on the values at both ends (edges that are no
/// seam). Union-find over the corners.
fn fans_of_values(soup: &PolygonSoup, uvs: &FaceUvs) -> Vec<u32> {
    let n = uvs.corners.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut c: u32) -> u32 {
        while parent[c as usize] != c {
            let g = parent[parent[c as usize] as usize];
            parent[c as usize] = g;
            c = g;
        }
        c
    }
    // Each directed face edge by its ends' (vertex, value) pairs, with
    // its corners.
    let mut edges: HashMap<(u32, u32, u32, u32), (u32, u32)> = HashMap::with_capacity(n);
    let mut start = 0usize;
    for f in soup.faces.iter() {
        for j in 0..f.len() {
            let (ca, cb) = (start + j, start + (j + 1) % f.len());
            let key = (f[j], uvs.corners[ca], f[(j + 1) % f.len()], uvs.corners[cb]);
            edges.insert(key, (ca as u32, cb as u32));
        }
        start += f.len();
    }
    for (&(a, ta, b, tb), &(ca, cb)) in &edges {
        if let Some(&(cb2, ca2)) = edges.get(&(b, tb, a, ta)) {
            for (x, y) in [(ca, ca2), (cb, cb2)] {
                let (rx, ry) = (root(&mut parent, x), root(&mut parent, y));
                if rx != ry {
                    parent[rx.max(ry) as usize] = rx.min(ry);
                }
            }
        }
    }
    (0..n as u32).map(|c| root(&mut parent, c)).collect()
}

/// The origin key of base mesh vertex `v`.
pub fn base_key(v: VertexId) -> u64 {
    mix64(u64::from(v.0))
}

/// True when some rule of `g` reads sharpness (`sharp`, `sharpness`,
/// `creases`, `crease_weight`): only such a grammar can keep the values
/// that a choice other than [`FvarLinear::None`] makes linear.
pub fn reads_sharpness(g: &Grammar) -> bool {
    use super::host::id;
    use crate::lang::ir::{Ex, Func};
    let mut found = false;
    for r in &g.rules {
        for e in r.cond.iter().chain(r.assign.iter()) {
            e.walk(&mut |x| {
                found |= matches!(
                    x,
                    Ex::Call(
                        Func::Host(id::SHARP | id::SHARPNESS | id::CREASES | id::CREASE_WEIGHT),
                        ..
                    )
                );
            });
        }
    }
    found
}

/// The mesh a run made, as a soup (basic blocks merged into polygons)
/// with its sharpness, and its corners' texture coordinates from the run
/// on the layout: each face is found in the layout's result by its
/// corners' origin keys. An error where a face has no counterpart (the
/// grammar made a different topology at a seam than inside).
pub fn carry(mesh: &Mesh, layout: &Mesh) -> Result<(PolygonSoup, SoupSharpness, FaceUvs), String> {
    let (soup, vertices) = mesh.quad_soup_with_vertices();
    let (uv_soup, uv_vertices) = layout.quad_soup_with_vertices();
    if uv_soup.faces.len() != soup.faces.len() {
        return Err(mismatch());
    }
    // The soups' vertices' keys, then each face's hash of its keys from
    // the smallest on; the two lists sorted by hash meet face to face (a
    // sort and a walk, where a table of a million faces would miss the
    // cache at every look-up).
    let keys_of = |m: &Mesh, vs: &[VertexId]| -> Vec<u64> {
        vs.iter().map(|&v| m.origin(v).unwrap_or(0)).collect()
    };
    let (keys, uv_keys) = (keys_of(mesh, &vertices), keys_of(layout, &uv_vertices));
    let hashed = |s: &PolygonSoup, keys: &[u64]| -> Vec<(u64, u32, u32)> {
        let mut cycle = Vec::new();
        let mut out: Vec<(u64, u32, u32)> = s
            .faces
            .iter()
            .enumerate()
            .map(|(k, f)| {
                cycle.clear();
                cycle.extend(f.iter().map(|&v| keys[v as usize]));
                let (h, rot) = cycle_hash(&cycle);
                (h, k as u32, rot as u32)
            })
            .collect();
        out.sort_unstable();
        out
    };
    let (faces, uv_faces) = (hashed(&soup, &keys), hashed(&uv_soup, &uv_keys));
    // The layout face and the two rotations of each face.
    let mut partner = vec![(0u32, 0u32, 0u32); soup.faces.len()];
    for (i, (&(h, k, rot), &(uh, uk, urot))) in faces.iter().zip(&uv_faces).enumerate() {
        let repeated = i > 0 && faces[i - 1].0 == h;
        if h != uh || repeated {
            return Err(mismatch());
        }
        partner[k as usize] = (uk, rot, urot);
    }
    let mut corners = Vec::with_capacity(soup.faces.indices().len());
    for (f, &(k, rot, uv_rot)) in soup.faces.iter().zip(&partner) {
        let g = &uv_soup.faces[k as usize];
        let n = f.len();
        if g.len() != n {
            return Err(mismatch());
        }
        for (j, &v) in f.iter().enumerate() {
            // Corner j of f is corner (j - rot + uv_rot) of g.
            let u = g[(j + n - rot as usize + uv_rot as usize) % n];
            if uv_keys[u as usize] != keys[v as usize] {
                return Err(mismatch());
            }
            corners.push(u);
        }
    }
    let values = uv_soup
        .positions
        .iter()
        .map(|p| DVec2::new(p.x, p.y))
        .collect();
    let mut index = vec![u32::MAX; mesh.v_alive.len()];
    for (i, v) in vertices.iter().enumerate() {
        index[v.index()] = i as u32;
    }
    let sharpness = mesh.soup_sharpness(&index, false);
    Ok((soup, sharpness, FaceUvs { values, corners }))
}

/// The message for a run whose result and its layout's do not match.
fn mismatch() -> String {
    "the grammar made a different mesh at the seams of the texture coordinates than inside \
     them (a scheme whose boundary rules change its topology: √3, a dual or an adaptive one), \
     so the coordinates cannot follow it; `--no-uvs` subdivides without them"
        .to_string()
}

/// A hash of a face's keys read from its smallest key on (the same for
/// any starting corner), and where that smallest key is.
fn cycle_hash(keys: &[u64]) -> (u64, usize) {
    let rot = (0..keys.len()).min_by_key(|&i| keys[i]).unwrap_or(0);
    let mut h = keys.len() as u64;
    for j in 0..keys.len() {
        h = mix64(h ^ keys[(rot + j) % keys.len()]);
    }
    (h, rot)
}
