//! Attribute values of one prim, read at one time and turned into plain arrays, every error
//! naming the prim and the attribute.

use openusd::sdf::Value;
use openusd::{sdf, tf, usd};
use rayon::prelude::*;
use subd_mesh::DVec3;

use crate::error::ReadError;

/// The attributes of one prim, read at one time (`None`: the default value).
pub(crate) struct PrimValues<'a> {
    pub(crate) prim: &'a usd::Prim,
    pub(crate) time: Option<f64>,
}

impl PrimValues<'_> {
    /// An error about attribute `attr` of this prim.
    pub(crate) fn error(&self, attr: &str, message: impl std::fmt::Display) -> ReadError {
        ReadError::general(format!(
            "prim {} attribute {attr}: {message}",
            self.prim.path()
        ))
    }

    /// An error about this prim.
    pub(crate) fn prim_error(&self, message: impl std::fmt::Display) -> ReadError {
        ReadError::general(format!("prim {}: {message}", self.prim.path()))
    }

    /// The value of `attr` at the time asked for, `None` when it has none. An attribute with
    /// time samples but no default value, read without a time, is an error that says so.
    pub(crate) fn value(&self, attr: &str) -> Result<Option<Value>, ReadError> {
        let a = self.prim.attribute(attr);
        let fail = |e: openusd::Error| self.error(attr, super::one_line(&e));
        match self.time {
            Some(t) => a.get_at::<Value>(usd::TimeCode::new(t)).map_err(fail),
            None => {
                let v = a.get::<Value>().map_err(fail)?;
                if v.is_none() {
                    let times = a.time_sample_times().map_err(fail)?;
                    if let (Some(first), Some(last)) = (times.first(), times.last()) {
                        return Err(self.error(
                            attr,
                            format!(
                                "has time samples ({} from {first} to {last}) and no default value; pick a time with --time (time= in Python)",
                                times.len()
                            ),
                        ));
                    }
                }
                Ok(v)
            }
        }
    }

    /// A metadata token of `attr` (`interpolation`).
    pub(crate) fn metadata_token(
        &self,
        attr: &str,
        key: &str,
    ) -> Result<Option<String>, ReadError> {
        let a = self.prim.attribute(attr);
        let v = a
            .get_metadata::<Value>(key)
            .map_err(|e| self.error(attr, super::one_line(&e)))?;
        match v {
            None => Ok(None),
            Some(Value::Token(t)) => Ok(Some(t.as_str().to_string())),
            Some(Value::String(s)) => Ok(Some(s)),
            Some(other) => Err(self.error(attr, format!("{key} is {}, not a token", kind(&other)))),
        }
    }

    /// An `int[]` attribute, each value checked non-negative.
    pub(crate) fn indices(&self, attr: &str) -> Result<Option<Vec<u32>>, ReadError> {
        let not_index =
            |i: usize, x: i64| Err(self.error(attr, format!("value [{i}] = {x} is not an index")));
        match self.value(attr)? {
            None => Ok(None),
            Some(Value::IntVec(v)) => match v.iter().position(|&x| x < 0) {
                Some(i) => not_index(i, v[i].into()),
                // Same size: the array is reused in place, not copied.
                None => Ok(Some(v.into_iter().map(|x| x as u32).collect())),
            },
            Some(Value::UintVec(v)) => Ok(Some(v)),
            Some(Value::Int64Vec(v)) => match v.iter().position(|&x| u32::try_from(x).is_err()) {
                Some(i) => not_index(i, v[i]),
                None => Ok(Some(v.into_iter().map(|x| x as u32).collect())),
            },
            Some(other) => Err(self.mismatch(attr, "int[]", &other)),
        }
    }

    /// A `float[]` (or `double[]`, `half[]`) attribute.
    pub(crate) fn floats(&self, attr: &str) -> Result<Option<Vec<f64>>, ReadError> {
        Ok(Some(match self.value(attr)? {
            None => return Ok(None),
            Some(Value::FloatVec(v)) => v.into_iter().map(f64::from).collect(),
            Some(Value::DoubleVec(v)) => v,
            Some(Value::HalfVec(v)) => v.into_iter().map(f64::from).collect(),
            Some(other) => return Err(self.mismatch(attr, "float[]", &other)),
        }))
    }

    /// A `point3f[]` (or `double3`, `half3`) attribute.
    pub(crate) fn points(&self, attr: &str) -> Result<Option<Vec<DVec3>>, ReadError> {
        let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        Ok(Some(match self.value(attr)? {
            None => return Ok(None),
            Some(Value::Vec3fVec(v)) => v
                .par_iter()
                .map(|a| p(a.x.into(), a.y.into(), a.z.into()))
                .collect(),
            Some(Value::Vec3dVec(v)) => v.iter().map(|a| p(a.x, a.y, a.z)).collect(),
            Some(Value::Vec3hVec(v)) => v
                .iter()
                .map(|a| p(a.x.into(), a.y.into(), a.z.into()))
                .collect(),
            Some(other) => return Err(self.mismatch(attr, "point3f[]", &other)),
        }))
    }

    /// A `texCoord2f[]` (or `float2[]`, `double2[]`, `half2[]`) attribute, u and v
    /// interleaved.
    pub(crate) fn pairs(&self, attr: &str) -> Result<Option<Vec<f64>>, ReadError> {
        Ok(Some(match self.value(attr)? {
            None => return Ok(None),
            Some(Value::Vec2fVec(v)) => v.iter().flat_map(|a| [a.x.into(), a.y.into()]).collect(),
            Some(Value::Vec2dVec(v)) => v.iter().flat_map(|a| [a.x, a.y]).collect(),
            Some(Value::Vec2hVec(v)) => v.iter().flat_map(|a| [a.x.into(), a.y.into()]).collect(),
            Some(other) => return Err(self.mismatch(attr, "texCoord2f[]", &other)),
        }))
    }

    /// A `token` attribute.
    pub(crate) fn token(&self, attr: &str) -> Result<Option<String>, ReadError> {
        match self.value(attr)? {
            None => Ok(None),
            Some(Value::Token(t)) => Ok(Some(t.as_str().to_string())),
            Some(Value::String(s)) => Ok(Some(s)),
            Some(other) => Err(self.mismatch(attr, "token", &other)),
        }
    }

    /// A `token[]` attribute.
    pub(crate) fn tokens(&self, attr: &str) -> Result<Option<Vec<String>>, ReadError> {
        match self.value(attr)? {
            None => Ok(None),
            Some(Value::TokenVec(v)) => {
                Ok(Some(v.iter().map(|t| t.as_str().to_string()).collect()))
            }
            Some(other) => Err(self.mismatch(attr, "token[]", &other)),
        }
    }

    fn mismatch(&self, attr: &str, expected: &str, found: &Value) -> ReadError {
        self.error(attr, format!("expected {expected}, found {}", kind(found)))
    }
}

/// The kind of a value, for messages.
pub(crate) fn kind(v: &Value) -> String {
    format!("{:?}", sdf::ValueKind::from(v))
}

/// A token of a USD enumeration mapped by `table`, or an error listing the allowed ones.
pub(crate) fn enum_token<T: Copy>(
    values: &PrimValues<'_>,
    attr: &str,
    token: &str,
    table: &[(&str, T)],
) -> Result<T, ReadError> {
    table
        .iter()
        .find(|(name, _)| *name == token)
        .map(|&(_, t)| t)
        .ok_or_else(|| {
            let names: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
            values.error(
                attr,
                format!(
                    "unknown token {token:?} (expected one of {})",
                    names.join(", ")
                ),
            )
        })
}

/// A token for writing.
pub(crate) fn token(s: &str) -> Value {
    Value::Token(tf::Token::from(s))
}
