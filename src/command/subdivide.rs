//! `subgram subdivide`: a surface grammar or vv program run on a mesh, or a
//! shape grammar derived; the mesh, the shapes or their picture written.

use std::path::{Path, PathBuf};
use std::time::Duration;

use super::common::{as_paths, extension_hint, in_run, refuse_overwrite, write_files};
use super::mesh::{write_mesh, write_textured};
use super::picture::{write_mesh_picture, write_soup_picture, MeshLooks, Out, Picture};
use crate::error::Error;
use crate::lang::ProgramOutput;
use crate::mesh::{self, PolygonSoup};
use crate::render::Rgba;
use crate::system::{Progress, RunOptions, Surface};

/// The arguments of `subgram subdivide`.
#[derive(Clone, Debug)]
pub struct SubdivideArgs {
    /// The base mesh; by default the grammar's `mesh:`.
    pub mesh: Option<String>,
    pub grammar: String,
    pub steps: Option<u64>,
    /// `.obj`, `.off`, `.ply`, `.png` or `.svg`.
    pub output: String,
    pub defines: Vec<String>,
    /// For pictures: iso, front, back, left, right, top or bottom.
    pub view: Option<String>,
    /// For pictures: `lit` (smooth: lit from vertex normals), `flat` (lit,
    /// one shade a face), `normals` or `reflection`; the last two draw no
    /// edges.
    pub shading: Option<String>,
    /// For pictures: no edges.
    pub no_wireframe: bool,
    /// Shape grammars: seeds the random choice of rules.
    pub seed: Option<u32>,
    /// `--timeout`: the command stops with an error after this long.
    pub timeout: Option<Duration>,
    /// Write the output even over one of the inputs.
    pub force: bool,
    /// `--limit`: the final vertices at their limit positions, with their
    /// limit normals written (surface grammars; see
    /// [`crate::analyze::limit`]).
    pub limit: bool,
    /// `--fvar-linear`: how texture coordinates are interpolated (one of
    /// [`crate::surface::uvs::FvarLinear::NAMES`]; default `boundaries`,
    /// Blender's).
    pub fvar_linear: Option<String>,
    /// `--no-uvs`: subdivide without the base mesh's texture coordinates.
    pub no_uvs: bool,
    /// What a vv program prints: the caller keeps a clone and prints it.
    pub program_output: ProgramOutput,
}

/// What a `subdivide --grammar` file holds.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Surface,
    Vv,
    Shapes,
}

/// `subgram subdivide`: runs a surface grammar or a vv program on a mesh,
/// or derives a shape grammar, and writes the mesh or its picture. The
/// file is read and lexed once.
pub fn subdivide(a: &SubdivideArgs, progress: impl FnMut(Progress)) -> Result<Vec<String>, Error> {
    in_run(a.timeout, Some(a.force), || subdivide_in_run(a, progress))
}

pub(super) fn subdivide_in_run(
    a: &SubdivideArgs,
    progress: impl FnMut(Progress),
) -> Result<Vec<String>, Error> {
    // One large mesh: freed working memory goes back at once, not kept
    // under the next step's peak.
    crate::huge::return_freed_memory();
    let deadline = crate::deadline::current();
    let grammar = Path::new(&a.grammar);
    let output = Path::new(&a.output);
    let mut inputs = vec![grammar.to_path_buf()];
    inputs.extend(a.mesh.as_deref().map(PathBuf::from));
    refuse_overwrite(&[output], &as_paths(&inputs), a.force)?;
    let opts = RunOptions {
        steps: a.steps,
        base_mesh: a.mesh.as_ref().map(PathBuf::from),
        deadline,
        output: a.program_output.clone(),
        ..RunOptions::default()
    };
    if Picture::from_path(output).is_err()
        && mesh::io::Format::from_path(output).is_none()
        && !is_glb(output)
    {
        return Err(Error::Usage(format!(
            "cannot tell the format of `{}`: subdivide writes meshes (.obj, .off, .ply, .glb) \
             and pictures (.png, .svg){}",
            output.display(),
            extension_hint(output, &["obj", "off", "ply", "glb", "png", "svg"])
        )));
    }
    let d = crate::render::mesh::MeshView::default();
    if Picture::from_path(output).is_err() && (a.shading.is_some() || a.no_wireframe) {
        let flag = if a.shading.is_some() {
            "--shading"
        } else {
            "--no-wireframe"
        };
        return Err(Error::Usage(format!(
            "`{flag}` is for pictures, and `{}` is not one (name it .png or .svg)",
            output.display()
        )));
    }
    let shading = match a.shading.as_deref() {
        None | Some("flat") => d.shading,
        Some(name) => crate::render::mesh::Shading::from_name(name).ok_or_else(|| {
            Error::Usage(format!(
                "`--shading {name}` is not a shading: use lit, flat, normals or reflection"
            ))
        })?,
    };
    let looks = MeshLooks {
        size: (d.width, d.height),
        background: d.background,
        view: a.view.as_deref(),
        wireframe: d.wireframe && !a.no_wireframe && shading == crate::render::mesh::Shading::Lit,
        shading,
        flat: a.shading.as_deref() == Some("flat"),
        cells: false,
    };
    // The file is read and lexed once; its tokens say what it is.
    let text = crate::load::read(grammar)?;
    let front = crate::load::front(&grammar.display().to_string(), text, &a.defines)?;
    let kind = if crate::shape::is_shapes(&front.tokens) {
        Kind::Shapes
    } else if crate::vv::is_vv(&front.tokens) {
        Kind::Vv
    } else {
        Kind::Surface
    };
    if a.limit && kind != Kind::Surface {
        return Err(Error::Usage(format!(
            "--limit is for surface grammars (its stencils come from `analyze`), and `{}` is \
             a {}",
            grammar.display(),
            if kind == Kind::Vv {
                "vertex-vertex program"
            } else {
                "shape grammar"
            }
        )));
    }
    // A shape grammar writes its terminal shapes.
    if kind == Kind::Shapes {
        let dir = grammar.parent().unwrap_or(Path::new("")).to_path_buf();
        let g = crate::load::with_stack(move || crate::shape::from_front(front, Some(&dir)))?;
        let shapes = crate::system::Shapes::new(g);
        let opts = RunOptions {
            seed: a.seed,
            ..opts
        };
        // An OBJ's MTL file is written too, never over an input either;
        // the meshes the grammar inserts and its scheme files are inputs.
        inputs.extend(shapes.inputs());
        let mtl = output.with_extension("mtl");
        refuse_overwrite(&[output, &mtl], &as_paths(&inputs), a.force)?;
        let run = shapes.derive(&opts)?;
        return write_shapes(&shapes, &run, output, &looks).map(|()| Vec::new());
    }
    // A vv program subdivides too.
    if kind == Kind::Vv {
        let program = crate::load::with_stack(move || crate::vv::from_front(front))?;
        let v = crate::system::Vv::new(program, Some(grammar));
        if a.mesh.is_none() {
            inputs.extend(v.base_mesh());
            refuse_overwrite(&[output], &as_paths(&inputs), a.force)?;
        }
        let dropped = dropped_uvs(
            a.mesh.as_deref().map(PathBuf::from).or(v.base_mesh()),
            output,
            a.no_uvs,
            "a vertex-vertex program carries none",
        );
        let run = v.run(&opts, progress)?;
        if Picture::from_path(output).is_ok() {
            return write_soup_picture(
                &run.soup,
                output,
                &looks.for_vv(&run.soup),
                &mut Out::Files,
            )
            .map(|()| Vec::new());
        }
        if is_glb(output) {
            return write_soup_glb(&run.soup, &[], output).map(|()| dropped);
        }
        mesh::io::write(output, &run.soup)?;
        return Ok(dropped);
    }
    let fvar = match a.fvar_linear.as_deref() {
        None => crate::surface::uvs::FvarLinear::default(),
        Some(name) => crate::surface::uvs::FvarLinear::from_name(name).ok_or_else(|| {
            Error::Usage(format!(
                "`--fvar-linear {name}` is not a choice: use {}",
                crate::surface::uvs::FvarLinear::NAMES.join(", ")
            ))
        })?,
    };
    if a.fvar_linear.is_some() && (kind != Kind::Surface || a.no_uvs) {
        return Err(Error::Usage(
            "`--fvar-linear` says how a surface grammar carries texture coordinates; it is \
             for surface grammars, without `--no-uvs`"
                .into(),
        ));
    }
    let g = crate::load::with_stack(move || crate::surface::from_front(front))?;
    let surface = Surface::new(g, Some(grammar));
    if a.mesh.is_none() {
        // The grammar's own `mesh:` is an input too.
        inputs.extend(surface.base_mesh());
        refuse_overwrite(&[output], &as_paths(&inputs), a.force)?;
    }
    // A mesh file gets the base mesh's texture coordinates, where it has
    // them.
    if mesh::io::Format::from_path(output).is_some() && !a.limit && !a.no_uvs {
        let (run, textured, dropped) = surface.subdivide_with_uvs(&opts, fvar, progress)?;
        let mut warnings = match textured {
            Some(t) => write_textured(output, &t)?,
            None => write_mesh(output, &run.mesh, false)?,
        };
        warnings.extend(dropped);
        return Ok(warnings);
    }
    let base = a.mesh.as_deref().map(PathBuf::from).or(surface.base_mesh());
    let run = surface.subdivide(&opts, progress)?;
    if a.limit {
        let mut warnings = write_limit(&surface.grammar, &run.mesh, output, &looks)?;
        if Picture::from_path(output).is_err() {
            warnings.extend(dropped_uvs(base, output, a.no_uvs, "`--limit` writes none"));
        }
        return Ok(warnings);
    }
    if Picture::from_path(output).is_ok() {
        return write_mesh_picture(&run.mesh, output, &looks, &mut Out::Files).map(|()| Vec::new());
    }
    if is_glb(output) {
        let dropped = dropped_uvs(base, output, a.no_uvs, "glTF is written without them");
        return write_soup_glb(&run.mesh.to_quad_soup(), &[], output).map(|()| dropped);
    }
    write_mesh(output, &run.mesh, false)
}

/// A warning that the base mesh's texture coordinates are not in the
/// mesh file `output` (`why`), where the base mesh has some and
/// `--no-uvs` did not ask for that; none for pictures.
fn dropped_uvs(base: Option<PathBuf>, output: &Path, no_uvs: bool, why: &str) -> Vec<String> {
    match base {
        Some(b) if !no_uvs && Picture::from_path(output).is_err() && mesh::io::mentions_uvs(&b) => {
            vec![format!(
                "{}: warning: the texture coordinates of `{}` are not in it: {why}",
                output.display(),
                b.display()
            )]
        }
        _ => Vec::new(),
    }
}

/// `--limit`: the run's mesh at its limit positions, written with its
/// limit normals where the format keeps them: OBJ a normal per face
/// corner (`v//n`; the corners of a vertex on a crease or at a corner
/// take their side's), PLY one per vertex (there the mean of the sides',
/// and a warning says so). A picture is drawn from the positions; OFF and
/// glTF get a warning that the normals are not in them.
fn write_limit(
    g: &crate::surface::Grammar,
    m: &crate::mesh::Mesh,
    output: &Path,
    looks: &MeshLooks,
) -> Result<Vec<String>, Error> {
    let mut soup = m.to_quad_soup();
    let deadline = crate::deadline::current()
        .unwrap_or_else(|| crate::Deadline::after(crate::analyze::TIMEOUT));
    let limit = crate::analyze::limit::limit_surface(g, m, deadline)?;
    soup.positions = limit.positions;
    if Picture::from_path(output).is_ok() {
        return write_soup_picture(&soup, output, looks, &mut Out::Files).map(|()| Vec::new());
    }
    let dropped = format!(
        "{}: warning: the file does not keep the limit normals (write .obj or .ply, which keep them)",
        output.display()
    );
    if is_glb(output) {
        return write_soup_glb(&soup, &[], output).map(|()| vec![dropped]);
    }
    let format = mesh::io::Format::from_path(output);
    if format == Some(mesh::io::Format::Obj) {
        mesh::io::write_with_corner_normals(
            output,
            &soup,
            &limit.normal_values,
            &limit.corner_normals,
        )?;
    } else {
        mesh::io::write_with_normals(output, &soup, &limit.normals)?;
    }
    let two_sided = limit.normal_values.len() > limit.normals.len();
    Ok(match format {
        Some(mesh::io::Format::Off) => vec![dropped],
        Some(mesh::io::Format::Ply) if two_sided => vec![format!(
            "{}: warning: PLY keeps one normal a vertex: a vertex on a crease or at a corner \
             gets the mean of its sides' limit normals (OBJ keeps each side's)",
            output.display()
        )],
        _ => Vec::new(),
    })
}

/// The output is binary glTF (`.glb`), which meshes are exported to as a
/// 3D scene.
fn is_glb(output: &Path) -> bool {
    crate::export::Format::from_path(output) == Some(crate::export::Format::Glb)
}

/// A polygon mesh as binary glTF: its faces fanned into triangles, one
/// primitive per face colour (the default blue without colours).
fn write_soup_glb(soup: &PolygonSoup, colours: &[Rgba], output: &Path) -> Result<(), Error> {
    let scene = crate::render::mesh::soup_scene3(soup, colours);
    if scene.triangle_count() == 0 {
        return Err(Error::Failed(
            "the mesh has no face of non-zero area to write".into(),
        ));
    }
    crate::export::write_glb(&scene, output)
}

/// A shape derivation to `.obj` (with its `.mtl` beside it, both or
/// neither written), `.ply`, `.off`, or a picture.
fn write_shapes(
    shapes: &crate::system::Shapes,
    run: &crate::system::ShapeRun,
    output: &Path,
    looks: &MeshLooks,
) -> Result<(), Error> {
    if Picture::from_path(output).is_ok() {
        return write_shapes_picture(run, output, looks, &mut Out::Files);
    }
    if mesh::io::Format::from_path(output) == Some(mesh::io::Format::Obj) {
        let mtl = output.with_extension("mtl");
        let mtl_name = mtl
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "shapes.mtl".into());
        let (obj, mtl_text) = shapes.obj(run, &mtl_name);
        return write_files(&[(output, obj.into_bytes()), (&mtl, mtl_text.into_bytes())]);
    }
    if run.soup.faces.is_empty() {
        return Err(Error::Failed(
            "the derivation left no terminal shape with faces to write".into(),
        ));
    }
    if is_glb(output) {
        return write_soup_glb(&run.soup, &run.colours, output);
    }
    Ok(mesh::io::write(output, &run.soup)?)
}

/// The terminal shapes, each face in its shape's colour, seen with y up
/// (CityEngine's convention, which shape grammars follow).
pub(super) fn write_shapes_picture(
    run: &crate::system::ShapeRun,
    output: &Path,
    looks: &MeshLooks,
    out: &mut Out,
) -> Result<(), Error> {
    let format = Picture::from_path(output)?;
    let mut mv = looks.check()?;
    // The mesh views are named for z up; turn them to y up.
    let y_up = |v: glam::DVec3| glam::DVec3::new(v.x, v.z, -v.y);
    mv.direction = y_up(mv.direction);
    mv.up = y_up(mv.up);
    mv.face_colours = run.colours.clone();
    if run.soup.faces.is_empty() {
        return Err(Error::Failed(
            "the derivation left no terminal shape with faces to draw".into(),
        ));
    }
    crate::render::mesh::validate(&run.soup, &mv)?;
    let bytes = match format {
        Picture::Svg => crate::render::mesh::render_svg(&run.soup, &mv).into_bytes(),
        Picture::Png => crate::render::mesh::render_png(&run.soup, &mv)?,
    };
    out.put(vec![(output.to_path_buf(), bytes)])
}
