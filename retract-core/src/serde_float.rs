//! Floats that may be NaN or infinite, through human-readable formats that have no such
//! numbers: JSON writes a non-finite `f64` as `null`, which it cannot read back as an `f64`.
//!
//! A finite value is written as a plain number; NaN and the infinities as the strings
//! `"NaN"`, `"inf"` and `"-inf"` (as `f64`'s `Display` writes them). Reading accepts a number,
//! one of those three strings, or `null` (NaN: what a plain `f64` field wrote for any
//! non-finite value). Binary formats (not human-readable), which hold every `f64`, keep the
//! plain derived form.
//!
//! On a field: `#[serde(with = "crate::serde_float")]` for an `f64`,
//! `#[serde(with = "crate::serde_float::list")]` for a `Vec<f64>` and
//! `#[serde(with = "crate::serde_float::vectors")]` for a `Vec<SVector<f64, D>>` (each vector
//! a list of its `D` entries, as nalgebra writes it).

use core::fmt;

use nalgebra::SVector;
use serde::de::{self, Deserializer, IgnoredAny, SeqAccess, Visitor};
use serde::ser::{SerializeSeq, SerializeTuple, Serializer};
use serde::{Deserialize, Serialize};

/// The string a non-finite `v` is written as: `"NaN"`, `"inf"` or `"-inf"`.
fn non_finite_name(v: f64) -> &'static str {
    if v.is_nan() {
        "NaN"
    } else if v > 0.0 {
        "inf"
    } else {
        "-inf"
    }
}

/// Writes `v`: a number where it is finite (or the format is binary), else its name
/// (`"NaN"`, `"inf"`, `"-inf"`).
///
/// # Errors
/// Those of the serializer.
pub(crate) fn serialize<S: Serializer>(v: &f64, serializer: S) -> Result<S::Ok, S::Error> {
    if v.is_finite() || !serializer.is_human_readable() {
        serializer.serialize_f64(*v)
    } else {
        serializer.serialize_str(non_finite_name(*v))
    }
}

/// Reads an `f64` written by [`serialize`]: a number, `"NaN"`, `"inf"`, `"-inf"`, or `null`
/// (NaN).
///
/// # Errors
/// Anything else (another string, a list, a map), and those of the deserializer.
pub(crate) fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
    if deserializer.is_human_readable() {
        deserializer.deserialize_any(FloatVisitor)
    } else {
        deserializer.deserialize_f64(FloatVisitor)
    }
}

/// The visitor of [`deserialize`].
struct FloatVisitor;

impl<'de> Visitor<'de> for FloatVisitor {
    type Value = f64;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(r#"a number, "NaN", "inf", "-inf" or null (NaN)"#)
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<f64, E> {
        Ok(v)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<f64, E> {
        Ok(v as f64)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<f64, E> {
        Ok(v as f64)
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<f64, E> {
        match v {
            "NaN" => Ok(f64::NAN),
            "inf" => Ok(f64::INFINITY),
            "-inf" => Ok(f64::NEG_INFINITY),
            _ => Err(E::invalid_value(de::Unexpected::Str(v), &self)),
        }
    }

    fn visit_unit<E: de::Error>(self) -> Result<f64, E> {
        Ok(f64::NAN)
    }

    fn visit_none<E: de::Error>(self) -> Result<f64, E> {
        Ok(f64::NAN)
    }

    fn visit_some<D: Deserializer<'de>>(self, deserializer: D) -> Result<f64, D::Error> {
        deserialize(deserializer)
    }
}

/// An `f64` written and read as by [`serialize`] and [`deserialize`] (an element of a list).
struct Float(f64);

impl Serialize for Float {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serialize(&self.0, serializer)
    }
}

impl<'de> Deserialize<'de> for Float {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserialize(deserializer).map(Float)
    }
}

/// A list of `f64` (`Vec<f64>`), each entry as by [`serialize`](super::serialize).
pub(crate) mod list {
    use super::*;

    /// Writes `values` as a list of entries written by [`super::serialize`].
    ///
    /// # Errors
    /// Those of the serializer.
    pub(crate) fn serialize<S: Serializer>(
        values: &[f64],
        serializer: S,
    ) -> Result<S::Ok, S::Error> {
        if !serializer.is_human_readable() {
            return values.serialize(serializer);
        }
        let mut seq = serializer.serialize_seq(Some(values.len()))?;
        for &v in values {
            seq.serialize_element(&Float(v))?;
        }
        seq.end()
    }

    /// Reads a list written by [`serialize`].
    ///
    /// # Errors
    /// An entry that [`super::deserialize`] refuses, and those of the deserializer.
    pub(crate) fn deserialize<'de, D: Deserializer<'de>>(
        deserializer: D,
    ) -> Result<Vec<f64>, D::Error> {
        if !deserializer.is_human_readable() {
            return Vec::deserialize(deserializer);
        }
        let floats = Vec::<Float>::deserialize(deserializer)?;
        Ok(floats.into_iter().map(|f| f.0).collect())
    }
}

/// A list of vectors (`Vec<SVector<f64, D>>`), each a list of its `D` entries written as by
/// [`serialize`](super::serialize).
pub(crate) mod vectors {
    use super::*;

    /// A vector written as the tuple of its entries (nalgebra's form), each by
    /// [`super::serialize`].
    struct Entries<'a, const D: usize>(&'a SVector<f64, D>);

    impl<const D: usize> Serialize for Entries<'_, D> {
        fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
            let mut tuple = serializer.serialize_tuple(D)?;
            for &v in self.0.iter() {
                tuple.serialize_element(&Float(v))?;
            }
            tuple.end()
        }
    }

    /// A vector read from exactly `D` entries, each by [`super::deserialize`].
    struct Read<const D: usize>(SVector<f64, D>);

    impl<'de, const D: usize> Deserialize<'de> for Read<D> {
        fn deserialize<De: Deserializer<'de>>(deserializer: De) -> Result<Self, De::Error> {
            deserializer.deserialize_tuple(D, EntriesVisitor::<D>)
        }
    }

    /// The visitor of [`Read`].
    struct EntriesVisitor<const D: usize>;

    impl<'de, const D: usize> Visitor<'de> for EntriesVisitor<D> {
        type Value = Read<D>;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(
                f,
                r#"a list of {D} numbers (each a number, "NaN", "inf", "-inf" or null)"#
            )
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Read<D>, A::Error> {
            let mut v = SVector::<f64, D>::zeros();
            for (i, entry) in v.iter_mut().enumerate() {
                *entry = seq
                    .next_element::<Float>()?
                    .ok_or_else(|| de::Error::invalid_length(i, &self))?
                    .0;
            }
            if seq.next_element::<IgnoredAny>()?.is_some() {
                return Err(de::Error::invalid_length(D + 1, &self));
            }
            Ok(Read(v))
        }
    }

    /// Writes `vectors` as a list of lists of entries written by [`super::serialize`].
    ///
    /// # Errors
    /// Those of the serializer.
    pub(crate) fn serialize<S: Serializer, const D: usize>(
        vectors: &[SVector<f64, D>],
        serializer: S,
    ) -> Result<S::Ok, S::Error> {
        if !serializer.is_human_readable() {
            return vectors.serialize(serializer);
        }
        let mut seq = serializer.serialize_seq(Some(vectors.len()))?;
        for v in vectors {
            seq.serialize_element(&Entries(v))?;
        }
        seq.end()
    }

    /// Reads a list written by [`serialize`].
    ///
    /// # Errors
    /// A vector without exactly `D` entries, an entry that [`super::deserialize`] refuses,
    /// and those of the deserializer.
    pub(crate) fn deserialize<'de, De: Deserializer<'de>, const D: usize>(
        deserializer: De,
    ) -> Result<Vec<SVector<f64, D>>, De::Error> {
        if !deserializer.is_human_readable() {
            return Vec::deserialize(deserializer);
        }
        let read = Vec::<Read<D>>::deserialize(deserializer)?;
        Ok(read.into_iter().map(|r| r.0).collect())
    }
}
