//! SVG output with the svg crate: one `path` per polyline and one `polygon`
//! per polygon, coordinates in pixels with two decimals, so that PNG and SVG
//! agree in size and width.

use std::fmt::Write;

use svg::node::element::{Circle, Path, Polygon, Rectangle};
use svg::Document;

use super::{Item, Scene};

/// A number with at most two decimals and no trailing zeros.
fn num(x: f64) -> String {
    let s = format!("{:.2}", x);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// "x1,y1 x2,y2 ..." with at most two decimals.
fn points_attr(points: &[glam::DVec2]) -> String {
    let mut s = String::with_capacity(points.len() * 14);
    for (k, p) in points.iter().enumerate() {
        let sep = if k == 0 { "" } else { " " };
        let _ = write!(s, "{sep}{},{}", num(p.x), num(p.y));
    }
    s
}

/// Renders a scene as an SVG document. Polygons fill by the even-odd rule,
/// as in the PNG (set once, on the root); a background that is not opaque
/// keeps its opacity.
pub fn render(scene: &Scene) -> String {
    let (w, h) = (scene.width, scene.height);
    let mut doc = Document::new()
        .set("width", w)
        .set("height", h)
        .set("viewBox", format!("0 0 {w} {h}"))
        .set("fill-rule", "evenodd");
    let b = scene.background;
    if b.3 > 0 {
        let mut rect = Rectangle::new()
            .set("width", "100%")
            .set("height", "100%")
            .set("fill", b.hex());
        if b.3 < 255 {
            rect = rect.set("fill-opacity", num(b.3 as f64 / 255.0));
        }
        doc = doc.add(rect);
    }
    for item in &scene.items {
        match item {
            Item::Polyline {
                points,
                color,
                width,
            } => {
                let mut d = String::with_capacity(points.len() * 12);
                for (i, p) in points.iter().enumerate() {
                    let _ = write!(
                        d,
                        "{}{} {}",
                        if i == 0 { "M" } else { "L" },
                        num(p.x),
                        num(p.y)
                    );
                }
                doc = doc.add(
                    Path::new()
                        .set("d", d)
                        .set("fill", "none")
                        .set("stroke", color.hex())
                        .set("stroke-width", num(*width))
                        .set("stroke-linecap", "round")
                        .set("stroke-linejoin", "round"),
                );
            }
            Item::Disc { c, r, color } => {
                doc = doc.add(
                    Circle::new()
                        .set("cx", num(c.x))
                        .set("cy", num(c.y))
                        .set("r", num(r.max(0.25)))
                        .set("fill", color.hex()),
                );
            }
            Item::Ring { c, r, color, width } => {
                doc = doc.add(
                    Circle::new()
                        .set("cx", num(c.x))
                        .set("cy", num(c.y))
                        .set("r", num(r.max(0.25)))
                        .set("fill", "none")
                        .set("stroke", color.hex())
                        .set("stroke-width", num(*width)),
                );
            }
            Item::Polygon {
                points,
                color,
                outline,
            } => {
                let mut polygon = Polygon::new()
                    .set("points", points_attr(points))
                    .set("fill", color.hex());
                if let Some(o) = outline {
                    polygon = polygon
                        .set("stroke", o.color.hex())
                        .set("stroke-width", num(o.width))
                        .set("stroke-linejoin", "round");
                }
                doc = doc.add(polygon);
            }
        }
    }
    doc.to_string()
}
