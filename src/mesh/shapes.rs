//! Standard meshes built in code: for tests, benchmarks and examples.

use glam::DVec3;

use super::soup::PolygonSoup;

/// A regular icosahedron on the unit sphere.
pub fn icosahedron() -> PolygonSoup {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let raw = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ];
    let faces: [[u32; 3]; 20] = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    PolygonSoup {
        positions: raw
            .iter()
            .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
            .collect(),
        faces: faces.iter().map(|f| f.to_vec()).collect(),
        ..Default::default()
    }
}

/// An icosphere: the icosahedron with every triangle split in four
/// `levels` times, new points pushed to the unit sphere. 20·4^levels faces.
pub fn icosphere(levels: u32) -> PolygonSoup {
    let mut s = icosahedron();
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut faces = crate::mesh::Faces::with_capacity(s.faces.len() * 4, s.faces.len() * 12);
        let mut m = |a: u32, b: u32, pos: &mut Vec<DVec3>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                pos.push(((pos[a as usize] + pos[b as usize]) * 0.5).normalize());
                pos.len() as u32 - 1
            })
        };
        for f in &s.faces {
            let (a, b, c) = (f[0], f[1], f[2]);
            let ab = m(a, b, &mut s.positions);
            let bc = m(b, c, &mut s.positions);
            let ca = m(c, a, &mut s.positions);
            faces.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        s.faces = faces;
    }
    s
}

/// A torus of `n` × `m` quads (radii 1 and 0.35).
pub fn quad_torus(n: usize, m: usize) -> PolygonSoup {
    let mut s = PolygonSoup::default();
    for i in 0..n {
        for j in 0..m {
            let (u, v) = (
                i as f64 / n as f64 * std::f64::consts::TAU,
                j as f64 / m as f64 * std::f64::consts::TAU,
            );
            let r = 1.0 + 0.35 * v.cos();
            s.positions
                .push(DVec3::new(r * u.cos(), r * u.sin(), 0.35 * v.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    for i in 0..n {
        for j in 0..m {
            s.faces
                .push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    s
}

/// A flat grid of `n` × `m` quads in the unit square (an open mesh).
pub fn quad_grid(n: usize, m: usize) -> PolygonSoup {
    let mut s = PolygonSoup::default();
    for j in 0..=m {
        for i in 0..=n {
            s.positions
                .push(DVec3::new(i as f64 / n as f64, j as f64 / m as f64, 0.0));
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    for j in 0..m {
        for i in 0..n {
            s.faces
                .push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    s
}

/// The same grid with each quad split into two triangles.
pub fn triangle_grid(n: usize, m: usize) -> PolygonSoup {
    quad_grid(n, m).fanned()
}
