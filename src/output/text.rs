//! Numbers and JSON as text: the shortest decimal that reads back to the same
//! `f64`, and pretty-printed JSON files.

use std::io::{self, Write};
use std::path::Path;

/// Write `value` to `path` as pretty-printed JSON followed by a newline (used for
/// `summary.json`), replacing the file atomically.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> io::Result<()> {
    super::atomic::write_atomically(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value)?;
        w.write_all(b"\n")
    })
}

/// Write `x` with the shortest decimal text that round-trips to the same `f64`:
/// plain notation for moderate magnitudes, scientific (`1.5e-7`) otherwise.
pub(crate) fn write_f64(w: &mut impl Write, x: f64) -> io::Result<()> {
    let a = x.abs();
    if a == 0.0 || (1e-5..1e16).contains(&a) || !a.is_finite() {
        write!(w, "{x}")
    } else {
        write!(w, "{x:e}")
    }
}

/// [`write_f64`] into a `String`.
pub(crate) fn f64_string(x: f64) -> String {
    let mut buf = Vec::with_capacity(24);
    write_f64(&mut buf, x).expect("writing to a Vec cannot fail");
    String::from_utf8(buf).expect("number formatting is ASCII")
}

/// Names of the first `dim` coordinate axes, lower case.
pub(crate) const AXES: [&str; 3] = ["x", "y", "z"];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f64_text_round_trips() {
        for &x in &[
            0.0,
            -0.0,
            1.0,
            0.1,
            -2.5,
            1.0 / 3.0,
            1e-5,
            9.999e-6,
            1e-300,
            6.02e23,
            1e16,
            f64::MAX,
            f64::MIN_POSITIVE,
            123456789.123,
        ] {
            let s = f64_string(x);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{s}");
        }
        assert_eq!(f64_string(0.5), "0.5");
        assert_eq!(f64_string(1e-7), "1e-7");
        assert_eq!(f64_string(2.0), "2");
    }

    #[test]
    fn json_is_pretty_and_parses_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("summary.json");
        let v = serde_json::json!({"steps": 10, "energy": {"kinetic": 0.25}});
        write_json(&path, &v).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("\n  \"steps\": 10"), "{text}");
        let back: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(back, v);
    }
}
