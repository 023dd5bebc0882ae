//! A prim's composed transform: its `xformOp`s and its ancestors', as `UsdGeomXformable`
//! defines them.
//!
//! Written here rather than taken from `openusd-schemas` (which has `Xformable`), a second
//! crate that would need the same toolchain exception as `openusd`, for about a hundred lines
//! of matrix algebra. Matrices are glam's column-vector ones: USD's row-vector matrix `M`
//! (points `p' = p M`) is glam's `Mᵀ`, so a `matrix4d` read in USD's row-major order is
//! glam's column-major array as it stands, and the ops of `xformOpOrder` `[a, b, c]`
//! compose to `A B C` (the last op applies first, as USD's `GetLocalTransformation`).

use glam::{DMat4, DQuat, DVec3, DVec4};
use openusd::sdf::Value;
use openusd::usd;

use super::values::{PrimValues, kind};
use crate::error::ReadError;

/// The transform from `prim`'s space to the world at `time`: the local transforms of the
/// prim and its ancestors, up to the root or to the first `!resetXformStack!`.
pub(super) fn world_transform(prim: &usd::Prim, time: Option<f64>) -> Result<DMat4, ReadError> {
    let mut world = DMat4::IDENTITY;
    let mut at = Some(prim.clone());
    while let Some(p) = at {
        if p.path().is_abs_root() {
            break;
        }
        let (local, reset) = local_transform(&PrimValues { prim: &p, time })?;
        world = local * world;
        if reset {
            break;
        }
        at = p.parent();
    }
    Ok(world)
}

/// A prim's own transform, and whether it resets its parents' (`!resetXformStack!`).
fn local_transform(values: &PrimValues<'_>) -> Result<(DMat4, bool), ReadError> {
    let Some(order) = values.tokens("xformOpOrder")? else {
        return Ok((DMat4::IDENTITY, false));
    };
    let mut m = DMat4::IDENTITY;
    let mut reset = false;
    for op in &order {
        if op == "!resetXformStack!" {
            // Ops before it are ignored as well as the parents (UsdGeomXformable).
            m = DMat4::IDENTITY;
            reset = true;
            continue;
        }
        let (name, invert) = match op.strip_prefix("!invert!") {
            Some(name) => (name, true),
            None => (op.as_str(), false),
        };
        let mut op_m = op_matrix(values, name)?;
        if invert {
            op_m = op_m.inverse();
        }
        m *= op_m;
    }
    Ok((m, reset))
}

/// The matrix of the op attribute `name` (`xformOp:TYPE[:suffix]`).
fn op_matrix(values: &PrimValues<'_>, name: &str) -> Result<DMat4, ReadError> {
    let ty = name
        .strip_prefix("xformOp:")
        .and_then(|rest| rest.split(':').next())
        .ok_or_else(|| values.error("xformOpOrder", format!("{name:?} is not an xformOp")))?;
    let value = values
        .value(name)?
        .ok_or_else(|| values.error(name, "listed in xformOpOrder but has no value"))?;
    let bad =
        |expected: &str| values.error(name, format!("expected {expected}, found {}", kind(&value)));
    let deg = |x: f64| x.to_radians();
    let m = match ty {
        "translate" => DMat4::from_translation(vec3(&value).ok_or_else(|| bad("double3"))?),
        "scale" => DMat4::from_scale(vec3(&value).ok_or_else(|| bad("double3"))?),
        "rotateX" => DMat4::from_rotation_x(deg(scalar(&value).ok_or_else(|| bad("double"))?)),
        "rotateY" => DMat4::from_rotation_y(deg(scalar(&value).ok_or_else(|| bad("double"))?)),
        "rotateZ" => DMat4::from_rotation_z(deg(scalar(&value).ok_or_else(|| bad("double"))?)),
        "translateX" | "translateY" | "translateZ" | "scaleX" | "scaleY" | "scaleZ" => {
            single_axis(ty, scalar(&value).ok_or_else(|| bad("double"))?)
        }
        "orient" => quat_matrix(quat(&value).ok_or_else(|| bad("quatd"))?),
        "transform" => match &value {
            Value::Matrix4d(m) => DMat4::from_cols_array(&m.0),
            _ => return Err(bad("matrix4d")),
        },
        _ => match ty.strip_prefix("rotate") {
            Some(axes) if axes.len() == 3 => {
                rotation_in_order(axes, vec3(&value).ok_or_else(|| bad("double3"))?)
                    .ok_or_else(|| values.error(name, format!("unknown op type {ty}")))?
            }
            _ => return Err(values.error(name, format!("unknown op type {ty}"))),
        },
    };
    Ok(m)
}

/// `rotateXYZ` and its five siblings: the value holds the angles about X, Y and Z (in
/// degrees) whatever the order, and the first axis named rotates first.
fn rotation_in_order(axes: &str, angles: DVec3) -> Option<DMat4> {
    let mut m = DMat4::IDENTITY;
    for axis in axes.chars() {
        let r = match axis {
            'X' => DMat4::from_rotation_x(angles.x.to_radians()),
            'Y' => DMat4::from_rotation_y(angles.y.to_radians()),
            'Z' => DMat4::from_rotation_z(angles.z.to_radians()),
            _ => return None,
        };
        // Each later rotation applies after the ones before: it multiplies from the left.
        m = r * m;
    }
    Some(m)
}

fn single_axis(ty: &str, x: f64) -> DMat4 {
    let axis = match ty.as_bytes().last() {
        Some(b'X') => DVec3::X,
        Some(b'Y') => DVec3::Y,
        _ => DVec3::Z,
    };
    if ty.starts_with("translate") {
        DMat4::from_translation(axis * x)
    } else {
        DMat4::from_scale(DVec3::ONE + axis * (x - 1.0))
    }
}

fn scalar(v: &Value) -> Option<f64> {
    match v {
        Value::Double(x) => Some(*x),
        Value::Float(x) => Some(f64::from(*x)),
        Value::Half(x) => Some(f64::from(*x)),
        _ => None,
    }
}

fn vec3(v: &Value) -> Option<DVec3> {
    match v {
        Value::Vec3d(a) => Some(DVec3::new(a.x, a.y, a.z)),
        Value::Vec3f(a) => Some(DVec3::new(a.x.into(), a.y.into(), a.z.into())),
        Value::Vec3h(a) => Some(DVec3::new(a.x.into(), a.y.into(), a.z.into())),
        _ => None,
    }
}

fn quat(v: &Value) -> Option<DQuat> {
    match v {
        Value::Quatd(q) => Some(DQuat::from_xyzw(q.x, q.y, q.z, q.w)),
        Value::Quatf(q) => Some(DQuat::from_xyzw(
            q.x.into(),
            q.y.into(),
            q.z.into(),
            q.w.into(),
        )),
        Value::Quath(q) => Some(DQuat::from_xyzw(
            q.x.into(),
            q.y.into(),
            q.z.into(),
            q.w.into(),
        )),
        _ => None,
    }
}

/// The rotation matrix of `orient`'s quaternion as USD forms it (a `GfRotation` made from
/// it): the angle from the real part alone (2 acos w) about the imaginary part's direction.
/// A `quatf` is a little off unit length, and this, not plain normalisation, is where USD
/// puts the points then.
fn quat_matrix(q: DQuat) -> DMat4 {
    let axis = DVec3::new(q.x, q.y, q.z);
    let len = axis.length();
    if len <= 1e-10 {
        return DMat4::IDENTITY;
    }
    let half = q.w.clamp(-1.0, 1.0).acos();
    let (sin, cos) = half.sin_cos();
    let (x, y, z, w) = (
        axis.x / len * sin,
        axis.y / len * sin,
        axis.z / len * sin,
        cos,
    );
    DMat4::from_cols(
        DVec4::new(
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y + z * w),
            2.0 * (z * x - y * w),
            0.0,
        ),
        DVec4::new(
            2.0 * (x * y - z * w),
            1.0 - 2.0 * (z * z + x * x),
            2.0 * (y * z + x * w),
            0.0,
        ),
        DVec4::new(
            2.0 * (z * x + y * w),
            2.0 * (y * z - x * w),
            1.0 - 2.0 * (y * y + x * x),
            0.0,
        ),
        DVec4::W,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// rotateXYZ turns about X first: (0, 1, 0) by 90° about X is (0, 0, 1), then 90° about
    /// Z leaves it there; the other order sends it to (-1, 0, 0) first.
    #[test]
    fn rotations_apply_in_the_named_order() {
        let angles = DVec3::new(90.0, 0.0, 90.0);
        let xyz = rotation_in_order("XYZ", angles).unwrap();
        let zyx = rotation_in_order("ZYX", angles).unwrap();
        let p = DVec3::Y;
        assert!((xyz.transform_point3(p) - DVec3::Z).length() < 1e-12);
        assert!((zyx.transform_point3(p) - DVec3::new(-1.0, 0.0, 0.0)).length() < 1e-12);
    }

    /// A unit quaternion gives glam's rotation; in one off unit length the real part sets
    /// the angle (USD's `GfRotation`), and a real part alone is the identity.
    #[test]
    fn orient_matrices_follow_usd() {
        let q = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        let diff = quat_matrix(q) - DMat4::from_quat(q);
        assert!(diff.to_cols_array().iter().all(|d| d.abs() < 1e-15));
        let long = DQuat::from_xyzw(0.0, 0.0, 0.0, 2.0);
        assert_eq!(quat_matrix(long), DMat4::IDENTITY);
        // w = cos 30°, the axis twice too long: still 60° about z.
        let off = DQuat::from_xyzw(0.0, 0.0, 1.0, 0.75f64.sqrt());
        let p = quat_matrix(off).transform_point3(DVec3::X);
        let want = DVec3::new(0.5, 0.75f64.sqrt(), 0.0);
        assert!((p - want).length() < 1e-15, "{p}");
    }

    #[test]
    fn single_axis_scale_keeps_the_other_axes() {
        let m = single_axis("scaleY", 3.0);
        assert_eq!(m.transform_point3(DVec3::ONE), DVec3::new(1.0, 3.0, 1.0));
        let t = single_axis("translateZ", 2.0);
        assert_eq!(t.transform_point3(DVec3::ZERO), DVec3::new(0.0, 0.0, 2.0));
    }
}
