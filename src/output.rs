//! Words as text and as JSON.
//!
//! A parameter of a single-precision type (`float`, `V2f`, `V3f`) is written
//! as the shortest decimal that reads back as the same `float`, as lpfg's
//! users see it: `1.9999987`, not the `double` `1.999998688697815` that
//! holds it.

use std::io::Write;

use crate::lang::value::StructDef;
use crate::lang::{Alphabet, Ty, Value};
use crate::rewrite::Word;

/// `P([0, 0.25]) E A(1, 2)`: one module after another, vectors in brackets.
pub fn word_text(word: &Word, alphabet: &Alphabet, structs: &[StructDef]) -> String {
    let mut out = Vec::new();
    write_word_text(&mut out, word, alphabet, structs).expect("writing into memory does not fail");
    String::from_utf8(out).expect("the text is UTF-8")
}

/// [`word_text`], written as it goes.
pub fn write_word_text(
    out: &mut impl Write,
    word: &Word,
    alphabet: &Alphabet,
    structs: &[StructDef],
) -> std::io::Result<()> {
    for i in 0..word.len() {
        let sym = word.syms()[i];
        if i > 0 {
            out.write_all(b" ")?;
        }
        out.write_all(alphabet.name(sym).as_bytes())?;
        if word.data(i).is_empty() && alphabet.layout(sym, 0, structs).is_empty() {
            continue;
        }
        let params = word.values(i, alphabet, structs);
        if !params.is_empty() {
            let tys = alphabet.layout(sym, word.data(i).len(), structs);
            out.write_all(b"(")?;
            for (j, p) in params.iter().enumerate() {
                if j > 0 {
                    out.write_all(b", ")?;
                }
                let ty = tys.get(j).copied().unwrap_or(Ty::Double);
                out.write_all(value_text(p, ty, structs).as_bytes())?;
            }
            out.write_all(b")")?;
        }
    }
    Ok(())
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
/// `{"modules": [{"params": [[0.0, 1.0]], "symbol": "P"}, …], "ring": bool, "step": N}`,
/// keys in that order, compact, as a `serde_json` value of the same word
/// prints; written as it goes, with no tree of values.
pub fn write_word_json(
    out: &mut impl Write,
    word: &Word,
    ring: bool,
    step: u64,
    alphabet: &Alphabet,
    structs: &[StructDef],
) -> std::io::Result<()> {
    out.write_all(b"{\"modules\":[")?;
    // Each symbol's name as a JSON string, and whether it has parameters
    // when it takes no slots (a struct of no fields is one), made once.
    let mut names: Vec<Option<(Vec<u8>, bool)>> = Vec::new();
    for i in 0..word.len() {
        if i > 0 {
            out.write_all(b",")?;
        }
        let sym = word.syms()[i];
        let k = sym.0 as usize;
        if names.len() <= k {
            names.resize(k + 1, None);
        }
        let (name, bare) = names[k].get_or_insert_with(|| {
            (
                serde_json::to_vec(alphabet.name(sym)).expect("a string is JSON"),
                alphabet.layout(sym, 0, structs).is_empty(),
            )
        });
        out.write_all(b"{\"params\":[")?;
        if !(word.data(i).is_empty() && *bare) {
            let tys = alphabet.layout(sym, word.data(i).len(), structs);
            for (j, p) in word.values(i, alphabet, structs).iter().enumerate() {
                if j > 0 {
                    out.write_all(b",")?;
                }
                value_json(out, p, tys.get(j).copied().unwrap_or(Ty::Double), structs)?;
            }
        }
        out.write_all(b"],\"symbol\":")?;
        out.write_all(name)?;
        out.write_all(b"}")?;
    }
    write!(out, "],\"ring\":{ring},\"step\":{step}}}")
}

/// [`write_word_json`] into a string.
pub fn word_json(
    word: &Word,
    ring: bool,
    step: u64,
    alphabet: &Alphabet,
    structs: &[StructDef],
) -> String {
    let mut out = Vec::new();
    write_word_json(&mut out, word, ring, step, alphabet, structs)
        .expect("writing into memory does not fail");
    String::from_utf8(out).expect("JSON is UTF-8")
}

/// A number as JSON shows it (`null` for a non-finite one): a
/// single-precision value is the `double` nearest the shortest decimal of
/// its `float`, so that JSON shows `0.1`, not `0.10000000149011612`.
fn float_json(out: &mut impl Write, x: f64, single: bool) -> std::io::Result<()> {
    let x = if single && (x as f32) as f64 == x {
        (x as f32).to_string().parse().unwrap_or(x)
    } else {
        x
    };
    if x.is_finite() {
        serde_json::to_writer(&mut *out, &x)?;
        Ok(())
    } else {
        out.write_all(b"null")
    }
}

fn value_json(
    out: &mut impl Write,
    v: &Value,
    ty: Ty,
    structs: &[StructDef],
) -> std::io::Result<()> {
    let single = ty.is_single();
    match v {
        Value::Int(i) => write!(out, "{i}"),
        Value::Float(f) => float_json(out, *f, single),
        Value::Bool(b) => write!(out, "{b}"),
        Value::V2(p) => {
            out.write_all(b"[")?;
            float_json(out, p.x, single)?;
            out.write_all(b",")?;
            float_json(out, p.y, single)?;
            out.write_all(b"]")
        }
        Value::V3(p) => {
            out.write_all(b"[")?;
            float_json(out, p.x, single)?;
            out.write_all(b",")?;
            float_json(out, p.y, single)?;
            out.write_all(b",")?;
            float_json(out, p.z, single)?;
            out.write_all(b"]")
        }
        Value::Struct(fs) => {
            let tys = field_types(ty, structs);
            out.write_all(b"[")?;
            for (i, f) in fs.iter().enumerate() {
                if i > 0 {
                    out.write_all(b",")?;
                }
                value_json(out, f, tys.get(i).copied().unwrap_or(Ty::Double), structs)?;
            }
            out.write_all(b"]")
        }
        Value::Str(s) => {
            serde_json::to_writer(&mut *out, s.as_ref())?;
            Ok(())
        }
        Value::Void | Value::Elem(_) | Value::Set(_) => out.write_all(b"null"),
    }
}

#[cfg(test)]
mod tests {
    use serde_json::{json, Value as Json};

    use super::*;

    /// The word as a `serde_json` tree, as this module built it before it
    /// wrote as it went: the reference for the streamed text.
    fn tree(
        word: &Word,
        ring: bool,
        step: u64,
        alphabet: &Alphabet,
        structs: &[StructDef],
    ) -> Json {
        fn float(x: f64, single: bool) -> Json {
            if single && (x as f32) as f64 == x {
                let shortest: f64 = (x as f32).to_string().parse().unwrap_or(x);
                json!(shortest)
            } else {
                json!(x)
            }
        }
        fn value(v: &Value, ty: Ty, structs: &[StructDef]) -> Json {
            let single = ty.is_single();
            match v {
                Value::Int(i) => json!(i),
                Value::Float(f) => float(*f, single),
                Value::Bool(b) => json!(b),
                Value::V2(p) => json!([float(p.x, single), float(p.y, single)]),
                Value::V3(p) => json!([float(p.x, single), float(p.y, single), float(p.z, single)]),
                Value::Struct(fs) => {
                    let tys = field_types(ty, structs);
                    Json::Array(
                        fs.iter()
                            .enumerate()
                            .map(|(i, f)| {
                                value(f, tys.get(i).copied().unwrap_or(Ty::Double), structs)
                            })
                            .collect(),
                    )
                }
                Value::Str(s) => json!(s.as_ref()),
                Value::Void | Value::Elem(_) | Value::Set(_) => Json::Null,
            }
        }
        let modules: Vec<Json> = (0..word.len())
            .map(|i| {
                let sym = word.syms()[i];
                let tys = alphabet.layout(sym, word.data(i).len(), structs);
                let params: Vec<Json> = word
                    .values(i, alphabet, structs)
                    .iter()
                    .enumerate()
                    .map(|(j, p)| value(p, tys.get(j).copied().unwrap_or(Ty::Double), structs))
                    .collect();
                json!({ "symbol": alphabet.name(sym), "params": params })
            })
            .collect();
        json!({ "ring": ring, "step": step, "modules": modules })
    }

    /// Every kind of parameter, streamed, prints as the tree prints.
    #[test]
    fn the_streamed_json_is_the_trees() {
        let text = r#"
            struct S { int k; float w; V2f v; };
            struct E { };
            module A(float, double, int, bool);
            module D(E);
            module B(V2f, V3d);
            module C(S);
            Axiom: A(0.1, 1e-7, -3, true) B(V2f(1.5, -2.25), V3d(1e300, 0, -0.5)) C(S(7, 0.3f, V2f(0, 1e-30))) D(E()) F;
            derivation length: 0;
        "#;
        let curve = crate::load_str("t.lsys", text, &[]).unwrap_or_else(|e| panic!("{e}"));
        let run = curve.run(Default::default()).unwrap();
        let (alphabet, structs) = (&curve.program.alphabet, &curve.program.structs);
        let word = run.word();
        for ring in [false, true] {
            let streamed = word_json(word, ring, 3, alphabet, structs);
            let reference = tree(word, ring, 3, alphabet, structs).to_string();
            assert_eq!(streamed, reference);
            assert!(serde_json::from_str::<Json>(&streamed).is_ok());
        }
    }
}
