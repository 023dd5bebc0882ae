// Evaluates the patches of a patch table: positions and first derivatives at (patch, u, v)
// queries, or on the uniform grid of every patch, plus the grid's triangle indices.
//
// Every kind of patch is one routine: a control point's weight at (s, t) of the patch's
// own domain is blend(s, t) * sum c[i + 5 j] s^i t^j (subd_limit's PatchBasisPolynomials;
// derivatives hold the blend constant, as OpenSubdiv's Gregory evaluation does).
//
// `Real` (f64 or f32) is defined by the Rust side in front of this text.

struct Params {
    // Queries (evaluate), grid samples (tessellate) or grid cells (grid_indices).
    count: u32,
    // Invocations per line of the dispatch grid.
    rows_per_line: u32,
    // Grid segments per patch side.
    rate: u32,
    patches: u32,
    // Where the control-point indices and the class words start in `words`.
    cps_base: u32,
    classes_base: u32,
    _pad0: u32,
    _pad1: u32,
}

// `words`: per patch 4 words (first control point in `words`, class, PatchParam's two
// words), then the control-point indices, then per class 22 words (control points,
// triangle flag, 20 blend codes).
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> words: array<u32>;
@group(0) @binding(2) var<storage, read> coefficients: array<Real>;
@group(0) @binding(3) var<storage, read> points: array<f32>;
@group(0) @binding(4) var<storage, read> coords: array<u32>;
@group(0) @binding(5) var<storage, read_write> out_position: array<f32>;
@group(0) @binding(6) var<storage, read_write> out_du: array<f32>;
@group(0) @binding(7) var<storage, read_write> out_dv: array<f32>;
@group(0) @binding(8) var<storage, read_write> out_indices: array<u32>;
// Tessellation: per class and grid sample, per control point, the weights of position,
// ∂s and ∂t (the same for every patch of a class, computed once per rate).
@group(0) @binding(9) var<storage, read> grid_weights: array<Real>;

const CLASS_WORDS: u32 = 22u;

fn recip_or_one(x: Real) -> Real {
    if (x <= Real(0.0)) {
        return Real(1.0);
    }
    return Real(1.0) / x;
}

// A Gregory triangle corner's share for its point paired with x (x / (x + y)), `first`
// saying whether that is the Fp point (1 where x + y is 0) or the Fm point (0 there).
fn triangle_share(x: Real, y: Real, first: bool) -> Real {
    if (x + y > Real(0.0)) {
        return x / (x + y);
    }
    return select(Real(0.0), Real(1.0), first);
}

// Blend codes: 0 one; 1 + c the Gregory quad's Fp share of corner c, 5 + c its Fm share;
// 9 + c the Gregory triangle's Fp share, 12 + c its Fm share.
fn blend(code: u32, s: Real, t: Real) -> Real {
    if (code == 0u) {
        return Real(1.0);
    }
    if (code < 9u) {
        let c = (code - 1u) % 4u;
        var fp: Real;
        switch c {
            case 0u: { fp = s * recip_or_one(s + t); }
            case 1u: { fp = t * recip_or_one((Real(1.0) - s) + t); }
            case 2u: { fp = (Real(1.0) - s) * recip_or_one((Real(1.0) - s) + (Real(1.0) - t)); }
            default: { fp = (Real(1.0) - t) * recip_or_one(s + (Real(1.0) - t)); }
        }
        return select(Real(1.0) - fp, fp, code < 5u);
    }
    let fp = code < 12u;
    let c = select(code - 12u, code - 9u, fp);
    let w = Real(1.0) - s - t;
    switch c {
        case 0u: { return triangle_share(select(t, s, fp), select(s, t, fp), fp); }
        case 1u: { return triangle_share(select(w, t, fp), select(t, w, fp), fp); }
        default: { return triangle_share(select(s, w, fp), select(w, s, fp), fp); }
    }
}

struct Sample {
    position: vec3<Real>,
    ds: vec3<Real>,
    dt: vec3<Real>,
}

fn point(i: u32) -> vec3<Real> {
    return vec3<Real>(Real(points[3u * i]), Real(points[3u * i + 1u]), Real(points[3u * i + 2u]));
}

// Patch `p` at (s, t) of its own domain, derivatives with respect to s and t.
fn evaluate_patch(p: u32, s: Real, t: Real) -> Sample {
    let first = words[4u * p];
    let basis = words[4u * p + 1u];
    let basis_at = params.classes_base + basis * CLASS_WORDS;
    let n = words[basis_at];
    let triangle = words[basis_at + 1u] != 0u;
    var sp: array<Real, 5>;
    var tp: array<Real, 5>;
    sp[0] = Real(1.0);
    tp[0] = Real(1.0);
    for (var i = 1u; i < 5u; i++) {
        sp[i] = sp[i - 1u] * s;
        tp[i] = tp[i - 1u] * t;
    }
    // Quads use sⁱ tʲ with i, j ≤ 3; triangles all of degree ≤ 4 (the other slots are 0).
    let top = select(4u, 5u, triangle);
    var out = Sample(vec3<Real>(Real(0.0)), vec3<Real>(Real(0.0)), vec3<Real>(Real(0.0)));
    for (var k = 0u; k < n; k++) {
        let c0 = (basis * 20u + k) * 25u;
        var value = Real(0.0);
        var ds = Real(0.0);
        var dt = Real(0.0);
        for (var j = 0u; j < top; j++) {
            // Σ_i c sⁱ and its s-derivative along row j.
            var row = Real(0.0);
            var row_ds = Real(0.0);
            for (var i = 0u; i < top; i++) {
                let c = coefficients[c0 + i + 5u * j];
                row += c * sp[i];
                if (i > 0u) {
                    row_ds += c * Real(i) * sp[i - 1u];
                }
            }
            value += row * tp[j];
            ds += row_ds * tp[j];
            if (j > 0u) {
                dt += row * Real(j) * tp[j - 1u];
            }
        }
        let b = blend(words[basis_at + 2u + k], s, t);
        let x = point(words[params.cps_base + first + k]);
        out.position += (b * value) * x;
        out.ds += (b * ds) * x;
        out.dt += (b * dt) * x;
    }
    return out;
}

fn is_triangle(p: u32) -> bool {
    let basis = words[4u * p + 1u];
    return words[params.classes_base + basis * CLASS_WORDS + 1u] != 0u;
}

// Whether a triangle patch is turned half a turn in its root's domain.
fn is_rotated(field1: u32) -> bool {
    let depth = field1 & 15u;
    let pu = (field1 >> 22u) & 1023u;
    let pv = (field1 >> 12u) & 1023u;
    return pu + pv >= (1u << depth);
}

// 1 / the fraction of its root a patch spans: 2^(depth − non-quad).
fn inverse_fraction(field1: u32) -> Real {
    let depth = field1 & 15u;
    let non_quad = (field1 >> 4u) & 1u;
    return Real(1u << (depth - non_quad));
}

fn store(row: u32, value: Sample, scale: Real) {
    let d = 3u * row;
    for (var c = 0u; c < 3u; c++) {
        out_position[d + c] = f32(value.position[c]);
        out_du[d + c] = f32(value.ds[c] * scale);
        out_dv[d + c] = f32(value.dt[c] * scale);
    }
}

fn invocation(id: vec3<u32>) -> u32 {
    return id.x + id.y * params.rows_per_line;
}

// Query q: patch, then u and v of its root face (f32 bits).
@compute @workgroup_size(64)
fn evaluate(@builtin(global_invocation_id) id: vec3<u32>) {
    let q = invocation(id);
    if (q >= params.count) {
        return;
    }
    let p = coords[3u * q];
    let u = Real(bitcast<f32>(coords[3u * q + 1u]));
    let v = Real(bitcast<f32>(coords[3u * q + 2u]));
    let field1 = words[4u * p + 3u];
    let inv = inverse_fraction(field1);
    let pu = Real((field1 >> 22u) & 1023u);
    let pv = Real((field1 >> 12u) & 1023u);
    if (is_triangle(p) && is_rotated(field1)) {
        // A turned triangle's coordinates run backwards (OpenSubdiv's NormalizeTriangle).
        let side = Real(1u << (field1 & 15u));
        let value = evaluate_patch(p, (side - pu) - u * side, (side - pv) - v * side);
        store(q, value, -inv);
        return;
    }
    store(q, evaluate_patch(p, u * inv - pu, v * inv - pv), inv);
}

// Sample x + (rate + 1) y of each patch's grid: (x, y) / rate of its own domain, points
// past a triangle's hypotenuse folded onto it; the basis there is `grid_weights`'.
@compute @workgroup_size(64)
fn tessellate(@builtin(global_invocation_id) id: vec3<u32>) {
    let q = invocation(id);
    if (q >= params.count) {
        return;
    }
    let side = params.rate + 1u;
    let p = q / (side * side);
    let r = q % (side * side);
    let first = words[4u * p];
    let basis = words[4u * p + 1u];
    let n = words[params.classes_base + basis * CLASS_WORDS];
    let at = (basis * side * side + r) * 60u;
    var out = Sample(vec3<Real>(Real(0.0)), vec3<Real>(Real(0.0)), vec3<Real>(Real(0.0)));
    for (var k = 0u; k < n; k++) {
        let x = point(words[params.cps_base + first + k]);
        out.position += grid_weights[at + 3u * k] * x;
        out.ds += grid_weights[at + 3u * k + 1u] * x;
        out.dt += grid_weights[at + 3u * k + 2u] * x;
    }
    let field1 = words[4u * p + 3u];
    let inv = inverse_fraction(field1);
    store(q, out, select(inv, -inv, is_triangle(p) && is_rotated(field1)));
}

// Cell (x, y) of each patch's grid: a quad cell's two triangles (a, b, c), (a, c, d) of
// its corners (x, y), (x + 1, y), (x + 1, y + 1), (x, y + 1); a triangle patch's cells
// below its hypotenuse give (x, y), (x + 1, y), (x, y + 1) and, where it fits,
// (x + 1, y), (x + 1, y + 1), (x, y + 1), rate² triangles per patch in row order.
@compute @workgroup_size(64)
fn grid_indices(@builtin(global_invocation_id) id: vec3<u32>) {
    let q = invocation(id);
    if (q >= params.count) {
        return;
    }
    let rate = params.rate;
    let p = q / (rate * rate);
    let x = (q % (rate * rate)) % rate;
    let y = (q % (rate * rate)) / rate;
    let side = rate + 1u;
    let first = p * side * side;
    let a = first + y * side + x;
    let b = a + 1u;
    let c = a + side + 1u;
    let d = a + side;
    if (!is_triangle(p)) {
        let o = 6u * q;
        out_indices[o] = a;
        out_indices[o + 1u] = b;
        out_indices[o + 2u] = c;
        out_indices[o + 3u] = a;
        out_indices[o + 4u] = c;
        out_indices[o + 5u] = d;
        return;
    }
    // Triangles before row y: the sum over rows y' < y of 2 (rate − y') − 1.
    let before = p * rate * rate + 2u * rate * y - y * y + 2u * x;
    if (x + y < rate) {
        out_indices[3u * before] = a;
        out_indices[3u * before + 1u] = b;
        out_indices[3u * before + 2u] = d;
    }
    if (x + y + 1u < rate) {
        out_indices[3u * before + 3u] = b;
        out_indices[3u * before + 4u] = c;
        out_indices[3u * before + 5u] = d;
    }
}
