//! Serde helpers: a spec (`AccelSpec`, `IntegratorSpec`, `TemporalSpec`, ...) is stored as
//! the text it displays as, which parses back to the same spec (each spec's round-trip
//! tests), so a job file reads like the command line that made it.

use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serializer};
use std::fmt::Display;
use std::str::FromStr;

/// A spec as its text.
pub fn serialize<T: Display, S: Serializer>(value: &T, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(value)
}

/// A spec from its text.
pub fn deserialize<'de, T, D>(d: D) -> Result<T, D::Error>
where
    T: FromStr,
    T::Err: Display,
    D: Deserializer<'de>,
{
    let text = String::deserialize(d)?;
    text.parse()
        .map_err(|e| D::Error::custom(format!("\"{text}\": {e}")))
}

/// An optional spec as its text, or `null`.
pub mod option {
    use super::*;

    /// `None` as `null`, a spec as its text.
    pub fn serialize<T: Display, S: Serializer>(
        value: &Option<T>,
        s: S,
    ) -> Result<S::Ok, S::Error> {
        match value {
            Some(v) => s.collect_str(v),
            None => s.serialize_none(),
        }
    }

    /// `null` as `None`, text as the spec it parses to.
    pub fn deserialize<'de, T, D>(d: D) -> Result<Option<T>, D::Error>
    where
        T: FromStr,
        T::Err: Display,
        D: Deserializer<'de>,
    {
        match Option::<String>::deserialize(d)? {
            None => Ok(None),
            Some(text) => text
                .parse()
                .map(Some)
                .map_err(|e| D::Error::custom(format!("\"{text}\": {e}"))),
        }
    }
}

/// An AOV set as its list of names (`rt_film::AovSet::names`).
pub mod aovs {
    use super::*;
    use rt_film::AovSet;

    /// The names.
    pub fn serialize<S: Serializer>(value: &AovSet, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(value.names())
    }

    /// The set the names make.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<AovSet, D::Error> {
        let names = Vec::<String>::deserialize(d)?;
        AovSet::parse_list(names.iter().map(String::as_str)).map_err(D::Error::custom)
    }
}
