//! A material's scene parameters and how a model is built from them.
//!
//! The parameters are the keys of a `[[material]]` table besides `name`, `model`
//! and `density`, kept as TOML values. A model reads them with typed getters whose
//! errors name the key (`material.0.cohesion`), so that the scene error can point
//! at its line, and checks their ranges while it builds itself
//! (`FromParameters::from_parameters`): the checks and the constructor are one
//! function and cannot drift apart. The keys shared by several models (E, ν and
//! the Mohr–Coulomb strength c, φ, ψ) are read here once.

use super::Material;
use serde::de::DeserializeOwned;

/// A failed check: the dotted key path and the message.
pub type KeyError = (String, String);

/// How a scene builds a model (listed once in `material::MODELS`).
pub trait FromParameters: Sized {
    /// The model's name in scene files (`model = "…"`).
    const NAME: &'static str;
    /// The keys the model takes besides name, model and density; any other key of
    /// the table "does not apply" to it.
    const KEYS: &'static [&'static str];
    /// A valid parameter table (TOML, the keys besides name, model and density):
    /// an example for readers, and what the registry's test builds the model from.
    const EXAMPLE: &'static str;
    /// The model from its density and parameters, their ranges checked.
    fn from_parameters(density: f64, p: &Parameters) -> Result<Self, KeyError>;
}

/// A model's constructor from its density and parameters.
type Constructor = fn(f64, &Parameters) -> Result<Box<dyn Material>, KeyError>;

/// One model: its name, its keys, an example of its parameters and its
/// constructor.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    pub name: &'static str,
    pub keys: &'static [&'static str],
    pub example: &'static str,
    pub(super) construct: Constructor,
}

impl Entry {
    pub const fn of<M: FromParameters + Material + 'static>() -> Entry {
        Entry {
            name: M::NAME,
            keys: M::KEYS,
            example: M::EXAMPLE,
            construct: construct::<M>,
        }
    }
}

fn construct<M: FromParameters + Material + 'static>(
    density: f64,
    p: &Parameters,
) -> Result<Box<dyn Material>, KeyError> {
    Ok(Box::new(M::from_parameters(density, p)?))
}

/// The parameters of one material table.
#[derive(Clone, Copy, Debug)]
pub struct Parameters<'a> {
    /// Dotted path of the table, `material.0`.
    table: &'a str,
    /// The model's name, for messages.
    model: &'a str,
    values: &'a toml::Table,
}

impl<'a> Parameters<'a> {
    pub fn new(table: &'a str, model: &'a str, values: &'a toml::Table) -> Self {
        Parameters {
            table,
            model,
            values,
        }
    }

    /// Dotted path of key k, `material.0.k`.
    pub fn key(&self, k: &str) -> String {
        format!("{}.{k}", self.table)
    }

    /// "model `name`", as messages name the model.
    pub fn what(&self) -> String {
        format!("model `{}`", self.model)
    }

    /// Whether key k is given.
    pub fn given(&self, k: &str) -> bool {
        self.values.contains_key(k)
    }

    /// The value of key k if given; a value of the wrong type is an error at k.
    pub fn get<T: DeserializeOwned>(&self, k: &str) -> Result<Option<T>, KeyError> {
        self.values
            .get(k)
            .map(|v| T::deserialize(v.clone()).map_err(|e| (self.key(k), e.message().into())))
            .transpose()
    }

    /// The value of key k, which the model requires.
    pub fn required<T: DeserializeOwned>(&self, k: &str) -> Result<T, KeyError> {
        self.required_for(k, &self.what())
    }

    /// The value of key k, which `what` requires.
    pub fn required_for<T: DeserializeOwned>(&self, k: &str, what: &str) -> Result<T, KeyError> {
        self.get(k)?
            .ok_or_else(|| (self.key(k), format!("is required for {what}")))
    }

    /// A range check of key k.
    pub fn ensure(&self, ok: bool, k: &str, message: impl Into<String>) -> Result<(), KeyError> {
        if ok {
            Ok(())
        } else {
            Err((self.key(k), message.into()))
        }
    }

    /// Key k, required, a positive number.
    pub fn positive(&self, k: &str) -> Result<f64, KeyError> {
        self.checked_positive(k, self.required(k)?)
    }

    /// Key k, a positive number, `default` when not given.
    pub fn positive_or(&self, k: &str, default: f64) -> Result<f64, KeyError> {
        self.checked_positive(k, self.get(k)?.unwrap_or(default))
    }

    /// v, the value of key k, if it is a positive number.
    fn checked_positive(&self, k: &str, v: f64) -> Result<f64, KeyError> {
        self.ensure(
            v > 0.0 && v.is_finite(),
            k,
            format!("must be a positive number; got {v}"),
        )?;
        Ok(v)
    }

    /// Key k, a number ≥ 0, `default` when not given.
    pub fn non_negative(&self, k: &str, default: f64) -> Result<f64, KeyError> {
        let v: f64 = self.get(k)?.unwrap_or(default);
        self.ensure(
            v >= 0.0 && v.is_finite(),
            k,
            format!("must be a number ≥ 0; got {v}"),
        )?;
        Ok(v)
    }

    /// Young's modulus E > 0.
    pub fn youngs_modulus(&self) -> Result<f64, KeyError> {
        let e: f64 = self.required("youngs_modulus")?;
        self.ensure(
            e > 0.0 && e.is_finite(),
            "youngs_modulus",
            "must be a positive number",
        )?;
        Ok(e)
    }

    /// Poisson's ratio −1 < ν < 0.5 (every model is compressible).
    pub fn poisson_ratio(&self) -> Result<f64, KeyError> {
        let nu: f64 = self.required("poisson_ratio")?;
        self.ensure(
            nu > -1.0 && nu < 0.5,
            "poisson_ratio",
            format!(
                "must lie in (-1, 0.5) for the compressible {}; got {nu}",
                self.what()
            ),
        )?;
        Ok(nu)
    }

    /// The Mohr–Coulomb strength as given (c, φ and ψ in degrees; ψ defaults to
    /// 0): c ≥ 0, 0 ≤ φ < 90°, 0 ≤ ψ ≤ φ, and some strength (c > 0 or φ > 0).
    pub fn mohr_coulomb_strength(&self) -> Result<(f64, f64, f64), KeyError> {
        let c: f64 = self.required("cohesion")?;
        let phi: f64 = self.required("friction_angle")?;
        let psi = self.get("dilation_angle")?.unwrap_or(0.0);
        self.ensure(
            c >= 0.0 && c.is_finite(),
            "cohesion",
            format!("must be a number ≥ 0 (no negative cohesion); got {c}"),
        )?;
        self.ensure(
            (0.0..90.0).contains(&phi),
            "friction_angle",
            format!("must lie in [0, 90) degrees; got {phi}"),
        )?;
        self.ensure(
            psi >= 0.0 && psi <= phi,
            "dilation_angle",
            format!("must lie in [0, friction_angle = {phi}] degrees; got {psi}"),
        )?;
        self.ensure(
            c > 0.0 || phi > 0.0,
            "cohesion",
            "cohesion and friction_angle are both zero: the material has no strength",
        )?;
        Ok((c, phi, psi))
    }
}
