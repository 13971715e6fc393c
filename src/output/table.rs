//! Reading the CSV outputs back (`particles_final.csv`, `history.csv`,
//! `newton.csv`, `bench.csv`) by column name, for error measures, the benchmark and
//! tests. Fields may be quoted (`"a, b"`, with `""` for a quote inside), as
//! `CsvWriter` writes them.

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

    /// Parse CSV text whose first line is the header (fields trimmed, blank
    /// lines skipped).
    pub fn parse(text: &str) -> Result<Table, String> {
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let mut records = reader.records().filter(|r| {
            r.as_ref()
                .map_or(true, |r| !(r.len() == 1 && r[0].is_empty()))
        });
        let header: Vec<String> = match records.next() {
            None => return Err("the file is empty".into()),
            Some(r) => r
                .map_err(|e| e.to_string())?
                .iter()
                .map(String::from)
                .collect(),
        };
        let mut text_cols: Vec<Vec<String>> = vec![Vec::new(); header.len()];
        for (i, record) in records.enumerate() {
            let record = record.map_err(|e| e.to_string())?;
            if record.len() != header.len() {
                return Err(format!(
                    "row {} has {} fields, the header has {}",
                    i + 2,
                    record.len(),
                    header.len()
                ));
            }
            for (col, f) in text_cols.iter_mut().zip(record.iter()) {
                col.push(f.to_string());
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
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        let mut w = crate::output::CsvWriter::create(&path, &["a", "b", "c", "d", "e"]).unwrap();
        w.row(row.iter().map(|s| crate::output::Field::Text(s)))
            .unwrap();
        w.flush().unwrap();
        let t = Table::read(&path).unwrap();
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
