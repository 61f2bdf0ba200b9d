//! `subgram mesh info` and `mesh convert`, and `write_mesh`, which
//! `subdivide` writes its meshes with too.

use std::path::Path;

use super::common::{extension_hint, in_run, json, refuse_overwrite};
use crate::error::Error;
use crate::mesh::{self, Mesh};
use crate::system::load_mesh;

/// Writes `m` to `output` (basic blocks as quads unless `triangles`) with
/// its sharp edges where the format carries them (PLY); a warning for
/// each kind of sharpness the file cannot hold, which would otherwise be
/// lost without a word.
pub(super) fn write_mesh(output: &Path, m: &Mesh, triangles: bool) -> Result<Vec<String>, Error> {
    let sharp = mesh::io::write_mesh(output, m, triangles)?;
    Ok(lost_in_file(output, &sharp))
}

/// Writes a run's mesh with its texture coordinates (see
/// [`crate::system::Surface::subdivide_with_uvs`]); the warnings say what
/// the file does not keep (OFF keeps no texture coordinates, only PLY
/// keeps sharp edges).
pub(super) fn write_textured(
    output: &Path,
    t: &crate::system::TexturedSoup,
) -> Result<Vec<String>, Error> {
    let off = mesh::io::Format::from_path(output) == Some(mesh::io::Format::Off);
    mesh::io::write_with_attributes(output, &t.soup, None, Some(&t.uvs), &t.sharpness.edges)?;
    let mut warnings = lost_in_file(output, &t.sharpness);
    if off {
        warnings.insert(
            0,
            format!(
                "{}: warning: the file does not keep the texture coordinates of the base mesh \
                 (write .obj or .ply, which keep them)",
                output.display()
            ),
        );
    }
    Ok(warnings)
}

/// Warnings for what of a mesh's sharpness the file at `output` does not
/// keep, and for a `.creases` file beside it.
fn lost_in_file(output: &Path, sharp: &crate::mesh::SoupSharpness) -> Vec<String> {
    let ply = mesh::io::Format::from_path(output) == Some(mesh::io::Format::Ply);
    let edges = |n: usize| format!("{n} sharp edge{}", if n == 1 { "" } else { "s" });
    let mut lost = Vec::new();
    if !ply && !sharp.edges.is_empty() {
        lost.push(format!(
            "{} (write .ply, which keeps them)",
            edges(sharp.edges.len())
        ));
    }
    if sharp.edges_left_out > 0 {
        lost.push(format!(
            "{} that are no edges of its polygons (quad diagonals)",
            edges(sharp.edges_left_out)
        ));
    }
    if sharp.vertices_left_out > 0 {
        let n = sharp.vertices_left_out;
        lost.push(format!(
            "{n} sharp vert{} (no mesh format carries them)",
            if n == 1 { "ex" } else { "ices" }
        ));
    }
    let mut warnings: Vec<String> = lost
        .into_iter()
        .map(|what| {
            format!(
                "{}: warning: the file does not keep {what}",
                output.display()
            )
        })
        .collect();
    // A file of creases beside the output is read with it from now on.
    let side = output.with_extension(mesh::io::CREASES_EXTENSION);
    if side.is_file() {
        warnings.push(format!(
            "{}: warning: `{}` beside it, which this command did not write, will be read with \
             it as its creases",
            output.display(),
            side.display()
        ));
    }
    warnings
}

/// `subgram mesh info`: counts, boundary loops, Euler characteristic, genus,
/// valences and levels, as text or JSON.
pub fn mesh_info(file: &str, as_json: bool) -> Result<String, Error> {
    let info = load_mesh(Path::new(file))?.info();
    if as_json {
        json(&info)
    } else {
        Ok(info.to_string().trim_end().to_string())
    }
}

/// `subgram mesh convert`: checks a mesh and writes it in the format of
/// `output`'s extension, basic blocks as quads unless `triangles`. The
/// output may be the input only with `force` (a conversion may lose what
/// subgram does not keep, such as texture coordinates and normals).
pub fn mesh_convert(
    input: &str,
    output: &str,
    triangles: bool,
    force: bool,
) -> Result<Vec<String>, Error> {
    in_run(None, Some(force), || {
        mesh_convert_in_run(input, output, triangles, force)
    })
}

fn mesh_convert_in_run(
    input: &str,
    output: &str,
    triangles: bool,
    force: bool,
) -> Result<Vec<String>, Error> {
    let (input, output) = (Path::new(input), Path::new(output));
    if mesh::io::Format::from_path(output).is_none() {
        // As for pictures: an output whose format cannot be told is a
        // usage error, found before anything is read.
        let ext = output
            .extension()
            .map_or(String::new(), |e| format!(" `.{}`", e.to_string_lossy()));
        return Err(Error::Usage(format!(
            "{}: unknown mesh format{ext}: expected a file ending in .obj, .off or .ply{}",
            output.display(),
            extension_hint(output, &["obj", "off", "ply"])
        )));
    }
    refuse_overwrite(&[output], &[input], force)?;
    let m = load_mesh(input)?;
    write_mesh(output, &m, triangles)
}
