//! Shaded 3D geometry: what a plant's turtle makes in 3D (tubes, Bézier
//! surfaces, generalized cylinders, polygons, spheres, discs) and what a
//! mesh from `subdivide` is, for the z-buffer renderer and the exporters
//! (OBJ with MTL, PLY, binary glTF).
//!
//! The geometry is one indexed triangle mesh per look (a colour of the
//! model's map or one of its materials), in single precision, as the
//! exporters and the renderer use it.

use glam::Vec3;

/// How a surface looks: lpfg's material model (OpenGL's fixed-function
/// lighting). A colour of a `.map` file is a look whose ambient and
/// diffuse are that colour.
#[derive(Clone, Debug, PartialEq)]
pub struct Look {
    /// The name the exporters give it (`colour7`, `material12`).
    pub name: String,
    /// The colour index the turtle chose (`SetColor`), for reference.
    pub index: i64,
    /// Colours from 0 to 1.
    pub ambient: [f32; 3],
    pub diffuse: [f32; 3],
    pub specular: [f32; 3],
    pub emission: [f32; 3],
    /// OpenGL's exponent, 0 to 128.
    pub shininess: f32,
    /// 1 opaque, 0 invisible.
    pub opacity: f32,
}

impl Look {
    /// A plain colour (a colour map's entry, or the default palette's):
    /// ambient and diffuse that colour, no specular.
    pub fn colour(name: impl Into<String>, index: i64, rgb: [u8; 3]) -> Look {
        let c = rgb.map(|b| b as f32 / 255.0);
        Look {
            name: name.into(),
            index,
            ambient: c,
            diffuse: c,
            specular: [0.0; 3],
            emission: [0.0; 3],
            shininess: 0.0,
            opacity: 1.0,
        }
    }
}

/// An indexed triangle mesh of one look. `normals` is empty for flat
/// shading, or has one unit normal per position for smooth shading.
///
/// `lines` are for pictures only: tubes thinner than a pixel, which the
/// geometry of a picture keeps as their axes (see
/// the drawing's `SolidOptions::picture_pixel` and [`Line`]); the
/// exporters refuse a scene that has any.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub lines: Vec<Line>,
}

/// A tube thinner than a pixel, kept as its axis from `a` to `b` with its
/// diameter `width`. The z-buffer draws it on its samples along the axis,
/// one sample wide, each with the chance that the tube covers it (its
/// width in samples, at most one), so that the ink of many thin twigs is
/// what their tubes would cover; it is lit as the side of the tube that
/// faces the viewer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    pub a: Vec3,
    pub b: Vec3,
    pub width: f32,
}

impl TriMesh {
    /// The axis-aligned bounds of its positions and lines, `None` when it
    /// has neither.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first =
            (self.positions.first().copied()).or_else(|| self.lines.first().map(|l| l.a))?;
        let (mut lo, mut hi) = (first, first);
        for &p in &self.positions {
            (lo, hi) = (lo.min(p), hi.max(p));
        }
        for l in &self.lines {
            (lo, hi) = (lo.min(l.a).min(l.b), hi.max(l.a).max(l.b));
        }
        Some((lo, hi))
    }

    /// Its vertices' positions, then its lines' ends.
    pub fn points(&self) -> impl Iterator<Item = Vec3> + '_ {
        (self.positions.iter().copied()).chain(self.lines.iter().flat_map(|l| [l.a, l.b]))
    }
}

/// A scene of shaded geometry: one mesh per look, in the order the looks
/// were first used.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene3 {
    pub looks: Vec<Look>,
    /// `meshes[k]` is drawn with `looks[k]`.
    pub meshes: Vec<TriMesh>,
}

impl Scene3 {
    /// The number of triangles over all meshes.
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.triangles.len()).sum()
    }

    /// The number of vertices over all meshes.
    pub fn vertex_count(&self) -> usize {
        self.meshes.iter().map(|m| m.positions.len()).sum()
    }

    /// The number of lines over all meshes (see [`TriMesh::lines`]).
    pub fn line_count(&self) -> usize {
        self.meshes.iter().map(|m| m.lines.len()).sum()
    }

    /// Every mesh's points (see [`TriMesh::points`]): what a camera frames.
    pub fn points(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.meshes.iter().flat_map(TriMesh::points)
    }

    /// The bounds of every mesh, `None` when there is no vertex or line.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.meshes
            .iter()
            .filter_map(TriMesh::bounds)
            .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
    }

    /// The mesh drawn with `look`, made on first use.
    pub fn mesh_for(&mut self, look: Look) -> &mut TriMesh {
        let k = match self.looks.iter().position(|l| *l == look) {
            Some(k) => k,
            None => {
                self.looks.push(look);
                self.meshes.push(TriMesh::default());
                self.looks.len() - 1
            }
        };
        &mut self.meshes[k]
    }
}
