//! C's `printf` formatting, for `printf`, `fprintf` and `sprintf` in L+C
//! programs: conversions `d i u x X o c s f F e E g G %`, the flags `-
//! 0 + space #`, widths and precisions (also `*`), and the length
//! modifiers `h hh l ll L z j t`, which change nothing here (integers are
//! 64 bits, floats doubles).
//!
//! A conversion applied to a value of another kind converts it as a cast
//! would (`%d` of 2.7 prints 2) rather than reinterpreting its bits.

use super::value::Value;

/// One conversion specification: `%-08.3f` is `left`, `zero`, width 8,
/// precision 3, conversion `f`.
#[derive(Clone, Copy, Debug, Default)]
struct Spec {
    left: bool,
    zero: bool,
    plus: bool,
    space: bool,
    alt: bool,
    width: usize,
    precision: Option<usize>,
    conv: char,
}

/// Widths and precisions larger than this are refused: a program cannot
/// make one conversion allocate without bound.
pub const MAX_WIDTH: usize = 10_000;

/// Formats `args` by the C format string `fmt`. An error says what is
/// wrong with the format or the arguments.
pub fn format(fmt: &str, args: &[Value]) -> Result<String, String> {
    let mut out = String::new();
    let mut args = args.iter();
    let mut chars = fmt.chars().peekable();
    while let Some(c) = chars.next() {
        if c != '%' {
            out.push(c);
            continue;
        }
        let mut spec = Spec::default();
        while let Some(&f) = chars.peek() {
            match f {
                '-' => spec.left = true,
                '0' => spec.zero = true,
                '+' => spec.plus = true,
                ' ' => spec.space = true,
                '#' => spec.alt = true,
                _ => break,
            }
            chars.next();
        }
        let mut next_arg = |what: &str| {
            args.next().ok_or_else(|| {
                format!("the format \"{fmt}\" needs more arguments than given ({what})")
            })
        };
        if chars.peek() == Some(&'*') {
            chars.next();
            let w = next_arg("a `*` width")?.as_i64();
            if w < 0 {
                spec.left = true;
            }
            spec.width = w.unsigned_abs() as usize;
        } else {
            spec.width = digits(&mut chars);
        }
        if chars.peek() == Some(&'.') {
            chars.next();
            if chars.peek() == Some(&'*') {
                chars.next();
                let p = next_arg("a `*` precision")?.as_i64();
                spec.precision = (p >= 0).then_some(p as usize);
            } else {
                spec.precision = Some(digits(&mut chars));
            }
        }
        if spec.width > MAX_WIDTH || spec.precision.unwrap_or(0) > MAX_WIDTH {
            return Err(format!(
                "a width or precision in the format \"{fmt}\" is larger than {MAX_WIDTH}"
            ));
        }
        while let Some(&l) = chars.peek() {
            if matches!(l, 'h' | 'l' | 'L' | 'z' | 'j' | 't' | 'q') {
                chars.next();
            } else {
                break;
            }
        }
        let Some(conv) = chars.next() else {
            return Err(format!("the format \"{fmt}\" ends inside a `%` conversion"));
        };
        spec.conv = conv;
        if conv == '%' {
            out.push('%');
            continue;
        }
        let arg = next_arg(&format!("`%{conv}`"))?;
        let body = match conv {
            'd' | 'i' => signed(&spec, arg.as_i64()),
            'u' => unsigned(&spec, arg.as_i64() as u64, 10, false),
            'x' => unsigned(&spec, arg.as_i64() as u64, 16, false),
            'X' => unsigned(&spec, arg.as_i64() as u64, 16, true),
            'o' => unsigned(&spec, arg.as_i64() as u64, 8, false),
            'c' => {
                let code = arg.as_i64();
                let ch = u32::try_from(code)
                    .ok()
                    .and_then(char::from_u32)
                    .unwrap_or('?');
                pad(&spec, String::new(), ch.to_string(), false)
            }
            's' => {
                let text = match arg {
                    Value::Str(s) => s.to_string(),
                    other => other.to_string(),
                };
                let text = match spec.precision {
                    Some(p) => text.chars().take(p).collect(),
                    None => text,
                };
                pad(&spec, String::new(), text, false)
            }
            'f' | 'F' | 'e' | 'E' | 'g' | 'G' => float(&spec, arg.as_f64()),
            other => {
                return Err(format!(
                    "`%{other}` in the format \"{fmt}\" is not a conversion this program may use"
                ))
            }
        };
        out.push_str(&body);
    }
    Ok(out)
}

fn digits(chars: &mut std::iter::Peekable<std::str::Chars>) -> usize {
    let mut n: usize = 0;
    while let Some(d) = chars.peek().and_then(|c| c.to_digit(10)) {
        n = n.saturating_mul(10).saturating_add(d as usize);
        chars.next();
    }
    n
}

/// The sign a number prints with: `-`, or `+`/space when asked.
fn sign(spec: &Spec, negative: bool) -> String {
    if negative {
        "-".into()
    } else if spec.plus {
        "+".into()
    } else if spec.space {
        " ".into()
    } else {
        String::new()
    }
}

/// Pads `sign` + `digits` to the width: spaces on the left, on the right
/// (`-`), or zeros between the sign and the digits (`0`, for numbers).
fn pad(spec: &Spec, sign: String, digits: String, numeric: bool) -> String {
    let len = sign.chars().count() + digits.chars().count();
    if len >= spec.width {
        return sign + &digits;
    }
    let fill = spec.width - len;
    if spec.left {
        sign + &digits + &" ".repeat(fill)
    } else if spec.zero && numeric {
        sign + &"0".repeat(fill) + &digits
    } else {
        " ".repeat(fill) + &sign + &digits
    }
}

fn signed(spec: &Spec, v: i64) -> String {
    let mut digits = v.unsigned_abs().to_string();
    if let Some(p) = spec.precision {
        if p == 0 && v == 0 {
            digits.clear();
        }
        while digits.len() < p {
            digits.insert(0, '0');
        }
    }
    // A precision turns the `0` flag off for integers.
    let spec = Spec {
        zero: spec.zero && spec.precision.is_none(),
        ..*spec
    };
    pad(&spec, sign(&spec, v < 0), digits, true)
}

fn unsigned(spec: &Spec, v: u64, radix: u32, upper: bool) -> String {
    let mut digits = match radix {
        16 if upper => format!("{v:X}"),
        16 => format!("{v:x}"),
        8 => format!("{v:o}"),
        _ => v.to_string(),
    };
    if let Some(p) = spec.precision {
        if p == 0 && v == 0 {
            digits.clear();
        }
        while digits.len() < p {
            digits.insert(0, '0');
        }
    }
    let prefix = match (spec.alt, radix, v) {
        (true, 16, v) if v != 0 => {
            if upper {
                "0X"
            } else {
                "0x"
            }
        }
        (true, 8, _) if !digits.starts_with('0') => "0",
        _ => "",
    };
    let spec = Spec {
        zero: spec.zero && spec.precision.is_none(),
        ..*spec
    };
    pad(&spec, prefix.to_string(), digits, true)
}

fn float(spec: &Spec, v: f64) -> String {
    let upper = spec.conv.is_ascii_uppercase();
    let negative = v.is_sign_negative() && !v.is_nan();
    if !v.is_finite() {
        let word = match (v.is_nan(), upper) {
            (true, false) => "nan",
            (true, true) => "NAN",
            (false, false) => "inf",
            (false, true) => "INF",
        };
        let spec = Spec {
            zero: false,
            ..*spec
        };
        return pad(&spec, sign(&spec, negative), word.into(), true);
    }
    let a = v.abs();
    let p = spec.precision.unwrap_or(6);
    let mut body = match spec.conv.to_ascii_lowercase() {
        'f' => fixed(a, p, spec.alt),
        'e' => exponent(a, p, spec.alt),
        _ => general(a, p, spec.alt),
    };
    if upper {
        body = body.to_ascii_uppercase();
    }
    pad(spec, sign(spec, negative), body, true)
}

/// `%f`: `p` digits after the point, rounded as C rounds (to the nearest,
/// ties to even, of the exact binary value; Rust's formatting does the same).
fn fixed(a: f64, p: usize, alt: bool) -> String {
    let mut s = format!("{a:.p$}");
    if alt && p == 0 {
        s.push('.');
    }
    s
}

/// `%e`: one digit, the point, `p` digits, `e`, the exponent's sign and at
/// least two digits.
fn exponent(a: f64, p: usize, alt: bool) -> String {
    let s = format!("{a:.p$e}");
    let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let mut m = mantissa.to_string();
    if alt && p == 0 {
        m.push('.');
    }
    let sign = if exp < 0 { '-' } else { '+' };
    format!("{m}e{sign}{:02}", exp.unsigned_abs())
}

/// `%g`: `%e` or `%f` by the exponent that `%e` with `p - 1` digits would
/// print, with `p` significant digits, trailing zeros removed (unless `#`).
fn general(a: f64, p: usize, alt: bool) -> String {
    let p = p.max(1);
    let e = format!("{a:.*e}", p - 1);
    let x: i64 = e
        .split_once('e')
        .and_then(|(_, x)| x.parse().ok())
        .unwrap_or(0);
    let mut s = if (x < p as i64) && x >= -4 {
        fixed(a, (p as i64 - 1 - x) as usize, alt)
    } else {
        exponent(a, p - 1, alt)
    };
    if !alt {
        // Trailing zeros of the fraction go, and a point left alone.
        let (num, exp) = match s.find('e') {
            Some(i) => (s[..i].to_string(), s[i..].to_string()),
            None => (s.clone(), String::new()),
        };
        let num = if num.contains('.') {
            num.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            num
        };
        s = num + &exp;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(fmt: &str, args: &[Value]) -> String {
        format(fmt, args).unwrap()
    }

    fn i(v: i64) -> Value {
        Value::Int(v)
    }

    fn x(v: f64) -> Value {
        Value::Float(v)
    }

    // Every expected string below was printed by glibc's printf: a C
    // program with the same format and arguments, compiled with gcc on
    // the build machine (see the comment of each group).

    /// printf("[%d] [%5d] [%-5d|] [%05d] [%+d] [% d] [%.3d] [%i] [%ld]", 42, 42, 42, 42, 42, 42, 7, -3, 123456789012)
    #[test]
    fn integers() {
        assert_eq!(
            f(
                "[%d] [%5d] [%-5d|] [%05d] [%+d] [% d] [%.3d] [%i] [%ld]",
                &[
                    i(42),
                    i(42),
                    i(42),
                    i(42),
                    i(42),
                    i(42),
                    i(7),
                    i(-3),
                    i(123456789012)
                ]
            ),
            "[42] [   42] [42   |] [00042] [+42] [ 42] [007] [-3] [123456789012]"
        );
        // printf("[%05d] [%-+6d|] [%.0d] [%08.3d]", -42, 5, 0, 12)
        assert_eq!(
            f(
                "[%05d] [%-+6d|] [%.0d] [%08.3d]",
                &[i(-42), i(5), i(0), i(12)]
            ),
            "[-0042] [+5    |] [] [     012]"
        );
    }

    /// printf("[%x] [%X] [%#x] [%o] [%#o] [%08x] [%u]", 255, 255, 255, 8, 8, 48879, 17)
    #[test]
    fn radixes() {
        assert_eq!(
            f(
                "[%x] [%X] [%#x] [%o] [%#o] [%08x] [%u]",
                &[i(255), i(255), i(255), i(8), i(8), i(48879), i(17)]
            ),
            "[ff] [FF] [0xff] [10] [010] [0000beef] [17]"
        );
    }

    /// printf("[%f] [%.2f] [%8.3f] [%-8.1f|] [%08.2f] [%+.1f] [%.0f] [%.0f] [%.0f] [%#.0f] [%lf]",
    ///        3.14158, 2.675, -1.5, 0.25, -3.14158, 2.0, 0.5, 1.5, 2.5, 3.0, 1e10)
    #[test]
    fn fixed_point() {
        assert_eq!(
            f(
                "[%f] [%.2f] [%8.3f] [%-8.1f|] [%08.2f] [%+.1f] [%.0f] [%.0f] [%.0f] [%#.0f] [%lf]",
                &[
                    x(3.14158),
                    x(2.675),
                    x(-1.5),
                    x(0.25),
                    x(-3.14158),
                    x(2.0),
                    x(0.5),
                    x(1.5),
                    x(2.5),
                    x(3.0),
                    x(1e10)
                ]
            ),
            "[3.141580] [2.67] [  -1.500] [0.2     |] [-0003.14] [+2.0] [0] [2] [2] [3.] [10000000000.000000]"
        );
    }

    /// printf("[%e] [%.2e] [%E] [%12.3e] [%e] [%.0e] [%e]", 12345.678, 0.000123456, 1e-300, -2.5, 0.0, 5e10, 1e100)
    #[test]
    fn exponents() {
        assert_eq!(
            f(
                "[%e] [%.2e] [%E] [%12.3e] [%e] [%.0e] [%e]",
                &[x(12345.678), x(0.000123456), x(1e-300), x(-2.5), x(0.0), x(5e10), x(1e100)]
            ),
            "[1.234568e+04] [1.23e-04] [1.000000E-300] [  -2.500e+00] [0.000000e+00] [5e+10] [1.000000e+100]"
        );
    }

    /// printf("[%g] [%g] [%g] [%g] [%g] [%g] [%.3g] [%10.4g] [%G] [%#g] [%g] [%g]",
    ///        0.0001, 0.00001, 123456.0, 1234567.0, 100.0, 2.5, 3.14158, 1234.5678, 1e-20, 1.0, 0.1+0.2, -0.0)
    #[test]
    fn general_form() {
        assert_eq!(
            f(
                "[%g] [%g] [%g] [%g] [%g] [%g] [%.3g] [%10.4g] [%G] [%#g] [%g] [%g]",
                &[
                    x(0.0001),
                    x(0.00001),
                    x(123456.0),
                    x(1234567.0),
                    x(100.0),
                    x(2.5),
                    x(3.14158),
                    x(1234.5678),
                    x(1e-20),
                    x(1.0),
                    x(0.1 + 0.2),
                    x(-0.0)
                ]
            ),
            "[0.0001] [1e-05] [123456] [1.23457e+06] [100] [2.5] [3.14] [      1235] [1E-20] [1.00000] [0.3] [-0]"
        );
    }

    /// printf("[%s] [%10s] [%-6s|] [%.2s] [%c] [%5c] [%%] [%*d] [%-*d|] [%.*f]",
    ///        "abc", "right", "left", "cut", 'A', 'z', 4, 7, 4, 7, 2, 3.14158)
    #[test]
    fn strings_chars_and_stars() {
        let s = |t: &str| Value::Str(t.into());
        assert_eq!(
            f(
                "[%s] [%10s] [%-6s|] [%.2s] [%c] [%5c] [%%] [%*d] [%-*d|] [%.*f]",
                &[
                    s("abc"),
                    s("right"),
                    s("left"),
                    s("cut"),
                    i(65),
                    i(122),
                    i(4),
                    i(7),
                    i(4),
                    i(7),
                    i(2),
                    x(3.14158)
                ]
            ),
            "[abc] [     right] [left  |] [cu] [A] [    z] [%] [   7] [7   |] [3.14]"
        );
    }

    /// printf("[%f] [%5.1f] [%e] [%g] [%-6f|]", INFINITY, -INFINITY, NAN, INFINITY, NAN)
    #[test]
    fn non_finite() {
        assert_eq!(
            f(
                "[%f] [%5.1f] [%e] [%g] [%-6f|]",
                &[
                    x(f64::INFINITY),
                    x(f64::NEG_INFINITY),
                    x(f64::NAN),
                    x(f64::INFINITY),
                    x(f64::NAN)
                ]
            ),
            "[inf] [ -inf] [nan] [inf] [nan   |]"
        );
    }

    #[test]
    fn errors_are_messages() {
        assert!(format("%d %d", &[i(1)])
            .unwrap_err()
            .contains("more arguments"));
        assert!(format("100%", &[]).unwrap_err().contains("ends inside"));
        assert!(format("%99999d", &[i(1)])
            .unwrap_err()
            .contains("larger than"));
        assert!(format("%n", &[i(1)]).unwrap_err().contains("`%n`"));
    }
}
