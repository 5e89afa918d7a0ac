//! serde for `[f64; N]` with a const-generic N (serde's own impls cover fixed sizes only),
//! used as `#[serde(with = "serde_array")]` on the solver's arrays, and for `[[f64; N]; M]`
//! (`serde_array::rows`) and `Option<[f64; N]>` (`serde_array::option`).

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

/// serde for `[[f64; N]; M]` (rows of `serde_array`), as M·N numbers.
pub mod rows {
    use serde::de::Error;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer, const N: usize, const M: usize>(
        a: &[[f64; N]; M],
        s: S,
    ) -> Result<S::Ok, S::Error> {
        a.iter()
            .flatten()
            .copied()
            .collect::<Vec<f64>>()
            .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>, const N: usize, const M: usize>(
        d: D,
    ) -> Result<[[f64; N]; M], D::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        if v.len() != N * M {
            return Err(D::Error::invalid_length(v.len(), &"M·N numbers"));
        }
        let mut a = [[0.0; N]; M];
        for (k, x) in v.into_iter().enumerate() {
            a[k / N][k % N] = x;
        }
        Ok(a)
    }
}

/// serde for `Option<[f64; N]>`, as an optional list of N numbers.
pub mod option {
    use serde::de::Error;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer, const N: usize>(
        a: &Option<[f64; N]>,
        s: S,
    ) -> Result<S::Ok, S::Error> {
        a.map(|a| a.to_vec()).serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>, const N: usize>(
        d: D,
    ) -> Result<Option<[f64; N]>, D::Error> {
        Option::<Vec<f64>>::deserialize(d)?
            .map(|v| {
                <[f64; N]>::try_from(v).map_err(|v| D::Error::invalid_length(v.len(), &"N numbers"))
            })
            .transpose()
    }
}
