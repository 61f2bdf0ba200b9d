//! "Did you mean": the known name nearest to a misspelt one.
//!
//! Distances are Damerau–Levenshtein (strsim): a swapped pair of letters
//! (`sqtr` for `sqrt`) is one edit, as a missing or doubled letter is. A
//! name is suggested when it is at most a third of the longer name's
//! letters away (at least one edit, at most three), and never when the
//! misspelt name is a single letter (every one-letter name is one edit
//! from every other). Letter case alone counts as the smallest edit:
//! `apex` suggests `Apex` before `ape`.

/// The candidate nearest to `name` within the distance allowed, if any;
/// among equals the first given. `name` itself is never suggested.
pub fn nearest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let len = name.chars().count();
    if len < 2 {
        return None;
    }
    let mut best: Option<(usize, bool, &str)> = None;
    for c in candidates {
        if c == name || c.is_empty() {
            continue;
        }
        let longer = len.max(c.chars().count());
        let allowed = (longer / 3).clamp(1, 3);
        let d = strsim::damerau_levenshtein(name, c);
        // Case alone: ranked before any other single edit.
        let case_only = name.eq_ignore_ascii_case(c);
        let d = if case_only { 0 } else { d };
        if d > allowed {
            continue;
        }
        let better = match best {
            None => true,
            Some((bd, bcase, _)) => (d, !case_only) < (bd, !bcase),
        };
        if better {
            best = Some((d, case_only, c));
        }
    }
    best.map(|(_, _, c)| c)
}

/// `"; did you mean `x`?"` for the nearest candidate, or nothing.
pub fn hint<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    nearest(name, candidates)
        .map(|c| format!("; did you mean `{c}`?"))
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_names_are_suggested_and_far_ones_are_not() {
        let fns = ["sqrt", "sin", "cos", "pow", "exp"];
        assert_eq!(nearest("sqtr", fns), Some("sqrt"));
        assert_eq!(nearest("sqr", fns), Some("sqrt"));
        assert_eq!(nearest("vrr", ["vr", "v", "x"]), Some("vr"));
        assert_eq!(nearest("Apx", ["Apex", "A", "B"]), Some("Apex"));
        assert_eq!(nearest("apex", ["ape", "Apex"]), Some("Apex"));
        assert_eq!(nearest("banana", fns), None);
        // One letter is one edit from every other one-letter name.
        assert_eq!(nearest("q", ["x", "y"]), None);
        // The name itself is no suggestion.
        assert_eq!(nearest("sin", ["sin"]), None);
        assert_eq!(hint("sqtr", fns), "; did you mean `sqrt`?");
        assert_eq!(hint("banana", fns), "");
    }
}
