//! `subgram infer`: L-system productions from a subdivision matrix, as
//! paper 002 infers them (§5 closed curves, §6 open curves with
//! endmarkers, §7 reverse subdivision).
//!
//! A matrix maps old points to new ones; a production replaces one old
//! point by a group of consecutive new points (or, reversed, a group of old
//! points by one new point). Choosing the groups is "an element of
//! decision" (§5): for a closed curve of arity `a`, old point `i` (1-based)
//! takes the new points `a·i + d − a + 1 ..= a·i + d` for a shift `d`
//! (the paper's `j ≡ 2i + d`, pairs `(j − 1, j)`). The non-zero columns of
//! a group's rows, placed around the old point's column, are the left
//! context, the strict predecessor and the right context; their entries
//! are the successor's weights. Every shift gives a valid production;
//! [`Inference::groupings`] lists them with their context sizes.
//!
//! Weights are exact rationals: the matrix is read from fractions or
//! decimals, and the productions print dyadic weights as decimals (exact in
//! binary) and others as quotients of doubles.

use std::fmt::Write as _;

use crate::error::Error;

/// The largest matrix read: rows × columns.
pub const MAX_ENTRIES: usize = 1 << 20;

/// An exact fraction, reduced, with a positive denominator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Ratio {
    pub num: i128,
    pub den: i128,
}

fn gcd(a: i128, b: i128) -> i128 {
    let (mut a, mut b) = (a.abs(), b.abs());
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

impl Ratio {
    pub const ZERO: Ratio = Ratio { num: 0, den: 1 };
    pub const ONE: Ratio = Ratio { num: 1, den: 1 };

    /// `num/den` reduced; `None` for a zero denominator.
    pub fn new(num: i128, den: i128) -> Option<Ratio> {
        if den == 0 {
            return None;
        }
        let g = gcd(num, den).max(1);
        let s = if den < 0 { -1 } else { 1 };
        Some(Ratio {
            num: s * num / g,
            den: s * den / g,
        })
    }

    pub fn is_zero(self) -> bool {
        self.num == 0
    }

    pub fn checked_add(self, o: Ratio) -> Option<Ratio> {
        let den = self.den.checked_mul(o.den)?;
        let num = self
            .num
            .checked_mul(o.den)?
            .checked_add(o.num.checked_mul(self.den)?)?;
        Ratio::new(num, den)
    }

    pub fn to_f64(self) -> f64 {
        self.num as f64 / self.den as f64
    }

    /// Reads `3`, `-1/16`, `0.75`, `+.5`: integers, fractions of integers
    /// and decimals, each exact. `None` for anything else, or numbers with
    /// more than 18 digits.
    pub fn parse(s: &str) -> Option<Ratio> {
        let digits =
            |t: &str| !t.is_empty() && t.len() <= 18 && t.bytes().all(|b| b.is_ascii_digit());
        let (sign, body) = match s.as_bytes().first()? {
            b'-' => (-1, &s[1..]),
            b'+' => (1, &s[1..]),
            _ => (1, s),
        };
        if let Some((n, d)) = body.split_once('/') {
            if !digits(n) || !digits(d) {
                return None;
            }
            return Ratio::new(sign * n.parse::<i128>().ok()?, d.parse().ok()?);
        }
        let (int, frac) = body.split_once('.').unwrap_or((body, ""));
        if (int.is_empty() && frac.is_empty())
            || !(int.is_empty() || digits(int))
            || !(frac.is_empty() || digits(frac))
        {
            return None;
        }
        let scale = 10i128.pow(frac.len() as u32);
        let i: i128 = if int.is_empty() { 0 } else { int.parse().ok()? };
        let f: i128 = if frac.is_empty() {
            0
        } else {
            frac.parse().ok()?
        };
        Ratio::new(sign * (i.checked_mul(scale)? + f), scale)
    }

    /// The weight as the production writes it: `0.75`, `-0.0625` when the
    /// denominator is a power of two (exact in binary), `1` and `-2` for
    /// integers, else `(1.0/3)`.
    pub fn lsys(self) -> String {
        if self.den == 1 {
            return format!("{}", self.num);
        }
        if self.den & (self.den - 1) == 0 {
            // A dyadic fraction has a finite decimal expansion.
            let mut s = format!("{}", self.to_f64());
            if !s.contains('.') && !s.contains('e') {
                s.push_str(".0");
            }
            return s;
        }
        format!("({}.0/{})", self.num, self.den)
    }
}

impl std::fmt::Display for Ratio {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.den == 1 {
            write!(f, "{}", self.num)
        } else {
            write!(f, "{}/{}", self.num, self.den)
        }
    }
}

/// A matrix of exact entries, rows of equal length.
#[derive(Clone, Debug, PartialEq)]
pub struct Matrix {
    pub rows: Vec<Vec<Ratio>>,
    pub cols: usize,
}

/// Reads a matrix: rows separated by `;` or new lines, entries by spaces
/// or commas; `//` and `#` start comments. `name` names the text in
/// messages, which point at the entry at fault.
pub fn parse_matrix(name: &str, text: &str) -> Result<Matrix, Error> {
    let mut rows: Vec<Vec<Ratio>> = Vec::new();
    let mut entries = 0usize;
    // (start, end) of every row's text, and of every entry's.
    let mut line_start = 0;
    for line in text.split_inclusive('\n') {
        let code = [line.find("//"), line.find('#')]
            .into_iter()
            .flatten()
            .min()
            .unwrap_or(line.len());
        let mut piece_start = line_start;
        for piece in line[..code].split(';') {
            let mut row = Vec::new();
            let mut word_start = None;
            for (k, ch) in piece
                .char_indices()
                .chain(std::iter::once((piece.len(), ' ')))
            {
                let sep = ch.is_whitespace() || ch == ',';
                match (word_start, sep) {
                    (None, false) => word_start = Some(k),
                    (Some(w), true) => {
                        word_start = None;
                        let word = &piece[w..k];
                        let at = piece_start + w..piece_start + k;
                        let Some(r) = Ratio::parse(word) else {
                            return Err(Error::in_text(
                                name,
                                text,
                                at,
                                format!(
                                    "expected a number (`3`, `-1/16` or `0.75`), found `{word}`"
                                ),
                            ));
                        };
                        entries += 1;
                        if entries > MAX_ENTRIES {
                            return Err(Error::in_text(
                                name,
                                text,
                                at,
                                format!("the matrix has more than {MAX_ENTRIES} entries"),
                            ));
                        }
                        row.push(r);
                    }
                    _ => {}
                }
            }
            if !row.is_empty() {
                if let Some(first) = rows.first() {
                    if first.len() != row.len() {
                        let lead = piece.len() - piece.trim_start().len();
                        return Err(Error::in_text(
                            name,
                            text,
                            piece_start + lead..piece_start + piece.trim_end().len(),
                            format!(
                                "this row has {} entries and the first row {}: every row needs one per old point",
                                row.len(),
                                first.len()
                            ),
                        ));
                    }
                }
                rows.push(row);
            }
            piece_start += piece.len() + 1;
        }
        line_start += line.len();
    }
    let cols = rows.first().map_or(0, Vec::len);
    if rows.is_empty() || cols == 0 {
        return Err(Error::file(name, "the matrix has no rows"));
    }
    Ok(Matrix { rows, cols })
}

/// Reads a mask (`1/4 3/4 3/4 1/4`): the weights `a_k` of the refinement
/// `new_j = Σ_i a_{j − arity·i} old_i`.
pub fn parse_mask(name: &str, text: &str) -> Result<Vec<Ratio>, Error> {
    let m = parse_matrix(name, &text.replace(';', " "))?;
    Ok(m.rows.into_iter().flatten().collect())
}

/// One term of a new point: the weight of the old point `offset` places
/// from the predecessor's strict module (negative: to the left).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Term {
    pub offset: i64,
    pub weight: Ratio,
}

/// A production inferred from a group of rows.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Production {
    /// The old points before the strict predecessor (a number of `P`s).
    pub left: usize,
    /// The strict predecessor's modules (1, or the group's size in reverse
    /// subdivision).
    pub strict: usize,
    pub right: usize,
    /// An endmarker `#` before the left context or after the right one.
    pub left_end: bool,
    pub right_end: bool,
    /// Each new point, as terms; an empty list for none (the point is
    /// removed).
    pub successor: Vec<Vec<Term>>,
}

/// The names of the old points: `vl`, `vll` to the left, `v`, `vr`, `vrr`
/// to the right; in a strict predecessor of several, `va`, `vb`, …
fn var(offset: i64, strict: usize) -> String {
    if strict > 1 {
        if offset >= 0 && (offset as usize) < strict {
            return format!("v{}", (b'a' + offset as u8) as char);
        }
        if offset >= strict as i64 {
            return format!("v{}", "r".repeat((offset - strict as i64 + 1) as usize));
        }
        return format!("v{}", "l".repeat((-offset) as usize));
    }
    match offset {
        0 => "v".into(),
        o if o < 0 => format!("v{}", "l".repeat((-o) as usize)),
        o => format!("v{}", "r".repeat(o as usize)),
    }
}

impl Production {
    /// The production in `.lsys` syntax, module `P`.
    pub fn lsys(&self) -> String {
        let mut s = String::new();
        if self.left_end {
            s.push_str("# ");
        }
        let l = self.left as i64;
        let left: Vec<String> = (-l..0)
            .map(|o| format!("P({})", var(o, self.strict)))
            .collect();
        if !left.is_empty() || self.left_end {
            s.push_str(&left.join(" "));
            if !left.is_empty() {
                s.push(' ');
            }
            s.push_str("< ");
        }
        let strict: Vec<String> = (0..self.strict as i64)
            .map(|o| format!("P({})", var(o, self.strict)))
            .collect();
        s.push_str(&strict.join(" "));
        let right: Vec<String> = (0..self.right as i64)
            .map(|o| format!("P({})", var(self.strict as i64 + o, self.strict)))
            .collect();
        if !right.is_empty() || self.right_end {
            s.push_str(" >");
            if !right.is_empty() {
                s.push(' ');
                s.push_str(&right.join(" "));
            }
            if self.right_end {
                s.push_str(" #");
            }
        }
        if self.successor.is_empty() {
            // No new point: the module is erased.
            s.push_str(" : { produce; }");
            return s;
        }
        s.push_str(" ->");
        for point in &self.successor {
            let mut sum = String::new();
            for (k, t) in point.iter().enumerate() {
                let w = t.weight;
                let name = var(t.offset, self.strict);
                let (neg, mag) = if w.num < 0 {
                    (
                        true,
                        Ratio {
                            num: -w.num,
                            den: w.den,
                        },
                    )
                } else {
                    (false, w)
                };
                let term = if mag == Ratio::ONE {
                    name
                } else {
                    format!("{}*{name}", mag.lsys())
                };
                match (k, neg) {
                    (0, false) => sum.push_str(&term),
                    (0, true) => {
                        let _ = write!(sum, "-{term}");
                    }
                    (_, false) => {
                        let _ = write!(sum, " + {term}");
                    }
                    (_, true) => {
                        let _ = write!(sum, " - {term}");
                    }
                }
            }
            if sum.is_empty() {
                sum.push_str("0*v");
            }
            let _ = write!(s, " P({sum})");
        }
        s
    }

    /// How far the new points lie from the strict predecessor: the sum of
    /// |offset| × |weight| over the terms, in millionths.
    pub fn distance(&self) -> i64 {
        let d: f64 = self
            .successor
            .iter()
            .flatten()
            .map(|t| t.offset.abs() as f64 * t.weight.to_f64().abs())
            .sum();
        (d * 1e6).round() as i64
    }

    /// Context sizes as `left|strict|right`.
    pub fn shape(&self) -> String {
        format!("{}|{}|{}", self.left, self.strict, self.right)
    }
}

/// One grouping of a closed scheme: the shift and its production.
#[derive(Clone, Debug, PartialEq)]
pub struct Grouping {
    pub shift: i64,
    pub production: Production,
}

/// What `infer` found.
#[derive(Clone, Debug, PartialEq)]
pub struct Inference {
    /// New points per old point (closed, open), or old points per new point
    /// (reverse).
    pub arity: usize,
    pub closed: bool,
    pub reverse: bool,
    /// Closed schemes: every shift in the listed range with its production.
    pub groupings: Vec<Grouping>,
    /// The shift of the production written out.
    pub chosen: i64,
    /// Open schemes: the productions in the paper's unordered form (28)–(33)
    /// and the ordered short form (34)–(36).
    pub open: Option<OpenProductions>,
}

/// The productions of an open scheme.
#[derive(Clone, Debug, PartialEq)]
pub struct OpenProductions {
    /// Special productions at the left end, by distance (0: the first point).
    pub left: Vec<Production>,
    pub interior: Production,
    /// Special productions at the right end, by distance (0: the last point).
    pub right: Vec<Production>,
    /// The short forms, applied first to last (lpfg's first match).
    pub ordered: Vec<Production>,
    /// The new points per old point, first to last.
    pub groups: Vec<usize>,
}

/// The offset of column `c` from column `i` on a ring of `n` (the
/// representative nearest zero; ties to the right).
fn ring_offset(c: usize, i: usize, n: usize) -> i64 {
    let n = n as i64;
    let d = (c as i64 - i as i64).rem_euclid(n);
    if d > n / 2 {
        d - n
    } else {
        d
    }
}

/// The non-zero entries of `row` as terms around column `i`.
fn terms(row: &[Ratio], i: usize, closed: bool) -> Vec<Term> {
    let n = row.len();
    let mut t: Vec<Term> = row
        .iter()
        .enumerate()
        .filter(|(_, w)| !w.is_zero())
        .map(|(c, &weight)| Term {
            offset: if closed {
                ring_offset(c, i, n)
            } else {
                c as i64 - i as i64
            },
            weight,
        })
        .collect();
    t.sort_by_key(|t| t.offset);
    t
}

/// A production from a group's new points (their terms around the strict
/// predecessor of `strict` modules): the contexts reach the farthest term.
fn production(successor: Vec<Vec<Term>>, strict: usize) -> Production {
    let lo = successor
        .iter()
        .flatten()
        .map(|t| t.offset)
        .min()
        .unwrap_or(0)
        .min(0);
    let hi = successor
        .iter()
        .flatten()
        .map(|t| t.offset)
        .max()
        .unwrap_or(0)
        .max(strict as i64 - 1);
    Production {
        left: (-lo) as usize,
        strict,
        right: (hi - (strict as i64 - 1)) as usize,
        left_end: false,
        right_end: false,
        successor,
    }
}

/// Checks that `m` is a closed scheme's matrix: `arity·n` rows of `n`
/// columns, each block of `arity` rows the one before moved one column to
/// the right around the ring. Returns the arity.
fn closed_arity(m: &Matrix) -> Result<usize, String> {
    let (r, n) = (m.rows.len(), m.cols);
    if r % n != 0 || r < n {
        return Err(format!(
            "a closed scheme's matrix has a whole number of rows per column; this one has {r} rows and {n} columns (use --open for a matrix with boundary rows)"
        ));
    }
    let a = r / n;
    for (j, row) in m.rows.iter().enumerate().skip(a) {
        let prev = &m.rows[j - a];
        for c in 0..n {
            if row[(c + 1) % n] != prev[c] {
                return Err(format!(
                    "row {} is not row {} moved one column to the right, so the matrix is not one stationary rule around a ring (use --open for boundary rows)",
                    j + 1,
                    j + 1 - a
                ));
            }
        }
    }
    // The stencils must be narrower than the ring, or offsets are ambiguous.
    for row in &m.rows[..a] {
        let nz: Vec<usize> = (0..n).filter(|&c| !row[c].is_zero()).collect();
        if nz.is_empty() {
            continue;
        }
        let spread = (0..n)
            .map(|i| {
                let o: Vec<i64> = nz.iter().map(|&c| ring_offset(c, i, n)).collect();
                o.iter().max().unwrap_or(&0) - o.iter().min().unwrap_or(&0)
            })
            .min()
            .unwrap_or(0);
        if 2 * spread as usize + 1 > n {
            return Err(format!(
                "the matrix has {n} columns, too few to tell a stencil {} wide from its wrap around the ring: give at least {} columns",
                spread + 1,
                2 * spread + 2
            ));
        }
    }
    Ok(a)
}

/// The matrix of a closed scheme of `arity` given by its mask, on a ring of
/// `n` old points: `new_j = Σ_i a_{j − arity·i} old_i`.
pub fn mask_matrix(mask: &[Ratio], arity: usize, n: usize) -> Matrix {
    let rows = (0..arity * n)
        .map(|j| {
            let mut row = vec![Ratio::ZERO; n];
            for (k, &w) in mask.iter().enumerate() {
                // new j takes a_k from old i where j − arity·i = k.
                let jk = j as i64 - k as i64;
                if jk.rem_euclid(arity as i64) == 0 {
                    let i = (jk / arity as i64).rem_euclid(n as i64) as usize;
                    row[i] = row[i].checked_add(w).unwrap_or(w);
                }
            }
            row
        })
        .collect();
    Matrix { rows, cols: n }
}

/// The matrix of a closed scheme given by one old point's rows, a band
/// of `arity` rows over a window of columns (`1/4 3/4 0; 0 3/4 1/4` for
/// Chaikin): the window's middle column (the left one of two) is the old
/// point the rows belong to, and each next old point's rows are the band
/// moved one column to the right, around a ring of `n` old points.
pub fn band_matrix(band: &Matrix, n: usize) -> Matrix {
    let a = band.rows.len();
    let w = band.cols;
    let c0 = (w - 1) / 2;
    let rows = (0..a * n)
        .map(|j| {
            let (i, e) = (j / a, j % a);
            let mut row = vec![Ratio::ZERO; n];
            for (k, &x) in band.rows[e].iter().enumerate() {
                let c = (i as i64 + k as i64 - c0 as i64).rem_euclid(n as i64) as usize;
                row[c] = row[c].checked_add(x).unwrap_or(x);
            }
            row
        })
        .collect();
    Matrix { rows, cols: n }
}

/// Infers the productions of a closed scheme for every shift in a range
/// around zero; `shift` chooses the one written out (by default the
/// most balanced one, then the shortest).
pub fn infer_closed(m: &Matrix, shift: Option<i64>) -> Result<Inference, Error> {
    let a = closed_arity(m).map_err(Error::Failed)?;
    let width = (0..a)
        .map(|e| {
            let t = terms(&m.rows[e], 0, true);
            t.last().map_or(0, |l| l.offset) - t.first().map_or(0, |f| f.offset)
        })
        .max()
        .unwrap_or(0)
        + 1;
    // Every shift from one whose group ends a stencil's width before the
    // old point to one that starts as far after it.
    let reach = a as i64 * (width + 1) + 1;
    // Row e < a belongs to old column 0; its terms around that column.
    let stencils: Vec<Vec<Term>> = (0..a).map(|e| terms(&m.rows[e], 0, true)).collect();
    let group = |d: i64| -> Production {
        // Old point i (1-based) takes new rows a·i + d − a + 1 ..= a·i + d;
        // with i = 1 that is rows d + 1 ..= d + a, 0-based d ..= d + a − 1,
        // and the old column 0. Row j is row j mod a moved j div a columns.
        let rows: Vec<Vec<Term>> = (0..a as i64)
            .map(|t| {
                let j = d + t;
                let (moved, e) = (j.div_euclid(a as i64), j.rem_euclid(a as i64) as usize);
                stencils[e]
                    .iter()
                    .map(|x| Term {
                        offset: x.offset + moved,
                        weight: x.weight,
                    })
                    .collect()
            })
            .collect();
        production(rows, 1)
    };
    let groupings: Vec<Grouping> = (-reach..=reach)
        .map(|d| Grouping {
            shift: d,
            production: group(d),
        })
        .collect();
    if let Some(d) = shift.filter(|d| d.unsigned_abs() > 64 * reach as u64) {
        return Err(Error::Usage(format!(
            "--shift {d}: a production reaching that far from its old point is not written; the listed shifts run from {} to {}",
            -reach, reach
        )));
    }
    let (groupings, chosen) = choose(groupings, shift, group);
    Ok(Inference {
        arity: a,
        closed: true,
        reverse: false,
        groupings,
        chosen,
        open: None,
    })
}

/// The grouping written: `shift`, else the most balanced, then the
/// shortest, then the one whose new points lie nearest the old point they
/// replace; added to the list when it lies outside it.
fn choose(
    mut groupings: Vec<Grouping>,
    shift: Option<i64>,
    group: impl Fn(i64) -> Production,
) -> (Vec<Grouping>, i64) {
    let chosen = shift.unwrap_or_else(|| {
        groupings
            .iter()
            .min_by_key(|g| {
                let (l, r) = (g.production.left as i64, g.production.right as i64);
                let far = g.production.distance();
                ((l - r).abs(), l + r, far, g.shift.abs(), g.shift)
            })
            .map_or(0, |g| g.shift)
    });
    if !groupings.iter().any(|g| g.shift == chosen) {
        groupings.push(Grouping {
            shift: chosen,
            production: group(chosen),
        });
    }
    (groupings, chosen)
}

/// Infers the productions of an open scheme (§6): rows for `n` old points
/// between endmarkers, fewer than `arity·n` of them. The missing rows are
/// taken from the end points, alternately from the first and the last (the
/// paper's (27): the first and last old points keep one new point each).
/// Points whose rows match the middle point's production share it; the
/// others near each end get productions pinned there by `#` in a context.
pub fn infer_open(m: &Matrix) -> Result<Inference, Error> {
    let (r, n) = (m.rows.len(), m.cols);
    if n < 3 {
        return Err(Error::Failed(format!(
            "an open scheme's matrix needs at least 3 columns (old points) to tell its ends from its middle; this one has {n}"
        )));
    }
    let a = r.div_ceil(n);
    let missing = a * n - r;
    let mut sizes = vec![a; n];
    for k in 0..missing {
        let from_left = k % 2 == 0;
        let pick = if from_left {
            (0..n).find(|&i| sizes[i] > 0)
        } else {
            (0..n).rev().find(|&i| sizes[i] > 0)
        };
        match pick {
            Some(i) => sizes[i] -= 1,
            None => break,
        }
    }
    let mut first = 0;
    let mut raw = Vec::with_capacity(n);
    for (i, &s) in sizes.iter().enumerate() {
        let successor: Vec<Vec<Term>> = (first..first + s)
            .map(|j| terms(&m.rows[j], i, false))
            .collect();
        first += s;
        raw.push(production(successor, 1));
    }
    let mid = n / 2;
    let interior_core = raw[mid].clone();
    let same = |p: &Production| p.successor == interior_core.successor;
    let mut left_n = 0;
    while left_n < mid && !same(&raw[left_n]) {
        left_n += 1;
    }
    let mut right_n = 0;
    while right_n < n - 1 - mid && !same(&raw[n - 1 - right_n]) {
        right_n += 1;
    }
    if (left_n..n - right_n).any(|i| !same(&raw[i])) {
        return Err(Error::Failed(
            "the rows between the ends are not one stationary rule: give a matrix with more columns, or check its middle rows"
                .into(),
        ));
    }
    // Unordered form: each end production is pinned by `#` at its distance;
    // the interior one reaches past every special point.
    let left: Vec<Production> = (0..left_n)
        .map(|k| {
            let mut p = raw[k].clone();
            p.left = k;
            p.left_end = true;
            p
        })
        .collect();
    let right: Vec<Production> = (0..right_n)
        .map(|k| {
            let mut p = raw[n - 1 - k].clone();
            p.right = k;
            p.right_end = true;
            p
        })
        .collect();
    let mut interior = interior_core.clone();
    interior.left = interior.left.max(left_n);
    interior.right = interior.right.max(right_n);
    // Ordered form: the special ones with their own contexts, first; then
    // the interior one as its rows need.
    // A special point that keeps itself needs no production where the
    // interior one cannot reach it (its contexts need more points there):
    // unmatched modules are copied (the paper's first convention).
    let identity = |p: &Production| {
        p.successor.len() == 1
            && p.successor[0]
                == [Term {
                    offset: 0,
                    weight: Ratio::ONE,
                }]
    };
    let mut ordered: Vec<Production> = Vec::new();
    for (k, p) in left.iter().enumerate() {
        if !(identity(p) && interior_core.left > k) {
            ordered.push(p.clone());
        }
    }
    for (k, p) in right.iter().enumerate() {
        if !(identity(p) && interior_core.right > k) {
            ordered.push(p.clone());
        }
    }
    ordered.push(interior_core);
    Ok(Inference {
        arity: a,
        closed: false,
        reverse: false,
        groupings: Vec::new(),
        chosen: 0,
        open: Some(OpenProductions {
            left,
            interior,
            right,
            ordered,
            groups: sizes,
        }),
    })
}

/// Infers a reverse subdivision production (§7): a matrix of `n` rows and
/// `arity·n` columns (each new point from a group of `arity` consecutive
/// old points, a pseudo-L-system's strict predecessor), closed. The
/// grouping that takes columns `arity·i + d …` for row `i` is chosen by
/// `shift` (default: the shortest symmetric one).
pub fn infer_reverse(m: &Matrix, shift: Option<i64>) -> Result<Inference, Error> {
    let (r, cols) = (m.rows.len(), m.cols);
    if cols % r != 0 || cols < 2 * r {
        return Err(Error::Failed(format!(
            "a reverse subdivision matrix has a whole number (at least 2) of columns per row; this one has {r} rows and {cols} columns"
        )));
    }
    let a = cols / r;
    for (j, row) in m.rows.iter().enumerate().skip(1) {
        let prev = &m.rows[j - 1];
        for c in 0..cols {
            if row[(c + a) % cols] != prev[c] {
                return Err(Error::Failed(format!(
                    "row {} is not row {} moved {a} columns to the right, so the matrix is not one stationary rule around a ring",
                    j + 1,
                    j
                )));
            }
        }
    }
    let nz = terms(&m.rows[0], 0, true);
    let span = nz.last().map_or(0, |t| t.offset) - nz.first().map_or(0, |t| t.offset) + 1;
    if 2 * span as usize + 1 > cols {
        return Err(Error::Failed(format!(
            "the matrix has {cols} columns, too few to tell a stencil {span} wide from its wrap around the ring: give at least {} columns",
            2 * span + 2
        )));
    }
    let reach = span + a as i64;
    let group = |d: i64| -> Production {
        // Row 1 takes the group of old points starting at column d.
        let t: Vec<Term> = nz
            .iter()
            .map(|x| Term {
                offset: x.offset - d,
                weight: x.weight,
            })
            .collect();
        production(vec![t], a)
    };
    let groupings: Vec<Grouping> = (-reach..=reach)
        .map(|d| Grouping {
            shift: d,
            production: group(d),
        })
        .collect();
    let (groupings, chosen) = choose(groupings, shift, group);
    Ok(Inference {
        arity: a,
        closed: true,
        reverse: true,
        groupings,
        chosen,
        open: None,
    })
}

impl Inference {
    /// The production written out (closed and reverse schemes).
    pub fn production(&self) -> Option<&Production> {
        self.groupings
            .iter()
            .find(|g| g.shift == self.chosen)
            .map(|g| &g.production)
    }

    /// A complete `.lsys` file that runs the inferred productions on a
    /// sample polygon; `ordered`: an open scheme's short form.
    pub fn lsys(&self, source: &str, ordered: bool) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "// Inferred by `subgram infer` from {source}.");
        let pts = [
            (0.0, 0.0),
            (1.0, 3.0),
            (4.0, 4.0),
            (7.0, 3.0),
            (8.0, 0.0),
            (11.0, 1.0),
            (10.0, -3.0),
            (5.0, -2.0),
        ];
        let axiom: Vec<String> = pts
            .iter()
            .map(|(x, y)| format!("P(V2d({x:?}, {y:?}))"))
            .collect();
        s.push_str("#define STEPS 4\nmodule P(V2d);\n\n");
        if let Some(open) = &self.open {
            let _ = writeln!(
                s,
                "// An open curve between endmarkers; new points per old point: {}.",
                group_summary(&open.groups)
            );
            s.push_str("derivation length: STEPS;\n\n");
            let _ = writeln!(s, "Axiom: # {} #;\n", axiom.join(" "));
            if ordered {
                s.push_str("// First match applies (lpfg's order), as (34)-(36) of paper 002.\n");
                for p in &open.ordered {
                    let _ = writeln!(s, "{}", p.lsys());
                }
            } else {
                s.push_str(
                    "// Each production applies at its place only, as (28)-(33) of paper 002.\n",
                );
                for p in open.left.iter().chain(std::iter::once(&open.interior)) {
                    let _ = writeln!(s, "{}", p.lsys());
                }
                for p in open.right.iter().rev() {
                    let _ = writeln!(s, "{}", p.lsys());
                }
                s.push_str("# -> #\n");
            }
            s.push_str(
                "\ninterpretation:\n# < P(v) : { produce MoveTo2d(v) SetColor(3) Circle(0.06); }\n\
                 P(vl) < P(v) : { produce SetColor(2) SetWidth(2) Line2d(vl, v) SetColor(3) Circle(0.06); }\n",
            );
            return s;
        }
        let p = self.production();
        let steps = if self.reverse { 1 } else { 4 };
        let _ = writeln!(
            s,
            "// {} grouping: shift {} (see `subgram infer --list`).",
            if self.reverse {
                "Reverse subdivision, a pseudo-L-system"
            } else {
                "A closed curve"
            },
            self.chosen
        );
        s = s.replace("#define STEPS 4", &format!("#define STEPS {steps}"));
        s.push_str("ring L-system: 1;\nderivation length: STEPS;\n\n");
        let _ = writeln!(s, "Axiom: {};\n", axiom.join(" "));
        if let Some(p) = p {
            let _ = writeln!(s, "{}", p.lsys());
        }
        s.push_str(
            "\ninterpretation:\nP(vl) < P(v) : { produce SetColor(2) SetWidth(2) Line2d(vl, v) SetColor(3) Circle(0.04); }\n",
        );
        s
    }

    /// The listing of every grouping (closed and reverse), or the open
    /// scheme's productions.
    pub fn report(&self) -> String {
        let mut s = String::new();
        if let Some(open) = &self.open {
            let _ = writeln!(
                s,
                "open scheme, arity {}: new points per old point {}",
                self.arity,
                group_summary(&open.groups)
            );
            let _ = writeln!(s, "unordered (28)-(33):");
            for p in open.left.iter().chain(std::iter::once(&open.interior)) {
                let _ = writeln!(s, "  {}", p.lsys());
            }
            for p in open.right.iter().rev() {
                let _ = writeln!(s, "  {}", p.lsys());
            }
            s.push_str("  # -> #\nordered (34)-(36), first match:\n");
            for p in &open.ordered {
                let _ = writeln!(s, "  {}", p.lsys());
            }
            return s;
        }
        let _ = writeln!(
            s,
            "{} scheme, arity {}; every grouping (shift d: left|strict|right context sizes):",
            if self.reverse { "reverse" } else { "closed" },
            self.arity
        );
        for g in &self.groupings {
            let mark = if g.shift == self.chosen { "*" } else { " " };
            let _ = writeln!(
                s,
                "{mark} d = {:>3}  {:>7}  {}",
                g.shift,
                g.production.shape(),
                g.production.lsys()
            );
        }
        s
    }
}

/// `1, 2 × 6, 1`: the group sizes, runs collapsed.
fn group_summary(groups: &[usize]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut k = 0;
    while k < groups.len() {
        let mut e = k;
        while e + 1 < groups.len() && groups[e + 1] == groups[k] {
            e += 1;
        }
        if e > k {
            parts.push(format!("{} × {}", groups[k], e - k + 1));
        } else {
            parts.push(groups[k].to_string());
        }
        k = e + 1;
    }
    parts.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratios_parse_exactly_and_print_as_the_production_needs() {
        let r = |s: &str| Ratio::parse(s).unwrap();
        assert_eq!(r("0.75"), Ratio::new(3, 4).unwrap());
        assert_eq!(r("-1/16"), Ratio::new(-1, 16).unwrap());
        assert_eq!(r("+.5"), Ratio::new(1, 2).unwrap());
        assert_eq!(
            r("3"),
            Ratio::ONE.checked_add(Ratio::new(2, 1).unwrap()).unwrap()
        );
        for bad in [
            "",
            "-",
            "1/0",
            "x",
            "1.2.3",
            "1/-2",
            "1e5",
            "1234567890123456789",
        ] {
            assert!(Ratio::parse(bad).is_none(), "{bad}");
        }
        assert_eq!(r("3/4").lsys(), "0.75");
        assert_eq!(r("-1/16").lsys(), "-0.0625");
        assert_eq!(r("1/3").lsys(), "(1.0/3)");
        assert_eq!(r("2").lsys(), "2");
    }

    #[test]
    fn a_bad_entry_is_reported_at_its_place() {
        let e = parse_matrix("--rows", "1/4 3/4; 3/4 x")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("--rows:1:14: error:"), "{e}");
        let e = parse_matrix("m.txt", "1 0\n0 1 0\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("m.txt:2:1: error:"), "{e}");
    }
}
