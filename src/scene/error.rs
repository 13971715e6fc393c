//! Scene errors that name the file, the key and the line and column, or the
//! `--set KEY=VALUE` override they come from.
//!
//! [`Source`] is what an error is located in: the file's text, the text after the
//! overrides and the overrides themselves. An error at a key path points at the
//! override that set the key (its value is not in the file), else at the key's
//! line and column in the file; [`blame`] then names the override that causes an
//! error at another key, found by replaying the checks with fewer overrides.
//! Deserialisation runs through `serde_path_to_error`, which records the key
//! path of a failing value (type errors, unknown enum values, untagged-enum
//! mismatches) while the TOML deserialiser keeps its span.

use serde::de::DeserializeOwned;
use std::fmt;

#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    pub file: String,
    /// Dotted key path, e.g. `material.0.density`.
    pub key: Option<String>,
    /// 1-based line and column.
    pub position: Option<(usize, usize)>,
    /// The `--set KEY=VALUE` override the error comes from (then there is no
    /// position: the error is not in the file).
    pub set: Option<String>,
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some((line, col)) = self.position {
            write!(f, ":{line}:{col}")?;
        }
        write!(f, ": ")?;
        if let Some(set) = &self.set {
            write!(f, "override `--set {set}`: ")?;
        }
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
            set: None,
            message: message.into(),
        }
    }

    /// From a TOML syntax or deserialisation error, with its span.
    pub fn from_toml(file: &str, text: &str, e: &toml::de::Error) -> Self {
        let position = e.span().map(|s| line_col(text, s.start));
        SceneError {
            position,
            ..SceneError::plain(file, e.message().trim())
        }
    }

    /// A validation error at a dotted key path; the position is looked up in the text.
    pub fn at_key(file: &str, text: &str, path: &str, message: impl Into<String>) -> Self {
        Source::new(file, text, text, &[]).at_key(path, message)
    }
}

/// Where the errors of one scene are located: the file's text, the text after
/// the `--set` overrides, and the overrides.
#[derive(Clone, Copy, Debug)]
pub struct Source<'a> {
    pub file: &'a str,
    /// The file's text.
    pub original: &'a str,
    /// The text after the overrides (what was parsed).
    pub text: &'a str,
    pub overrides: &'a [String],
}

impl<'a> Source<'a> {
    pub fn new(file: &'a str, original: &'a str, text: &'a str, overrides: &'a [String]) -> Self {
        Source {
            file,
            original,
            text,
            overrides,
        }
    }

    /// Deserialise the text, an error naming its key path.
    pub fn deserialize<T: DeserializeOwned>(&self) -> Result<T, SceneError> {
        let de = toml::Deserializer::new(self.text);
        serde_path_to_error::deserialize(de).map_err(|e| {
            let path = key_path(e.path(), e.inner().message());
            let span = e.inner().span().map(|s| s.start);
            self.error(path, span, e.inner().message().trim())
        })
    }

    /// An error at a dotted key path.
    pub fn at_key(&self, path: &str, message: impl Into<String>) -> SceneError {
        self.error(Some(path.to_string()), None, message)
    }

    /// An error at a key path (if known) and a byte offset in the parsed text (if
    /// known): the override that set the key, or the position in the file.
    fn error(
        &self,
        key: Option<String>,
        span: Option<usize>,
        message: impl Into<String>,
    ) -> SceneError {
        let mut e = SceneError {
            key: key.clone(),
            ..SceneError::plain(self.file, message)
        };
        let Some(path) = key else {
            e.position = span.map(|s| line_col(self.text, s));
            return e;
        };
        let keys = || self.overrides.iter().map(|o| (o, override_key(o)));
        let under = |path: &str, key: &str| {
            path == key || path.starts_with(key) && path[key.len()..].starts_with('.')
        };
        // The key, or a table holding it, was set by an override.
        if let Some((o, _)) = keys().rev().find(|(_, k)| under(&path, k)) {
            e.set = Some(o.clone());
            return e;
        }
        e.position = if self.overrides.is_empty() {
            span.map(|s| line_col(self.text, s))
                .or_else(|| locate(self.text, &path))
        } else {
            locate(self.original, &path)
        };
        if e.position.is_none() {
            // Not in the file: a table that an override created.
            if let Some((o, _)) = keys().rev().find(|(_, k)| under(k, &path)) {
                e.set = Some(o.clone());
            }
        }
        e
    }
}

/// `e`, an error found with the `overrides` applied, naming the override that
/// causes it: the first one after which `replay` (the same parse and checks on
/// the file with the first overrides only) gives the same error, the same key
/// and message. An error at a key that no override set may come from an
/// override at another key (`--set body.0.max=…` takes the body out of the
/// grid: key `body.0.shape`), and only the replay tells. An error that the
/// file gives without overrides, or that no replay gives again, is left as it
/// is.
pub fn blame<T>(
    e: SceneError,
    overrides: &[String],
    replay: impl Fn(&[String]) -> Result<T, SceneError>,
) -> SceneError {
    if e.set.is_some() {
        return e;
    }
    let gives_e =
        |k: usize| replay(&overrides[..k]).is_err_and(|f| f.key == e.key && f.message == e.message);
    match (0..=overrides.len()).find(|&k| gives_e(k)) {
        Some(k) if k > 0 => SceneError {
            set: Some(overrides[k - 1].clone()),
            position: None,
            ..e
        },
        _ => e,
    }
}

/// The dotted key of an override `KEY=VALUE`.
fn override_key(o: &str) -> &str {
    o.split_once('=').map_or(o, |(k, _)| k).trim()
}

/// The dotted key path of a deserialisation error (`body.0.radius`); an unknown
/// field is named at its own key, not only its table's.
fn key_path(path: &serde_path_to_error::Path, message: &str) -> Option<String> {
    use serde_path_to_error::Segment;
    let mut parts: Vec<String> = path
        .iter()
        .filter_map(|s| match s {
            Segment::Seq { index } => Some(index.to_string()),
            Segment::Map { key } => Some(key.clone()),
            Segment::Enum { .. } => None,
            Segment::Unknown => Some("?".into()),
        })
        .collect();
    let field = ["unknown field `", "missing field `"]
        .iter()
        .find_map(|p| message.strip_prefix(p))
        .and_then(|m| m.split('`').next());
    if let Some(field) = field.filter(|f| parts.last().map(String::as_str) != Some(*f)) {
        parts.push(field.to_string());
    }
    (!parts.is_empty()).then(|| parts.join("."))
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

#[cfg(test)]
mod tests {
    use super::*;

    fn at(key: &str) -> SceneError {
        SceneError {
            key: Some(key.into()),
            position: Some((3, 1)),
            ..SceneError::plain("s.toml", "wrong")
        }
    }

    /// The error blamed by a replay that gives it from the first `from`
    /// overrides on (0: the file gives it; more than there are: no replay does).
    fn blamed(from: usize) -> SceneError {
        let overrides = ["grid.cells=[2,2]", "body.0.max=[9,9]", "x=1"].map(String::from);
        blame(at("body.0.shape"), &overrides, |o| match o.len() >= from {
            true => Err(at("body.0.shape")),
            false => Ok(()),
        })
    }

    #[test]
    fn the_first_override_that_gives_the_error_is_named() {
        let e = blamed(2);
        assert_eq!(e.set.as_deref(), Some("body.0.max=[9,9]"));
        assert_eq!((e.key.as_deref(), e.position), (Some("body.0.shape"), None));
    }

    #[test]
    fn an_error_of_the_file_or_of_no_replay_is_left_as_it_is() {
        for from in [0, 4] {
            assert_eq!(blamed(from), at("body.0.shape"), "{from}");
        }
    }
}
