//! PNG output with tiny-skia: antialiased fills, and strokes with round caps
//! and joins; polylines with a pen of at most a pixel by their ink
//! (`render::ink`, a private module).

use tiny_skia::{
    Color, FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Stroke, Transform,
};

use super::{Item, RenderError, Rgba, Scene};

/// An anti-aliased solid paint.
fn paint(c: Rgba) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(Color::from_rgba8(c.0, c.1, c.2, c.3));
    p.anti_alias = true;
    p
}

fn stroke(width: f64) -> Stroke {
    Stroke {
        width: width.max(0.0) as f32,
        line_cap: LineCap::Round,
        line_join: LineJoin::Round,
        ..Stroke::default()
    }
}

/// Rasterises a scene and encodes it as PNG.
pub fn render(scene: &Scene) -> Result<Vec<u8>, RenderError> {
    let mut pm = Pixmap::new(scene.width, scene.height)
        .ok_or_else(|| RenderError::new("cannot allocate an image of that size"))?;
    let b = scene.background;
    pm.fill(Color::from_rgba8(b.0, b.1, b.2, b.3));
    let id = Transform::identity();
    let mut ink = super::ink::Ink::new(scene.width, scene.height);
    for item in &scene.items {
        match item {
            Item::Polyline {
                points,
                color,
                width,
            } => {
                if *width <= 1.0 {
                    // A thin pen: its ink (a pen of width 0 is a hairline).
                    let pen = if *width > 0.0 { *width } else { 1.0 };
                    ink.polyline(points, pen);
                    ink.blend(&mut pm, *color);
                    continue;
                }
                let [first, rest @ ..] = points.as_slice() else {
                    continue;
                };
                let mut pb = PathBuilder::new();
                pb.move_to(first.x as f32, first.y as f32);
                for p in rest {
                    pb.line_to(p.x as f32, p.y as f32);
                }
                if let Some(path) = pb.finish() {
                    pm.stroke_path(&path, &paint(*color), &stroke(*width), id, None);
                }
            }
            Item::Disc { c, r, color } => {
                if let Some(path) =
                    PathBuilder::from_circle(c.x as f32, c.y as f32, (*r as f32).max(0.25))
                {
                    pm.fill_path(&path, &paint(*color), FillRule::Winding, id, None);
                }
            }
            Item::Ring { c, r, color, width } => {
                if let Some(path) =
                    PathBuilder::from_circle(c.x as f32, c.y as f32, (*r as f32).max(0.25))
                {
                    pm.stroke_path(&path, &paint(*color), &stroke(*width), id, None);
                }
            }
            Item::Polygon {
                points,
                color,
                outline,
            } => {
                let [first, rest @ ..] = points.as_slice() else {
                    continue;
                };
                let mut pb = PathBuilder::new();
                pb.move_to(first.x as f32, first.y as f32);
                for p in rest {
                    pb.line_to(p.x as f32, p.y as f32);
                }
                pb.close();
                if let Some(path) = pb.finish() {
                    pm.fill_path(&path, &paint(*color), FillRule::EvenOdd, id, None);
                    if let Some(o) = outline {
                        pm.stroke_path(&path, &paint(o.color), &stroke(o.width), id, None);
                    }
                }
            }
        }
    }
    pm.encode_png()
        .map_err(|e| RenderError::new(format!("cannot encode the PNG: {e}")))
}
