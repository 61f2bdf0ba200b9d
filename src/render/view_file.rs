//! A model's view file (`.v`) as the renderer's settings: the camera of
//! its `view:` lines and its lights, lpfg's defaults where it says
//! nothing. (The model folder's reader, `model::view`, knows nothing of
//! the renderer.)

use crate::model::view::{Light, RenderMode, ViewCamera};

impl ViewCamera {
    /// The renderer's view: lpfg's defaults where the file says nothing.
    pub fn spec(&self) -> super::raster::ViewSpec {
        use super::raster::{Projection, ViewSpec};
        use glam::Vec3;
        let v = |a: [f64; 3]| Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32);
        let d = ViewSpec::default();
        ViewSpec {
            dir: self.dir.map(v).unwrap_or(d.dir),
            up: self.up.map(v).unwrap_or(d.up),
            projection: if self.perspective {
                Projection::Perspective
            } else {
                Projection::Parallel
            },
            fov: self.fov.map_or(d.fov, |f| f as f32),
            scale: self.scale.map_or(d.scale, |s| s as f32),
            pan: self.pan.map(v).unwrap_or(d.pan),
            shift: self.shift.map(|s| s as f32),
            bounds: self.bbox.map(|b| {
                (
                    Vec3::new(b[0] as f32, b[2] as f32, b[4] as f32),
                    Vec3::new(b[1] as f32, b[3] as f32, b[5] as f32),
                )
            }),
            clip: self.front.zip(self.back).map(|(f, b)| (f as f32, b as f32)),
            tight: false,
        }
    }
}

impl ViewCamera {
    /// The renderer's settings for geometry within the box `bounds` (the
    /// lowest and highest corners; `None` for no geometry), in an image of
    /// `width`×`height`: the camera of [`ViewCamera::spec`], the view
    /// file's `lights` (see [`raster_lights`]), and lit shading for
    /// `render mode: shaded` or `shadows`, unlit colours for `filled`
    /// (lpfg's default) and `wireframe`. (The camera frames the box: a
    /// view file's camera is never fitted to the outline on screen.)
    pub fn raster_options(
        &self,
        lights: &[Light],
        bounds: Option<(glam::Vec3, glam::Vec3)>,
        width: u32,
        height: u32,
    ) -> Result<super::raster::RasterOptions, super::RenderError> {
        use super::raster::{Camera, RasterOptions, Shading};
        let spec = self.spec();
        debug_assert!(!spec.tight, "the box's corners stand for the points");
        let mut corners = bounds.into_iter().flat_map(|(lo, hi)| [lo, hi]);
        let camera = Camera::from_view(&spec, &mut corners, width, height)?;
        Ok(RasterOptions {
            lights: raster_lights(lights),
            shading: match self.render_mode {
                RenderMode::Shaded | RenderMode::Shadows => Shading::Lit,
                RenderMode::Filled | RenderMode::Wireframe => Shading::Unlit,
            },
            ..RasterOptions::new(camera)
        })
    }
}

/// The renderer's lights for the view file's (lpfg's default light when
/// there is none): directional lights in eye coordinates, as lpfg's
/// stationary lights are. A point light (`O:`) shines from the direction
/// of its position.
pub fn raster_lights(lights: &[Light]) -> Vec<super::raster::Light> {
    let f = |a: [f64; 3]| a.map(|x| x as f32);
    let default = [Light::default()];
    let lights = if lights.is_empty() {
        &default[..]
    } else {
        lights
    };
    lights
        .iter()
        .map(|l| super::raster::Light {
            direction: glam::Vec3::from_array(f(l.direction)),
            ambient: f(l.ambient),
            diffuse: f(l.diffuse),
            specular: f(l.specular),
        })
        .collect()
}
