// One level of uniform Catmull-Clark or Loop refinement on the device: the child level's
// topology (face vertices, face edges, edge vertices, numbered as subd-schemes and
// OpenSubdiv number them) of any mesh, and the points of a manifold one whose sharpness is
// all or nothing: boundaries and infinitely sharp creases and corners (OpenSubdiv's crease
// and corner masks), smooth elsewhere.
//
// A face corner is a halfedge: corner h of face f runs from its vertex to the face's next
// vertex along edge face_edges[h]. `corners` and `twins` find, per edge, its corners (two
// inside, running opposite ways; one on a boundary) and, per corner, the other corner of
// its edge; a vertex's ring is then walked corner to corner, next(twin(h)), without
// vertex-face lists, from the corner that arrives by a boundary edge where there is one.
//
// Vertex rules: 0 smooth (and dart), 1 crease, 2 corner. With infinite sharpness they
// pass to the children unchanged: a vertex's child keeps its rule, an edge's child is a
// crease when the edge is sharp, a face's child is smooth.
//
// `Real` (f64 or f32) is defined by the Rust side in front of this text.

struct Params {
    // Parent counts: vertices, faces, edges, face corners.
    nv: u32,
    nf: u32,
    ne: u32,
    nh: u32,
    // Vertices per face where all faces have as many (0: read face_offsets, corner_info).
    face_size: u32,
    // 0 Catmull-Clark, 1 Loop.
    scheme: u32,
    // Invocations, and invocations per line of the dispatch grid.
    count: u32,
    rows_per_line: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> face_offsets: array<u32>;
// Per corner its face, then its face's next corner, then its previous (level 0 only).
@group(0) @binding(2) var<storage, read> corner_info: array<u32>;
@group(0) @binding(3) var<storage, read> face_vertices: array<u32>;
@group(0) @binding(4) var<storage, read> face_edges: array<u32>;
@group(0) @binding(5) var<storage, read> edge_vertices: array<u32>;
@group(0) @binding(6) var<storage, read_write> edge_corners: array<u32>;
@group(0) @binding(7) var<storage, read_write> vertex_corner: array<atomic<u32>>;
@group(0) @binding(8) var<storage, read_write> twin: array<u32>;
@group(0) @binding(9) var<storage, read> points: array<f32>;
@group(0) @binding(10) var<storage, read_write> child_face_vertices: array<u32>;
@group(0) @binding(11) var<storage, read_write> child_face_edges: array<u32>;
@group(0) @binding(12) var<storage, read_write> child_edge_vertices: array<u32>;
@group(0) @binding(13) var<storage, read_write> child_points: array<f32>;
// Loop's smooth vertex weights per valence: (neighbour weight, own weight).
@group(0) @binding(14) var<storage, read> loop_weights: array<Real>;
@group(0) @binding(15) var<storage, read> twin_in: array<u32>;
@group(0) @binding(16) var<storage, read> edge_corners_in: array<u32>;
@group(0) @binding(17) var<storage, read> vertex_corner_in: array<u32>;
// Per edge 1 where it is (infinitely) sharp; per vertex its rule.
@group(0) @binding(18) var<storage, read> edge_sharp: array<u32>;
@group(0) @binding(19) var<storage, read_write> child_edge_sharp: array<u32>;
@group(0) @binding(20) var<storage, read> vertex_rules: array<u32>;
@group(0) @binding(21) var<storage, read_write> child_vertex_rules: array<u32>;

// A level's quads as triangles (a, b, c), (a, c, d), for drawing.
@group(0) @binding(22) var<storage, read_write> triangles: array<u32>;

// No corner: a twin across a boundary edge.
const NONE: u32 = 0x7fffffffu;
// A twin's flag: the corner's own edge is sharp. A vertex corner's flag: it arrives by a
// boundary edge.
const FLAG: u32 = 0x80000000u;

fn invocation(id: vec3<u32>) -> u32 {
    return id.x + id.y * params.rows_per_line;
}

fn face_of(h: u32) -> u32 {
    if (params.face_size != 0u) {
        return h / params.face_size;
    }
    return corner_info[h];
}

fn next_of(h: u32) -> u32 {
    if (params.face_size != 0u) {
        let s = params.face_size;
        return h - h % s + (h % s + 1u) % s;
    }
    return corner_info[params.nh + h];
}

fn prev_of(h: u32) -> u32 {
    if (params.face_size != 0u) {
        let s = params.face_size;
        return h - h % s + (h % s + s - 1u) % s;
    }
    return corner_info[2u * params.nh + h];
}

fn point(i: u32) -> vec3<Real> {
    return vec3<Real>(Real(points[3u * i]), Real(points[3u * i + 1u]), Real(points[3u * i + 2u]));
}

fn child_point(i: u32) -> vec3<Real> {
    return vec3<Real>(
        Real(child_points[3u * i]),
        Real(child_points[3u * i + 1u]),
        Real(child_points[3u * i + 2u]),
    );
}

fn store_child(i: u32, p: vec3<Real>) {
    child_points[3u * i] = f32(p.x);
    child_points[3u * i + 1u] = f32(p.y);
    child_points[3u * i + 2u] = f32(p.z);
}

// Which end (0, 1) of edge e is vertex v (the point walks have no degenerate edges).
fn end_at(e: u32, v: u32) -> u32 {
    return select(1u, 0u, edge_vertices[2u * e] == v);
}

// Which end of edge e a face corner at vertex v uses, the corner `leaving` along e or
// arriving by it: for a degenerate edge (both ends v) the leaving side takes end 0 and the
// arriving side end 1, as subd-schemes numbers them.
fn corner_end(e: u32, v: u32, leaving: bool) -> u32 {
    if (edge_vertices[2u * e] == edge_vertices[2u * e + 1u]) {
        return select(1u, 0u, leaving);
    }
    return end_at(e, v);
}

// Per corner: its edge's slot for it (by the end it starts at), as h + 1 (0: no corner;
// the slots are cleared before each run).
@compute @workgroup_size(64)
fn corners(@builtin(global_invocation_id) id: vec3<u32>) {
    let h = invocation(id);
    if (h >= params.nh) {
        return;
    }
    let e = face_edges[h];
    edge_corners[2u * e + end_at(e, face_vertices[h])] = h + 1u;
}

// Whether edge e has a corner in only one face.
fn is_boundary(e: u32) -> bool {
    return edge_corners_in[2u * e] == 0u || edge_corners_in[2u * e + 1u] == 0u;
}

// Per corner its twin (NONE across a boundary), flagged where its edge is sharp; and its
// vertex's first corner: one arriving by a boundary edge where there is one, else the
// largest (every run picks the same).
@compute @workgroup_size(64)
fn twins(@builtin(global_invocation_id) id: vec3<u32>) {
    let h = invocation(id);
    if (h >= params.nh) {
        return;
    }
    let e = face_edges[h];
    let v = face_vertices[h];
    let other = edge_corners_in[2u * e + 1u - end_at(e, v)];
    let t = select(other - 1u, NONE, other == 0u);
    twin[h] = t | select(0u, FLAG, edge_sharp[e] != 0u);
    let arriving = face_edges[prev_of(h)];
    atomicMax(&vertex_corner[v], h | select(0u, FLAG, is_boundary(arriving)));
}

// The halves of parent edges: H(e, k) = (E, V_k), after the face-interior child edges.
@compute @workgroup_size(64)
fn edge_halves(@builtin(global_invocation_id) id: vec3<u32>) {
    let e = invocation(id);
    if (e >= params.ne) {
        return;
    }
    var first: u32;
    var edge_point: u32;
    if (params.scheme == 0u) {
        first = params.nh;
        edge_point = params.nv + params.nf + e;
    } else {
        first = 3u * params.nf;
        edge_point = params.nv + e;
    }
    for (var k = 0u; k < 2u; k++) {
        child_edge_vertices[2u * (first + 2u * e + k)] = edge_point;
        child_edge_vertices[2u * (first + 2u * e + k) + 1u] = edge_vertices[2u * e + k];
        child_edge_sharp[first + 2u * e + k] = edge_sharp[e];
    }
}

fn face_range(f: u32) -> vec2<u32> {
    if (params.face_size != 0u) {
        return vec2<u32>(f * params.face_size, (f + 1u) * params.face_size);
    }
    return vec2<u32>(face_offsets[f], face_offsets[f + 1u]);
}

fn write_child_face(first_corner: u32, vertices: vec4<u32>, edges: vec4<u32>) {
    for (var k = 0u; k < 4u; k++) {
        child_face_vertices[first_corner + k] = vertices[k];
        child_face_edges[first_corner + k] = edges[k];
    }
}

// Catmull-Clark's child faces of parent face f: a quad's child k is rotated so that the
// parent corner sits at position k, (V0, E0, F, E3), (E0, V1, E1, F), (F, E1, V2, E2),
// (E3, F, E2, V3); a face of another size gives (Vk, Ek, F, Ek-1). Child edges: the halves
// at the corners (a_k leaving corner k along edge k, b_k arriving along edge k - 1), the
// face-interior edges I_k = (F, E_k).
fn catmark_faces(f: u32) {
    let range = face_range(f);
    let n = range.y - range.x;
    // The first child (face, and interior edge) of f: its first corner at level 0 (the
    // children of a face are numbered by its corners), else 4 f.
    let base = range.x;
    let hb = params.nh;
    let fp = params.nv + f;
    let ep0 = params.nv + params.nf;
    for (var k = 0u; k < n; k++) {
        let km1 = (k + n - 1u) % n;
        let v = face_vertices[base + k];
        let e = face_edges[base + k];
        let em1 = face_edges[base + km1];
        child_edge_vertices[2u * (base + k)] = fp;
        child_edge_vertices[2u * (base + k) + 1u] = ep0 + e;
        child_edge_sharp[base + k] = 0u;
        let a = hb + 2u * e + corner_end(e, v, true);
        let b = hb + 2u * em1 + corner_end(em1, v, false);
        let ik = base + k;
        let ikm1 = base + km1;
        let vs = vec4<u32>(v, ep0 + e, fp, ep0 + em1);
        let es = vec4<u32>(a, ik, ikm1, b);
        let corner = 4u * (base + k);
        if (n != 4u) {
            write_child_face(corner, vs, es);
            continue;
        }
        // Rotated by k: position (j + k) % 4 holds entry j.
        var rv: vec4<u32>;
        var re: vec4<u32>;
        for (var j = 0u; j < 4u; j++) {
            rv[(j + k) % 4u] = vs[j];
            re[(j + k) % 4u] = es[j];
        }
        write_child_face(corner, rv, re);
    }
}

// Loop's child triangles of parent triangle f: (V0, E0, E2), (E0, V1, E1), (E2, E1, V2),
// (E1, E2, E0); interior edges (E0, E2), (E1, E0), (E2, E1).
fn loop_faces(f: u32) {
    let hb = 3u * params.nf;
    var v: array<u32, 3>;
    var e: array<u32, 3>;
    var s: array<u32, 3>;
    var t: array<u32, 3>;
    for (var k = 0u; k < 3u; k++) {
        v[k] = face_vertices[3u * f + k];
        e[k] = face_edges[3u * f + k];
    }
    for (var k = 0u; k < 3u; k++) {
        // The half of edge k at its start corner, and at its end corner.
        s[k] = hb + 2u * e[k] + corner_end(e[k], v[k], true);
        t[k] = hb + 2u * e[k] + corner_end(e[k], v[(k + 1u) % 3u], false);
    }
    let nv = params.nv;
    let i = 3u * f;
    let fv = array<u32, 12>(
        v[0], nv + e[0], nv + e[2], nv + e[0], v[1], nv + e[1],
        nv + e[2], nv + e[1], v[2], nv + e[1], nv + e[2], nv + e[0],
    );
    let fe = array<u32, 12>(s[0], i, t[2], t[0], s[1], i + 1u, i + 2u, t[1], s[2], i + 2u, i, i + 1u);
    for (var k = 0u; k < 12u; k++) {
        child_face_vertices[12u * f + k] = fv[k];
        child_face_edges[12u * f + k] = fe[k];
    }
    let ends = array<u32, 6>(nv + e[0], nv + e[2], nv + e[1], nv + e[0], nv + e[2], nv + e[1]);
    for (var k = 0u; k < 6u; k++) {
        child_edge_vertices[6u * f + k] = ends[k];
    }
    for (var k = 0u; k < 3u; k++) {
        child_edge_sharp[3u * f + k] = 0u;
    }
}

@compute @workgroup_size(64)
fn child_faces(@builtin(global_invocation_id) id: vec3<u32>) {
    let f = invocation(id);
    if (f >= params.nf) {
        return;
    }
    if (params.scheme == 0u) {
        catmark_faces(f);
    } else {
        loop_faces(f);
    }
}

// Catmull-Clark's face points: the average of the face's vertices.
@compute @workgroup_size(64)
fn face_points(@builtin(global_invocation_id) id: vec3<u32>) {
    let f = invocation(id);
    if (f >= params.nf) {
        return;
    }
    let range = face_range(f);
    var sum = vec3<Real>(Real(0.0));
    for (var h = range.x; h < range.y; h++) {
        sum += point(face_vertices[h]);
    }
    store_child(params.nv + f, sum / Real(range.y - range.x));
}

// Edge points: a sharp edge's midpoint; else Catmull-Clark (V0 + V1 + F0 + F1) / 4 with
// the child face points, Loop 3/8 (V0 + V1) + 1/8 (the two opposite vertices).
@compute @workgroup_size(64)
fn edge_points(@builtin(global_invocation_id) id: vec3<u32>) {
    let e = invocation(id);
    if (e >= params.ne) {
        return;
    }
    let child = select(params.nv + e, params.nv + params.nf + e, params.scheme == 0u);
    let ends = point(edge_vertices[2u * e]) + point(edge_vertices[2u * e + 1u]);
    if (edge_sharp[e] != 0u) {
        store_child(child, Real(0.5) * ends);
        return;
    }
    let h0 = edge_corners_in[2u * e] - 1u;
    let h1 = edge_corners_in[2u * e + 1u] - 1u;
    if (params.scheme == 0u) {
        let faces = child_point(params.nv + face_of(h0)) + child_point(params.nv + face_of(h1));
        store_child(child, Real(0.25) * (ends + faces));
        return;
    }
    // The corner before h in its triangle holds the vertex opposite h's edge.
    let o0 = face_vertices[prev_of(h0)];
    let o1 = face_vertices[prev_of(h1)];
    store_child(child, Real(0.375) * ends + Real(0.125) * (point(o0) + point(o1)));
}

// Vertex points, the ring walked corner to corner: a corner stays; a crease is
// (E0 + 6 V + E1) / 8 over its two sharp edges' other ends; a smooth vertex is
// Catmull-Clark's ((n - 2) V + (Σ neighbours + Σ child face points) / n) / n or Loop's
// (1 - n β) V + β Σ neighbours.
@compute @workgroup_size(64)
fn vertex_points(@builtin(global_invocation_id) id: vec3<u32>) {
    let v = invocation(id);
    if (v >= params.nv) {
        return;
    }
    let own = point(v);
    let rule = vertex_rules[v];
    if (rule == 2u) {
        store_child(v, own);
        return;
    }
    let start = vertex_corner_in[v];
    let h0 = start & NONE;
    var h = h0;
    var n = 0u;
    var neighbours = vec3<Real>(Real(0.0));
    var sharp = vec3<Real>(Real(0.0));
    var faces = vec3<Real>(Real(0.0));
    // A ring closes or ends at a boundary; the bound only keeps a broken input from hanging.
    loop {
        let across = twin_in[h];
        let x = point(face_vertices[next_of(h)]);
        neighbours += x;
        if ((across & FLAG) != 0u) {
            sharp += x;
        }
        if (params.scheme == 0u) {
            faces += child_point(params.nv + face_of(h));
        }
        n++;
        if ((across & NONE) == NONE || n >= 65536u) {
            // A boundary vertex: the edge its first corner arrives by is sharp too.
            sharp += point(face_vertices[prev_of(h0)]);
            break;
        }
        h = next_of(across & NONE);
        if (h == h0) {
            break;
        }
    }
    if (rule == 1u) {
        store_child(v, Real(0.125) * sharp + Real(0.75) * own);
        return;
    }
    if (params.scheme == 0u) {
        let rn = Real(1.0) / Real(n);
        store_child(v, (Real(n) - Real(2.0)) * rn * own + rn * rn * (neighbours + faces));
        return;
    }
    let beta = loop_weights[2u * n];
    let centre = loop_weights[2u * n + 1u];
    store_child(v, centre * own + beta * neighbours);
}

// The rules of the child level: a vertex's child keeps its rule, an edge's child is a
// crease where the edge is sharp, a face's child is smooth.
@compute @workgroup_size(64)
fn child_rules(@builtin(global_invocation_id) id: vec3<u32>) {
    let c = invocation(id);
    if (c >= params.count) {
        return;
    }
    if (c < params.nv) {
        child_vertex_rules[c] = vertex_rules[c];
        return;
    }
    let edges = select(params.nv, params.nv + params.nf, params.scheme == 0u);
    if (c < edges) {
        child_vertex_rules[c] = 0u;
        return;
    }
    child_vertex_rules[c] = select(0u, 1u, edge_sharp[c - edges] != 0u);
}

// Quad f of a level (`face_vertices`, `count` quads) as the triangles (a, b, c), (a, c, d).
@compute @workgroup_size(64)
fn quad_triangles(@builtin(global_invocation_id) id: vec3<u32>) {
    let f = invocation(id);
    if (f >= params.count) {
        return;
    }
    let a = face_vertices[4u * f];
    let b = face_vertices[4u * f + 1u];
    let c = face_vertices[4u * f + 2u];
    let d = face_vertices[4u * f + 3u];
    let out = array<u32, 6>(a, b, c, a, c, d);
    for (var k = 0u; k < 6u; k++) {
        triangles[6u * f + k] = out[k];
    }
}
