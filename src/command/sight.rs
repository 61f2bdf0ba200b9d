//! What the live page (`subgram serve`) shows of a program: a 2D drawing
//! as the SVG that `render -o X.svg` writes, or 3D geometry for the
//! page's own WebGL view (a plant's tubes and surfaces as `render -o
//! X.glb` exports them; a grammar's, vv program's or shape grammar's mesh
//! with its polygons' edges) with the camera the command line's picture
//! would have, so that the page's first view is that picture's.

use std::path::Path;

use super::common::{load_options, write_program_files, writes_folder};
use super::picture::{MeshLooks, Picture};
use super::render::{
    picture_in_memory, solid_raster_options, solid_scene, wants_solid, RenderArgs,
};
use crate::deadline::Deadline;
use crate::error::Error;
use crate::mesh::soup::PolygonSoup;
use crate::render::raster::{Camera, Shading};
use crate::render::Rgba;
use crate::scene3::Scene3;
use crate::system::{RunOptions, System};

/// 3D geometry as the page draws it.
#[derive(Clone, Debug)]
pub struct Solid {
    /// The triangles, one mesh per look.
    pub scene: Scene3,
    /// Per mesh of `scene`, its polygons' edges (the wireframe); empty for
    /// a plant's geometry, whose wireframe is its triangles'.
    pub edges: Vec<Vec<[u32; 2]>>,
    /// The camera of the command line's picture (800×800).
    pub camera: Camera,
    /// Lit (a view file's `render mode: shaded`, every mesh), or the looks'
    /// colours as they are (lpfg's `filled`).
    pub lit: bool,
    pub background: Rgba,
    /// The up direction the view turns about: y for L-systems and shape
    /// grammars, z for meshes.
    pub up: [f32; 3],
    /// Shaded smooth (normals given, or averaged at shared vertices): a
    /// plant, a subdivision surface, a vv program's mesh; flat: a shape
    /// grammar's buildings.
    pub smooth: bool,
}

/// What the page shows.
#[derive(Clone, Debug)]
pub enum Sight {
    /// A 2D drawing: the SVG's text.
    Flat(String),
    Solid(Box<Solid>),
}

/// A sight and the program's warnings.
#[derive(Clone, Debug)]
pub struct Seen {
    pub sight: Sight,
    pub warnings: Vec<String>,
}

/// Derives the program with its text replaced by `text` (see
/// [`crate::load_edited`]) and returns what the page shows: an L-system's
/// 2D drawing as SVG (what [`super::render_edited`] draws for `page.svg`),
/// or 3D geometry (an L-system that [`super::Solidity`] draws in 3D, a
/// surface grammar's mesh, a vv program's, a shape grammar's shapes).
/// Writes nothing; a program's own files (`fopen`) are refused as without
/// `--allow-writes`.
pub fn sight_edited(a: &RenderArgs, text: &str) -> Result<Seen, Error> {
    let deadline = a.timeout.map(Deadline::after);
    let _deadline = crate::deadline::scope(deadline);
    let file = Path::new(&a.file);
    let mut a = a.clone();
    a.allow_writes = None;
    a.force = true;
    a.output = "page.svg".into();
    let looks = MeshLooks::of_render(&a);
    let (w, h) = looks.size;
    let white = Rgba(255, 255, 255, 255);
    // A mesh as the command line's picture shades it (`MeshLooks`: the
    // view, smooth or flat, sharp edges, a vv program's cells, a shape
    // grammar's colours), y up for a shape grammar's buildings.
    let mesh = |soup: &PolygonSoup,
                sharp: Vec<(u32, u32)>,
                looks: &MeshLooks,
                colours: &[Rgba],
                y_up: bool|
     -> Result<Sight, Error> {
        let mut mv = looks.view_of(std::iter::once(soup))?;
        mv.sharp_edges = sharp;
        if looks.cells {
            mv.face_colours = crate::render::mesh::cell_colours(soup);
        } else {
            mv.face_colours = colours.to_vec();
        }
        if y_up {
            let turn = |v: glam::DVec3| glam::DVec3::new(v.x, v.z, -v.y);
            mv.direction = turn(mv.direction);
            mv.up = turn(mv.up);
        }
        crate::render::mesh::validate(soup, &mv)?;
        let (scene, edges) = crate::render::mesh::viewer_scene3(soup, &mv);
        let camera = crate::render::mesh::camera(
            &mv,
            &mut crate::render::mesh::used_vertices(soup).map(|p| p.as_vec3()),
        )?;
        Ok(Sight::Solid(Box::new(Solid {
            scene,
            edges,
            camera,
            lit: true,
            background: a.background.unwrap_or(white),
            up: if y_up {
                [0.0, 1.0, 0.0]
            } else {
                mv.up.as_vec3().to_array()
            },
            smooth: mv.smooth,
        })))
    };
    // A mesh file: the edited text read as the mesh (OBJ, OFF, ASCII PLY).
    if let Some(format) = crate::mesh::io::Format::from_path(file) {
        let soup = crate::mesh::io::read_str(&a.file, format, text.as_bytes())?;
        let sight = mesh(&soup, Vec::new(), &looks, &[], false)?;
        return Ok(Seen {
            sight,
            warnings: Vec::new(),
        });
    }
    let system = crate::load::load_edited(
        file,
        text,
        &load_options(&a.defines, a.double, &a.environment),
    )?;
    let mut warnings = system.warnings();
    let sight = match system {
        System::Surface(s) => {
            let opts = RunOptions {
                steps: a.steps,
                deadline,
                ..RunOptions::default()
            };
            let run = s.subdivide(&opts, |_| {})?;
            let (soup, sharp) = run.mesh.to_soup_with_sharpness(false);
            let sharp = sharp.edges.iter().map(|&(a, b, _)| (a, b)).collect();
            mesh(&soup, sharp, &looks, &[], false)?
        }
        System::Vv(v) => {
            let dir = writes_folder(&a.allow_writes, &a.program_output)?;
            let opts = RunOptions {
                steps: a.steps,
                seed: a.seed,
                deadline,
                output: a.program_output.clone(),
                ..RunOptions::default()
            };
            let run = v.run(&opts, |_| {})?;
            write_program_files(&a.program_output, dir.as_deref(), &[file])?;
            mesh(&run.soup, Vec::new(), &looks.for_vv(&run.soup), &[], false)?
        }
        // Shape grammars: buildings, flat-shaded, y up.
        System::Shapes(s) => {
            let opts = RunOptions {
                seed: a.seed,
                deadline,
                ..RunOptions::default()
            };
            let run = s.derive(&opts)?;
            if run.soup.faces.is_empty() {
                return Err(Error::Failed(
                    "the derivation left no terminal shape with faces to draw".into(),
                ));
            }
            mesh(&run.soup, Vec::new(), &looks, &run.colours, true)?
        }
        System::Curve(c) if wants_solid(a.solid, &c) => {
            let (scene, dir) = solid_scene(&a, &c, (w, h), deadline, |_| {}, false)?;
            write_program_files(&a.program_output, dir.as_deref(), &[file])?;
            if scene.triangle_count() == 0 {
                return Err(Error::Failed(
                    "nothing to show: the turtle made no 3D geometry (no lines, surfaces, polygons or spheres)".into(),
                ));
            }
            let ropts = solid_raster_options(&a, &c, &scene, w, h)?;
            Sight::Solid(Box::new(Solid {
                edges: Vec::new(),
                camera: ropts.camera,
                lit: ropts.shading == Shading::Lit,
                background: ropts.background,
                up: ropts.camera.up.to_array(),
                smooth: true,
                scene,
            }))
        }
        system @ System::Curve(_) => {
            let (svg, more) = picture_in_memory(&a, system, (&looks, Picture::Svg), deadline)?;
            warnings.extend(more);
            Sight::Flat(String::from_utf8_lossy(&svg).into_owned())
        }
    };
    Ok(Seen { sight, warnings })
}

/// A run's frames for the page's playback.
#[derive(Clone, Debug)]
pub struct SeenFrames {
    /// One per step (or per frame of the model's `.a` file), one camera:
    /// 2D drawings laid out in one box, or 3D geometry for a viewer (no
    /// thin lines: pixel-wide lines are whole tubes).
    pub frames: super::Frames,
    pub warnings: Vec<String>,
    /// The up direction a 3D view turns about: the camera's for an
    /// L-system, z for a mesh.
    pub up: [f32; 3],
}

/// The frames of the program with its text replaced by `text`, as
/// [`super::frames`] draws them for `render -o growth.gif` (2D frames in
/// one box, 3D frames with one camera), derived once; `progress` hears
/// after each step. Writes nothing. The page shows them one by one.
pub fn frames_edited(
    a: &RenderArgs,
    text: &str,
    progress: impl FnMut(crate::system::Progress),
) -> Result<SeenFrames, Error> {
    let deadline = a.timeout.map(Deadline::after);
    let _deadline = crate::deadline::scope(deadline);
    if crate::mesh::io::Format::from_path(Path::new(&a.file)).is_some() {
        return Err(Error::Usage(
            "a mesh file has no steps to play: serve a grammar or a vv program that subdivides it"
                .into(),
        ));
    }
    let system = crate::load::load_edited(
        Path::new(&a.file),
        text,
        &load_options(&a.defines, a.double, &a.environment),
    )?;
    let warnings = system.warnings();
    let opts = super::FrameOptions {
        run: RunOptions {
            steps: a.steps,
            max_modules: a.max_modules,
            seed: a.seed,
            deadline,
            ..RunOptions::default()
        },
        size: a.size.unwrap_or((800, 800)),
        background: a.background,
        solid: a.solid,
        wireframe: a.wireframe,
        viewer: true,
        ..Default::default()
    };
    let frames = super::frames(&system, &opts, progress)?;
    let up = match (&system, frames.frames.first().map(|f| &f.geometry)) {
        (System::Curve(_), Some(super::FrameGeometry::Solid(s))) => s.raster.camera.up.to_array(),
        _ => [0.0, 0.0, 1.0],
    };
    let mut warnings = warnings;
    warnings.extend(frames.notes.iter().cloned());
    Ok(SeenFrames {
        frames,
        warnings,
        up,
    })
}
