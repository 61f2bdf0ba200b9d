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
    let text = |f: &mut Formatter<'_>, buf: &mut Vec<u8>, i: usize| {
        let sym = word.syms()[i];
        buf.extend_from_slice(alphabet.name(sym).as_bytes());
        let data = word.data(i);
        let tys = f.layouts.of(sym, data.len());
        if !tys.is_empty() {
            buf.push(b'(');
            let mut slots = data;
            for (j, &ty) in tys.iter().enumerate() {
                if j > 0 {
                    buf.extend_from_slice(b", ");
                }
                slots = f.num.value(Style::Text, buf, ty, slots, structs);
            }
            buf.push(b')');
        }
    };
    write_modules(out, word, b' ', || Formatter::new(alphabet, structs), text)
}

/// What one thread needs to format modules: its number buffers, its
/// cache of parameter layouts, and each symbol's last text.
struct Formatter<'a> {
    num: Numbers,
    layouts: Layouts<'a>,
    /// Each symbol's name as a JSON string, once met.
    names: Vec<Option<Vec<u8>>>,
    memo: Memo,
}

impl<'a> Formatter<'a> {
    fn new(alphabet: &'a Alphabet, structs: &'a [StructDef]) -> Self {
        Formatter {
            num: Numbers::default(),
            layouts: Layouts::new(alphabet, structs),
            names: Vec::new(),
            memo: Memo::default(),
        }
    }
}

/// The text of the last module of each symbol, with the bits of its
/// parameters: turtle modules repeat their parameters (`F(1)`, `+(90)`)
/// through the whole word, and a repeat is copied instead of formatted.
/// The text depends on the symbol and those bits alone.
#[derive(Default)]
struct Memo {
    last: Vec<Remembered>,
}

#[derive(Default)]
struct Remembered {
    known: bool,
    bits: Vec<u64>,
    text: Vec<u8>,
}

impl Memo {
    /// Modules with more slots than this, or a longer text, are not kept.
    const SLOTS: usize = 8;
    const TEXT: usize = 256;

    #[inline]
    fn get(&self, sym: crate::lang::Sym, data: &[f64]) -> Option<&[u8]> {
        let r = self.last.get(sym.0 as usize)?;
        let same = r.known
            && r.bits.len() == data.len()
            && r.bits.iter().zip(data).all(|(&b, x)| b == x.to_bits());
        same.then_some(&r.text[..])
    }

    fn put(&mut self, sym: crate::lang::Sym, data: &[f64], text: &[u8]) {
        let k = sym.0 as usize;
        if data.len() > Self::SLOTS || text.len() > Self::TEXT {
            if let Some(r) = self.last.get_mut(k) {
                r.known = false;
            }
            return;
        }
        if self.last.len() <= k {
            self.last.resize_with(k + 1, Remembered::default);
        }
        let r = &mut self.last[k];
        r.known = true;
        r.bits.clear();
        r.bits.extend(data.iter().map(|x| x.to_bits()));
        r.text.clear();
        r.text.extend_from_slice(text);
    }
}

/// Modules in a block formatted by one task.
const BLOCK: usize = 8192;
/// Blocks formatted at once, while the ones before them are written.
const WINDOW: usize = 16;

/// Writes the text `module(f, buf, i)` appends for each module `i` of
/// `word`, in order, `sep` between two modules. A small word is formatted
/// on this thread, a large one in blocks on rayon's pool: a window of
/// blocks is formatted while the window before it is written, so that
/// memory beyond the word stays two windows of text whatever the word's
/// length. The bytes are the same either way: each module's text depends
/// on the module alone.
fn write_modules<'a, W: Write + ?Sized>(
    out: &mut W,
    word: &Word,
    sep: u8,
    init: impl Fn() -> Formatter<'a> + Sync,
    module: impl Fn(&mut Formatter<'a>, &mut Vec<u8>, usize) + Sync,
) -> std::io::Result<()> {
    use rayon::prelude::*;
    let n = word.len();
    let module = |f: &mut Formatter<'a>, buf: &mut Vec<u8>, i: usize| {
        if i > 0 {
            buf.push(sep);
        }
        let (sym, data) = (word.syms()[i], word.data(i));
        if let Some(text) = f.memo.get(sym, data) {
            buf.extend_from_slice(text);
            return;
        }
        let start = buf.len();
        module(f, buf, i);
        f.memo.put(sym, data, &buf[start..]);
    };
    if n < 2 * BLOCK || rayon::current_num_threads() == 1 {
        let mut f = init();
        let mut buf = Chunks::new(out);
        for i in 0..n {
            module(&mut f, &mut buf.text, i);
            buf.flush_if_full()?;
        }
        return buf.finish();
    }
    let format = |window: usize, bufs: &mut Vec<Vec<u8>>| {
        let first = window * WINDOW * BLOCK;
        bufs.par_iter_mut()
            .enumerate()
            .for_each_init(&init, |f, (b, buf)| {
                buf.clear();
                let from = (first + b * BLOCK).min(n);
                let to = (from + BLOCK).min(n);
                for i in from..to {
                    module(f, buf, i);
                }
            });
    };
    let windows = n.div_ceil(WINDOW * BLOCK);
    let mut ready: Vec<Vec<u8>> = vec![Vec::new(); WINDOW];
    let mut next: Vec<Vec<u8>> = vec![Vec::new(); WINDOW];
    format(0, &mut ready);
    for w in 0..windows {
        let mut written = Ok(());
        rayon::in_place_scope(|s| {
            if w + 1 < windows {
                let next = &mut next;
                let format = &format;
                s.spawn(move |_| format(w + 1, next));
            }
            written = ready.iter().try_for_each(|b| out.write_all(b));
        });
        written?;
        std::mem::swap(&mut ready, &mut next);
    }
    Ok(())
}

/// Each symbol's parameter types for the number of slots it was last met
/// with, so that an overloaded module (`F`, `F(l)`) is looked up once.
struct Layouts<'a> {
    alphabet: &'a Alphabet,
    structs: &'a [StructDef],
    known: Vec<Option<(usize, &'a [Ty])>>,
}

impl<'a> Layouts<'a> {
    fn new(alphabet: &'a Alphabet, structs: &'a [StructDef]) -> Self {
        Layouts {
            alphabet,
            structs,
            known: vec![None; alphabet.kinds.len()],
        }
    }

    #[inline]
    fn of(&mut self, sym: crate::lang::Sym, slots: usize) -> &'a [Ty] {
        match self.known.get(sym.0 as usize) {
            Some(Some((n, tys))) if *n == slots => tys,
            _ => {
                let tys = self.alphabet.layout(sym, slots, self.structs);
                if let Some(k) = self.known.get_mut(sym.0 as usize) {
                    *k = Some((slots, tys));
                }
                tys
            }
        }
    }
}

/// Bytes gathered in memory and written to `out` a large chunk at a time,
/// so that a word of millions of modules costs a few hundred writes.
struct Chunks<'a, W: Write + ?Sized> {
    out: &'a mut W,
    text: Vec<u8>,
}

impl<'a, W: Write + ?Sized> Chunks<'a, W> {
    const SIZE: usize = 1 << 16;

    fn new(out: &'a mut W) -> Self {
        Chunks {
            out,
            text: Vec::with_capacity(Self::SIZE + 256),
        }
    }

    fn flush_if_full(&mut self) -> std::io::Result<()> {
        if self.text.len() >= Self::SIZE {
            self.out.write_all(&self.text)?;
            self.text.clear();
        }
        Ok(())
    }

    fn finish(mut self) -> std::io::Result<()> {
        self.out.write_all(&self.text)?;
        self.text.clear();
        Ok(())
    }
}

/// Text or JSON.
#[derive(Clone, Copy)]
enum Style {
    Text,
    Json,
}

/// Numbers written without allocating: integers by `itoa`, floats from
/// the shortest digits `zmij` finds (the digits `std` and `serde_json`
/// print, laid out as each of them lays them out).
#[derive(Default)]
struct Numbers {
    ints: itoa::Buffer,
    floats: zmij::Buffer,
}

impl Numbers {
    /// Writes one parameter of type `ty` read from the front of `slots` as
    /// [`value_text`] or [`value_json`] writes it, and returns the slots
    /// after it.
    fn value<'s>(
        &mut self,
        style: Style,
        out: &mut Vec<u8>,
        ty: Ty,
        slots: &'s [f64],
        structs: &[StructDef],
    ) -> &'s [f64] {
        let at = |i: usize| slots.get(i).copied().unwrap_or(0.0);
        let single = ty.is_single();
        let mut float = |out: &mut Vec<u8>, x: f64| match style {
            Style::Text => self.float_text(out, x, single),
            Style::Json => self.float_json(out, x, single),
        };
        let used = match ty {
            Ty::Int => {
                out.extend_from_slice(self.ints.format(at(0).to_bits() as i64).as_bytes());
                1
            }
            Ty::Float | Ty::Double => {
                float(out, at(0));
                1
            }
            Ty::V2 | Ty::V2d | Ty::V3 | Ty::V3d => {
                let n = if matches!(ty, Ty::V2 | Ty::V2d) { 2 } else { 3 };
                out.push(b'[');
                for k in 0..n {
                    if k > 0 {
                        out.extend_from_slice(match style {
                            Style::Text => b", ",
                            Style::Json => b",",
                        });
                    }
                    float(out, at(k));
                }
                out.push(b']');
                n
            }
            _ => {
                let (v, n) = crate::lang::value::decode(ty, slots, structs);
                match style {
                    Style::Text => out.extend_from_slice(value_text(&v, ty, structs).as_bytes()),
                    Style::Json => {
                        value_json(out, &v, ty, structs).expect("writing into memory does not fail")
                    }
                }
                n
            }
        };
        slots.get(used..).unwrap_or(&[])
    }

    /// Writes `x` as an integer (`-0` for negative zero) and returns true
    /// when it is one whose shortest decimal is itself: every integer below
    /// 2^24 is such a `float` (`single`), and below 2^53 such a `double`.
    fn integer(&mut self, out: &mut Vec<u8>, x: f64, single: bool) -> bool {
        let exact = if single {
            16_777_216.0
        } else {
            9_007_199_254_740_992.0
        };
        if !(x.abs() < exact && (x as i64) as f64 == x) {
            return false;
        }
        if x == 0.0 && x.is_sign_negative() {
            out.push(b'-');
        }
        out.extend_from_slice(self.ints.format(x as i64).as_bytes());
        true
    }

    /// [`float_text`]'s text.
    fn float_text(&mut self, out: &mut Vec<u8>, x: f64, single: bool) {
        let single = single && (x as f32) as f64 == x;
        if self.integer(out, x, single) {
            return;
        }
        if !x.is_finite() {
            out.extend_from_slice(float_text(x, single).as_bytes());
            return;
        }
        let shortest = if single {
            self.floats.format_finite(x as f32)
        } else {
            self.floats.format_finite(x)
        };
        if tie(x, shortest.as_bytes(), single) {
            out.extend_from_slice(float_text(x, single).as_bytes());
        } else {
            display_layout(out, shortest.as_bytes());
        }
    }

    /// [`float_json`]'s text.
    fn float_json(&mut self, out: &mut Vec<u8>, x: f64, single: bool) {
        let single = single && (x as f32) as f64 == x;
        if self.integer(out, x, single) {
            // `zmij` writes such a number as `12.0` (it switches to
            // exponents only at 1e16).
            out.extend_from_slice(b".0");
        } else if !x.is_finite() {
            out.extend_from_slice(b"null");
        } else if single {
            // The `double` nearest the `float`'s shortest decimal, laid out
            // as a `double`.
            let shortest = self.floats.format_finite(x as f32);
            let decimal = if tie(x, shortest.as_bytes(), true) {
                (x as f32).to_string().parse()
            } else {
                shortest.parse()
            };
            let near = decimal.unwrap_or(x);
            out.extend_from_slice(self.floats.format_finite(near).as_bytes());
        } else {
            out.extend_from_slice(self.floats.format_finite(x).as_bytes());
        }
    }
}

/// True when `std` may write `x` otherwise than `shortest`, `zmij`'s
/// shortest decimal of it: when [`may_tie`] says a tie is possible and,
/// for a `float`, [`halfway_f32`] finds that `x` really lies halfway
/// between `shortest` and a neighbour with as many digits.
fn tie(x: f64, shortest: &[u8], single: bool) -> bool {
    may_tie(shortest, single) && (!single || halfway_f32(x as f32, shortest))
}

/// True when the `float` `x` lies exactly halfway between `shortest` (its
/// shortest decimal, as `zmij` wrote it: `-0.47455198`, `1e-7`,
/// `1.5e+16`) and the decimal one unit of its last digit above or below:
/// the one case where two shortest decimals are equally near and `zmij`
/// (half to even) and `std` may choose differently. Exact, in integers:
/// `x = m·2^e` with `m` odd, and `x = (2d ± 1)·10^k / 2` for the digits
/// `d` and exponent `k` of `shortest`; since `2d ± 1` and `5^k` are odd,
/// that needs `e + 1 = k` and `m = (2d ± 1)·5^k` (`k ≥ 0`) or
/// `m·5^-k = 2d ± 1` (`k < 0`). A decimal it cannot read counts as a tie
/// (`std` decides).
fn halfway_f32(x: f32, shortest: &[u8]) -> bool {
    let Some((d, k)) = decimal_parts(shortest) else {
        return true;
    };
    let bits = x.abs().to_bits();
    let (exp, frac) = ((bits >> 23) as i32, (bits & 0x7f_ffff) as u128);
    let (mut m, mut e) = if exp == 0 {
        (frac, -149)
    } else {
        (frac | 1 << 23, exp - 150)
    };
    if m == 0 {
        return false;
    }
    let t = m.trailing_zeros();
    m >>= t;
    e += t as i32;
    if e + 1 != k {
        return false;
    }
    let pow5 = |n: u32| 5u128.checked_pow(n);
    [2 * d + 1, (2 * d).wrapping_sub(1)]
        .into_iter()
        .filter(|&c| c != u128::MAX)
        .any(|c| {
            if k >= 0 {
                pow5(k as u32).and_then(|p| c.checked_mul(p)) == Some(m)
            } else {
                pow5(k.unsigned_abs()).and_then(|p| m.checked_mul(p)) == Some(c)
            }
        })
}

/// The digits and decimal exponent of a decimal as `zmij` writes it:
/// `d·10^k`, the sign left out; `None` for anything else.
fn decimal_parts(s: &[u8]) -> Option<(u128, i32)> {
    let s = s.strip_prefix(b"-").unwrap_or(s);
    let (mantissa, exponent) = match s.iter().position(|&c| c == b'e') {
        Some(i) => {
            let e = std::str::from_utf8(&s[i + 1..]).ok()?;
            (&s[..i], e.trim_start_matches('+').parse::<i32>().ok()?)
        }
        None => (s, 0),
    };
    let (whole, fraction) = match mantissa.iter().position(|&c| c == b'.') {
        Some(i) => (&mantissa[..i], &mantissa[i + 1..]),
        None => (mantissa, &mantissa[..0]),
    };
    if whole.len() + fraction.len() > 30 {
        return None;
    }
    let mut d: u128 = 0;
    for &c in whole.iter().chain(fraction) {
        if !c.is_ascii_digit() {
            return None;
        }
        d = d * 10 + (c - b'0') as u128;
    }
    Some((d, exponent.checked_sub(fraction.len() as i32)?))
}

/// True when the shortest decimal `zmij` wrote has so many digits that
/// another of the same length may lie as close to the number, so that
/// `std` may break the tie the other way (`zmij` rounds half to even, `std`
/// does not). Two candidates one unit `u` of the last of `n` digits apart
/// both read back as the number only when `u` is at most its spacing,
/// which is at most 2^-52 of it for a normal `double` (2^-23 for a
/// `float`), while `u` is more than 10^-n of it: so only at `n` ≥ 16 (7).
/// Subnormal numbers have a coarser spacing; they are below 1e-300
/// (1e-37) and are passed on too.
fn may_tie(shortest: &[u8], single: bool) -> bool {
    let (limit, tiny) = if single { (7, -37) } else { (16, -300) };
    let (mantissa, exponent) = match shortest.iter().position(|&c| c == b'e') {
        Some(k) => {
            let e = std::str::from_utf8(&shortest[k + 1..])
                .ok()
                .and_then(|e| e.trim_start_matches('+').parse::<i32>().ok())
                .unwrap_or(i32::MIN);
            (&shortest[..k], e)
        }
        None => (shortest, 0),
    };
    if exponent <= tiny {
        return true;
    }
    let digits = || mantissa.iter().filter(|c| c.is_ascii_digit());
    let leading = digits().take_while(|&&c| c == b'0').count();
    let trailing = digits().rev().take_while(|&&c| c == b'0').count();
    let all = digits().count();
    all.saturating_sub(leading + trailing) >= limit
}

/// Lays out the digits of a finite, non-integral number that `zmij` wrote
/// (`-1.25`, `0.0001`, `1e-7`, `1.5e+16`) as Rust's `Display` does: every
/// digit in place, with no exponent (`0.0000001`).
fn display_layout(out: &mut Vec<u8>, shortest: &[u8]) {
    let (negative, rest) = match shortest.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, shortest),
    };
    let (mantissa, exponent) = match rest.iter().position(|&c| c == b'e') {
        Some(k) => {
            let e = std::str::from_utf8(&rest[k + 1..])
                .ok()
                .and_then(|e| e.trim_start_matches('+').parse::<i64>().ok())
                .unwrap_or(0);
            (&rest[..k], e)
        }
        None => (rest, 0),
    };
    let whole = mantissa
        .iter()
        .position(|&c| c == b'.')
        .unwrap_or(mantissa.len());
    // At most 17 significant digits (and zeros `zmij` puts before them).
    let mut buf = [0u8; 40];
    let mut len = 0;
    for &c in mantissa.iter().filter(|&&c| c != b'.').take(buf.len()) {
        buf[len] = c;
        len += 1;
    }
    // The decimal point falls after `point` of the digits.
    let mut point = whole as i64 + exponent;
    let leading = buf[..len].iter().take_while(|&&c| c == b'0').count();
    point -= leading as i64;
    let mut digits = &buf[leading..len];
    while let [rest @ .., b'0'] = digits {
        digits = rest;
    }
    if negative {
        out.push(b'-');
    }
    if digits.is_empty() {
        out.push(b'0');
    } else if point <= 0 {
        out.extend_from_slice(b"0.");
        out.extend(std::iter::repeat_n(b'0', (-point) as usize));
        out.extend_from_slice(digits);
    } else if point as usize >= digits.len() {
        out.extend_from_slice(digits);
        out.extend(std::iter::repeat_n(b'0', point as usize - digits.len()));
    } else {
        out.extend_from_slice(&digits[..point as usize]);
        out.push(b'.');
        out.extend_from_slice(&digits[point as usize..]);
    }
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
    let json = |f: &mut Formatter<'_>, buf: &mut Vec<u8>, i: usize| {
        let sym = word.syms()[i];
        let k = sym.0 as usize;
        if f.names.len() <= k {
            f.names.resize(k + 1, None);
        }
        buf.extend_from_slice(b"{\"params\":[");
        let data = word.data(i);
        let mut slots = data;
        for (j, &ty) in f.layouts.of(sym, data.len()).iter().enumerate() {
            if j > 0 {
                buf.push(b',');
            }
            slots = f.num.value(Style::Json, buf, ty, slots, structs);
        }
        buf.extend_from_slice(b"],\"symbol\":");
        let name = f.names[k].get_or_insert_with(|| {
            serde_json::to_vec(alphabet.name(sym)).expect("a string is JSON")
        });
        buf.extend_from_slice(name);
        buf.push(b'}');
    };
    write_modules(out, word, b',', || Formatter::new(alphabet, structs), json)?;
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

    /// Numbers to compare the fast writers with `std` and `serde_json` on:
    /// random bit patterns of both widths, numbers as programs make them,
    /// and the edges of the integer and exponent ranges.
    fn numbers() -> Vec<f64> {
        let mut next = crate::testing::xorshift(0x2545_f491_4f6c_dd1d);
        let mut xs = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            90.0,
            1e-7,
            1e-5,
            1e15,
            1e16,
            1e17,
            1e21,
            1e22,
            1e-300,
            5e-324,
            f64::MAX,
            f64::MIN_POSITIVE,
            f64::NAN,
            f64::INFINITY,
            -f64::INFINITY,
            16_777_215.0,
            16_777_216.0,
            16_777_218.0,
            123_456_792.0,
            3.4e38,
            9_007_199_254_740_991.0,
            9_007_199_254_740_992.0,
            9_007_199_254_740_994.0,
        ];
        for _ in 0..100_000 {
            let r = next();
            xs.push(f64::from_bits(r));
            xs.push(f32::from_bits(r as u32) as f64);
            let k = (r >> 11) as i64 % 2_000_001 - 1_000_000;
            xs.push(k as f64 / 1000.0);
            xs.push((k as f64 / 7.0) as f32 as f64);
            xs.push((k as f64) * 10f64.powi((r % 40) as i32 - 10));
        }
        xs
    }

    #[test]
    fn fast_float_text_is_std_display() {
        let mut num = Numbers::default();
        let mut out = Vec::new();
        for x in numbers() {
            for single in [false, true] {
                out.clear();
                num.float_text(&mut out, x, single);
                assert_eq!(
                    std::str::from_utf8(&out).unwrap(),
                    float_text(x, single),
                    "{x:e} (single: {single})"
                );
            }
        }
    }

    /// A `float` goes to `std` only when it lies exactly halfway between
    /// two shortest decimals. 2,097,152.25 (2^21 + 1/4, a quarter apart
    /// from its neighbours) lies halfway between 2097152.2 and 2097152.3,
    /// which both read back as it: the exact check must see that, and the
    /// text must be `std`'s. Around it and in other decades, 140,000
    /// consecutive floats are written as `std` writes them, and the
    /// halfway ones counted by the exact check are few.
    #[test]
    fn a_float_goes_to_std_only_when_it_lies_halfway() {
        let mut num = Numbers::default();
        // 2^21 + 1/4: floats there are a quarter apart.
        let x = f32::from_bits(2_097_152.0f32.to_bits() + 1);
        assert_eq!(x as f64, 2_097_152.25);
        let shortest = num.floats.format_finite(x).to_string();
        assert!(may_tie(shortest.as_bytes(), true));
        assert!(halfway_f32(x, shortest.as_bytes()), "{shortest}");
        // A neighbour a quarter away is not halfway.
        let y = f32::from_bits(x.to_bits() + 1);
        let s = num.floats.format_finite(y).to_string();
        assert!(!halfway_f32(y, s.as_bytes()), "{s}");
        let (mut out, mut laid) = (Vec::new(), Vec::new());
        let (mut halfway, mut differ) = (0, 0);
        for start in [2_097_152.0f32, 0.1, 0.474_552, 3.3, 1e-30, 1e30, 7.0e6] {
            for i in 0..20_000 {
                let x = f32::from_bits(start.to_bits() + i);
                let z = num.floats.format_finite(x).to_string();
                let half = may_tie(z.as_bytes(), true) && halfway_f32(x, z.as_bytes());
                halfway += half as usize;
                // zmij's digits where std's differ: only ever halfway.
                laid.clear();
                display_layout(&mut laid, z.as_bytes());
                if laid != x.to_string().as_bytes() {
                    differ += 1;
                    assert!(half, "{x:e}: zmij {z}, std {x}, not seen as halfway");
                }
                out.clear();
                num.float_text(&mut out, x as f64, true);
                assert_eq!(std::str::from_utf8(&out).unwrap(), x.to_string(), "{x:e}");
            }
        }
        // From 2^21 a float is a quarter from the next: every other one
        // (x.25, x.75) is halfway, and std and zmij part on some.
        assert!(
            halfway >= 10_000 && differ > 0,
            "{halfway} halfway, {differ} differ"
        );
    }

    #[test]
    fn fast_float_json_is_serde_json() {
        let mut num = Numbers::default();
        let (mut fast, mut slow) = (Vec::new(), Vec::new());
        for x in numbers() {
            for single in [false, true] {
                fast.clear();
                slow.clear();
                num.float_json(&mut fast, x, single);
                float_json(&mut slow, x, single).unwrap();
                assert_eq!(
                    std::str::from_utf8(&fast).unwrap(),
                    std::str::from_utf8(&slow).unwrap(),
                    "{x:e} (single: {single})"
                );
            }
        }
    }

    /// The text as this module wrote it before it wrote numbers itself:
    /// each module's values decoded, then printed with `std`.
    fn text_by_values(word: &Word, alphabet: &Alphabet, structs: &[StructDef]) -> String {
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
                let texts: Vec<String> = params
                    .iter()
                    .enumerate()
                    .map(|(j, p)| value_text(p, tys.get(j).copied().unwrap_or(Ty::Double), structs))
                    .collect();
                out.push_str(&format!("({})", texts.join(", ")));
            }
        }
        out
    }

    #[test]
    fn the_fast_text_is_the_values_text() {
        let text = r#"
            struct S { int k; float w; V2f v; };
            struct E { };
            module A(float, double, int, bool);
            module D(E);
            module B(V2f, V3d);
            module C(S);
            module T(float);
            Axiom: A(0.1, 1e-7, -3, true) B(V2f(1.5, -2.25), V3d(1e300, 0, -0.5)) C(S(7, 0.3f, V2f(0, 1e-30))) D(E()) F F(2) T(1);
            derivation length: 6;
            T(x) : { produce T(x / 3) T(x * 7.1) F(x + 0.1); }
        "#;
        let curve = crate::load_str("t.lsys", text, &[]).unwrap_or_else(|e| panic!("{e}"));
        let run = curve.run(Default::default()).unwrap();
        let (alphabet, structs) = (&curve.program.alphabet, &curve.program.structs);
        let word = run.word();
        assert!(word.len() > 100);
        assert_eq!(
            word_text(word, alphabet, structs),
            text_by_values(word, alphabet, structs)
        );
    }

    /// A word of several windows of blocks is written in parallel blocks,
    /// in pools of one and of three threads: the text is the values' text
    /// and the JSON the tree's, byte for byte. Modules repeat (the memo's
    /// copies), and `F` comes with and without parameters and with 0 and
    /// -0 between others.
    #[test]
    fn a_long_word_in_blocks_is_the_same_text_for_any_number_of_threads() {
        let text = r#"
            struct S { int k; float w; V2f v; };
            module A(float, double, int, bool);
            module C(S);
            module T(float);
            Axiom: A(0.1, 1e-7, -3, true) C(S(7, 0.3f, V2f(0, 1e-30))) F T(1);
            derivation length: 15;
            T(x) : { produce T(x / 3) C(S(2, x, V2f(x, -x))) T(x * 1.7) F(x + 0.1) F Left(30) F(1) F(0 * x) F(-0.0 * x) Right(30); }
        "#;
        let curve = crate::load_str("t.lsys", text, &[]).unwrap_or_else(|e| panic!("{e}"));
        let run = curve.run(Default::default()).unwrap();
        let (alphabet, structs) = (&curve.program.alphabet, &curve.program.structs);
        let word = run.word();
        // Past two windows, and not a whole number of blocks.
        assert!(word.len() > 2 * WINDOW * BLOCK, "{}", word.len());
        assert_ne!(word.len() % BLOCK, 0);
        let text_ref = text_by_values(word, alphabet, structs);
        let json_ref = tree(word, false, 15, alphabet, structs).to_string();
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let (text, json) = pool.install(|| {
                (
                    word_text(word, alphabet, structs),
                    word_json(word, false, 15, alphabet, structs),
                )
            });
            assert!(text == text_ref, "text differs on {threads} threads");
            assert!(json == json_ref, "JSON differs on {threads} threads");
        }
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
