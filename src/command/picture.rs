//! Pictures: their format from a file name, a scene's or a mesh's bytes,
//! a curve's views, and where they go (`Out`: files, or memory for `serve`).

use std::path::{Path, PathBuf};

use super::common::{extension_hint, refuse_overwrite, write_file};
use super::render::RenderArgs;
use crate::error::Error;
use crate::mesh::{Mesh, PolygonSoup};
use crate::render::{self, Rgba, Scene};

/// A picture format, told by a file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Picture {
    Png,
    Svg,
}

impl Picture {
    /// `.png` or `.svg` (any case); any other name is a usage error.
    pub fn from_path(path: &Path) -> Result<Picture, Error> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("png") => Ok(Picture::Png),
            Some("svg") => Ok(Picture::Svg),
            _ => Err(Error::Usage(format!(
                "cannot tell the format of `{}`: name it .png or .svg{}",
                path.display(),
                extension_hint(path, &["png", "svg"])
            ))),
        }
    }
}

/// Draws `scene` in `format` and writes it to `path` whole, or not at all.
pub fn write_picture(scene: &Scene, path: &Path, format: Picture) -> Result<(), Error> {
    write_file(path, &picture_bytes(scene, format)?)
}

/// Writes the main view to `output` and each other view that the view
/// file names to `OUTPUT-NAME.EXT` beside it, all or none. Returns a
/// warning for each view that `UseView` activated and the view file does
/// not define (lpfg ignores those too).
pub(super) fn write_views(
    figures: crate::Figures<Vec<u8>>,
    program: &Path,
    output: &Path,
    force: bool,
    out: &mut Out,
) -> Result<Vec<String>, Error> {
    let names = crate::load::window_names(program);
    let mut files: Vec<(PathBuf, Vec<u8>)> = vec![(output.to_path_buf(), figures.main)];
    let mut warnings = Vec::new();
    for (view, picture) in figures.views {
        let name = usize::try_from(view)
            .ok()
            .and_then(|v| names.get(v))
            .filter(|n| crate::load::is_identifier(n));
        let Some(name) = name else {
            warnings.push(format!(
                "{}: warning: `UseView({view})`: the view file defines no view {view}, so it is not drawn",
                program.display()
            ));
            continue;
        };
        files.push((view_path(output, name), picture));
    }
    let outputs: Vec<&Path> = files.iter().map(|(p, _)| p.as_path()).collect();
    refuse_overwrite(&outputs, &[program], force)?;
    out.put(files)?;
    Ok(warnings)
}

/// `out.png` and view `Top`: `out-Top.png`, in the same folder.
fn view_path(output: &Path, name: &str) -> PathBuf {
    let stem = output.file_stem().unwrap_or_default().to_string_lossy();
    let file = match output.extension() {
        Some(ext) => format!("{stem}-{name}.{}", ext.to_string_lossy()),
        None => format!("{stem}-{name}"),
    };
    output.with_file_name(file)
}

/// `scene` drawn in `format`.
pub(super) fn picture_bytes(scene: &Scene, format: Picture) -> Result<Vec<u8>, Error> {
    Ok(match format {
        Picture::Svg => render::svg::render(scene).into_bytes(),
        Picture::Png => render::png::render(scene)?,
    })
}

/// Where pictures go: written to their files (atomically, all or none),
/// or kept in memory (`serve` writes nothing).
pub(super) enum Out {
    Files,
    Memory(Vec<(PathBuf, Vec<u8>)>),
}

impl Out {
    /// Writes, or keeps, every file or none.
    pub(super) fn put(&mut self, files: Vec<(PathBuf, Vec<u8>)>) -> Result<(), Error> {
        match self {
            Out::Files => {
                let all: Vec<(&Path, &[u8])> = files
                    .iter()
                    .map(|(p, b)| (p.as_path(), b.as_slice()))
                    .collect();
                crate::files::atomic::write_all_atomic(&all)
                    .map_err(|(path, e)| Error::write(path, e))
            }
            Out::Memory(kept) => {
                kept.extend(files);
                Ok(())
            }
        }
    }
}

/// How a mesh is drawn.
#[derive(Clone)]
pub(super) struct MeshLooks<'a> {
    pub(super) size: (u32, u32),
    pub(super) background: Rgba,
    pub(super) view: Option<&'a str>,
    pub(super) wireframe: bool,
    pub(super) shading: crate::render::mesh::Shading,
    /// One flat shade per face, not smoothed across faces.
    pub(super) flat: bool,
    /// Each face in a colour of its own, told apart from its neighbours:
    /// a vv program's cells.
    pub(super) cells: bool,
}

impl<'a> MeshLooks<'a> {
    /// How `render` draws a mesh: its size (800×800 by default),
    /// background (white by default), view and wireframe, lit.
    pub(super) fn of_render(a: &'a RenderArgs) -> MeshLooks<'a> {
        MeshLooks {
            size: a.size.unwrap_or((800, 800)),
            background: a.background.unwrap_or(Rgba(255, 255, 255, 255)),
            view: a.view.as_deref(),
            wireframe: a.wireframe,
            shading: crate::render::mesh::Shading::Lit,
            flat: a.flat,
            cells: false,
        }
    }
}

impl MeshLooks<'_> {
    /// These looks for a vv program's mesh: its cells each in a colour
    /// when it is a sheet of cells (see [`crate::render::mesh::has_cells`]).
    pub(super) fn for_vv(&self, soup: &PolygonSoup) -> Self {
        MeshLooks {
            cells: crate::render::mesh::has_cells(soup),
            ..self.clone()
        }
    }

    /// The view of `soups` (one mesh, or an animation's): [`MeshLooks::check`]'s,
    /// from the top when no view is named and every mesh lies in the xy
    /// plane (a sheet of cells).
    pub(super) fn view_of<'s>(
        &self,
        mut soups: impl Iterator<Item = &'s PolygonSoup>,
    ) -> Result<crate::render::mesh::MeshView, Error> {
        let mut mv = self.check()?;
        if self.view.is_none() && soups.all(crate::render::mesh::is_flat_in_z) {
            let (dir, up) = crate::render::mesh::view_direction("top").expect("a view");
            mv.direction = dir;
            mv.up = up;
        }
        Ok(mv)
    }

    /// The view: the default one, or a named one.
    pub(super) fn check(&self) -> Result<crate::render::mesh::MeshView, Error> {
        let mut mv = crate::render::mesh::MeshView {
            width: self.size.0,
            height: self.size.1,
            background: self.background,
            wireframe: self.wireframe,
            shading: self.shading,
            smooth: !self.flat,
            ..Default::default()
        };
        if let Some(name) = self.view {
            let Some((dir, up)) = crate::render::mesh::view_direction(name) else {
                return Err(Error::Usage(format!(
                    "`--view {name}` is not a view of a mesh: use iso, front, back, left, right, top or bottom"
                )));
            };
            mv.direction = dir;
            mv.up = up;
        }
        Ok(mv)
    }
}

/// A mesh's picture, to `.png` or `.svg`; its sharp edges stay sharp in
/// smooth shading.
pub(super) fn write_mesh_picture(
    m: &Mesh,
    output: &Path,
    looks: &MeshLooks,
    out: &mut Out,
) -> Result<(), Error> {
    let (soup, sharp) = m.to_soup_with_sharpness(false);
    let sharp: Vec<(u32, u32)> = sharp.edges.iter().map(|&(a, b, _)| (a, b)).collect();
    write_soup_picture_sharp(&soup, &sharp, output, looks, out)
}

pub(super) fn write_soup_picture(
    soup: &PolygonSoup,
    output: &Path,
    looks: &MeshLooks,
    out: &mut Out,
) -> Result<(), Error> {
    write_soup_picture_sharp(soup, &[], output, looks, out)
}

fn write_soup_picture_sharp(
    soup: &PolygonSoup,
    sharp: &[(u32, u32)],
    output: &Path,
    looks: &MeshLooks,
    out: &mut Out,
) -> Result<(), Error> {
    let format = Picture::from_path(output)?;
    let mut mv = looks.view_of(std::iter::once(soup))?;
    mv.sharp_edges = sharp.to_vec();
    if looks.cells {
        mv.face_colours = crate::render::mesh::cell_colours(soup);
    }
    crate::render::mesh::validate(soup, &mv)?;
    let bytes = match format {
        Picture::Svg => crate::render::mesh::render_svg(soup, &mv).into_bytes(),
        Picture::Png => crate::render::mesh::render_png(soup, &mv)?,
    };
    out.put(vec![(output.to_path_buf(), bytes)])
}
