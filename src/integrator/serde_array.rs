//! serde for `[f64; N]` with a const-generic N (serde's own impls cover fixed sizes only),
//! used as `#[serde(with = "serde_array")]` on the solver's arrays.

use serde::de::{Error, SeqAccess, Visitor};
use serde::ser::SerializeTuple;
use serde::{Deserializer, Serializer};
use std::fmt;

pub fn serialize<S: Serializer, const N: usize>(a: &[f64; N], s: S) -> Result<S::Ok, S::Error> {
    let mut tuple = s.serialize_tuple(N)?;
    for x in a {
        tuple.serialize_element(x)?;
    }
    tuple.end()
}

pub fn deserialize<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<[f64; N], D::Error> {
    struct Numbers<const N: usize>;
    impl<'de, const N: usize> Visitor<'de> for Numbers<N> {
        type Value = [f64; N];
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            write!(f, "{N} numbers")
        }
        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[f64; N], A::Error> {
            let mut a = [0.0; N];
            for (i, x) in a.iter_mut().enumerate() {
                *x = seq
                    .next_element()?
                    .ok_or_else(|| A::Error::invalid_length(i, &self))?;
            }
            Ok(a)
        }
    }
    d.deserialize_tuple(N, Numbers::<N>)
}
