//! [`PatchParam`]: where a patch lies in its base face, packed in two 32-bit words with
//! OpenSubdiv's bit layout (`Far::PatchParam`), so a shader reads the same buffer.
//!
//! Word 0: base face (bits 0–27), transition mask (28–31). Word 1: depth (0–3), non-quad
//! root (4), regular (5), boundary mask (7–11), v (12–21), u (22–31). `u` and `v` are the
//! patch's integer position in its root domain at its depth: the patch covers
//! `[u, u + 1] × [v, v + 1] / 2^(depth − nonquad)` of it.

/// A patch's place in its base face and its boundary and transition edges.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[repr(C)]
pub struct PatchParam {
    /// Base face and transition mask.
    pub field0: u32,
    /// Depth, flags, boundary mask, u and v.
    pub field1: u32,
}

fn pack(value: u32, width: u32, offset: u32) -> u32 {
    (value & ((1 << width) - 1)) << offset
}

fn unpack(word: u32, width: u32, offset: u32) -> u32 {
    (word >> offset) & ((1 << width) - 1)
}

/// The fields of a [`PatchParam`], unpacked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct PatchPlace {
    /// The root face: the base face, or for a Catmull-Clark base face that is not a quad,
    /// the ptex index of its sub-face (OpenSubdiv's `faceId`).
    pub face: u32,
    /// Integer position in the root domain at `depth`.
    pub u: u16,
    /// Integer position in the root domain at `depth`.
    pub v: u16,
    /// Refinement level of the patch.
    pub depth: u8,
    /// The root is a sub-face of a non-quad base face (its domain starts at level 1).
    pub non_quad: bool,
    /// Boundary edges: bit `i` for edge `i` (quads: v0v1, v1v2, v2v3, v3v0).
    pub boundary: u8,
    /// Edges shared with a patch one level deeper.
    pub transition: u8,
    /// A regular patch (B-spline or box-spline), not an end cap.
    pub regular: bool,
}

impl PatchParam {
    /// Packs `p`.
    pub fn new(p: PatchPlace) -> PatchParam {
        PatchParam {
            field0: pack(p.face, 28, 0) | pack(p.transition.into(), 4, 28),
            field1: pack(p.u.into(), 10, 22)
                | pack(p.v.into(), 10, 12)
                | pack(p.boundary.into(), 5, 7)
                | pack(p.regular.into(), 1, 5)
                | pack(p.non_quad.into(), 1, 4)
                | pack(p.depth.into(), 4, 0),
        }
    }

    /// The unpacked fields.
    pub fn place(self) -> PatchPlace {
        PatchPlace {
            face: unpack(self.field0, 28, 0),
            transition: unpack(self.field0, 4, 28) as u8,
            u: unpack(self.field1, 10, 22) as u16,
            v: unpack(self.field1, 10, 12) as u16,
            boundary: unpack(self.field1, 5, 7) as u8,
            regular: unpack(self.field1, 1, 5) != 0,
            non_quad: unpack(self.field1, 1, 4) != 0,
            depth: unpack(self.field1, 4, 0) as u8,
        }
    }

    /// The boundary mask the patch's basis folds: the boundary of a regular patch, none for
    /// an end cap (whose points stand in for the missing ones).
    pub fn basis_boundary(self) -> u8 {
        let p = self.place();
        if p.regular { p.boundary } else { 0 }
    }

    /// The fraction of the root domain one side of the patch spans: `2^-(depth − nonquad)`.
    pub fn fraction(self) -> f64 {
        let p = self.place();
        let d = i32::from(p.depth) - i32::from(p.non_quad);
        0.5f64.powi(d)
    }

    /// Maps `(u, v)` in the root domain to the patch's own unit square (OpenSubdiv's
    /// `Normalize`).
    pub fn normalize(self, u: f64, v: f64) -> (f64, f64) {
        let p = self.place();
        let frac_inv = 1.0 / self.fraction();
        (u * frac_inv - f64::from(p.u), v * frac_inv - f64::from(p.v))
    }

    /// Whether a triangle is turned half a turn in its root's domain (`IsTriangleRotated`).
    pub fn is_triangle_rotated(self) -> bool {
        let p = self.place();
        u32::from(p.u) + u32::from(p.v) >= 1 << p.depth
    }

    /// Maps `(u, v)` in a root triangle to the patch's own triangle (`NormalizeTriangle`):
    /// a turned patch's coordinates run backwards.
    pub fn normalize_triangle(self, u: f64, v: f64) -> (f64, f64) {
        if !self.is_triangle_rotated() {
            return self.normalize(u, v);
        }
        let p = self.place();
        let side = f64::from(1u32 << p.depth);
        (
            (side - f64::from(p.u)) - u * side,
            (side - f64::from(p.v)) - v * side,
        )
    }

    /// The inverse of [`Self::normalize_triangle`].
    pub fn unnormalize_triangle(self, u: f64, v: f64) -> (f64, f64) {
        if !self.is_triangle_rotated() {
            return self.unnormalize(u, v);
        }
        let p = self.place();
        let side = f64::from(1u32 << p.depth);
        (
            ((side - f64::from(p.u)) - u) / side,
            ((side - f64::from(p.v)) - v) / side,
        )
    }

    /// Maps `(u, v)` of the patch's unit square to the root domain (`Unnormalize`).
    pub fn unnormalize(self, u: f64, v: f64) -> (f64, f64) {
        let p = self.place();
        let frac = self.fraction();
        ((u + f64::from(p.u)) * frac, (v + f64::from(p.v)) * frac)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packs_every_field_where_opensubdiv_puts_it() {
        let p = PatchPlace {
            face: (1 << 28) - 3,
            u: 1023,
            v: 517,
            depth: 10,
            non_quad: true,
            boundary: 0b1_0110,
            transition: 0b1001,
            regular: true,
        };
        let packed = PatchParam::new(p);
        assert_eq!(packed.place(), p);
        // Bits written out by hand from the layout in the module doc.
        assert_eq!(packed.field0, ((1 << 28) - 3) | (0b1001 << 28));
        assert_eq!(
            packed.field1,
            (1023 << 22) | (517 << 12) | (0b1_0110 << 7) | (1 << 5) | (1 << 4) | 10
        );
    }

    #[test]
    fn normalize_inverts_unnormalize() {
        let p = PatchParam::new(PatchPlace {
            u: 3,
            v: 5,
            depth: 3,
            ..Default::default()
        });
        assert_eq!(p.fraction(), 0.125);
        let (s, t) = p.unnormalize(0.25, 0.5);
        assert_eq!((s, t), (3.25 / 8.0, 5.5 / 8.0));
        assert_eq!(p.normalize(s, t), (0.25, 0.5));
    }
}
