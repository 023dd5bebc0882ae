//! A small CPU rasteriser for `subd render`: an orthographic camera, z-buffered triangles
//! with per-pixel interpolated normals, depth-tested lines and dots, and PNG output.
//!
//! Hand-written: the Rust rasterisers that exist are GPU front ends or 2-D vector
//! renderers; a z-buffered, smooth-shaded triangle fill is a few dozen lines.

use subd_mesh::DVec3;

/// An RGB colour.
pub(crate) type Rgb = [u8; 3];

/// The background of every picture.
pub(crate) const BACKGROUND: Rgb = [246, 246, 246];

/// An orthographic view: the scene's bounding sphere fills 90% of the shorter side.
pub(crate) struct Camera {
    centre: DVec3,
    right: DVec3,
    up: DVec3,
    /// Unit vector from the scene towards the viewer.
    towards_eye: DVec3,
    /// Pixels per scene unit.
    scale: f64,
    width: usize,
    height: usize,
}

impl Camera {
    /// Looks at the sphere (`centre`, `radius`) from azimuth and elevation in degrees, with
    /// +y up: azimuth 0, elevation 0 looks down −z.
    pub(crate) fn new(
        centre: DVec3,
        radius: f64,
        azimuth: f64,
        elevation: f64,
        width: usize,
        height: usize,
    ) -> Camera {
        let (az, el) = (azimuth.to_radians(), elevation.to_radians());
        let towards_eye = DVec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
        let right = DVec3::Y
            .cross(towards_eye)
            .try_normalize()
            .unwrap_or(DVec3::X);
        let up = towards_eye.cross(right);
        let radius = if radius > 0.0 { radius } else { 1.0 };
        Camera {
            centre,
            right,
            up,
            towards_eye,
            scale: 0.45 * width.min(height) as f64 / radius,
            width,
            height,
        }
    }

    /// Screen position (pixels, y down) and depth (scene units, smaller is nearer).
    pub(crate) fn project(&self, p: DVec3) -> DVec3 {
        let d = p - self.centre;
        DVec3::new(
            self.width as f64 / 2.0 + self.scale * d.dot(self.right),
            self.height as f64 / 2.0 - self.scale * d.dot(self.up),
            -d.dot(self.towards_eye),
        )
    }

    /// Unit vector towards the viewer.
    pub(crate) fn towards_eye(&self) -> DVec3 {
        self.towards_eye
    }

    /// The camera's right and up vectors, for [`shade`].
    pub(crate) fn axes(&self) -> (DVec3, DVec3) {
        (self.right, self.up)
    }
}

/// Colour and depth buffers.
pub(crate) struct Canvas {
    width: usize,
    height: usize,
    color: Vec<Rgb>,
    depth: Vec<f64>,
}

impl Canvas {
    pub(crate) fn new(width: usize, height: usize) -> Canvas {
        Canvas {
            width,
            height,
            color: vec![BACKGROUND; width * height],
            depth: vec![f64::INFINITY; width * height],
        }
    }

    /// Fills the screen-space triangle `s` (from [`Camera::project`]) where it is nearer than
    /// what is drawn; `shade` gets the barycentric weights of the pixel centre.
    pub(crate) fn triangle(&mut self, s: [DVec3; 3], shade: impl Fn([f64; 3]) -> Rgb) {
        let area = edge(s[0], s[1], s[2]);
        if area.abs() < 1e-12 || !area.is_finite() {
            return;
        }
        let clamp = |v: f64, n: usize| v.clamp(0.0, n as f64) as usize;
        let x0 = clamp(
            s.iter().map(|p| p.x).fold(f64::INFINITY, f64::min).floor(),
            self.width,
        );
        let x1 = clamp(
            s.iter()
                .map(|p| p.x)
                .fold(f64::NEG_INFINITY, f64::max)
                .ceil(),
            self.width,
        );
        let y0 = clamp(
            s.iter().map(|p| p.y).fold(f64::INFINITY, f64::min).floor(),
            self.height,
        );
        let y1 = clamp(
            s.iter()
                .map(|p| p.y)
                .fold(f64::NEG_INFINITY, f64::max)
                .ceil(),
            self.height,
        );
        for y in y0..y1 {
            for x in x0..x1 {
                let p = DVec3::new(x as f64 + 0.5, y as f64 + 0.5, 0.0);
                let w = [
                    edge(s[1], s[2], p) / area,
                    edge(s[2], s[0], p) / area,
                    edge(s[0], s[1], p) / area,
                ];
                // Both windings are drawn (no culling): pixel centres inside, edges included.
                if w.iter().any(|&b| b < 0.0) {
                    continue;
                }
                let z = w[0] * s[0].z + w[1] * s[1].z + w[2] * s[2].z;
                let i = y * self.width + x;
                if z < self.depth[i] {
                    self.depth[i] = z;
                    self.color[i] = shade(w);
                }
            }
        }
    }

    /// A line `width` pixels wide from `a` to `b` (screen space). Where the surface is
    /// nearer by more than `bias`, the line is blended in at `hidden` opacity (0: not drawn).
    pub(crate) fn line(
        &mut self,
        a: DVec3,
        b: DVec3,
        color: Rgb,
        width: usize,
        bias: f64,
        hidden: f64,
    ) {
        let steps = (b.x - a.x).abs().max((b.y - a.y).abs()).ceil().max(1.0) as usize;
        for k in 0..=steps {
            let p = a.lerp(b, k as f64 / steps as f64);
            self.spot(p, width, color, bias, hidden);
        }
    }

    /// A round dot of `radius` pixels at `p` (screen space), depth-tested as [`Self::line`].
    pub(crate) fn dot(&mut self, p: DVec3, radius: f64, color: Rgb, bias: f64, hidden: f64) {
        let r = radius.ceil() as i64;
        for dy in -r..=r {
            for dx in -r..=r {
                if ((dx * dx + dy * dy) as f64) <= radius * radius {
                    let q = DVec3::new(p.x + dx as f64, p.y + dy as f64, p.z);
                    self.spot(q, 1, color, bias, hidden);
                }
            }
        }
    }

    fn spot(&mut self, p: DVec3, width: usize, color: Rgb, bias: f64, hidden: f64) {
        let half = (width as i64 - 1) / 2;
        for dy in -half..=(width as i64 - 1 - half) {
            for dx in -half..=(width as i64 - 1 - half) {
                let (x, y) = (p.x.floor() as i64 + dx, p.y.floor() as i64 + dy);
                if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
                    continue;
                }
                let i = y as usize * self.width + x as usize;
                let opacity = if p.z <= self.depth[i] + bias {
                    1.0
                } else {
                    hidden
                };
                if opacity > 0.0 {
                    self.color[i] = blend(self.color[i], color, opacity);
                }
            }
        }
    }

    /// The picture as PNG (8-bit RGB).
    pub(crate) fn png(&self) -> Result<Vec<u8>, png::EncodingError> {
        let mut bytes = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut bytes, self.width as u32, self.height as u32);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            let mut writer = encoder.write_header()?;
            let data: Vec<u8> = self.color.iter().flatten().copied().collect();
            writer.write_image_data(&data)?;
        }
        Ok(bytes)
    }
}

/// Twice the signed area of (a, b, c) in the screen plane.
fn edge(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)
}

fn blend(under: Rgb, over: Rgb, opacity: f64) -> Rgb {
    let mix =
        |u: u8, o: u8| (f64::from(u) * (1.0 - opacity) + f64::from(o) * opacity).round() as u8;
    [
        mix(under[0], over[0]),
        mix(under[1], over[1]),
        mix(under[2], over[2]),
    ]
}

/// Lambert and Blinn-Phong shading of `base` at unit normal `n` (turned to face the viewer,
/// so both sides of an open surface are lit) under a key light above-left of the viewer.
pub(crate) fn shade(
    base: Rgb,
    n: DVec3,
    towards_eye: DVec3,
    camera_right: DVec3,
    camera_up: DVec3,
) -> Rgb {
    let n = if n.dot(towards_eye) < 0.0 { -n } else { n };
    let light = (towards_eye - 0.45 * camera_right + 0.55 * camera_up).normalize();
    let diffuse = n.dot(light).max(0.0);
    let half = (light + towards_eye).normalize();
    let specular = n.dot(half).max(0.0).powi(48);
    let c = |b: u8| {
        let v = f64::from(b) * (0.28 + 0.72 * diffuse) + 255.0 * 0.22 * specular;
        v.clamp(0.0, 255.0).round() as u8
    };
    [c(base[0]), c(base[1]), c(base[2])]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_covers_its_pixels_and_the_nearer_one_wins() {
        let mut c = Canvas::new(10, 10);
        let far = [
            DVec3::new(0.0, 0.0, 5.0),
            DVec3::new(10.0, 0.0, 5.0),
            DVec3::new(0.0, 10.0, 5.0),
        ];
        let near = [
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(10.0, 0.0, 1.0),
            DVec3::new(0.0, 10.0, 1.0),
        ];
        c.triangle(near, |_| [1, 1, 1]);
        c.triangle(far, |_| [2, 2, 2]);
        let covered = c.color.iter().filter(|&&p| p == [1, 1, 1]).count();
        // Pixel centres (i + ½, j + ½) with i + j ≤ 9; the ten with i + j = 9 lie on the
        // hypotenuse itself, which is included.
        assert_eq!(covered, 55);
        assert!(c.color.contains(&BACKGROUND));
    }

    #[test]
    fn the_camera_frames_the_bounding_sphere() {
        let cam = Camera::new(DVec3::ZERO, 2.0, 0.0, 0.0, 200, 100);
        // Looking down −z with +y up: +x is right, +y up; radius 2 → 45 pixels.
        assert_eq!(
            cam.project(DVec3::new(2.0, 0.0, 0.0)),
            DVec3::new(145.0, 50.0, 0.0)
        );
        assert_eq!(
            cam.project(DVec3::new(0.0, 2.0, 1.0)),
            DVec3::new(100.0, 5.0, -1.0)
        );
    }
}
