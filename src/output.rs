//! Words as text and as JSON.

use serde_json::{json, Value as Json};

use crate::lang::value::StructDef;
use crate::lang::{Alphabet, Value};
use crate::rewrite::Word;

/// `P([0, 0.25]) E A(1, 2)`: one module after another, vectors in brackets.
pub fn word_text(word: &Word, alphabet: &Alphabet, structs: &[StructDef]) -> String {
    let mut out = String::new();
    for (i, (sym, params)) in word.modules(alphabet, structs).enumerate() {
        if i > 0 {
            out.push(' ');
        }
        out.push_str(alphabet.name(sym));
        if !params.is_empty() {
            out.push('(');
            for (j, p) in params.iter().enumerate() {
                if j > 0 {
                    out.push_str(", ");
                }
                out.push_str(&value_text(p));
            }
            out.push(')');
        }
    }
    out
}

fn value_text(v: &Value) -> String {
    match v {
        Value::V2(p) => format!("[{}, {}]", p.x, p.y),
        Value::V3(p) => format!("[{}, {}, {}]", p.x, p.y, p.z),
        other => other.to_string(),
    }
}

/// A struct parameter is an array of its fields.
/// `{"ring": bool, "step": N, "modules": [{"symbol": "P", "params": [[0.0, 1.0]]}]}`
pub fn word_json(
    word: &Word,
    ring: bool,
    step: u64,
    alphabet: &Alphabet,
    structs: &[StructDef],
) -> Json {
    let modules: Vec<Json> = word
        .modules(alphabet, structs)
        .map(|(sym, params)| {
            json!({
                "symbol": alphabet.name(sym),
                "params": params.iter().map(value_json).collect::<Vec<_>>(),
            })
        })
        .collect();
    json!({ "ring": ring, "step": step, "modules": modules })
}

fn value_json(v: &Value) -> Json {
    match v {
        Value::Int(i) => json!(i),
        Value::Float(f) => json!(f),
        Value::Bool(b) => json!(b),
        Value::V2(p) => json!([p.x, p.y]),
        Value::V3(p) => json!([p.x, p.y, p.z]),
        Value::Struct(fs) => Json::Array(fs.iter().map(value_json).collect()),
        Value::Str(s) => json!(s.as_ref()),
        Value::Void | Value::Elem(_) => Json::Null,
    }
}
