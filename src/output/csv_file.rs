//! The one CSV writer of the code (history.csv, particles_final.csv, newton.csv,
//! footing.csv, strength_reduction.csv, bench.csv, refinement.csv): the `csv` crate
//! quotes text where needed; numbers are written as the shortest text that reads
//! back to the same `f64` (`text::write_f64`).

use super::text::write_f64;
use std::fs::File;
use std::io;
use std::path::Path;

/// One field of a row.
#[derive(Clone, Copy, Debug)]
pub enum Field<'a> {
    Number(f64),
    Count(u64),
    Text(&'a str),
    /// Nothing between the commas (a value that does not apply).
    Empty,
}

impl From<f64> for Field<'_> {
    fn from(x: f64) -> Self {
        Field::Number(x)
    }
}

impl From<usize> for Field<'_> {
    fn from(n: usize) -> Self {
        Field::Count(n as u64)
    }
}

impl From<u64> for Field<'_> {
    fn from(n: u64) -> Self {
        Field::Count(n)
    }
}

impl From<u32> for Field<'_> {
    fn from(n: u32) -> Self {
        Field::Count(n.into())
    }
}

impl<'a> From<&'a str> for Field<'a> {
    fn from(s: &'a str) -> Self {
        Field::Text(s)
    }
}

impl<'a> From<&'a String> for Field<'a> {
    fn from(s: &'a String) -> Self {
        Field::Text(s)
    }
}

impl<'a, T: Into<Field<'a>>> From<Option<T>> for Field<'a> {
    fn from(v: Option<T>) -> Self {
        v.map_or(Field::Empty, Into::into)
    }
}

/// A CSV file being written, row by row.
pub struct CsvWriter {
    w: csv::Writer<File>,
    number: Vec<u8>,
}

fn io_error(e: csv::Error) -> io::Error {
    match e.into_kind() {
        csv::ErrorKind::Io(e) => e,
        other => io::Error::other(format!("{other:?}")),
    }
}

impl CsvWriter {
    /// Create (truncate) `path` and write the header row.
    pub fn create<S: AsRef<str>>(path: &Path, header: &[S]) -> io::Result<Self> {
        let mut w = CsvWriter {
            w: csv::Writer::from_writer(File::create(path)?),
            number: Vec::with_capacity(32),
        };
        w.row(header.iter().map(|h| Field::Text(h.as_ref())))?;
        Ok(w)
    }

    /// Create (truncate) `path` with `text`, the file as an earlier run had
    /// written it so far (header and rows, from a checkpoint), and write on after it.
    pub fn resume(path: &Path, text: &str) -> io::Result<Self> {
        let mut file = File::create(path)?;
        io::Write::write_all(&mut file, text.as_bytes())?;
        Ok(CsvWriter {
            w: csv::Writer::from_writer(file),
            number: Vec::with_capacity(32),
        })
    }

    /// Write one row.
    pub fn row<'a>(&mut self, fields: impl IntoIterator<Item = Field<'a>>) -> io::Result<()> {
        for f in fields {
            match f {
                Field::Number(x) => {
                    self.number.clear();
                    write_f64(&mut self.number, x)?;
                    self.w.write_field(&self.number)
                }
                Field::Count(n) => self.w.write_field(n.to_string()),
                // One row per line: a line break inside a text becomes a space.
                Field::Text(s) if s.contains('\n') => self.w.write_field(s.replace('\n', " ")),
                Field::Text(s) => self.w.write_field(s),
                Field::Empty => self.w.write_field(""),
            }
            .map_err(io_error)?;
        }
        self.w.write_record(None::<&[u8]>).map_err(io_error)
    }

    /// Push the rows written so far to the file.
    pub fn flush(&mut self) -> io::Result<()> {
        self.w.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::Table;

    #[test]
    fn rows_read_back_through_table() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        let mut w = CsvWriter::create(&path, &["x", "n", "note", "missing"]).unwrap();
        w.row([
            Field::from(1e-7),
            Field::from(3usize),
            Field::from("a, \"quoted\"\nline"),
            Field::from(None::<f64>),
        ])
        .unwrap();
        w.row([2.0.into(), 4u64.into(), "plain".into(), Some(0.5).into()])
            .unwrap();
        w.flush().unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text,
            "x,n,note,missing\n1e-7,3,\"a, \"\"quoted\"\" line\",\n2,4,plain,0.5\n"
        );
        let t = Table::read(&path).unwrap();
        assert_eq!(t.col("x"), &[1e-7, 2.0]);
        assert_eq!(t.text_column("note").unwrap()[0], "a, \"quoted\" line");
        assert!(t.col("missing")[0].is_nan());
    }
}
