//! The golden-file helper's own comparisons: too lenient a comparison
//! would let every golden test pass.

use crate::golden::*;
use crate::support::scratch;

/// The comparison itself: these would pass if it were too lenient.
#[test]
fn numeric_comparison_tolerates_last_bits_and_nothing_more() {
    let ok = |a: &str, b: &str| compare_numeric(a.as_bytes(), b.as_bytes()).is_ok();
    assert!(ok("v 0.1 0.2\n", "v 0.1 0.2\n"));
    assert!(ok("v 0.3333333333\n", "v 0.3333333334\n"));
    assert!(ok("x 1e-7\n", "x 0.0000001\n"));
    assert!(ok("x 1234567890.5\n", "x 1234567890.6\n"));
    assert!(!ok("v 0.1 0.2\n", "v 0.1 0.2000001\n"));
    assert!(!ok("f 1 2 3\n", "f 1 2 4\n"));
    assert!(!ok("n 1\n", "n 1.0\n"), "an integer is not a float");
    assert!(!ok("P(1)\n", "Q(1)\n"));
    assert!(!ok("a\nb\n", "a\n"));
    assert_eq!(round(0.1 + 0.2), 0.3);
    assert_eq!(round(-1e-17), 0.0);
    assert!(round(-1e-17).is_sign_positive());
    assert_eq!(round(2.0 / 3.0), 0.6666666667);
    assert_eq!(
        tokens("P(-1.5e-3, 2) fig10-kolam"),
        [
            Token::Other("P("),
            Token::Number("-1.5e-3"),
            Token::Other(", "),
            Token::Number("2"),
            Token::Other(") fig"),
            Token::Number("10"),
            Token::Other("-kolam"),
        ]
    );
}

#[test]
fn json_lines_is_json_with_one_module_per_line() {
    let v = serde_json::json!({"ring": true, "step": 2,
        "modules": [{"symbol": "P", "params": [[0.1 + 0.2, 1e-17]]}, {"symbol": "F", "params": []}]});
    let s = json_lines(&v);
    assert_eq!(
        s,
        "{\n\"modules\": [\n{\"params\":[[0.3,0.0]],\"symbol\":\"P\"},\n\
         {\"params\":[],\"symbol\":\"F\"}\n],\n\"ring\": true,\n\"step\": 2\n}\n"
    );
    let back: serde_json::Value = serde_json::from_str(&s).unwrap();
    assert_eq!(back["modules"][0]["params"][0][0], 0.3);
}

/// A missing expectation fails unless `UPDATE_GOLDEN` asks for it to be
/// written; a differing one is reported with the line that differs.
#[test]
fn a_missing_or_differing_expectation_fails() {
    let tmp = scratch("golden");
    let dir = tmp.path();
    let missing = dir.join("missing.txt");
    let result = compare(&missing, b"x\n", Kind::Exact);
    if updating() {
        assert!(result.is_ok());
        assert_eq!(std::fs::read(&missing).unwrap(), b"x\n");
        std::fs::remove_file(&missing).unwrap();
    } else {
        let e = result.unwrap_err();
        assert!(e.contains("cannot read the expectation"), "{e}");
        assert!(!missing.exists());
    }
    let present = dir.join("present.txt");
    std::fs::write(&present, "a\nb\n").unwrap();
    assert!(compare(&present, b"a\nb\n", Kind::Exact).is_ok());
    if !updating() {
        let e = compare(&present, b"a\nc\n", Kind::Exact).unwrap_err();
        assert!(e.contains("line 2") && e.contains("expected: b"), "{e}");
    }
}

/// Pictures: one pixel in a hundred far off is too many; a faint change
/// everywhere is not.
#[test]
fn png_comparison_has_its_documented_tolerance() {
    let picture = |f: &dyn Fn(u32, u32) -> u8| {
        let mut pm = tiny_skia::Pixmap::new(10, 10).unwrap();
        for y in 0..10 {
            for x in 0..10 {
                let v = f(x, y);
                let i = (y * 10 + x) as usize;
                pm.pixels_mut()[i] =
                    tiny_skia::PremultipliedColorU8::from_rgba(v, v, v, 255).unwrap();
            }
        }
        pm.encode_png().unwrap()
    };
    let white = picture(&|_, _| 255);
    let tmp = scratch("golden-png");
    let dir = tmp.path();
    let path = dir.join("white.png");
    std::fs::write(&path, &white).unwrap();
    assert!(compare(&path, &picture(&|_, _| 254), Kind::Png).is_ok());
    if !updating() {
        let one_black = picture(&|x, y| if (x, y) == (3, 4) { 0 } else { 255 });
        assert!(compare(&path, &one_black, Kind::Png).is_err());
        let grey = picture(&|_, _| 250);
        assert!(
            compare(&path, &grey, Kind::Png).is_err(),
            "mean difference 5"
        );
    }
}
