//! The unit tests of the rotation-system mesh: Table 2 with its notes,
//! properties, synchronize, the steady state, and Edmonds' technique.

use super::*;
use crate::mesh::shapes::{icosphere, quad_grid};
use crate::mesh::PolygonSoup;

/// A system of `n` vertices with no neighbours.
fn vertices(n: usize) -> (Rotation, Vec<u32>) {
    let mut r = Rotation::new();
    let vs = (0..n).map(|_| r.new_vertex()).collect();
    (r, vs)
}

fn nbs(r: &Rotation, v: u32) -> Vec<u32> {
    r.neighbours(v, false).unwrap().to_vec()
}

/// A polygon rotated to start at its smallest vertex.
fn canonical(f: &[u32]) -> Vec<u32> {
    let k = (0..f.len()).min_by_key(|&k| f[k]).unwrap();
    f[k..].iter().chain(&f[..k]).copied().collect()
}

fn canonical_faces<F: AsRef<[u32]>>(faces: impl IntoIterator<Item = F>) -> Vec<Vec<u32>> {
    let mut out: Vec<Vec<u32>> = faces.into_iter().map(|f| canonical(f.as_ref())).collect();
    out.sort();
    out
}

/// The number of undirected edges: half the directed ones.
fn edge_count(r: &Rotation, set: &[u32]) -> usize {
    set.iter()
        .map(|&v| r.valence(v, false).unwrap())
        .sum::<usize>()
        / 2
}

/// Newell's normal of a polygon.
fn normal(r: &Rotation, f: &[u32]) -> DVec3 {
    let p = |k: usize| r.pos(f[k % f.len()], false).unwrap();
    (0..f.len()).map(|k| p(k).cross(p(k + 1))).sum()
}

fn centroid(r: &Rotation, f: &[u32]) -> DVec3 {
    f.iter().map(|&v| r.pos(v, false).unwrap()).sum::<DVec3>() / f.len() as f64
}

/// Every face's normal points away from `centre`: the faces run
/// counter-clockwise seen from the outside.
fn assert_outward(r: &Rotation, faces: &[Vec<u32>], centre: DVec3) {
    for f in faces {
        assert!(
            normal(r, f).dot(centroid(r, f) - centre) > 0.0,
            "face {f:?} runs clockwise"
        );
    }
}

fn cube() -> PolygonSoup {
    let positions = [
        (0., 0., 0.),
        (1., 0., 0.),
        (1., 1., 0.),
        (0., 1., 0.),
        (0., 0., 1.),
        (1., 0., 1.),
        (1., 1., 1.),
        (0., 1., 1.),
    ];
    PolygonSoup {
        positions: positions
            .iter()
            .map(|&(x, y, z)| DVec3::new(x, y, z))
            .collect(),
        // Bottom, top, y = 0, y = 1, x = 0, x = 1; outward normals are
        // checked by `assert_outward`.
        faces: vec![
            vec![0, 3, 2, 1],
            vec![4, 5, 6, 7],
            vec![0, 1, 5, 4],
            vec![2, 3, 7, 6],
            vec![0, 4, 7, 3],
            vec![1, 2, 6, 5],
        ]
        .into(),
        ..Default::default()
    }
}

fn octahedron() -> PolygonSoup {
    // 0 = +x, 1 = -x, 2 = +y, 3 = -y, 4 = +z, 5 = -z; one triangle per
    // octant, (x, y, z) turned over where an odd number of signs is
    // negative (a reflection reverses orientation).
    let positions = vec![
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ];
    let mut faces = Vec::new();
    for sx in 0..2u32 {
        for sy in 0..2u32 {
            for sz in 0..2u32 {
                let (x, y, z) = (sx, 2 + sy, 4 + sz);
                faces.push(if (sx + sy + sz) % 2 == 0 {
                    vec![x, y, z]
                } else {
                    vec![x, z, y]
                });
            }
        }
    }
    PolygonSoup {
        positions,
        faces: faces.into(),
        ..Default::default()
    }
}

// ----- Table 2: queries and selection -------------------------------

#[test]
fn queries_and_selection_on_a_closed_neighbourhood() {
    let (mut r, v) = vertices(5);
    r.make(v[0], &[v[1], v[2], v[3]]).unwrap();
    assert_eq!(r.valence(v[0], false), Ok(3));
    assert_eq!(r.is_in(v[2], v[0], false), Ok(true));
    assert_eq!(r.is_in(v[4], v[0], false), Ok(false));
    assert_eq!(r.is_in(NULL, v[0], false), Ok(false));
    assert_eq!(r.any(v[0], false), Ok(v[1]));
    assert_eq!(r.is_open(v[0], false), Ok(false));
    // Cyclic: after the last comes the first, before the first the last.
    assert_eq!(r.nextto(v[1], v[0], false), Ok(v[2]));
    assert_eq!(r.nextto(v[3], v[0], false), Ok(v[1]));
    assert_eq!(r.prevto(v[1], v[0], false), Ok(v[3]));
    assert_eq!(r.prevto(v[3], v[0], false), Ok(v[2]));
    // Note 2: the null vertex for a vertex not in the neighbourhood.
    assert_eq!(r.nextto(v[4], v[0], false), Ok(NULL));
    assert_eq!(r.prevto(v[4], v[0], false), Ok(NULL));
    assert_eq!(r.nextto(NULL, v[0], false), Ok(NULL));
    // Note 1: the null vertex from an empty neighbourhood.
    assert_eq!(r.any(v[4], false), Ok(NULL));
    assert_eq!(r.valence(v[4], false), Ok(0));
}

#[test]
fn a_single_neighbour_follows_and_precedes_itself() {
    let (mut r, v) = vertices(2);
    r.make(v[0], &[v[1]]).unwrap();
    assert_eq!(r.nextto(v[1], v[0], false), Ok(v[1]));
    assert_eq!(r.prevto(v[1], v[0], false), Ok(v[1]));
}

#[test]
fn selection_on_an_open_neighbourhood_stops_at_the_gap() {
    let (mut r, v) = vertices(4);
    // `{p, NULL, q, r}`: the gap lies between p and q, so the open list
    // runs q, r, p.
    r.make(v[0], &[v[1], NULL, v[2], v[3]]).unwrap();
    assert_eq!(nbs(&r, v[0]), [v[2], v[3], v[1]]);
    assert_eq!(r.is_open(v[0], false), Ok(true));
    assert_eq!(r.any(v[0], false), Ok(v[2]));
    assert_eq!(r.nextto(v[2], v[0], false), Ok(v[3]));
    assert_eq!(r.nextto(v[3], v[0], false), Ok(v[1]));
    assert_eq!(
        r.nextto(v[1], v[0], false),
        Ok(NULL),
        "last: the gap follows"
    );
    assert_eq!(
        r.prevto(v[2], v[0], false),
        Ok(NULL),
        "first: the gap precedes"
    );
    assert_eq!(r.prevto(v[1], v[0], false), Ok(v[3]));
}

// ----- make (note 3) --------------------------------------------------

#[test]
fn make_takes_one_run_of_null_vertices_read_cyclically() {
    let (mut r, v) = vertices(4);
    // A run at both ends is one run across the wrap.
    r.make(v[0], &[NULL, v[1], v[2], NULL]).unwrap();
    assert_eq!(nbs(&r, v[0]), [v[1], v[2]]);
    assert_eq!(r.is_open(v[0], false), Ok(true));
    r.make(v[0], &[NULL, NULL, v[3]]).unwrap();
    assert_eq!(nbs(&r, v[0]), [v[3]]);
    assert_eq!(r.is_open(v[0], false), Ok(true));
    // Nothing but the null vertex: no neighbours, closed.
    r.make(v[0], &[NULL]).unwrap();
    assert_eq!(nbs(&r, v[0]), [] as [u32; 0]);
    assert_eq!(r.is_open(v[0], false), Ok(false));
    // A list without gaps closes an open neighbourhood.
    r.make(v[0], &[v[1], NULL]).unwrap();
    r.make(v[0], &[v[3], v[1]]).unwrap();
    assert_eq!(nbs(&r, v[0]), [v[3], v[1]]);
    assert_eq!(r.is_open(v[0], false), Ok(false));
    assert_eq!(
        r.make(v[0], &[v[1], NULL, v[2], NULL]),
        Err(
            "`make {…} nb_of v`: the list has more than one gap (its null vertices form 2 \
             runs); an open neighbourhood has one"
                .into()
        )
    );
}

#[test]
fn make_refuses_v_itself_and_repeats() {
    let (mut r, v) = vertices(4);
    r.make(v[0], &[v[1], v[2]]).unwrap();
    assert_eq!(
        r.make(v[0], &[v[1], v[0], v[2]]),
        Err("`make {…} nb_of v`: v (vertex 0) is listed in its own neighbourhood".into())
    );
    assert_eq!(
        r.make(v[0], &[v[1], v[2], v[3], v[2]]),
        Err("`make {…} nb_of v`: vertex 2 is listed twice".into())
    );
    // A refused make leaves the neighbourhood as it was.
    assert_eq!(nbs(&r, v[0]), [v[1], v[2]]);
    // Long lists are checked by sorting.
    let (mut r, v) = vertices(60);
    let mut list: Vec<u32> = v[1..].to_vec();
    list.push(v[40]);
    assert_eq!(
        r.make(v[0], &list),
        Err("`make {…} nb_of v`: vertex 40 is listed twice".into())
    );
    list.pop();
    r.make(v[0], &list).unwrap();
    assert_eq!(r.valence(v[0], false), Ok(59));
}

#[test]
fn make_refuses_dead_and_unknown_vertices() {
    let (mut r, v) = vertices(3);
    r.free(v[2]).unwrap();
    assert_eq!(
        r.make(v[0], &[v[1], v[2]]),
        Err("`make {…} nb_of v`: the list holds vertex 2, which no longer exists".into())
    );
    assert_eq!(
        r.make(v[0], &[v[1], 7]),
        Err("`make {…} nb_of v`: the list holds vertex 7, which does not exist".into())
    );
    assert_eq!(
        r.make(NULL, &[v[1]]),
        Err("`make {…} nb_of v`: the null vertex has no neighbourhood".into())
    );
    assert_eq!(
        r.make(v[2], &[v[1]]),
        Err("`make {…} nb_of v`: vertex 2 no longer exists".into())
    );
}

// ----- erase (note 4) -------------------------------------------------

#[test]
fn erase_removes_or_does_nothing() {
    let (mut r, v) = vertices(5);
    r.make(v[0], &[v[1], v[2], v[3]]).unwrap();
    r.erase(v[2], v[0]).unwrap();
    assert_eq!(nbs(&r, v[0]), [v[1], v[3]]);
    // Note 4: no effect if x is not a neighbour.
    r.erase(v[4], v[0]).unwrap();
    r.erase(NULL, v[0]).unwrap();
    assert_eq!(nbs(&r, v[0]), [v[1], v[3]]);
    // An open neighbourhood emptied is closed.
    r.make(v[4], &[v[1], NULL]).unwrap();
    r.erase(v[1], v[4]).unwrap();
    assert_eq!(r.valence(v[4], false), Ok(0));
    assert_eq!(r.is_open(v[4], false), Ok(false));
    assert_eq!(
        r.erase(v[1], NULL),
        Err("`erase x from v`: the null vertex has no neighbourhood".into())
    );
}

// ----- replace (note 5) ------------------------------------------------

#[test]
fn replace_substitutes_in_place() {
    let (mut r, v) = vertices(6);
    r.make(v[0], &[v[1], v[2], NULL, v[3]]).unwrap();
    assert_eq!(nbs(&r, v[0]), [v[3], v[1], v[2]]);
    r.replace(v[1], v[4], v[0]).unwrap();
    assert_eq!(nbs(&r, v[0]), [v[3], v[4], v[2]]);
    assert_eq!(r.is_open(v[0], false), Ok(true), "openness unchanged");
    // Note 5: no effect if a is not a neighbour.
    r.replace(v[5], v[1], v[0]).unwrap();
    r.replace(NULL, v[1], v[0]).unwrap();
    assert_eq!(nbs(&r, v[0]), [v[3], v[4], v[2]]);
    // Note 5: refused if x = v or x is a neighbour already.
    assert_eq!(
        r.replace(v[4], v[0], v[0]),
        Err(
            "`replace a with x in v`: x is v itself (vertex 0); a vertex is not its own \
             neighbour"
                .into()
        )
    );
    assert_eq!(
        r.replace(v[4], v[2], v[0]),
        Err("`replace a with x in v`: vertex 2 is already a neighbour of vertex 0".into())
    );
    assert_eq!(
        r.replace(v[4], v[4], v[0]),
        Err("`replace a with x in v`: vertex 4 is already a neighbour of vertex 0".into())
    );
    assert_eq!(
        r.replace(v[4], NULL, v[0]),
        Err("`replace a with x in v`: x is the null vertex, which cannot be a neighbour".into())
    );
    r.free(v[5]).unwrap();
    assert_eq!(
        r.replace(v[4], v[5], v[0]),
        Err("`replace a with x in v`: x is vertex 5, which no longer exists".into())
    );
    assert_eq!(nbs(&r, v[0]), [v[3], v[4], v[2]]);
}

// ----- splice (note 5) -------------------------------------------------

#[test]
fn splice_inserts_after_and_before() {
    let (mut r, v) = vertices(7);
    r.make(v[0], &[v[1], v[2], v[3]]).unwrap();
    r.splice_after(v[4], v[1], v[0]).unwrap();
    assert_eq!(nbs(&r, v[0]), [v[1], v[4], v[2], v[3]]);
    r.splice_before(v[5], v[1], v[0]).unwrap();
    // Before the first of a closed list: cyclically between 3 and 1.
    assert_eq!(nbs(&r, v[0]), [v[5], v[1], v[4], v[2], v[3]]);
    assert_eq!(r.prevto(v[1], v[0], false), Ok(v[5]));
    assert_eq!(r.nextto(v[3], v[0], false), Ok(v[5]));
    // Note 5: no effect if a is not a neighbour.
    r.splice_after(v[6], NULL, v[0]).unwrap();
    r.splice_before(v[6], v[6], v[0]).unwrap();
    assert_eq!(r.valence(v[0], false), Ok(5));
    // Note 5: refused if x = v or x is a neighbour already.
    assert_eq!(
        r.splice_after(v[0], v[1], v[0]),
        Err(
            "`splice x after a in v`: x is v itself (vertex 0); a vertex is not its own \
             neighbour"
                .into()
        )
    );
    assert_eq!(
        r.splice_before(v[2], v[1], v[0]),
        Err("`splice x before a in v`: vertex 2 is already a neighbour of vertex 0".into())
    );
    assert_eq!(
        r.splice_before(NULL, v[1], v[0]),
        Err("`splice x before a in v`: x is the null vertex, which cannot be a neighbour".into())
    );
    assert_eq!(r.valence(v[0], false), Ok(5));
}

#[test]
fn splice_at_the_gap_extends_an_open_neighbourhood() {
    let (mut r, v) = vertices(5);
    r.make(v[0], &[v[1], v[2], NULL]).unwrap();
    // After the last: the new vertex is the last, the gap after it.
    r.splice_after(v[3], v[2], v[0]).unwrap();
    assert_eq!(nbs(&r, v[0]), [v[1], v[2], v[3]]);
    assert_eq!(r.nextto(v[3], v[0], false), Ok(NULL));
    // Before the first: the new vertex is the first.
    r.splice_before(v[4], v[1], v[0]).unwrap();
    assert_eq!(nbs(&r, v[0]), [v[4], v[1], v[2], v[3]]);
    assert_eq!(r.prevto(v[4], v[0], false), Ok(NULL));
    assert_eq!(r.any(v[0], false), Ok(v[4]));
    assert_eq!(r.is_open(v[0], false), Ok(true));
}

// ----- dead, null and unsynchronized vertices --------------------------

#[test]
fn every_operation_refuses_null_dead_and_unknown_vertices() {
    let (mut r, v) = vertices(3);
    r.make(v[0], &[v[1], v[2]]).unwrap();
    r.free(v[1]).unwrap();
    type Call = fn(&mut Rotation, u32) -> Result<(), String>;
    let calls: [(&str, Call); 12] = [
        ("is x in v", |r, v| r.is_in(0, v, false).map(drop)),
        ("valence v", |r, v| r.valence(v, false).map(drop)),
        ("forall x in v", |r, v| r.neighbours(v, false).map(drop)),
        ("any in v", |r, v| r.any(v, false).map(drop)),
        ("nextto x in v", |r, v| r.nextto(0, v, false).map(drop)),
        ("prevto x in v", |r, v| r.prevto(0, v, false).map(drop)),
        ("make {…} nb_of v", |r, v| r.make(v, &[0])),
        ("erase x from v", |r, v| r.erase(0, v)),
        ("replace a with x in v", |r, v| r.replace(0, 2, v)),
        ("splice x after a in v", |r, v| r.splice_after(2, 0, v)),
        ("splice x before a in v", |r, v| r.splice_before(2, 0, v)),
        ("v$pos", |r, v| r.set_pos(v, DVec3::ONE)),
    ];
    for (name, call) in calls {
        let null = if name == "v$pos" {
            "has no position"
        } else {
            "has no neighbourhood"
        };
        assert_eq!(
            call(&mut r, NULL),
            Err(format!("`{name}`: the null vertex {null}"))
        );
        assert_eq!(
            call(&mut r, v[1]),
            Err(format!("`{name}`: vertex 1 no longer exists"))
        );
        assert_eq!(
            call(&mut r, 9),
            Err(format!("`{name}`: vertex 9 does not exist"))
        );
    }
    assert_eq!(
        r.free(v[1]),
        Err("`free`: vertex 1 no longer exists".into())
    );
    assert_eq!(
        r.free(NULL),
        Err("`free`: the null vertex cannot be freed".into())
    );
    // Old state exists only after a synchronize.
    assert_eq!(
        r.nextto(v[1], v[0], true),
        Err("`nextto x in v`: vertex 0 was not synchronized, so it has no old state".into())
    );
    assert_eq!(
        r.pos(v[2], true),
        Err("`v$pos`: vertex 2 was not synchronized, so it has no old state".into())
    );
}

#[test]
fn a_freed_slot_is_reused_and_old_handles_go_stale() {
    let (mut r, v) = vertices(3);
    let gen = r.generation(v[1]).unwrap();
    assert!(r.is_live(v[1], gen));
    r.set_pos(v[1], DVec3::ONE).unwrap();
    r.make(v[1], &[v[0], v[2]]).unwrap();
    r.free(v[1]).unwrap();
    assert!(!r.is_live(v[1], gen));
    assert_eq!(r.len(), 2);
    let w = r.new_vertex();
    assert_eq!(w, v[1], "the freed slot is reused");
    assert!(!r.is_live(v[1], gen), "the old handle stays stale");
    assert!(r.is_live(w, r.generation(w).unwrap()));
    assert_eq!(r.generation(w), Some(gen + 1));
    // A fresh vertex in the old slot: no neighbours, closed, at zero.
    assert_eq!(r.valence(w, false), Ok(0));
    assert_eq!(r.pos(w, false), Ok(DVec3::ZERO));
    assert_eq!(r.len(), 3);
    assert!(!r.is_live(NULL, 0));
    assert_eq!(r.generation(NULL), None);
}

#[test]
fn retain_frees_what_is_not_kept() {
    let (mut r, v) = vertices(5);
    r.retain(&[v[1], v[3], NULL]);
    assert_eq!(r.members_alive().collect::<Vec<_>>(), [v[1], v[3]]);
    assert_eq!(r.len(), 2);
}

// ----- properties ------------------------------------------------------

#[test]
fn vertex_and_mesh_properties_start_at_their_defaults() {
    let (mut r, v) = vertices(2);
    // Declared after vertices exist: they get the default too.
    let colour = r.add_vertex_property(3, &[0.5, 0.25, 1.0]);
    let w = r.new_vertex();
    for x in [v[0], v[1], w] {
        assert_eq!(
            r.vertex_property(x, colour, false),
            Ok(&[0.5, 0.25, 1.0][..])
        );
    }
    r.set_vertex_property(w, colour, &[1.0, 2.0, 3.0]).unwrap();
    assert_eq!(
        r.vertex_property(w, colour, false),
        Ok(&[1.0, 2.0, 3.0][..])
    );
    assert_eq!(
        r.vertex_property(v[0], colour, false),
        Ok(&[0.5, 0.25, 1.0][..])
    );
    assert_eq!(
        r.set_vertex_property(w, colour, &[1.0]),
        Err("vertex property 0 holds 3 values, not 1".into())
    );
    assert_eq!(
        r.vertex_property(w, 4, false),
        Err("there is no vertex property 4".into())
    );
    // A reused slot starts again from the default.
    r.free(w).unwrap();
    let w2 = r.new_vertex();
    assert_eq!(w2, w);
    assert_eq!(
        r.vertex_property(w2, colour, false),
        Ok(&[0.5, 0.25, 1.0][..])
    );
    let m = r.add_mesh_property(2, &[1.0, -1.0]);
    let n = r.add_mesh_property(1, &[4.0]);
    assert_eq!(r.mesh_property(m), Ok(&[1.0, -1.0][..]));
    r.set_mesh_property(n, &[5.0]).unwrap();
    assert_eq!(r.mesh_property(n), Ok(&[5.0][..]));
    assert_eq!(r.mesh_property(m), Ok(&[1.0, -1.0][..]));
}

#[test]
fn edge_properties_stay_with_their_edges() {
    let (mut r, v) = vertices(6);
    let w = r.add_edge_property(2, &[7.0, 8.0]);
    r.make(v[0], &[v[1], v[2], v[3]]).unwrap();
    let get = |r: &Rotation, x: u32, idx| {
        r.edge_property(v[0], x, idx, false)
            .unwrap()
            .map(<[f64]>::to_vec)
    };
    assert_eq!(get(&r, v[2], w), Some(vec![7.0, 8.0]));
    r.set_edge_property(v[0], v[2], w, &[1.0, 2.0]).unwrap();
    r.set_edge_property(v[0], v[3], w, &[3.0, 4.0]).unwrap();
    // splice: the new edge gets the default, the others keep theirs.
    r.splice_after(v[4], v[2], v[0]).unwrap();
    assert_eq!(get(&r, v[2], w), Some(vec![1.0, 2.0]));
    assert_eq!(get(&r, v[4], w), Some(vec![7.0, 8.0]));
    assert_eq!(get(&r, v[3], w), Some(vec![3.0, 4.0]));
    r.splice_before(v[5], v[1], v[0]).unwrap();
    assert_eq!(get(&r, v[5], w), Some(vec![7.0, 8.0]));
    assert_eq!(get(&r, v[2], w), Some(vec![1.0, 2.0]));
    // replace: the default in the replaced slot.
    r.erase(v[1], v[0]).unwrap();
    r.replace(v[2], v[1], v[0]).unwrap();
    assert_eq!(get(&r, v[1], w), Some(vec![7.0, 8.0]));
    assert_eq!(get(&r, v[2], w), None);
    assert_eq!(get(&r, v[3], w), Some(vec![3.0, 4.0]));
    // erase drops the edge's values.
    r.erase(v[4], v[0]).unwrap();
    assert_eq!(nbs(&r, v[0]), [v[5], v[1], v[3]]);
    assert_eq!(get(&r, v[3], w), Some(vec![3.0, 4.0]));
    // A second property declared now: the first keeps its values.
    let u = r.add_edge_property(1, &[9.0]);
    assert_eq!(get(&r, v[3], w), Some(vec![3.0, 4.0]));
    assert_eq!(get(&r, v[3], u), Some(vec![9.0]));
    r.set_edge_property(v[0], v[3], u, &[-1.0]).unwrap();
    assert_eq!(get(&r, v[3], w), Some(vec![3.0, 4.0]));
    assert_eq!(
        r.set_edge_property(v[0], v[2], w, &[0.0, 0.0]),
        Err(
            "`edge property`: vertex 2 is not a neighbour of vertex 0, so there is no \
             edge (0, 2)"
                .into()
        )
    );
    assert_eq!(
        r.set_edge_property(v[0], v[3], u, &[0.0, 0.0]),
        Err("edge property 1 holds 1 values, not 2".into())
    );
    // make resets every edge to the defaults.
    r.make(v[0], &[v[3], v[5]]).unwrap();
    assert_eq!(get(&r, v[3], w), Some(vec![7.0, 8.0]));
    assert_eq!(get(&r, v[3], u), Some(vec![9.0]));
}

// ----- synchronize ------------------------------------------------------

#[test]
fn the_old_state_is_what_synchronize_copied() {
    let (mut r, v) = vertices(5);
    let p = r.add_vertex_property(1, &[0.0]);
    let e = r.add_edge_property(1, &[0.0]);
    r.make(v[0], &[v[1], v[2], NULL]).unwrap();
    r.set_pos(v[0], DVec3::new(1.0, 2.0, 3.0)).unwrap();
    r.set_vertex_property(v[0], p, &[5.0]).unwrap();
    r.set_edge_property(v[0], v[2], e, &[6.0]).unwrap();
    r.synchronize(&[v[0]]).unwrap();
    // Later edits change the current state only.
    r.make(v[0], &[v[3], v[2], v[4]]).unwrap();
    r.set_pos(v[0], DVec3::ZERO).unwrap();
    r.set_vertex_property(v[0], p, &[-5.0]).unwrap();
    r.set_edge_property(v[0], v[2], e, &[-6.0]).unwrap();
    assert_eq!(r.neighbours(v[0], true), Ok(&[v[1], v[2]][..]));
    assert_eq!(r.is_open(v[0], true), Ok(true));
    assert_eq!(r.is_open(v[0], false), Ok(false));
    assert_eq!(r.nextto(v[2], v[0], true), Ok(NULL));
    assert_eq!(r.nextto(v[2], v[0], false), Ok(v[4]));
    assert_eq!(r.prevto(v[2], v[0], true), Ok(v[1]));
    assert_eq!(r.valence(v[0], true), Ok(2));
    assert_eq!(r.is_in(v[3], v[0], true), Ok(false));
    assert_eq!(r.any(v[0], true), Ok(v[1]));
    assert_eq!(r.pos(v[0], true), Ok(DVec3::new(1.0, 2.0, 3.0)));
    assert_eq!(r.vertex_property(v[0], p, true), Ok(&[5.0][..]));
    assert_eq!(r.edge_property(v[0], v[2], e, true), Ok(Some(&[6.0][..])));
    assert_eq!(r.edge_property(v[0], v[2], e, false), Ok(Some(&[-6.0][..])));
    // A second synchronize takes the new state.
    r.synchronize(&[v[0]]).unwrap();
    assert_eq!(r.neighbours(v[0], true), Ok(&[v[3], v[2], v[4]][..]));
    assert_eq!(r.pos(v[0], true), Ok(DVec3::ZERO));
}

#[test]
fn synchronize_refuses_a_dead_member_and_copies_nothing() {
    let (mut r, v) = vertices(3);
    r.free(v[2]).unwrap();
    assert_eq!(
        r.synchronize(&[v[0], v[2]]),
        Err("`synchronize`: vertex 2 no longer exists".into())
    );
    assert!(r.pos(v[0], true).is_err(), "v0 was not copied");
    assert_eq!(
        r.synchronize(&[NULL]),
        Err("`synchronize`: the null vertex cannot be synchronized".into())
    );
    // A vertex freed and created again has no old state.
    r.synchronize(&[v[1]]).unwrap();
    r.free(v[1]).unwrap();
    let w = r.new_vertex();
    assert!(r.valence(w, true).is_err());
}

/// One step of smoothing: every vertex moves to the average of its
/// neighbours, reading old positions (`old`) or current ones.
fn smooth(r: &mut Rotation, order: &[u32], old: bool) {
    if old {
        r.synchronize(order).unwrap();
    }
    for &v in order {
        let list = r.neighbours(v, old).unwrap().to_vec();
        let sum: DVec3 = list.iter().map(|&x| r.pos(x, old).unwrap()).sum();
        r.set_pos(v, sum / list.len() as f64).unwrap();
    }
}

#[test]
fn reading_the_old_state_makes_iteration_order_irrelevant() {
    let (base, members) = Rotation::from_soup(&icosphere(1)).unwrap();
    let forward = members.clone();
    let mut shuffled = members.clone();
    shuffled.reverse();
    shuffled.rotate_left(17);
    let run = |order: &[u32], old: bool| {
        let mut r = base.clone();
        smooth(&mut r, order, old);
        smooth(&mut r, order, old);
        members
            .iter()
            .map(|&v| r.pos(v, false).unwrap().to_array().map(f64::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(run(&forward, true), run(&shuffled, true));
    // Reading the current positions instead, the order shows.
    assert_ne!(run(&forward, false), run(&shuffled, false));
}

/// One step of the paper's polyhedral subdivision (§3.2), written with
/// the operations of Table 2: a vertex at the midpoint of every edge
/// (Fig. 3's insertion), then every new vertex joined to the new
/// vertices of the two triangles beside its edge. Returns the new set.
///
/// For the edge p–q with the triangles (p, q, r) and (q, p, s), the new
/// vertex x gets the counter-clockwise list [p, u, w, q, y, z] (u on
/// p–s, w on s–q, y on q–r, z on r–p): at p, u precedes x and z follows
/// it; at q, y precedes x and w follows it.
fn polyhedral(r: &mut Rotation, set: &[u32]) -> Vec<u32> {
    r.synchronize(set).unwrap();
    let mut all = set.to_vec();
    let mut new = Vec::new();
    for &p in set {
        for k in 0..r.valence(p, true).unwrap() {
            let q = r.neighbours(p, true).unwrap()[k];
            if p < q {
                let x = r.new_vertex();
                let mid = (r.pos(p, true).unwrap() + r.pos(q, true).unwrap()) / 2.0;
                r.set_pos(x, mid).unwrap();
                r.replace(q, x, p).unwrap();
                r.replace(p, x, q).unwrap();
                r.make(x, &[p, q]).unwrap();
                new.push(x);
            }
        }
    }
    for &x in &new {
        let p = r.any(x, false).unwrap();
        let q = r.nextto(p, x, false).unwrap();
        let list = [
            p,
            r.prevto(x, p, false).unwrap(),
            r.nextto(x, q, false).unwrap(),
            q,
            r.prevto(x, q, false).unwrap(),
            r.nextto(x, p, false).unwrap(),
        ];
        r.make(x, &list).unwrap();
    }
    all.extend(new);
    all
}

#[test]
fn polyhedral_subdivision_runs_on_the_operations() {
    let (mut r, set) = Rotation::from_soup(&octahedron()).unwrap();
    let all = polyhedral(&mut r, &set);
    r.check(&all).unwrap();
    let faces = r.faces(&all).unwrap();
    // Each triangle in four: V = 6 + 12 edges, E = 2 * 12 + 3 * 8,
    // F = 4 * 8.
    assert_eq!((all.len(), edge_count(&r, &all), faces.len()), (18, 48, 32));
    assert!(faces.iter().all(|f| f.len() == 3));
    assert_outward(&r, &faces, DVec3::ZERO);
    // A new vertex has valence 6, an old one keeps its 4.
    for &v in &all {
        assert_eq!(r.valence(v, false), Ok(if v < 6 { 4 } else { 6 }));
    }
    let all = polyhedral(&mut r, &all);
    r.check(&all).unwrap();
    assert_eq!(r.faces(&all).unwrap().len(), 128);
}

// ----- steady state ----------------------------------------------------

/// Every capacity the system holds.
fn capacities(r: &Rotation) -> Vec<usize> {
    let mut c = vec![
        r.alive.capacity(),
        r.nbs.capacity(),
        r.edges.capacity(),
        r.old_nbs.capacity(),
        r.old_edges.capacity(),
        r.pos.capacity(),
        r.free.capacity(),
    ];
    for lists in [&r.nbs, &r.old_nbs] {
        c.extend(lists.iter().map(Vec::capacity));
    }
    for vals in [&r.edges, &r.old_edges] {
        c.extend(vals.iter().map(Vec::capacity));
    }
    c.extend(
        r.vprops
            .iter()
            .flat_map(|p| [p.cur.capacity(), p.old.capacity()]),
    );
    c
}

#[test]
fn creating_editing_and_freeing_allocates_nothing_once_warm() {
    let (mut r, ring) = vertices(8);
    r.add_vertex_property(3, &[0.0; 3]);
    r.add_edge_property(2, &[0.0; 2]);
    let round = |r: &mut Rotation| {
        for k in 0..40 {
            let made: Vec<u32> = (0..3).map(|_| r.new_vertex()).collect();
            for (j, &c) in made.iter().enumerate() {
                let n = 3 + (k + j) % 4;
                r.make(c, &ring[..n]).unwrap();
                r.splice_after(ring[7], ring[1], c).unwrap();
                r.erase(ring[0], c).unwrap();
                r.replace(ring[2], ring[6], c).unwrap();
                r.set_pos(c, DVec3::splat(k as f64)).unwrap();
            }
            r.synchronize(&made).unwrap();
            for &c in made.iter().rev().skip(k % 2) {
                r.free(c).unwrap();
            }
            if k % 2 == 1 {
                r.free(made[2]).unwrap();
            }
        }
    };
    round(&mut r);
    let warm = capacities(&r);
    round(&mut r);
    assert_eq!(capacities(&r), warm);
    assert_eq!(r.len(), 8);
}

#[test]
fn reserved_room_takes_new_vertices_without_moving_arrays() {
    let (mut r, _) = vertices(3);
    r.add_vertex_property(2, &[0.0; 2]);
    r.reserve(100);
    let outer = |r: &Rotation| {
        [
            r.alive.capacity(),
            r.nbs.capacity(),
            r.old_nbs.capacity(),
            r.pos.capacity(),
            r.old_pos.capacity(),
            r.vprops[0].cur.capacity(),
        ]
    };
    let before = outer(&r);
    assert!(before.iter().all(|&c| c >= 103));
    for _ in 0..100 {
        r.new_vertex();
    }
    assert_eq!(outer(&r), before);
}

// ----- Edmonds' technique and the check ---------------------------------

#[test]
fn a_tetrahedron_made_by_hand_has_four_faces() {
    let (mut r, v) = vertices(4);
    let at = [(1., 1., 1.), (1., -1., -1.), (-1., 1., -1.), (-1., -1., 1.)];
    for (k, &(x, y, z)) in at.iter().enumerate() {
        r.set_pos(v[k], DVec3::new(x, y, z)).unwrap();
    }
    // The outward counter-clockwise faces are (0,1,2), (0,3,1),
    // (0,2,3), (1,3,2) (checked below by their normals). At a corner
    // (a, v, b) of a face, a follows b in v's list: at 0, 2 follows 1
    // (face 012), 1 follows 3 (031), 3 follows 2 (023): [1, 2, 3]. The
    // same for the others.
    r.make(v[0], &[v[1], v[2], v[3]]).unwrap();
    r.make(v[1], &[v[0], v[3], v[2]]).unwrap();
    r.make(v[2], &[v[0], v[1], v[3]]).unwrap();
    r.make(v[3], &[v[1], v[0], v[2]]).unwrap();
    r.check(&v).unwrap();
    let faces = r.faces(&v).unwrap();
    assert_eq!(faces, [[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]);
    assert_outward(&r, &faces, DVec3::ZERO);
    assert_eq!(r.holes(&v), Ok(vec![]));
    // Euler: V - E + F = 4 - 6 + 4 = 2.
    assert_eq!(edge_count(&r, &v), 6);
}

#[test]
fn a_cube_has_six_quads() {
    let soup = cube();
    let (r, set) = Rotation::from_soup(&soup).unwrap();
    r.check(&set).unwrap();
    let faces = r.faces(&set).unwrap();
    assert_eq!(faces.len(), 6);
    assert!(faces.iter().all(|f| f.len() == 4));
    assert_eq!(canonical_faces(&faces), canonical_faces(&soup.faces));
    assert_outward(&r, &faces, DVec3::splat(0.5));
    assert!(set.iter().all(|&v| r.valence(v, false) == Ok(3)));
    assert!(set.iter().all(|&v| r.is_open(v, false) == Ok(false)));
    // Euler: 8 - 12 + 6 = 2.
    assert_eq!(edge_count(&r, &set), 12);
    assert_eq!(r.holes(&set), Ok(vec![]));
}

#[test]
fn an_octahedron_has_eight_triangles() {
    let soup = octahedron();
    let (r, set) = Rotation::from_soup(&soup).unwrap();
    let faces = r.faces(&set).unwrap();
    assert_eq!(faces.len(), 8);
    assert_eq!(canonical_faces(&faces), canonical_faces(&soup.faces));
    assert_outward(&r, &faces, DVec3::ZERO);
    assert!(set.iter().all(|&v| r.valence(v, false) == Ok(4)));
    // Euler: 6 - 12 + 8 = 2.
    assert_eq!(edge_count(&r, &set), 12);
}

#[test]
fn a_three_by_three_grid_has_nine_quads_and_one_hole() {
    // Vertex (i, j) of the 4 x 4 grid points is 4j + i.
    let soup = quad_grid(3, 3);
    let (r, set) = Rotation::from_soup(&soup).unwrap();
    r.check(&set).unwrap();
    let faces = r.faces(&set).unwrap();
    assert_eq!(faces.len(), 9);
    assert_eq!(canonical_faces(&faces), canonical_faces(&soup.faces));
    // The grid lies in z = 0: counter-clockwise seen from +z.
    for f in &faces {
        assert!(normal(&r, f).z > 0.0);
    }
    // The hole runs round the 12 boundary vertices the other way:
    // up the side x = 0, along y = 1, down x = 1, back along y = 0.
    assert_eq!(
        r.holes(&set),
        Ok(vec![vec![0, 4, 8, 12, 13, 14, 15, 11, 7, 3, 2, 1]])
    );
    // The inner points 5, 6, 9, 10 are closed, the others open; a
    // corner has valence 2.
    for &v in &set {
        let (i, j) = (v % 4, v / 4);
        let inner = (1..3).contains(&i) && (1..3).contains(&j);
        assert_eq!(r.is_open(v, false), Ok(!inner));
    }
    assert_eq!(r.neighbours(0, false), Ok(&[1, 4][..]));
    assert_eq!(r.nextto(4, 0, false), Ok(NULL));
    // Euler of a disc: 16 - 24 + 9 = 1.
    assert_eq!(edge_count(&r, &set), 24);
}

#[test]
fn faces_come_in_a_fixed_order_from_their_smallest_vertex() {
    let (r, set) = Rotation::from_soup(&cube()).unwrap();
    let faces = r.faces(&set).unwrap();
    for f in &faces {
        assert_eq!(f[0], *f.iter().min().unwrap());
    }
    let keys: Vec<_> = faces.iter().map(|f| (f[0], f[1])).collect();
    let mut sorted = keys.clone();
    sorted.sort();
    assert_eq!(keys, sorted);
    // The same set in another order gives the same faces.
    let mut rev = set.clone();
    rev.reverse();
    assert_eq!(r.faces(&rev), Ok(faces));
}

#[test]
fn to_soup_and_back_keeps_the_faces() {
    for soup in [cube(), quad_grid(3, 2), icosphere(1)] {
        let (r, set) = Rotation::from_soup(&soup).unwrap();
        // Number the soup in another order, so that the ids change.
        let mut order = set.clone();
        order.reverse();
        order.rotate_left(3);
        let out = r.to_soup(&order).unwrap();
        assert_eq!(out.positions[0], r.pos(order[0], false).unwrap());
        let (back, set2) = Rotation::from_soup(&out).unwrap();
        let renumbered: Vec<Vec<u32>> = back
            .faces(&set2)
            .unwrap()
            .iter()
            .map(|f| f.iter().map(|&k| order[k as usize]).collect())
            .collect();
        assert_eq!(
            canonical_faces(&renumbered),
            canonical_faces(r.faces(&set).unwrap())
        );
        assert_eq!(
            back.holes(&set2).unwrap().len(),
            r.holes(&set).unwrap().len()
        );
    }
}

#[test]
fn an_icosphere_satisfies_euler() {
    // icosphere(2): 20 * 16 = 320 triangles, 162 vertices.
    let (r, set) = Rotation::from_soup(&icosphere(2)).unwrap();
    let f = r.faces(&set).unwrap().len();
    let e = edge_count(&r, &set);
    assert_eq!((set.len(), e, f), (162, 480, 320));
    assert_eq!(set.len() as i64 - e as i64 + f as i64, 2);
}

#[test]
fn from_soup_refuses_bow_ties_and_flipped_faces() {
    let soup = |faces: Vec<Vec<u32>>| PolygonSoup {
        positions: vec![DVec3::ZERO; 6],
        faces: faces.into(),
        ..Default::default()
    };
    // Two triangles that meet only at vertex 0.
    assert_eq!(
        Rotation::from_soup(&soup(vec![vec![0, 1, 2], vec![0, 3, 4]])).err(),
        Some(
            "vertex 1 is a bow-tie: its faces form more than one fan, so the mesh is not \
             a 2-manifold there"
                .into()
        )
    );
    // Two fans that close round vertex 0 (two cones sharing their tip).
    let cones = vec![vec![0, 1, 2], vec![0, 2, 1], vec![0, 3, 4], vec![0, 4, 3]];
    let err = Rotation::from_soup(&soup(cones)).err().unwrap();
    assert!(err.starts_with("vertex 1 is a bow-tie"), "{err}");
    // The second triangle turned over: both run 2 -> 0.
    let mut flipped = soup(vec![vec![0, 1, 2], vec![0, 3, 2]]);
    flipped.face_lines = vec![4, 5];
    assert_eq!(
        Rotation::from_soup(&flipped).err(),
        Some(
            "face 1 (line 4) and face 2 (line 5) both run from vertex 3 to vertex 1: \
             their orientations disagree, or more than two faces meet at that edge"
                .into()
        )
    );
    assert_eq!(
        Rotation::from_soup(&soup(vec![vec![0, 1]])).err(),
        Some("face 1 has 2 vertices; a face needs at least 3".into())
    );
    assert_eq!(
        Rotation::from_soup(&soup(vec![vec![0, 1, 0, 2]])).err(),
        Some("face 1 uses vertex 1 twice".into())
    );
    assert_eq!(
        Rotation::from_soup(&soup(vec![vec![0, 1, 9]])).err(),
        Some("face 1 refers to vertex 10, but there are only 6 vertices".into())
    );
    // An isolated vertex is allowed: no neighbours.
    let (r, set) = Rotation::from_soup(&soup(vec![vec![0, 1, 2]])).unwrap();
    assert_eq!(r.valence(5, false), Ok(0));
    assert_eq!(r.faces(&set).unwrap(), [[0, 1, 2]]);
    assert_eq!(r.holes(&set).unwrap(), [[0, 2, 1]]);
}

#[test]
fn check_names_the_first_asymmetry() {
    let (mut r, v) = vertices(8);
    r.make(v[3], &[v[7]]).unwrap();
    assert_eq!(
        r.check(&v),
        Err("vertex 3 lists 7 as a neighbour but 7 does not list 3".into())
    );
    assert_eq!(
        r.check(&v[..4]),
        Err("vertex 3 lists vertex 7, which is not in the set".into())
    );
    r.free(v[7]).unwrap();
    assert_eq!(
        r.check(&v[..7]),
        Err("vertex 3 lists vertex 7, which no longer exists".into())
    );
    assert_eq!(
        r.check(&v),
        Err("`check`: the set holds vertex 7, which no longer exists".into())
    );
    assert_eq!(
        r.check(&[v[0], v[0]]),
        Err("`check`: the set holds vertex 0 twice".into())
    );
    assert_eq!(
        r.check(&[NULL]),
        Err("`check`: the set holds the null vertex".into())
    );
}

#[test]
fn check_refuses_what_is_not_a_two_manifold() {
    // An edge alone, closed at both ends: a "face" of 2 vertices.
    let (mut r, v) = vertices(2);
    r.make(v[0], &[v[1]]).unwrap();
    r.make(v[1], &[v[0]]).unwrap();
    assert_eq!(
        r.check(&v),
        Err("the face through edge (0, 1) has only 2 vertices: a face needs at least 3".into())
    );
    // The same edge open at both ends: boundary on both sides.
    r.make(v[0], &[v[1], NULL]).unwrap();
    r.make(v[1], &[v[0], NULL]).unwrap();
    assert_eq!(
        r.check(&v),
        Err("edge (0, 1) borders no face: both its sides are boundary".into())
    );
    // A triangle with one corner open and two closed: faces and gaps
    // on one orbit.
    let (mut r, v) = vertices(3);
    r.make(v[0], &[v[1], v[2], NULL]).unwrap();
    r.make(v[1], &[v[2], v[0]]).unwrap();
    r.make(v[2], &[v[0], v[1]]).unwrap();
    assert_eq!(
        r.check(&v),
        Err(
            "the faces and the boundary disagree on the loop through edge (0, 2): vertex \
             0's neighbourhood is open there but vertex 2's is not"
                .into()
        )
    );
    // Closed, it is a pillow of two triangles: V - E + F = 3 - 3 + 2.
    r.make(v[0], &[v[1], v[2]]).unwrap();
    r.check(&v).unwrap();
    assert_eq!(r.faces(&v), Ok(vec![vec![0, 1, 2], vec![0, 2, 1]]));
    // A dangling vertex 3 hung on 0: the face round it meets 0 twice.
    let w = r.new_vertex();
    r.splice_after(w, v[1], v[0]).unwrap();
    r.make(w, &[v[0]]).unwrap();
    let mut all = v.clone();
    all.push(w);
    assert_eq!(
        r.check(&all),
        Err("the face through edge (0, 1) passes vertex 0 twice".into())
    );
    assert!(r.faces(&all).is_err());
}

#[test]
fn check_refuses_loops_and_repeats_that_bypass_the_editing_operations() {
    let (mut r, v) = vertices(3);
    r.nbs[0] = vec![v[0]];
    assert_eq!(
        r.check(&v),
        Err("vertex 0 lists itself as a neighbour".into())
    );
    r.nbs[0] = vec![v[1], v[1]];
    r.nbs[1] = vec![v[0]];
    assert_eq!(r.check(&v), Err("vertex 0 lists vertex 1 twice".into()));
}
