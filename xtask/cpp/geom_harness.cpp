// Reference harness: subdivide a mesh with the system CGAL (5.5, Subdivision_method_3) or
// OpenMesh (9.0, Tools/Subdivider/Uniform) so that subd's own schemes can be compared with them.
//
// Usage:
//   geom_harness LIBRARY SCHEME LEVELS IN.off OUT.off
//     LIBRARY  cgal | openmesh
//     SCHEME   sqrt3 | doo-sabin | loop | catmull-clark | modified-butterfly
//              cgal:     sqrt3, doo-sabin, loop, catmull-clark
//              openmesh: sqrt3, loop, catmull-clark, modified-butterfly
//     LEVELS   number of subdivision steps (>= 0), applied in ONE library call
//              (this matters for sqrt3: both libraries apply the boundary rule only on the
//              2nd, 4th, ... step of a single call).
//
//   geom_harness bench LIBRARY SCHEME LEVELS IN.off REPEATS
//     Benchmark mode (REPEATS >= 1). IN.off is read once into flat arrays (positions, face sizes,
//     face indices) and validated exactly as in the normal mode. Then, REPEATS times:
//       (a) build a fresh library mesh from those in-memory arrays (timed; the analogue of
//           building a topology from face lists: add_vertex / add_face, nothing reserved),
//       then the library's own validity check of the normal mode (not timed),
//       (b) the same subdivision call as the normal mode, LEVELS steps in one call (timed; for
//           OpenMesh this includes constructing the subdivider and sizing its weight table),
//       (c) destroy the mesh (not timed).
//     Nothing is written; exactly one JSON line goes to stdout:
//       {"seconds": S, "build_seconds": B, "subdivide_seconds": D, "peak_rss_bytes": R,
//        "vertices": V, "faces": F}
//     S is the median over the repeats of (a)+(b), B the median of (a), D the median of (b)
//     (std::chrono::steady_clock; an even count takes the mean of the two middle values), R is
//     VmHWM from /proc/self/status read at the end (null if unavailable), V and F the vertex and
//     face counts of the result (as the normal mode would write them). Exit codes as below.
//
// Build (header-only CGAL with Simple_cartesian<double> needs neither GMP nor MPFR; OpenMesh's
// subdividers are header templates and only need libOpenMeshCore; -frounding-math is what CGAL
// asks for and costs nothing here; asserts are left on on purpose so that misuse aborts loudly):
//   mkdir -p target/xtask
//   g++ -O2 -std=c++17 -frounding-math -o target/xtask/geom_harness xtask/cpp/geom_harness.cpp -lOpenMeshCore
//   (about 12-13 s wall on one core, ~800 MB peak memory, g++ 12.2; -lOpenMeshTools, -lgmp and
//   -lmpfr are not needed; adding them is harmless)
//
// Input and output are ASCII OFF. The reader here parses coordinates with strtod (full double
// precision; '#' comments, optional per-face colour columns after the indices are ignored); the
// writer prints coordinates with %.17g, so a round trip is exact. Output vertices and faces come in
// the library's own iteration order (removed/garbage elements skipped, indices compacted).
//
// Exit status: 0 success; 3 unsupported LIBRARY/SCHEME combination or an input that is rejected
// (by the library, or by the harness's own checks below, which reject what the libraries would
// silently mishandle or assert on: faces with < 3 or repeated vertices, non-triangles for
// sqrt3/loop/butterfly, an edge used by more than two faces or twice in the same direction
// (non-manifold or inconsistently oriented), a vertex whose faces do not form a single fan,
// unreferenced vertices, and for the triangle schemes an interior vertex of valence < 3);
// one line is printed to stderr. 2: usage, I/O or OFF syntax error.
//
// Debug knobs (environment variables, not part of the interface; they apply to both modes):
//   GEOM_HARNESS_PER_LEVEL=1       call the library LEVELS times with one step each instead.
//   GEOM_HARNESS_OM_RAW_TABLES=1   do not enlarge OpenMesh's LoopT / Sqrt3T weight tables (which
//                                  have entries for valences 0..49 only; a higher interior
//                                  valence then reads past the end of a std::vector).
//
// This file uses only the libraries' public APIs.

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/subdivision_method_3.h>

#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/CatmullClarkT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/ModifiedButterFlyT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/Sqrt3T.hh>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

namespace {

// A polygon mesh as flat arrays: xyz holds 3 coordinates per vertex; face k has face_size[k]
// vertex indices, stored consecutively in face_idx (faces in order).
struct Mesh {
    std::vector<double> xyz;
    std::vector<size_t> face_size;
    std::vector<long> face_idx;

    size_t num_vertices() const { return xyz.size() / 3; }
    size_t num_faces() const { return face_size.size(); }
    void add_vertex(double x, double y, double z) {
        xyz.push_back(x);
        xyz.push_back(y);
        xyz.push_back(z);
    }
    // Calls fn(face number, pointer to its first index, its size) for every face in order.
    template <class F> void for_each_face(F fn) const {
        size_t off = 0;
        for (size_t fi = 0; fi < face_size.size(); ++fi) {
            fn(fi, face_idx.data() + off, face_size[fi]);
            off += face_size[fi];
        }
    }
};

// Exit helpers -------------------------------------------------------------------------------

[[noreturn]] void fail(int code, const std::string& msg) {
    std::fprintf(stderr, "geom_harness: %s\n", msg.c_str());
    std::exit(code);
}
[[noreturn]] void reject(const std::string& msg) { fail(3, msg); }

// OFF I/O --------------------------------------------------------------------------------------

// Splits the file into non-empty, comment-stripped lines.
std::vector<std::string> off_lines(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(2, "cannot open " + path);
    std::vector<std::string> lines;
    std::string line;
    while (std::getline(in, line)) {
        size_t hash = line.find('#');
        if (hash != std::string::npos) line.erase(hash);
        size_t a = line.find_first_not_of(" \t\r\n");
        if (a == std::string::npos) continue;
        size_t b = line.find_last_not_of(" \t\r\n");
        lines.push_back(line.substr(a, b - a + 1));
    }
    return lines;
}

std::vector<std::string> tokens(const std::string& s) {
    std::vector<std::string> t;
    std::istringstream is(s);
    std::string w;
    while (is >> w) t.push_back(w);
    return t;
}

double parse_double(const std::string& s, const std::string& what) {
    errno = 0;
    char* end = nullptr;
    double v = std::strtod(s.c_str(), &end);
    if (end == s.c_str() || *end != '\0' || errno == ERANGE) fail(2, "bad number '" + s + "' in " + what);
    return v;
}

long parse_long(const std::string& s, const std::string& what) {
    errno = 0;
    char* end = nullptr;
    long v = std::strtol(s.c_str(), &end, 10);
    if (end == s.c_str() || *end != '\0' || errno == ERANGE) fail(2, "bad integer '" + s + "' in " + what);
    return v;
}

Mesh read_off(const std::string& path) {
    std::vector<std::string> lines = off_lines(path);
    if (lines.empty()) fail(2, path + ": empty file");
    // Header: "OFF" alone, or "OFF nv nf ne" on one line.
    std::vector<std::string> head = tokens(lines[0]);
    size_t li = 1;
    if (head.empty() || head[0] != "OFF") fail(2, path + ": not an ASCII OFF file (header '" + lines[0] + "')");
    std::vector<std::string> counts(head.begin() + 1, head.end());
    if (counts.empty()) {
        if (li >= lines.size()) fail(2, path + ": missing counts");
        counts = tokens(lines[li++]);
    }
    if (counts.size() < 2) fail(2, path + ": bad counts line");
    long nv = parse_long(counts[0], "vertex count"), nf = parse_long(counts[1], "face count");
    if (nv < 0 || nf < 0) fail(2, path + ": negative counts");
    Mesh m;
    m.xyz.reserve(3 * (size_t)nv);
    for (long i = 0; i < nv; ++i) {
        if (li >= lines.size()) fail(2, path + ": truncated vertex list");
        std::vector<std::string> t = tokens(lines[li++]);
        if (t.size() < 3) fail(2, path + ": vertex line with < 3 coordinates");
        double x = parse_double(t[0], "vertex"), y = parse_double(t[1], "vertex"), z = parse_double(t[2], "vertex");
        m.add_vertex(x, y, z);
    }
    m.face_size.reserve(nf);
    for (long i = 0; i < nf; ++i) {
        if (li >= lines.size()) fail(2, path + ": truncated face list");
        std::vector<std::string> t = tokens(lines[li++]);
        if (t.empty()) fail(2, path + ": empty face line");
        long n = parse_long(t[0], "face size");
        if (n < 0 || (long)t.size() < n + 1) fail(2, path + ": face line shorter than its size");
        for (long k = 0; k < n; ++k) {
            long v = parse_long(t[k + 1], "face index");
            if (v < 0 || v >= nv) fail(2, path + ": face index out of range");
            m.face_idx.push_back(v);
        }
        m.face_size.push_back((size_t)n);  // extra columns (colours) ignored
    }
    return m;
}

void write_off(const std::string& path, const Mesh& m) {
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) fail(2, "cannot create " + path);
    std::fprintf(f, "OFF\n%zu %zu 0\n", m.num_vertices(), m.num_faces());
    for (size_t v = 0; v < m.num_vertices(); ++v)
        std::fprintf(f, "%.17g %.17g %.17g\n", m.xyz[3 * v], m.xyz[3 * v + 1], m.xyz[3 * v + 2]);
    m.for_each_face([&](size_t, const long* fc, size_t n) {
        std::fprintf(f, "%zu", n);
        for (size_t k = 0; k < n; ++k) std::fprintf(f, " %ld", fc[k]);
        std::fprintf(f, "\n");
    });
    if (std::fclose(f) != 0) fail(2, "error writing " + path);
}

// Combinatorial checks ------------------------------------------------------------------------

// Rejects inputs whose behaviour in the libraries is undefined or silently wrong.
void validate(const Mesh& m, bool triangles_only) {
    const size_t nv = m.num_vertices();
    std::vector<int> used(nv, 0);
    // directed edge (a,b) -> count; also per vertex the list of (prev, next) around each corner
    std::map<std::pair<long, long>, int> dir;
    m.for_each_face([&](size_t fi, const long* f, size_t n) {
        if (n < 3) reject("face " + std::to_string(fi) + " has fewer than 3 vertices");
        if (triangles_only && n != 3)
            reject("face " + std::to_string(fi) + " is not a triangle (scheme needs a triangle mesh)");
        std::vector<long> s(f, f + n);
        std::sort(s.begin(), s.end());
        if (std::adjacent_find(s.begin(), s.end()) != s.end())
            reject("face " + std::to_string(fi) + " repeats a vertex");
        for (size_t k = 0; k < n; ++k) {
            long a = f[k], b = f[(k + 1) % n];
            used[a] = 1;
            if (++dir[{a, b}] > 1) reject("edge used twice in the same direction (non-manifold or inconsistent orientation)");
        }
    });
    for (size_t v = 0; v < nv; ++v)
        if (!used[v]) reject("unreferenced vertex " + std::to_string(v));
    // Vertex manifoldness: around v, each face corner maps "in" neighbour -> "out" neighbour
    // (prev -> next). The corners must chain into one cycle (interior) or one path (boundary).
    std::vector<std::vector<std::pair<long, long>>> corners(nv);
    m.for_each_face([&](size_t, const long* f, size_t n) {
        for (size_t k = 0; k < n; ++k) corners[f[k]].push_back({f[(k + n - 1) % n], f[(k + 1) % n]});
    });
    for (size_t v = 0; v < nv; ++v) {
        // Corner c maps next(c) -> prev(c'), where c' is the corner across edge (v, next(c)),
        // i.e. the corner whose prev equals next(c).
        std::unordered_map<long, size_t> by_prev;
        for (size_t c = 0; c < corners[v].size(); ++c) by_prev[corners[v][c].first] = c;
        // Find a start: a corner whose prev neighbour is not any corner's next (boundary start).
        std::unordered_map<long, int> nexts;
        for (const auto& c : corners[v]) nexts[c.second]++;
        size_t start = 0;
        int starts = 0;
        for (size_t c = 0; c < corners[v].size(); ++c)
            if (!nexts.count(corners[v][c].first)) { start = c; ++starts; }
        if (starts > 1) reject("non-manifold vertex " + std::to_string(v) + " (several boundary fans)");
        size_t visited = 0, c = start;
        std::vector<char> seen(corners[v].size(), 0);
        while (!seen[c]) {
            seen[c] = 1;
            ++visited;
            auto it = by_prev.find(corners[v][c].second);
            if (it == by_prev.end()) break;
            c = it->second;
        }
        if (visited != corners[v].size())
            reject("non-manifold vertex " + std::to_string(v) + " (faces do not form one fan)");
        // In a triangle mesh an interior vertex of valence < 3 means two triangles sharing two
        // edges; OpenMesh's Sqrt3T (flip) and ModifiedButterflyT assert on it. (In polygon meshes
        // an interior valence-2 vertex is legitimate and kept for catmull-clark / doo-sabin.)
        if (triangles_only && starts == 0 && corners[v].size() < 3)
            reject("degenerate triangle mesh: interior vertex " + std::to_string(v) + " has valence < 3");
    }
}

bool env_flag(const char* name) {
    const char* s = std::getenv(name);
    return s && *s && std::strcmp(s, "0") != 0;
}

// Engines ------------------------------------------------------------------------------------

// One library mesh type plus one scheme's subdivision call. Both modes drive an engine through
// the same steps: build, check, subdivide, then extract (normal mode) or count (bench mode).
class Engine {
public:
    virtual ~Engine() = default;
    // Builds a fresh library mesh from the arrays (replacing any previous one); rejects a face
    // that the library's add_face refuses.
    virtual void build(const Mesh& in) = 0;
    // The library's own validity checks on the built mesh.
    virtual void check() = 0;
    // The scheme's subdivision with LEVELS steps in one call (or one call per step with
    // GEOM_HARNESS_PER_LEVEL).
    virtual void subdivide(unsigned levels) = 0;
    // The current mesh in the library's iteration order, indices compacted.
    virtual Mesh extract() const = 0;
    // Vertex and face counts of what extract() would return.
    virtual std::pair<size_t, size_t> counts() const = 0;
    // Frees the library mesh.
    virtual void destroy() = 0;
};

// Splits LEVELS into (number of library calls, steps per call).
std::pair<unsigned, unsigned> level_calls(unsigned levels) {
    const bool per_level = env_flag("GEOM_HARNESS_PER_LEVEL");
    return {per_level ? levels : (levels > 0 ? 1u : 0u), per_level ? 1u : levels};
}

// CGAL ---------------------------------------------------------------------------------------

typedef CGAL::Simple_cartesian<double> Kernel;
typedef Kernel::Point_3 CPoint;
typedef CGAL::Surface_mesh<CPoint> CMesh;

// Subdivides with `steps` iterations in one call.
typedef void (*CgalStep)(CMesh&, unsigned steps);

class CgalEngine : public Engine {
public:
    explicit CgalEngine(CgalStep step) : step_(step) {}

    void build(const Mesh& in) override {
        sm_.reset(new CMesh);
        CMesh& sm = *sm_;
        std::vector<CMesh::Vertex_index> vs;
        vs.reserve(in.num_vertices());
        for (size_t v = 0; v < in.num_vertices(); ++v)
            vs.push_back(sm.add_vertex(CPoint(in.xyz[3 * v], in.xyz[3 * v + 1], in.xyz[3 * v + 2])));
        std::vector<CMesh::Vertex_index> f;
        in.for_each_face([&](size_t fi, const long* fc, size_t n) {
            f.clear();
            for (size_t k = 0; k < n; ++k) f.push_back(vs[fc[k]]);
            if (sm.add_face(f) == CMesh::null_face()) reject("CGAL Surface_mesh::add_face rejected face " + std::to_string(fi));
        });
    }

    void check() override {
        if (!CGAL::is_valid_polygon_mesh(*sm_)) reject("CGAL: input is not a valid polygon mesh");
    }

    void subdivide(unsigned levels) override {
        const auto cs = level_calls(levels);
        for (unsigned c = 0; c < cs.first; ++c) step_(*sm_, cs.second);
    }

    Mesh extract() const override {
        const CMesh& sm = *sm_;
        Mesh out;
        std::unordered_map<CMesh::Vertex_index, long> idx;
        for (CMesh::Vertex_index v : sm.vertices()) {
            idx[v] = (long)out.num_vertices();
            const CPoint& p = sm.point(v);
            out.add_vertex(p.x(), p.y(), p.z());
        }
        for (CMesh::Face_index f : sm.faces()) {
            size_t n = 0;
            for (CMesh::Vertex_index v : CGAL::vertices_around_face(sm.halfedge(f), sm)) {
                out.face_idx.push_back(idx.at(v));
                ++n;
            }
            out.face_size.push_back(n);
        }
        return out;
    }

    std::pair<size_t, size_t> counts() const override {
        return {(size_t)sm_->number_of_vertices(), (size_t)sm_->number_of_faces()};
    }

    void destroy() override { sm_.reset(); }

private:
    CgalStep step_;
    std::unique_ptr<CMesh> sm_;
};

// Returns nullptr for a scheme CGAL does not have.
std::unique_ptr<Engine> make_cgal(const std::string& scheme) {
    namespace SM3 = CGAL::Subdivision_method_3;
    namespace P = CGAL::parameters;
    CgalStep step = nullptr;
    if (scheme == "sqrt3") step = [](CMesh& m, unsigned n) { SM3::Sqrt3_subdivision(m, P::number_of_iterations(n)); };
    else if (scheme == "doo-sabin") step = [](CMesh& m, unsigned n) { SM3::DooSabin_subdivision(m, P::number_of_iterations(n)); };
    else if (scheme == "loop") step = [](CMesh& m, unsigned n) { SM3::Loop_subdivision(m, P::number_of_iterations(n)); };
    else if (scheme == "catmull-clark") step = [](CMesh& m, unsigned n) { SM3::CatmullClark_subdivision(m, P::number_of_iterations(n)); };
    if (!step) return nullptr;
    return std::unique_ptr<Engine>(new CgalEngine(step));
}

// OpenMesh -----------------------------------------------------------------------------------

// Double precision throughout (the default traits use Vec3f points).
struct DoubleTraits : public OpenMesh::DefaultTraits {
    typedef OpenMesh::Vec3d Point;
    typedef OpenMesh::Vec3d Normal;
};
typedef OpenMesh::TriMesh_ArrayKernelT<DoubleTraits> OTriMesh;
typedef OpenMesh::PolyMesh_ArrayKernelT<DoubleTraits> OPolyMesh;

template <class M> unsigned om_max_valence(const M& mesh) {
    unsigned mv = 0;
    for (auto vh : mesh.vertices()) mv = std::max(mv, mesh.valence(vh));
    return mv;
}

// LoopT and Sqrt3T have weight tables for valences 0..49 and index them without a bounds check.
// Interior valences never grow during these schemes (new vertices have valence <= 6), so a table
// sized from the input is enough. Entries below 50 are the same whatever the table size.
template <class S> void om_enlarge_table(S& sub, unsigned max_valence) {
    if (env_flag("GEOM_HARNESS_OM_RAW_TABLES")) return;
    if (max_valence + 8 > 50) sub.init_weights(max_valence + 8);
}

// Subdivider S on mesh type M. With EnlargeTable the subdivider's weight table is sized from the
// mesh's maximal valence before the first step (see om_enlarge_table).
template <class M, class S, bool EnlargeTable> class OmEngine : public Engine {
public:
    void build(const Mesh& in) override {
        mesh_.reset(new M);
        M& mesh = *mesh_;
        std::vector<typename M::VertexHandle> vs;
        vs.reserve(in.num_vertices());
        for (size_t v = 0; v < in.num_vertices(); ++v)
            vs.push_back(mesh.add_vertex(typename M::Point(in.xyz[3 * v], in.xyz[3 * v + 1], in.xyz[3 * v + 2])));
        std::vector<typename M::VertexHandle> f;
        in.for_each_face([&](size_t fi, const long* fc, size_t n) {
            f.clear();
            for (size_t k = 0; k < n; ++k) f.push_back(vs[fc[k]]);
            if (!mesh.add_face(f).is_valid()) reject("OpenMesh add_face rejected face " + std::to_string(fi));
        });
    }

    void check() override {
        for (auto vh : mesh_->vertices())
            if (!mesh_->is_manifold(vh)) reject("OpenMesh: non-manifold vertex " + std::to_string(vh.idx()));
    }

    void subdivide(unsigned levels) override {
        M& mesh = *mesh_;
        S sub;
        if constexpr (EnlargeTable) om_enlarge_table(sub, om_max_valence(mesh));
        const auto cs = level_calls(levels);
        for (unsigned c = 0; c < cs.first; ++c)
            if (!sub(mesh, cs.second)) reject(std::string("OpenMesh ") + sub.name() + " failed");
    }

    Mesh extract() const override {
        const M& mesh = *mesh_;
        Mesh out;
        std::unordered_map<int, long> idx;
        for (auto vh : mesh.vertices()) {
            idx[vh.idx()] = (long)out.num_vertices();
            const auto& p = mesh.point(vh);
            out.add_vertex(p[0], p[1], p[2]);
        }
        for (auto fh : mesh.faces()) {
            size_t n = 0;
            for (auto vh : mesh.fv_range(fh)) {
                out.face_idx.push_back(idx.at(vh.idx()));
                ++n;
            }
            out.face_size.push_back(n);
        }
        return out;
    }

    std::pair<size_t, size_t> counts() const override {
        // The skipping ranges, as in extract() (deleted elements are not counted).
        const auto vr = mesh_->vertices();
        const auto fr = mesh_->faces();
        return {(size_t)std::distance(vr.begin(), vr.end()), (size_t)std::distance(fr.begin(), fr.end())};
    }

    void destroy() override { mesh_.reset(); }

private:
    std::unique_ptr<M> mesh_;
};

// Returns nullptr for a scheme OpenMesh does not have.
std::unique_ptr<Engine> make_openmesh(const std::string& scheme) {
    namespace U = OpenMesh::Subdivider::Uniform;
    if (scheme == "sqrt3") return std::unique_ptr<Engine>(new OmEngine<OTriMesh, U::Sqrt3T<OTriMesh, double>, true>);
    if (scheme == "loop") return std::unique_ptr<Engine>(new OmEngine<OTriMesh, U::LoopT<OTriMesh, double>, true>);
    // ModifiedButterflyT resizes its own table (default 30) when the input needs more.
    if (scheme == "modified-butterfly")
        return std::unique_ptr<Engine>(new OmEngine<OTriMesh, U::ModifiedButterflyT<OTriMesh, double>, false>);
    if (scheme == "catmull-clark")
        return std::unique_ptr<Engine>(new OmEngine<OPolyMesh, U::CatmullClarkT<OPolyMesh, double>, false>);
    return nullptr;
}

// The one place where LIBRARY and SCHEME are dispatched; rejects unsupported combinations.
std::unique_ptr<Engine> make_engine(const std::string& lib, const std::string& scheme) {
    std::unique_ptr<Engine> e;
    if (lib == "cgal") e = make_cgal(scheme);
    else if (lib == "openmesh") e = make_openmesh(scheme);
    else reject("unknown library '" + lib + "' (cgal | openmesh)");
    if (!e) reject("scheme '" + scheme + "' is not supported with " + lib);
    return e;
}

bool scheme_needs_triangles(const std::string& scheme) {
    return scheme == "sqrt3" || scheme == "loop" || scheme == "modified-butterfly";
}

// Runs fn(); an exception from the library (CGAL's failed assertions/preconditions throw by
// default) becomes a rejection.
template <class F> void guarded(const std::string& lib, F fn) {
    try {
        fn();
    } catch (const std::exception& e) {
        std::string w = e.what();
        std::replace(w.begin(), w.end(), '\n', ' ');
        reject(lib + " failed: " + w);
    }
}

unsigned parse_levels(const char* s) {
    const long lv = parse_long(s, "LEVELS");
    if (lv < 0 || lv > 64) fail(2, "LEVELS must be in 0..64");
    return (unsigned)lv;
}

// Bench mode ---------------------------------------------------------------------------------

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// VmHWM (peak resident set) in bytes, or -1 if it cannot be read.
long long peak_rss_bytes() {
    std::ifstream st("/proc/self/status");
    std::string line;
    while (std::getline(st, line)) {
        if (line.compare(0, 6, "VmHWM:") != 0) continue;
        std::istringstream is(line.substr(6));
        long long kb = -1;
        std::string unit;
        if (is >> kb >> unit && unit == "kB") return kb * 1024;
        return -1;
    }
    return -1;
}

int bench_main(int argc, char** argv) {
    if (argc != 7) fail(2, "usage: geom_harness bench cgal|openmesh SCHEME LEVELS IN.off REPEATS");
    const std::string lib = argv[2], scheme = argv[3];
    const unsigned levels = parse_levels(argv[4]);
    const long repeats = parse_long(argv[6], "REPEATS");
    if (repeats < 1 || repeats > 1000000) fail(2, "REPEATS must be in 1..1000000");

    std::unique_ptr<Engine> engine = make_engine(lib, scheme);
    Mesh in = read_off(argv[5]);
    validate(in, scheme_needs_triangles(scheme));

    typedef std::chrono::steady_clock Clock;
    std::vector<double> total, build, subdivide;
    std::pair<size_t, size_t> counts{0, 0};
    guarded(lib, [&] {
        for (long r = 0; r < repeats; ++r) {
            const Clock::time_point t0 = Clock::now();
            engine->build(in);
            const Clock::time_point t1 = Clock::now();
            engine->check();
            const Clock::time_point t2 = Clock::now();
            engine->subdivide(levels);
            const Clock::time_point t3 = Clock::now();
            counts = engine->counts();
            engine->destroy();
            const double b = std::chrono::duration<double>(t1 - t0).count();
            const double d = std::chrono::duration<double>(t3 - t2).count();
            build.push_back(b);
            subdivide.push_back(d);
            total.push_back(b + d);
        }
    });

    const long long rss = peak_rss_bytes();
    if (rss < 0) std::fprintf(stderr, "geom_harness: VmHWM not available in /proc/self/status\n");
    std::string rss_s = rss < 0 ? std::string("null") : std::to_string(rss);
    std::printf("{\"seconds\": %.9g, \"build_seconds\": %.9g, \"subdivide_seconds\": %.9g, "
                "\"peak_rss_bytes\": %s, \"vertices\": %zu, \"faces\": %zu}\n",
                median(total), median(build), median(subdivide), rss_s.c_str(), counts.first, counts.second);
    if (std::fflush(stdout) != 0) fail(2, "error writing stdout");
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc >= 2 && std::strcmp(argv[1], "bench") == 0) return bench_main(argc, argv);
    if (argc != 6) fail(2, "usage: geom_harness cgal|openmesh SCHEME LEVELS IN.off OUT.off");
    const std::string lib = argv[1], scheme = argv[2];
    const unsigned levels = parse_levels(argv[3]);

    std::unique_ptr<Engine> engine = make_engine(lib, scheme);
    Mesh in = read_off(argv[4]);
    validate(in, scheme_needs_triangles(scheme));

    Mesh out;
    guarded(lib, [&] {
        engine->build(in);
        engine->check();
        engine->subdivide(levels);
        out = engine->extract();
        engine->destroy();
    });
    write_off(argv[5], out);
    return 0;
}
