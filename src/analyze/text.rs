//! The reports as text: headings and aligned columns.

use std::fmt::Write;

use super::curve::{CurveReport, Weight};
use super::num::fraction;
use super::surface::{LabelWeight, SurfaceReport};

fn at(o: i64, base: &str) -> String {
    if base.is_empty() {
        return format!("p[{o}]");
    }
    match o {
        0 => format!("p[{base}]"),
        o if o > 0 => format!("p[{base}+{o}]"),
        o => format!("p[{base}{o}]"),
    }
}

fn row(ws: &[Weight], base: &str) -> String {
    ws.iter()
        .map(|w| match w.fraction.as_str() {
            "1" => at(w.offset, base),
            f => format!("{f} {}", at(w.offset, base)),
        })
        .collect::<Vec<_>>()
        .join(" + ")
        .replace("+ -", "- ")
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}

fn poly(first: i64, c: &[String]) -> String {
    let terms: Vec<String> = c
        .iter()
        .enumerate()
        .filter(|(_, x)| x.as_str() != "0")
        .map(|(i, x)| match first + i as i64 {
            0 => x.clone(),
            1 if x == "1" => "z".into(),
            1 => format!("{x} z"),
            k => format!("{x} z^{k}"),
        })
        .collect();
    terms.join(" + ").replace("+ -", "- ")
}

/// A curve scheme's report.
pub fn curve(file: &str, r: &CurveReport) -> String {
    let mut s = String::new();
    let kind = if r.closed { "closed (ring)" } else { "open" };
    let _ = writeln!(s, "{file}: curve scheme, {kind}, module {}", r.module);
    let _ = writeln!(
        s,
        "probe: {} old points, {} new points after one step",
        r.probe_points, r.new_points
    );
    match (r.arity, r.reduction) {
        (Some(a), _) => {
            let _ = writeln!(s, "arity: {a} new points per old point");
            let _ = writeln!(s, "\nstencils (new point {a}i+r from old points p[i+o]):");
            let _ = writeln!(s, "  {:<3} {:<48} {:>6}", "r", "weights", "sum");
            for st in &r.stencils {
                let _ = writeln!(
                    s,
                    "  {:<3} {:<48} {:>6}",
                    st.coset,
                    row(&st.weights, "i"),
                    fraction(st.sum)
                );
            }
        }
        (None, Some(k)) => {
            let _ = writeln!(s, "a reduction: one new point from {k} old points");
            let _ = writeln!(s, "\nstencil (new point i from old points p[{k}i+o]):");
            for st in &r.stencils {
                let _ = writeln!(
                    s,
                    "  {}   sum {}",
                    row(&st.weights, &format!("{k}i")),
                    fraction(st.sum)
                );
            }
        }
        _ => {}
    }
    if !r.boundary.is_empty() {
        let _ = writeln!(
            s,
            "\nboundary rows (old points p[0], p[1], … and p[-1], p[-2], … from the ends):"
        );
        let _ = writeln!(
            s,
            "  {:<6} {:<5} {:<44} {:>6}",
            "end", "row", "weights", "sum"
        );
        for b in &r.boundary {
            let _ = writeln!(
                s,
                "  {:<6} {:<5} {:<44} {:>6}",
                b.end,
                b.row,
                row(&b.weights, ""),
                fraction(b.sum)
            );
        }
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "affine invariance:  {} ({})",
        yes(r.affine),
        if r.affine {
            "every stencil sums to 1"
        } else {
            "some stencil does not sum to 1"
        }
    );
    let _ = writeln!(s, "support:            {}", r.support);
    let _ = writeln!(s, "interpolating:      {}", yes(r.interpolating));
    if let Some(m) = &r.mask {
        let _ = writeln!(
            s,
            "mask:               a(z) = {}",
            poly(m.first, &m.fractions)
        );
        let sigma = match r.arity {
            Some(2) => "(1+z)".to_string(),
            Some(a) => format!("(1+z+…+z^{})", a - 1),
            None => String::new(),
        };
        let _ = writeln!(
            s,
            "factors:            a(z) = z^{} {sigma}^{} ({})",
            m.first,
            m.factor_power,
            poly(0, &m.quotient_fractions)
        );
    }
    if let Some(d) = r.reproduction_degree {
        let _ = writeln!(s, "reproduces:         polynomials of degree ≤ {d}");
    }
    if let Some(d) = r.generation_degree {
        let _ = writeln!(s, "generates:          polynomials of degree ≤ {d}");
    }
    if let Some(h) = &r.smoothness {
        let up = h.upper.map_or("?".to_string(), |u| format!("{u:.4}"));
        let _ = writeln!(
            s,
            "Hölder exponent:    {:.4} ≤ α ≤ {up} (Rioul: norms of {} steps, spectral radii of products of {})",
            h.lower, h.norm_steps, h.product_steps
        );
        match h.continuity {
            Some(c) => {
                let _ = writeln!(s, "smoothness:         C^{c}");
            }
            None => {
                let _ = writeln!(s, "smoothness:         not shown continuous");
            }
        }
    }
    for n in &r.notes {
        let _ = writeln!(s, "note: {n}");
    }
    s
}

fn short(ws: &[LabelWeight], n: usize) -> String {
    // The centre and the first sector's vertices: the stencil's shape.
    ws.iter()
        .filter(|w| w.sector == 0 || (w.i == 0.0 && w.j == 0.0))
        .take(n)
        .map(|w| format!("({},{}):{}", fraction(w.i), fraction(w.j), w.fraction))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A surface grammar's report.
pub fn surface(file: &str, r: &SurfaceReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{file}: surface grammar, probed on fans of {}, around {}",
        r.faces,
        if r.around == "face" {
            "an n-sided face"
        } else {
            "a vertex of valence n"
        }
    );
    if r.valences.iter().any(|v| v.skipped.is_none()) {
        let _ = writeln!(
            s,
            "\n{:>2} {:>5} {:>5} {:>5} {:>6} {:>10} {:>10} {:>10} {:>10} {:>5}",
            "n", "steps", "scale", "size", "affine", "λ0", "λ1", "λ2", "|λ3|", "Reif"
        );
        for v in &r.valences {
            if v.skipped.is_some() {
                continue;
            }
            let l = |k: usize| v.eigenvalues.get(k);
            let show = |k: usize| {
                l(k).map_or("-".into(), |e| {
                    if e.im.abs() > 1e-9 {
                        format!("{:.4}{:+.3}i", e.re, e.im)
                    } else {
                        format!("{:.6}", e.re)
                    }
                })
            };
            let _ = writeln!(
                s,
                "{:>2} {:>5} {:>5} {:>5} {:>6} {:>10} {:>10} {:>10} {:>10} {:>5}",
                v.n,
                v.steps,
                v.scale,
                v.size,
                yes(v.affine),
                show(0),
                show(1),
                show(2),
                l(3).map_or("-".into(), |e| format!("{:.6}", e.modulus)),
                yes(v.reif)
            );
        }
        if r.valences.iter().any(|v| v.wider.is_some()) {
            let _ = writeln!(
                s,
                "\none ring more (what the outer ring adds to the spectrum):\n{:>2} {:>5} {:>5} {:>10} {:>10} {:>10} {:>5}",
                "n", "rings", "size", "λ1", "λ2", "|λ3|", "Reif"
            );
            for v in &r.valences {
                let Some(w) = &v.wider else { continue };
                let l = |k: usize| w.eigenvalues.get(k);
                let _ = writeln!(
                    s,
                    "{:>2} {:>5} {:>5} {:>10} {:>10} {:>10} {:>5}",
                    v.n,
                    w.rings,
                    w.size,
                    l(1).map_or("-".into(), |e| format!("{:.6}", e.re)),
                    l(2).map_or("-".into(), |e| format!("{:.6}", e.re)),
                    l(3).map_or("-".into(), |e| format!("{:.6}", e.modulus)),
                    yes(w.reif)
                );
            }
        }
        let centre = if r.around == "face" {
            "the central polygon's corner (1/4,1/4) and the first sector's corners (i,j)"
        } else {
            "centre (0,0) and the first sector's vertices (i,j)"
        };
        let _ = writeln!(s, "\nlimit stencils ({centre}):");
        for v in r.valences.iter().filter(|v| !v.limit.is_empty()) {
            let _ = writeln!(s, "{:>2} {}", v.n, short(&v.limit, 8));
        }
        let _ = writeln!(s, "\ntangent stencils (first of two, same vertices):");
        for v in r.valences.iter().filter(|v| !v.tangents.is_empty()) {
            let t: Vec<LabelWeight> = v.tangents[0]
                .iter()
                .map(|w| LabelWeight {
                    fraction: format!("{:.4}", w.weight),
                    ..w.clone()
                })
                .collect();
            let _ = writeln!(s, "{:>2} {}", v.n, short(&t, 8));
        }
    }
    for v in r.valences.iter().filter(|v| v.skipped.is_some()) {
        let _ = writeln!(
            s,
            "valence {:>2} skipped: {}",
            v.n,
            v.skipped.as_deref().unwrap_or("")
        );
    }
    for n in &r.notes {
        let _ = writeln!(s, "note: {n}");
    }
    s
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The characteristic maps' control nets as an SVG picture, one panel per
/// valence that has one (`None` when none has).
pub fn characteristic_svg(file: &str, r: &SurfaceReport) -> Option<String> {
    let nets: Vec<_> = r
        .valences
        .iter()
        .filter_map(|v| Some((v, v.characteristic.as_ref()?)))
        .filter(|(_, c)| !c.points.is_empty())
        .collect();
    if nets.is_empty() {
        return None;
    }
    let (cell, cols) = (220.0, 5usize);
    let rows = nets.len().div_ceil(cols);
    let (w, h) = (
        cell * cols.min(nets.len()) as f64,
        30.0 + cell * rows as f64,
    );
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">"
    );
    let _ = writeln!(s, "<rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>");
    let _ = writeln!(
        s,
        "<text x=\"8\" y=\"20\" font-family=\"sans-serif\" font-size=\"13\">{}: control nets of the characteristic maps (eigenvectors of λ1 = λ2)</text>",
        xml_escape(file)
    );
    for (k, (v, c)) in nets.iter().enumerate() {
        let (x0, y0) = (cell * (k % cols) as f64, 30.0 + cell * (k / cols) as f64);
        let reach = c
            .points
            .iter()
            .map(|p| p[0].abs().max(p[1].abs()))
            .fold(0.0, f64::max)
            .max(1e-12);
        let scale = (cell / 2.0 - 22.0) / reach;
        let (cx, cy) = (x0 + cell / 2.0, y0 + cell / 2.0 + 6.0);
        let at = |p: [f64; 2]| (cx + scale * p[0], cy - scale * p[1]);
        let _ = writeln!(s, "<g stroke=\"#1f4e9c\" stroke-width=\"1\">");
        for e in &c.edges {
            let (a, b) = (at(c.points[e[0]]), at(c.points[e[1]]));
            let _ = writeln!(
                s,
                "<line x1=\"{:.2}\" y1=\"{:.2}\" x2=\"{:.2}\" y2=\"{:.2}\"/>",
                a.0, a.1, b.0, b.1
            );
        }
        let _ = writeln!(s, "</g>");
        let l1 = v.eigenvalues.get(1).map_or(0.0, |e| e.re);
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-family=\"sans-serif\" font-size=\"12\">n = {}, λ1 = {:.4}</text>",
            x0 + 8.0,
            y0 + 14.0,
            v.n,
            l1
        );
    }
    s.push_str("</svg>\n");
    Some(s)
}
