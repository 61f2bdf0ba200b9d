//! Phase 2: the waiting shapes' smoothing groups, each welded,
//! subdivided and its slices handed back to its shapes, whose successors
//! then run.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use crate::shape::geom::{self, Geometry};
use crate::shape::smooth;
use crate::syntax::span::Span;

use super::tree::{tree_order, GroupReport, Node, State};
use super::{mix, random_of, smooth_scheme, Cur, Deriver, ShapeError, R};

impl<'g> Deriver<'g> {
    /// Phase 2: every smoothing group of the waiting shapes, subdivided.
    pub(super) fn smooth_all(&mut self) -> R<()> {
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
