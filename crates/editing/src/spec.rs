//! The JSON files of `subd edit` and `subd deform`.
//!
//! Edit constraints:
//!
//! ```json
//! {"constraints": [
//!   {"kind": "point", "vertex": 12, "target": [0.0, 1.0, 2.0]},
//!   {"kind": "point", "face": 3, "uv": [0.25, 0.5], "displacement": [0.0, 0.0, 0.1]},
//!   {"kind": "point", "face": 7, "sub": 2, "uv": [0.5, 0.5], "target": [1.0, 0.0, 0.0]},
//!   {"kind": "normal", "face": 3, "uv": [0.25, 0.5], "normal": [0.0, 0.3, 1.0]},
//!   {"kind": "normal", "vertex": 12, "normal": [0.0, 0.0, 1.0]},
//!   {"kind": "isoline", "face": 40, "along": "u", "at": 0.5, "faces": 3,
//!    "displacements": [[0,0,0], [0,0,0.1], [0,0,0.2], [0,0,0.2], [0,0,0.1], [0,0,0]]}
//! ]}
//! ```
//!
//! A point or normal is at a `vertex` (its limit point) or at a `face` with `uv` (and `sub`
//! for a sub-face of a Catmull-Clark non-quad, as `subd eval`). A point has a `target` or a
//! `displacement`. An iso-line starts in quad `face` at `at` of the other parameter, runs
//! `along` u or v across `faces` quads, and has `targets` or `displacements`: the control
//! points of a uniform cubic B-spline, `faces + 3` of them.
//!
//! Deformation constraints:
//!
//! ```json
//! {"constraints": [{"center": [0.0, 0.0, 1.0], "radius": 0.5, "displacement": [0.0, 0.0, 0.2]}]}
//! ```

use glam::DVec3;
use serde_json::{Map, Value};
use subd_limit::eval::FaceParam;

use crate::constraint::{Constraint, Goal, Location};
use crate::deform::DeformConstraint;
use crate::isoline::{Axis, Isoline};

/// A problem in a constraint file: where (the constraint's index, when it is one) and what.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}{message}", index.map(|i| format!("constraint {i}: ")).unwrap_or_default())]
pub struct SpecError {
    /// The constraint (index in the list), when the problem is in one.
    pub index: Option<usize>,
    /// What is wrong.
    pub message: String,
}

fn whole(message: String) -> SpecError {
    SpecError {
        index: None,
        message,
    }
}

/// The constraint list of a file: `{"constraints": [...]}`.
fn list(text: &str) -> Result<Vec<Value>, SpecError> {
    let v: Value = serde_json::from_str(text).map_err(|e| whole(format!("not JSON: {e}")))?;
    let Value::Object(mut top) = v else {
        return Err(whole(
            "expected an object with a \"constraints\" list".into(),
        ));
    };
    match top.remove("constraints") {
        Some(Value::Array(a)) => Ok(a),
        Some(_) => Err(whole("\"constraints\" must be a list".into())),
        None => Err(whole("no \"constraints\" list".into())),
    }
}

struct Fields<'a> {
    map: &'a Map<String, Value>,
}

impl Fields<'_> {
    fn has(&self, k: &str) -> bool {
        self.map.contains_key(k)
    }
    fn number(&self, k: &str) -> Result<f64, String> {
        match self.map.get(k) {
            Some(Value::Number(n)) => n.as_f64().ok_or_else(|| format!("\"{k}\" is not a number")),
            Some(_) => Err(format!("\"{k}\" must be a number")),
            None => Err(format!("missing \"{k}\"")),
        }
    }
    fn index(&self, k: &str) -> Result<usize, String> {
        match self.map.get(k) {
            Some(Value::Number(n)) => n
                .as_u64()
                .map(|x| x as usize)
                .ok_or_else(|| format!("\"{k}\" must be a non-negative integer")),
            Some(_) => Err(format!("\"{k}\" must be a non-negative integer")),
            None => Err(format!("missing \"{k}\"")),
        }
    }
    fn reals(v: &Value, k: &str, n: usize) -> Result<Vec<f64>, String> {
        let Value::Array(a) = v else {
            return Err(format!("\"{k}\" must be a list of {n} numbers"));
        };
        if a.len() != n {
            return Err(format!("\"{k}\" must have {n} numbers, not {}", a.len()));
        }
        a.iter()
            .map(|x| {
                x.as_f64()
                    .ok_or_else(|| format!("\"{k}\" must hold numbers"))
            })
            .collect()
    }
    fn vec3(&self, k: &str) -> Result<DVec3, String> {
        let v = self.map.get(k).ok_or_else(|| format!("missing \"{k}\""))?;
        let r = Self::reals(v, k, 3)?;
        Ok(DVec3::new(r[0], r[1], r[2]))
    }
    fn vec3_list(&self, k: &str) -> Result<Vec<DVec3>, String> {
        match self.map.get(k) {
            Some(Value::Array(a)) => a
                .iter()
                .map(|v| Self::reals(v, k, 3).map(|r| DVec3::new(r[0], r[1], r[2])))
                .collect(),
            Some(_) => Err(format!("\"{k}\" must be a list of [x, y, z]")),
            None => Err(format!("missing \"{k}\"")),
        }
    }
    fn location(&self) -> Result<Location, String> {
        match (self.has("vertex"), self.has("face")) {
            (true, true) => Err("give a \"vertex\" or a \"face\", not both".into()),
            (true, false) => Ok(Location::Vertex(self.index("vertex")?)),
            (false, true) => {
                let face = self.index("face")?;
                let sub = if self.has("sub") {
                    self.index("sub")?
                } else {
                    0
                };
                let uv = self
                    .map
                    .get("uv")
                    .ok_or_else(|| "a face location needs \"uv\"".to_string())?;
                let uv = Self::reals(uv, "uv", 2)?;
                Ok(Location::Face(FaceParam {
                    face,
                    sub,
                    u: uv[0],
                    v: uv[1],
                }))
            }
            (false, false) => Err("give a \"vertex\" or a \"face\" with \"uv\"".into()),
        }
    }
    fn goal(&self) -> Result<Goal, String> {
        match (self.has("target"), self.has("displacement")) {
            (true, false) => Ok(Goal::Position(self.vec3("target")?)),
            (false, true) => Ok(Goal::Displacement(self.vec3("displacement")?)),
            _ => Err("give a \"target\" or a \"displacement\" (one of them)".into()),
        }
    }
    fn only(&self, allowed: &[&str]) -> Result<(), String> {
        match self.map.keys().find(|k| !allowed.contains(&k.as_str())) {
            Some(k) => Err(format!("unknown field \"{k}\"")),
            None => Ok(()),
        }
    }
}

fn one_constraint(v: &Value) -> Result<Constraint, String> {
    let Value::Object(map) = v else {
        return Err("must be an object".into());
    };
    let f = Fields { map };
    let kind = match map.get("kind") {
        Some(Value::String(s)) => s.as_str(),
        Some(_) => return Err("\"kind\" must be a string".into()),
        None => return Err("missing \"kind\" (point, normal or isoline)".into()),
    };
    match kind {
        "point" => {
            f.only(&[
                "kind",
                "vertex",
                "face",
                "sub",
                "uv",
                "target",
                "displacement",
            ])?;
            Ok(Constraint::Point {
                at: f.location()?,
                goal: f.goal()?,
            })
        }
        "normal" => {
            f.only(&["kind", "vertex", "face", "sub", "uv", "normal"])?;
            Ok(Constraint::Normal {
                at: f.location()?,
                normal: f.vec3("normal")?,
            })
        }
        "isoline" => {
            f.only(&[
                "kind",
                "face",
                "along",
                "at",
                "faces",
                "targets",
                "displacements",
            ])?;
            let along = match map.get("along") {
                Some(Value::String(s)) if s == "u" => Axis::U,
                Some(Value::String(s)) if s == "v" => Axis::V,
                Some(_) => return Err("\"along\" must be \"u\" or \"v\"".into()),
                None => return Err("missing \"along\" (\"u\" or \"v\")".into()),
            };
            let line = Isoline {
                face: f.index("face")?,
                along,
                at: f.number("at")?,
                faces: f.index("faces")?,
            };
            let goals = match (f.has("targets"), f.has("displacements")) {
                (true, false) => f
                    .vec3_list("targets")?
                    .into_iter()
                    .map(Goal::Position)
                    .collect(),
                (false, true) => f
                    .vec3_list("displacements")?
                    .into_iter()
                    .map(Goal::Displacement)
                    .collect(),
                _ => return Err("give \"targets\" or \"displacements\" (one of them)".into()),
            };
            Ok(Constraint::Isoline { line, goals })
        }
        other => Err(format!(
            "unknown kind \"{other}\" (expected point, normal or isoline)"
        )),
    }
}

/// Parses an edit constraint file.
///
/// # Errors
/// [`SpecError`] naming the constraint and the problem (unknown kind or field, missing or
/// mistyped value), or the file (not JSON, no list).
pub fn parse_constraints(text: &str) -> Result<Vec<Constraint>, SpecError> {
    list(text)?
        .iter()
        .enumerate()
        .map(|(i, v)| {
            one_constraint(v).map_err(|message| SpecError {
                index: Some(i),
                message,
            })
        })
        .collect()
}

/// Parses a deformation constraint file.
///
/// # Errors
/// As [`parse_constraints`].
pub fn parse_deformation(text: &str) -> Result<Vec<DeformConstraint>, SpecError> {
    list(text)?
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let one = || -> Result<DeformConstraint, String> {
                let Value::Object(map) = v else {
                    return Err("must be an object".into());
                };
                let f = Fields { map };
                f.only(&["center", "radius", "displacement"])?;
                Ok(DeformConstraint {
                    center: f.vec3("center")?,
                    radius: f.number("radius")?,
                    displacement: f.vec3("displacement")?,
                })
            };
            one().map_err(|message| SpecError {
                index: Some(i),
                message,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_documented_examples_parse() {
        let c = parse_constraints(
            r#"{"constraints": [
              {"kind": "point", "vertex": 12, "target": [0.0, 1.0, 2.0]},
              {"kind": "point", "face": 3, "uv": [0.25, 0.5], "displacement": [0.0, 0.0, 0.1]},
              {"kind": "normal", "vertex": 12, "normal": [0.0, 0.0, 1.0]},
              {"kind": "isoline", "face": 40, "along": "v", "at": 0.5, "faces": 1,
               "targets": [[0,0,0], [1,0,0], [2,0,0], [3,0,0]]}]}"#,
        )
        .unwrap();
        assert_eq!(c.len(), 4);
        assert_eq!(
            c[1],
            Constraint::Point {
                at: Location::Face(FaceParam {
                    face: 3,
                    sub: 0,
                    u: 0.25,
                    v: 0.5
                }),
                goal: Goal::Displacement(DVec3::new(0.0, 0.0, 0.1)),
            }
        );
        let d = parse_deformation(
            r#"{"constraints": [{"center": [0, 0, 1], "radius": 0.5, "displacement": [0, 0, 0.2]}]}"#,
        )
        .unwrap();
        assert_eq!(d[0].radius, 0.5);
    }

    #[test]
    fn problems_name_the_constraint() {
        let cases = [
            (
                r#"{"constraints": [{"kind": "pointy"}]}"#,
                "constraint 0: unknown kind \"pointy\"",
            ),
            (
                r#"{"constraints": [{"kind": "point", "vertex": 1, "target": [0, 0, 0]}, {"kind": "point", "vertex": -1, "target": [0,0,0]}]}"#,
                "constraint 1: \"vertex\" must be a non-negative integer",
            ),
            (
                r#"{"constraints": [{"kind": "normal", "vertex": 1}]}"#,
                "constraint 0: missing \"normal\"",
            ),
            (
                r#"{"constraints": [{"kind": "point", "vertex": 1}]}"#,
                "constraint 0: give a \"target\"",
            ),
            (
                r#"{"constraints": [{"kind": "point", "face": 1, "uv": [0.5], "target": [0,0,0]}]}"#,
                "\"uv\" must have 2 numbers",
            ),
            (
                r#"{"constraints": [{"kind": "point", "vertex": 1, "target": [0,0,0], "colour": 1}]}"#,
                "unknown field \"colour\"",
            ),
            (
                r#"{"constraints": [{"kind": "point", "vertex": 1, "target": [NaN,0,0]}]}"#,
                "not JSON",
            ),
            (r#"[1, 2]"#, "expected an object"),
        ];
        for (text, want) in cases {
            let e = parse_constraints(text).unwrap_err().to_string();
            assert!(e.contains(want), "{e:?} lacks {want:?}");
        }
        let e = parse_deformation(
            r#"{"constraints": [{"center": [0, 0], "radius": 1, "displacement": [0,0,0]}]}"#,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("constraint 0: \"center\" must have 3 numbers"),
            "{e}"
        );
    }
}
