//! The checks every table uses: a condition at a key, vectors of the scene's
//! dimension, required and ruled-out optional keys.

pub use crate::material::parameters::KeyError;
pub type Check = Result<(), KeyError>;

pub fn ensure(ok: bool, path: impl Into<String>, msg: impl Into<String>) -> Check {
    if ok {
        Ok(())
    } else {
        Err((path.into(), msg.into()))
    }
}

pub fn vector(v: &[f64], dim: usize, path: &str) -> Check {
    ensure(
        v.len() == dim,
        path,
        format!(
            "needs {dim} components (dimension = {dim}), has {}",
            v.len()
        ),
    )?;
    ensure(
        v.iter().all(|x| x.is_finite()),
        path,
        "components must be finite numbers",
    )
}

pub fn required<T>(v: &Option<T>, path: String, what: &str) -> Check {
    ensure(v.is_some(), path, format!("is required for {what}"))
}

pub fn forbidden<T>(v: &Option<T>, path: String, what: &str) -> Check {
    ensure(v.is_none(), path, format!("does not apply to {what}"))
}
