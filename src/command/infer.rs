//! `subgram infer`: L-system productions from a subdivision matrix or mask.

use std::path::Path;

use super::common::{in_run, write_file};
use crate::error::Error;
use crate::reverse;

/// The arguments of `subgram infer`.
#[derive(Clone, Debug, Default)]
pub struct InferArgs {
    /// The matrix as text (`;` between rows): a whole matrix, or one old
    /// point's band of rows (closed schemes).
    pub rows: Option<String>,
    /// The matrix from a file (a row per line).
    pub rows_file: Option<String>,
    /// A mask: the weights `a_k` of `new_j = Σ a_{j − arity·i} old_i`.
    pub mask: Option<String>,
    /// New points per old point for a mask (default 2).
    pub arity: Option<usize>,
    /// The matrix has boundary rows: endmarker productions.
    pub open: bool,
    /// A reverse subdivision matrix (each new point from a group of old
    /// points): a pseudo-L-system production.
    pub reverse: bool,
    /// The grouping written out (closed and reverse schemes).
    pub shift: Option<i64>,
    /// List every grouping instead of writing the program.
    pub list: bool,
    /// Open schemes: the ordered short form (first match).
    pub ordered: bool,
    /// Write the program here instead of returning it.
    pub output: Option<String>,
}

/// `subgram infer`: productions from a subdivision matrix (paper 002
/// §5–7). Returns the `.lsys` program (or, with `list`, every grouping),
/// unless it was written to `output`.
pub fn infer(a: &InferArgs) -> Result<String, Error> {
    in_run(None, None, || infer_in_run(a))
}

fn infer_in_run(a: &InferArgs) -> Result<String, Error> {
    use crate::infer;
    let sources = [a.rows.is_some(), a.rows_file.is_some(), a.mask.is_some()];
    if sources.iter().filter(|&&x| x).count() != 1 {
        return Err(Error::Usage(
            "give the scheme once: --rows \"R1; R2; …\", --rows-file FILE or --mask \"a0 a1 …\""
                .into(),
        ));
    }
    if a.open && a.reverse {
        return Err(Error::Usage(
            "--open and --reverse: reverse subdivision of open curves is not inferred; give a closed reverse matrix".into(),
        ));
    }
    let (source, matrix) = if let Some(mask) = &a.mask {
        if a.open || a.reverse {
            return Err(Error::Usage(
                "a mask describes a closed scheme: give the matrix with --rows for --open or --reverse".into(),
            ));
        }
        let arity = a.arity.unwrap_or(2);
        if !(2..=8).contains(&arity) {
            return Err(Error::Usage(format!(
                "--arity {arity}: give 2 to 8 new points per old point"
            )));
        }
        let m = infer::parse_mask("--mask", mask)?;
        if m.len() > 64 {
            return Err(Error::Usage(
                "a mask of more than 64 weights is not inferred".into(),
            ));
        }
        let n = (4 * m.len().div_ceil(arity) + 8).max(16);
        let mut matrix = infer::mask_matrix(&m, arity, n);
        // A mask has no first row: number the shifts from the grouping
        // written by default (the shortest symmetric one), as d = 0.
        let c = infer::infer_closed(&matrix, None)?.chosen;
        let r = matrix.rows.len() as i64;
        matrix.rows.rotate_left(c.rem_euclid(r) as usize);
        let mask = mask.split_whitespace().collect::<Vec<_>>().join(" ");
        (format!("the mask {mask}"), matrix)
    } else {
        let (name, text) = match (&a.rows, &a.rows_file) {
            (Some(r), _) => ("--rows".to_string(), r.clone()),
            (_, Some(f)) => {
                let p = Path::new(f);
                let bytes = reverse::input::read_bounded(p, reverse::input::MAX_INPUT_BYTES)?;
                let text = reverse::input::utf8_text(f, bytes, "a matrix file")?;
                (f.clone(), text)
            }
            _ => unreachable_usage()?,
        };
        let m = infer::parse_matrix(&name, &text)?;
        // A whole closed matrix has a whole number (2 or more) of rows per
        // column; anything else is one old point's band of rows.
        let whole = m.rows.len() >= 2 * m.cols && m.rows.len() % m.cols == 0;
        let m = if a.open || a.reverse || whole {
            m
        } else {
            if a.arity.is_some_and(|r| r != m.rows.len()) {
                return Err(Error::Usage(format!(
                    "--arity {}: the band has {} rows, one per new point of an old point",
                    a.arity.unwrap_or(0),
                    m.rows.len()
                )));
            }
            if m.rows.len() > 8 || m.cols > 64 {
                return Err(Error::Failed(format!(
                    "{name}: {} rows of {} columns are neither a whole closed matrix (each block of rows the one before moved a column) nor a band of one old point's rows (at most 8 rows of 64 columns); use --open for a matrix with boundary rows",
                    m.rows.len(),
                    m.cols
                )));
            }
            infer::band_matrix(&m, (4 * m.cols + 8).max(16))
        };
        let what = if a.rows.is_some() {
            format!(
                "the rows {}",
                text.split_whitespace().collect::<Vec<_>>().join(" ")
            )
        } else {
            format!("the matrix in {name}")
        };
        (what, m)
    };
    let inference = if a.reverse {
        infer::infer_reverse(&matrix, a.shift)?
    } else if a.open {
        if a.shift.is_some() {
            return Err(Error::Usage(
                "--shift chooses among the groupings of a closed scheme; an open one takes the paper's (the ends keep fewer points)".into(),
            ));
        }
        infer::infer_open(&matrix)?
    } else {
        infer::infer_closed(&matrix, a.shift)?
    };
    let text = if a.list {
        inference.report()
    } else {
        inference.lsys(&source, a.ordered)
    };
    match &a.output {
        Some(out) => {
            write_file(Path::new(out), text.as_bytes())?;
            Ok(String::new())
        }
        None => Ok(text),
    }
}

fn unreachable_usage<T>() -> Result<T, Error> {
    Err(Error::Usage(
        "give the scheme with --rows, --rows-file or --mask".into(),
    ))
}
