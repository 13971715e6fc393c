//! Reading the CSV outputs back (`particles_final.csv`, `history.csv`,
//! `newton.csv`, `bench.csv`) by column name, for error measures, the benchmark and
//! tests. Fields may be quoted (`"a, b"`, with `""` for a quote inside), as
//! [`csv_field`] writes them.

use std::collections::HashMap;
use std::path::Path;

/// A CSV file as columns keyed by header name: every column as text, and as numbers
/// (NaN where a field is not a number).
#[derive(Clone, Debug, Default)]
pub struct Table {
    pub header: Vec<String>,
    pub columns: HashMap<String, Vec<f64>>,
    pub text: HashMap<String, Vec<String>>,
}

impl Table {
    /// Read a CSV file; the error names the file.
    pub fn read(path: &Path) -> Result<Table, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        Table::parse(&text).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Parse CSV text whose first line is the header.
    pub fn parse(text: &str) -> Result<Table, String> {
        let mut lines = text.lines().filter(|l| !l.trim().is_empty());
        let header = split_fields(lines.next().ok_or("the file is empty")?);
        let mut text_cols: Vec<Vec<String>> = vec![Vec::new(); header.len()];
        for (i, line) in lines.enumerate() {
            let fields = split_fields(line);
            if fields.len() != header.len() {
                return Err(format!(
                    "row {} has {} fields, the header has {}",
                    i + 2,
                    fields.len(),
                    header.len()
                ));
            }
            for (col, f) in text_cols.iter_mut().zip(fields) {
                col.push(f);
            }
        }
        let columns = header
            .iter()
            .zip(&text_cols)
            .map(|(h, c)| {
                let numbers = c.iter().map(|s| s.parse().unwrap_or(f64::NAN)).collect();
                (h.clone(), numbers)
            })
            .collect();
        let text = header.iter().cloned().zip(text_cols).collect();
        Ok(Table {
            header,
            columns,
            text,
        })
    }

    /// Number of data rows.
    pub fn len(&self) -> usize {
        self.header
            .first()
            .and_then(|h| self.columns.get(h))
            .map_or(0, Vec::len)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// A numeric column, or an error naming the columns there are.
    pub fn column(&self, name: &str) -> Result<&[f64], String> {
        self.columns
            .get(name)
            .map(Vec::as_slice)
            .ok_or_else(|| format!("no column `{name}` (columns: {})", self.header.join(",")))
    }

    /// A column as text.
    pub fn text_column(&self, name: &str) -> Result<&[String], String> {
        self.text
            .get(name)
            .map(Vec::as_slice)
            .ok_or_else(|| format!("no column `{name}` (columns: {})", self.header.join(",")))
    }

    /// A numeric column that must exist (for tests and scripts that know the file).
    pub fn col(&self, name: &str) -> &[f64] {
        self.column(name).unwrap_or_else(|e| panic!("{e}"))
    }
}

/// Split one CSV line into fields, honouring double quotes.
fn split_fields(line: &str) -> Vec<String> {
    let mut fields = Vec::new();
    let mut field = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(std::mem::take(&mut field).trim().to_string()),
            _ => field.push(c),
        }
    }
    fields.push(field.trim().to_string());
    fields
}

/// A text field for a CSV file: quoted when it holds a comma, a quote or a line break.
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\"").replace('\n', " "))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quoted_fields_round_trip() {
        let row = [
            "plain",
            "grid.cells=[1,16]",
            "say \"hi\", twice",
            "",
            "1.5e-3",
        ];
        let line: Vec<String> = row.iter().map(|s| csv_field(s)).collect();
        let text = format!("a,b,c,d,e\n{}\n", line.join(","));
        let t = Table::parse(&text).unwrap();
        assert_eq!(t.len(), 1);
        for (h, want) in ["a", "b", "c", "d", "e"].iter().zip(row) {
            assert_eq!(t.text_column(h).unwrap()[0], want);
        }
        assert_eq!(t.col("e")[0], 1.5e-3);
        assert!(t.col("a")[0].is_nan());
        assert!(t.column("f").unwrap_err().contains("a,b,c,d,e"));
    }

    #[test]
    fn ragged_rows_are_errors() {
        let e = Table::parse("a,b\n1,2\n3\n").unwrap_err();
        assert!(e.contains("row 3"), "{e}");
    }
}
