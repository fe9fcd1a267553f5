//! Values a builder is given that the file model cannot hold yet: type names read as the file
//! reads them, with the error `build` reports.

use crate::scenario::error::KeyPath;

/// A value given to a builder that could not become part of the file model (a type name that
/// is no type): its key and message, reported by `build` as the file's parse error would be.
pub(super) type Deferred = Option<(KeyPath, String)>;

/// A name read as the file reads it (`"mcl"` → `LocalizerType::Mcl`), with serde's message
/// when it is none of the names.
pub(super) fn parse_name<T: serde::de::DeserializeOwned>(name: &str) -> Result<T, String> {
    use serde::de::IntoDeserializer;
    let d: serde::de::value::StringDeserializer<serde::de::value::Error> =
        name.to_string().into_deserializer();
    T::deserialize(d).map_err(|e| e.to_string())
}
