//! The lines of a vlab environmental program's specification file
//! (`density.spec`, `light.spec`), read as the programs read them: the
//! keyword up to the first colon or tab, the value the next word (words
//! end at white space, `:`, `,`, `;` or `x`). Empty lines are passed over.

use crate::model::ModelError;

/// One line of a specification file.
pub(super) struct Line<'a> {
    path: &'a str,
    /// 1-based.
    number: usize,
    pub text: &'a str,
    /// The keyword, as written (`3d case`).
    pub key: &'a str,
    /// Everything after the keyword's colon.
    pub rest: &'a str,
    /// Where the value starts in the line.
    pub value_at: usize,
    /// The value's first word.
    pub value: &'a str,
}

impl Line<'_> {
    /// An error at bytes `start..end` of the line.
    pub fn error(&self, start: usize, end: usize, message: String) -> ModelError {
        ModelError::FileAt {
            path: self.path.to_string(),
            line: self.number,
            text: self.text.to_string(),
            start,
            end: end.max(start + 1),
            message,
        }
    }

    /// An error at the value.
    pub fn bad_value(&self, message: String) -> ModelError {
        self.error(self.value_at, self.text.len(), message)
    }

    /// The error for a keyword `program` does not have: its keywords
    /// listed, the nearest suggested.
    pub fn unknown(&self, program: &str, keys: &[&str]) -> ModelError {
        let key = self.key.trim();
        let hint = keys
            .iter()
            .find(|k| strsim::damerau_levenshtein(k, key) <= 2)
            .map(|k| format!("; did you mean `{k}:`?"))
            .unwrap_or_default();
        let listed: Vec<String> = keys.iter().map(|k| format!("`{k}:`")).collect();
        self.error(
            0,
            self.key.len(),
            format!(
                "{program} has no setting `{key}` (it has {}){hint}",
                listed.join(", ")
            ),
        )
    }

    /// The value as `on` (true) or `off` (false).
    pub fn on_off(&self) -> Result<bool, ModelError> {
        match self.value {
            "on" => Ok(true),
            "off" => Ok(false),
            _ => Err(self.bad_value(format!(
                "expected `on` or `off`, found `{}`",
                self.rest.trim()
            ))),
        }
    }

    /// The value as a finite number.
    pub fn number(&self) -> Result<f64, ModelError> {
        self.value
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                self.bad_value(format!(
                    "expected a number after `{}:`, found `{}`",
                    self.key.trim(),
                    self.rest.trim()
                ))
            })
    }
}

/// The non-empty lines of `text` (the file `path`).
pub(super) fn lines<'a>(path: &'a str, text: &'a str) -> impl Iterator<Item = Line<'a>> {
    text.lines().enumerate().filter_map(move |(n, raw)| {
        let l = raw.trim_end_matches('\r');
        if l.trim().is_empty() {
            return None;
        }
        let key_end = l.find([':', '\t']).unwrap_or(l.len());
        let rest = l.get(key_end + 1..).unwrap_or("");
        let value = rest
            .split(|c: char| " \t:,;x\n".contains(c))
            .find(|w| !w.is_empty())
            .unwrap_or("");
        Some(Line {
            path,
            number: n + 1,
            text: l,
            key: &l[..key_end],
            rest,
            value_at: key_end + 1 + (rest.len() - rest.trim_start().len()),
            value,
        })
    })
}
