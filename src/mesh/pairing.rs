//! Pairing triangles into basic blocks: the preprocess of paper 004, §1,
//! which turns a triangulation into a triangulated quadrangulation.
//!
//! Two triangles that share an edge form a block when that edge is made
//! the block's internal edge. Which pairs to take is a matching on the dual
//! graph (one node per triangle, one edge per interior mesh edge): a
//! maximum matching pairs as many triangles as can be. On a closed surface
//! it pairs them all, for the dual graph of a closed triangulation is cubic
//! and bridgeless (the faces around either end of an edge join its two
//! faces another way), and such a graph has a perfect matching (Petersen's
//! theorem). On a surface with boundary a triangle may be left over; each
//! left-over triangle is then moved, along an alternating path, to a
//! triangle on the boundary, whose boundary edge a grammar's `init:` rule
//! splits so that the two halves make a block.
//!
//! Pairs across an edge with an interior end of valence 3 or 4 are taken
//! only where the others cannot pair every triangle: a diagonal there
//! leaves the vertex in two quads, where the C4 scheme is not C1.
//!
//! The matching is Edmonds' blossom algorithm, one augmenting search per
//! unmatched node after a greedy start, with every search's bookkeeping
//! undone over the nodes it touched only, so that the whole runs in time
//! close to linear on meshes (each search is local).

use super::halfedge::{EdgeId, FaceId, Mesh, MeshError, VertexId};

const NONE: u32 = u32::MAX;

/// The work (node visits) one repair of a pair over an edge that is not
/// preferred may take.
const REPAIR_WORK: u64 = 20_000;

/// A graph in compressed rows: the neighbours of node `i` are
/// `adj[start[i]..start[i + 1]]`.
#[derive(Clone, Debug, Default)]
pub(crate) struct Graph {
    pub start: Vec<u32>,
    pub adj: Vec<u32>,
}

impl Graph {
    pub fn from_edges(n: usize, edges: &[(u32, u32)]) -> Graph {
        let mut start = vec![0u32; n + 1];
        for &(a, b) in edges {
            start[a as usize + 1] += 1;
            start[b as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut adj = vec![0u32; 2 * edges.len()];
        for &(a, b) in edges {
            adj[fill[a as usize] as usize] = b;
            fill[a as usize] += 1;
            adj[fill[b as usize] as usize] = a;
            fill[b as usize] += 1;
        }
        Graph { start, adj }
    }

    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    fn neighbours(&self, i: u32) -> &[u32] {
        &self.adj[self.start[i as usize] as usize..self.start[i as usize + 1] as usize]
    }
}

/// The state of Edmonds' algorithm on one graph: the matching and the
/// scratch arrays of one augmenting search, all reset after each search
/// over the nodes it touched.
struct Blossom<'g> {
    g: &'g Graph,
    mate: Vec<u32>,
    parent: Vec<u32>,
    /// Union-find over contracted blossoms: `uf` the parent pointers,
    /// `set_base` the base of the blossom at each root.
    uf: Vec<u32>,
    set_base: Vec<u32>,
    in_tree: Vec<bool>,
    in_blossom: Vec<bool>,
    on_path: Vec<bool>,
    /// Nodes of the trees of searches that failed: no augmenting path
    /// passes through them later (the tree is Hungarian: every node in it
    /// is matched within it but its root, and every edge out of it leaves
    /// an odd node), so later searches leave them out. Without this, each
    /// failed search walked the same large tree again: a triangle cut into
    /// 800^2 triangles (800 more up than down, so 800 searches that fail)
    /// took 31 s.
    dead: Vec<bool>,
    /// Whether a failed search marks its tree `dead`: not where the
    /// matching changes other than by augmenting (the repairs of
    /// `maximum_matching` undo a pair and may put it back).
    remember_failures: bool,
    touched: Vec<u32>,
    queue: Vec<u32>,
    /// Nodes at and above this are not part of the graph (yet).
    limit: u32,
    /// The run's deadline: a search past it ends as one out of budget.
    deadline: Option<crate::Deadline>,
    ticks: u32,
}

impl<'g> Blossom<'g> {
    fn new(g: &'g Graph, mate: Vec<u32>) -> Blossom<'g> {
        let n = g.len();
        Blossom {
            g,
            mate,
            parent: vec![NONE; n],
            uf: (0..n as u32).collect(),
            set_base: (0..n as u32).collect(),
            in_tree: vec![false; n],
            in_blossom: vec![false; n],
            on_path: vec![false; n],
            dead: vec![false; n],
            remember_failures: true,
            touched: Vec::new(),
            queue: Vec::new(),
            limit: n as u32,
            deadline: crate::deadline::current(),
            ticks: 0,
        }
    }

    fn touch(&mut self, v: u32) {
        self.touched.push(v);
    }

    fn find(&mut self, mut x: u32) -> u32 {
        let mut r = x;
        while self.uf[r as usize] != r {
            r = self.uf[r as usize];
        }
        while self.uf[x as usize] != r {
            let next = self.uf[x as usize];
            self.uf[x as usize] = r;
            x = next;
        }
        r
    }

    /// The base of the blossom `x` is in (`x` itself outside blossoms).
    fn base(&mut self, x: u32) -> u32 {
        let r = self.find(x);
        self.set_base[r as usize]
    }

    /// The base of the blossom that the tree paths from `a` and `b` meet in.
    fn common_base(&mut self, mut a: u32, mut b: u32) -> u32 {
        let mut marked = Vec::new();
        loop {
            a = self.base(a);
            self.on_path[a as usize] = true;
            marked.push(a);
            if self.mate[a as usize] == NONE {
                break;
            }
            a = self.parent[self.mate[a as usize] as usize];
        }
        let found = loop {
            b = self.base(b);
            if self.on_path[b as usize] {
                break b;
            }
            b = self.parent[self.mate[b as usize] as usize];
        };
        for m in marked {
            self.on_path[m as usize] = false;
        }
        found
    }

    /// Marks the blossom's bases on the path from `v` down to `b`, points
    /// the odd nodes on it back across the blossom's closing edge, and
    /// lists those not yet in the tree (they become even).
    fn mark_path(
        &mut self,
        mut v: u32,
        b: u32,
        mut child: u32,
        marked: &mut Vec<u32>,
        odd: &mut Vec<u32>,
    ) {
        while self.base(v) != b {
            let m = self.mate[v as usize];
            if !self.in_tree[m as usize] {
                odd.push(m);
            }
            for x in [self.base(v), self.base(m)] {
                if !self.in_blossom[x as usize] {
                    self.in_blossom[x as usize] = true;
                    marked.push(x);
                }
            }
            self.parent[v as usize] = child;
            child = m;
            v = self.parent[m as usize];
        }
    }

    /// An augmenting path from the free node `root`: its other end, with
    /// `parent` and `mate` describing the path, or None. `budget` bounds the
    /// work (node visits); a search that runs out gives None.
    fn search(&mut self, root: u32, budget: &mut u64) -> Option<u32> {
        let g = self.g;
        self.queue.clear();
        self.in_tree[root as usize] = true;
        self.touch(root);
        self.queue.push(root);
        let mut head = 0;
        while head < self.queue.len() {
            let v = self.queue[head];
            head += 1;
            for &to in g.neighbours(v) {
                if *budget == 0 {
                    return None;
                }
                *budget -= 1;
                self.ticks = self.ticks.wrapping_add(1);
                if self.ticks.is_multiple_of(1 << 14) && self.deadline.is_some_and(|d| d.passed()) {
                    // Past the deadline: every search from here on ends.
                    *budget = 0;
                    return None;
                }
                if to >= self.limit || self.dead[to as usize] {
                    continue;
                }
                if self.mate[v as usize] == to || self.base(v) == self.base(to) {
                    continue;
                }
                let to_mate = self.mate[to as usize];
                if to == root || (to_mate != NONE && self.parent[to_mate as usize] != NONE) {
                    // An odd cycle: contract it into its base. Its odd
                    // nodes outside the tree are the only nodes it brings
                    // in; the rest are in the tree already.
                    let b = self.common_base(v, to);
                    let (mut marked, mut odd) = (Vec::new(), Vec::new());
                    self.mark_path(v, b, to, &mut marked, &mut odd);
                    self.mark_path(to, b, v, &mut marked, &mut odd);
                    let rb = self.find(b);
                    for &x in &marked {
                        let r = self.find(x);
                        if r != rb {
                            self.uf[r as usize] = rb;
                        }
                        self.in_blossom[x as usize] = false;
                    }
                    self.set_base[rb as usize] = b;
                    *budget = budget.saturating_sub(marked.len() as u64);
                    for m in odd {
                        if !self.in_tree[m as usize] {
                            self.in_tree[m as usize] = true;
                            self.queue.push(m);
                        }
                    }
                } else if self.parent[to as usize] == NONE {
                    self.parent[to as usize] = v;
                    self.touch(to);
                    if to_mate == NONE {
                        return Some(to);
                    }
                    self.in_tree[to_mate as usize] = true;
                    self.touch(to_mate);
                    self.queue.push(to_mate);
                }
            }
        }
        None
    }

    fn augment(&mut self, mut v: u32) {
        while v != NONE {
            let pv = self.parent[v as usize];
            let next = self.mate[pv as usize];
            self.mate[v as usize] = pv;
            self.mate[pv as usize] = v;
            v = next;
        }
    }

    fn reset(&mut self) {
        for &i in &self.touched {
            self.parent[i as usize] = NONE;
            self.uf[i as usize] = i;
            self.set_base[i as usize] = i;
            self.in_tree[i as usize] = false;
        }
        self.touched.clear();
    }

    /// Searches from `root` and augments along what it finds.
    fn grow(&mut self, root: u32, budget: &mut u64) -> bool {
        let end = self.search(root, budget);
        if let Some(end) = end {
            self.augment(end);
        } else if *budget > 0 && self.remember_failures {
            // A whole search failed (not one cut short by the budget).
            for &i in &self.touched {
                self.dead[i as usize] = true;
            }
        }
        self.reset();
        end.is_some()
    }
}

/// A greedy matching, nodes of fewest free neighbours first (on meshes it
/// leaves few nodes for the augmenting searches).
fn greedy(g: &Graph, eligible: impl Fn(u32) -> bool) -> Vec<u32> {
    let n = g.len();
    let mut mate = vec![NONE; n];
    let mut free_deg: Vec<u32> = (0..n as u32)
        .map(|i| g.neighbours(i).iter().filter(|&&j| eligible(j)).count() as u32)
        .collect();
    // Buckets by free degree (at most the largest degree).
    let max_deg = free_deg.iter().copied().max().unwrap_or(0) as usize;
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); max_deg + 1];
    for i in (0..n as u32).rev() {
        if eligible(i) {
            buckets[free_deg[i as usize] as usize].push(i);
        }
    }
    let mut d = 0;
    loop {
        while d <= max_deg && buckets[d].is_empty() {
            d += 1;
        }
        if d > max_deg {
            break;
        }
        let i = buckets[d].pop().expect("non-empty bucket");
        if mate[i as usize] != NONE || free_deg[i as usize] as usize != d {
            continue; // matched meanwhile, or a stale entry
        }
        let pick = g
            .neighbours(i)
            .iter()
            .copied()
            .filter(|&j| eligible(j) && mate[j as usize] == NONE)
            .min_by_key(|&j| free_deg[j as usize]);
        let Some(j) = pick else { continue };
        mate[i as usize] = j;
        mate[j as usize] = i;
        for k in [i, j] {
            for &w in g.neighbours(k) {
                if eligible(w) && mate[w as usize] == NONE && free_deg[w as usize] > 0 {
                    free_deg[w as usize] -= 1;
                    let nd = free_deg[w as usize] as usize;
                    buckets[nd].push(w);
                    d = d.min(nd);
                }
            }
        }
    }
    mate
}

/// A maximum matching of the nodes `0..real` of `g`, then augmenting paths
/// from the nodes left free to the free nodes at and above `real` (the
/// boundary's stand-ins): `mate[i]` for each node, `u32::MAX` where free.
/// The matching starts as a maximum one of `preferred` (a graph on the
/// same nodes with some of `g`'s edges), so that `g`'s other edges are
/// taken only where the preferred ones cannot pair the nodes. `budget`
/// bounds the total work; a search that runs out leaves its node free.
pub(crate) fn maximum_matching(
    g: &Graph,
    preferred: &Graph,
    real: usize,
    budget: &mut u64,
) -> Vec<u32> {
    let mut mate = greedy(preferred, |i| (i as usize) < real);
    // Real pairs first, over the preferred edges, then over all.
    for graph in [preferred, g] {
        let mut b = Blossom::new(graph, mate);
        b.limit = real as u32;
        for i in 0..real as u32 {
            if b.mate[i as usize] == NONE {
                b.grow(i, budget);
            }
        }
        mate = b.mate;
    }
    // Each pair over an edge that is not preferred: undone, and kept only
    // where no alternating path over preferred edges pairs its two nodes
    // otherwise (matched pairs are followed through `mate`, so the search
    // may cross other such pairs but never makes one).
    let mut b = Blossom::new(preferred, mate);
    b.limit = real as u32;
    b.remember_failures = false;
    for i in 0..real as u32 {
        let m = b.mate[i as usize];
        if m == NONE || m < i || preferred.neighbours(i).contains(&m) {
            continue;
        }
        b.mate[i as usize] = NONE;
        b.mate[m as usize] = NONE;
        // A repair is local or not at all: a search that walks far is
        // given up, and the pair kept.
        let mut local = REPAIR_WORK.min(*budget);
        let found = b.grow(i, &mut local);
        *budget -= REPAIR_WORK.min(*budget) - local;
        if !found {
            b.mate[i as usize] = m;
            b.mate[m as usize] = i;
        }
    }
    mate = b.mate;
    // Then the stand-ins, for what the triangles left.
    if g.len() > real {
        let mut b = Blossom::new(g, mate);
        for i in 0..real as u32 {
            if b.mate[i as usize] == NONE {
                b.grow(i, budget);
            }
        }
        mate = b.mate;
    }
    mate
}

/// The matchings [`Mesh::match_blocks`] tries, each preferring edges
/// chosen from the one before.
const PASSES: usize = 3;

/// The interior vertices that a pairing may leave in fewer than 3 blocks
/// (valence 3 or 4), and which of their edges a pairing may take as a
/// block's internal edge: none at valence 3; at valence 4 none at first,
/// then two that share a face (`pick`: the first of them, in the order
/// of [`Mesh::outgoing_halfedges`]).
struct Few {
    /// Per vertex slot: 0 not low (boundary or valence 5 or more), else
    /// its valence; `u8::MAX` not yet known.
    low: Vec<u8>,
    pick: std::collections::HashMap<VertexId, usize>,
}

impl Few {
    fn new(m: &Mesh) -> Few {
        let slots = m.vertices().map(|v| v.index() + 1).max().unwrap_or(0);
        Few {
            low: vec![u8::MAX; slots],
            pick: std::collections::HashMap::new(),
        }
    }

    /// 3 or 4 for an interior vertex of that valence, else 0; once a
    /// vertex (a fan's centre has thousands of edges).
    fn low(&mut self, m: &Mesh, v: VertexId) -> u8 {
        let l = &mut self.low[v.index()];
        if *l == u8::MAX {
            *l = if m.is_boundary_vertex(v) {
                0
            } else {
                // Stops counting at 5: a fan's centre is not walked whole.
                match m.outgoing_halfedges(v).take(5).count() {
                    d @ (3 | 4) => d as u8,
                    _ => 0,
                }
            };
        }
        *l
    }

    /// Whether `e` may be an internal edge as far as its ends go.
    fn allowed(&mut self, m: &Mesh, e: EdgeId) -> bool {
        let (p, q) = m.edge_vertices(e);
        [p, q].into_iter().all(|v| match self.low(m, v) {
            0 => true,
            3 => false,
            _ => self.pick.get(&v).is_some_and(|&i| {
                let ring: Vec<EdgeId> = m.outgoing_halfedges(v).map(|h| h.edge()).collect();
                ring[i] == e || ring[(i + 1) % ring.len()] == e
            }),
        })
    }

    /// The vertices left in fewer than 3 blocks when `taken` become
    /// internal edges (with the blocks the mesh has already).
    fn count(&mut self, m: &Mesh, taken: &[EdgeId]) -> usize {
        let mut diagonals: std::collections::HashMap<VertexId, usize> =
            std::collections::HashMap::new();
        let lows: Vec<VertexId> = taken
            .iter()
            .flat_map(|&e| {
                let (p, q) = m.edge_vertices(e);
                [p, q]
            })
            .filter(|&v| self.low(m, v) != 0)
            .collect();
        for v in lows {
            *diagonals.entry(v).or_default() += 1;
        }
        diagonals
            .into_iter()
            .filter(|&(v, j)| {
                let old = m
                    .outgoing_halfedges(v)
                    .filter(|h| m.is_block_edge(h.edge()))
                    .count();
                (self.low(m, v) as usize) < 3 + j + old
            })
            .count()
    }

    /// At each vertex of valence 4, allows the edge `taken` has there (the
    /// first, where two are) and the next one.
    fn follow(&mut self, m: &Mesh, taken: &[EdgeId]) {
        for &e in taken {
            let (p, q) = m.edge_vertices(e);
            for v in [p, q] {
                if self.low(m, v) == 4 {
                    let i = m
                        .outgoing_halfedges(v)
                        .position(|h| h.edge() == e)
                        .expect("an edge at its end");
                    self.pick.entry(v).or_insert(i);
                }
            }
        }
    }
}

/// What [`Mesh::match_blocks`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Pairing {
    /// Blocks made of two triangles.
    pub pairs: usize,
    /// Triangles left alone on the boundary, for a boundary split.
    pub on_boundary: usize,
    /// Interior vertices the matching left in two blocks, whose two quads
    /// were cut into five (each adds 3 vertices and 3 blocks; see
    /// `mesh/two_blocks.rs`).
    pub split: usize,
}

impl Mesh {
    /// Pairs every triangle that is in no basic block with a neighbour, so
    /// that the mesh becomes a tri-quad mesh (paper 004, §1): a maximum
    /// matching of the dual graph; a triangle left over is moved along an
    /// alternating path to the boundary, where it is left for a boundary
    /// split (see the module's comment). Original vertices and positions
    /// stay; on a base mesh (all vertices at level 0) the levels become
    /// those of a tri-quad mesh (internal edges 0, the others 1).
    ///
    /// Two triangles across a sharp edge are never paired (the edge would
    /// become a quad's diagonal).
    ///
    /// An error, with the mesh unchanged, when an interior triangle cannot
    /// be paired or `budget` runs out.
    pub fn match_blocks(&mut self, budget: u64) -> Result<Pairing, MeshError> {
        let slots = self.f_alive.len();
        let lone = |m: &Mesh, f: FaceId| !m.face_edges(f).iter().any(|&e| m.is_block_edge(e));
        // Nodes: the lone faces, then one stand-in per boundary edge of a
        // lone face.
        let mut node_of = vec![NONE; slots];
        let mut faces: Vec<FaceId> = Vec::new();
        for f in self.faces() {
            if lone(self, f) {
                node_of[f.index()] = faces.len() as u32;
                faces.push(f);
            }
        }
        let real = faces.len();
        let mut links: Vec<(u32, u32)> = Vec::new();
        let mut via: Vec<EdgeId> = Vec::new();
        let mut stand_ins: Vec<EdgeId> = Vec::new();
        for e in self.edges() {
            match self.edge_faces(e) {
                // Never across a crease: a sharp edge made a block's
                // internal edge would be a quad's diagonal, which the
                // crease rules (and the mesh files) do not have.
                [Some(_), Some(_)] if self.is_sharp_edge(e) => {}
                [Some(a), Some(b)] => {
                    let (na, nb) = (node_of[a.index()], node_of[b.index()]);
                    if na != NONE && nb != NONE && a != b {
                        links.push((na, nb));
                        via.push(e);
                    }
                }
                [Some(a), None] | [None, Some(a)] => {
                    let na = node_of[a.index()];
                    if na != NONE {
                        links.push((na, (real + stand_ins.len()) as u32));
                        via.push(e);
                        stand_ins.push(e);
                    }
                }
                [None, None] => {}
            }
        }
        let g = Graph::from_edges(real + stand_ins.len(), &links);
        // Preferred pairs: those that leave every interior vertex in 3
        // blocks or more (`Few`). A vertex of valence d in j blocks'
        // internal edges is in d - j blocks; C4 needs 3 (k = 2 in
        // c4.lsys's terms, a vertex in two quads, is not C1: its
        // subdominant eigenvalue 1/4 is not above the next one; see
        // tests/it/surface_c4.rs). A vertex of valence 5 or more is in 3
        // at least whatever is paired (each internal edge at it takes two
        // of its faces); one of valence 3 may have no internal edge, and
        // one of valence 4 at most one. The first matching prefers no edge
        // at either; the next ones allow two edges at each vertex of
        // valence 4 that share a face (so at most one is taken), the two
        // at the edge the matching before took there, and keep the
        // matching that leaves the fewest vertices in two blocks.
        let mut few = Few::new(self);
        let mut left = budget;
        let mut best: Option<(usize, Vec<u32>)> = None;
        for pass in 0..PASSES {
            let preferred: Vec<(u32, u32)> = links
                .iter()
                .zip(&via)
                .filter(|&(&(_, b), &e)| (b as usize) < real && few.allowed(self, e))
                .map(|(&l, _)| l)
                .collect();
            let preferred = Graph::from_edges(real + stand_ins.len(), &preferred);
            let mate = maximum_matching(&g, &preferred, real, &mut left);
            if left == 0 || crate::deadline::current().is_some_and(|d| d.passed()) {
                best = Some((0, mate));
                break;
            }
            let taken: Vec<EdgeId> = links
                .iter()
                .zip(&via)
                .filter(|&(&(a, b), _)| (b as usize) < real && mate[a as usize] == b)
                .map(|(_, &e)| e)
                .collect();
            let bad = few.count(self, &taken);
            if best.as_ref().is_none_or(|(b, _)| bad < *b) {
                best = Some((bad, mate));
            }
            if bad == 0 || pass + 1 == PASSES {
                break;
            }
            few.follow(self, &taken);
        }
        let (_, mate) = best.expect("one pass at least");
        if let Some(d) = crate::deadline::current().filter(|d| d.passed()) {
            return Err(MeshError::new(format!(
                "pairing triangles into blocks: {}",
                d.message()
            )));
        }
        if left == 0 {
            return Err(MeshError::new(format!(
                "pairing triangles into blocks: the search for a maximum matching of {real} triangles \
                 ran past its work limit"
            )));
        }
        // The mesh edge between each matched pair.
        let mut pairs = Vec::new();
        let mut on_boundary = 0;
        for (k, &(a, b)) in links.iter().enumerate() {
            if mate[a as usize] == b && (b as usize) < real {
                pairs.push(via[k]);
            } else if mate[a as usize] == b {
                on_boundary += 1;
            }
        }
        if let Some(i) = (0..real).find(|&i| mate[i] == NONE) {
            let [a, b, c] = self.face_vertices(faces[i]);
            let creases = if self.has_sharpness_flag() {
                " (no pair is made across a sharp edge)"
            } else {
                ""
            };
            return Err(MeshError::new(format!(
                "pairing triangles into blocks: the triangle on vertices {a}, {b} and {c} cannot be \
                 paired with a neighbour, nor moved to the boundary along an alternating path{creases}"
            )));
        }
        let base = self.vertices().all(|v| self.vertex_level(v) == 0);
        // The fans' triangles are paired like any others: no polygon is
        // taken whole any more.
        self.fans.clear();
        self.fan_of.clear();
        for &e in &pairs {
            self.e_block.set(e.index(), true);
        }
        // What the matching left in two blocks, cut into three (a base
        // mesh's: the cut rebuilds it).
        let split = if base {
            self.split_two_block_vertices().inspect_err(|_| {
                for &e in &pairs {
                    self.e_block.set(e.index(), false);
                }
            })?
        } else {
            0
        };
        if base {
            let edges: Vec<EdgeId> = self.edges().collect();
            for e in edges {
                self.e_level
                    .set(e.index(), if self.e_block.get(e.index()) { 0 } else { 1 });
            }
        }
        Ok(Pairing {
            pairs: pairs.len() + 3 * split,
            on_boundary,
            split,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small linear congruential generator: the random graphs are fixed.
    fn lcg(seed: u64) -> impl FnMut() -> u32 {
        let mut s = seed;
        move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 33) as u32
        }
    }

    /// The size of a maximum matching by trying every subset of edges
    /// (small graphs only): the reference.
    fn brute_force(n: usize, edges: &[(u32, u32)]) -> usize {
        let mut best = 0;
        for mask in 0u32..(1 << edges.len()) {
            let mut used = vec![false; n];
            let mut ok = true;
            let mut k = 0;
            for (i, &(a, b)) in edges.iter().enumerate() {
                if mask >> i & 1 == 1 {
                    if used[a as usize] || used[b as usize] {
                        ok = false;
                        break;
                    }
                    used[a as usize] = true;
                    used[b as usize] = true;
                    k += 1;
                }
            }
            if ok {
                best = best.max(k);
            }
        }
        best
    }

    fn check(n: usize, edges: &[(u32, u32)]) -> usize {
        let g = Graph::from_edges(n, edges);
        let mut budget = u64::MAX;
        let mate = maximum_matching(&g, &g, n, &mut budget);
        // A matching: symmetric, along edges.
        for (i, &m) in mate.iter().enumerate() {
            if m != NONE {
                assert_eq!(mate[m as usize], i as u32);
                assert!(edges.contains(&(i as u32, m)) || edges.contains(&(m, i as u32)));
            }
        }
        mate.iter().filter(|&&m| m != NONE).count() / 2
    }

    #[test]
    fn odd_cycles_need_blossoms() {
        // Two triangles joined by a path, the classic case where a search
        // without contraction fails: 0-1-2-0, 2-3, 3-4, 4-5-6-4 plus a
        // pendant 7 on 0 and 8 on 6.
        let edges = [
            (0, 1),
            (1, 2),
            (2, 0),
            (2, 3),
            (3, 4),
            (4, 5),
            (5, 6),
            (6, 4),
            (0, 7),
            (6, 8),
        ];
        assert_eq!(check(9, &edges), brute_force(9, &edges));
    }

    #[test]
    fn petersen_graph_has_a_perfect_matching() {
        let mut edges = Vec::new();
        for i in 0..5u32 {
            edges.push((i, (i + 1) % 5));
            edges.push((i, i + 5));
            edges.push((5 + i, 5 + (i + 2) % 5));
        }
        assert_eq!(check(10, &edges), 5);
    }

    #[test]
    fn random_graphs_match_brute_force() {
        let mut next = lcg(12345);
        for _ in 0..300 {
            let n = 2 + (next() % 9) as usize;
            let mut edges = Vec::new();
            for a in 0..n as u32 {
                for b in a + 1..n as u32 {
                    if next().is_multiple_of(3) && edges.len() < 16 {
                        edges.push((a, b));
                    }
                }
            }
            assert_eq!(check(n, &edges), brute_force(n, &edges), "{edges:?}");
        }
    }

    #[test]
    fn preferred_edges_win_where_they_can() {
        // A 4-cycle 0-1-2-3-0 has two perfect matchings; with 0-1 and 2-3
        // preferred, those are taken, whatever the greedy start would do.
        let edges = [(0, 1), (1, 2), (2, 3), (3, 0)];
        let g = Graph::from_edges(4, &edges);
        for pref in [[(0, 1), (2, 3)], [(1, 2), (3, 0)]] {
            let p = Graph::from_edges(4, &pref);
            let mut budget = u64::MAX;
            let mate = maximum_matching(&g, &p, 4, &mut budget);
            for (a, b) in pref {
                assert_eq!(mate[a as usize], b);
            }
        }
        // Where the preferred edges cannot pair everything, the others do:
        // a path 0-1-2-3 with only 1-2 preferred pairs 0-1 and 2-3.
        let g = Graph::from_edges(4, &[(0, 1), (1, 2), (2, 3)]);
        let p = Graph::from_edges(4, &[(1, 2)]);
        let mut budget = u64::MAX;
        let mate = maximum_matching(&g, &p, 4, &mut budget);
        assert_eq!((mate[0], mate[2]), (1, 3));
    }

    #[test]
    fn stand_ins_take_only_what_real_pairs_leave() {
        // A path 0-1-2 of real nodes, with stand-in 3 on node 2 and 4 on 0:
        // one real pair, and the third node goes to its stand-in.
        let edges = [(0, 1), (1, 2), (2, 3), (0, 4)];
        let g = Graph::from_edges(5, &edges);
        let mut budget = u64::MAX;
        let mate = maximum_matching(&g, &g, 3, &mut budget);
        let real_pairs = (0..3).filter(|&i| mate[i] != NONE && mate[i] < 3).count() / 2;
        assert_eq!(real_pairs, 1);
        assert!((0..3).all(|i| mate[i] != NONE));
    }

    /// The size of a maximum matching by dynamic programming over subsets
    /// of nodes (the lowest node of a subset is either left free or
    /// matched with a neighbour in the subset): a reference for graphs of
    /// up to 20 nodes, with no limit on the number of edges.
    fn by_subsets(n: usize, edges: &[(u32, u32)]) -> usize {
        covering_by_subsets(n, edges, &vec![false; n]) / 2
    }

    #[test]
    fn larger_random_graphs_match_the_subset_reference() {
        // Graphs of 6 to 18 nodes, sparse to dense, many with odd cycles
        // nested in one another: blossoms inside blossoms.
        let mut next = lcg(987654321);
        for round in 0..1500 {
            let n = 6 + (next() % 13) as usize;
            let p = 2 + round % 6; // an edge with probability 1/p
            let mut edges = Vec::new();
            for a in 0..n as u32 {
                for b in a + 1..n as u32 {
                    if next().is_multiple_of(p as u32) {
                        edges.push((a, b));
                    }
                }
            }
            // Shuffle the node numbers' order of search by shuffling edges.
            for i in (1..edges.len()).rev() {
                let j = next() as usize % (i + 1);
                edges.swap(i, j);
            }
            assert_eq!(check(n, &edges), by_subsets(n, &edges), "n {n}: {edges:?}");
        }
    }

    /// The most real nodes a matching can cover when node `i` may also be
    /// matched with a stand-in of its own (`has_stand_in[i]`): the same
    /// subset recursion, the lowest node left free, matched with its
    /// stand-in (one node covered) or with a neighbour (two).
    fn covering_by_subsets(n: usize, edges: &[(u32, u32)], has_stand_in: &[bool]) -> usize {
        let mut nb = vec![0u32; n];
        for &(a, b) in edges {
            nb[a as usize] |= 1 << b;
            nb[b as usize] |= 1 << a;
        }
        let mut best = vec![0u8; 1 << n];
        for mask in 1usize..1 << n {
            let i = mask.trailing_zeros() as usize;
            let rest = mask & !(1 << i);
            let mut b = best[rest] + has_stand_in[i] as u8;
            let mut cand = nb[i] as usize & rest;
            while cand != 0 {
                let j = cand.trailing_zeros() as usize;
                cand &= cand - 1;
                b = b.max(2 + best[rest & !(1 << j)]);
            }
            best[mask] = b;
        }
        best[(1 << n) - 1] as usize
    }

    #[test]
    fn stand_ins_cover_as_many_real_nodes_as_can_be() {
        // Random graphs with real nodes 0..r and stand-ins r..n, each
        // stand-in on one real node (a boundary edge) and at most one per
        // real node: the pairing must keep a maximum matching among the
        // real nodes and, besides, cover as many real nodes as any matching
        // can (reference: `covering_by_subsets`).
        let mut next = lcg(55555);
        for round in 0..1500 {
            let r = 3 + (next() % 11) as usize;
            let p = 2 + round % 5;
            let mut edges = Vec::new();
            for a in 0..r as u32 {
                for b in a + 1..r as u32 {
                    if next().is_multiple_of(p as u32) {
                        edges.push((a, b));
                    }
                }
            }
            let real_edges = edges.clone();
            let mut n = r;
            for a in 0..r as u32 {
                if next().is_multiple_of(4) {
                    edges.push((a, n as u32));
                    n += 1;
                }
            }
            let g = Graph::from_edges(n, &edges);
            let mut budget = u64::MAX;
            let mate = maximum_matching(&g, &g, r, &mut budget);
            for (i, &m) in mate.iter().enumerate() {
                if m != NONE {
                    assert_eq!(mate[m as usize], i as u32);
                    assert!(edges.contains(&(i as u32, m)) || edges.contains(&(m, i as u32)));
                }
            }
            let rr = (0..r)
                .filter(|&i| mate[i] != NONE && (mate[i] as usize) < r)
                .count()
                / 2;
            let covered = (0..r).filter(|&i| mate[i] != NONE).count();
            let best_rr = by_subsets(r, &real_edges);
            assert_eq!(rr, best_rr, "{edges:?}");
            let has_stand_in: Vec<bool> = (0..r as u32)
                .map(|a| edges.iter().any(|&(x, y)| x == a && y as usize >= r))
                .collect();
            let best_cover = covering_by_subsets(r, &real_edges, &has_stand_in);
            assert_eq!(covered, best_cover, "r {r}: {edges:?}");
        }
    }

    /// The dual graph of a triangle cut into k^2 triangles: k(k+1)/2 up
    /// and k(k-1)/2 down, each down triangle beside three up ones. It is
    /// bipartite with k more up nodes, so a maximum matching pairs every
    /// down triangle and leaves k up ones: k searches that fail.
    fn cut_triangle(k: u32) -> (usize, Vec<(u32, u32)>) {
        let up = |i: u32, j: u32| {
            // Row i holds k - i up triangles.
            (0..i).map(|r| k - r).sum::<u32>() + j
        };
        let ups = k * (k + 1) / 2;
        let mut edges = Vec::new();
        let mut down = ups;
        for i in 0..k {
            for j in 0..k - i {
                if i + j + 1 < k {
                    edges.push((down, up(i, j)));
                    edges.push((down, up(i + 1, j)));
                    edges.push((down, up(i, j + 1)));
                    down += 1;
                }
            }
        }
        (down as usize, edges)
    }

    #[test]
    fn failed_searches_are_not_walked_again() {
        let k = 120;
        let (n, edges) = cut_triangle(k);
        assert_eq!(n as u32, k * k);
        let g = Graph::from_edges(n, &edges);
        let start = u64::MAX;
        let mut budget = start;
        let mate = maximum_matching(&g, &g, n, &mut budget);
        let matched = mate.iter().filter(|&&m| m != NONE).count() / 2;
        assert_eq!(
            matched as u32,
            k * (k - 1) / 2,
            "every down triangle paired"
        );
        // The work: a few visits per edge end, not one walk of the graph
        // per failed search (120 of them, 2 * 21,420 edge ends each).
        let used = start - budget;
        assert!(used < 20 * 2 * edges.len() as u64, "{used} visits");
    }
}
