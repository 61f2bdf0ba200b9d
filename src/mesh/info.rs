//! `subgram mesh info`: counts, boundary loops, Euler characteristic and
//! genus, valences and levels.

use std::collections::BTreeMap;

use serde::Serialize;

use super::halfedge::{HalfEdgeId, Mesh};

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeshInfo {
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
    /// Faces after merging basic blocks back into quads (or, for dual
    /// blocks, the polygons around their centres).
    pub quads: usize,
    /// Vertices after merging: dual-block centres are left out.
    pub merged_vertices: usize,
    pub boundary_loops: usize,
    pub components: usize,
    /// Vertices on no edge (an OBJ `v` no face uses). They count in
    /// `vertices` but not in the Euler characteristic or the genus.
    pub isolated_vertices: usize,
    /// `V - E + F` over the vertices that are on a face.
    pub euler_characteristic: i64,
    /// `(2c - χ - b) / 2` summed over components; `None` if not an integer.
    pub genus: Option<i64>,
    pub valences: BTreeMap<usize, usize>,
    pub vertex_levels: BTreeMap<u32, usize>,
    pub edge_levels: BTreeMap<u32, usize>,
    pub face_levels: BTreeMap<u32, usize>,
    /// Edges of positive sharpness (creases), and those sharp for ever.
    #[serde(skip_serializing_if = "is_zero")]
    pub sharp_edges: usize,
    #[serde(skip_serializing_if = "is_zero")]
    pub infinitely_sharp_edges: usize,
    /// Vertices of positive sharpness (corners by their own sharpness).
    #[serde(skip_serializing_if = "is_zero")]
    pub sharp_vertices: usize,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

impl Mesh {
    pub fn info(&self) -> MeshInfo {
        let merged = self.to_quad_soup();
        let mut seen = vec![false; self.he_to.len()];
        let mut loops = 0;
        for e in self.edges() {
            for h in [e.halfedge(), e.halfedge().twin()] {
                if self.is_boundary_halfedge(h) && !seen[h.index()] {
                    loops += 1;
                    let mut g: HalfEdgeId = h;
                    loop {
                        seen[g.index()] = true;
                        g = self.next(g);
                        if g == h || seen[g.index()] {
                            break;
                        }
                    }
                }
            }
        }
        // Components by union-find over edges.
        let n = self.v_alive.len();
        let mut parent: Vec<usize> = (0..n).collect();
        fn find(p: &mut [usize], mut x: usize) -> usize {
            while p[x] != x {
                p[x] = p[p[x]];
                x = p[x];
            }
            x
        }
        for e in self.edges() {
            let (a, b) = self.edge_vertices(e);
            let (ra, rb) = (find(&mut parent, a.index()), find(&mut parent, b.index()));
            if ra != rb {
                parent[ra] = rb;
            }
        }
        let mut roots = std::collections::HashSet::new();
        for v in self.vertices() {
            if self.outgoing(v).is_some() {
                roots.insert(find(&mut parent, v.index()));
            }
        }
        let (v, e, f) = (self.vertex_count(), self.edge_count(), self.face_count());
        let isolated = self
            .vertices()
            .filter(|&v| self.outgoing(v).is_none())
            .count();
        let chi = (v - isolated) as i64 - e as i64 + f as i64;
        let c = roots.len() as i64;
        let twice = 2 * c - chi - loops as i64;
        let mut valences = BTreeMap::new();
        let mut vertex_levels = BTreeMap::new();
        for v in self.vertices() {
            *valences.entry(self.valence(v)).or_insert(0) += 1;
            *vertex_levels.entry(self.vertex_level(v)).or_insert(0) += 1;
        }
        let mut edge_levels = BTreeMap::new();
        for e in self.edges() {
            *edge_levels.entry(self.edge_level(e)).or_insert(0) += 1;
        }
        let mut face_levels = BTreeMap::new();
        for f in self.faces() {
            *face_levels.entry(self.face_level(f)).or_insert(0) += 1;
        }
        MeshInfo {
            vertices: v,
            edges: e,
            faces: f,
            quads: merged.faces.len(),
            merged_vertices: merged.positions.len(),
            boundary_loops: loops,
            components: roots.len(),
            isolated_vertices: isolated,
            euler_characteristic: chi,
            genus: (twice % 2 == 0).then_some(twice / 2),
            valences,
            vertex_levels,
            edge_levels,
            face_levels,
            sharp_edges: self.edges().filter(|&e| self.is_sharp_edge(e)).count(),
            infinitely_sharp_edges: self
                .edges()
                .filter(|&e| self.edge_sharpness(e) == f64::INFINITY)
                .count(),
            sharp_vertices: self
                .vertices()
                .filter(|&v| self.vertex_sharpness(v) > 0.0)
                .count(),
        }
    }
}

impl std::fmt::Display for MeshInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.merged_vertices == self.vertices {
            writeln!(
                f,
                "vertices {}, edges {}, faces {} (triangles; {} after merging basic blocks)",
                self.vertices, self.edges, self.faces, self.quads
            )?;
        } else {
            writeln!(
                f,
                "vertices {}, edges {}, faces {} (triangles; {} vertices and {} polygons after \
                 merging basic blocks, whose centres are left out)",
                self.vertices, self.edges, self.faces, self.merged_vertices, self.quads
            )?;
        }
        write!(
            f,
            "components {}, boundary loops {}",
            self.components, self.boundary_loops
        )?;
        if self.isolated_vertices > 0 {
            write!(
                f,
                ", isolated vertices {} (on no face; left out of χ)",
                self.isolated_vertices
            )?;
        }
        writeln!(f)?;
        match self.genus {
            Some(g) => writeln!(
                f,
                "Euler characteristic {}, genus {}",
                self.euler_characteristic, g
            )?,
            None => writeln!(f, "Euler characteristic {}", self.euler_characteristic)?,
        }
        write!(f, "valences:")?;
        for (k, n) in &self.valences {
            write!(f, " {k}:{n}")?;
        }
        writeln!(f)?;
        for (name, m) in [
            ("vertex", &self.vertex_levels),
            ("edge", &self.edge_levels),
            ("face", &self.face_levels),
        ] {
            write!(f, "{name} levels:")?;
            for (k, n) in m {
                write!(f, " {k}:{n}")?;
            }
            writeln!(f)?;
        }
        if self.sharp_edges + self.sharp_vertices > 0 {
            writeln!(
                f,
                "sharp edges {} ({} for ever), sharp vertices {}",
                self.sharp_edges, self.infinitely_sharp_edges, self.sharp_vertices
            )?;
        }
        Ok(())
    }
}
