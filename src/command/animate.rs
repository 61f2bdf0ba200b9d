//! `render -o growth.gif`, `-o growth.apng` and `-o 'frames/step-{n}.png'`:
//! the frames of [`super::frames`] encoded as one animated picture, or
//! written as one still a frame, all or none.

use std::path::{Path, PathBuf};

use super::frames::{Frame, Frames};
use super::picture::Picture;
use crate::error::Error;

/// An animated picture's format, told by the output's name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Animated {
    /// `.gif`: the `gif` crate, each frame's palette by NeuQuant.
    Gif,
    /// `.apng`: an animated PNG (the `png` crate's `acTL`/`fcTL`).
    Apng,
    /// `{n}` in the name: one still a frame, `.png` or `.svg`.
    Stills(Picture),
}

/// The stand-in for a frame's step in a name of stills.
pub(super) const STEP: &str = "{n}";
/// The same in capitals: what `--help` shows, where clap would make
/// `{n}` a line break.
const STEP_CAPITAL: &str = "{N}";

impl Animated {
    /// What `path` asks for: an animation, stills, or `None` for a single
    /// picture. `.webp` and `{n}` with another extension are usage errors.
    pub(super) fn from_path(path: &Path) -> Result<Option<Animated>, Error> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        let name = path.to_string_lossy();
        let stills = name.contains(STEP) || name.contains(STEP_CAPITAL);
        match (ext.as_deref(), stills) {
            (Some("gif"), false) => Ok(Some(Animated::Gif)),
            (Some("apng"), false) => Ok(Some(Animated::Apng)),
            (Some("webp"), _) => Err(Error::Usage(format!(
                "`{}`: animated WebP is not written (no well-kept pure-Rust crate encodes it); \
                 write .gif or .apng, or one still a frame with {STEP} in a .png or .svg name",
                path.display()
            ))),
            (Some("png"), true) => Ok(Some(Animated::Stills(Picture::Png))),
            (Some("svg"), true) => Ok(Some(Animated::Stills(Picture::Svg))),
            (_, true) => Err(Error::Usage(format!(
                "`{}`: {STEP} names one still a frame, as .png or .svg",
                path.display()
            ))),
            _ => Ok(None),
        }
    }
}

/// Checks `fps`: more than 0 and at most 100 (a GIF's delays are
/// hundredths of a second).
pub(super) fn check_fps(fps: f64) -> Result<f64, Error> {
    if fps.is_finite() && fps > 0.0 && fps <= 100.0 {
        Ok(fps)
    } else {
        Err(Error::Usage(format!(
            "--fps {fps}: frames a second must be more than 0 and at most 100"
        )))
    }
}

/// The folder that stills go to must exist: it is not made.
pub(super) fn check_folder(output: &Path) -> Result<(), Error> {
    let dir = output
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let d = dir.to_string_lossy();
    if d.contains(STEP) || d.contains(STEP_CAPITAL) {
        return Err(Error::Usage(format!(
            "`{}`: {STEP} may stand in the file's name only, not in a folder's",
            output.display()
        )));
    }
    if !dir.is_dir() {
        return Err(Error::Usage(format!(
            "`{}`: the folder {} does not exist; create it first",
            output.display(),
            dir.display()
        )));
    }
    Ok(())
}

/// The still of the frame of `step`: `{n}` (or `{N}`) replaced by the step, padded
/// with zeros to the digits of the last frame's step (`step-07.png` when
/// the last is 12), so that the names sort in the frames' order.
pub(super) fn still_path(output: &Path, step: u64, last: u64) -> PathBuf {
    let width = last.to_string().len();
    let name = output
        .to_string_lossy()
        .replace(STEP, &format!("{step:0width$}"));
    PathBuf::from(name)
}

/// The files that `frames` make as `format` at `output`: one animation,
/// or one still a frame.
pub(super) fn files(
    frames: &Frames,
    format: Animated,
    output: &Path,
    fps: f64,
) -> Result<Vec<(PathBuf, Vec<u8>)>, Error> {
    let deadline = || crate::deadline::check(crate::deadline::current()).map_err(Error::Failed);
    match format {
        Animated::Stills(picture) => {
            let last = frames.frames.last().map_or(0, |f| f.step);
            frames
                .frames
                .iter()
                .map(|f| {
                    deadline()?;
                    Ok((still_path(output, f.step, last), f.picture(picture)?))
                })
                .collect()
        }
        Animated::Gif => Ok(vec![(output.to_path_buf(), gif(&frames.frames, fps)?)]),
        Animated::Apng => Ok(vec![(output.to_path_buf(), apng(&frames.frames, fps)?)]),
    }
}

/// A frame's pixels as straight (not premultiplied) RGBA.
fn straight_rgba(frame: &Frame) -> Result<(u32, u32, Vec<u8>), Error> {
    let image = frame.image()?;
    let mut pixels = image.pixels;
    for p in pixels.chunks_exact_mut(4) {
        let a = p[3] as u32;
        if a != 0 && a != 255 {
            for c in &mut p[..3] {
                *c = ((*c as u32 * 255 + a / 2) / a).min(255) as u8;
            }
        }
    }
    Ok((image.width, image.height, pixels))
}

fn encoding(format: &str, e: impl std::fmt::Display) -> Error {
    Error::Failed(format!("cannot encode the {format}: {e}"))
}

/// The frames as a GIF that loops for ever, each frame its own palette
/// (NeuQuant where it has more than 256 colours), `1/fps` seconds
/// apart (in hundredths of a second, at least 1).
fn gif(frames: &[Frame], fps: f64) -> Result<Vec<u8>, Error> {
    let delay = (100.0 / fps).round().clamp(1.0, u16::MAX as f64) as u16;
    let (w, h) = frames.first().map_or((1, 1), Frame::size);
    let (w16, h16) = (side(w)?, side(h)?);
    let mut encoder =
        gif::Encoder::new(Vec::new(), w16, h16, &[]).map_err(|e| encoding("GIF", e))?;
    encoder
        .set_repeat(gif::Repeat::Infinite)
        .map_err(|e| encoding("GIF", e))?;
    for frame in frames {
        crate::deadline::check(crate::deadline::current()).map_err(Error::Failed)?;
        let (_, _, mut pixels) = straight_rgba(frame)?;
        let mut f = gif::Frame::from_rgba_speed(w16, h16, &mut pixels, 10);
        f.delay = delay;
        encoder.write_frame(&f).map_err(|e| encoding("GIF", e))?;
    }
    encoder.into_inner().map_err(|e| encoding("GIF", e))
}

/// A GIF's side: at most 65,535 pixels.
fn side(n: u32) -> Result<u16, Error> {
    u16::try_from(n)
        .map_err(|_| Error::Usage(format!("a GIF is at most 65535 pixels a side, not {n}")))
}

/// The frames as an animated PNG that loops for ever, RGBA, `1/fps`
/// seconds apart (in milliseconds).
fn apng(frames: &[Frame], fps: f64) -> Result<Vec<u8>, Error> {
    let delay = (1000.0 / fps).round().clamp(1.0, u16::MAX as f64) as u16;
    let (w, h) = frames.first().map_or((1, 1), Frame::size);
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, w, h);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        encoder
            .set_animated(frames.len() as u32, 0)
            .map_err(|e| encoding("APNG", e))?;
        encoder
            .set_frame_delay(delay, 1000)
            .map_err(|e| encoding("APNG", e))?;
        let mut writer = encoder.write_header().map_err(|e| encoding("APNG", e))?;
        for frame in frames {
            crate::deadline::check(crate::deadline::current()).map_err(Error::Failed)?;
            let (_, _, pixels) = straight_rgba(frame)?;
            writer
                .write_image_data(&pixels)
                .map_err(|e| encoding("APNG", e))?;
        }
        writer.finish().map_err(|e| encoding("APNG", e))?;
    }
    Ok(bytes)
}
