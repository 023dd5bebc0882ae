// OpenSubdiv side of subd's conformance and benchmark harness.
//
// Reads one mesh in a small binary format from stdin (written by `cargo xtask`), refines it
// uniformly with OpenSubdiv's Far API in double precision, and writes every refined level to
// stdout. With --bench it instead times topology refinement + primvar interpolation and
// prints one line of JSON. Linked against the system OpenSubdiv (Debian libosd-dev).
//
// Input (little-endian): "SUBDOSD1", u32 scheme (0 bilinear, 1 catmark, 2 loop),
// u32 boundary (0 none, 1 edge-only, 2 edge-and-corner), u32 crease method (0 uniform,
// 1 chaikin), u32 triangle rule (0 catmark, 1 smooth), u32 levels, u32 nv, u32 nf,
// u32 sizes[nf], u32 nidx, u32 idx[nidx], f64 pos[3 nv], u32 ncrease, {u32 a, u32 b, f32 s},
// u32 ncorner, {u32 v, f32 s}, u32 nhole, u32 f[nhole].
// Output per level 1..L: u32 nv, u32 nf, u32 sizes[nf], u32 idx[sum sizes], f64 pos[3 nv].
// With --limit: PrimvarRefiner::Limit applied to level L instead: u32 nv, then f64 pos[3 nv],
// f64 tan1[3 nv], f64 tan2[3 nv]; --limit-positions the same with zero tangents (for the
// meshes where OpenSubdiv's tangent masks overflow their buffers and crash).
// With --eval, the input continues with u32 count, {u32 ptex face, f64 u, f64 v}: the mesh is
// refined adaptively to isolation level L (infinitely sharp patches on, legacy sharp corners
// off, Gregory end caps) and the patch table evaluated in double precision at each point:
// output per point f64 P[3], Du[3], Dv[3], Duu[3], Duv[3], Dvv[3].
// With --bfr RATE: Bfr::RefinerSurfaceFactory (approximation levels 10, as the patch table's
// isolation) and a uniform Bfr::Tessellation at RATE for every face with a surface; output
// u32 count, then per point u32 face, u32 sub-face (0 unless the face is parameterised by
// quad sub-faces), f64 u, f64 v (the sub-face's normalised coordinates), f64 P[3].
// With --fvar MODE (Sdc's FVarLinearInterpolation, 0 none .. 5 all), the input continues with
// one face-varying channel of 2-component values: u32 nvalues, f64 values[2 nvalues],
// u32 index[nidx] (one per face-vertex). The channel is refined with
// PrimvarRefinerReal<double>::InterpolateFaceVarying; output per level 1..L: u32 nvalues,
// u32 nfv, u32 faceValues[nfv] (GetFaceFVarValues, face after face), f64 values[2 nvalues].
// --fvar-limit MODE then applies LimitFaceVarying at level L instead: u32 nvalues,
// f64 values[2 nvalues].
// --fvar-bench MODE REPEATS times the same instead: the medians of topology refinement with
// the channel (Create + RefineUniform), of InterpolateFaceVarying through every level into
// vectors allocated as it goes, and of the same again into those vectors; one line of JSON.
// With --bfr-bench RATE REPEATS: the median time of building the factory and, for every
// face, its surface, tessellation coordinates, patch points and positions with first
// derivatives; one line of JSON.

#include <time.h>

#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/bfr/tessellation.h>
#include <opensubdiv/far/error.h>
#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

using namespace OpenSubdiv;

namespace {

struct Reader {
    std::vector<unsigned char> data;
    size_t pos = 0;
    template <typename T> T get() {
        if (pos + sizeof(T) > data.size()) throw std::runtime_error("input truncated");
        T v;
        std::memcpy(&v, &data[pos], sizeof(T));
        pos += sizeof(T);
        return v;
    }
};

struct Point {
    double p[3];
    void Clear() { p[0] = p[1] = p[2] = 0.0; }
    void AddWithWeight(Point const &src, double w) {
        p[0] += w * src.p[0];
        p[1] += w * src.p[1];
        p[2] += w * src.p[2];
    }
};

struct Uv {
    double p[2];
    void Clear() { p[0] = p[1] = 0.0; }
    void AddWithWeight(Uv const &src, double w) {
        p[0] += w * src.p[0];
        p[1] += w * src.p[1];
    }
};

template <typename T> void put(std::vector<unsigned char> &out, T v) {
    size_t n = out.size();
    out.resize(n + sizeof(T));
    std::memcpy(&out[n], &v, sizeof(T));
}

struct Mesh {
    Sdc::SchemeType scheme;
    Sdc::Options options;
    int levels;
    int nv;
    std::vector<int> sizes;
    std::vector<Far::Index> idx;
    std::vector<Point> pos;
    std::vector<Far::Index> creasePairs;
    std::vector<float> creaseWeights;
    std::vector<Far::Index> corners;
    std::vector<float> cornerWeights;
    std::vector<Far::Index> holes;
    std::vector<Uv> fvarValues;
    std::vector<Far::Index> fvarIndices;
};

// The face-varying channel that follows the mesh for --fvar.
void readFVar(Reader &r, Mesh &m) {
    uint32_t nvalues = r.get<uint32_t>();
    m.fvarValues.resize(nvalues);
    for (auto &v : m.fvarValues)
        for (double &c : v.p) c = r.get<double>();
    m.fvarIndices.resize(m.idx.size());
    for (auto &i : m.fvarIndices) i = (Far::Index)r.get<uint32_t>();
}

Mesh readMesh(Reader &r) {
    if (r.data.size() < 8 || std::memcmp(r.data.data(), "SUBDOSD1", 8) != 0)
        throw std::runtime_error("bad magic");
    r.pos = 8;
    Mesh m;
    uint32_t scheme = r.get<uint32_t>();
    m.scheme = scheme == 0 ? Sdc::SCHEME_BILINEAR : scheme == 1 ? Sdc::SCHEME_CATMARK : Sdc::SCHEME_LOOP;
    uint32_t boundary = r.get<uint32_t>();
    m.options.SetVtxBoundaryInterpolation(boundary == 0   ? Sdc::Options::VTX_BOUNDARY_NONE
                                          : boundary == 1 ? Sdc::Options::VTX_BOUNDARY_EDGE_ONLY
                                                          : Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    m.options.SetCreasingMethod(r.get<uint32_t>() == 0 ? Sdc::Options::CREASE_UNIFORM
                                                       : Sdc::Options::CREASE_CHAIKIN);
    m.options.SetTriangleSubdivision(r.get<uint32_t>() == 0 ? Sdc::Options::TRI_SUB_CATMARK
                                                            : Sdc::Options::TRI_SUB_SMOOTH);
    m.levels = (int)r.get<uint32_t>();
    m.nv = (int)r.get<uint32_t>();
    uint32_t nf = r.get<uint32_t>();
    m.sizes.resize(nf);
    for (auto &s : m.sizes) s = (int)r.get<uint32_t>();
    uint32_t nidx = r.get<uint32_t>();
    m.idx.resize(nidx);
    for (auto &i : m.idx) i = (Far::Index)r.get<uint32_t>();
    m.pos.resize(m.nv);
    for (auto &p : m.pos)
        for (double &c : p.p) c = r.get<double>();
    uint32_t nc = r.get<uint32_t>();
    for (uint32_t i = 0; i < nc; ++i) {
        m.creasePairs.push_back((Far::Index)r.get<uint32_t>());
        m.creasePairs.push_back((Far::Index)r.get<uint32_t>());
        m.creaseWeights.push_back(r.get<float>());
    }
    uint32_t nk = r.get<uint32_t>();
    for (uint32_t i = 0; i < nk; ++i) {
        m.corners.push_back((Far::Index)r.get<uint32_t>());
        m.cornerWeights.push_back(r.get<float>());
    }
    uint32_t nh = r.get<uint32_t>();
    for (uint32_t i = 0; i < nh; ++i) m.holes.push_back((Far::Index)r.get<uint32_t>());
    return m;
}

Far::TopologyRefiner *createRefiner(Mesh const &m) {
    Far::TopologyDescriptor desc;
    desc.numVertices = m.nv;
    desc.numFaces = (int)m.sizes.size();
    desc.numVertsPerFace = m.sizes.data();
    desc.vertIndicesPerFace = m.idx.data();
    desc.numCreases = (int)m.creaseWeights.size();
    desc.creaseVertexIndexPairs = m.creasePairs.data();
    desc.creaseWeights = m.creaseWeights.data();
    desc.numCorners = (int)m.cornerWeights.size();
    desc.cornerVertexIndices = m.corners.data();
    desc.cornerWeights = m.cornerWeights.data();
    desc.numHoles = (int)m.holes.size();
    desc.holeIndices = m.holes.data();
    Far::TopologyDescriptor::FVarChannel channel;
    if (!m.fvarIndices.empty()) {
        channel.numValues = (int)m.fvarValues.size();
        channel.valueIndices = m.fvarIndices.data();
        desc.numFVarChannels = 1;
        desc.fvarChannels = &channel;
    }
    typedef Far::TopologyRefinerFactory<Far::TopologyDescriptor> Factory;
    Far::TopologyRefiner *refiner =
        Factory::Create(desc, Factory::Options(m.scheme, m.options));
    if (!refiner) throw std::runtime_error("OpenSubdiv rejected the topology");
    return refiner;
}

// Refines and interpolates; returns the positions of every level (level 0 included).
std::vector<std::vector<Point>> refineAll(Far::TopologyRefiner &refiner, Mesh const &m) {
    Far::TopologyRefiner::UniformOptions uo(m.levels);
    uo.fullTopologyInLastLevel = true;
    refiner.RefineUniform(uo);
    std::vector<std::vector<Point>> levels(m.levels + 1);
    levels[0] = m.pos;
    Far::PrimvarRefinerReal<double> primvar(refiner);
    for (int l = 1; l <= m.levels; ++l) {
        levels[l].resize(refiner.GetLevel(l).GetNumVertices());
        primvar.Interpolate(l, levels[l - 1], levels[l]);
    }
    return levels;
}

// Peak resident set size of this process in bytes (VmHWM), 0 if unknown.
long peakRssBytes() {
    FILE *f = std::fopen("/proc/self/status", "r");
    if (!f) return 0;
    char line[256];
    long kb = 0;
    while (std::fgets(line, sizeof line, f))
        if (std::strncmp(line, "VmHWM:", 6) == 0) kb = std::atol(line + 6);
    std::fclose(f);
    return kb * 1024;
}

// Bfr's uniform tessellation of every face at `rate`: writes the points (see the header)
// into `out` when given; returns a checksum (so the timed run does the same work).
double bfrTessellate(Far::TopologyRefiner const &refiner, Mesh const &m, int rate,
                     std::vector<unsigned char> *out) {
    typedef Bfr::RefinerSurfaceFactory<> Factory;
    Factory::Options fo;
    fo.SetApproxLevelSmooth(10);
    fo.SetApproxLevelSharp(10);
    Factory factory(refiner, fo);
    Bfr::Surface<double> surface;
    Bfr::Surface<double>::PointDescriptor desc(3);
    std::vector<double> coords, patchPoints;
    std::vector<unsigned char> body;
    uint32_t count = 0;
    double check = 0.0;
    for (int f = 0; f < (int)m.sizes.size(); ++f) {
        if (!factory.InitVertexSurface(f, &surface)) continue;
        Bfr::Parameterization param = surface.GetParameterization();
        Bfr::Tessellation tess(param, rate, Bfr::Tessellation::Options());
        coords.resize(2 * tess.GetNumCoords());
        tess.GetCoords(coords.data());
        patchPoints.resize(3 * surface.GetNumPatchPoints());
        surface.PreparePatchPoints(&m.pos[0].p[0], desc, patchPoints.data(), desc);
        for (int k = 0; k < tess.GetNumCoords(); ++k) {
            double P[3], Du[3], Dv[3];
            surface.Evaluate(&coords[2 * k], patchPoints.data(), desc, P, Du, Dv);
            check += P[0] + Du[1] + Dv[2];
            if (!out) continue;
            double uv[2] = {coords[2 * k], coords[2 * k + 1]};
            int sub = 0;
            if (param.HasSubFaces()) sub = param.ConvertCoordToNormalizedSubFace(&coords[2 * k], uv);
            put<uint32_t>(body, (uint32_t)f);
            put<uint32_t>(body, (uint32_t)sub);
            put<double>(body, uv[0]);
            put<double>(body, uv[1]);
            for (double x : P) put<double>(body, x);
            ++count;
        }
    }
    if (out) {
        put<uint32_t>(*out, count);
        out->insert(out->end(), body.begin(), body.end());
    }
    return check;
}

// The factory options of --patches and --patches-bench (argv[2..5]: ENDCAP SINGLE_CREASE
// INF_SHARP LEGACY_CORNERS), double precision, no varying tables.
Far::PatchTableFactory::Options patchOptions(Mesh const &m, char **argv) {
    Far::PatchTableFactory::Options po(m.levels);
    po.SetPatchPrecision<double>();
    po.endCapType = (Far::PatchTableFactory::Options::EndCapType)std::atoi(argv[2]);
    po.useSingleCreasePatch = std::atoi(argv[3]) != 0;
    po.useInfSharpPatch = std::atoi(argv[4]) != 0;
    po.generateLegacySharpCornerPatches = std::atoi(argv[5]) != 0;
    po.generateVaryingTables = false;
    return po;
}

// The refined vertices of every level of an adaptive refinement, then the table's local
// points, from the mesh's positions.
std::vector<Point> patchPoints(Mesh const &m, Far::TopologyRefiner const &refiner, Far::PatchTable const &table) {
    int nRefined = refiner.GetNumVerticesTotal();
    int nLocal = table.GetNumLocalPoints();
    std::vector<Point> verts(nRefined + nLocal);
    std::copy(m.pos.begin(), m.pos.end(), verts.begin());
    Far::PrimvarRefinerReal<double> primvar(refiner);
    Point *src = verts.data();
    for (int l = 1; l < refiner.GetNumLevels(); ++l) {
        Point *dst = src + refiner.GetLevel(l - 1).GetNumVertices();
        primvar.Interpolate(l, src, dst);
        src = dst;
    }
    if (nLocal) table.GetLocalPointStencilTable<double>()->UpdateValues(verts.data(), verts.data() + nRefined);
    return verts;
}

// The face-varying channel 0 of a patch table at each point: value, du, dv (f64[2] each),
// then u32 n and the n values (f64[2]) of the point's face-varying patch.
void patchFVar(Mesh const &m, Far::TopologyRefiner const &refiner, Far::PatchTable const &table,
               std::vector<int> const &faces, std::vector<double> const &us, std::vector<double> const &vs,
               std::vector<unsigned char> &out) {
    std::vector<Uv> values(refiner.GetNumFVarValuesTotal(0));
    std::copy(m.fvarValues.begin(), m.fvarValues.end(), values.begin());
    Far::PrimvarRefinerReal<double> primvar(refiner);
    Uv *src = values.data();
    for (int l = 1; l < refiner.GetNumLevels(); ++l) {
        Uv *dst = src + refiner.GetLevel(l - 1).GetNumFVarValues(0);
        primvar.InterpolateFaceVarying(l, src, dst, 0);
        src = dst;
    }
    Far::PatchMap map(table);
    double w[3][20];
    for (size_t i = 0; i < faces.size(); ++i) {
        Far::PatchTable::PatchHandle const *h = map.FindPatch(faces[i], us[i], vs[i]);
        if (!h) throw std::runtime_error("no patch at point " + std::to_string(i));
        table.EvaluateBasisFaceVarying(*h, us[i], vs[i], w[0], w[1], w[2], 0, 0, 0, 0);
        Far::ConstIndexArray cvs = table.GetPatchFVarValues(*h, 0);
        for (int d = 0; d < 3; ++d) {
            Uv acc;
            acc.Clear();
            for (int c = 0; c < cvs.size(); ++c) acc.AddWithWeight(values[cvs[c]], w[d][c]);
            for (double x : acc.p) put<double>(out, x);
        }
        put<uint32_t>(out, (uint32_t)cvs.size());
        for (int c = 0; c < cvs.size(); ++c)
            for (double x : values[cvs[c]].p) put<double>(out, x);
    }
}

// The patch table of an adaptive refinement to isolation level `m.levels` with the given
// factory options (--patches ENDCAP SINGLE_CREASE INF_SHARP LEGACY_CORNERS; ENDCAP is
// PatchTableFactory::Options::EndCapType), evaluated in double precision at the points that
// follow the mesh (u32 count, {u32 ptex face, f64 u, f64 v}). Output: u32 arrays, per array
// u32 type (PatchDescriptor::Type), u32 control points, u32 patches, per patch u32 face, u, v,
// depth, nonquad, boundary, transition, regular, f32 single-crease sharpness, u32 cvs[n];
// then u32 local points, u32 refined vertices, per point f64 P, Du, Dv, Duu, Duv, Dvv [3],
// then f64 pos[3 (refined + local)]. With a face-varying channel (--patches ... MODE, the
// channel between the mesh and the points), the table also has its face-varying patches
// (generateFVarTables, OpenSubdiv's default linear ones), and per point f64 value[2], du[2],
// dv[2] (EvaluateBasisFaceVarying over the values refined per level), u32 n and the n
// values of its patch follow.
void patchTable(Mesh const &m, Reader &r, char **argv, std::vector<unsigned char> &out) {
    uint32_t count = r.get<uint32_t>();
    std::vector<int> faces(count);
    std::vector<double> us(count), vs(count);
    for (uint32_t i = 0; i < count; ++i) {
        faces[i] = (int)r.get<uint32_t>();
        us[i] = r.get<double>();
        vs[i] = r.get<double>();
    }
    Far::TopologyRefiner *refiner = createRefiner(m);
    Far::PatchTableFactory::Options po = patchOptions(m, argv);
    bool fvar = !m.fvarIndices.empty();
    po.generateFVarTables = fvar;
    refiner->RefineAdaptive(po.GetRefineAdaptiveOptions());
    Far::PatchTable const *table = Far::PatchTableFactory::Create(*refiner, po);
    put<uint32_t>(out, (uint32_t)table->GetNumPatchArrays());
    for (int a = 0; a < table->GetNumPatchArrays(); ++a) {
        Far::PatchDescriptor d = table->GetPatchArrayDescriptor(a);
        int np = table->GetNumPatches(a);
        put<uint32_t>(out, (uint32_t)d.GetType());
        put<uint32_t>(out, (uint32_t)d.GetNumControlVertices());
        put<uint32_t>(out, (uint32_t)np);
        for (int p = 0; p < np; ++p) {
            Far::PatchParam pp = table->GetPatchParam(a, p);
            for (int x : {pp.GetFaceId(), (int)pp.GetU(), (int)pp.GetV(), (int)pp.GetDepth(),
                          (int)pp.NonQuadRoot(), (int)pp.GetBoundary(), (int)pp.GetTransition(), (int)pp.IsRegular()})
                put<uint32_t>(out, (uint32_t)x);
            // The sharpness arrays exist only with single-crease patches.
            put<float>(out, po.useSingleCreasePatch ? table->GetSingleCreasePatchSharpnessValue(a, p) : 0.0f);
            Far::ConstIndexArray cvs = table->GetPatchVertices(a, p);
            for (int c = 0; c < cvs.size(); ++c) put<uint32_t>(out, (uint32_t)cvs[c]);
        }
    }
    put<uint32_t>(out, (uint32_t)table->GetNumLocalPoints());
    put<uint32_t>(out, (uint32_t)refiner->GetNumVerticesTotal());
    std::vector<Point> verts = patchPoints(m, *refiner, *table);
    Far::PatchMap map(*table);
    double w[6][20];
    for (uint32_t i = 0; i < count; ++i) {
        Far::PatchTable::PatchHandle const *h = map.FindPatch(faces[i], us[i], vs[i]);
        if (!h) throw std::runtime_error("no patch at point " + std::to_string(i));
        table->EvaluateBasis(*h, us[i], vs[i], w[0], w[1], w[2], w[3], w[4], w[5]);
        Far::ConstIndexArray cvs = table->GetPatchVertices(*h);
        for (int d = 0; d < 6; ++d) {
            Point acc;
            acc.Clear();
            for (int c = 0; c < cvs.size(); ++c) acc.AddWithWeight(verts[cvs[c]], w[d][c]);
            for (double x : acc.p) put<double>(out, x);
        }
    }
    for (auto const &p : verts)
        for (double c : p.p) put<double>(out, c);
    if (fvar) patchFVar(m, *refiner, *table, faces, us, vs, out);
    delete table;
    delete refiner;
}

// --patches-bench ENDCAP SINGLE_CREASE INF_SHARP LEGACY_CORNERS REPEATS: the medians of
// building (topology refiner, RefineAdaptive, PatchTableFactory::Create with its local-point
// stencils, the refined and local points of the mesh's positions) and of evaluating the
// points that follow the mesh (PatchMap::FindPatch, EvaluateBasis with first derivatives,
// the weighted sums); one line of JSON.
void patchBench(Mesh const &m, Reader &r, char **argv) {
    uint32_t count = r.get<uint32_t>();
    std::vector<int> faces(count);
    std::vector<double> us(count), vs(count);
    for (uint32_t i = 0; i < count; ++i) {
        faces[i] = (int)r.get<uint32_t>();
        us[i] = r.get<double>();
        vs[i] = r.get<double>();
    }
    int reps = std::atoi(argv[6]);
    std::vector<double> build, eval;
    double check = 0.0;
    for (int rep = 0; rep < reps; ++rep) {
        auto t0 = std::chrono::steady_clock::now();
        Far::TopologyRefiner *refiner = createRefiner(m);
        Far::PatchTableFactory::Options po = patchOptions(m, argv);
        refiner->RefineAdaptive(po.GetRefineAdaptiveOptions());
        Far::PatchTable const *table = Far::PatchTableFactory::Create(*refiner, po);
        std::vector<Point> verts = patchPoints(m, *refiner, *table);
        auto t1 = std::chrono::steady_clock::now();
        Far::PatchMap map(*table);
        auto t2 = std::chrono::steady_clock::now();
        double w[3][20];
        for (uint32_t i = 0; i < count; ++i) {
            Far::PatchTable::PatchHandle const *h = map.FindPatch(faces[i], us[i], vs[i]);
            if (!h) continue;
            table->EvaluateBasis(*h, us[i], vs[i], w[0], w[1], w[2]);
            Far::ConstIndexArray cvs = table->GetPatchVertices(*h);
            Point acc[3];
            for (auto &p : acc) p.Clear();
            for (int c = 0; c < cvs.size(); ++c)
                for (int d = 0; d < 3; ++d) acc[d].AddWithWeight(verts[cvs[c]], w[d][c]);
            check += acc[0].p[0] + acc[1].p[1] + acc[2].p[2];
        }
        auto t3 = std::chrono::steady_clock::now();
        build.push_back(std::chrono::duration<double>(t1 - t0).count());
        eval.push_back(std::chrono::duration<double>(t3 - t2).count());
        delete table;
        delete refiner;
    }
    std::sort(build.begin(), build.end());
    std::sort(eval.begin(), eval.end());
    std::printf("{\"build_seconds\": %.9f, \"eval_seconds\": %.9f, \"check\": %.6f}\n",
                build[build.size() / 2], eval[eval.size() / 2], check);
}

} // namespace

int main(int argc, char **argv) {
    // OpenSubdiv prints its warnings on stdout, which carries the binary results: send them
    // to stderr.
    Far::SetWarningCallback([](char const *msg) { std::fprintf(stderr, "OpenSubdiv: %s\n", msg); });
    try {
        bool bench = argc > 1 && std::string(argv[1]) == "--bench";
        int repeats = argc > 2 ? std::atoi(argv[2]) : 5;
        Reader r;
        unsigned char buf[1 << 16];
        size_t n;
        while ((n = std::fread(buf, 1, sizeof buf, stdin)) > 0) r.data.insert(r.data.end(), buf, buf + n);
        Mesh m = readMesh(r);
        if (bench) {
            // Median of `repeats` runs of topology refinement (OpenSubdiv's default uniform
            // options: full topology only below the last level) + primvar interpolation.
            std::vector<double> topo, prim, total, cpu;
            // CPU time of the whole process (user + system), beside the wall clock.
            auto cpuNow = [] {
                timespec ts;
                clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
                return ts.tv_sec + ts.tv_nsec * 1e-9;
            };
            for (int i = 0; i < repeats; ++i) {
                double c0 = cpuNow();
                auto t0 = std::chrono::steady_clock::now();
                Far::TopologyRefiner *refiner = createRefiner(m);
                Far::TopologyRefiner::UniformOptions uo(m.levels);
                refiner->RefineUniform(uo);
                auto t1 = std::chrono::steady_clock::now();
                std::vector<std::vector<Point>> levels(m.levels + 1);
                levels[0] = m.pos;
                Far::PrimvarRefinerReal<double> primvar(*refiner);
                for (int l = 1; l <= m.levels; ++l) {
                    levels[l].resize(refiner->GetLevel(l).GetNumVertices());
                    primvar.Interpolate(l, levels[l - 1], levels[l]);
                }
                auto t2 = std::chrono::steady_clock::now();
                cpu.push_back(cpuNow() - c0);
                topo.push_back(std::chrono::duration<double>(t1 - t0).count());
                prim.push_back(std::chrono::duration<double>(t2 - t1).count());
                total.push_back(std::chrono::duration<double>(t2 - t0).count());
                delete refiner;
            }
            auto median = [](std::vector<double> v) {
                std::sort(v.begin(), v.end());
                return v[v.size() / 2];
            };
            std::printf("{\"seconds\": %.9f, \"topology_seconds\": %.9f, \"primvar_seconds\": %.9f, "
                        "\"cpu_seconds\": %.9f, \"peak_rss_bytes\": %ld}\n",
                        median(total), median(topo), median(prim), median(cpu), peakRssBytes());
            return 0;
        }
        if (argc > 6 && std::string(argv[1]) == "--patches-bench") {
            patchBench(m, r, argv);
            return 0;
        }
        if (argc > 5 && std::string(argv[1]) == "--patches") {
            if (argc > 6) {
                m.options.SetFVarLinearInterpolation((Sdc::Options::FVarLinearInterpolation)std::atoi(argv[6]));
                readFVar(r, m);
            }
            std::vector<unsigned char> out;
            patchTable(m, r, argv, out);
            std::fwrite(out.data(), 1, out.size(), stdout);
            return 0;
        }
        bool bfrBench = argc > 1 && std::string(argv[1]) == "--bfr-bench";
        if (bfrBench || (argc > 1 && std::string(argv[1]) == "--bfr")) {
            int rate = argc > 2 ? std::atoi(argv[2]) : 4;
            Far::TopologyRefiner *refiner = createRefiner(m);
            if (!bfrBench) {
                std::vector<unsigned char> out;
                bfrTessellate(*refiner, m, rate, &out);
                std::fwrite(out.data(), 1, out.size(), stdout);
                delete refiner;
                return 0;
            }
            int reps = argc > 3 ? std::atoi(argv[3]) : 5;
            std::vector<double> times;
            double check = 0.0;
            for (int i = 0; i < reps; ++i) {
                auto a = std::chrono::steady_clock::now();
                check += bfrTessellate(*refiner, m, rate, nullptr);
                times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count());
            }
            std::sort(times.begin(), times.end());
            std::printf("{\"seconds\": %.9f, \"check\": %.6f}\n", times[times.size() / 2], check);
            delete refiner;
            return 0;
        }
        bool evalBench = argc > 1 && std::string(argv[1]) == "--eval-bench";
        if (evalBench || (argc > 1 && std::string(argv[1]) == "--eval")) {
            uint32_t count = r.get<uint32_t>();
            std::vector<int> faces(count);
            std::vector<double> us(count), vs(count);
            for (uint32_t i = 0; i < count; ++i) {
                faces[i] = (int)r.get<uint32_t>();
                us[i] = r.get<double>();
                vs[i] = r.get<double>();
            }
            auto t0 = std::chrono::steady_clock::now();
            Far::TopologyRefiner *refiner = createRefiner(m);
            Far::PatchTableFactory::Options po(m.levels);
            po.SetPatchPrecision<double>();
            po.useInfSharpPatch = true;
            po.generateLegacySharpCornerPatches = false;
            po.generateVaryingTables = false;
            po.endCapType = Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS;
            refiner->RefineAdaptive(po.GetRefineAdaptiveOptions());
            Far::PatchTable const *table = Far::PatchTableFactory::Create(*refiner, po);
            int nRefined = refiner->GetNumVerticesTotal();
            int nLocal = table->GetNumLocalPoints();
            std::vector<Point> verts(nRefined + nLocal);
            std::copy(m.pos.begin(), m.pos.end(), verts.begin());
            Far::PrimvarRefinerReal<double> primvar(*refiner);
            Point *src = verts.data();
            for (int l = 1; l < refiner->GetNumLevels(); ++l) {
                Point *dst = src + refiner->GetLevel(l - 1).GetNumVertices();
                primvar.Interpolate(l, src, dst);
                src = dst;
            }
            if (nLocal) table->GetLocalPointStencilTable<double>()->UpdateValues(verts.data(), verts.data() + nRefined);
            Far::PatchMap map(*table);
            std::vector<unsigned char> out;
            double w[6][20];
            if (evalBench) {
                // Setup (refinement, patch table, points, patch map) once; then the median of
                // `repeats` passes over all points: find the patch, evaluate the basis with
                // derivatives, combine the control points.
                double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
                std::vector<double> times;
                double check = 0.0;
                for (int rep = 0; rep < repeats; ++rep) {
                    auto a = std::chrono::steady_clock::now();
                    for (uint32_t i = 0; i < count; ++i) {
                        Far::PatchTable::PatchHandle const *h = map.FindPatch(faces[i], us[i], vs[i]);
                        table->EvaluateBasis(*h, us[i], vs[i], w[0], w[1], w[2], w[3], w[4], w[5]);
                        Far::ConstIndexArray cvs = table->GetPatchVertices(*h);
                        Point acc[6];
                        for (auto &p : acc) p.Clear();
                        for (int c = 0; c < cvs.size(); ++c)
                            for (int d = 0; d < 6; ++d) acc[d].AddWithWeight(verts[cvs[c]], w[d][c]);
                        check += acc[0].p[0] + acc[1].p[1];
                    }
                    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count());
                }
                std::sort(times.begin(), times.end());
                std::printf("{\"setup_seconds\": %.9f, \"seconds\": %.9f, \"points\": %u, \"check\": %.6f}\n",
                            setup, times[times.size() / 2], count, check);
                return 0;
            }
            for (uint32_t i = 0; i < count; ++i) {
                Far::PatchTable::PatchHandle const *h = map.FindPatch(faces[i], us[i], vs[i]);
                if (!h) throw std::runtime_error("no patch at point " + std::to_string(i));
                table->EvaluateBasis(*h, us[i], vs[i], w[0], w[1], w[2], w[3], w[4], w[5]);
                Far::ConstIndexArray cvs = table->GetPatchVertices(*h);
                for (int d = 0; d < 6; ++d) {
                    Point acc;
                    acc.Clear();
                    for (int c = 0; c < cvs.size(); ++c) acc.AddWithWeight(verts[cvs[c]], w[d][c]);
                    for (double x : acc.p) put<double>(out, x);
                }
            }
            std::fwrite(out.data(), 1, out.size(), stdout);
            delete table;
            delete refiner;
            return 0;
        }
        if (argc > 3 && std::string(argv[1]) == "--fvar-bench") {
            m.options.SetFVarLinearInterpolation((Sdc::Options::FVarLinearInterpolation)std::atoi(argv[2]));
            readFVar(r, m);
            int reps = std::atoi(argv[3]);
            std::vector<double> topo, fvar, into;
            for (int i = 0; i < reps; ++i) {
                auto t0 = std::chrono::steady_clock::now();
                Far::TopologyRefiner *refiner = createRefiner(m);
                Far::TopologyRefiner::UniformOptions uo(m.levels);
                refiner->RefineUniform(uo);
                auto t1 = std::chrono::steady_clock::now();
                Far::PrimvarRefinerReal<double> primvar(*refiner);
                std::vector<std::vector<Uv>> values(m.levels + 1);
                values[0] = m.fvarValues;
                for (int l = 1; l <= m.levels; ++l) {
                    values[l].resize(refiner->GetLevel(l).GetNumFVarValues(0));
                    primvar.InterpolateFaceVarying(l, values[l - 1], values[l], 0);
                }
                auto t2 = std::chrono::steady_clock::now();
                // Again into the same buffers, now allocated and written: the time of
                // InterpolateFaceVarying alone, as a caller that keeps its buffers sees it.
                for (int l = 1; l <= m.levels; ++l)
                    primvar.InterpolateFaceVarying(l, values[l - 1], values[l], 0);
                auto t3 = std::chrono::steady_clock::now();
                topo.push_back(std::chrono::duration<double>(t1 - t0).count());
                fvar.push_back(std::chrono::duration<double>(t2 - t1).count());
                into.push_back(std::chrono::duration<double>(t3 - t2).count());
                delete refiner;
            }
            auto median = [](std::vector<double> v) {
                std::sort(v.begin(), v.end());
                return v[v.size() / 2];
            };
            std::printf("{\"topology_seconds\": %.9f, \"fvar_seconds\": %.9f, \"fvar_into_seconds\": %.9f}\n",
                        median(topo), median(fvar), median(into));
            return 0;
        }
        bool fvarLimit = argc > 2 && std::string(argv[1]) == "--fvar-limit";
        if (fvarLimit || (argc > 2 && std::string(argv[1]) == "--fvar")) {
            m.options.SetFVarLinearInterpolation((Sdc::Options::FVarLinearInterpolation)std::atoi(argv[2]));
            readFVar(r, m);
            Far::TopologyRefiner *refiner = createRefiner(m);
            Far::TopologyRefiner::UniformOptions uo(m.levels);
            uo.fullTopologyInLastLevel = true;
            refiner->RefineUniform(uo);
            Far::PrimvarRefinerReal<double> primvar(*refiner);
            std::vector<std::vector<Uv>> values(m.levels + 1);
            values[0] = m.fvarValues;
            std::vector<unsigned char> out;
            for (int l = 1; l <= m.levels; ++l) {
                Far::TopologyLevel const &lev = refiner->GetLevel(l);
                values[l].resize(lev.GetNumFVarValues(0));
                primvar.InterpolateFaceVarying(l, values[l - 1], values[l], 0);
                if (fvarLimit) continue;
                put<uint32_t>(out, (uint32_t)values[l].size());
                put<uint32_t>(out, (uint32_t)lev.GetNumFaceVertices());
                for (int f = 0; f < lev.GetNumFaces(); ++f) {
                    Far::ConstIndexArray fv = lev.GetFaceFVarValues(f, 0);
                    for (int k = 0; k < fv.size(); ++k) put<uint32_t>(out, (uint32_t)fv[k]);
                }
                for (auto const &v : values[l])
                    for (double c : v.p) put<double>(out, c);
            }
            if (fvarLimit) {
                std::vector<Uv> limit(values[m.levels].size());
                primvar.LimitFaceVarying(values[m.levels], limit, 0);
                put<uint32_t>(out, (uint32_t)limit.size());
                for (auto const &v : limit)
                    for (double c : v.p) put<double>(out, c);
            }
            std::fwrite(out.data(), 1, out.size(), stdout);
            delete refiner;
            return 0;
        }
        Far::TopologyRefiner *refiner = createRefiner(m);
        auto levels = refineAll(*refiner, m);
        std::vector<unsigned char> out;
        bool limitPositions = argc > 1 && std::string(argv[1]) == "--limit-positions";
        if (limitPositions || (argc > 1 && std::string(argv[1]) == "--limit")) {
            std::vector<Point> const &last = levels[m.levels];
            size_t nv = last.size();
            std::vector<Point> pos(nv), tan1(nv), tan2(nv);
            for (auto *v : {&tan1, &tan2})
                for (auto &p : *v) p.Clear();
            Far::PrimvarRefinerReal<double> primvar(*refiner);
            if (limitPositions)
                primvar.Limit(last, pos);
            else
                primvar.Limit(last, pos, tan1, tan2);
            put<uint32_t>(out, (uint32_t)nv);
            for (auto const *v : {&pos, &tan1, &tan2})
                for (auto const &p : *v)
                    for (double c : p.p) put<double>(out, c);
            std::fwrite(out.data(), 1, out.size(), stdout);
            delete refiner;
            return 0;
        }
        for (int l = 1; l <= m.levels; ++l) {
            Far::TopologyLevel const &lev = refiner->GetLevel(l);
            put<uint32_t>(out, (uint32_t)lev.GetNumVertices());
            put<uint32_t>(out, (uint32_t)lev.GetNumFaces());
            for (int f = 0; f < lev.GetNumFaces(); ++f) put<uint32_t>(out, (uint32_t)lev.GetFaceVertices(f).size());
            for (int f = 0; f < lev.GetNumFaces(); ++f) {
                Far::ConstIndexArray fv = lev.GetFaceVertices(f);
                for (int k = 0; k < fv.size(); ++k) put<uint32_t>(out, (uint32_t)fv[k]);
            }
            for (auto const &p : levels[l])
                for (double c : p.p) put<double>(out, c);
        }
        std::fwrite(out.data(), 1, out.size(), stdout);
        delete refiner;
        return 0;
    } catch (std::exception const &e) {
        std::fprintf(stderr, "osd_harness: %s\n", e.what());
        return 2;
    }
}
