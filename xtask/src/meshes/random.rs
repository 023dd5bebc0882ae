//! Random meshes for the conformance run: grids (open, or closed as a torus), stars and
//! bipyramids with centre valences 3..12, mixed quads, triangles and n-gons, with random
//! infinitely sharp and semi-sharp creases, corners, holes, non-manifold "fin" faces, and
//! random scheme options. Deterministic in the seed.

use subd_mesh::{
    BoundaryInterpolation, CreaseMethod, DVec3, Topology, TopologyBuilder, TriangleSubdivision,
};
use subd_schemes::{Options, Scheme};

/// xorshift64*: small, fast, deterministic (seed: any nonzero state).
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    pub(crate) fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
}

/// One random case.
pub struct RandomCase {
    pub name: String,
    pub topology: Topology,
    pub positions: Vec<DVec3>,
    pub scheme: Scheme,
    pub options: Options,
}

struct Builder {
    positions: Vec<DVec3>,
    faces: Vec<Vec<u32>>,
}

impl Builder {
    fn vertex(&mut self, p: DVec3) -> u32 {
        self.positions.push(p);
        (self.positions.len() - 1) as u32
    }
}

/// A grid of m x n cells; `closed` wraps both ways into a torus. Cells become a quad, two
/// triangles, a fan of four triangles, or (with the next cell) a hexagon.
fn grid(rng: &mut Rng, b: &mut Builder, m: u32, n: u32, closed: bool, triangles_only: bool) {
    let (rows, cols) = if closed { (m, n) } else { (m + 1, n + 1) };
    let first = b.positions.len() as u32;
    for i in 0..rows {
        for j in 0..cols {
            let p = if closed {
                let (u, v) = (
                    i as f64 / m as f64 * std::f64::consts::TAU,
                    j as f64 / n as f64 * std::f64::consts::TAU,
                );
                DVec3::new(
                    (3.0 + v.cos()) * u.cos(),
                    (3.0 + v.cos()) * u.sin(),
                    v.sin(),
                )
            } else {
                DVec3::new(j as f64, i as f64, 0.3 * rng.unit())
            };
            b.vertex(p + 0.05 * DVec3::new(rng.unit(), rng.unit(), rng.unit()));
        }
    }
    let id = |i: u32, j: u32| first + (i % rows) * cols + (j % cols);
    for i in 0..m {
        let mut j = 0;
        while j < n {
            let q = [id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)];
            let choice = if triangles_only {
                1 + rng.below(2)
            } else {
                rng.below(5)
            };
            match choice {
                0 | 4 if j + 1 < n && !triangles_only && choice == 4 => {
                    b.faces
                        .push(vec![q[0], q[1], id(i, j + 2), id(i + 1, j + 2), q[2], q[3]]);
                    j += 1;
                }
                1 => {
                    b.faces.push(vec![q[0], q[1], q[2]]);
                    b.faces.push(vec![q[0], q[2], q[3]]);
                }
                2 => {
                    let c =
                        b.vertex(q.iter().map(|&v| b.positions[v as usize]).sum::<DVec3>() / 4.0);
                    for k in 0..4 {
                        b.faces.push(vec![q[k], q[(k + 1) % 4], c]);
                    }
                }
                _ => b.faces.push(q.to_vec()),
            }
            j += 1;
        }
    }
}

/// A star around a centre of valence k (triangles or quads), open, or closed into a
/// bipyramid by a second centre.
fn star(rng: &mut Rng, b: &mut Builder, k: u32, closed: bool, triangles_only: bool) {
    let c = b.vertex(DVec3::new(0.0, 0.0, 0.5 + rng.unit()));
    let ring: Vec<u32> = (0..k)
        .map(|i| {
            let a = i as f64 / k as f64 * std::f64::consts::TAU;
            b.vertex(DVec3::new(a.cos(), a.sin(), 0.2 * rng.unit()))
        })
        .collect();
    let quads = !triangles_only && rng.chance(0.5);
    let mids: Vec<u32> = if quads {
        (0..k)
            .map(|i| {
                let a = (i as f64 + 0.5) / k as f64 * std::f64::consts::TAU;
                b.vertex(DVec3::new(0.8 * a.cos(), 0.8 * a.sin(), 0.4))
            })
            .collect()
    } else {
        Vec::new()
    };
    for i in 0..k as usize {
        let (r0, r1) = (ring[i], ring[(i + 1) % k as usize]);
        if quads {
            b.faces.push(vec![c, r0, mids[i], r1]);
            // Keep the quad consistent: ring vertices share the mid point of their sector.
        } else {
            b.faces.push(vec![c, r0, r1]);
        }
    }
    if closed {
        let d = b.vertex(DVec3::new(0.0, 0.0, -0.5 - rng.unit()));
        for i in 0..k as usize {
            let (r0, r1) = (ring[i], ring[(i + 1) % k as usize]);
            if quads {
                b.faces.push(vec![d, r1, mids[i], r0]);
            } else {
                b.faces.push(vec![d, r1, r0]);
            }
        }
    }
}

/// The random case number `seed`. Every step draws from the one generator in a fixed
/// order, so a seed always yields the same mesh.
pub fn case(seed: u64) -> RandomCase {
    let mut rng = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let scheme = random_scheme(&mut rng);
    let (mut b, kind) = random_shape(&mut rng, scheme == Scheme::Loop);
    add_fins(&mut rng, &mut b);
    let sizes: Vec<u32> = b.faces.iter().map(|f| f.len() as u32).collect();
    let idx: Vec<u32> = b.faces.iter().flatten().copied().collect();
    let mut topology = TopologyBuilder::new(b.positions.len())
        .accept_inconsistent_orientation(true)
        .build(&sizes, &idx)
        .expect("random mesh is valid");
    add_tags(&mut rng, &mut topology);
    let options = random_options(&mut rng);
    RandomCase {
        name: case_name(seed, kind, &scheme),
        topology,
        positions: b.positions,
        scheme,
        options,
    }
}

/// The scheme, the first draw: Catmull-Clark and Loop two times in five each, bilinear
/// once.
fn random_scheme(rng: &mut Rng) -> Scheme {
    match rng.below(5) {
        0 | 1 => Scheme::CatmullClark,
        2 | 3 => Scheme::Loop,
        _ => Scheme::Bilinear,
    }
}

/// The base shape and its kind (0 grid, 1 torus, 2 star, 3 bipyramid); triangles only
/// with `tri`. The grid sizes and the star valence are drawn whichever kind is picked.
fn random_shape(rng: &mut Rng, tri: bool) -> (Builder, u64) {
    let mut b = Builder {
        positions: Vec::new(),
        faces: Vec::new(),
    };
    let kind = rng.below(4);
    let (m, n, k) = (
        rng.below(6) as u32,
        rng.below(6) as u32,
        3 + rng.below(10) as u32,
    );
    match kind {
        0 => grid(rng, &mut b, 2 + m, 2 + n, false, tri),
        1 => grid(rng, &mut b, 3 + m, 3 + n, true, tri),
        2 => star(rng, &mut b, k, false, tri),
        _ => star(rng, &mut b, k, true, tri),
    }
    (b, kind)
}

/// Non-manifold fins, on three meshes in ten: one or two triangles each hung on an
/// existing edge (a third face on it).
fn add_fins(rng: &mut Rng, b: &mut Builder) {
    if rng.chance(0.3) {
        for _ in 0..1 + rng.below(2) {
            let f = rng.below(b.faces.len() as u64) as usize;
            let fv = b.faces[f].clone();
            let i = rng.below(fv.len() as u64) as usize;
            let (a, c) = (fv[i], fv[(i + 1) % fv.len()]);
            let p = (b.positions[a as usize] + b.positions[c as usize]) / 2.0
                + DVec3::new(0.0, 0.0, 1.0);
            let v = b.vertex(p);
            b.faces.push(vec![a, c, v]);
        }
    }
}

/// Random creases, corners and holes: edges, then vertices, then faces, in index order.
fn add_tags(rng: &mut Rng, topology: &mut Topology) {
    for e in 0..topology.num_edges() {
        if rng.chance(0.12) {
            topology.set_edge_sharpness(e, random_sharpness(rng));
        }
    }
    for v in 0..topology.num_vertices() {
        if rng.chance(0.05) {
            topology.set_vertex_sharpness(v, random_sharpness(rng));
        }
    }
    for f in 0..topology.num_faces() {
        if rng.chance(0.04) {
            topology.set_hole(f, true);
        }
    }
}

/// A tag's sharpness: infinitely sharp three times in ten, else a semi-sharp value.
fn random_sharpness(rng: &mut Rng) -> f32 {
    // Tags, in f32 as a file would give them; non-dyadic values like OpenSubdiv's shapes.
    const SEMI: [f64; 8] = [0.2, 0.5, 0.9, 1.0, 1.4, 2.5, 2.8, 4.7];
    let s = if rng.chance(0.3) {
        10.0
    } else {
        SEMI[rng.below(8) as usize]
    };
    s as f32
}

/// The scheme options, drawn in field order: boundary interpolation, crease method,
/// triangle subdivision.
fn random_options(rng: &mut Rng) -> Options {
    Options {
        boundary_interpolation: match rng.below(3) {
            0 => BoundaryInterpolation::None,
            1 => BoundaryInterpolation::EdgeOnly,
            _ => BoundaryInterpolation::EdgeAndCorner,
        },
        crease_method: if rng.chance(0.5) {
            CreaseMethod::Uniform
        } else {
            CreaseMethod::Chaikin
        },
        triangle_subdivision: if rng.chance(0.3) {
            TriangleSubdivision::Smooth
        } else {
            TriangleSubdivision::Catmark
        },
    }
}

/// `random_<seed>_<kind>_<scheme>`, e.g. `random_073_torus_loop`.
fn case_name(seed: u64, kind: u64, scheme: &Scheme) -> String {
    let kinds = ["grid", "torus", "star", "bipyramid"];
    format!(
        "random_{seed:03}_{}_{}",
        kinds[kind as usize],
        match scheme {
            Scheme::CatmullClark => "catmark",
            Scheme::Loop => "loop",
            Scheme::Bilinear => "bilinear",
            other => unreachable!("random cases use OpenSubdiv's schemes, not {other}"),
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The random set exercises every feature the conformance run is meant to cover.
    #[test]
    fn random_cases_cover_the_features() {
        let cases: Vec<RandomCase> = (0..360).map(case).collect();
        let any = |p: &dyn Fn(&RandomCase) -> bool| cases.iter().filter(|c| p(c)).count();
        assert!(
            any(&|c| (0..c.topology.num_edges()).any(|e| c.topology.is_non_manifold_edge(e))) > 20
        );
        assert!(any(&|c| c.topology.tags().num_holes() > 0) > 20);
        assert!(any(&|c| c.topology.tags().num_infinite_creases() > 0) > 20);
        assert!(
            any(&|c| c.topology.tags().num_creased_edges()
                > c.topology.tags().num_infinite_creases())
                > 50
        );
        assert!(any(&|c| c.topology.tags().num_corners() > 0) > 50);
        assert!(any(&|c| c.options.crease_method == CreaseMethod::Chaikin) > 50);
        assert!(any(&|c| c.options.boundary_interpolation == BoundaryInterpolation::None) > 50);
        assert!(
            any(&|c| c.options.boundary_interpolation == BoundaryInterpolation::EdgeAndCorner) > 50
        );
        assert!(any(&|c| c.scheme == Scheme::Loop) > 50);
        assert!(any(&|c| c.scheme == Scheme::Bilinear) > 20);
        assert!(any(&|c| (0..c.topology.num_faces()).any(|f| c.topology.face_size(f) > 4)) > 20);
        assert!(any(&|c| (0..c.topology.num_vertices()).any(|v| c.topology.valence(v) >= 10)) > 10);
        assert!(any(&|c| (0..c.topology.num_vertices()).any(|v| c.topology.valence(v) == 3)) > 10);
        assert!(
            any(&|c| (0..c.topology.num_edges()).all(|e| !c.topology.is_boundary_edge(e))) > 50
        );
    }
}
