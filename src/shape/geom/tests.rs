//! Tests of the geometry kernel: cuts and splits, caps, welding, primitives,
//! extrusion, components and transforms, and the sharing of cut points.

use std::collections::{HashMap, HashSet};

use glam::{DAffine3, DVec3};

use crate::mesh::PolygonSoup;

use super::comp::lot_scope;
use super::cut::plane_cut;
use super::primitives::{polygon_in, quad};
use super::weld::Welded;
use super::*;

/// The signed volume by the divergence theorem: the sum over faces
/// (fanned) of p0 · (pi × pi+1) / 6, positions taken relative to the
/// first point (a closed surface's volume does not depend on it).
fn volume(points: &Points, g: &Geometry) -> f64 {
    let Some(o) = g.point_ids().next().map(|p| points.get(p)) else {
        return 0.0;
    };
    let at = |p: PointId| points.get(p) - o;
    let mut v = 0.0;
    for f in &g.faces {
        let p0 = at(f.pts[0]);
        for i in 1..f.pts.len() - 1 {
            v += p0.dot(at(f.pts[i]).cross(at(f.pts[i + 1])));
        }
    }
    v / 6.0
}

/// Every undirected edge in exactly two faces, once each way (a closed,
/// consistently oriented 2-manifold surface).
fn assert_closed(faces: &[Vec<u32>]) {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for f in faces {
        for i in 0..f.len() {
            *directed.entry((f[i], f[(i + 1) % f.len()])).or_default() += 1;
        }
    }
    for (&(a, b), &k) in &directed {
        assert_eq!(k, 1, "edge {a}->{b} used {k} times");
        assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}-{b} has one face");
    }
}

fn face_lists(g: &Geometry) -> Vec<Vec<u32>> {
    g.faces.iter().map(|f| f.pts.clone()).collect()
}

fn sized(origin: DVec3, size: DVec3) -> Scope {
    Scope {
        origin,
        size,
        ..Scope::world()
    }
}

fn unit_box(points: &mut Points) -> Geometry {
    box_in(points, &sized(DVec3::ZERO, DVec3::ONE)).unwrap()
}

/// Splits the unit box at x = 0.3 and x = 0.7 (cuts 1 and 2).
fn three_pieces(points: &mut Points) -> Vec<Geometry> {
    let b = unit_box(points);
    split(points, &b, DVec3::ZERO, DVec3::X, &[0.3, 0.7], 1).unwrap()
}

fn cap(g: &Geometry, seam: u32) -> Vec<PointId> {
    let caps: Vec<&Face> = g.faces.iter().filter(|f| f.seam == seam).collect();
    assert_eq!(caps.len(), 1, "one cap with seam {seam}");
    caps[0].pts.clone()
}

#[test]
fn split_box_gives_pieces_of_the_right_volumes_with_mirrored_caps() {
    let mut points = Points::new();
    let pieces = three_pieces(&mut points);
    assert_eq!(pieces.len(), 3);
    // Slabs of the unit box: 1 x 1 x width.
    for (g, w) in pieces.iter().zip([0.3, 0.4, 0.3]) {
        assert!((volume(&points, g) - w).abs() < 1e-12);
        assert_closed(&face_lists(g));
    }
    for k in 1..=2u32 {
        let lower = cap(&pieces[k as usize - 1], 2 * k);
        let mut upper = cap(&pieces[k as usize], 2 * k + 1);
        upper.reverse();
        assert_eq!(lower, upper, "cut {k}'s caps are mirrored id for id");
        assert_eq!(lower.len(), 4);
        let x = [0.3, 0.7][k as usize - 1];
        for &p in &lower {
            assert!((points.get(p).x - x).abs() < 1e-15);
        }
        // The lower side's cap faces +x.
        assert!(newell(&points, &lower).x > 0.0);
    }
    // 8 corners and 4 points per cut.
    assert_eq!(points.len(), 16);
}

#[test]
fn welding_every_piece_closes_the_box_again() {
    let mut points = Points::new();
    let pieces = three_pieces(&mut points);
    let members: Vec<&Geometry> = pieces.iter().collect();
    let w = weld(&mut points, &members, &[], &HashSet::new(), &HashMap::new()).unwrap();
    assert_closed(&w.soup.faces.to_vecs());
    // 8 corners + 2 cuts x 4 points; the 4 faces across x in 3 pieces
    // each and the 2 ends: 14 faces, none of them a cap.
    assert_eq!(w.soup.positions.len(), 16);
    assert_eq!(w.soup.faces.len(), 14);
    assert!(w.protected_vertex.iter().all(|&p| !p));
    assert_eq!(w.tags.iter().filter(|&&t| t == 1).count(), 4);
    let mut g = Geometry::empty(3);
    for f in &w.soup.faces {
        g.faces.push(Face {
            pts: f.iter().map(|&v| w.point_of[v as usize]).collect(),
            seam: 0,
        });
    }
    assert!((volume(&points, &g) - 1.0).abs() < 1e-12);
}

#[test]
fn a_loose_cut_leaves_a_slit() {
    let mut points = Points::new();
    let pieces = three_pieces(&mut points);
    let members: Vec<&Geometry> = pieces.iter().collect();
    let loose: HashSet<u32> = [2].into_iter().collect();
    let w = weld(&mut points, &members, &[], &loose, &HashMap::new()).unwrap();
    assert_closed(&w.soup.faces.to_vecs());
    // 16 points and the 4 points of cut 2 copied for the upper side;
    // 14 faces and both caps of cut 2.
    assert_eq!(w.soup.positions.len(), 20);
    assert_eq!(w.soup.faces.len(), 16);
    // The copies sit where the originals are.
    let mut at: HashMap<[u64; 3], usize> = HashMap::new();
    for p in &w.soup.positions {
        *at.entry([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
            .or_default() += 1;
    }
    assert_eq!(at.values().filter(|&&k| k == 2).count(), 4);
    assert!(w
        .soup
        .positions
        .iter()
        .all(|p| p.x == 0.7 || at[&[p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]] == 1));
}

/// The welded soup as one geometry on point ids (for `volume`).
fn soup_geometry(w: &Welded) -> Geometry {
    let mut g = Geometry::empty(3);
    for f in &w.soup.faces {
        g.faces.push(Face {
            pts: f.iter().map(|&v| w.point_of[v as usize]).collect(),
            seam: 0,
        });
    }
    g
}

#[test]
fn a_wall_shared_with_a_shape_outside_the_group_keeps_its_uncovered_part() {
    let mut points = Points::new();
    let pieces = three_pieces(&mut points);
    // Piece 1 split along z (cut 3): its halves both hold a part of
    // cut 2's wall; the plane crossed a shape with cut-2 faces.
    let halves = split(&mut points, &pieces[1], DVec3::ZERO, DVec3::Z, &[0.5], 3).unwrap();
    let seam_planes: HashMap<u32, Vec<(DVec3, f64)>> =
        [(2, vec![plane_of(DVec3::ZERO, DVec3::Z, 0.5)])]
            .into_iter()
            .collect();
    let w = weld(
        &mut points,
        &[&halves[0], &pieces[2]],
        &[&halves[1]],
        &HashSet::new(),
        &seam_planes,
    )
    .unwrap();
    // Piece 2's wall is cut in two: the half against halves[0] goes
    // with its mirror, the half against halves[1] stays.
    assert_closed(&w.soup.faces.to_vecs());
    // [0.3, 1] x [0, 1] x [0, 0.5] and [0.7, 1] x [0, 1] x [0.5, 1].
    let v = 0.7 * 0.5 + 0.3 * 0.5;
    assert!((volume(&points, &soup_geometry(&w)) - v).abs() < 1e-12);
    // Protected faces: halves[0]'s cut-3 cap and piece 2's kept wall
    // half, both on points of halves[1].
    assert_eq!(w.protected_face.iter().filter(|&&p| p).count(), 2);
}

#[test]
fn welding_resolves_t_junctions() {
    let mut points = Points::new();
    let pieces = three_pieces(&mut points);
    let halves = split(&mut points, &pieces[1], DVec3::ZERO, DVec3::Y, &[0.5], 3).unwrap();
    assert_eq!(halves.len(), 2);
    let members = [&pieces[0], &halves[0], &halves[1], &pieces[2]];
    // The y cut crossed a shape holding walls of cuts 1 and 2.
    let y = plane_of(DVec3::ZERO, DVec3::Y, 0.5);
    let seam_planes: HashMap<u32, Vec<(DVec3, f64)>> =
        [(1, vec![y]), (2, vec![y])].into_iter().collect();
    let w = weld(&mut points, &members, &[], &HashSet::new(), &seam_planes).unwrap();
    assert_closed(&w.soup.faces.to_vecs());
    // The y cut put 4 points on the middle slab's edges at x = 0.3 and
    // 0.7 (front and back), all used.
    assert_eq!(w.soup.positions.len(), 20);
}

#[test]
fn a_shape_outside_the_group_protects_the_shared_wall() {
    let mut points = Points::new();
    let pieces = three_pieces(&mut points);
    let w = weld(
        &mut points,
        &[&pieces[0]],
        &[&pieces[1]],
        &HashSet::new(),
        &HashMap::new(),
    )
    .unwrap();
    assert_closed(&w.soup.faces.to_vecs());
    let protected: Vec<DVec3> = (0..w.soup.positions.len())
        .filter(|&v| w.protected_vertex[v])
        .map(|v| w.soup.positions[v])
        .collect();
    assert_eq!(protected.len(), 4);
    assert!(protected.iter().all(|p| (p.x - 0.3).abs() < 1e-15));
    let faces: Vec<usize> = (0..w.soup.faces.len())
        .filter(|&f| w.protected_face[f])
        .collect();
    assert_eq!(faces.len(), 1);
    let n = {
        let f = &w.soup.faces[faces[0]];
        let ids: Vec<PointId> = f.iter().map(|&v| w.point_of[v as usize]).collect();
        newell(&points, &ids)
    };
    assert!(n.x > 0.0 && n.y.abs() < 1e-12 && n.z.abs() < 1e-12);
}

/// An L: [0,2]x[0,1] and [0,1]x[0,2] in the ground plane (x, z), facing up.
fn l_shape(points: &mut Points) -> Geometry {
    let mut c = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(2.0, 0.0, 1.0),
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(1.0, 0.0, 2.0),
        DVec3::new(0.0, 0.0, 2.0),
    ];
    // Face +y: counter-clockwise seen from above.
    let mut n = DVec3::ZERO;
    for i in 0..c.len() {
        n += c[i].cross(c[(i + 1) % c.len()]);
    }
    if n.y < 0.0 {
        c.reverse();
    }
    polygon(points, &c).unwrap()
}

fn components(g: &Geometry) -> usize {
    let faces = &g.faces;
    let mut parent: Vec<usize> = (0..faces.len()).collect();
    fn find(p: &mut [usize], i: usize) -> usize {
        let mut i = i;
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    let mut owner: HashMap<PointId, usize> = HashMap::new();
    for (f, face) in faces.iter().enumerate() {
        for &p in &face.pts {
            if let Some(&o) = owner.get(&p) {
                let (a, b) = (find(&mut parent, o), find(&mut parent, f));
                parent[a] = b;
            } else {
                owner.insert(p, f);
            }
        }
    }
    (0..faces.len())
        .filter(|&f| find(&mut parent, f) == f)
        .count()
}

#[test]
fn a_non_convex_solid_cut_through_its_notch_gives_two_parts_on_one_side() {
    let mut points = Points::new();
    let lot = l_shape(&mut points);
    let solid = extrude(&mut points, &lot, DVec3::Y, 1.0).unwrap();
    assert!((volume(&points, &solid) - 3.0).abs() < 1e-12);
    // The plane x + z = 2.5 crosses both arms: the tip of each arm is
    // the triangle (1.5, 1), (2, 1), (2, 0.5) (or its mirror), area
    // 0.125, so 0.25 above and 3 - 0.25 below (height 1).
    let n = DVec3::new(1.0, 0.0, 1.0).normalize();
    let d = 2.5 / 2f64.sqrt();
    let (below, above) = plane_cut(&mut points, &solid, n, d, 1, 1e-9).unwrap();
    assert!((volume(&points, &above) - 0.25).abs() < 1e-12);
    assert!((volume(&points, &below) - 2.75).abs() < 1e-12);
    assert_closed(&face_lists(&above));
    assert_closed(&face_lists(&below));
    assert_eq!(components(&above), 2);
    assert_eq!(components(&below), 1);
    assert_eq!(above.faces.iter().filter(|f| f.seam == 3).count(), 2);
    // The lot itself: two pieces above, one below sharing cut points.
    let (b2, a2) = plane_cut(&mut points, &lot, n, d, 2, 1e-9).unwrap();
    assert_eq!(a2.faces.len(), 2);
    assert_eq!(b2.faces.len(), 1);
    let below_pts: HashSet<PointId> = b2.point_ids().collect();
    assert_eq!(a2.point_ids().filter(|p| below_pts.contains(p)).count(), 4);
}

#[test]
fn on_plane_vertices_belong_to_both_sides_without_cuts() {
    let mut points = Points::new();
    let b = unit_box(&mut points);
    // A plane through the diagonal edge pair x = z: no edge is crossed
    // between its ends except across the faces; the two halves are
    // prisms of volume 1/2.
    let n = DVec3::new(1.0, 0.0, -1.0).normalize();
    let (lo, hi) = plane_cut(&mut points, &b, n, 0.0, 1, 1e-9).unwrap();
    assert_eq!(
        points.len(),
        8,
        "no new point: the plane passes through vertices"
    );
    assert!((volume(&points, &lo) - 0.5).abs() < 1e-12);
    assert!((volume(&points, &hi) - 0.5).abs() < 1e-12);
    assert_closed(&face_lists(&lo));
    assert_closed(&face_lists(&hi));
    // A plane along a face keeps the whole on one side, without caps.
    let (lo, hi) = plane_cut(&mut points, &b, DVec3::X, 1.0, 2, 1e-9).unwrap();
    assert_eq!((lo.faces.len(), hi.faces.len()), (6, 0));
    let (lo, hi) = plane_cut(&mut points, &b, DVec3::X, 0.0, 3, 1e-9).unwrap();
    assert_eq!((lo.faces.len(), hi.faces.len()), (0, 6));
}

#[test]
fn siblings_cut_by_one_plane_share_the_points_on_their_wall() {
    let mut points = Points::new();
    let b = unit_box(&mut points);
    let halves = split(&mut points, &b, DVec3::ZERO, DVec3::X, &[0.5], 1).unwrap();
    let lo = split(&mut points, &halves[0], DVec3::ZERO, DVec3::Y, &[0.5], 2).unwrap();
    let hi = split(&mut points, &halves[1], DVec3::ZERO, DVec3::Y, &[0.5], 3).unwrap();
    // 8 corners, 4 points of cut 1, and the y cuts cross the 4 vertical
    // edges of each half, 2 of them (at x = 0.5) shared: 6.
    assert_eq!(points.len(), 18);
    let members = [&lo[0], &lo[1], &hi[0], &hi[1]];
    for g in members {
        assert!((volume(&points, g) - 0.25).abs() < 1e-12);
    }
    let w = weld(&mut points, &members, &[], &HashSet::new(), &HashMap::new()).unwrap();
    assert_closed(&w.soup.faces.to_vecs());
    assert_eq!(w.soup.positions.len(), 18);
}

#[test]
fn cuts_through_a_reflex_vertex() {
    let mut points = Points::new();
    let lot = l_shape(&mut points);
    let area = |points: &Points, g: &Geometry| -> f64 {
        g.faces.iter().map(|f| newell(points, &f.pts).y / 2.0).sum()
    };
    // x = 1 runs along the inner wall from the reflex corner (1, 1):
    // [0,1]x[0,2] (area 2) below, [1,2]x[0,1] (area 1) above.
    let (lo, hi) = plane_cut(&mut points, &lot, DVec3::X, 1.0, 1, 1e-9).unwrap();
    assert_eq!((lo.faces.len(), hi.faces.len()), (1, 1));
    assert!((area(&points, &lo) - 2.0).abs() < 1e-12);
    assert!((area(&points, &hi) - 1.0).abs() < 1e-12);
    let solid = extrude(&mut points, &lot, DVec3::Y, 1.0).unwrap();
    for (n, d, vlo, vhi) in [(DVec3::Z, 1.0, 2.0, 1.0), (DVec3::X, 1.0, 2.0, 1.0)] {
        let (lo, hi) = plane_cut(&mut points, &solid, n, d, 2, 1e-9).unwrap();
        assert!((volume(&points, &lo) - vlo).abs() < 1e-12);
        assert!((volume(&points, &hi) - vhi).abs() < 1e-12);
        assert_closed(&face_lists(&lo));
        assert_closed(&face_lists(&hi));
    }
}

#[test]
fn tilted_cuts_of_round_solids_conserve_volume() {
    let mut points = Points::new();
    let far = DVec3::new(1e6, -2e5, 3e5);
    let c = cylinder_in(&mut points, &sized(far, DVec3::new(2.0, 3.0, 1.0)), 24).unwrap();
    let sp = sphere_in(&mut points, &sized(far, DVec3::splat(2.0)), 16, 9).unwrap();
    let mut cut = 1;
    for g in [&c, &sp] {
        let whole = volume(&points, g);
        for n in [
            DVec3::new(1.0, 2.0, 0.5),
            DVec3::new(-0.3, 0.1, 1.0),
            DVec3::X,
        ] {
            let n = n.normalize();
            let d = n.dot(far + DVec3::new(0.9, 1.1, 0.5));
            let (lo, hi) = plane_cut(&mut points, g, n, d, cut, 0.0).unwrap();
            cut += 1;
            assert_closed(&face_lists(&lo));
            assert_closed(&face_lists(&hi));
            let (vl, vh) = (volume(&points, &lo), volume(&points, &hi));
            assert!(vl > 0.0 && vh > 0.0);
            // Both parts make up the whole (additivity of volume).
            assert!(
                (vl + vh - whole).abs() < 1e-6 * whole.abs().max(1.0),
                "{vl} + {vh} vs {whole}"
            );
        }
    }
}

/// A small deterministic generator (an LCG) for the randomised tests.
struct Lcg(u64);

impl Lcg {
    /// Uniform in [0, 1).
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A star-shaped simple polygon in the ground plane, facing up: corner
/// k at angle 2 pi k / m and a random radius.
fn star(points: &mut Points, rng: &mut Lcg, m: usize) -> Geometry {
    let corners: Vec<DVec3> = (0..m)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / m as f64;
            let r = 0.3 + rng.next();
            // Counter-clockwise seen from +y: x = cos, z = -sin.
            DVec3::new(r * a.cos(), 0.0, -r * a.sin())
        })
        .collect();
    polygon(points, &corners).unwrap()
}

fn area_up(points: &Points, g: &Geometry) -> f64 {
    g.faces.iter().map(|f| newell(points, &f.pts).y / 2.0).sum()
}

#[test]
fn random_cuts_of_non_convex_polygons_and_prisms_conserve_area_and_volume() {
    let mut rng = Lcg(14);
    let mut cut = 1;
    for round in 0..200 {
        let mut points = Points::new();
        let m = 3 + (rng.next() * 12.0) as usize;
        let lot = star(&mut points, &mut rng, m);
        let whole = area_up(&points, &lot);
        let a = rng.next() * std::f64::consts::TAU;
        let n = DVec3::new(a.cos(), 0.0, a.sin());
        // Every other plane passes exactly through a corner.
        let d = if round % 2 == 0 {
            n.dot(points.get(lot.faces[0].pts[(rng.next() * m as f64) as usize]))
        } else {
            (rng.next() - 0.5) * 1.5
        };
        let (lo, hi) = plane_cut(&mut points, &lot, n, d, cut, 1e-9).unwrap();
        cut += 1;
        // Additivity of area; every piece faces up and lies on its side.
        let (al, ah) = (area_up(&points, &lo), area_up(&points, &hi));
        assert!(
            (al + ah - whole).abs() < 1e-9,
            "round {round}: {al} + {ah} vs {whole}"
        );
        for f in &lo.faces {
            assert!(newell(&points, &f.pts).y > 0.0);
            assert!(f.pts.iter().all(|&p| n.dot(points.get(p)) - d <= 1e-9));
        }
        for f in &hi.faces {
            assert!(newell(&points, &f.pts).y > 0.0);
            assert!(f.pts.iter().all(|&p| n.dot(points.get(p)) - d >= -1e-9));
        }
        // The prism over the lot, cut by a plane off the corners: the
        // two closed parts make up its volume.
        if round % 2 == 1 {
            let solid = extrude(&mut points, &lot, DVec3::Y, 1.0).unwrap();
            let tilt = DVec3::new(n.x, 0.4 * (rng.next() - 0.5), n.z).normalize();
            let d = tilt.dot(DVec3::new(0.0, 0.5, 0.0)) + (rng.next() - 0.5);
            let (lo, hi) = plane_cut(&mut points, &solid, tilt, d, cut, 1e-9).unwrap();
            cut += 1;
            assert_closed(&face_lists(&lo));
            assert_closed(&face_lists(&hi));
            let (vl, vh) = (volume(&points, &lo), volume(&points, &hi));
            assert!(
                (vl + vh - whole).abs() < 1e-9,
                "round {round}: {vl} + {vh} vs {whole}"
            );
        }
    }
}

#[test]
fn outlines_meeting_at_a_point_give_separate_caps() {
    let mut points = Points::new();
    // Two unit squares facing up that share one corner (1, 0, 1).
    let mut id = |x: f64, z: f64| points.add(DVec3::new(x, 0.0, z)).unwrap();
    let (a0, a1, p, a3) = (id(0.0, 0.0), id(0.0, 1.0), id(1.0, 1.0), id(1.0, 0.0));
    let (b1, b2, b3) = (id(1.0, 2.0), id(2.0, 2.0), id(2.0, 1.0));
    let mut bowtie = Geometry::empty(2);
    bowtie.faces.push(quad(a0, a1, p, a3));
    bowtie.faces.push(quad(p, b1, b2, b3));
    let solid = extrude(&mut points, &bowtie, DVec3::Y, 1.0).unwrap();
    let (lo, hi) = plane_cut(&mut points, &solid, DVec3::Y, 0.5, 1, 1e-9).unwrap();
    // Each square's section is a square cap; both pass through the
    // point cut on the shared vertical edge.
    let caps: Vec<&Face> = lo.faces.iter().filter(|f| f.seam == 2).collect();
    assert_eq!(caps.len(), 2);
    assert!(caps.iter().all(|f| f.pts.len() == 4));
    let shared: Vec<PointId> = caps[0]
        .pts
        .iter()
        .copied()
        .filter(|q| caps[1].pts.contains(q))
        .collect();
    assert_eq!(shared.len(), 1);
    assert_eq!(points.get(shared[0]), DVec3::new(1.0, 0.5, 1.0));
    // Two unit squares by half the height on each side.
    assert!((volume(&points, &lo) - 1.0).abs() < 1e-12);
    assert!((volume(&points, &hi) - 1.0).abs() < 1e-12);
}

#[test]
fn a_cap_with_a_hole_is_refused() {
    let mut points = Points::new();
    // A square frame: outer [0,3]^2, inner [1,2]^2 in (x, z), as 4
    // quads facing +y, extruded up: a solid with a hole through it.
    let corner = |x: f64, z: f64| DVec3::new(x, 0.0, z);
    let o = [
        corner(0.0, 0.0),
        corner(0.0, 3.0),
        corner(3.0, 3.0),
        corner(3.0, 0.0),
    ];
    let i = [
        corner(1.0, 1.0),
        corner(1.0, 2.0),
        corner(2.0, 2.0),
        corner(2.0, 1.0),
    ];
    let oid: Vec<PointId> = o.iter().map(|&p| points.add(p).unwrap()).collect();
    let iid: Vec<PointId> = i.iter().map(|&p| points.add(p).unwrap()).collect();
    let mut frame = Geometry::empty(2);
    for k in 0..4 {
        let j = (k + 1) % 4;
        frame.faces.push(quad(oid[k], oid[j], iid[j], iid[k]));
    }
    assert!(newell(&points, &frame.faces[0].pts).y > 0.0);
    let solid = extrude(&mut points, &frame, DVec3::Y, 1.0).unwrap();
    assert_closed(&face_lists(&solid));
    // Outer 9 - inner 1, height 1.
    assert!((volume(&points, &solid) - 8.0).abs() < 1e-12);
    let e = plane_cut(&mut points, &solid, DVec3::Y, 0.5, 1, 1e-9);
    assert!(e.unwrap_err().contains("hole"));
    // Across the hole's axis there is no hole in the caps.
    let (lo, hi) = plane_cut(&mut points, &solid, DVec3::X, 1.5, 2, 1e-9).unwrap();
    assert!((volume(&points, &lo) - 4.0).abs() < 1e-12);
    assert!((volume(&points, &hi) - 4.0).abs() < 1e-12);
    assert_eq!(lo.faces.iter().filter(|f| f.seam == 4).count(), 2);
}

#[test]
fn primitives_are_closed_with_outward_faces() {
    let mut points = Points::new();
    let s = sized(DVec3::new(1.0, 2.0, 3.0), DVec3::new(2.0, 3.0, 4.0));
    let b = box_in(&mut points, &s).unwrap();
    assert_closed(&face_lists(&b));
    assert!((volume(&points, &b) - 24.0).abs() < 1e-12);

    // A regular n-gon of circumradius r has area (n / 2) r^2 sin(2 pi / n).
    let n = 64;
    let c = cylinder_in(
        &mut points,
        &sized(DVec3::ZERO, DVec3::new(2.0, 5.0, 2.0)),
        n,
    )
    .unwrap();
    assert_closed(&face_lists(&c));
    let ngon = n as f64 / 2.0 * (std::f64::consts::TAU / n as f64).sin();
    assert!((volume(&points, &c) - 5.0 * ngon).abs() < 1e-9);
    assert!((volume(&points, &c) / (5.0 * std::f64::consts::PI) - 1.0).abs() < 0.01);

    let sp = sphere_in(&mut points, &sized(DVec3::ZERO, DVec3::splat(2.0)), 32, 16).unwrap();
    assert_closed(&face_lists(&sp));
    for f in &sp.faces {
        assert!(
            newell(&points, &f.pts).length() > 1e-6,
            "no degenerate face"
        );
    }
    let v = volume(&points, &sp);
    let ball = 4.0 / 3.0 * std::f64::consts::PI;
    assert!(v < ball && v > 0.95 * ball, "{v} vs {ball}");
    // 32 triangles at each pole, 32 x 14 quads.
    assert_eq!(sp.faces.len(), 64 + 32 * 14);

    // A zero-size scope gives nothing.
    let flat = sized(DVec3::ZERO, DVec3::new(1.0, 0.0, 1.0));
    assert!(box_in(&mut points, &flat).unwrap().is_empty());
    assert!(sphere_in(&mut points, &flat, 8, 4).unwrap().is_empty());
    assert!(cylinder_in(&mut points, &flat, 2).is_err());
}

#[test]
fn a_mesh_fills_its_scope() {
    let mut points = Points::new();
    // A tetrahedron with outward faces, volume 1/6, in [0,1]^3.
    let soup = PolygonSoup {
        positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
        faces: vec![vec![0, 2, 1], vec![0, 1, 3], vec![0, 3, 2], vec![1, 2, 3]].into(),
        ..PolygonSoup::default()
    };
    let s = sized(DVec3::new(5.0, 0.0, 0.0), DVec3::new(2.0, 3.0, 4.0));
    let g = mesh_in(&mut points, &s, &soup).unwrap();
    assert_closed(&face_lists(&g));
    // Scaled by 2, 3, 4.
    assert!((volume(&points, &g) - 24.0 / 6.0).abs() < 1e-12);
    let bs = bounding_scope(&points, &g, s.axes);
    assert_eq!(bs.origin, s.origin);
    assert_eq!(bs.size, s.size);
    // A flat soup lands on the scope's origin plane.
    let flat = PolygonSoup {
        positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
        faces: vec![vec![0, 1, 2]].into(),
        ..PolygonSoup::default()
    };
    let g = mesh_in(&mut points, &s, &flat).unwrap();
    assert!(g.point_ids().all(|p| points.get(p).z == 0.0));
    let bad = PolygonSoup {
        faces: vec![vec![0, 1, 7]].into(),
        ..flat
    };
    assert!(mesh_in(&mut points, &s, &bad).is_err());
}

#[test]
fn extruding_a_lot_gives_height_times_area() {
    let mut points = Points::new();
    let lot = polygon_in(
        &mut points,
        &Scope::world(),
        &[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 2.0),
            DVec3::new(2.0, 0.0, 2.0),
            DVec3::new(2.0, 0.0, 0.0),
        ],
    )
    .unwrap();
    assert!(newell(&points, &lot.faces[0].pts).y > 0.0);
    let area = 4.0;
    for (dir, h) in [(DVec3::Y, 3.0), (DVec3::Y, -3.0), (DVec3::NEG_Y, 3.0)] {
        let g = extrude(&mut points, &lot, dir, h).unwrap();
        assert_closed(&face_lists(&g));
        assert!((volume(&points, &g) - 3.0 * area).abs() < 1e-12);
        // The base keeps the lot's ids.
        assert!(g.faces[0].pts.iter().all(|p| lot.faces[0].pts.contains(p)));
    }
    // The lot's own scope: x along its first edge (+z here), y up.
    let s = lot_scope(&points, &lot).unwrap();
    assert!((s.axes[0] - DVec3::Z).length() < 1e-12);
    assert!((s.axes[1] - DVec3::Y).length() < 1e-12);
    assert!((s.axes[2] + DVec3::X).length() < 1e-12);
    assert!((s.size - DVec3::new(2.0, 0.0, 2.0)).length() < 1e-12);
    assert!((s.origin - DVec3::new(2.0, 0.0, 0.0)).length() < 1e-12);
    assert!(extrude(&mut points, &lot, DVec3::X, 3.0).is_err());
    assert!(extrude(&mut points, &lot, DVec3::Y, f64::NAN).is_err());
}

#[test]
fn comp_of_a_box_gives_each_side_once_with_up_facades() {
    let mut points = Points::new();
    let s = sized(DVec3::ZERO, DVec3::new(2.0, 3.0, 4.0));
    let b = box_in(&mut points, &s).unwrap();
    for name in ["front", "back", "left", "right", "top", "bottom"] {
        let sel = Selector::parse(name).unwrap();
        let faces = comp_faces(&points, &b, &s, sel);
        assert_eq!(faces.len(), 1, "{name}");
        let (g, fs) = &faces[0];
        assert_eq!(g.dim, 2);
        assert_eq!(
            g.faces[0],
            *b.faces.iter().find(|f| f.pts == g.faces[0].pts).unwrap()
        );
        assert_eq!(fs.size.z, 0.0);
    }
    let sides = comp_faces(&points, &b, &s, Selector::Side);
    assert_eq!(sides.len(), 4);
    for (_, fs) in &sides {
        assert!((fs.axes[1] - DVec3::Y).length() < 1e-12);
        assert!(fs.axes[2].y.abs() < 1e-12);
        assert!((fs.size.y - 3.0).abs() < 1e-12);
    }
    let (_, front) = &comp_faces(&points, &b, &s, Selector::Front)[0];
    assert!((front.size - DVec3::new(2.0, 3.0, 0.0)).length() < 1e-12);
    assert!((front.origin - DVec3::new(0.0, 0.0, 4.0)).length() < 1e-12);
    assert_eq!(comp_faces(&points, &b, &s, Selector::Horizontal).len(), 2);
    assert_eq!(comp_faces(&points, &b, &s, Selector::All).len(), 6);
    // 12 edges and 8 vertices.
    let edges = comp_edges(&points, &b, &s);
    assert_eq!(edges.len(), 12);
    for (g, es) in &edges {
        let [a, c] = g.edges[0];
        let e = points.get(c) - points.get(a);
        assert!((es.axes[0] * es.size.x - e).length() < 1e-12);
    }
    assert_eq!(comp_vertices(&points, &b, &s).len(), 8);
    assert_eq!(Selector::parse("sideways"), None);
}

#[test]
fn classify_by_the_dominant_component_with_y_then_z_winning_ties() {
    assert_eq!(Selector::classify(DVec3::ONE), Selector::Top);
    assert_eq!(
        Selector::classify(DVec3::new(1.0, -1.0, 0.0)),
        Selector::Bottom
    );
    assert_eq!(
        Selector::classify(DVec3::new(1.0, 0.0, -1.0)),
        Selector::Back
    );
    assert_eq!(
        Selector::classify(DVec3::new(-2.0, 1.0, 1.0)),
        Selector::Left
    );
    assert_eq!(
        Selector::classify(DVec3::new(0.0, 0.2, 0.3)),
        Selector::Front
    );
    assert_eq!(
        Selector::classify(DVec3::new(0.5, 0.2, 0.3)),
        Selector::Right
    );
}

#[test]
fn cuts_are_shared_and_resolved_in_chains() {
    let mut points = Points::new();
    let a = points.add(DVec3::ZERO).unwrap();
    let b = points.add(DVec3::new(1.0, 0.0, 0.0)).unwrap();
    let c = points.add(DVec3::new(0.0, 1.0, 0.0)).unwrap();
    let m = points.cut(a, b, DVec3::X, 0.5).unwrap();
    assert_eq!(points.cut(b, a, DVec3::X, 0.5).unwrap(), m);
    assert_eq!(points.get(m), DVec3::new(0.5, 0.0, 0.0));
    // A cut on a cut, and a sibling's cut of the whole edge by the
    // same plane: one point each.
    let q = points.cut(a, m, DVec3::X, 0.25).unwrap();
    assert_eq!(points.cut(a, b, DVec3::X, 0.25).unwrap(), q);
    let r = points.cut(m, b, DVec3::X, 0.75).unwrap();
    let mut out = Vec::new();
    points.resolve(&[a, b, c], &mut out);
    assert_eq!(out, vec![a, q, m, r, b, c]);
    points.resolve(&[c, b, a], &mut out);
    assert_eq!(out, vec![c, b, r, m, q, a]);
    points.resolve(&[q, r, c], &mut out);
    assert_eq!(out, vec![q, m, r, c]);
    assert_eq!(points.len(), 6);
}

#[test]
fn bad_input_gives_errors_not_panics() {
    let mut points = Points::new();
    assert!(points.add(DVec3::new(f64::NAN, 0.0, 0.0)).is_err());
    let b = unit_box(&mut points);
    assert!(plane_cut(&mut points, &b, DVec3::ZERO, 0.5, 1, 1e-9).is_err());
    assert!(plane_cut(&mut points, &b, DVec3::X, f64::NAN, 1, 1e-9).is_err());
    assert!(plane_cut(&mut points, &b, DVec3::X, 0.5, 0, 1e-9).is_err());
    assert!(split(&mut points, &b, DVec3::ZERO, DVec3::X, &[0.7, 0.3], 1).is_err());
    let e = Geometry::empty(3);
    let pieces = split(&mut points, &e, DVec3::ZERO, DVec3::X, &[0.5], 1).unwrap();
    assert!(pieces.iter().all(Geometry::is_empty));
    // Cuts outside the shape give empty pieces.
    let pieces = split(&mut points, &b, DVec3::ZERO, DVec3::X, &[-1.0, 2.0], 1).unwrap();
    assert!(pieces[0].is_empty() && pieces[2].is_empty());
    assert_eq!(pieces[1].faces.len(), 6);
    let ghost = Geometry {
        verts: vec![999],
        ..Geometry::empty(0)
    };
    assert!(plane_cut(&mut points, &ghost, DVec3::X, 0.5, 1, 1e-9).is_err());
    let bs = bounding_scope(&points, &e, Scope::world().axes);
    assert_eq!(bs.size, DVec3::ZERO);
    let nan = DAffine3::from_translation(DVec3::NAN);
    assert!(transform(&mut points, &b, &nan).is_err());
}

#[test]
fn transform_copies_onto_new_points_and_keeps_faces_outward() {
    let mut points = Points::new();
    let b = unit_box(&mut points);
    let mirror = DAffine3::from_scale(DVec3::new(-2.0, 1.0, 1.0));
    let t = transform(&mut points, &b, &mirror).unwrap();
    let old: HashSet<PointId> = b.point_ids().collect();
    assert!(t.point_ids().all(|p| !old.contains(&p)));
    assert_eq!(t.unique_points().len(), 8);
    assert_closed(&face_lists(&t));
    assert!((volume(&points, &t) - 2.0).abs() < 1e-12);
}

#[test]
fn lower_dimensions_split_too() {
    let mut points = Points::new();
    let a = points.add(DVec3::ZERO).unwrap();
    let b = points.add(DVec3::new(2.0, 0.0, 0.0)).unwrap();
    let edge = Geometry {
        edges: vec![[a, b]],
        ..Geometry::empty(1)
    };
    let (lo, hi) = plane_cut(&mut points, &edge, DVec3::X, 0.5, 1, 1e-9).unwrap();
    let m = lo.edges[0][1];
    assert_eq!(lo.edges, vec![[a, m]]);
    assert_eq!(hi.edges, vec![[m, b]]);
    assert_eq!(points.get(m).x, 0.5);
    let pts = Geometry {
        verts: vec![a, b, m],
        ..Geometry::empty(0)
    };
    let (lo, hi) = plane_cut(&mut points, &pts, DVec3::X, 0.5, 2, 1e-9).unwrap();
    assert_eq!(lo.verts, vec![a, m]);
    assert_eq!(hi.verts, vec![b]);
}

/// The S0/S1 case: a 2 x 4 x 2 box split at x = 1 (cut 1); the left
/// part split at y = 1 (cut 2), the right part at y = 2 (cut 3), in
/// the order asked; both lower parts welded, cut 1's wall refined by
/// the planes of the splits that crossed it, in the order they ran.
fn s0_s1(right_first: bool, loose: &[u32]) -> (Points, Welded) {
    let mut points = Points::new();
    let b = box_in(&mut points, &sized(DVec3::ZERO, DVec3::new(2.0, 4.0, 2.0))).unwrap();
    let halves = split(&mut points, &b, DVec3::ZERO, DVec3::X, &[1.0], 1).unwrap();
    let right_origin = DVec3::new(1.0, 0.0, 0.0);
    let mut planes = Vec::new();
    let mut left = None;
    let mut right = None;
    for step in 0..2 {
        if (step == 0) != right_first {
            left = Some(split(&mut points, &halves[0], DVec3::ZERO, DVec3::Y, &[1.0], 2).unwrap());
            planes.push(plane_of(DVec3::ZERO, DVec3::Y, 1.0));
        } else {
            right =
                Some(split(&mut points, &halves[1], right_origin, DVec3::Y, &[2.0], 3).unwrap());
            planes.push(plane_of(right_origin, DVec3::Y, 2.0));
        }
    }
    let (left, right) = (left.unwrap(), right.unwrap());
    assert!((volume(&points, &left[0]) - 2.0).abs() < 1e-12);
    assert!((volume(&points, &right[0]) - 4.0).abs() < 1e-12);
    // The lower left part holds caps of cuts 1 and 2, the right one of
    // cuts 1 and 3.
    assert_eq!(seams_of(&left[0]).collect::<Vec<_>>(), vec![1, 2]);
    assert_eq!(seams_of(&right[0]).collect::<Vec<_>>(), vec![1, 3]);
    let seam_planes: HashMap<u32, Vec<(DVec3, f64)>> = [(1, planes)].into_iter().collect();
    let w = weld(
        &mut points,
        &[&left[0], &right[0]],
        &[],
        &loose.iter().copied().collect(),
        &seam_planes,
    )
    .unwrap();
    (points, w)
}

#[test]
fn a_wall_cut_later_on_one_side_only_is_refined_on_both() {
    let (points, w) = s0_s1(false, &[]);
    // Every edge in two faces: closed, and no T-junction (a vertex in
    // the middle of another face's edge would leave that edge in one).
    assert_closed(&w.soup.faces.to_vecs());
    // [0, 1] x [0, 1] x [0, 2] and [1, 2] x [0, 2] x [0, 2].
    let v = 1.0 * 1.0 * 2.0 + 1.0 * 2.0 * 2.0;
    assert!((volume(&points, &soup_geometry(&w)) - v).abs() < 1e-12);
    // The wall's part against the left piece went; its part above
    // y = 1 stayed, facing -x.
    let walls: Vec<DVec3> = w
        .soup
        .faces
        .iter()
        .filter(|f| f.iter().all(|&v| w.soup.positions[v as usize].x == 1.0))
        .map(|f| {
            let ids: Vec<PointId> = f.iter().map(|&v| w.point_of[v as usize]).collect();
            newell(&points, &ids)
        })
        .collect();
    assert_eq!(walls.len(), 1);
    assert!(walls[0].x < 0.0);
}

#[test]
fn the_order_of_splits_does_not_change_positions() {
    let sorted = |points: &Points, w: &Welded| {
        let mut v: Vec<[u64; 3]> = w
            .point_of
            .iter()
            .map(|&p| {
                let q = points.get(p);
                [q.x.to_bits(), q.y.to_bits(), q.z.to_bits()]
            })
            .collect();
        v.sort_unstable();
        v
    };
    let (pa, wa) = s0_s1(false, &[]);
    let (pb, wb) = s0_s1(true, &[]);
    assert_closed(&wb.soup.faces.to_vecs());
    assert_eq!(sorted(&pa, &wa), sorted(&pb, &wb));
    assert_eq!(wa.soup.faces.len(), wb.soup.faces.len());
    // Every point of the derivation too (the right piece's removed
    // upper part included).
    let all = |p: &Points| {
        let mut v: Vec<[u64; 3]> = p
            .pos
            .iter()
            .map(|q| [q.x.to_bits(), q.y.to_bits(), q.z.to_bits()])
            .collect();
        v.sort_unstable();
        v
    };
    assert_eq!(all(&pa), all(&pb));
}

#[test]
fn a_cut_on_a_root_is_found_from_any_piece_and_placed_from_its_canonical_end() {
    let mut points = Points::new();
    // Made in the order b, a: a (the smaller x) is the canonical end.
    let b = points.add(DVec3::new(3.0, 0.0, 0.0)).unwrap();
    let a = points.add(DVec3::new(0.0, 0.0, 0.0)).unwrap();
    let m = points.cut(b, a, DVec3::X, 2.0).unwrap();
    let q = points.cut(a, b, DVec3::X, 1.0).unwrap();
    // The plane x = 2 asked again from the piece (q, b): the same point.
    assert_eq!(points.cut(q, b, DVec3::X, 2.0).unwrap(), m);
    assert_eq!(points.cut(b, q, DVec3::X, 2.0).unwrap(), m);
    // t = 2/3 and 1/3 along a -> b.
    assert_eq!(
        points.get(m),
        DVec3::new(0.0 + (2.0f64 / 3.0) * 3.0, 0.0, 0.0)
    );
    assert_eq!(
        points.get(q),
        DVec3::new(0.0 + (1.0f64 / 3.0) * 3.0, 0.0, 0.0)
    );
    // Two planes on one root: both points, in order, on every piece.
    let c = points.add(DVec3::new(0.0, 1.0, 0.0)).unwrap();
    let mut out = Vec::new();
    points.resolve(&[b, a, c], &mut out);
    assert_eq!(out, vec![b, m, q, a, c]);
    points.resolve(&[q, b, c], &mut out);
    assert_eq!(out, vec![q, m, b, c]);
    assert_eq!(points.len(), 5);
}

/// Splits `g` (its scope `s`) in half along x, pieces with their scopes
/// (the origin moved as a split moves it).
fn halve(
    points: &mut Points,
    g: &Geometry,
    s: Scope,
    cut: u32,
) -> Result<Vec<(Geometry, Scope)>, String> {
    let half = s.size.x / 2.0;
    let pieces = split(points, g, s.origin, s.axes[0], &[half], cut)?;
    let mut off = 0.0;
    let mut out = Vec::new();
    for p in pieces {
        let mut sc = s;
        sc.origin += s.axes[0] * off;
        sc.size.x = half;
        off += half;
        out.push((p, sc));
    }
    Ok(out)
}

#[test]
fn repeated_halving_gives_closed_pieces_of_the_right_volumes() {
    let mut points = Points::new();
    let s = sized(DVec3::ZERO, DVec3::new(8.0, 1.0, 1.0));
    let b = box_in(&mut points, &s).unwrap();
    let mut work = vec![(b, s)];
    let mut cut = 1;
    for _ in 0..9 {
        let mut next = Vec::new();
        for (g, s) in &work {
            next.extend(halve(&mut points, g, *s, cut).unwrap());
            cut += 1;
        }
        work = next;
    }
    // 2^9 = 512 pieces of 8/512 x 1 x 1.
    assert_eq!(work.len(), 512);
    for (g, _) in &work {
        assert_closed(&face_lists(g));
        assert!((volume(&points, g) - 8.0 / 512.0).abs() < 1e-12);
    }
    let members: Vec<&Geometry> = work.iter().map(|(g, _)| g).collect();
    let w = weld(&mut points, &members, &[], &HashSet::new(), &HashMap::new()).unwrap();
    assert_closed(&w.soup.faces.to_vecs());
    assert!((volume(&points, &soup_geometry(&w)) - 8.0).abs() < 1e-9);
    // 8 corners and 4 points on each of the 511 walls.
    assert_eq!(w.soup.positions.len(), 8 + 4 * 511);
}

#[test]
fn halving_past_the_precision_of_the_numbers_does_not_fail() {
    // The last piece halved again and again (a runaway grammar): past
    // the cut tolerance a piece stops being cut (it goes whole below),
    // and nothing fails.
    let mut points = Points::new();
    let s = sized(DVec3::ZERO, DVec3::new(8.0, 1.0, 1.0));
    let b = box_in(&mut points, &s).unwrap();
    let mut cur = (b, s);
    let mut kept = Vec::new();
    for cut in 1..=80 {
        let mut two = halve(&mut points, &cur.0, cur.1, cut).unwrap();
        cur = two.pop().unwrap();
        kept.push(two.pop().unwrap().0);
    }
    kept.push(cur.0);
    let mut total = 0.0;
    for (i, g) in kept.iter().enumerate() {
        if g.is_empty() {
            continue;
        }
        assert_closed(&face_lists(g));
        let v = volume(&points, g);
        assert!(v > 0.0);
        // While a half is well above the tolerance it is exact.
        if i < 20 {
            assert!((v - 8.0 / 2f64.powi(i as i32 + 1)).abs() < 1e-12);
        }
        total += v;
    }
    assert!((total - 8.0).abs() < 1e-12);
}

#[test]
fn cut_positions_do_not_depend_on_the_order_of_cuts_or_ids() {
    // Two planes cross a segment; run A makes its ends in one order and
    // cuts at plane 1 then plane 2 (on the piece left over), run B
    // makes the ends the other way round and cuts at plane 2 first.
    // The same geometric points must come out bit for bit.
    let mut rng = Lcg(7);
    let mut r = |s: f64| (rng.next() - 0.5) * s;
    for _ in 0..500 {
        let a = DVec3::new(r(10.0), r(10.0), r(10.0));
        let b = DVec3::new(r(10.0), r(10.0), r(10.0));
        let n = DVec3::new(r(2.0), r(2.0), r(2.0)) + (b - a).normalize();
        let (t1, t2) = (0.1 + 0.35 * (r(1.0) + 0.5), 0.55 + 0.35 * (r(1.0) + 0.5));
        let d1 = n.dot(a + t1 * (b - a));
        let d2 = n.dot(a + t2 * (b - a));
        let mut pa = Points::new();
        let (ia, ib) = (pa.add(a).unwrap(), pa.add(b).unwrap());
        let m = pa.cut(ia, ib, n, d1).unwrap();
        let q = pa.cut(m, ib, n, d2).unwrap();
        let mut pb = Points::new();
        let (jb, ja) = (pb.add(b).unwrap(), pb.add(a).unwrap());
        let q2 = pb.cut(jb, ja, n, d2).unwrap();
        let m2 = pb.cut(ja, q2, n, d1).unwrap();
        assert_eq!(pa.get(m), pb.get(m2));
        assert_eq!(pa.get(q), pb.get(q2));
    }
}

#[test]
fn walls_refined_by_crossing_planes_from_both_sides_still_match() {
    // A 2 x 4 x 2 box split at x = 1 (cut 1); the left part split at
    // y = 1 (cut 2), the right part at z = 1 (cut 3): the wall's
    // refinement puts a point where the two lines cross, reached along
    // the y = 1 line on one side and along the z = 1 line on the other.
    for right_first in [false, true] {
        let mut points = Points::new();
        let b = box_in(&mut points, &sized(DVec3::ZERO, DVec3::new(2.0, 4.0, 2.0))).unwrap();
        let halves = split(&mut points, &b, DVec3::ZERO, DVec3::X, &[1.0], 1).unwrap();
        let ro = DVec3::new(1.0, 0.0, 0.0);
        let (mut left, mut right, mut planes) = (None, None, Vec::new());
        for step in 0..2 {
            if (step == 0) != right_first {
                left =
                    Some(split(&mut points, &halves[0], DVec3::ZERO, DVec3::Y, &[1.0], 2).unwrap());
                planes.push(plane_of(DVec3::ZERO, DVec3::Y, 1.0));
            } else {
                right = Some(split(&mut points, &halves[1], ro, DVec3::Z, &[1.0], 3).unwrap());
                planes.push(plane_of(ro, DVec3::Z, 1.0));
            }
        }
        let (left, right) = (left.unwrap(), right.unwrap());
        let seam_planes: HashMap<u32, Vec<(DVec3, f64)>> = [(1, planes)].into_iter().collect();
        let w = weld(
            &mut points,
            &[&left[0], &right[0]],
            &[],
            &HashSet::new(),
            &seam_planes,
        )
        .unwrap();
        assert_closed(&w.soup.faces.to_vecs());
        // [0, 1] x [0, 1] x [0, 2] and [1, 2] x [0, 4] x [0, 1].
        let v = 1.0 * 1.0 * 2.0 + 1.0 * 4.0 * 1.0;
        assert!((volume(&points, &soup_geometry(&w)) - v).abs() < 1e-12);
    }
}

#[test]
fn a_loose_wall_cut_on_one_side_only_opens_where_both_sides_meet() {
    let (points, w) = s0_s1(false, &[1]);
    // Both parts closed on their own: the pair of wall pieces that
    // mirror each other stays, the right part on copies of its points.
    assert_closed(&w.soup.faces.to_vecs());
    assert!((volume(&points, &soup_geometry(&w)) - 6.0).abs() < 1e-12);
    // The left part's 8 corners, the right part's 8 corners (2 of them
    // copies) and its 2 copied points at y = 1 on the wall: 18, and
    // the 4 corners of the mirrored piece twice.
    assert_eq!(w.soup.positions.len(), 18);
    let mut at: HashMap<[u64; 3], usize> = HashMap::new();
    for p in &w.soup.positions {
        *at.entry([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
            .or_default() += 1;
    }
    assert_eq!(at.values().filter(|&&k| k == 2).count(), 4);
    // Left: 6 faces; right: 5 outer faces and its wall in 2 pieces.
    assert_eq!(w.soup.faces.len(), 13);
}
