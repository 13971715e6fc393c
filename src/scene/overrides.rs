//! `--set KEY=VALUE` overrides: KEY is a dotted TOML path (`grid.cells`,
//! `material.0.youngs_modulus` for the first [[material]]), VALUE is in TOML syntax
//! (`[64,1]`, `1e6`, `"cpdi"`); a value that is not valid TOML is taken as a string,
//! so `--set grid.shape_function=cpdi` works too. Arrays are replaced whole.
//! [`unset`] removes keys (used by `mpm bench` configurations that switch solvers).

use super::SceneError;
use toml_edit::{DocumentMut, Item, Table, TableLike, Value};

pub fn apply(file: &str, text: &str, overrides: &[String]) -> Result<String, SceneError> {
    if overrides.is_empty() {
        return Ok(text.to_string());
    }
    let mut doc = parse(file, text)?;
    for o in overrides {
        let bad = |m: String| SceneError {
            set: Some(o.clone()),
            ..SceneError::plain(file, m)
        };
        let (key, value) = o
            .split_once('=')
            .ok_or_else(|| bad("is not of the form KEY=VALUE".into()))?;
        let value: Value = value
            .trim()
            .parse()
            .unwrap_or_else(|_| Value::from(value.trim()));
        set(doc.as_table_mut(), key.trim(), value)
            .ok_or_else(|| bad(format!("the scene has no place for key `{}`", key.trim())))?;
    }
    Ok(doc.to_string())
}

/// Remove the keys at dotted paths (`solver.load_steps`); a missing key is no error.
pub fn unset(file: &str, text: &str, keys: &[String]) -> Result<String, SceneError> {
    if keys.is_empty() {
        return Ok(text.to_string());
    }
    let mut doc = parse(file, text)?;
    for key in keys {
        remove(doc.as_table_mut(), key.trim());
    }
    Ok(doc.to_string())
}

fn parse(file: &str, text: &str) -> Result<DocumentMut, SceneError> {
    text.parse().map_err(|e: toml_edit::TomlError| {
        let position = e.span().map(|s| super::error::line_col(text, s.start));
        SceneError {
            position,
            ..SceneError::plain(file, e.message().trim())
        }
    })
}

/// Remove the value at a dotted path, if it is there.
fn remove(mut table: &mut dyn TableLike, path: &str) {
    let segs: Vec<&str> = path.split('.').collect();
    let Some((last, parents)) = segs.split_last() else {
        return;
    };
    let mut i = 0;
    while i < parents.len() {
        let next = match table.get_mut(parents[i]) {
            Some(Item::ArrayOfTables(a)) => {
                let Some(t) = parents.get(i + 1).and_then(|s| s.parse().ok()) else {
                    return;
                };
                i += 1;
                a.get_mut(t).map(|t| t as &mut dyn TableLike)
            }
            Some(other) => other.as_table_like_mut(),
            None => None,
        };
        let Some(next) = next else { return };
        table = next;
        i += 1;
    }
    table.remove(last);
}

/// Set the value at a dotted path, creating missing tables on the way.
fn set(mut table: &mut dyn TableLike, path: &str, value: Value) -> Option<()> {
    let segs: Vec<&str> = path.split('.').collect();
    let (last, parents) = segs.split_last()?;
    let mut i = 0;
    while i < parents.len() {
        let seg = parents[i];
        if table.get(seg).is_none() {
            table.insert(seg, Item::Table(Table::new()));
        }
        match table.get_mut(seg)? {
            Item::ArrayOfTables(a) => {
                let index: usize = parents.get(i + 1)?.parse().ok()?;
                table = a.get_mut(index)?;
                i += 2;
            }
            other => {
                table = other.as_table_like_mut()?;
                i += 1;
            }
        }
    }
    table.insert(last, Item::Value(value));
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str =
        "dimension = 2\n[grid]\ncells = [8, 1]\n[[material]]\nname = \"a\"\ndensity = 1.0\n";

    #[test]
    fn overrides_replace_nested_and_array_of_table_values() {
        let out = apply(
            "s.toml",
            SCENE,
            &["grid.cells=[64,1]".into(), "material.0.density=2.5".into()],
        )
        .unwrap();
        let doc: toml::Table = toml::from_str(&out).unwrap();
        assert_eq!(
            doc["grid"]["cells"].as_array().unwrap()[0].as_integer(),
            Some(64)
        );
        assert_eq!(
            doc["material"].as_array().unwrap()[0]["density"].as_float(),
            Some(2.5)
        );
    }

    #[test]
    fn bare_words_become_strings() {
        let out = apply("s.toml", SCENE, &["grid.shape_function=cpdi".into()]).unwrap();
        let doc: toml::Table = toml::from_str(&out).unwrap();
        assert_eq!(doc["grid"]["shape_function"].as_str(), Some("cpdi"));
    }

    #[test]
    fn unset_removes_nested_keys_and_ignores_missing_ones() {
        let out = unset(
            "s.toml",
            SCENE,
            &[
                "grid.cells".into(),
                "material.0.density".into(),
                "solver.dt".into(),
                "material.5.name".into(),
            ],
        )
        .unwrap();
        let doc: toml::Table = toml::from_str(&out).unwrap();
        assert!(doc["grid"].get("cells").is_none());
        let m = &doc["material"].as_array().unwrap()[0];
        assert!(m.get("density").is_none() && m.get("name").is_some());
    }

    #[test]
    fn malformed_overrides_are_errors() {
        let e = apply("s.toml", SCENE, &["grid.cells".into()]).unwrap_err();
        assert!(e.message.contains("KEY=VALUE"), "{e}");
        assert_eq!(e.set.as_deref(), Some("grid.cells"));
        let e = apply("s.toml", SCENE, &["material.3.density=1".into()]).unwrap_err();
        assert!(e.message.contains("material.3.density"), "{e}");
        assert!(e.to_string().contains("--set material.3.density=1"), "{e}");
    }
}
