//! Words as text and as JSON.
//!
//! A parameter of a single-precision type (`float`, `V2f`, `V3f`) is written
//! as the shortest decimal that reads back as the same `float`, as lpfg's
//! users see it: `1.9999987`, not the `double` `1.999998688697815` that
//! holds it.

use serde_json::{json, Value as Json};

use crate::lang::value::StructDef;
use crate::lang::{Alphabet, Ty, Value};
use crate::rewrite::Word;

/// `P([0, 0.25]) E A(1, 2)`: one module after another, vectors in brackets.
pub fn word_text(word: &Word, alphabet: &Alphabet, structs: &[StructDef]) -> String {
    let mut out = String::new();
    for i in 0..word.len() {
        let sym = word.syms()[i];
        if i > 0 {
            out.push(' ');
        }
        out.push_str(alphabet.name(sym));
        let params = word.values(i, alphabet, structs);
        if !params.is_empty() {
            let tys = alphabet.layout(sym, word.data(i).len(), structs);
            out.push('(');
            for (j, p) in params.iter().enumerate() {
                if j > 0 {
                    out.push_str(", ");
                }
                let ty = tys.get(j).copied().unwrap_or(Ty::Double);
                out.push_str(&value_text(p, ty, structs));
            }
            out.push(')');
        }
    }
    out
}

/// `x` as text: a single-precision value as the shortest decimal of its
/// `float`, anything else as the shortest decimal of its `double`.
fn float_text(x: f64, single: bool) -> String {
    if single && (x as f32) as f64 == x {
        (x as f32).to_string()
    } else {
        x.to_string()
    }
}

fn value_text(v: &Value, ty: Ty, structs: &[StructDef]) -> String {
    let single = ty.is_single();
    match v {
        Value::Float(x) => float_text(*x, single),
        Value::V2(p) => format!("[{}, {}]", float_text(p.x, single), float_text(p.y, single)),
        Value::V3(p) => format!(
            "[{}, {}, {}]",
            float_text(p.x, single),
            float_text(p.y, single),
            float_text(p.z, single)
        ),
        Value::Struct(fs) => {
            let tys = field_types(ty, structs);
            let parts: Vec<String> = fs
                .iter()
                .enumerate()
                .map(|(i, f)| value_text(f, tys.get(i).copied().unwrap_or(Ty::Double), structs))
                .collect();
            format!("{{{}}}", parts.join(", "))
        }
        other => other.to_string(),
    }
}

fn field_types(ty: Ty, structs: &[StructDef]) -> Vec<Ty> {
    match ty {
        Ty::Struct(id) => structs
            .get(id as usize)
            .map(|s| s.fields.iter().map(|(_, t)| *t).collect())
            .unwrap_or_default(),
        _ => Vec::new(),
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
    let modules: Vec<Json> = (0..word.len())
        .map(|i| {
            let sym = word.syms()[i];
            let tys = alphabet.layout(sym, word.data(i).len(), structs);
            let params: Vec<Json> = word
                .values(i, alphabet, structs)
                .iter()
                .enumerate()
                .map(|(j, p)| value_json(p, tys.get(j).copied().unwrap_or(Ty::Double), structs))
                .collect();
            json!({ "symbol": alphabet.name(sym), "params": params })
        })
        .collect();
    json!({ "ring": ring, "step": step, "modules": modules })
}

/// A number: a single-precision value is the `double` nearest the shortest
/// decimal of its `float`, so that JSON shows `0.1`, not `0.10000000149011612`.
fn float_json(x: f64, single: bool) -> Json {
    if single && (x as f32) as f64 == x {
        let shortest: f64 = (x as f32).to_string().parse().unwrap_or(x);
        json!(shortest)
    } else {
        json!(x)
    }
}

fn value_json(v: &Value, ty: Ty, structs: &[StructDef]) -> Json {
    let single = ty.is_single();
    match v {
        Value::Int(i) => json!(i),
        Value::Float(f) => float_json(*f, single),
        Value::Bool(b) => json!(b),
        Value::V2(p) => json!([float_json(p.x, single), float_json(p.y, single)]),
        Value::V3(p) => json!([
            float_json(p.x, single),
            float_json(p.y, single),
            float_json(p.z, single)
        ]),
        Value::Struct(fs) => {
            let tys = field_types(ty, structs);
            Json::Array(
                fs.iter()
                    .enumerate()
                    .map(|(i, f)| value_json(f, tys.get(i).copied().unwrap_or(Ty::Double), structs))
                    .collect(),
            )
        }
        Value::Str(s) => json!(s.as_ref()),
        Value::Void | Value::Elem(_) | Value::Set(_) => Json::Null,
    }
}
