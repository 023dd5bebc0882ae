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
// Debug knobs (environment variables, not part of the interface):
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
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace {

struct Mesh {
    std::vector<std::array<double, 3>> pos;
    std::vector<std::vector<long>> faces;
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
    m.pos.reserve(nv);
    for (long i = 0; i < nv; ++i) {
        if (li >= lines.size()) fail(2, path + ": truncated vertex list");
        std::vector<std::string> t = tokens(lines[li++]);
        if (t.size() < 3) fail(2, path + ": vertex line with < 3 coordinates");
        m.pos.push_back({parse_double(t[0], "vertex"), parse_double(t[1], "vertex"),
                         parse_double(t[2], "vertex")});
    }
    m.faces.reserve(nf);
    for (long i = 0; i < nf; ++i) {
        if (li >= lines.size()) fail(2, path + ": truncated face list");
        std::vector<std::string> t = tokens(lines[li++]);
        if (t.empty()) fail(2, path + ": empty face line");
        long n = parse_long(t[0], "face size");
        if (n < 0 || (long)t.size() < n + 1) fail(2, path + ": face line shorter than its size");
        std::vector<long> f;
        for (long k = 0; k < n; ++k) {
            long v = parse_long(t[k + 1], "face index");
            if (v < 0 || v >= nv) fail(2, path + ": face index out of range");
            f.push_back(v);
        }
        m.faces.push_back(f);  // extra columns (colours) ignored
    }
    return m;
}

void write_off(const std::string& path, const Mesh& m) {
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) fail(2, "cannot create " + path);
    std::fprintf(f, "OFF\n%zu %zu 0\n", m.pos.size(), m.faces.size());
    for (const auto& p : m.pos) std::fprintf(f, "%.17g %.17g %.17g\n", p[0], p[1], p[2]);
    for (const auto& fc : m.faces) {
        std::fprintf(f, "%zu", fc.size());
        for (long v : fc) std::fprintf(f, " %ld", v);
        std::fprintf(f, "\n");
    }
    if (std::fclose(f) != 0) fail(2, "error writing " + path);
}

// Combinatorial checks ------------------------------------------------------------------------

// Rejects inputs whose behaviour in the libraries is undefined or silently wrong.
void validate(const Mesh& m, bool triangles_only) {
    const size_t nv = m.pos.size();
    std::vector<int> used(nv, 0);
    // directed edge (a,b) -> count; also per vertex the list of (prev, next) around each corner
    std::map<std::pair<long, long>, int> dir;
    for (size_t fi = 0; fi < m.faces.size(); ++fi) {
        const auto& f = m.faces[fi];
        if (f.size() < 3) reject("face " + std::to_string(fi) + " has fewer than 3 vertices");
        if (triangles_only && f.size() != 3)
            reject("face " + std::to_string(fi) + " is not a triangle (scheme needs a triangle mesh)");
        std::vector<long> s(f);
        std::sort(s.begin(), s.end());
        if (std::adjacent_find(s.begin(), s.end()) != s.end())
            reject("face " + std::to_string(fi) + " repeats a vertex");
        for (size_t k = 0; k < f.size(); ++k) {
            long a = f[k], b = f[(k + 1) % f.size()];
            used[a] = 1;
            if (++dir[{a, b}] > 1) reject("edge used twice in the same direction (non-manifold or inconsistent orientation)");
        }
    }
    for (size_t v = 0; v < nv; ++v)
        if (!used[v]) reject("unreferenced vertex " + std::to_string(v));
    // Vertex manifoldness: around v, each face corner maps "in" neighbour -> "out" neighbour
    // (prev -> next). The corners must chain into one cycle (interior) or one path (boundary).
    std::vector<std::vector<std::pair<long, long>>> corners(nv);
    for (const auto& f : m.faces)
        for (size_t k = 0; k < f.size(); ++k)
            corners[f[k]].push_back({f[(k + f.size() - 1) % f.size()], f[(k + 1) % f.size()]});
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

// CGAL ---------------------------------------------------------------------------------------

typedef CGAL::Simple_cartesian<double> Kernel;
typedef Kernel::Point_3 CPoint;
typedef CGAL::Surface_mesh<CPoint> CMesh;

Mesh run_cgal(const std::string& scheme, unsigned levels, const Mesh& in) {
    namespace SM3 = CGAL::Subdivision_method_3;
    CMesh sm;
    std::vector<CMesh::Vertex_index> vs;
    vs.reserve(in.pos.size());
    for (const auto& p : in.pos) vs.push_back(sm.add_vertex(CPoint(p[0], p[1], p[2])));
    for (size_t fi = 0; fi < in.faces.size(); ++fi) {
        std::vector<CMesh::Vertex_index> f;
        for (long v : in.faces[fi]) f.push_back(vs[v]);
        if (sm.add_face(f) == CMesh::null_face()) reject("CGAL Surface_mesh::add_face rejected face " + std::to_string(fi));
    }
    if (!CGAL::is_valid_polygon_mesh(sm)) reject("CGAL: input is not a valid polygon mesh");

    const bool per_level = env_flag("GEOM_HARNESS_PER_LEVEL");
    const unsigned calls = per_level ? levels : (levels > 0 ? 1 : 0);
    const unsigned steps = per_level ? 1 : levels;
    for (unsigned c = 0; c < calls; ++c) {
        auto np = CGAL::parameters::number_of_iterations(steps);
        if (scheme == "sqrt3") SM3::Sqrt3_subdivision(sm, np);
        else if (scheme == "doo-sabin") SM3::DooSabin_subdivision(sm, np);
        else if (scheme == "loop") SM3::Loop_subdivision(sm, np);
        else if (scheme == "catmull-clark") SM3::CatmullClark_subdivision(sm, np);
        else reject("scheme '" + scheme + "' is not supported with cgal");
    }

    Mesh out;
    std::unordered_map<CMesh::Vertex_index, long> idx;
    for (CMesh::Vertex_index v : sm.vertices()) {
        idx[v] = (long)out.pos.size();
        const CPoint& p = sm.point(v);
        out.pos.push_back({p.x(), p.y(), p.z()});
    }
    for (CMesh::Face_index f : sm.faces()) {
        std::vector<long> fc;
        for (CMesh::Vertex_index v : CGAL::vertices_around_face(sm.halfedge(f), sm)) fc.push_back(idx.at(v));
        out.faces.push_back(fc);
    }
    return out;
}

// OpenMesh -----------------------------------------------------------------------------------

// Double precision throughout (the default traits use Vec3f points).
struct DoubleTraits : public OpenMesh::DefaultTraits {
    typedef OpenMesh::Vec3d Point;
    typedef OpenMesh::Vec3d Normal;
};
typedef OpenMesh::TriMesh_ArrayKernelT<DoubleTraits> OTriMesh;
typedef OpenMesh::PolyMesh_ArrayKernelT<DoubleTraits> OPolyMesh;

template <class M> void om_build(M& mesh, const Mesh& in) {
    std::vector<typename M::VertexHandle> vs;
    vs.reserve(in.pos.size());
    for (const auto& p : in.pos) vs.push_back(mesh.add_vertex(typename M::Point(p[0], p[1], p[2])));
    for (size_t fi = 0; fi < in.faces.size(); ++fi) {
        std::vector<typename M::VertexHandle> f;
        for (long v : in.faces[fi]) f.push_back(vs[v]);
        if (!mesh.add_face(f).is_valid()) reject("OpenMesh add_face rejected face " + std::to_string(fi));
    }
    for (auto vh : mesh.vertices())
        if (!mesh.is_manifold(vh)) reject("OpenMesh: non-manifold vertex " + std::to_string(vh.idx()));
}

template <class M> Mesh om_extract(M& mesh) {
    Mesh out;
    std::unordered_map<int, long> idx;
    for (auto vh : mesh.vertices()) {
        idx[vh.idx()] = (long)out.pos.size();
        const auto& p = mesh.point(vh);
        out.pos.push_back({p[0], p[1], p[2]});
    }
    for (auto fh : mesh.faces()) {
        std::vector<long> fc;
        for (auto vh : mesh.fv_range(fh)) fc.push_back(idx.at(vh.idx()));
        out.faces.push_back(fc);
    }
    return out;
}

template <class M> unsigned om_max_valence(M& mesh) {
    unsigned mv = 0;
    for (auto vh : mesh.vertices()) mv = std::max(mv, mesh.valence(vh));
    return mv;
}

// Runs subdivider S on a fresh mesh of type M. `enlarge` is called with the subdivider and the
// input's maximal valence before the first step.
template <class M, class S, class Enlarge> Mesh om_run(const Mesh& in, unsigned levels, Enlarge enlarge) {
    M mesh;
    om_build(mesh, in);
    S sub;
    enlarge(sub, om_max_valence(mesh));
    const bool per_level = env_flag("GEOM_HARNESS_PER_LEVEL");
    if (per_level) {
        for (unsigned l = 0; l < levels; ++l)
            if (!sub(mesh, 1)) reject(std::string("OpenMesh ") + sub.name() + " failed");
    } else if (levels > 0) {
        if (!sub(mesh, levels)) reject(std::string("OpenMesh ") + sub.name() + " failed");
    }
    return om_extract(mesh);
}

// LoopT and Sqrt3T have weight tables for valences 0..49 and index them without a bounds check.
// Interior valences never grow during these schemes (new vertices have valence <= 6), so a table
// sized from the input is enough. Entries below 50 are the same whatever the table size.
template <class S> void om_enlarge_table(S& sub, unsigned max_valence) {
    if (env_flag("GEOM_HARNESS_OM_RAW_TABLES")) return;
    if (max_valence + 8 > 50) sub.init_weights(max_valence + 8);
}

Mesh run_openmesh(const std::string& scheme, unsigned levels, const Mesh& in) {
    namespace U = OpenMesh::Subdivider::Uniform;
    auto none = [](auto&, unsigned) {};
    auto table = [](auto& s, unsigned mv) { om_enlarge_table(s, mv); };
    if (scheme == "sqrt3") return om_run<OTriMesh, U::Sqrt3T<OTriMesh, double>>(in, levels, table);
    if (scheme == "loop") return om_run<OTriMesh, U::LoopT<OTriMesh, double>>(in, levels, table);
    // ModifiedButterflyT resizes its own table (default 30) when the input needs more.
    if (scheme == "modified-butterfly")
        return om_run<OTriMesh, U::ModifiedButterflyT<OTriMesh, double>>(in, levels, none);
    if (scheme == "catmull-clark") return om_run<OPolyMesh, U::CatmullClarkT<OPolyMesh, double>>(in, levels, none);
    reject("scheme '" + scheme + "' is not supported with openmesh");
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 6) fail(2, "usage: geom_harness cgal|openmesh SCHEME LEVELS IN.off OUT.off");
    const std::string lib = argv[1], scheme = argv[2];
    const long lv = parse_long(argv[3], "LEVELS");
    if (lv < 0 || lv > 64) fail(2, "LEVELS must be in 0..64");
    const unsigned levels = (unsigned)lv;

    const bool cgal_ok = scheme == "sqrt3" || scheme == "doo-sabin" || scheme == "loop" || scheme == "catmull-clark";
    const bool om_ok = scheme == "sqrt3" || scheme == "loop" || scheme == "catmull-clark" || scheme == "modified-butterfly";
    if (lib == "cgal") {
        if (!cgal_ok) reject("scheme '" + scheme + "' is not supported with cgal");
    } else if (lib == "openmesh") {
        if (!om_ok) reject("scheme '" + scheme + "' is not supported with openmesh");
    } else {
        reject("unknown library '" + lib + "' (cgal | openmesh)");
    }

    Mesh in = read_off(argv[4]);
    const bool tri = scheme == "sqrt3" || scheme == "loop" || scheme == "modified-butterfly";
    validate(in, tri);

    Mesh out;
    try {
        out = lib == "cgal" ? run_cgal(scheme, levels, in) : run_openmesh(scheme, levels, in);
    } catch (const std::exception& e) {
        // CGAL's failed assertions/preconditions throw by default.
        std::string w = e.what();
        std::replace(w.begin(), w.end(), '\n', ' ');
        reject(lib + " failed: " + w);
    }
    write_off(argv[5], out);
    return 0;
}
