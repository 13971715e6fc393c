//! Time histories of the scene: piecewise-linear curves of (time, value)
//! pairs, given inline as `[[t, value], …]` or as the path of a CSV file with
//! two columns (time, value; a header line, blank lines and `#` comments
//! allowed; the path relative to the scene file). Times increase strictly;
//! between rows the value is interpolated linearly, before the first row it is
//! the first value and after the last row the last value (held). The
//! evaluator is `model::curve::TimeCurve`.
//!
//! Errors of an inline table name the key path of the row; errors of a CSV
//! file name the file, its line and column, and the scene key that names it.

use super::error::Source;
use super::SceneError;
use serde::Deserialize;
use std::path::Path;

/// A time history as the scene gives it.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(
    untagged,
    expecting = "a table of [time, value] rows, or the path of a CSV file with columns time, value"
)]
pub enum TimeHistory {
    /// Inline rows `[t, value]`.
    Table(Vec<Vec<f64>>),
    /// The path of a CSV file, relative to the scene file (read at parse time).
    File(String),
    /// A CSV file as read: the path it was read from and its rows.
    #[serde(skip)]
    Read { file: String, points: Vec<[f64; 2]> },
}

impl TimeHistory {
    /// The (time, value) rows (validated; a file is read when the scene is parsed).
    pub fn points(&self) -> Vec<[f64; 2]> {
        match self {
            TimeHistory::Table(rows) => rows.iter().map(|r| [r[0], r[1]]).collect(),
            TimeHistory::Read { points, .. } => points.clone(),
            TimeHistory::File(f) => unreachable!("the time history file {f} is read at parse time"),
        }
    }
}

/// Read every time history given as a file (`SceneConfig::time_histories_mut`), relative to the directory of the
/// scene file `source.file`; an error names the CSV file, its line and column,
/// and the key (or, when the file cannot be read, the key in the scene).
pub fn read_files(
    histories: Vec<(String, &mut TimeHistory)>,
    source: &Source,
) -> Result<(), SceneError> {
    let dir = Path::new(source.file).parent().unwrap_or(Path::new(""));
    for (key, h) in histories {
        let TimeHistory::File(name) = h else { continue };
        let path = dir.join(name.as_str());
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(&path).map_err(|e| {
            source.at_key(
                &key,
                format!("cannot read the time history file `{shown}`: {e}"),
            )
        })?;
        let points = parse_csv(&text).map_err(|(line, col, msg)| SceneError {
            file: shown.clone(),
            key: Some(key.clone()),
            position: Some((line, col)),
            set: None,
            message: format!("{msg} (a time history of {})", source.file),
        })?;
        *h = TimeHistory::Read {
            file: shown,
            points,
        };
    }
    Ok(())
}

/// The rows of a CSV time history: two columns separated by a comma (or by
/// white space), a first line that is not numeric taken as a header. An error
/// is (line, column, message), both 1-based.
pub fn parse_csv(text: &str) -> Result<Vec<[f64; 2]>, (usize, usize, String)> {
    let mut points: Vec<[f64; 2]> = Vec::new();
    let mut last_line = 0;
    for (n, line) in text.lines().enumerate() {
        let line_no = n + 1;
        last_line = line_no;
        let content = line.split('#').next().unwrap_or("");
        if content.trim().is_empty() {
            continue;
        }
        let fields = fields(content);
        let numbers: Vec<Option<f64>> = fields.iter().map(|(_, f)| f.parse::<f64>().ok()).collect();
        if points.is_empty() && numbers.iter().all(Option::is_none) {
            continue; // the header
        }
        if fields.len() != 2 {
            let col = fields.get(2).map_or(1, |f| f.0);
            let msg = format!(
                "a row is `time, value`; this one has {} fields",
                fields.len()
            );
            return Err((line_no, col, msg));
        }
        let mut row = [0.0; 2];
        for (k, (col, f)) in fields.iter().enumerate() {
            row[k] = match numbers[k] {
                Some(x) if x.is_finite() => x,
                _ => return Err((line_no, *col, format!("`{f}` is not a finite number"))),
            };
        }
        if let Some(before) = points.last().map(|p| p[0]) {
            if row[0] <= before {
                let msg = format!(
                    "time {} does not follow the previous row's {before}: times must increase strictly",
                    row[0]
                );
                return Err((line_no, fields[0].0, msg));
            }
        }
        points.push(row);
    }
    if points.is_empty() {
        return Err((
            last_line.max(1),
            1,
            "the file holds no `time, value` row".into(),
        ));
    }
    Ok(points)
}

/// The fields of a CSV line with their 1-based columns: split at commas, or
/// at white space when the line has none.
fn fields(line: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut start = 0;
    let comma = line.contains(',');
    let parts: Vec<&str> = if comma {
        line.split(',').collect()
    } else {
        line.split_whitespace().collect()
    };
    for part in parts {
        let offset = line[start..].find(part).map_or(start, |o| start + o);
        start = offset + part.len();
        let lead = part.len() - part.trim_start().len();
        let col = line[..offset + lead].chars().count() + 1;
        out.push((col, part.trim()));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_header_comments_and_blank_lines_are_skipped() {
        let text = "time, factor\n# ramp\n0, 0\n\n0.5, 1 # up\n1.0,1\n";
        assert_eq!(
            parse_csv(text).unwrap(),
            vec![[0.0, 0.0], [0.5, 1.0], [1.0, 1.0]]
        );
        assert_eq!(
            parse_csv("0 1\n2 3\n").unwrap(),
            vec![[0.0, 1.0], [2.0, 3.0]]
        );
    }

    #[test]
    fn errors_name_the_line_and_column() {
        assert_eq!(parse_csv("t,v\n0,0\n1, x\n").unwrap_err().0, 3);
        let (line, col, msg) = parse_csv("t,v\n0,0\n1, x\n").unwrap_err();
        assert_eq!((line, col), (3, 4), "{msg}");
        let (line, col, msg) = parse_csv("0,0\n1,1\n0.5,2\n").unwrap_err();
        assert_eq!((line, col), (3, 1));
        assert!(msg.contains("increase strictly"), "{msg}");
        let (line, _, msg) = parse_csv("0,0,1\n").unwrap_err();
        assert!(line == 1 && msg.contains("3 fields"), "{msg}");
        assert!(parse_csv("t,v\n")
            .unwrap_err()
            .2
            .contains("no `time, value` row"));
    }
}
