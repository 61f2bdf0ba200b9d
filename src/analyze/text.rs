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
