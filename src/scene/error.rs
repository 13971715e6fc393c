//! Scene errors that name the file, the key and the line and column.

use std::fmt;

#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    pub file: String,
    /// Dotted key path, e.g. `material.0.density`.
    pub key: Option<String>,
    /// 1-based line and column.
    pub position: Option<(usize, usize)>,
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some((line, col)) = self.position {
            write!(f, ":{line}:{col}")?;
        }
        write!(f, ": ")?;
        if let Some(key) = &self.key {
            write!(f, "key `{key}`: ")?;
        }
        write!(f, "{}", self.message)
    }
}

impl std::error::Error for SceneError {}

impl SceneError {
    pub fn plain(file: &str, message: impl Into<String>) -> Self {
        SceneError {
            file: file.into(),
            key: None,
            position: None,
            message: message.into(),
        }
    }

    /// From a TOML syntax or deserialisation error, with its span.
    pub fn from_toml(file: &str, text: &str, e: &toml::de::Error) -> Self {
        let position = e.span().map(|s| line_col(text, s.start));
        SceneError {
            file: file.into(),
            key: None,
            position,
            message: e.message().trim().to_string(),
        }
    }

    /// A validation error at a dotted key path; the position is looked up in the text.
    pub fn at_key(file: &str, text: &str, path: &str, message: impl Into<String>) -> Self {
        SceneError {
            file: file.into(),
            key: Some(path.to_string()),
            position: locate(text, path),
            message: message.into(),
        }
    }
}

/// 1-based line and column of a byte offset.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// Position of the value at a dotted path (`body.1.radius`) in the TOML text: the
/// deepest part of the path that exists (a missing key points at its table).
fn locate(text: &str, path: &str) -> Option<(usize, usize)> {
    use toml_edit::{Item, Value};
    let doc = toml_edit::ImDocument::parse(text.to_string()).ok()?;
    let mut table: &dyn toml_edit::TableLike = doc.as_table();
    let mut span = None;
    let mut segs = path.split('.').peekable();
    while let Some(seg) = segs.next() {
        let Some(item) = table.get(seg) else { break };
        span = item.span().or(span);
        let index = segs.peek().and_then(|s| s.parse::<usize>().ok());
        match item {
            Item::Table(t) => {
                span = t.span().or(span);
                table = t;
            }
            Item::Value(Value::InlineTable(t)) => table = t,
            Item::ArrayOfTables(a) => {
                let Some(t) = index.and_then(|i| a.get(i)) else {
                    break;
                };
                segs.next();
                span = t.span().or(span);
                table = t;
            }
            Item::Value(Value::Array(a)) => {
                if let Some(v) = index.and_then(|i| a.get(i)) {
                    span = v.span().or(span);
                }
                break;
            }
            _ => break,
        }
    }
    span.map(|s| line_col(text, s.start))
}
