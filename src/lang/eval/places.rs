//! The places of assignments: variables, struct fields, vector
//! components and array elements, read and written in place.

use super::super::ir::*;
use super::super::value::Value;
use super::expressions::{char_at, field, out_of_range};
use super::{rt, Cx, Interp, R};

impl<'p> Interp<'p> {
    /// The array indices of a place's path, evaluated in order.
    #[inline(never)]
    fn indices(&mut self, place: &Place, cx: &mut Cx) -> R<Vec<i64>> {
        let mut out = Vec::new();
        for step in &place.path {
            if let Step::Index(e, _) = step {
                out.push(self.expr(e, cx)?.as_i64());
            }
        }
        Ok(out)
    }

    #[inline(never)]
    pub(super) fn load(&mut self, place: &Place, cx: &mut Cx) -> R<Value> {
        let idx = if place.path.is_empty() {
            Vec::new()
        } else {
            self.indices(place, cx)?
        };
        load_at(place, &idx, cx)
    }

    #[inline(never)]
    pub(super) fn store(&mut self, place: &Place, value: Value, cx: &mut Cx) -> R<()> {
        if place.path.iter().all(|s| matches!(s, Step::Field(_))) {
            let root = if place.global {
                &mut cx.env.globals[place.slot as usize]
            } else {
                &mut cx.frame[place.slot as usize]
            };
            set_path(root, &place.path, value);
            return Ok(());
        }
        let idx = self.indices(place, cx)?;
        store_at(place, &idx, value, cx)
    }

    /// Reads a place and writes `f` of its value back, the indices
    /// evaluated once (C's `a[i++] += x` and `a[i++]++` step `i` once).
    /// Returns the old and the new value.
    #[inline(never)]
    pub(super) fn update(
        &mut self,
        place: &Place,
        cx: &mut Cx,
        f: impl FnOnce(Value) -> R<Value>,
    ) -> R<(Value, Value)> {
        if place.path.is_empty() {
            // A plain variable (`s += x`, `i++`): read and written in place.
            let slot = if place.global {
                &mut cx.env.globals[place.slot as usize]
            } else {
                &mut cx.frame[place.slot as usize]
            };
            let new = f(slot.clone())?;
            let cur = std::mem::replace(slot, new.clone());
            return Ok((cur, new));
        }
        let idx = self.indices(place, cx)?;
        let cur = load_at(place, &idx, cx)?;
        let new = f(cur.clone())?;
        store_at(place, &idx, new.clone(), cx)?;
        Ok((cur, new))
    }
}

fn set_path(root: &mut Value, path: &[Step], value: Value) {
    let Some((first, rest)) = path.split_first() else {
        *root = value;
        return;
    };
    let Step::Field(first) = *first else {
        return;
    };
    match root {
        Value::V2(p) => p[first as usize] = value.as_f64(),
        Value::V3(p) => p[first as usize] = value.as_f64(),
        Value::Struct(fs) => set_path(&mut fs[first as usize], rest, value),
        _ => {}
    }
}

/// The value at a place whose array indices `idx` are evaluated.
fn load_at(place: &Place, idx: &[i64], cx: &Cx) -> R<Value> {
    let mut v = if place.global {
        &cx.env.globals[place.slot as usize]
    } else {
        &cx.frame[place.slot as usize]
    };
    let mut k = 0;
    for step in &place.path {
        match step {
            Step::Field(i) => match v {
                Value::Struct(fs) => v = &fs[*i as usize],
                other => return Ok(field(other, *i)),
            },
            Step::Index(_, span) => {
                let i = idx[k];
                k += 1;
                match v {
                    Value::Struct(fs) => match usize::try_from(i).ok().and_then(|i| fs.get(i)) {
                        Some(e) => v = e,
                        None => return Err(out_of_range(i, fs.len(), *span)),
                    },
                    Value::Str(s) => return char_at(s, i, *span),
                    _ => return Ok(Value::Void),
                }
            }
        }
    }
    Ok(v.clone())
}

/// Writes `value` at a place whose array indices `idx` are evaluated.
fn store_at(place: &Place, idx: &[i64], value: Value, cx: &mut Cx) -> R<()> {
    let root = if place.global {
        &mut cx.env.globals[place.slot as usize]
    } else {
        &mut cx.frame[place.slot as usize]
    };
    let mut v = root;
    let mut k = 0;
    for step in &place.path {
        match step {
            Step::Field(i) => match v {
                Value::Struct(fs) => v = &mut fs[*i as usize],
                other => {
                    // The last step: a vector's component.
                    set_path(other, std::slice::from_ref(step), value);
                    return Ok(());
                }
            },
            Step::Index(_, span) => {
                let i = idx[k];
                k += 1;
                match v {
                    Value::Struct(fs) => {
                        let n = fs.len();
                        match usize::try_from(i).ok().and_then(|i| fs.get_mut(i)) {
                            Some(e) => v = e,
                            None => return Err(out_of_range(i, n, *span)),
                        }
                    }
                    Value::Str(_) => {
                        return Err(rt(
                            Some(*span),
                            "a character of a string cannot be assigned; build the string with sprintf, strcpy or strcat",
                        ))
                    }
                    _ => return Ok(()),
                }
            }
        }
    }
    *v = value;
    Ok(())
}
