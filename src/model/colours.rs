//! Colour maps (`.map`) and materials (`.mat`): the 256 colours that
//! `SetColor(i)`, `IncColor()` and `DecColor()` choose from, and the
//! background, which is entry 0 in both.
//!
//! A `.map` file is 768 bytes: 256 RGB triplets. A `.mat` file is a run of
//! 15-byte records: the index, the transparency, then ambient, diffuse,
//! emission and specular RGB and the shininess; an index the file does
//! not set keeps the default material (ambient 0.2, diffuse 0.8 grey).
//! lpfg clears its window to material 0's emission colour, and lights
//! materials with OpenGL's lighting (a global ambient light of 0.2, then
//! the view file's lights, by default one white light from the viewer).
//! subgram's 2D pictures draw flat: a material's colour is what that
//! lighting gives a surface facing the viewer: emission + ambient × (0.2 +
//! Σ light ambient) + diffuse × Σ light diffuse × cos(light, view
//! direction). Its 3D pictures light each surface by its normal
//! (`render::raster`), with the same lights.

use super::error::ModelError as Error;

/// The bytes of one material record after its index byte.
const RECORD: usize = 15;

/// One material, its colours as bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Material {
    pub transparency: u8,
    pub ambient: [u8; 3],
    pub diffuse: [u8; 3],
    pub emission: [u8; 3],
    pub specular: [u8; 3],
    pub shininess: u8,
}

impl Default for Material {
    /// lpfg's and medit's default: grey, ambient 0.2, diffuse 0.8.
    fn default() -> Self {
        Material {
            transparency: 0,
            ambient: [51, 51, 51],
            diffuse: [204, 204, 204],
            emission: [0, 0, 0],
            specular: [0, 0, 0],
            shininess: 0,
        }
    }
}

/// The colours of a model: a colour map or a material set.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Colours {
    Map(Box<[[u8; 3]; 256]>),
    Materials(Box<[Material; 256]>),
}

impl Colours {
    /// The colour of index `i` (taken modulo 256) as subgram draws it,
    /// materials lit by `lights` (lpfg's default light when empty).
    pub fn colour(&self, i: i64, lights: &[super::view::Light]) -> [u8; 3] {
        let i = i.rem_euclid(256) as usize;
        let m = match self {
            Colours::Map(m) => return m[i],
            Colours::Materials(m) => m[i],
        };
        let default = [super::view::Light::default()];
        let lights = if lights.is_empty() {
            &default[..]
        } else {
            lights
        };
        [0, 1, 2].map(|k| {
            let f = |b: u8| b as f64 / 255.0;
            let mut c = f(m.emission[k]) + f(m.ambient[k]) * 0.2;
            for l in lights {
                let d = l.direction;
                let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                let facing = if len > 0.0 {
                    (d[2] / len).max(0.0)
                } else {
                    0.0
                };
                c += f(m.ambient[k]) * l.ambient[k] + f(m.diffuse[k]) * l.diffuse[k] * facing;
            }
            (c.clamp(0.0, 1.0) * 255.0).round() as u8
        })
    }

    /// The background: colour 0 of a map, material 0's emission.
    pub fn background(&self) -> [u8; 3] {
        match self {
            Colours::Map(m) => m[0],
            Colours::Materials(m) => m[0].emission,
        }
    }
}

/// Reads a colour map: exactly 768 bytes.
pub fn read_map(path: &str, bytes: &[u8]) -> Result<Colours, Error> {
    if bytes.len() != 768 {
        return Err(Error::file(
            path,
            format!(
                "a colour map is 768 bytes (256 RGB triplets), but the file has {}",
                bytes.len()
            ),
        ));
    }
    let mut m = Box::new([[0u8; 3]; 256]);
    for (i, c) in bytes.chunks_exact(3).enumerate() {
        m[i] = [c[0], c[1], c[2]];
    }
    Ok(Colours::Map(m))
}

/// Reads a material file: whole 15-byte records, at most one per index.
pub fn read_mat(path: &str, bytes: &[u8]) -> Result<Colours, Error> {
    if bytes.is_empty() || !bytes.len().is_multiple_of(RECORD) {
        return Err(Error::file(
            path,
            format!(
                "a material file is made of 15-byte records, but the file has {} bytes{}",
                bytes.len(),
                if bytes.is_empty() {
                    String::new()
                } else {
                    let whole = bytes.len() / RECORD;
                    format!(
                        " ({whole} whole record{} and {} bytes over)",
                        if whole == 1 { "" } else { "s" },
                        bytes.len() % RECORD
                    )
                }
            ),
        ));
    }
    let mut m = Box::new([Material::default(); 256]);
    for r in bytes.chunks_exact(RECORD) {
        let rgb = |k: usize| [r[k], r[k + 1], r[k + 2]];
        m[r[0] as usize] = Material {
            transparency: r[1],
            ambient: rgb(2),
            diffuse: rgb(5),
            emission: rgb(8),
            specular: rgb(11),
            shininess: r[14],
        };
    }
    Ok(Colours::Materials(m))
}
